#include "physics/trajectory_simulator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "physics/scene_generator.h"

namespace tubepick::physics {
namespace {

using ::testing::HasSubstr;
constexpr double kR = 0.0125;
/// The grasped tube must follow its commanded pose this closely at every step, metres.
constexpr double kTrackingTol = 0.001;
/// Lifting a tube nothing rests on may move the others at most this much in total, metres.
constexpr double kFreeLiftTol = 0.005;
/// Lifting a tube that another rests on must move it at least this much, metres.
constexpr double kEntangledCost = 0.05;

/// A tube through `points`: one cylinder between consecutive points, joints of length 0.
Tube PolylineTube(std::uint32_t id, const std::vector<Eigen::Vector3d>& points) {
  Tube tube;
  tube.id = id;
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    Cylinder c;
    c.start = points[i];
    c.end = points[i + 1];
    c.radius = kR;
    tube.cylinders.push_back(c);
  }
  return tube;
}

/// A straight tube from `a` to `b` made of two cylinders (so it has a joint).
Tube StraightTube(std::uint32_t id, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return PolylineTube(id, {a, 0.5 * (a + b), b});
}

/// Tube 0 along x on the floor; tube 1 along y across it at its own centre, balanced on it.
std::vector<Tube> BalancedCrossingTubes() {
  return {StraightTube(1, {-0.25, 0.0, kR}, {0.25, 0.0, kR}),
          StraightTube(2, {0.05, -0.2, 3 * kR}, {0.05, 0.2, 3 * kR})};
}

/// Two crossing tubes in the default bin (0.8 × 0.6 m): tube 0 lies along x on the floor; tube 1
/// lies along y across it, off its own centre, so it settles leaning on tube 0 with its +y end on
/// the floor.
std::vector<Tube> CrossingTubes() {
  return {StraightTube(1, {-0.25, 0.0, kR}, {0.25, 0.0, kR}),
          StraightTube(2, {0.05, -0.10, 3 * kR}, {0.05, 0.25, 3 * kR})};
}

Trajectory Lift(std::uint32_t tube_index, double height) {
  Trajectory t;
  t.tube_index = tube_index;
  t.waypoints = {Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, height)};
  return t;
}

TrajectorySimParams OneThread() {
  TrajectorySimParams params;
  params.threads = 1;
  return params;
}

TEST(TrajectorySimulator, CrossingTubesSettle) {
  const SettledTubes settled(CrossingTubes(), OneThread(), nullptr);
  EXPECT_TRUE(settled.at_rest());
  ASSERT_EQ(settled.size(), 2u);
  // Tube 0 on the floor; tube 1 leans on it: its centre of mass between floor and 3R.
  EXPECT_NEAR(settled.p_BinCo(0).z(), kR, 0.002);
  EXPECT_GT(settled.p_BinCo(1).z(), kR + 0.002);
  EXPECT_LT(settled.p_BinCo(1).z(), 3 * kR);
}

TEST(TrajectorySimulator, LiftingTheLowerTubeCarriesTheUpperOne) {
  const SettledTubes settled(BalancedCrossingTubes(), OneThread(), nullptr);
  const TrajectoryRun run = settled.Run(Lift(0, 0.4), nullptr);
  // No clipping: the upper tube rides up on the lower one instead of falling through it.
  EXPECT_GT(run.outcome.displacement, kEntangledCost);
  EXPECT_GT(run.p_BinCo_final[1].z(), settled.p_BinCo(1).z() + 0.3);
  EXPECT_FALSE(run.outcome.stopped_early);
  // No deflection: the grasped tube stayed on its path.
  EXPECT_LT(run.outcome.max_tracking_error, kTrackingTol);
}

