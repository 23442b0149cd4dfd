// A crane on a site enforces its grant on its own (issue 34, item 4; docs/site.md, "The crane's own
// guard"): the whole stack as processes, its supervisor started with --site and --site-crane tc1,
// and this test's participant playing the site service on the site's domain (its heartbeat and
// its instructions). Three moves of the trolley, outward along tc1's jib toward tc2 (shared
// airspace):
//   1. with no grant: the supervisor brakes the crane (FAULT_SITE_GRANT: nothing moves by default);
//      its status says that its guard does not hear the service (WARNING_SITE_UNHEARD), cleared
//      once the heartbeat runs;
//   2. with a grant of that path and the heartbeat: the move ends, no site fault;
//   3. granted back, the heartbeat stops early in the move: past the link deadline the supervisor warns
//      (WARNING_SITE), the planner stops softly (REASON_SITE) inside the grant, and no brake.
// ctest runs it in a private network namespace; the participants are bound to loopback.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "crane/anti_collision/site_file.hpp"
#include "crane/anti_collision/site_messages.hpp"
#include "crane/launch/process_group.hpp"
#include "crane/launch/stack.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/testing/scratch_directory.hpp"
#include "crane/transport/participant.hpp"
#include "crane/transport/topics.hpp"

namespace {

namespace fs = std::filesystem;
namespace ac = crane::anti_collision;
namespace tp = crane::transport::topics;
using Status = crane::protocol::SupervisorStatus;
using Clock = std::chrono::steady_clock;

const std::string kBin = CRANE_BIN_DIR;
const std::string kSite = std::string(CRANE_SOURCE_DIR) + "/deploy/config/site_three_towers.yaml";
const std::string kConfig = std::string(CRANE_SOURCE_DIR) + "/deploy/config/lab_tower_crane.yaml";
constexpr std::uint32_t kCraneDomain = 63;

class SiteCrane {
 public:
  SiteCrane()
      : dir_(crane::testing::scratch_directory("site_guard")), layout_(ac::load_site_layout(kSite)) {
    crane::launch::StackOptions options;
    options.config_path = kConfig;
    options.binary_directory = kBin;
    options.log_directory = dir_.string();
    options.domain_id = kCraneDomain;
    options.lockstep = false;
    options.operator_relay = false;
    options.site_file = kSite;
    options.site_crane = "tc1";
    for (const auto& spec : crane::launch::stack_processes(options)) group_.start(spec);

    crane::transport::ParticipantOptions crane_side;
    crane_side.name = "site_guard_test";
    crane_side.domain_id = kCraneDomain;
    crane_ = std::make_unique<crane::transport::Participant>(crane_side);
    status_reader_ = crane_->make_recording_reader<tp::SafetyStatus>(&wakeup_, 4096);
    move_status_reader_ = crane_->make_recording_reader<tp::MoveStatus>(&wakeup_, 4096);
    sensors_reader_ = crane_->make_reader<tp::Sensors>(&wakeup_);
    goal_writer_ = crane_->make_writer<tp::Goal>();
    command_writer_ = crane_->make_writer<tp::SafetyCommand>();
    crane::transport::ParticipantOptions site_side;
    site_side.name = "site_guard_test_service";
    site_side.domain_id = static_cast<std::uint32_t>(layout_.domain_id);
    site_ = std::make_unique<crane::transport::Participant>(site_side);
    instruction_writer_ = site_->make_writer<tp::SiteInstruction>();
    site_status_writer_ = site_->make_writer<tp::SiteStatus>();
    report_writer_ = site_->make_writer<tp::SiteReport>();
  }
  ~SiteCrane() {
    status_reader_.reset();
    move_status_reader_.reset();
    sensors_reader_.reset();
    group_.stop_all();
  }

