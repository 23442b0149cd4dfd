#pragma once
// A site of several cranes in lockstep, in one thread (issue 34, item 6; docs/site.md): one
// in-process stack per crane (in_process_stack.hpp: the same stage objects as each crane's
// processes, its own plant), each crane's side of the site protocol (anti_collision::CraneSiteLink,
// the core the site_link process runs) and the site service's (anti_collision::SiteService, the
// core the site_service process runs), stepped cycle by cycle. The messages the processes send
// over DDS pass here every cycle: each crane's report to the service, the service's instructions,
// its heartbeat. Each crane works through a queue of pick-and-place jobs (crane_site_link.hpp: the
// legs, the requests, the moves waypoint by waypoint, settling and dwelling).
//
// The true distance between any two cranes is measured every cycle from the plants' states
// (crane_geometry.hpp's capsules of jib, counter-jib and mast, the cable from the sheave to the
// swinging load, the load's sphere): the figure "no contact, ever" is about.
//
// Beside it runs the rule of the industrial systems, which watch distances only: every
// kWatchStride cycles, each pair's soft- and emergency-stop envelopes from the estimators' states
// (crane_geometry.hpp's envelope and classify). Its actions are counted, not applied: each time a
// pair enters slow_down, stop or emergency_stop. On a run whose true distance never comes below
// margins.stop, every one of them is a stop the grants made needless.
//
// A lost link (SiteRunOptions::faults): the crane's reports, the instructions to it and the
// heartbeat are dropped, and so are those on their way; a killed site service hears and sends
// nothing and restarts (another epoch) knowing only what its memory file said (SiteService::memory
// at the kill, recall: where each crane stood, for the operator's word), and what was on its way
// to or from it is lost. A degraded link delivers them late, in order (LinkFault). A stopped host (HostStop) takes its
// crane's stack and link away for good; its plant runs on, braked by its actuation gate. What the crane and the service
// then do is their cores' (crane_site_link.hpp, site_service.hpp). The guard's rules 1-3 brake a crane that leaves its grant (it then stays
// braked and stops reporting, so the service holds its whole reach); its swing rule is counted,
// not applied (SiteOutcome::guard_*).
//
// Errors: common::ConfigError for an invalid site or stack config; std::invalid_argument for jobs
// outside a crane's reach, a job list not one per crane, or a fault or host stop out of range.

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "crane/anti_collision/crane_site_link.hpp"
#include "crane/anti_collision/schedule_bound.hpp"
#include "crane/anti_collision/site_arbiter.hpp"
#include "crane/plant/plant_stage.hpp"
#include "crane/stack/stack_config.hpp"

