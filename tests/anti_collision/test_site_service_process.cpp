// The site service as a process on DDS (services/anti_collision/node/site_service_node.cpp): this
// test's participant plays the three cranes of the shipped site on the site's topics and checks
// what the process answers: a grant over DDS, its heartbeat, a silent crane's whole reach, the
// site operator's word that a silent crane is out of service, a malformed report refused without harm, and a service killed with -9 and started again (a new
// epoch, a crane still moving held at its whole reach until it reports at rest). ctest runs it in
// a private network namespace; the participants are bound to loopback.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <fstream>
#include <iterator>
#include <thread>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "crane/anti_collision/site_messages.hpp"
#include "crane/launch/process_group.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/testing/scratch_directory.hpp"
#include "crane/transport/participant.hpp"
#include "crane/transport/topics.hpp"

namespace {

namespace fs = std::filesystem;
namespace ac = crane::anti_collision;
namespace tp = crane::transport::topics;
using crane::protocol::SiteStatus;
using Clock = std::chrono::steady_clock;

const std::string kBin = CRANE_BIN_DIR;
const std::string kSite = std::string(CRANE_SOURCE_DIR) + "/deploy/config/site_three_towers.yaml";
constexpr double kPi = 3.14159265358979323846;
constexpr std::uint32_t kDomain = 61;

// Each crane hook up, its jib pointed away from the others (slew pi: tc1 west, tc2 east, tc3 north).
const ac::Pose kRest[3] = {{kPi, 0.5, 0.2}, {kPi, 0.5, 0.2}, {kPi, 0.5, 0.2}};

class SiteProcess {
 public:
  SiteProcess() : dir_(crane::testing::scratch_directory("site_service")) {
    crane::transport::ParticipantOptions p;
    p.name = "site_test_cranes";
    p.domain_id = kDomain;
    participant_ = std::make_unique<crane::transport::Participant>(p);
    reports_ = participant_->make_writer<tp::SiteReport>();
    instructions_ = participant_->make_recording_reader<tp::SiteInstruction>(&wakeup_, 256);
    status_ = participant_->make_recording_reader<tp::SiteStatus>(&wakeup_, 256);
    start();
  }
  ~SiteProcess() {
    status_.reset();
    instructions_.reset();
    group_.stop_all();
  }

