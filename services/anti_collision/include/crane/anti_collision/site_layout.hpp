#pragma once
// A construction site of several cranes (issue 34): where each crane stands, the shape of its
// structure, its drives' stopping data, its DDS domain, its priority, and the site's fixed zones.
// One YAML file (deploy/config/site_*.yaml), read by site_file.hpp strictly like the crane configs;
// validate() is the one place of the site's structural rules. Errors are common::ConfigError
// naming the field, the value and the bound, e.g.
//   "site.cranes[2] (tc3).jib_length = 0 is out of range: must be in [0.1, 200]"
//
// Site frame: origin anywhere on the ground, x east, y north, z up [m]. A crane's slew angle
// (its own encoder's, crane frame of common/site.hpp) points its jib at the site heading
// `slew_zero_heading + slew` [rad], counter-clockwise from +x.
//
// The structure is the usual tower-crane outline (EN 14439, the industrial anti-collision
// systems' "jib box"): a square mast from the ground to the jib; the jib from the slew axis to its
// tip and the counter-jib from the axis backwards, both of cross-section width x depth, their
// lower chord at `jib_height` (where the trolley runs and the hoist cable leaves it); the hook
// between `hook_height_min` and `hook_height_max`; the trolley between `trolley_min` and
// `trolley_max` from the axis. Apex, cat-head and pendants are not modelled (say so in a site
// survey where they stand above the jib).

#include <cstddef>
#include <string>
#include <vector>

#include "crane/common/crane_parameters.hpp"
#include "crane/common/site.hpp"