namespace crane::stack {

/// A place a crane lifts from or sets down at, and a pick-and-place job (crane_site_link.hpp).
using WorkPoint = anti_collision::WorkPoint;
using SiteJob = anti_collision::SiteJob;

enum class SiteMode : std::uint8_t {
  coordinated,  // the site service's rules (SiteArbiter, coordinated)
  serialized,   // the baseline: one crane at a time in shared airspace
  solo,         // each crane alone on the site (no other crane): the reference for throughput
};
[[nodiscard]] const char* to_string(SiteMode mode) noexcept;

/// A fault between the cranes and the site service, from `start` for `duration` [s]. With `delay`
/// and `loss` both 0: crane `crane`'s link lost (both ways), or, with crane == kSiteService, the
/// site service killed and restarted with only its memory file (every link down meanwhile; the new
/// service holds every crane's whole reach until it reports). Otherwise the link is degraded, the crane's
/// (every crane's with kSiteService: the service's host): each message sent on it either way
/// arrives `delay` late, and with probability `loss` one kResendDelay later still (the site's
/// topics are reliable: a lost sample is sent again), in the order sent.
struct LinkFault {
  std::size_t crane{0};
  double start{0.0};     // [s]
  double duration{1.0};  // [s]
  double delay{0.0};     // [s] >= 0
  double loss{0.0};      // [-] in [0, 1]
  [[nodiscard]] bool degraded() const noexcept { return delay > 0.0 || loss > 0.0; }
};
/// [s] What a lost message on a degraded link costs: one round of the reliable protocol, taken as
/// Cyclone DDS's default heartbeat interval (100 ms). An assumption of the model, not measured.
inline constexpr double kResendDelay = 0.1;
inline constexpr std::size_t kSiteService = static_cast<std::size_t>(-1);

/// A crane's host stopped for good at `time` [s], as by a power cut (the hosts' `stop-host`): every
/// process of its stack and its site link gone. Nothing reaches its drives any more, so the plant's
/// actuation gate brakes it once its last command is older than the watchdog (actuation_gate.hpp:
/// 30 ms on the lab crane; on a real crane, the drives' own watchdog or the spring-applied brakes of
/// the power cut, taken to act as fast); it reports nothing, so the site service holds its whole
/// reach once link_deadline has passed, for good.
/// With `out_of_service_after`, the site operator, having seen the crane braked, puts it out of
/// service that long after the stop (SiteService::out_of_service, as `crane_site_status
/// --out-of-service` over DDS): the service then holds where it stood instead of its whole reach.
/// [s] How long the operator's word is given, each cycle, before it counts as refused (the service
/// down, or one that never knew the crane's place).
inline constexpr double kWordWindow = 1.0;
struct HostStop {
  std::size_t crane{0};
  double time{0.0};  // [s] >= 0
  double out_of_service_after{std::numeric_limits<double>::infinity()};  // [s] > 0 (infinity: never)
};
/// [s] How long a crane waits at rest for a stopped crane's reach (or for cranes that wait for it)
/// before its run counts as over: the hosts' rule (`deploy/crane site run`, docs/site.md).
inline constexpr double kStuckWait = 15.0;

/// Cycles between two evaluations of the distance-watching rule (20 Hz at the stack's 100 Hz).
inline constexpr int kWatchStride = 5;

struct SiteRunOptions {
  SiteMode mode{SiteMode::coordinated};
  double dwell{1.0};            // [s] at the pick and at the place
  double settle_timeout{8.0};   // [s] after the reference arrived
  double time_limit{1800.0};    // [s] simulated; the run stops there (SiteOutcome::completed false)
  // [rad/s^2] of every move, half the lab crane's rated 2.08: at the travel height (0.2 m of cable)
  // the default controller slewing at the rated acceleration swings past the supervisor's
  // max_swing (0.6 rad) in 8 of 40 seeded job sets (docs/site.md).
  double slew_acceleration{1.0};
  std::vector<LinkFault> faults;
  std::vector<HostStop> host_stops;
  std::uint64_t loss_seed{1};  // draws which messages a degraded link loses
  // Every crane's simulated plant off its configuration, as crane_sim's --mismatch: the cable length,
  // load mass and friction factors (plant::PlantMismatch; the stacks still assume the configuration).
  plant::PlantMismatch plant_mismatch{};
  // A crane that disobeys: at `time` [s] crane `crane` is told to move to `to` without asking the
  // site service (a test of its guard, grant_guard.hpp).
  struct Rogue {
    std::size_t crane{0};
    double time{0.0};
    anti_collision::Pose to;
  };
  std::optional<Rogue> rogue;
};

struct CraneOutcome {
  std::string name;
  int jobs_done{0};
  double finish_time{0.0};   // [s] its last job done
  double waiting_time{0.0};  // [s] between asking for a leg and its grant
  int yields{0};             // yields it obeyed
  int unsettled_moves{0};    // moves ended by settle_timeout
  std::uint32_t latched_faults{0};  // its supervisor's, at the end (FAULT_* bits)
  double braked_at{std::numeric_limits<double>::quiet_NaN()};  // [s] when its guard braked it (NaN: never)
  double host_stopped_at{std::numeric_limits<double>::quiet_NaN()};  // [s] its host stopped (NaN: never)
  // [s] From its host's stop to its plant at rest (trolley and slew under 0.01 m/s and rad/s, the
  // hoist under 0.01 m/s; NaN: not at rest by the run's end, or no stop).
  double rest_after_host_stop{std::numeric_limits<double>::quiet_NaN()};
  // [s] When the site service put it out of service on the operator's word (NaN: never; the word
  // is given each cycle for kWordWindow until the service takes it).
  double out_of_service_at{std::numeric_limits<double>::quiet_NaN()};
  // Why the service did not take the word, its last answer ("": taken, never given, or given
  // only while the service was down).
  std::string out_of_service_refused;
  bool stuck{false};  // it ended waiting, for kStuckWait, for a stopped crane (or for one that waits for it)
  // Its work interval by interval until its last job was done (schedule_bound.hpp): each change of
  // what it held, as its own reports say (moving, dwelling too: the segment from the point it has
  // passed to the waypoint ahead; at rest: the box where it stands). In a solo run, the input of
  // the bound of any order of grants (two_crane_bound).
  anti_collision::Timeline timeline;
};

struct SiteOutcome {
  std::vector<CraneOutcome> cranes;
  // Where the waits go [s]: crane-seconds the cranes spent asking for a leg, by what the cranes
  // the site service had them wait for were doing (SiteArbiter::waits_for at its last decision;
  // index: CraneSiteLink::Activity; a crane that waits for k cranes counts 1/k to each), and
  // asking while it waited for no crane (`waited_for_none`: its request or the go on their way,
  // or the service down), and for a crane whose host had stopped (`waited_for_stopped_host`). On a
  // fault-free run they add up to the cranes' waiting_time; a lost link that cuts an ask short
  // counts here and not there.
  std::array<double, anti_collision::CraneSiteLink::kActivityCount> waited_for{};
  double waited_for_none{0.0};
  double waited_for_stopped_host{0.0};
  // The same crane-seconds asking (a stopped host's too), by why the service's last decision had the
  // crane wait (SiteArbiter::wait_reason; index: WaitReason; none: it waited for no crane, or the
  // service was down). On a fault-free run they add up to the cranes' waiting_time too.
  std::array<double, anti_collision::kWaitReasonCount> waited_why{};
  // Every job done within the time limit (no crane braked by its guard), but those a stopped host
  // left undone: its crane's, and those of the cranes stuck waiting for its reach.
  bool completed{false};
  int stopped_hosts{0};      // cranes whose host stopped (SiteRunOptions::host_stops)
  double total_time{0.0};    // [s] the last crane's finish time
  double min_distance{0.0};  // [m] true, between any two parts of any two cranes, over the run
  std::string closest;       // "tc1.jib-tc3.cable at 41.23 s"
  std::uint64_t unresolved{0};  // arbiter decisions that found a blocked crane no yield could free
  // The distance-watching rule's actions (see the header), each pair's entries into them.
  int watch_slow_downs{0};
  int watch_stops{0};
  int watch_emergency_stops{0};
  double simulated_seconds{0.0};  // [s] crane-seconds stepped (all cranes)
  // For each link loss that lasted link_deadline: from the loss to the crane safe [s], its drives
  // at rest (trolley, slew and hoist under 0.01 m/s, rad/s) after its soft stop (its path was in
  // shared airspace), or still on a path outside it.
  std::vector<double> reactions;
  // The longest of them: "tc2: link lost at 41.23 s, safe 6.49 s later, at rest at its move's
  // waypoint (...)" (empty: no loss), and its length [s].
  std::string longest_reaction;
  double longest_reaction_seconds{0.0};
  int halts{0};  // stops for a lost link: a soft stop, or the move under way ended at its waypoint
  int halts_at_waypoint{0};  // of them, those whose soft stop would have run out of the grant
  int halts_per_axis{0};     // of them, stops of some axes, the others gone on to the waypoint
  // Messages (reports, instructions, heartbeats) sent on a degraded link, and those of them lost
  // once and sent again (LinkFault::loss).
  std::uint64_t delayed_messages{0};
  std::uint64_t resent_messages{0};
  // Each crane's guard on its grant (grant_guard.hpp): the cranes it braked (leaving their grant:
  // applied, the crane stays braked), the cycles on which it would have asked for a soft stop for
  // a swing wider than the grant (counted, not applied), and its first verdict ("tc1 at 12.3 s:
  // leaving its grant"; empty: none).
  int guard_emergency_stops{0};
  int guard_soft_stops{0};
  std::string guard_first;
};

/// The stack config every crane of the simulated site runs: the one the site file's cranes name
/// (SiteCrane::config), loaded with load_stack_config. Throws common::ConfigError when the cranes
/// name different configs ("site.cranes[1].config = ... differs from site.cranes[0].config = ...:
/// the simulated site runs one crane config") or it does not load.
[[nodiscard]] StackConfig load_site_crane_config(const anti_collision::SiteLayout& site);

/// Runs `jobs` (one list per crane of `site`, in its order) on `site`, every crane with `config`
/// (its stack, load_site_crane_config; the site file gives where it stands and its shape). With a
/// host stopped, the run ends once every other crane has done its jobs or is stuck (kStuckWait),
/// every link fault is over and every operator's word has been given (kWordWindow). Solo runs (SiteMode::solo) keep each crane's own faults and host
/// stops and those of the site service. Throws std::invalid_argument for a fault or a host stop
/// out of range (naming it), besides the errors above.
[[nodiscard]] SiteOutcome run_site(const anti_collision::SiteLayout& site, const StackConfig& config,
                                   const std::vector<std::vector<SiteJob>>& jobs, const SiteRunOptions& options);

/// `count` seeded random faults for `site`: a crane's link lost for 0.5-30 s (probability 0.6) or
/// the site service killed and restarted after 0.5-10 s, each starting within the first 80 s.
[[nodiscard]] std::vector<LinkFault> random_link_faults(const anti_collision::SiteLayout& site, int count,
                                                        std::uint64_t seed);

/// When a message sent at `time` [s] arrives over a link degraded by `fault` (nullptr, or a fault
/// that is not degraded: at once): `delay` later, one kResendDelay more when it was `lost`, and
/// never before `previous`, the arrival of the message sent before it the same way (-infinity:
/// none). The one place of the degraded link's rule (LinkFault).
[[nodiscard]] double arrival_time(double time, const LinkFault* fault, bool lost, double previous) noexcept;

/// `count` seeded random degraded links for `site`, the network faults of issue 34 that leave a
/// link up: a crane's link (probability 0.75) or the site service's host (every link) degraded for
/// 5-30 s, each starting in the first 80 s, with a delay of 0-200 ms each way and 0-30 % of the
/// messages lost (LinkFault).
[[nodiscard]] std::vector<LinkFault> random_degraded_links(const anti_collision::SiteLayout& site, int count,
                                                           std::uint64_t seed);

/// `count` seeded random host stops for `site` (issue 34's "a crane's host stopped"): a crane drawn
/// uniformly, its host stopped for good within the first 80 s. Deterministic in `seed`.
[[nodiscard]] std::vector<HostStop> random_host_stops(const anti_collision::SiteLayout& site, int count,
                                                      std::uint64_t seed);

/// How random_site_jobs places a point with respect to the other cranes. A point is "within another
/// crane's reach" when its distance from that crane's slew axis lies strictly between the planner's
/// trolley_min_position + 0.1 and trolley_max_position - 0.05 [m]; "clear of the other cranes" when
/// it lies further from every other crane's slew axis than that crane's jib or counter-jib, whichever
/// is longer, plus the site's margins.slow_down [m]: no other jib passes over it.
struct SiteJobDraw {
  double shared_probability{0.7};  // [-] in [0, 1]: a point is drawn within another crane's reach
  bool others_clear{false};        // the other points: false, anywhere in the crane's reach (in another's
                                   // too, by chance); true, clear of the other cranes
};

/// `per_crane` seeded random jobs for each crane of `site`: pick and place points within the
/// planner's reach of `config`, at random work heights in the lowest 0.8 m of the crane's hook
/// range; by default a point lies within another crane's reach too with probability 0.7, and
/// anywhere otherwise (jobs that force conflicts). Where 1000 draws find no point as `draw` asks,
/// the last one is taken. Deterministic in `seed`; the default draw is the one every figure of
/// docs/site.md was measured on. Throws std::invalid_argument for a shared_probability outside
/// [0, 1] or NaN.
[[nodiscard]] std::vector<std::vector<SiteJob>> random_site_jobs(const anti_collision::SiteLayout& site,
                                                                 const StackConfig& config, int per_crane,
                                                                 std::uint64_t seed, const SiteJobDraw& draw = {});

}  // namespace crane::stack
