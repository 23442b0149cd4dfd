#pragma once
// What an observer of the site's DDS domain knows of the site (issue 34, item 5; docs/site.md,
// "Watching the site"): each crane's last report, the site service's last status, the last
// instruction to each crane, and the distance between every two cranes at their last reports, the
// smallest over the watch too. crane_site_status prints it; crane_web's site page draws it
// (GET /site/view.json). A core with no clock and no DDS: the caller passes the messages and the
// time it heard them.
//
// The distance between two cranes at their reports is crane_geometry.hpp's, between the parts at
// each crane's reported pose and motion (StopKind::none: the load as its measured swing envelope),
// each report paired with the other crane's latest.
//
// Errors: report() and instruction() ignore (return false) a message for a crane index not on the
// site, a report whose measured motion is not finite or whose counts exceed its arrays; nothing
// throws beyond std::bad_alloc.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "crane/anti_collision/airspace.hpp"
#include "crane/anti_collision/crane_geometry.hpp"
#include "crane/anti_collision/site_layout.hpp"
#include "crane/anti_collision/site_service.hpp"
#include "crane/protocol/messages.hpp"

namespace crane::anti_collision {

class SiteWatch {
 public:
  struct Crane {
    std::optional<protocol::SiteReport> report;  // its last report
    std::optional<CraneReport> read;             // that report as the service reads it
    std::uint64_t reports{0};                    // reports heard
    double first_heard{std::numeric_limits<double>::infinity()};  // [s] its first report
    double heard{-std::numeric_limits<double>::infinity()};  // [s] its last report
    std::optional<SiteOrder> order;              // the last instruction to it
    std::uint32_t order_epoch{0};                // of the service that sent it
  };
  struct Pair {
    std::size_t first{0}, second{0};  // first < second, crane indices
    PairDistance distance;
  };

  explicit SiteWatch(SiteLayout layout);

  /// A crane's report heard at `time` [s]; false (ignored) as the header says.
  bool report(const protocol::SiteReport& message, double time);
  /// The service's status heard at `time` [s].
  void status(const protocol::SiteStatus& message, double time);
  /// An instruction of the service; false (ignored) for a crane not on the site or one that cannot
  /// be read (site_messages.hpp).
  bool instruction(const protocol::SiteInstruction& message);

  [[nodiscard]] const SiteLayout& layout() const noexcept { return layout_; }
  [[nodiscard]] const std::vector<Crane>& cranes() const noexcept { return cranes_; }
  [[nodiscard]] const std::optional<protocol::SiteStatus>& last_status() const noexcept { return status_; }
  [[nodiscard]] double status_heard() const noexcept { return status_heard_; }  // [s]
  /// The distance of every two cranes that both reported, at their last reports.
  [[nodiscard]] std::vector<Pair> distances() const;
  /// The smallest distance at any report [m] (+infinity before two cranes reported), between which
  /// parts ("tc1.jib-tc2.cable"), and when [s].
  [[nodiscard]] double closest() const noexcept { return closest_; }
  [[nodiscard]] const std::string& closest_parts() const noexcept { return closest_parts_; }
  [[nodiscard]] double closest_time() const noexcept { return closest_time_; }
  /// At the closest distance, the two reports it paired (the first and the second crane of
  /// closest_parts()), and how long before closest_time() [s] the older of them was heard: the two
  /// poses are of moments about that far apart. Empty before two cranes reported.
  [[nodiscard]] const std::vector<protocol::SiteReport>& closest_reports() const noexcept { return closest_reports_; }
  [[nodiscard]] double closest_apart() const noexcept { return closest_apart_; }

  /// The airspace the service holds for crane `i` as its last report and the service's status say
  /// (HOLDING_REST: its rest pose; PATH or YIELD: the last instruction's path until its report
  /// says it carried it out, then the rest of its reported path; WHOLE_REACH: its whole reach; no
  /// report or no status: none), and the airspace its pending request asks for.
  [[nodiscard]] Airspace held(std::size_t i) const;
  [[nodiscard]] Airspace requested(std::size_t i) const;

 private:
  [[nodiscard]] PairDistance pair_distance(std::size_t i, std::size_t j) const;

  SiteLayout layout_;
  std::vector<Crane> cranes_;
  std::optional<protocol::SiteStatus> status_;
  double status_heard_{-std::numeric_limits<double>::infinity()};
  double closest_{std::numeric_limits<double>::infinity()};
  std::string closest_parts_;
  double closest_time_{0.0};
  std::vector<protocol::SiteReport> closest_reports_;
  double closest_apart_{0.0};
};

/// The plan-view outline of what hangs from the trolley anywhere in `box` of `crane` (site frame
/// [m], counter-clockwise): the annular sector of its slew interval between the trolley interval's
/// ends less and plus the swing and the load's radius, its arcs sampled every 2 deg at most. For
/// views; the rules use airspace_distance.
[[nodiscard]] std::vector<common::Point2> plan_outline(const SiteCrane& crane, const JointBox& box);

}  // namespace crane::anti_collision