  // Pumps for `seconds`: the heartbeat at 10 Hz while `heartbeat`, every status taken.
  void run_for(double seconds) {
    const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    while (Clock::now() < until) {
      if (auto exit = group_.poll()) FAIL() << exit->describe() << "; see " << dir_;
      if (heartbeat && Clock::now() >= next_beat_) {
        tp::msgs::SiteStatus_ beat;
        beat.epoch(kEpoch);
        beat.crane_count(3);
        site_status_writer_->write(beat);
        next_beat_ = Clock::now() + std::chrono::milliseconds(100);
      }
      tp::msgs::SupervisorStatus_ s;
      while (status_reader_->take_next(s)) {
        crane::protocol::from_dds(s, status_.emplace());
        warnings_seen_ |= s.warnings();
      }
      tp::msgs::SensorSample_ sample;
      while (sensors_reader_->take_next(sample)) {
        trolley_ = sample.trolley_position();
        sensed_ = true;
        const double t = static_cast<double>(sample.header().stamp().sec()) + 1e-9 * sample.header().stamp().nanosec();
        if (!first_fast_ && last_sample_ && sample.header().seq() == last_sample_->seq + 1 && t > last_sample_->time &&
            (trolley_ - last_sample_->trolley) / (t - last_sample_->time) >= kGuardSpeed) {
          first_fast_ = trolley_;
        }
        last_sample_ = Sample{sample.header().seq(), t, trolley_};
      }
      tp::msgs::MoveStatus_ m;
      while (move_status_reader_->take_next(m)) {
        crane::protocol::from_dds(m, moves_.emplace_back());
      }
      wakeup_.wait_until(std::min(until, Clock::now() + std::chrono::milliseconds(10)));
    }
  }
  bool wait(double timeout, const std::function<bool()>& done) {
    const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout));
    while (Clock::now() < until) {
      run_for(0.05);
      if (done()) return true;
    }
    return false;
  }
  // Ready, and this process has a sensor sample (under load the first one can come after the
  // status: the start position was then read as 0, and a 0.081 m braking figure as 0.331 m).
  bool ready() const {
    return sensed_ && status_ && status_->stages_alive == Status::STAGES_ALL &&
           (status_->mode == Status::MODE_READY || status_->mode == Status::MODE_OPERATING) && status_->brakes_released;
  }
  // The site service's grant to tc1: from (slew 0, `from` m) to (0, `to` m), cable 1 m, through
  // (0, `via` m) when given.
  void grant(double from, double to, std::optional<double> via = std::nullopt) {
    ac::SiteOrder order;
    order.crane = 0;
    order.seq = ++seq_;
    order.request_id = static_cast<std::uint32_t>(seq_);
    order.waypoints = {{0.0, from, 1.0}, {0.0, to, 1.0}};
    if (via) order.waypoints.insert(order.waypoints.begin() + 1, {0.0, *via, 1.0});
    granted_ = order.waypoints;
    crane::protocol::SiteInstruction m;
    ac::to_message(order, kEpoch, m);
    tp::msgs::SiteInstruction_ out;
    crane::protocol::to_dds(m, out);
    instruction_writer_->write(out);
  }
  // tc1's report as its site link sends it, moving on the last grant: the rest of the path from the
  // point of its first segment at `trolley` [m] (grant_guard.hpp, progress within a segment).
  void report_progress_at(double trolley) {
    ac::CraneReport r;
    r.crane = 0;
    r.moving = true;
    r.waypoints.assign(granted_.begin() + 1, granted_.end());
    r.waypoints.insert(r.waypoints.begin(), {0.0, trolley, 1.0});
    r.instruction_epoch = kEpoch;
    r.instruction_seq = seq_;
    crane::protocol::SiteReport m{};
    ac::to_message(r, m);
    tp::msgs::SiteReport_ out;
    crane::protocol::to_dds(m, out);
    report_writer_->write(out);
  }
  void move(double target, double speed = 0.3) {
    tp::msgs::MoveRequest_ goal;
    goal.request_id(++goal_id_);
    goal.profile(crane::protocol::MoveRequest::PROFILE_TRAPEZOID);
    goal.axes(crane::protocol::MoveRequest::AXIS_TROLLEY);
    goal.trolley_target(target);
    goal.cable_length_target(1.0);
    goal.trolley_max_velocity(speed);
    goal.trolley_max_acceleration(0.5);
    goal.slew_max_velocity(1.0);
    goal.slew_max_acceleration(1.0);
    goal_writer_->write(goal);
  }
  void reset() {
    tp::msgs::SupervisorCommand_ c;
    c.request_id(++command_id_);
    c.command(crane::protocol::SupervisorCommand::COMMAND_RESET);
    command_writer_->write(c);
  }

  static constexpr std::uint32_t kEpoch = 4242;
  bool heartbeat{false};
  const std::optional<Status>& status() const { return status_; }
  double trolley() const { return trolley_; }  // [m] the latest sensor sample's
  /// [m/s] the speed at which the guard's emergency stop would carry the trolley past its 2 cm
  /// containment tolerance: 0.27 x 0.03 + 0.27^2 / (2 x 2.97) = 0.02 m ("moving with no grant").
  static constexpr double kGuardSpeed = 0.27;
  /// [m] where the trolley first went kGuardSpeed or faster (two consecutive samples), if it has.
  const std::optional<double>& first_fast() const { return first_fast_; }
  const std::vector<crane::protocol::MoveStatus>& moves() const { return moves_; }
  std::uint32_t warnings_seen() const { return warnings_seen_; }
  void forget_warnings() { warnings_seen_ = 0; }
  const fs::path& dir() const { return dir_; }

 private:
  fs::path dir_;
  ac::SiteLayout layout_;
  crane::launch::ProcessGroup group_;
  crane::transport::Wakeup wakeup_;
  std::unique_ptr<crane::transport::Participant> crane_;
  std::unique_ptr<crane::transport::Participant> site_;
  std::unique_ptr<crane::transport::Reader<tp::SafetyStatus>> status_reader_;
  std::unique_ptr<crane::transport::Reader<tp::MoveStatus>> move_status_reader_;
  std::unique_ptr<crane::transport::Reader<tp::Sensors>> sensors_reader_;
  std::unique_ptr<crane::transport::Writer<tp::Goal>> goal_writer_;
  std::unique_ptr<crane::transport::Writer<tp::SafetyCommand>> command_writer_;
  std::unique_ptr<crane::transport::Writer<tp::SiteInstruction>> instruction_writer_;
  std::unique_ptr<crane::transport::Writer<tp::SiteStatus>> site_status_writer_;
  std::unique_ptr<crane::transport::Writer<tp::SiteReport>> report_writer_;
  std::vector<ac::Pose> granted_;
  std::optional<Status> status_;
  double trolley_{0.0};
  bool sensed_{false};  // a sensor sample was taken
  struct Sample {
    std::uint64_t seq;
    double time;     // [s] its stamp: when its position was measured
    double trolley;  // [m]
  };
  std::optional<Sample> last_sample_;
  std::optional<double> first_fast_;  // [m] where the trolley first went kGuardSpeed or faster
  std::vector<crane::protocol::MoveStatus> moves_;
  std::uint32_t warnings_seen_{0};
  Clock::time_point next_beat_{};
  std::uint64_t seq_{0};
  std::uint32_t goal_id_{10};
  std::uint32_t command_id_{100};
};