TEST(TrajectorySimulator, LiftingTheLowerTubeCarriesABentTubeDrapedOverIt) {
  // Tube 1 is a roof over tube 0: its middle on tube 0, both ends on the floor.
  const std::vector<Tube> tubes = {
      StraightTube(1, {-0.25, 0.0, kR}, {0.25, 0.0, kR}),
      PolylineTube(2, {{0.05, -0.2, kR}, {0.05, 0.0, 3 * kR + 0.001}, {0.05, 0.2, kR}})};
  const SettledTubes settled(tubes, OneThread(), nullptr);
  const TrajectoryRun run = settled.Run(Lift(0, 0.4), nullptr);
  EXPECT_GT(run.outcome.displacement, 0.3);
  EXPECT_GT(run.p_BinCo_final[1].z(), settled.p_BinCo(1).z() + 0.3);
  EXPECT_LT(run.outcome.max_tracking_error, kTrackingTol);
}

TEST(TrajectorySimulator, LiftingTheLowerTubeRaisesATubeLeaningOnIt) {
  const SettledTubes settled(CrossingTubes(), OneThread(), nullptr);
  const TrajectoryRun run = settled.Run(Lift(0, 0.4), nullptr);
  // The leaning tube is raised by 10 cm before it slides off and lands near where it lay: it was
  // pushed, not passed through.
  EXPECT_GT(run.max_com_z[1], settled.p_BinCo(1).z() + 0.1);
  EXPECT_GT(run.outcome.displacement, 0.01);
  EXPECT_LT(run.outcome.max_tracking_error, kTrackingTol);
}

TEST(TrajectorySimulator, LateralMovePushesATubeInTheWayAside) {
  // Two parallel tubes on the floor, 6 cm apart; tube 0 is lifted 1 cm and moved 15 cm towards
  // tube 1, which it must shove ahead of it rather than pass through.
  const std::vector<Tube> tubes = {StraightTube(1, {-0.2, 0.0, kR}, {0.2, 0.0, kR}),
                                   StraightTube(2, {-0.2, 0.06, kR}, {0.2, 0.06, kR})};
  const SettledTubes settled(tubes, OneThread(), nullptr);
  Trajectory push;
  push.tube_index = 0;
  push.waypoints = {Eigen::Vector3d::Zero(), {0, 0, 0.01}, {0, 0.15, 0.01}};
  const TrajectoryRun run = settled.Run(push, nullptr);
  EXPECT_LT(run.outcome.max_tracking_error, kTrackingTol);
  const double y0 = run.p_BinCo_final[0].y(), y1 = run.p_BinCo_final[1].y();
  EXPECT_NEAR(y0, settled.p_BinCo(0).y() + 0.15, 1e-9);
  // Tube 1 ends beyond tube 0 (no tunnelling) and at least two radii from its axis (less contact
  // penetration).
  EXPECT_GT(y1 - y0, 2 * kR - 0.002);
  EXPECT_GT(run.outcome.displacement, 0.05);
}

TEST(TrajectorySimulator, LiftingAFreeTubeCostsNothing) {
  const SettledTubes settled(CrossingTubes(), OneThread(), nullptr);
  const TrajectoryRun run = settled.Run(Lift(1, 0.4), nullptr);
  EXPECT_LT(run.outcome.displacement, kFreeLiftTol);
  EXPECT_LT((run.p_BinCo_final[0] - settled.p_BinCo(0)).norm(), kFreeLiftTol);
  EXPECT_LT(run.outcome.max_tracking_error, kTrackingTol);
}

TEST(TrajectorySimulator, TubesNothingReachesStayExactlyWhereTheySettled) {
  std::vector<Tube> tubes = CrossingTubes();
  tubes.push_back(StraightTube(3, {0.3, -0.2, kR}, {0.3, 0.2, kR}));  // far from both
  const SettledTubes settled(tubes, OneThread(), nullptr);
  const TrajectoryRun run = settled.Run(Lift(0, 0.4), nullptr);
  EXPECT_EQ(run.p_BinCo_final[2], settled.p_BinCo(2));
  EXPECT_EQ(run.max_com_z[2], settled.p_BinCo(2).z());
}

TEST(TrajectorySimulator, EveryRunStartsFromTheSameSnapshot) {
  const SettledTubes settled(BalancedCrossingTubes(), OneThread(), nullptr);
  const TrajectoryRun first = settled.Run(Lift(0, 0.2), nullptr);
  settled.Run(Lift(1, 0.3), nullptr);
  const TrajectoryRun again = settled.Run(Lift(0, 0.2), nullptr);
  EXPECT_EQ(first.outcome.displacement, again.outcome.displacement);
  EXPECT_EQ(first.p_BinCo_final, again.p_BinCo_final);
  EXPECT_EQ(first.steps, again.steps);
}

