#pragma once
// The site service's protocol (issue 34, item 3; docs/site.md, "The site service on DDS"): what
// the site_service process makes of each crane's reports (rt/site/report) before the site's rules
// (site_arbiter.hpp) decide, and the instructions it sends back (rt/site/instruction). A core with
// no clock, no DDS and no threads: the process and the tests drive it the same way.
//
// A report is a crane's whole state, sent at 10 Hz and on every change, so that a restarted
// service learns everything from the next one:
//   - at rest at a pose, or moving on its grant with the rest of its path from the last waypoint
//     it reached;
//   - the last instruction it carried out (the service's epoch and the instruction's seq);
//   - the leg it asks for, at rest (request_id != 0, a new id a new request).
// What the service does with it, by what it holds for the crane:
//   whole reach (lost, or never heard): at rest -> holds the pose's box (SiteArbiter::rest);
//       moving -> keeps the whole reach until the crane rests (a crane that lost its link stops);
//   rest: at rest -> the pose's box (moved with the crane when it crept more than kRestTolerance
//       on an axis since the box was taken); moving -> the whole reach (moving without a grant);
//   out of service (an operator's word, out_of_service()): at rest -> the pose's box (it is
//       back); moving -> the whole reach (moving without a grant);
//   path or yield: before the crane has carried out that instruction, nothing (it holds the
//       path already); after, moving -> the rest of the path (SiteArbiter::progress, when it
//       has come further along it: another waypoint reached, or a point of the segment under way
//       passed, grant_guard.hpp's narrows()), at rest -> the pose's box (the path is done).
// A request id the service has not seen is a new request (SiteArbiter::request); a report with
// none withdraws the pending one. step() marks every crane heard from for no longer than the
// site's link_deadline as lost (it holds its whole reach, its request is dropped), runs the rules
// when what the service holds or is asked changed since they last ran (SiteArbiter::decide: a
// decision, as its counters count them) and numbers the instructions; an instruction the crane
// has not carried out is sent again every kResendPeriod.
//
// Errors: report() refuses a malformed report (an unknown crane, a waypoint count out of range, a
// non-finite or non-positive cable length, a request of fewer than 2 waypoints, a non-finite
// measured motion, a negative or non-finite work left) with a message
// naming the field and the value, counts it and changes nothing; it never throws. The constructor
// throws common::ConfigError for an invalid layout (validate()).

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "crane/anti_collision/airspace.hpp"
#include "crane/anti_collision/grant_guard.hpp"
#include "crane/anti_collision/site_arbiter.hpp"
#include "crane/anti_collision/site_layout.hpp"

namespace crane::anti_collision {

/// [s] How often a crane reports when nothing changes (its site link: 10 Hz, and on every change).
inline constexpr double kReportPeriod = 0.1;

/// One crane's report, in the core's terms (rt/site/report).
struct CraneReport {
  std::size_t crane{0};                 // index in the site file
  bool moving{false};                   // false: at rest at waypoints[0]
  CraneMotion motion{};                 // measured, at the report (the views; a silent crane's braked swing)
  std::vector<Pose> waypoints;          // 1 to Airspace::kMaxBoxes + 1 (see the header)
  std::uint32_t instruction_epoch{0};   // the last instruction carried out: its service's epoch
  std::uint64_t instruction_seq{0};     // and its seq (0, 0: none)
  std::uint32_t request_id{0};          // 0: no request
  std::vector<Pose> request;            // request_id != 0: 2 to Airspace::kMaxBoxes + 1, from where it rests
  double work_left{0.0};                // [s] >= 0: the time its jobs left take it alone, by its own estimate
                                        // (CraneSiteLink::work_left; SiteArbiter::work_left)
};

/// What a site service remembers of a crane across its own restart (docs/site.md, "The service's
/// memory"): where the crane stood (SiteArbiter::place: at rest, on a path or a yield, or what it
/// held when it went silent), its last reported motion and whether an operator put it out of
/// service. Only a silent crane's place is ever used, by the operator's word (out_of_service()).
struct CraneMemory {
  std::optional<SiteArbiter::Place> place;  // none: the service never knew
  CraneMotion motion{};                     // its last reported motion
  bool out_of_service{false};
};
/// Per crane, in the site file's order (site_memory.hpp reads and writes it as a file).
using SiteMemory = std::vector<CraneMemory>;
/// True when `a` and `b` remember the same, exactly (what site_service compares each cycle before
/// it writes its memory file).
[[nodiscard]] bool same_memory(const SiteMemory& a, const SiteMemory& b) noexcept;

/// One instruction to send (rt/site/instruction).
struct SiteOrder {
  std::size_t crane{0};
  Instruction::Kind kind{Instruction::Kind::go};
  std::uint32_t request_id{0};  // go: the request granted; yield: 0
  std::uint64_t seq{0};         // the service's instruction counter, from 1
  std::vector<Pose> waypoints;
};

class SiteService {
 public:
  static constexpr double kResendPeriod = 0.5;  // [s] an instruction not yet carried out is sent again
  static constexpr double kRestTolerance = 0.005;  // [m], [rad] a crane at rest that crept further gets a new box