TEST(SiteGuardProcess, ACraneOnASiteMovesOnlyWithinItsGrantAndStopsWhenTheServiceIsSilent) {
  SiteCrane crane;
  ASSERT_TRUE(crane.wait(40.0, [&] { return crane.ready(); })) << "stack not ready; see " << crane.dir();
  const double start = crane.trolley();
  // No heartbeat yet: the status says the guard does not hear the site service (a site link would
  // not start: ready_for_site).
  EXPECT_NE(crane.status()->warnings & Status::WARNING_SITE_UNHEARD, 0u);

  // 1. No grant: the first motion brakes the crane.
  crane.move(0.6);
  ASSERT_TRUE(crane.wait(10.0, [&] { return (crane.status()->latched_faults & Status::FAULT_SITE_GRANT) != 0; }))
      << "a move with no grant was not braked; see " << crane.dir();
  EXPECT_FALSE(crane.status()->brakes_released);
  const double braked_at = crane.trolley();
  // "Moving": its emergency stop would travel more than kContainmentTolerance (2 cm): from 0.27 m/s
  // (kGuardSpeed), 0.073 m into the planner's 0.5 m/s^2 ramp. Braked from where the trolley first
  // went that fast: those 2 cm of braking, a cycle at 0.27 m/s (3 mm) for the sample the supervisor
  // acts on and one for this process's own differentiation, 4 mm for the model's decelerations.
  // (Measured from the start, as first written, the bound failed on a starved machine: stalls brake
  // the drives, the planner pauses the goal and starts it again from rest, and the trolley crept
  // 0.17 m before it first went that fast.)
  ASSERT_TRUE(crane.first_fast().has_value()) << "braked before it went 0.27 m/s; see " << crane.dir();
  std::printf("[ figure   ] with no grant the trolley was braked %.3f m from where it started, %.3f m from where it "
              "first went %.2f m/s\n",
              braked_at - start, braked_at - *crane.first_fast(), SiteCrane::kGuardSpeed);
  EXPECT_LT(std::fabs(braked_at - *crane.first_fast()), 0.02 + 0.003 + 0.003 + 0.004)
      << "braked within its 2 cm stop of going 0.27 m/s (a cycle for the supervisor's sample, one for this process's)";

  // 2. Granted from where it stands to 0.6 m, the heartbeat on: the move ends, no site fault.
  crane.heartbeat = true;
  crane.grant(braked_at, 0.6);
  crane.run_for(0.5);
  crane.reset();
  ASSERT_TRUE(crane.wait(10.0, [&] { return crane.ready() && crane.status()->latched_faults == 0; }))
      << "reset; see " << crane.dir();
  ASSERT_TRUE(crane.wait(5.0, [&] { return (crane.status()->warnings & Status::WARNING_SITE_UNHEARD) == 0; }))
      << "the heartbeat on, the guard still does not hear the service; see " << crane.dir();
  crane.move(0.6);
  ASSERT_TRUE(crane.wait(20.0, [&] {
    return crane.status()->mode == Status::MODE_READY && std::fabs(crane.trolley() - 0.6) < 0.02 &&
           std::fabs(crane.status()->trolley_velocity) < 0.01;
  })) << "the granted move did not end at 0.6 m; trolley " << crane.trolley() << " m; see " << crane.dir();
  EXPECT_EQ(crane.status()->latched_faults, 0u);

  // 3. Granted back to where it was braked, at 0.1 m/s; the heartbeat stops 0.5 s into the move.
  // The soft stop then (ZVD on 1 m of cable, T = 2.0 s): 0.1 x 0.03 + 0.1^2 / 1.98 + 0.1 x 1.0 =
  // 0.11 m, well inside the grant (finish_path otherwise: GrantGuard's tests).
  crane.grant(crane.trolley(), braked_at);
  crane.run_for(0.3);
  crane.forget_warnings();
  crane.move(braked_at, 0.1);
  crane.run_for(0.5);
  crane.heartbeat = false;
  ASSERT_TRUE(crane.wait(5.0, [&] { return (crane.warnings_seen() & Status::WARNING_SITE) != 0; }))
      << "no WARNING_SITE after the heartbeat stopped; see " << crane.dir();
  EXPECT_NE(crane.warnings_seen() & Status::WARNING_SITE_UNHEARD, 0u);
  ASSERT_TRUE(crane.wait(10.0, [&] { return std::fabs(crane.status()->trolley_velocity) < 0.005; }));
  crane.run_for(1.0);
  const double rest = crane.trolley();
  std::printf("[ figure   ] the site service silent 0.5 s into a 0.6 -> %.3f m move: the trolley rests at %.3f m\n",
              braked_at, rest);
  EXPECT_GT(rest, braked_at + 0.05) << "stopped before the move's end, inside its grant";
  EXPECT_LT(rest, 0.6 - 0.03) << "it had moved (0.05 m in the 0.5 s before the silence) before the stop";
  EXPECT_EQ(crane.status()->latched_faults & Status::FAULT_SITE_GRANT, 0u) << "a soft stop, not the brakes";
  bool aborted_for_site = false;
  for (const auto& m : crane.moves()) {
    if (m.result == crane::protocol::MoveStatus::RESULT_ABORTED && m.reason == crane::protocol::MoveStatus::REASON_SITE) {
      aborted_for_site = true;
    }
  }
  EXPECT_TRUE(aborted_for_site) << "the planner's soft stop names the site";

  // 4. The crane's progress narrows its guard's grant: granted from where it rests out to 0.75 m,
  // it gets there and its site link reports the rest of the segment from 0.70 m, a point it has
  // passed; a move back to where it started (inside the granted box, outside the narrowed one:
  // 0.70 -> 0.75 m holds [0.66, 0.86] m with the tracking and overshoot allowances) is braked.
  crane.heartbeat = true;
  const double from = crane.trolley();
  crane.grant(from, 0.75);
  ASSERT_TRUE(crane.wait(10.0, [&] { return crane.ready() && crane.status()->mode == Status::MODE_READY; }))
      << "the soft stop did not end; see " << crane.dir();
  crane.move(0.75);
  ASSERT_TRUE(crane.wait(20.0, [&] {
    return std::fabs(crane.trolley() - 0.75) < 0.02 && std::fabs(crane.status()->trolley_velocity) < 0.01;
  })) << "the move to 0.75 m did not end; trolley " << crane.trolley() << " m; see " << crane.dir();
  ASSERT_EQ(crane.status()->latched_faults & Status::FAULT_SITE_GRANT, 0u);
  crane.report_progress_at(0.70);
  crane.run_for(0.3);
  crane.move(from + 0.02, 0.2);
  ASSERT_TRUE(crane.wait(10.0, [&] { return (crane.status()->latched_faults & Status::FAULT_SITE_GRANT) != 0; }))
      << "a move back into the part of its path the crane had left was not braked; trolley " << crane.trolley()
      << " m; see " << crane.dir();
  std::printf("[ figure   ] back into what it had left (0.75 -> %.3f m): braked at %.3f m\n", from + 0.02,
              crane.trolley());
  EXPECT_GT(crane.trolley(), 0.66 - 0.1) << "braked near the narrowed box's edge";
}

}  // namespace