namespace crane::anti_collision {

/// What a crane's drives do when told to stop; the envelope of its stopping motion (crane_geometry.hpp).
struct StoppingData {
  double reaction_time{0.1};          // [s] from the decision to the drives acting (one cycle and the link)
  double trolley_deceleration{0.5};   // [m/s^2] a soft (controlled) stop of the trolley
  double slew_deceleration{0.5};      // [rad/s^2] a soft stop of the slew
  double hoist_deceleration{0.5};     // [m/s^2] a soft stop of the hoist
  double brake_deceleration_factor{3.0};  // emergency stop (brakes) decelerates this many times faster, >= 1
  double soft_stop_delay_periods{0.5};  // [swing periods] the mean delay sum A_i t_i of the shaper of the
                                        // soft stop, in [0, 3]: it travels v T times this further (zvd 0.5,
                                        // zv 0.25) and leaves no residual swing (Singer & Seering 1990); 0:
                                        // unshaped. The site file takes it from the crane's own config
                                        // (trajectory_planner.manual.shaping), never from the site's.
};

/// One crane of the site.
struct SiteCrane {
  std::string name;                   // unique on the site ("tc1")
  common::CraneKind kind{common::CraneKind::tower};  // tower only in this version
  common::Point2 base{0.0, 0.0};      // [m] slew axis at the ground, site frame
  double slew_zero_heading{0.0};      // [rad] site heading of the jib at slew angle 0, in [-pi, pi]
  double jib_height{2.0};             // [m] lower chord of the jib above the ground (the trolley's rails)
  double jib_length{1.0};             // [m] slew axis to jib tip, > trolley_max
  double counter_jib_length{0.3};     // [m] slew axis to counter-jib tail
  double jib_width{0.1};              // [m] width of the jib's and counter-jib's cross-section
  double jib_depth{0.1};              // [m] depth (height) of that cross-section
  double mast_width{0.1};             // [m] side of the square mast
  double trolley_min{0.1};            // [m] trolley travel from the slew axis, trolley_min < trolley_max
  double trolley_max{0.9};            // [m]
  double slew_min{-3.0};              // [rad] the slew's travel (its planner's range), slew_min < slew_max
  double slew_max{3.0};               // [rad]
  double hook_height_min{0.0};        // [m] lowest the load's centre goes above the ground
  double hook_height_max{1.5};        // [m] highest, below jib_height
  double load_radius{0.1};            // [m] radius of a sphere enclosing the load and the hook block
  StoppingData stopping;
  std::string config;                 // the crane's stack config (deploy/config/*.yaml): the path the site
                                      // file names, relative to the site file's directory, resolved
  int domain_id{0};                   // the crane's own DDS domain, unique on the site, in [0, 232]
  int priority{0};                    // higher wins a conflict (0: none); see the site rules
};

/// Distances every rule of the site keeps between any two parts of two cranes [m]; 0 < stop <
/// slow_down < warning.
struct Margins {
  double warning{1.0};    // operators are warned
  double slow_down{0.5};  // the crane slows to its creep speed
  double stop{0.2};       // the crane stops (a soft stop whose envelope keeps this margin)
};

/// What a granted path of a crane may deviate from its plan (airspace.hpp): the tracking
/// controller's overshoot of a goal and the load's swing, bounded by the crane's own supervisor.
struct PathAllowance {
  double trolley_overshoot{0.07};  // [m] past a trolley goal (the delayed-feedback law's, measured)
  double slew_overshoot{0.05};     // [rad] past a slew goal
  double travel_swing{0.6};        // [rad] swing while the trolley or the slew moves (the supervisor's max_swing)
  // [m] the load's swing, as a radius at the hook, while neither the trolley nor the slew moves (the
  // residual of the travel, which the anti-swing law damps as the hoist moves: measured, docs/site.md,
  // "The swing while hoisting"). A radius, not an angle: it does not grow with the cable.
  double hoist_swing_radius{0.025};
  // How far the drives' tracking strays from the plan, on either side of every box in which the
  // slew or the trolley travels: the trolley pulled outward while the jib slews, a stop from the
  // slew's speed (measured: docs/site.md, "The crane's own guard").
  double trolley_tracking{0.0};    // [m]
  double slew_tracking{0.0};       // [rad]
  // The same on either side of a box in which neither travels (only the hoist moves, or the crane
  // rests): how far from the plan the travel before left the trolley and the slew, settled, and
  // how far they creep while the hoist moves (measured: docs/site.md, "Holding an axis").
  double trolley_hold{0.0};        // [m]
  double slew_hold{0.0};           // [rad]
};

struct SiteLayout {
  std::string name;                   // the site's name (messages, the HMI)
  std::vector<SiteCrane> cranes;      // 1 to kMaxCranes
  std::vector<common::Zone> zones;    // fixed zones in the site frame (buildings, roads, neighbours' plots)
  Margins margins;
  int domain_id{10};                  // the site's own DDS domain (the site service and every crane's site
                                      // link: rt/site/*), in [0, 232], unlike every crane's
  double link_deadline{0.3};          // [s] a crane hears nothing from the site service this long: it stops
                                      // moving into shared airspace (the supervisor's rule)
  double max_wait{0.0};               // [s] a request that has waited this long goes before every later one
                                      // (the site service's rule 0, site_arbiter.hpp); 0: no limit
  bool part_of_leg{false};            // a leg may be granted up to a waypoint where it waits for the cranes
                                      // in its way (site_arbiter.hpp, "A part of a leg")
  bool most_work_left_first{false};   // the request of the crane with the most work left goes first (the site
                                      // service's rule 0, site_arbiter.hpp; each crane reports its estimate)
  double travel_step{0.0};            // [rad or m] each crane asks for a leg's travel with waypoints on its way,
                                      // this far apart at most on the axis that travels further (as many as a
                                      // request holds): a part of a leg may end there (CraneSiteLink); 0: none
  PathAllowance paths;

  static constexpr std::size_t kMaxCranes = 20;
};

/// Checks every field and the site's structure. Throws common::ConfigError naming the field, the
/// value and the bound when: a number is out of its range (site_layout.cpp's ranges, which the file
/// reader uses too); a name
/// or a domain id is repeated; a crane's trolley range leaves its jib, its hook range reaches its
/// jib; the margins are not 0 < stop < slow_down < warning; a zone is malformed (common::validate);
/// two masts stand within each other's margins; or a crane's jib can reach another crane's mast
/// and does not pass above that crane's highest part by the stop margin (the lower crane's jib
/// would hit the higher crane's mast; EN 14439's vertical clearance between cranes).
void validate(const SiteLayout& layout, const std::string& prefix = "site");

/// The index of the crane called `name`, or -1.
[[nodiscard]] int find_crane(const SiteLayout& layout, const std::string& name) noexcept;

}  // namespace crane::anti_collision
