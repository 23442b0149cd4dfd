// A crane's side of the site protocol (crane_site_link.hpp), driven by hand: the request of a leg
// computed by hand from where the crane rests, the go taken once and only for its request, the
// moves waypoint by waypoint as the reference arrives and the crane settles, the dwell at the work
// height, the job counted, the yield, a goal sent again until the planner answers, a move the
// planner ends short sent again and at last given up, the lost link
// (a soft stop in shared airspace, a stop of the axes whose stop stays in the grant while the others
// run on to the waypoint, the move ended at its waypoint when no stop would stay in the grant, the
// path finished outside it), the brakes, and bad jobs and job files refused.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "crane/anti_collision/crane_site_link.hpp"
#include "crane/anti_collision/site_arbiter.hpp"
#include "crane/anti_collision/site_file.hpp"
#include "crane/common/validation.hpp"

namespace {

namespace fs = std::filesystem;
using namespace crane::anti_collision;
using crane::protocol::CraneState;
using crane::protocol::MoveRequest;
using crane::protocol::MoveStatus;
using crane::protocol::Reference;

const std::string kSite = std::string(CRANE_SOURCE_DIR) + "/deploy/config/site_three_towers.yaml";
constexpr std::uint32_t kFirstGoal = 500;
constexpr std::uint32_t kEpoch = 77;

// tc1 (base (0, 0), slew 0 along +x toward tc2 at (2, 0)) resting at slew 0, trolley 0.3 m, cable
// 0.2 m (hook up), with one job: pick at (slew 0, trolley 0.9 m, cable 1.5 m) in shared airspace,
// place at (slew -1.5, 0.5 m, 1.2 m).
class Link : public ::testing::Test {
 protected:
  Link() : layout_(load_site_layout(kSite)) {
    layout_.travel_step = 0.0;  // a leg's waypoints counted below: none on its way (but in ATravelIsAsked...)
    params_.travel_cable_length = 0.2;
    params_.dwell = 1.0;
    params_.settle_timeout = 8.0;
    SiteJob job;
    job.pick = {0.0, 0.9, 1.5};
    job.place = {-1.5, 0.5, 1.2};
    link_.emplace(layout_, 0, params_, std::vector<SiteJob>{job}, kFirstGoal);
    at({0.0, 0.3, 0.2});
  }
  // The estimate at rest at `p`, settled.
  void at(const Pose& p) {
    estimate_ = CraneState{};
    estimate_.slew_angle = p.slew;
    estimate_.trolley_position = p.trolley;
    estimate_.cable_length = p.cable_length;
  }
  std::optional<MoveRequest> step() {
    link_->heard(t_);
    auto g = link_->step(t_, estimate_, reference_, false);
    t_ += 0.01;
    return g;
  }
  // The planner's feedback on goal `id`.
  void answer(std::uint32_t id, std::uint8_t result = MoveStatus::RESULT_MOVING,
              std::uint8_t reason = MoveStatus::REASON_NONE) {
    MoveStatus s{};
    s.request_id = id;
    s.result = result;
    s.reason = reason;
    link_->move_status(s, t_);
  }
  // The planner answers `goal`, runs it and arrives; the crane rests at its target, settled.
  void arrive(const MoveRequest& goal) {
    answer(goal.request_id, MoveStatus::RESULT_ARRIVED);
    reference_.request_id = goal.request_id;
    reference_.phase = Reference::PHASE_ARRIVED;
    at({goal.slew_target, goal.trolley_target, goal.cable_length_target});
  }
  SiteOrder go(std::uint64_t seq) {
    const auto r = link_->report();
    SiteOrder o;
    o.crane = 0;
    o.kind = Instruction::Kind::go;
    o.request_id = r->request_id;
    o.seq = seq;
    o.waypoints = stops_of(r->request);  // as the site service sends a whole leg
    return o;
  }
  // The service tells crane 0 to yield through `waypoints`.
  static SiteOrder yield(std::uint64_t seq, std::vector<Pose> waypoints) {
    SiteOrder o;
    o.crane = 0;
    o.kind = Instruction::Kind::yield;
    o.seq = seq;
    o.waypoints = std::move(waypoints);
    return o;
  }
  // Asks, is granted, and its first move is under way at `here` with `velocity` [m/s] along the jib.
  void moving_at(const Pose& here, double velocity) {
    (void)step();
    ASSERT_TRUE(link_->instruction(go(1), kEpoch, t_));
    const auto g = step();
    ASSERT_TRUE(g.has_value());
    answer(g->request_id);
    reference_.request_id = g->request_id;
    reference_.phase = Reference::PHASE_MOVING;
    // The reference where the crane is, the trolley's moving at the same speed.
    reference_.slew_angle = here.slew;
    reference_.trolley_position = here.trolley;
    reference_.trolley_velocity = velocity;
    reference_.cable_length = here.cable_length;
    at(here);
    estimate_.trolley_velocity = velocity;
  }
  // Steps with nothing heard for `cycles` cycles; the last goal sent, if any.
  std::optional<MoveRequest> silent(int cycles, bool until_goal) {
    std::optional<MoveRequest> last;
    for (int k = 0; k < cycles && !(until_goal && last); ++k) {
      if (auto g = link_->step(t_, estimate_, reference_, false)) last = g;
      t_ += 0.01;
    }
    return last;
  }
  // Asking for the place's leg (hook up at the pick), it is granted the whole leg by go `seq` and
  // moves it: travel, lower (then the dwell), raise, each arriving and settled.
  void place_leg_granted(std::uint64_t seq) {
    ASSERT_TRUE(link_->instruction(go(seq), kEpoch, t_));
    for (int move = 0; move < 3; ++move) {
      const auto g = next_goal(2.0);
      ASSERT_TRUE(g.has_value()) << "move " << move;
      arrive(*g);
    }
  }
  // Steps until a goal comes (at most `seconds`).
  std::optional<MoveRequest> next_goal(double seconds = 0.5) {
    for (double until = t_ + seconds; t_ < until;) {
      if (auto g = step()) return g;
    }
    return std::nullopt;
  }

