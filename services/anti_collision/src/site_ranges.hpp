#pragma once
// The range of each number of the site file: one place for the reader (site_file.cpp) and
// validate() (site_layout.cpp).

#include <numbers>

namespace crane::anti_collision::detail {

struct Range {
  double lower, upper;
};
inline constexpr Range kCoordinate{-1.0e4, 1.0e4};
inline constexpr Range kHeading{-std::numbers::pi, std::numbers::pi};
inline constexpr Range kHeight{0.1, 500.0};
inline constexpr Range kLength{0.1, 200.0};
inline constexpr Range kCounterJib{0.0, 200.0};
inline constexpr Range kSection{0.01, 20.0};
inline constexpr Range kTrolley{0.0, 200.0};
inline constexpr Range kSlewTravel{-10.0, 10.0};  // [rad] a slew limited by cables may turn more than once
inline constexpr Range kHook{-100.0, 500.0};
inline constexpr Range kLoadRadius{0.0, 50.0};
inline constexpr Range kReaction{0.0, 5.0};
inline constexpr Range kDeceleration{1.0e-3, 50.0};
inline constexpr Range kBrakeFactor{1.0, 100.0};
inline constexpr Range kDelayPeriods{0.0, 3.0};  // [swing periods] as the supervisor's zone_stop_delay_periods
inline constexpr Range kMargin{1.0e-3, 100.0};
inline constexpr Range kDeadline{1.0e-3, 10.0};
inline constexpr Range kMaxWait{0.0, 3600.0};  // [s] 0: no limit
inline constexpr Range kOvershoot{0.0, 10.0};
inline constexpr Range kTravelStep{0.0, 10.0};  // [rad or m] 0: no waypoints on a travel's way
inline constexpr Range kSwingAllowance{0.0, 1.5};
inline constexpr int kMaxDomain = 232;  // the DDS port mapping's largest domain id
inline constexpr int kMaxPriority = 100;

}  // namespace crane::anti_collision::detail