TEST(TrajectorySimulator, GraspedTubeFollowsAnEscapeTrajectoryThroughContact) {
  TrajectorySimParams params = OneThread();
  const SettledTubes settled(CrossingTubes(), params, nullptr);
  // Small lift, a lateral move along +y pushing through the upper tube, then a lift.
  Trajectory escape;
  escape.tube_index = 0;
  escape.kind = TrajectoryKind::kEscape;
  escape.waypoints = {Eigen::Vector3d::Zero(), {0, 0, 0.02}, {0, 0.15, 0.02}, {0, 0.15, 0.3}};
  const TrajectoryRun run = settled.Run(escape, nullptr);
  EXPECT_LT(run.outcome.max_tracking_error, kTrackingTol);
  EXPECT_TRUE((run.p_BinCo_final[0] - settled.p_BinCo(0)).isApprox(escape.waypoints.back(), 1e-9));
  EXPECT_GT(run.outcome.displacement, 0.01);  // the upper tube was pushed
  // Path length / speed, plus the hold at the end.
  const double expected_time = (0.02 + 0.15 + 0.28) / params.gripper_speed + params.post_motion_time;
  EXPECT_NEAR(run.outcome.simulated_time, expected_time, 2 * params.time_step);
}

TEST(TrajectorySimulator, StopsEarlyOnceDisplacementExceedsDispMax) {
  TrajectorySimParams params = OneThread();
  params.disp_max = 0.02;
  const SettledTubes settled(CrossingTubes(), params, nullptr);
  const TrajectoryRun run = settled.Run(Lift(0, 0.4), nullptr);
  EXPECT_TRUE(run.outcome.stopped_early);
  EXPECT_GT(run.outcome.displacement, params.disp_max);
  EXPECT_LT(run.outcome.simulated_time, 0.4 / params.gripper_speed);
}

TEST(TrajectorySimulator, StillTrajectoryCostsNothing) {
  TrajectorySimParams params = OneThread();
  const SettledTubes settled(CrossingTubes(), params, nullptr);
  Trajectory still;
  still.tube_index = 0;
  still.waypoints = {Eigen::Vector3d::Zero()};
  const TrajectoryRun run = settled.Run(still, nullptr);
  EXPECT_LT(run.outcome.displacement, 1e-4);
  EXPECT_NEAR(run.outcome.simulated_time, params.post_motion_time, params.time_step);
}

TEST(TrajectorySimulator, EvaluatorReturnsOneOutcomePerTrajectoryInOrder) {
  BulletTrajectoryEvaluator evaluator(OneThread());
  const std::vector<TrajectoryOutcome> outcomes =
      evaluator.Evaluate(BalancedCrossingTubes(), {Lift(1, 0.4), Lift(0, 0.4)}, 1, nullptr);
  ASSERT_EQ(outcomes.size(), 2u);
  EXPECT_LT(outcomes[0].displacement, kFreeLiftTol);
  EXPECT_GT(outcomes[1].displacement, kEntangledCost);
  EXPECT_TRUE(evaluator.Evaluate(CrossingTubes(), {}, 1, nullptr).empty());
}

void ExpectBitwiseEqual(const std::vector<TrajectoryOutcome>& a, const std::vector<TrajectoryOutcome>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    SCOPED_TRACE("trajectory " + std::to_string(k));
    EXPECT_EQ(a[k].displacement, b[k].displacement);
    EXPECT_EQ(a[k].stopped_early, b[k].stopped_early);
    EXPECT_EQ(a[k].max_tracking_error, b[k].max_tracking_error);
    EXPECT_EQ(a[k].simulated_time, b[k].simulated_time);
  }
}