  pid_t start() {
    crane::launch::ProcessSpec spec;
    spec.name = "site_service";
    spec.executable = kBin + "/site_service";
    spec.arguments = {"--site", kSite, "--domain", std::to_string(kDomain), "--memory", memory().string()};
    spec.log_path = (dir_ / ("site_service_" + std::to_string(++starts_) + ".log")).string();
    pid_ = group_.start(spec);
    return pid_;
  }
  [[nodiscard]] std::filesystem::path memory() const { return dir_ / "memory.json"; }
  /// The log of the process's `start`-th start (1 for the first).
  [[nodiscard]] std::string log(int start) const {
    std::ifstream in(dir_ / ("site_service_" + std::to_string(start) + ".log"));
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  void kill_hard() {
    ::kill(pid_, SIGKILL);
    for (int i = 0; i < 200 && !group_.poll(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }

  void report(const ac::CraneReport& r) {
    crane::protocol::SiteReport m;
    ac::to_message(r, m);
    tp::msgs::SiteReport_ out;
    crane::protocol::to_dds(m, out);
    reports_->write(out);
  }
  void report_raw(const crane::protocol::SiteReport& m) {
    tp::msgs::SiteReport_ out;
    crane::protocol::to_dds(m, out);
    reports_->write(out);
  }
  // Takes what arrived for `seconds`, calling `tick` every 100 ms (the cranes' 10 Hz reports).
  template <class Tick>
  void run_for(double seconds, Tick&& tick) {
    const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    auto next_tick = Clock::now();
    while (Clock::now() < until) {
      if (Clock::now() >= next_tick) {
        tick();
        next_tick += std::chrono::milliseconds(100);
      }
      take();
      wakeup_.wait_until(std::min(until, next_tick));
    }
    take();
  }
  // Runs until `done()` or `timeout` [s]; true when done.
  template <class Tick, class Done>
  bool run_until(double timeout, Tick&& tick, Done&& done) {
    const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout));
    while (Clock::now() < until) {
      run_for(0.05, tick);
      if (done()) return true;
    }
    return false;
  }

  const std::vector<crane::protocol::SiteInstruction>& instructions() const { return instructions_seen_; }
  const std::optional<SiteStatus>& status() const { return last_status_; }
  std::size_t statuses() const { return statuses_; }
  double largest_status_gap() const { return largest_gap_; }
  const fs::path& dir() const { return dir_; }

 private:
  void take() {
    tp::msgs::SiteInstruction_ i;
    while (instructions_->take_next(i)) {
      crane::protocol::SiteInstruction m;
      crane::protocol::from_dds(i, m);
      instructions_seen_.push_back(m);
    }
    tp::msgs::SiteStatus_ s;
    while (status_->take_next(s)) {
      SiteStatus m;
      crane::protocol::from_dds(s, m);
      const auto now = Clock::now();
      if (last_status_ && last_status_->epoch == m.epoch) {
        largest_gap_ = std::max(largest_gap_, std::chrono::duration<double>(now - last_arrival_).count());
      }
      last_arrival_ = now;
      last_status_ = m;
      ++statuses_;
    }
  }

  fs::path dir_;
  crane::launch::ProcessGroup group_;
  pid_t pid_{0};
  int starts_{0};
  crane::transport::Wakeup wakeup_;
  std::unique_ptr<crane::transport::Participant> participant_;
  std::unique_ptr<crane::transport::Writer<tp::SiteReport>> reports_;
  std::unique_ptr<crane::transport::Reader<tp::SiteInstruction>> instructions_;
  std::unique_ptr<crane::transport::Reader<tp::SiteStatus>> status_;
  std::vector<crane::protocol::SiteInstruction> instructions_seen_;
  std::optional<SiteStatus> last_status_;
  std::size_t statuses_{0};
  double largest_gap_{0.0};
  Clock::time_point last_arrival_{};
};

// crane_site_status with `arguments` (output and errors into `out`), the cranes reporting meanwhile;
// its exit status.
template <class Tick>
int run_status(SiteProcess& site, Tick&& tick, const std::string& arguments, std::string& out) {
  const std::string path = (site.dir() / "status.txt").string();
  const std::string command = kBin + "/crane_site_status --site '" + kSite + "' " + arguments + " > '" + path + "' 2>&1";
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return -1;
  // The command runs in the background of popen; the cranes keep reporting until it ends.
  std::atomic<bool> done{false};
  int status = -1;
  std::thread waiter([&] {
    status = ::pclose(pipe);
    done = true;
  });
  while (!done) site.run_for(0.1, tick);
  waiter.join();
  std::ifstream in(path);
  out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

ac::CraneReport at_rest(std::size_t crane, const ac::Pose& pose) {
  ac::CraneReport r;
  r.crane = crane;
  r.waypoints = {pose};
  return r;
}

TEST(SiteServiceProcess, GrantsOverDdsHoldsSilentCranesAndStartsAgainKnowingOnlyItsMemory) {
  SiteProcess site;
  // tc1 asks to turn its jib 0.3 rad further from the others, hook up: clear of everything held.
  const std::vector<ac::Pose> leg{kRest[0], {kPi - 0.3, 0.5, 0.2}};
  bool tc3_reports = true;
  ac::CraneReport tc1 = at_rest(0, kRest[0]);
  tc1.request_id = 1;
  tc1.request = leg;
  const auto tick = [&] {
    site.report(tc1);
    site.report(at_rest(1, kRest[1]));
    if (tc3_reports) site.report(at_rest(2, kRest[2]));
  };
  // The grant, over DDS (discovery first: the service holds every crane's whole reach until then).
  ASSERT_TRUE(site.run_until(20.0, tick, [&] { return !site.instructions().empty(); }))
      << "no instruction within 20 s; see " << site.dir();
  const auto go = site.instructions().front();  // a copy: more arrive
  EXPECT_EQ(go.crane, 0);
  EXPECT_EQ(go.kind, crane::protocol::SiteInstruction::KIND_GO);
  EXPECT_EQ(go.request_id, 1u);
  EXPECT_EQ(go.header.seq, 1u);
  ASSERT_EQ(go.waypoint_count, 2);
  EXPECT_DOUBLE_EQ(go.waypoint_slew[1], kPi - 0.3);
  ASSERT_TRUE(site.run_until(5.0, tick, [&] {
    return site.status() && site.status()->holding[0] == SiteStatus::HOLDING_PATH &&
           site.status()->holding[1] == SiteStatus::HOLDING_REST && site.status()->holding[2] == SiteStatus::HOLDING_REST;
  })) << "status: tc1 holding its path, the others their rest boxes; see " << site.dir();
  const std::uint32_t epoch = site.status()->epoch;
  EXPECT_EQ(go.epoch, epoch);
  EXPECT_EQ(site.status()->crane_count, 3);
  // deploy/crane site status (crane_site_status), a participant of its own, prints the same.
  {
    std::string out;
    const int rc = run_status(site, tick, "--domain " + std::to_string(kDomain) + " --wait 1.5", out);
    EXPECT_EQ(rc, 0) << out;
    EXPECT_NE(out.find("site service epoch " + std::to_string(epoch)), std::string::npos) << out;
    EXPECT_NE(out.find("tc1      path         -        -"), std::string::npos) << out;
    EXPECT_NE(out.find("tc2      rest         -        -"), std::string::npos) << out;
    EXPECT_NE(out.find("tc3      rest         -        -"), std::string::npos) << out;
    EXPECT_EQ(run_status(site, tick, "--domain 59 --wait 0.5", out), 1) << out;
    EXPECT_NE(out.find("no site service heard on domain 59 within 0.5 s"), std::string::npos) << out;
  }

  // tc1 carries it out: moving, then at rest at the leg's end.
  tc1.request_id = 0;
  tc1.request.clear();
  tc1.moving = true;
  tc1.waypoints = leg;
  tc1.instruction_epoch = epoch;
  tc1.instruction_seq = go.header.seq;
  site.run_for(0.3, tick);
  const std::size_t sent = site.instructions().size();  // 1, and once more every 0.5 s until carried out
  site.run_for(1.2, tick);
  EXPECT_EQ(site.status()->holding[0], SiteStatus::HOLDING_PATH);
  EXPECT_EQ(site.instructions().size(), sent) << "carried out: not sent again";
  for (const auto& again : site.instructions()) EXPECT_EQ(again.header.seq, go.header.seq) << "sent again as it was";

  // tc3 goes silent: past the link deadline (0.3 s) the service holds its whole reach; it reports
  // again at rest and holds its rest box.
  tc3_reports = false;
  ASSERT_TRUE(site.run_until(5.0, tick, [&] { return site.status()->holding[2] == SiteStatus::HOLDING_WHOLE_REACH; }));
  // The site operator's word (crane_site_status --out-of-service, rt/site/command): refused for
  // tc2, which reports; taken for the silent tc3, which the service then holds where it stood.
  {
    std::string out;
    const std::string domain = "--domain " + std::to_string(kDomain);
    EXPECT_EQ(run_status(site, tick, domain + " --wait 1.5 --out-of-service tc2", out), 3) << out;
    EXPECT_NE(out.find("did not put tc2 out of service within 1.5 s"), std::string::npos) << out;
    EXPECT_EQ(run_status(site, tick, domain + " --wait 1 --out-of-service tc9", out), 2) << out;
    EXPECT_NE(out.find("--out-of-service tc9: no such crane"), std::string::npos) << out;
    EXPECT_EQ(run_status(site, tick, domain + " --wait 10 --out-of-service tc3", out), 0) << out;
    EXPECT_NE(out.find("tc3      out_of_service"), std::string::npos) << out;
    EXPECT_NE(out.find("tc3 is out of service"), std::string::npos) << out;
    ASSERT_TRUE(site.run_until(5.0, tick, [&] {
      return site.status()->holding[2] == SiteStatus::HOLDING_OUT_OF_SERVICE;
    }));
    site.run_for(0.5, tick);  // still silent: held so
    EXPECT_EQ(site.status()->holding[2], SiteStatus::HOLDING_OUT_OF_SERVICE);
    const std::string text = site.log(1);
    EXPECT_NE(text.find("operator: tc2 not put out of service: site service: tc2 was heard"), std::string::npos) << text;
    EXPECT_NE(text.find("operator: tc3 out of service"), std::string::npos) << text;
  }
  tc3_reports = true;
  ASSERT_TRUE(site.run_until(5.0, tick, [&] { return site.status()->holding[2] == SiteStatus::HOLDING_REST; }));

  // A malformed report (a NaN slew; a waypoint count beyond the arrays) is refused and counted;
  // the service goes on.
  crane::protocol::SiteReport bad;
  bad.crane = 1;
  bad.waypoint_count = 1;
  bad.waypoint_slew[0] = std::nan("");
  bad.waypoint_trolley[0] = 0.5;
  bad.waypoint_cable_length[0] = 0.2;
  site.report_raw(bad);
  bad.waypoint_slew[0] = kPi;
  bad.waypoint_count = 200;
  site.report_raw(bad);
  ASSERT_TRUE(site.run_until(5.0, tick, [&] { return site.status()->reports_rejected == 2; }))
      << "both counted; see " << site.dir();
  EXPECT_EQ(site.status()->holding[1], SiteStatus::HOLDING_REST);
  std::printf("[ figure   ] %zu statuses, the largest gap between two %.0f ms (sent at 10 Hz)\n", site.statuses(),
              1e3 * site.largest_status_gap());

  // kill -9 and start again: another epoch; tc1, still reporting moving, is held at its whole
  // reach until it reports at rest. tc3 went silent before the kill: the new service never hears
  // it, but its memory file (--memory) knows where tc3 stood, and takes the operator's word.
  tc3_reports = false;
  site.run_for(0.5, tick);
  site.kill_hard();
  ASSERT_TRUE(std::filesystem::exists(site.memory()));
  site.start();
  ASSERT_TRUE(site.run_until(20.0, tick, [&] { return site.status() && site.status()->epoch != epoch; }))
      << "see " << site.dir();
  site.run_for(0.5, tick);
  EXPECT_EQ(site.status()->holding[0], SiteStatus::HOLDING_WHOLE_REACH);
  EXPECT_EQ(site.status()->holding[1], SiteStatus::HOLDING_REST);
  EXPECT_EQ(site.status()->holding[2], SiteStatus::HOLDING_WHOLE_REACH);  // nothing granted on a memory
  const std::string domain = "--domain " + std::to_string(kDomain);
  {
    std::string out;
    EXPECT_EQ(run_status(site, tick, domain + " --wait 10 --out-of-service tc3", out), 0) << out;
    const std::string text = site.log(2);
    EXPECT_NE(text.find("recalled where the cranes stood from"), std::string::npos) << text;
    EXPECT_NE(text.find("operator: tc3 out of service"), std::string::npos) << text;
  }
  tc1 = at_rest(0, leg.back());
  ASSERT_TRUE(site.run_until(5.0, tick, [&] { return site.status()->holding[0] == SiteStatus::HOLDING_REST; }));

  // A memory file that cannot be read: logged, kept as .bad, the service starts knowing nothing,
  // and the word for tc3 is refused.
  const std::uint32_t second = site.status()->epoch;
  site.kill_hard();
  std::ofstream(site.memory()) << "{\"format\": \"crane site service memory 1\", \"cranes\": [";
  site.start();
  ASSERT_TRUE(site.run_until(20.0, tick, [&] { return site.status() && site.status()->epoch != second; }))
      << "see " << site.dir();
  {
    std::string out;
    EXPECT_EQ(run_status(site, tick, domain + " --wait 1.5 --out-of-service tc3", out), 3) << out;
    const std::string text = site.log(3);
    EXPECT_NE(text.find("memory.json: the file is not JSON"), std::string::npos) << text;
    EXPECT_NE(text.find("not recalled, kept as"), std::string::npos) << text;
    EXPECT_NE(text.find("operator: tc3 not put out of service: site arbiter: crane tc3 went silent where this service "
                        "did not know it stood"),
              std::string::npos)
        << text;
    EXPECT_TRUE(std::filesystem::exists(site.memory().string() + ".bad"));
  }
}

}  // namespace