  SiteLayout layout_;
  CraneLinkParams params_;
  std::optional<CraneSiteLink> link_;
  CraneState estimate_{};
  Reference reference_{};
  double t_{0.0};
};

void expect_pose(const Pose& p, double slew, double trolley, double cable) {
  EXPECT_DOUBLE_EQ(p.slew, slew);
  EXPECT_DOUBLE_EQ(p.trolley, trolley);
  EXPECT_DOUBLE_EQ(p.cable_length, cable);
}

TEST_F(Link, AsksForItsLegAndMovesOnlyOnTheGoForIt) {
  EXPECT_FALSE(link_->report().has_value()) << "no report before the first step";
  EXPECT_FALSE(step().has_value());
  ASSERT_EQ(link_->phase(), CraneSiteLink::Phase::asking);
  auto r = link_->report();
  ASSERT_TRUE(r.has_value());
  EXPECT_FALSE(r->moving);
  ASSERT_EQ(r->waypoints.size(), 1u);
  expect_pose(r->waypoints[0], 0.0, 0.3, 0.2);
  // Hook up already: travel at 0.2 m of cable, lower to the pick's 1.5 m, hoist up again.
  ASSERT_NE(r->request_id, 0u);
  ASSERT_EQ(r->request.size(), 4u);
  expect_pose(r->request[0], 0.0, 0.3, 0.2);
  expect_pose(r->request[1], 0.0, 0.9, 0.2);
  expect_pose(r->request[2], 0.0, 0.9, 1.5);
  expect_pose(r->request[3], 0.0, 0.9, 0.2);
  EXPECT_EQ(r->instruction_seq, 0u);

  // A go for another request, and a yield-less go to another crane: ignored, nothing moves.
  SiteOrder wrong = go(1);
  wrong.request_id += 1;
  EXPECT_FALSE(link_->instruction(wrong, kEpoch, t_));
  SiteOrder other = go(1);
  other.crane = 1;
  EXPECT_FALSE(link_->instruction(other, kEpoch, t_));
  EXPECT_FALSE(step().has_value());

  const SiteOrder order = go(2);
  EXPECT_TRUE(link_->instruction(order, kEpoch, t_));
  EXPECT_FALSE(link_->instruction(order, kEpoch, t_)) << "the same instruction sent again is not taken twice";
  const auto g = step();
  ASSERT_TRUE(g.has_value());
  EXPECT_EQ(g->request_id, kFirstGoal + 1);
  EXPECT_EQ(g->command, MoveRequest::COMMAND_MOVE);
  EXPECT_EQ(g->axes, MoveRequest::AXIS_SLEW | MoveRequest::AXIS_TROLLEY | MoveRequest::AXIS_HOIST);
  EXPECT_DOUBLE_EQ(g->trolley_target, 0.9);
  EXPECT_DOUBLE_EQ(g->cable_length_target, 0.2);
  r = link_->report();
  EXPECT_TRUE(r->moving);
  EXPECT_EQ(r->instruction_epoch, kEpoch);
  EXPECT_EQ(r->instruction_seq, 2u);
  EXPECT_EQ(r->request_id, 0u) << "moving, it asks for nothing";
  EXPECT_EQ(r->waypoints.size(), 4u) << "the whole path ahead until it reaches waypoint 1";
}

// Within a segment the crane reports, every kProgressStep of its travel, the point it has passed,
// and its guard holds the same: the segment from there, with the tracking allowance behind it.
// Backwards, it reports nothing new; within the last step, nothing; at the waypoint, the rest.
TEST_F(Link, ReportsThePointOfTheSegmentItHasPassed) {
  moving_at({0.0, 0.3, 0.2}, 0.3);  // the first segment: the trolley 0.3 -> 0.9 m, hook up
  EXPECT_EQ(link_->report()->waypoints.size(), 4u);
  at({0.0, 0.37, 0.2});  // 0.07 m on: not a step yet
  (void)step();
  expect_pose(link_->report()->waypoints[0], 0.0, 0.3, 0.2);
  (void)link_->report_changed();
  at({0.0, 0.55, 0.2});  // 0.25 m on: two steps passed
  (void)step();
  EXPECT_TRUE(link_->report_changed()) << "sent at once, not only at the report period";
  auto r = link_->report();
  ASSERT_EQ(r->waypoints.size(), 4u);
  EXPECT_NEAR(r->waypoints[0].trolley, 0.5, 1e-12);
  expect_pose(r->waypoints[1], 0.0, 0.9, 0.2);
  const double tracking = layout_.paths.trolley_tracking;
  const JointBox& box = link_->guard().granted().boxes[0];
  EXPECT_NEAR(box.trolley_low, 0.5 - tracking, 1e-12) << "the guard holds the same, the allowance behind";
  EXPECT_EQ(link_->guard().granted().count, 3u);
  at({0.0, 0.45, 0.2});  // pulled back: nothing new
  (void)step();
  EXPECT_NEAR(link_->report()->waypoints[0].trolley, 0.5, 1e-12);
  at({0.0, 0.89, 0.2});  // within the last step: the report stays a step short of the waypoint
  (void)step();
  EXPECT_NEAR(link_->report()->waypoints[0].trolley, 0.8, 1e-12);
  // Arrived and settled: the next move, and the rest of the path from the waypoint.
  reference_.phase = Reference::PHASE_ARRIVED;
  at({0.0, 0.9, 0.2});
  const auto g = next_goal();
  ASSERT_TRUE(g.has_value());
  EXPECT_DOUBLE_EQ(g->cable_length_target, 1.5);
  r = link_->report();
  ASSERT_EQ(r->waypoints.size(), 3u);
  expect_pose(r->waypoints[0], 0.0, 0.9, 0.2);
}

TEST_F(Link, MovesWaypointByWaypointDwellsAndCountsTheJob) {
  (void)step();
  ASSERT_TRUE(link_->instruction(go(1), kEpoch, t_));
  auto g = step();
  ASSERT_TRUE(g.has_value());
  // Arrived but swinging 1 deg: no next move until it settles.
  arrive(*g);
  estimate_.swing_in_plane = 0.0175;
  EXPECT_FALSE(next_goal(1.0).has_value());
  estimate_.swing_in_plane = 0.0;
  g = next_goal();
  ASSERT_TRUE(g.has_value());
  EXPECT_DOUBLE_EQ(g->cable_length_target, 1.5);
  EXPECT_EQ(link_->report()->waypoints.size(), 3u) << "it reached waypoint 1: the rest of the path from there";
  // At the work height: the dwell (1 s), then up.
  arrive(*g);
  const double reached = t_;
  g = next_goal(2.0);
  ASSERT_TRUE(g.has_value());
  EXPECT_NEAR(t_ - reached, 1.0, 0.02);
  EXPECT_DOUBLE_EQ(g->cable_length_target, 0.2);
  arrive(*g);
  EXPECT_FALSE(next_goal(0.05).has_value());
  EXPECT_EQ(link_->jobs_done(), 0) << "the pick is the job's first leg";
  ASSERT_EQ(link_->phase(), CraneSiteLink::Phase::asking);
  const auto r = link_->report();
  ASSERT_EQ(r->request.size(), 4u);
  expect_pose(r->request[1], -1.5, 0.5, 0.2);
  expect_pose(r->request[2], -1.5, 0.5, 1.2);
  // The place: the job is done when its last move settles.
  place_leg_granted(5);
  (void)step();
  EXPECT_EQ(link_->jobs_done(), 1);
  (void)step();
  EXPECT_EQ(link_->phase(), CraneSiteLink::Phase::done) << "at rest with no leg left, the next cycle";
  EXPECT_EQ(link_->report()->request_id, 0u);
  EXPECT_EQ(link_->unsettled_moves(), 0);
}

// Its work left (CraneSiteLink::work_left, moves_time) by hand, with the default rates: the trolley
// 0.4982 m/s and 0.9929 m/s^2, the slew 1.0435 rad/s (rated) and 1.0 rad/s^2, the hoist 0.2 m/s and
// 0.5 m/s^2; a travel one swing period on 0.2 m of cable longer, every move 1 s of settling more, 1 s
// of dwell at each work point. The pick's leg from (0, 0.3 m, 0.2 m): the trolley's 0.6 m, lower
// and raise 1.3 m; the place's leg from the pick hook up: the slew's 1.5 rad (the trolley's 0.4 m
// takes less), lower and raise 1.0 m.
TEST_F(Link, ItsWorkLeftByHand) {
  // (3.43): Z / v + v / a past v^2 / a, else 2 sqrt(Z / a).
  const auto trapezoid = [](double z, double v, double a) { return z >= v * v / a ? z / v + v / a : 2.0 * std::sqrt(z / a); };
  const double swing_period = 2.0 * std::numbers::pi * std::sqrt(0.2 / 9.81);
  const double travel_to_pick = trapezoid(0.6, 0.4982, 0.9929) + swing_period + 1.0;
  const double hoist_at_pick = trapezoid(1.3, 0.2, 0.5) + 1.0;
  const double travel_to_place = trapezoid(1.5, 1.0435, 1.0) + swing_period + 1.0;
  ASSERT_GT(travel_to_place - swing_period - 1.0, trapezoid(0.4, 0.4982, 0.9929));
  const double hoist_at_place = trapezoid(1.0, 0.2, 0.5) + 1.0;
  const double place_leg = travel_to_place + 2.0 * hoist_at_place + 1.0;
  const double whole = travel_to_pick + 2.0 * hoist_at_pick + 1.0 + place_leg;
  EXPECT_NEAR(whole, 38.58, 0.01);  // 1.706 + 0.897 + 1 + 2 (6.9 + 1) + 1 + 2.481 + 0.897 + 1 + 2 (5.4 + 1) + 1

  (void)step();
  EXPECT_NEAR(link_->work_left(), whole, 1e-9);
  EXPECT_NEAR(link_->report()->work_left, whole, 1e-9) << "its report carries it";
  ASSERT_TRUE(link_->instruction(go(1), kEpoch, t_));
  auto g = step();
  ASSERT_TRUE(g.has_value());
  EXPECT_NEAR(link_->work_left(), whole, 1e-9) << "the travel started: the same path ahead";
  arrive(*g);
  g = next_goal();
  ASSERT_TRUE(g.has_value());
  arrive(*g);
  (void)step();
  ASSERT_EQ(link_->phase(), CraneSiteLink::Phase::dwelling);
  EXPECT_NEAR(link_->work_left(), hoist_at_pick + place_leg, 1e-9) << "at the pick: raise, then the place's leg";
  g = next_goal(2.0);
  ASSERT_TRUE(g.has_value());
  arrive(*g);
  EXPECT_FALSE(next_goal(0.05).has_value());
  ASSERT_EQ(link_->phase(), CraneSiteLink::Phase::asking);
  EXPECT_NEAR(link_->work_left(), place_leg, 1e-9);
  place_leg_granted(5);
  (void)step();
  (void)step();
  ASSERT_EQ(link_->phase(), CraneSiteLink::Phase::done);
  EXPECT_EQ(link_->work_left(), 0.0);

  // A NaN estimate at rest (a crane whose estimator fails, asking from where it stands): no throw
  // in the cycle, and the estimate it had is kept.
  CraneSiteLink fresh(layout_, 0, params_, {SiteJob{{0.0, 0.9, 1.5}, {-1.5, 0.5, 1.2}}}, kFirstGoal);
  CraneState nan_estimate{};
  nan_estimate.slew_angle = std::nan("");
  fresh.heard(0.0);
  EXPECT_NO_THROW((void)fresh.step(0.0, nan_estimate, Reference{}, false));
  EXPECT_EQ(fresh.work_left(), 0.0);
  EXPECT_EQ(fresh.report()->work_left, 0.0);

  EXPECT_EQ(moves_time(std::vector<Pose>{{0.0, 0.3, 0.2}}, params_), 0.0);
  EXPECT_THROW((void)moves_time(std::vector<Pose>{{0.0, 0.3, 0.2}, {std::nan(""), 0.3, 0.2}}, params_),
               std::invalid_argument);
  CraneLinkParams slow = params_;
  slow.rated.hoist.rated_speed = 0.0;
  EXPECT_THROW((void)moves_time(std::vector<Pose>{{0.0, 0.3, 0.2}}, slow), std::invalid_argument);
  EXPECT_THROW(CraneSiteLink(layout_, 0, slow, {}, kFirstGoal), std::invalid_argument);
}

// A part of a leg (site_arbiter.hpp): a go for the first waypoints of its leg only. The
// crane moves to the last of them and asks there, with a new request, for the rest of the leg from
// that waypoint (not from its measured pose: a hair of slew would make the hoist's segment a
// travel's). A go for the old request is not taken; the dwell at the work height comes once,
// whether the part granted ends before it or at it.
TEST_F(Link, AGoForTheFirstWaypointsOfItsLegMovesThereAndAsksForTheRest) {
  (void)step();
  SiteOrder part = go(1);
  const std::uint32_t first_request = part.request_id;
  part.waypoints.resize(2);  // the travel to above the pick only
  ASSERT_TRUE(link_->instruction(part, kEpoch, t_));
  auto g = step();
  ASSERT_TRUE(g.has_value());
  EXPECT_DOUBLE_EQ(g->trolley_target, 0.9);
  EXPECT_DOUBLE_EQ(g->cable_length_target, 0.2);
  arrive(*g);
  estimate_.slew_angle = 0.004;  // it rests a hair off the waypoint
  EXPECT_FALSE(next_goal(0.5).has_value()) << "no move past the part granted";
  ASSERT_EQ(link_->phase(), CraneSiteLink::Phase::asking);
  auto r = link_->report();
  EXPECT_FALSE(r->moving);
  expect_pose(r->waypoints[0], 0.004, 0.9, 0.2);
  EXPECT_NE(r->request_id, first_request) << "a new request";
  ASSERT_EQ(r->request.size(), 3u);
  expect_pose(r->request[0], 0.0, 0.9, 0.2);
  expect_pose(r->request[1], 0.0, 0.9, 1.5);
  expect_pose(r->request[2], 0.0, 0.9, 0.2);
  SiteOrder old = go(2);
  old.request_id = first_request;
  EXPECT_FALSE(link_->instruction(old, kEpoch, t_)) << "a go for the request it was granted part of";
  // The rest: lower, dwell 1 s, hoist up; then it asks for the place, the job not yet done.
  ASSERT_TRUE(link_->instruction(go(3), kEpoch, t_));
  g = next_goal();
  ASSERT_TRUE(g.has_value());
  EXPECT_DOUBLE_EQ(g->cable_length_target, 1.5);
  arrive(*g);
  const double lowered = t_;
  g = next_goal(2.0);
  ASSERT_TRUE(g.has_value());
  EXPECT_NEAR(t_ - lowered, 1.0, 0.02) << "the dwell at the work height";
  EXPECT_DOUBLE_EQ(g->cable_length_target, 0.2);
  arrive(*g);
  EXPECT_FALSE(next_goal(0.05).has_value());
  ASSERT_EQ(link_->phase(), CraneSiteLink::Phase::asking);
  r = link_->report();
  ASSERT_EQ(r->request.size(), 4u) << "the place's whole leg";
  expect_pose(r->request[2], -1.5, 0.5, 1.2);
  EXPECT_EQ(link_->jobs_done(), 0);

  // The place granted up to its work height: the dwell there, then it asks for the hoist up, and
  // the go for it starts the hoist at once (no second dwell); the job is done when it settles.
  part = go(4);
  part.waypoints.resize(3);
  ASSERT_TRUE(link_->instruction(part, kEpoch, t_));
  g = next_goal();
  ASSERT_TRUE(g.has_value());
  arrive(*g);
  g = next_goal();
  ASSERT_TRUE(g.has_value());
  EXPECT_DOUBLE_EQ(g->cable_length_target, 1.2);
  arrive(*g);
  const double placed = t_;
  EXPECT_FALSE(next_goal(0.9).has_value()) << "dwelling";
  for (int k = 0; k < 20 && link_->phase() != CraneSiteLink::Phase::asking; ++k) (void)step();
  ASSERT_EQ(link_->phase(), CraneSiteLink::Phase::asking);
  EXPECT_NEAR(t_ - placed, 1.0, 0.05);
  r = link_->report();
  ASSERT_EQ(r->request.size(), 2u);
  expect_pose(r->request[1], -1.5, 0.5, 0.2);
  ASSERT_TRUE(link_->instruction(go(5), kEpoch, t_));
  g = step();
  ASSERT_TRUE(g.has_value()) << "the hoist up at once";
  EXPECT_DOUBLE_EQ(g->cable_length_target, 0.2);
  arrive(*g);
  (void)step();
  EXPECT_EQ(link_->jobs_done(), 1);
}

// Waypoints on the travel's way (the site file's travel_step): the request lists them, a go names
// the stops of the part granted (stops_of), and the crane moves to its last stop in one move,
// whether that ends on the travel's way or the whole leg was granted. A go that names waypoints on
// the way as stops is not the service's: refused.
TEST_F(Link, ATravelIsAskedWithWaypointsOnItsWayAndGrantedUpToOneOfThem) {
  layout_.travel_step = 0.25;
  SiteJob job;
  job.pick = {0.0, 0.9, 1.5};
  job.place = {-1.5, 0.5, 1.2};
  link_.emplace(layout_, 0, params_, std::vector<SiteJob>{job}, kFirstGoal);
  (void)step();
  auto r = link_->report();
  // 0.6 m of trolley in three pieces of 0.2 m.
  ASSERT_EQ(r->request.size(), 6u);
  expect_pose(r->request[1], 0.0, 0.5, 0.2);
  expect_pose(r->request[2], 0.0, 0.7, 0.2);
  expect_pose(r->request[3], 0.0, 0.9, 0.2);
  SiteOrder raw = go(1);
  raw.waypoints = r->request;
  EXPECT_FALSE(link_->instruction(raw, kEpoch, t_)) << "waypoints on the way are not stops";
  SiteOrder part = go(2);
  part.waypoints = stops_of(std::span(r->request).first(3));
  ASSERT_EQ(part.waypoints.size(), 2u);
  ASSERT_TRUE(link_->instruction(part, kEpoch, t_));
  auto g = step();
  ASSERT_TRUE(g.has_value());
  EXPECT_DOUBLE_EQ(g->trolley_target, 0.7) << "one move to the waypoint granted";
  arrive(*g);
  EXPECT_FALSE(next_goal(0.5).has_value());
  ASSERT_EQ(link_->phase(), CraneSiteLink::Phase::asking);
  r = link_->report();
  ASSERT_EQ(r->request.size(), 4u) << "the rest of the leg, from where it waits";
  expect_pose(r->request[0], 0.0, 0.7, 0.2);
  expect_pose(r->request[1], 0.0, 0.9, 0.2);
  SiteOrder rest = go(3);
  rest.waypoints = stops_of(r->request);
  ASSERT_TRUE(link_->instruction(rest, kEpoch, t_));
  g = next_goal();
  ASSERT_TRUE(g.has_value());
  EXPECT_DOUBLE_EQ(g->trolley_target, 0.9);
  arrive(*g);
  g = next_goal();
  ASSERT_TRUE(g.has_value());
  EXPECT_DOUBLE_EQ(g->cable_length_target, 1.5) << "lowering: the leg's work height";
  arrive(*g);
  g = next_goal(2.0);
  ASSERT_TRUE(g.has_value());
  arrive(*g);
  EXPECT_FALSE(next_goal(0.05).has_value());
  // The place: 1.5 rad of slew, at most 0.25 apart, but a request holds MAX_WAYPOINTS: six pieces.
  r = link_->report();
  ASSERT_EQ(r->request.size(), Airspace::kMaxBoxes + 1);
  for (std::size_t k = 1; k < 6; ++k) {
    expect_pose(r->request[k], -0.25 * static_cast<double>(k), 0.9 - 0.4 * static_cast<double>(k) / 6.0, 0.2);
  }
  SiteOrder whole = go(4);
  whole.waypoints = stops_of(r->request);
  ASSERT_EQ(whole.waypoints.size(), 4u);
  ASSERT_TRUE(link_->instruction(whole, kEpoch, t_));
  g = next_goal();
  ASSERT_TRUE(g.has_value());
  EXPECT_DOUBLE_EQ(g->slew_target, -1.5) << "granted whole: one move to the travel's end";
  EXPECT_DOUBLE_EQ(g->trolley_target, 0.5);
}

// What the crane is doing, as the site's waits are counted by it: the segment under way (the one
// about to start once it has settled at a waypoint), the dwell, a yield (a lost-link stop:
// ALostLinkInSharedAirspaceStopsSoftlyThenTheCraneAsksAgain).
TEST_F(Link, SaysWhatItIsDoingSegmentBySegment) {
  using A = CraneSiteLink::Activity;
  (void)step();
  EXPECT_EQ(link_->activity(), A::at_rest) << "asking";
  ASSERT_TRUE(link_->instruction(go(1), kEpoch, t_));
  EXPECT_EQ(link_->activity(), A::travelling) << "the go taken: out along the jib, hook up";
  auto g = step();
  ASSERT_TRUE(g.has_value());
  arrive(*g);
  estimate_.swing_in_plane = 0.0175;
  (void)step();
  EXPECT_EQ(link_->activity(), A::travelling) << "arrived, still swinging: the travel's settling";
  estimate_.swing_in_plane = 0.0;
  g = next_goal();
  ASSERT_TRUE(g.has_value());
  EXPECT_EQ(link_->activity(), A::lowering);
  arrive(*g);
  (void)step();
  EXPECT_EQ(link_->activity(), A::dwelling);
  g = next_goal(2.0);
  ASSERT_TRUE(g.has_value());
  EXPECT_EQ(link_->activity(), A::raising);
  arrive(*g);
  (void)next_goal(0.05);
  EXPECT_EQ(link_->activity(), A::at_rest) << "asking for the place";
  ASSERT_TRUE(link_->instruction(yield(9, {{0.0, 0.9, 0.2}, {-0.5, 0.9, 0.2}}), kEpoch, t_));
  EXPECT_EQ(link_->activity(), A::yielding);
  EXPECT_STREQ(to_string(A::yielding), "yielding");
  EXPECT_STREQ(to_string(A::at_rest), "at rest");
}

TEST_F(Link, ASwingThatDoesNotSettleEndsTheMoveAtTheSettleTimeout) {
  (void)step();
  ASSERT_TRUE(link_->instruction(go(1), kEpoch, t_));
  auto g = step();
  arrive(*g);
  estimate_.swing_in_plane = 0.05;
  const double arrived = t_;
  g = next_goal(10.0);
  ASSERT_TRUE(g.has_value());
  EXPECT_NEAR(t_ - arrived, params_.settle_timeout, 0.02);
  EXPECT_EQ(link_->unsettled_moves(), 1);
}

TEST_F(Link, AGoalIsSentAgainUntilThePlannerAnswers) {
  (void)step();
  ASSERT_TRUE(link_->instruction(go(1), kEpoch, t_));
  const auto first = step();
  ASSERT_TRUE(first.has_value());
  const double sent = t_ - 0.01;
  const auto again = next_goal(1.5);
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(again->request_id, first->request_id);
  EXPECT_NEAR(t_ - 0.01 - sent, kGoalResendPeriod, 0.011);
  answer(first->request_id);
  EXPECT_FALSE(next_goal(2.0).has_value());
}

TEST_F(Link, AMoveThePlannerEndsShortIsSentAgainOnceTheCraneRestsAndAtLastGivenUp) {
  // Its supervisor's soft stop (a swing or a limit approached) ends the first move, 0.3 m short.
  moving_at({0.0, 0.6, 0.2}, 0.1);
  const std::uint32_t first = kFirstGoal + 1;
  answer(first - 1, MoveStatus::RESULT_ABORTED);
  EXPECT_EQ(link_->aborted_moves(), 0) << "feedback on an older goal is not about this move";
  answer(first, MoveStatus::RESULT_ABORTED);
  EXPECT_EQ(link_->aborted_moves(), 1);
  const double ended = t_;
  // Still stopping: nothing is sent.
  reference_.request_id = 0;
  EXPECT_FALSE(next_goal(2.0).has_value());
  // At rest and settled: the same move again (a new id), a resend period after the abort at the
  // earliest.
  reference_.phase = Reference::PHASE_HOLDING;
  at({0.0, 0.62, 0.2});
  auto again = next_goal(2.0);
  ASSERT_TRUE(again.has_value()) << "a move ended short must not leave the link waiting for good";
  EXPECT_GT(again->request_id, first);
  EXPECT_EQ(again->command, MoveRequest::COMMAND_MOVE);
  EXPECT_DOUBLE_EQ(again->trolley_target, 0.9);
  EXPECT_DOUBLE_EQ(again->cable_length_target, 0.2);
  EXPECT_GE(t_ - 0.01 - ended, 2.0 - 1e-9);
  EXPECT_EQ(link_->phase(), CraneSiteLink::Phase::moving);
  EXPECT_TRUE(link_->report()->moving) << "it still holds its path";
  // Braked under way (a stalled chain), as often as it may be: sent again each time, and no attempt.
  for (int braked = 0; braked < 2 * kMoveAttempts; ++braked) {
    answer(again->request_id, MoveStatus::RESULT_ABORTED, MoveStatus::REASON_BRAKED);
    again = next_goal(2.0);
    ASSERT_TRUE(again.has_value()) << "a crane that only stalls is never given up on";
    EXPECT_EQ(link_->phase(), CraneSiteLink::Phase::moving);
  }
  // Refused (the mode changed) and then aborted again: the third time it gives up.
  answer(again->request_id, MoveStatus::RESULT_REJECTED);
  const double refused = t_;
  again = next_goal(2.0);
  ASSERT_TRUE(again.has_value());
  EXPECT_NEAR(t_ - 0.01 - refused, kGoalResendPeriod, 0.011);
  answer(again->request_id, MoveStatus::RESULT_ABORTED);
  EXPECT_FALSE(next_goal(3.0).has_value());
  EXPECT_EQ(link_->aborted_moves(), kMoveAttempts + 2 * kMoveAttempts);
  ASSERT_EQ(link_->phase(), CraneSiteLink::Phase::aborted);
  const auto r = link_->report();
  EXPECT_FALSE(r->moving) << "at rest where it stopped: the service frees the rest of its path";
  ASSERT_EQ(r->waypoints.size(), 1u);
  expect_pose(r->waypoints[0], 0.0, 0.62, 0.2);
  EXPECT_EQ(r->request_id, 0u) << "it asks for nothing more";
  EXPECT_EQ(link_->jobs_done(), 0);
  // It still obeys a yield, and rests again where that ends.
  ASSERT_TRUE(link_->instruction(yield(9, {{0.0, 0.62, 0.2}, {-0.5, 0.62, 0.2}}), kEpoch, t_));
  const auto g = next_goal();
  ASSERT_TRUE(g.has_value());
  arrive(*g);
  (void)next_goal(0.05);
  EXPECT_EQ(link_->phase(), CraneSiteLink::Phase::aborted);
  EXPECT_EQ(link_->report()->request_id, 0u);
}

TEST_F(Link, AYieldIsObeyedAtRestAndTheLegAskedAgainWithANewRequest) {
  (void)step();
  const std::uint32_t asked = link_->report()->request_id;
  ASSERT_TRUE(link_->instruction(yield(3, {{0.0, 0.3, 0.2}, {-0.5, 0.3, 0.2}}), kEpoch, t_));
  EXPECT_EQ(link_->yields(), 1);
  EXPECT_EQ(link_->report()->request_id, 0u) << "yielding withdraws its request";
  auto g = step();
  ASSERT_TRUE(g.has_value());
  EXPECT_DOUBLE_EQ(g->slew_target, -0.5);
  arrive(*g);
  (void)next_goal(0.05);
  ASSERT_EQ(link_->phase(), CraneSiteLink::Phase::asking);
  const auto r = link_->report();
  EXPECT_NE(r->request_id, asked);
  expect_pose(r->request[0], -0.5, 0.3, 0.2);
  EXPECT_EQ(link_->jobs_done(), 0);
}

TEST_F(Link, ALostLinkInSharedAirspaceStopsSoftlyThenTheCraneAsksAgain) {
  // Half way out along the jib, slowly: nothing heard from now on.
  moving_at({0.0, 0.6, 0.2}, 0.1);
  const double last_heard = t_ - 0.01;
  const auto stop = silent(100, true);
  ASSERT_TRUE(stop.has_value());
  EXPECT_EQ(stop->command, MoveRequest::COMMAND_STOP);
  EXPECT_EQ(stop->axes, MoveRequest::AXIS_TROLLEY | MoveRequest::AXIS_SLEW | MoveRequest::AXIS_HOIST);
  EXPECT_EQ(link_->halts_per_axis(), 0);
  EXPECT_NEAR(t_ - 0.01 - last_heard, layout_.link_deadline, 0.011);
  EXPECT_EQ(link_->phase(), CraneSiteLink::Phase::halting);
  EXPECT_EQ(link_->activity(), CraneSiteLink::Activity::stopping);
  EXPECT_EQ(link_->halts(), 1);
  // The stop ends: at rest, it waits for the link.
  reference_.phase = Reference::PHASE_ARRIVED;
  at({0.0, 0.62, 0.2});
  (void)link_->step(t_, estimate_, reference_, false);
  t_ += 0.01;
  EXPECT_EQ(link_->phase(), CraneSiteLink::Phase::halted);
  EXPECT_EQ(link_->activity(), CraneSiteLink::Activity::at_rest);
  ASSERT_EQ(link_->reactions().size(), 1u);
  EXPECT_NEAR(link_->reactions()[0], t_ - 0.01 - last_heard, 0.011);
  ASSERT_TRUE(link_->longest_reaction().has_value());
  EXPECT_EQ(link_->longest_reaction()->seconds, link_->reactions()[0]);
  EXPECT_NEAR(link_->longest_reaction()->lost_at, last_heard, 0.011);
  EXPECT_EQ(link_->longest_reaction()->end, CraneSiteLink::ReactionEnd::soft_stop);
  // Heard again: it reports where it rests and asks again for the leg.
  (void)step();
  ASSERT_EQ(link_->phase(), CraneSiteLink::Phase::asking);
  expect_pose(link_->report()->request[0], 0.0, 0.62, 0.2);
}

TEST_F(Link, ALostLinkEndsTheMoveAtItsWaypointWhenASoftStopWouldLeaveTheGrant) {
  // 1 cm before its goal at 0.5 m/s: a soft stop runs far past the box's end.
  moving_at({0.0, 0.89, 0.2}, 0.5);
  EXPECT_FALSE(silent(100, false).has_value()) << "no soft stop, no next move";
  EXPECT_EQ(link_->halts_at_waypoint(), 1);
  EXPECT_EQ(link_->phase(), CraneSiteLink::Phase::halting);
  EXPECT_FALSE(link_->longest_reaction().has_value()) << "not safe yet";
  // At rest at the waypoint: safe, and the reaction says how.
  reference_.phase = Reference::PHASE_ARRIVED;
  at({0.0, 0.9, 0.2});
  (void)link_->step(t_, estimate_, reference_, false);
  t_ += 0.01;
  ASSERT_EQ(link_->reactions().size(), 1u);
  ASSERT_TRUE(link_->longest_reaction().has_value());
  EXPECT_EQ(link_->longest_reaction()->end, CraneSiteLink::ReactionEnd::at_waypoint);
  EXPECT_EQ(link_->longest_reaction()->seconds, link_->reactions()[0]);
  EXPECT_STREQ(to_string(CraneSiteLink::ReactionEnd::at_waypoint),
               "at rest at its move's waypoint (a soft stop would have left the grant)");
}

TEST_F(Link, ALostLinkStopsTheAxesThatStayInsideAndLetsTheOthersRunOnToTheWaypoint) {
  // A pick at slew 1.0 rad: the travel turns the jib and runs the trolley out. The link is lost with
  // the trolley 2 cm short of 0.9 m at 0.5 m/s (its soft stop runs past it) and the slew at 0.3 rad
  // turning at 0.3 rad/s (its soft stop ends near 0.59 rad, well short of 1.0): the stop names the
  // slew and the resting hoist, and the trolley goes on to the waypoint
  // (GrantGuard.ASoftStopOfTheAxesThatStayInsideLetsTheOthersRunOnToTheirTarget computes the ends).
  SiteJob turn;
  turn.pick = {1.0, 0.9, 1.5};
  turn.place = {-1.5, 0.5, 1.2};
  link_.emplace(layout_, 0, params_, std::vector<SiteJob>{turn}, kFirstGoal);
  moving_at({0.3, 0.88, 0.2}, 0.5);
  ASSERT_EQ(link_->path()[link_->waypoint()].slew, 1.0);
  reference_.slew_rate = 0.3;
  estimate_.slew_rate = 0.3;
  const auto stop = silent(100, true);
  ASSERT_TRUE(stop.has_value());
  EXPECT_EQ(stop->command, MoveRequest::COMMAND_STOP);
  EXPECT_EQ(stop->axes, MoveRequest::AXIS_SLEW | MoveRequest::AXIS_HOIST);
  EXPECT_EQ(link_->halts(), 1);
  EXPECT_EQ(link_->halts_per_axis(), 1);
  EXPECT_EQ(link_->halts_at_waypoint(), 0);
  // At rest, the trolley at the waypoint and the slew short of it: safe, and the reaction says how.
  reference_.phase = Reference::PHASE_ARRIVED;
  at({0.6, 0.9, 0.2});
  (void)link_->step(t_, estimate_, reference_, false);
  t_ += 0.01;
  ASSERT_EQ(link_->reactions().size(), 1u);
  ASSERT_TRUE(link_->longest_reaction().has_value());
  EXPECT_EQ(link_->longest_reaction()->end, CraneSiteLink::ReactionEnd::per_axis);
  EXPECT_EQ(link_->phase(), CraneSiteLink::Phase::halted);
}

TEST_F(Link, ALostLinkStopsSoftlyWhenTheReferenceRestsWhateverTheMeasuredSpeed) {
  // The same measured motion, but the reference has arrived at the goal (0.9 m) and rests: the
  // crane overshooting it still moves at 0.5 m/s. A soft stop keeps the reference there, so it is
  // the stop (GrantGuard::soft_stop_stays_in_grant with reference_rest_of).
  moving_at({0.0, 0.89, 0.2}, 0.5);
  reference_.trolley_position = 0.9;
  reference_.trolley_velocity = 0.0;
  const auto stop = silent(100, true);
  ASSERT_TRUE(stop.has_value());
  EXPECT_EQ(stop->command, MoveRequest::COMMAND_STOP);
  EXPECT_EQ(link_->halts(), 1);
  EXPECT_EQ(link_->halts_at_waypoint(), 0);
}

TEST_F(Link, ALostLinkOutsideSharedAirspaceLetsTheCraneFinishItsPath) {
  // The other two cranes moved 10 m away: nothing tc1 does is in shared airspace (on the shipped
  // lab site every path of every crane is: its counter-jib alone reaches the others).
  SiteLayout apart = layout_;
  apart.cranes[1].base = {10.0, 0.0};
  apart.cranes[2].base = {10.0, 5.0};
  SiteJob away;
  away.pick = {-1.6, 0.4, 0.6};
  away.place = {-1.5, 0.3, 0.6};
  link_.emplace(apart, 0, params_, std::vector<SiteJob>{away}, kFirstGoal);
  at({-1.5, 0.3, 0.2});
  (void)step();
  ASSERT_FALSE(in_shared_airspace(apart, 0, path_airspace(link_->report()->request, apart.paths)));
  ASSERT_TRUE(link_->instruction(go(1), kEpoch, t_));
  auto g = step();
  answer(g->request_id);
  const auto after = silent(100, false);
  EXPECT_FALSE(after.has_value() && after->command == MoveRequest::COMMAND_STOP);
  EXPECT_EQ(link_->phase(), CraneSiteLink::Phase::moving);
  EXPECT_EQ(link_->halts(), 0);
  ASSERT_EQ(link_->reactions().size(), 1u) << "safe at once: its path is its own";
  EXPECT_EQ(link_->longest_reaction()->end, CraneSiteLink::ReactionEnd::outside_shared);
}

TEST_F(Link, ABrakedCraneStopsReportingForGood) {
  (void)step();
  ASSERT_TRUE(link_->report().has_value());
  EXPECT_FALSE(link_->step(t_, estimate_, reference_, true).has_value());
  EXPECT_EQ(link_->phase(), CraneSiteLink::Phase::braked);
  EXPECT_FALSE(link_->report().has_value());
  EXPECT_FALSE(step().has_value());
  EXPECT_FALSE(link_->report().has_value());
}

// The crane may start on the site once its supervisor says so, each condition by itself.
TEST(CraneSiteLinkReady, OnlyAWholeArmedChainWhoseGuardHearsTheSiteService) {
  using Status = crane::protocol::SupervisorStatus;
  Status ready{};
  ready.stages_alive = Status::STAGES_ALL;
  ready.brakes_released = true;
  ready.mode = Status::MODE_READY;
  ready.warnings = Status::WARNING_SITE;  // another warning: no matter
  EXPECT_TRUE(ready_for_site(ready));
  Status s = ready;
  s.mode = Status::MODE_OPERATING;
  EXPECT_TRUE(ready_for_site(s));
  s = ready;
  s.warnings |= Status::WARNING_SITE_UNHEARD;
  EXPECT_FALSE(ready_for_site(s)) << "its guard does not hear the site service";
  s = ready;
  s.stages_alive = Status::STAGES_ALL & ~Status::STAGE_TRACKING;
  EXPECT_FALSE(ready_for_site(s));
  s = ready;
  s.brakes_released = false;
  EXPECT_FALSE(ready_for_site(s));
  s = ready;
  s.latched_faults = Status::FAULT_SITE_GRANT;
  EXPECT_FALSE(ready_for_site(s));
  s = ready;
  s.mode = Status::MODE_STANDBY;
  EXPECT_FALSE(ready_for_site(s));
}

TEST(CraneSiteLinkJobs, JobsOutsideTheCranesRangesAreRefusedNamingTheField) {
  const SiteLayout layout = load_site_layout(kSite);
  const CraneLinkParams params;
  const auto refused = [&](const SiteJob& job) -> std::string {
    try {
      CraneSiteLink link(layout, 0, params, {job}, 1);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  SiteJob job;
  job.place.trolley = 1.5;
  EXPECT_EQ(refused(job), "crane tc1 job 0 place.trolley = 1.500000 is outside [0.050000, 1.300000]");
  job = SiteJob{};
  job.pick.cable_length = 2.5;  // tc1's hook reaches 0.5 m: 2.0 m of cable at most
  EXPECT_EQ(refused(job), "crane tc1 job 0 pick.cable_length = 2.500000 is outside [0.200000, 2.000000]");
  job = SiteJob{};
  job.pick.slew = std::nan("");
  EXPECT_NE(refused(job).find("pick.slew = nan"), std::string::npos);
  EXPECT_THROW(CraneSiteLink(layout, 3, params, {}, 1), std::out_of_range);
  CraneLinkParams bad = params;
  bad.dwell = 0.0;
  EXPECT_THROW(CraneSiteLink(layout, 0, bad, {}, 1), std::invalid_argument);
}

TEST(CraneSiteLinkJobs, AJobFileIsReadBackExactlyAndBadFilesAreRefused) {
  const fs::path dir = fs::temp_directory_path() / ("crane_site_jobs_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::vector<SiteJob> jobs{{{0.1, 0.2, 0.3}, {-1.0 / 3.0, 1.0 / 7.0, 1.2345678901234567}},
                                  {{2.0, 0.9, 1.5}, {-2.5, 0.05, 2.0}}};
  write_site_jobs((dir / "tc1.csv").string(), jobs);
  const auto back = load_site_jobs((dir / "tc1.csv").string());
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].place.slew, jobs[0].place.slew);
  EXPECT_EQ(back[0].place.trolley, jobs[0].place.trolley);
  EXPECT_EQ(back[0].place.cable_length, jobs[0].place.cable_length);
  EXPECT_EQ(back[1].pick.trolley, 0.9);
  const auto message = [&](const std::string& text) -> std::string {
    std::ofstream(dir / "bad.csv") << text;
    try {
      (void)load_site_jobs((dir / "bad.csv").string());
    } catch (const crane::common::ConfigError& e) {
      return e.what();
    }
    return "";
  };
  const std::string header = std::string(kSiteJobsHeader) + "\n";
  EXPECT_EQ(message("slew,trolley\n"), std::string("bad.csv: line 1 must be the header ") + kSiteJobsHeader);
  EXPECT_EQ(message(header + "0,0.5,1,0,0.5,x\n"), "bad.csv: line 2: place_cable_length_m = 'x' is not a finite number");
  EXPECT_EQ(message(header + "0,0.5,1,0,0.5\n"),
            std::string("bad.csv: line 2: expected 6 fields (") + kSiteJobsHeader + ")");
  EXPECT_EQ(message(header + "0,0.5,1,0,0.5,1,2\n"),
            std::string("bad.csv: line 2: expected 6 fields (") + kSiteJobsHeader + ")");
  EXPECT_EQ(message(header + "0,inf,1,0,0.5,1\n"), "bad.csv: line 2: pick_trolley_m = 'inf' is not a finite number");
  EXPECT_THROW((void)load_site_jobs((dir / "missing.csv").string()), crane::common::ConfigError);
  fs::remove_all(dir);
}

}  // namespace