TEST(TrajectorySimulator, SameOutcomesWhateverTheThreadCount) {
  SceneParams scene;
  scene.tube_count = 6;
  const DropResult drop = GenerateScene(scene, 11);
  std::vector<Tube> tubes;
  for (const TubeGeometry& g : drop.tubes) tubes.push_back(g.ToTube());
  std::vector<Trajectory> trajectories;
  for (std::uint32_t i = 0; i < tubes.size(); ++i) trajectories.push_back(Lift(i, 0.3));
  Trajectory escape = Lift(0, 0.0);
  escape.waypoints = {Eigen::Vector3d::Zero(), {0, 0, 0.02}, {0.1, 0, 0.02}, {0.1, 0, 0.2}};
  trajectories.push_back(escape);

  TrajectorySimParams params;
  params.threads = 1;
  const std::vector<TrajectoryOutcome> one =
      BulletTrajectoryEvaluator(params).Evaluate(tubes, trajectories, 5, nullptr);
  params.threads = 2;
  const std::vector<TrajectoryOutcome> two =
      BulletTrajectoryEvaluator(params).Evaluate(tubes, trajectories, 5, nullptr);
  ExpectBitwiseEqual(one, two);
  params.threads = 3;
  const std::vector<TrajectoryOutcome> three =
      BulletTrajectoryEvaluator(params).Evaluate(tubes, trajectories, 5, nullptr);
  ExpectBitwiseEqual(one, three);
  // The scene is a pile: at least one lift disturbs other tubes.
  double most = 0.0;
  for (const TrajectoryOutcome& o : one) {
    most = std::max(most, o.displacement);
    EXPECT_LT(o.max_tracking_error, kTrackingTol);
  }
  EXPECT_GT(most, 0.01);
}

TEST(TrajectorySimulator, CancelStopsWithinAFewSteps) {
  TrajectorySimParams params;
  params.threads = 2;
  BulletTrajectoryEvaluator evaluator(params);
  // Two lifts of 10 km: minutes of simulation if nothing stopped them.
  const std::vector<Trajectory> long_lifts = {Lift(0, 1e4), Lift(1, 1e4)};
  StopToken stop;
  std::chrono::steady_clock::time_point requested;
  std::thread canceller([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    requested = std::chrono::steady_clock::now();
    stop.RequestStop();
  });
  bool cancelled = false;
  try {
    evaluator.Evaluate(CrossingTubes(), long_lifts, 1, &stop);
  } catch (const Cancelled& e) {
    cancelled = true;
    EXPECT_FALSE(e.deadline_exceeded());
    EXPECT_THAT(e.what(), HasSubstr("trajectory simulation"));
  }
  const auto returned = std::chrono::steady_clock::now();
  canceller.join();
  EXPECT_TRUE(cancelled);
  // Workers poll every step (well under 1 ms), so the stop lands at once; unpolled, the lifts would
  // run for minutes. The bound is that difference, not a latency target: a loaded 2-core CI machine
  // once took 0.36 s to schedule the return.
  EXPECT_LT(std::chrono::duration<double>(returned - requested).count(), 5.0);
}

TEST(TrajectorySimulator, DeadlineStopsTheSimulation) {
  BulletTrajectoryEvaluator evaluator(OneThread());
  const StopToken deadline(std::chrono::steady_clock::now() + std::chrono::milliseconds(100));
  EXPECT_THAT([&] { evaluator.Evaluate(CrossingTubes(), {Lift(0, 1e4)}, 1, &deadline); },
              ::testing::Throws<Cancelled>(::testing::Property(&Cancelled::deadline_exceeded, true)));
}