  /// The service of `layout` in `mode`; `epoch` identifies this run (drawn at the process's start,
  /// != 0). Throws common::ConfigError for an invalid layout, std::invalid_argument for epoch 0.
  SiteService(SiteLayout layout, ArbiterMode mode, std::uint32_t epoch);

  /// Applies `report`, heard at `time` [s] (see the header). Returns "" when applied, else why it
  /// was refused ("site service: crane 7 is not on the site (3 cranes)").
  [[nodiscard]] std::string report(const CraneReport& report, double time);
  /// At `time` [s]: the silent cranes lost, the rules, the instructions to send (new ones and those
  /// to send again).
  [[nodiscard]] std::vector<SiteOrder> step(double time);
  /// An operator's word at `time` [s] (rt/site/command, COMMAND_OUT_OF_SERVICE): crane `crane`,
  /// silent, stands braked where it was when it went silent; the service holds that, with the
  /// swing of its load braked from its last report's motion (SiteArbiter::out_of_service, the
  /// report up to kReportPeriod old), instead of its whole reach, until the crane reports at rest.
  /// Returns "" when applied (or already so), else why not: an unknown crane, a crane heard within
  /// link_deadline ("tc2 was heard 0.12 s ago: a crane that reports is not out of service"), or
  /// one whose place this service does not know (it restarted since with no memory of it, recall();
  /// or the crane moved without a grant). Never throws.
  [[nodiscard]] std::string out_of_service(std::size_t crane, double time);

  /// What this service would need to remember across a restart (CraneMemory). The site_service
  /// process writes it whenever it changes, before the instructions of the same step leave, so that
  /// every grant a crane may be carrying out is in it.
  [[nodiscard]] SiteMemory memory() const;
  /// A restarted service, before it hears any report, recalls what the one before it remembered
  /// (`memory`, one entry per crane). Each crane still holds its whole reach, and nothing is granted
  /// on a memory; a silent crane's remembered place is what an operator's word then holds
  /// (out_of_service()): its rest box with its load's swing braked from the remembered motion; a
  /// path or yield as it was held (the crane may have been moving at any speed its grant allows
  /// when it stopped, after the memory's motion); a crane out of service in the memory is out of
  /// service again at once. A crane heard moving whose remembered place is a rest box forgets it (a
  /// move without a grant). Returns "" when recalled, else why not, recalling nothing: a memory of
  /// another number of cranes, a crane heard already, a place SiteArbiter::recall refuses (the crane
  /// and the box named). Never throws beyond std::bad_alloc.
  [[nodiscard]] std::string recall(const SiteMemory& memory);

  [[nodiscard]] const SiteArbiter& arbiter() const noexcept { return arbiter_; }
  [[nodiscard]] std::uint32_t epoch() const noexcept { return epoch_; }
  [[nodiscard]] std::uint64_t reports_rejected() const noexcept { return rejected_; }
  /// Reports that showed a crane moving while the service held only its rest box.
  [[nodiscard]] std::uint64_t moves_without_grant() const noexcept { return moves_without_grant_; }
  /// True when crane `crane` was heard within link_deadline of `time`. std::out_of_range for a
  /// crane index not on the site.
  [[nodiscard]] bool heard(std::size_t crane, double time) const;

 private:
  struct Link {
    double last_heard{-std::numeric_limits<double>::infinity()};
    std::uint32_t pending_id{0};   // the request the arbiter holds
    std::uint32_t granted_id{0};   // the last request granted
    bool carried_out{true};        // the crane has carried out its last instruction
    SiteOrder last_order;          // its last instruction (seq 0: none)
    double last_sent{0.0};
    Pose rest_pose{};                // where its rest box was taken
    std::vector<Pose> progressed;    // the rest of its path at its last progress taken (empty: none yet)
    CraneMotion motion{};            // measured, at its last report
    bool motion_trusted{true};       // false: recalled on a path (the memory's motion may be older than its stop)
  };

  SiteArbiter arbiter_;
  std::uint32_t epoch_;
  std::vector<Link> links_;
  std::uint64_t seq_{0};
  std::uint64_t rejected_{0};
  std::uint64_t moves_without_grant_{0};
  bool dirty_{true};  // what the service holds or is asked changed since the rules last ran
};

}  // namespace crane::anti_collision