TEST(TrajectorySimulator, InvalidParamsAreNamed) {
  const std::vector<std::pair<std::string, std::function<void(TrajectorySimParams&)>>> cases = {
      {"gripper_speed", [](TrajectorySimParams& p) { p.gripper_speed = 0.0; }},
      // So slow or so fine that the step count would overflow an int.
      {"gripper_speed", [](TrajectorySimParams& p) { p.gripper_speed = 1e-300; }},
      {"time_step", [](TrajectorySimParams& p) { p.time_step = -1.0; }},
      {"time_step", [](TrajectorySimParams& p) { p.time_step = 1e-300; }},
      {"solver_iterations", [](TrajectorySimParams& p) { p.solver_iterations = 0; }},
      {"settle_time", [](TrajectorySimParams& p) { p.settle_time = std::nan(""); }},
      {"rest_time", [](TrajectorySimParams& p) { p.rest_time = -0.1; }},
      {"linear_rest_velocity", [](TrajectorySimParams& p) { p.linear_rest_velocity = 0.0; }},
      {"angular_rest_velocity", [](TrajectorySimParams& p) { p.angular_rest_velocity = 0.0; }},
      {"post_motion_time", [](TrajectorySimParams& p) { p.post_motion_time = -1.0; }},
      {"disp_max", [](TrajectorySimParams& p) { p.disp_max = 0.0; }},
      {"tube_mass", [](TrajectorySimParams& p) { p.tube_mass = 0.0; }},
      {"tube_friction", [](TrajectorySimParams& p) { p.tube_friction = -0.1; }},
      {"bin_friction", [](TrajectorySimParams& p) { p.bin_friction = INFINITY; }},
      {"tube_rolling_friction", [](TrajectorySimParams& p) { p.tube_rolling_friction = -1.0; }},
      {"tube_restitution", [](TrajectorySimParams& p) { p.tube_restitution = 1.5; }},
      {"bin_restitution", [](TrajectorySimParams& p) { p.bin_restitution = -0.5; }},
      {"linear_damping", [](TrajectorySimParams& p) { p.linear_damping = 2.0; }},
      {"angular_damping", [](TrajectorySimParams& p) { p.angular_damping = -1.0; }},
      {"collision_margin", [](TrajectorySimParams& p) { p.collision_margin = 0.04; }},
      {"joint_min_length", [](TrajectorySimParams& p) { p.joint_min_length = -0.001; }},
      {"sleep_linear_velocity", [](TrajectorySimParams& p) { p.sleep_linear_velocity = -1.0; }},
      {"sleep_angular_velocity", [](TrajectorySimParams& p) { p.sleep_angular_velocity = -1.0; }},
      {"wall_thickness", [](TrajectorySimParams& p) { p.wall_thickness = 0.0; }},
      {"threads", [](TrajectorySimParams& p) { p.threads = -1; }},
      {"bin.inner_size[2]", [](TrajectorySimParams& p) { p.bin.inner_size.z() = 0.0; }},
  };
  for (const auto& [field, mutate] : cases) {
    SCOPED_TRACE(field);
    TrajectorySimParams params;
    mutate(params);
    EXPECT_THAT([&] { params.Validate(); },
                ::testing::ThrowsMessage<InvalidArgument>(HasSubstr(field + " = ")));
    EXPECT_THROW(BulletTrajectoryEvaluator{params}, InvalidArgument);
  }
  EXPECT_NO_THROW(TrajectorySimParams{}.Validate());
}

TEST(TrajectorySimulator, InvalidTrajectoriesAreNamedBeforeSimulating) {
  BulletTrajectoryEvaluator evaluator(OneThread());
  Trajectory bad_index = Lift(5, 0.1);
  EXPECT_THAT(
      [&] {
        evaluator.Evaluate(CrossingTubes(), {Lift(0, 0.1), bad_index}, 1, nullptr);
      },
      ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("trajectory 1: tube_index = 5")));
  Trajectory empty;
  EXPECT_THAT([&] { evaluator.Evaluate(CrossingTubes(), {empty}, 1, nullptr); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("trajectory 0: no waypoints")));
  Trajectory offset = Lift(0, 0.1);
  offset.waypoints.front() = Eigen::Vector3d(0, 0, 0.01);
  EXPECT_THAT([&] { evaluator.Evaluate(CrossingTubes(), {offset}, 1, nullptr); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("first waypoint must be (0, 0, 0)")));
  Trajectory nan = Lift(0, std::nan(""));
  EXPECT_THAT([&] { evaluator.Evaluate(CrossingTubes(), {nan}, 1, nullptr); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("waypoint 1 is not finite")));
  std::vector<Tube> tubes = CrossingTubes();
  tubes[1].cylinders.clear();
  EXPECT_THAT([&] { evaluator.Evaluate(tubes, {Lift(0, 0.1)}, 1, nullptr); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("tube 2 has no cylinders")));
}

}  // namespace
}  // namespace tubepick::physics
