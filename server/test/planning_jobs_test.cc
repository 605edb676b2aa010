#include "server/planning_jobs.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <thread>

#include "core/common/errors.h"
#include "core/params.h"
#include "core/testing/sanitizer_build.h"
#include "core/testing/synthetic_cloud.h"
#include "wire/packed_cloud.h"
#include "wire/proto_convert.h"

namespace tubepick::server {
namespace {

using testing::FloorTube;
using ::testing::HasSubstr;
using testing::StraightTube;
using testing::SyntheticTube;

constexpr double kR = 0.0125;

std::string Encode(const Points& points) {
  std::string bytes(points.size() * 12, '\0');
  for (std::size_t i = 0; i < points.size(); ++i) std::memcpy(&bytes[12 * i], points[i].data(), 12);
  return bytes;
}

std::string RenderBytes(const std::vector<SyntheticTube>& tubes) {
  testing::SyntheticCloudParams params;
  params.pixel_angle = 0.0008;  // ≈ 0.9 mm at the floor: fine enough for 12.5 mm tubes, fast to model
  params.seed = 11;
  return Encode(testing::RenderSyntheticCloud(tubes, params).points_Sensor);
}

// Three straight 0.40 m tubes lying apart on the floor: nothing occludes anything.
const std::string& ThreeTubesCloud() {
  static const std::string bytes =
      RenderBytes({FloorTube({{-0.22, -0.17}, {0.18, -0.17}}), FloorTube({{-0.20, 0.0}, {0.20, 0.03}}),
                   FloorTube({{-0.15, 0.17}, {0.25, 0.14}})});
  return bytes;
}

// Three inclined tubes woven into a triangle: each lies on the next one at its start and under the
// previous one at its end, so every tube is weakly occluded and planning must simulate. Each tube
// is 0.50 m long, the default cell's tube.length (joining builds no longer tube).
const std::string& WeaveCloud() {
  static const std::string bytes = [] {
    const double side = 0.30, extension = 0.10;
    const double drop = 2.0 * kR;  // height change between the two crossings of a tube
    const double slope = drop / side;
    std::vector<Eigen::Vector2d> v;
    for (int i = 0; i < 3; ++i) {
      const double a = M_PI / 2 + i * 2.0 * M_PI / 3;
      v.emplace_back(side / std::sqrt(3.0) * std::cos(a), side / std::sqrt(3.0) * std::sin(a));
    }
    std::vector<SyntheticTube> tubes;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector2d from = v[i], to = v[(i + 1) % 3];
      const Eigen::Vector2d d = (to - from).normalized();
      const Eigen::Vector2d a = from - extension * d, b = to + extension * d;
      const double z_low = kR + 0.001;
      const double z_high = z_low + slope * (side + 2.0 * extension);
      tubes.push_back(StraightTube({a.x(), a.y(), z_high}, {b.x(), b.y(), z_low}));
    }
    return RenderBytes(tubes);
  }();
  return bytes;
}

v1::PlanPickRequest Request(const std::string& cloud, std::uint64_t seed = 3) {
  v1::PlanPickRequest r;
  r.mutable_cloud()->set_xyz(cloud);
  r.mutable_options()->set_seed(seed);
  return r;
}

// The response without its wall-clock timings (the only fields that may differ between runs).
v1::PlanPickResponse WithoutTimings(v1::PlanPickResponse r) {
  r.clear_stage_timings();
  r.clear_total_seconds();
  r.mutable_modeling()->clear_stage_timings();
  r.mutable_modeling()->clear_total_seconds();
  return r;
}

void ExpectOrderedByCost(const v1::PlanPickResponse& r) {
  for (int i = 1; i < r.plans_size(); ++i) {
    EXPECT_LE(r.plans(i - 1).cost().total(), r.plans(i).cost().total()) << "plan " << i;
  }
}

TEST(RunModelTubes, FindsTheThreeTubes) {
  const PlanningDefaults defaults;
  const v1::PlanPickRequest job_request = Request(ThreeTubesCloud(), 5);
  const PlanningJob job = ValidatePlanPick(job_request, defaults);
  const v1::ModelTubesResponse r = RunModelTubes(job, 1, nullptr);
  ASSERT_EQ(r.tubes_size(), 3);
  for (const v1::Tube& t : r.tubes()) {
    EXPECT_NEAR(t.length(), 0.40, 0.02) << "tube " << t.id();
    ASSERT_GE(t.cylinders_size(), 1);
    EXPECT_NEAR(t.cylinders(0).radius(), kR, 0.001);
  }
  EXPECT_EQ(r.input_points(), job.xyz_Sensor.size() / 12);
  EXPECT_NEAR(r.max_height(), 2.0 * kR, 0.004);
  EXPECT_EQ(r.profile(), "fast");
  EXPECT_EQ(r.seed(), 5u);
  EXPECT_GT(r.step_counts_size(), 2);
  EXPECT_GT(r.stage_timings_size(), 2);
}

TEST(RunModelTubes, MillimetreCloudGivesTheSameTubes) {
  const PlanningDefaults defaults;
  const v1::PlanPickRequest metres_request = Request(ThreeTubesCloud());
  const PlanningJob metres = ValidatePlanPick(metres_request, defaults);
  Points scaled = UnpackXyz(metres.xyz_Sensor);
  for (Eigen::Vector3f& p : scaled) p *= 1000.0f;
  v1::PlanPickRequest request = Request(Encode(scaled));
  request.mutable_cloud()->set_unit(v1::LENGTH_UNIT_MILLIMETRE);
  const v1::ModelTubesResponse a = RunModelTubes(metres, 1, nullptr);
  const v1::ModelTubesResponse b = RunModelTubes(ValidatePlanPick(request, defaults), 1, nullptr);
  ASSERT_EQ(a.tubes_size(), b.tubes_size());
  for (int i = 0; i < a.tubes_size(); ++i) EXPECT_NEAR(a.tubes(i).length(), b.tubes(i).length(), 1e-3);
}

TEST(RunModelTubes, AllNonFiniteCloudIsACallerMistake) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const v1::PlanPickRequest request = Request(Encode(Points(100, Eigen::Vector3f(nan, nan, nan))));
  const PlanningJob job = ValidatePlanPick(request, PlanningDefaults{});
  EXPECT_THROW(RunModelTubes(job, 1, nullptr), InvalidArgument);
}

TEST(RunPlanPick, UnoccludedTubesNeedNoSimulation) {
  const PlanningDefaults defaults;
  const v1::PlanPickRequest job_request = Request(ThreeTubesCloud());
  const PlanningJob job = ValidatePlanPick(job_request, defaults);
  const v1::PlanPickResponse r = RunPlanPick(job, defaults, 1, nullptr);
  EXPECT_FALSE(r.used_simulation());
  EXPECT_FALSE(r.bin_empty());
  ASSERT_EQ(r.tubes_size(), 3);
  for (const v1::Tube& t : r.tubes()) EXPECT_EQ(t.occlusion(), v1::OCCLUSION_NONE);
  ASSERT_GT(r.plans_size(), 10);
  ExpectOrderedByCost(r);
  for (const v1::PickPlan& p : r.plans()) {
    EXPECT_EQ(p.trajectory_kind(), v1::TRAJECTORY_KIND_UPWARD);
    EXPECT_EQ(p.cost().trajectory(), 0.0);
    // Horizontal tubes have a yaw: every plan gets a placement pose.
    EXPECT_TRUE(p.has_place_tcp_pose());
  }
  // The best grasp is near the middle of its tube (centre cost ≈ 0), 2r above the floor.
  EXPECT_LT(r.plans(0).cost().centre(), 0.1);
  EXPECT_NEAR(r.plans(0).grasp().tcp_pose().position().z(), kR, 0.005);
  EXPECT_EQ(r.modeling().tubes_size(), 0);  // the classified tubes above replace them
  EXPECT_EQ(r.modeling().seed(), 3u);
  // The counts explain the plans: 3 free tubes, no simulation, every accepted candidate is a plan.
  const v1::PlanningCounts& c = r.counts();
  EXPECT_EQ(c.tubes(), 3u);
  EXPECT_EQ(c.non_occluded(), 3u);
  EXPECT_EQ(c.simulated_trajectories(), 0u);
  EXPECT_EQ(c.grasp_candidates() - c.rejected_section() - c.rejected_workspace() - c.rejected_tool() -
                c.rejected_fingers(),
            static_cast<std::uint64_t>(r.plans_size()));
}

TEST(RunPlanPick, WovenTubesAreSimulatedAndRankedByCost) {
  const PlanningDefaults defaults;
  v1::PlanPickRequest request = Request(WeaveCloud());
  const v1::PlanPickResponse simulated =
      RunPlanPick(ValidatePlanPick(request, defaults), defaults, 2, nullptr);
  request.mutable_options()->set_disable_simulation(true);
  const v1::PlanPickResponse unsimulated =
      RunPlanPick(ValidatePlanPick(request, defaults), defaults, 2, nullptr);

  ASSERT_EQ(simulated.tubes_size(), 3);
  for (const v1::Tube& t : simulated.tubes()) EXPECT_EQ(t.occlusion(), v1::OCCLUSION_WEAK);
  EXPECT_TRUE(simulated.used_simulation());
  EXPECT_FALSE(unsimulated.used_simulation());
  ASSERT_GT(simulated.plans_size(), 10);
  ASSERT_EQ(simulated.plans_size(), unsimulated.plans_size());  // the same candidates, other costs
  ExpectOrderedByCost(simulated);
  ExpectOrderedByCost(unsimulated);
  int moved = 0;
  for (const v1::PickPlan& p : simulated.plans()) {
    EXPECT_GE(p.simulated_displacement(), 0.0);
    EXPECT_GE(p.cost().trajectory(), 0.0);
    EXPECT_LE(p.cost().trajectory(), 1.0);
    if (p.simulated_displacement() > 0.01) ++moved;
  }
  EXPECT_GT(moved, 0);  // lifting a woven tube drags the others
  for (const v1::PickPlan& p : unsimulated.plans()) {
    EXPECT_EQ(p.simulated_displacement(), 0.0);
    EXPECT_EQ(p.cost().trajectory(), 0.0);
  }
}

TEST(RunPlanPick, SameSeedGivesIdenticalBytesWhateverTheThreads) {
  const PlanningDefaults defaults;
  const v1::PlanPickRequest job_request = Request(WeaveCloud(), 8);
  const PlanningJob job = ValidatePlanPick(job_request, defaults);
  const std::string a = WithoutTimings(RunPlanPick(job, defaults, 1, nullptr)).SerializeAsString();
  const std::string b = WithoutTimings(RunPlanPick(job, defaults, 2, nullptr)).SerializeAsString();
  EXPECT_GT(a.size(), 1000u);
  EXPECT_EQ(a, b);
}

TEST(RunPlanPick, MaxPlansKeepsTheBestOnes) {
  const PlanningDefaults defaults;
  v1::PlanPickRequest request = Request(ThreeTubesCloud());
  request.mutable_options()->set_disable_simulation(true);
  const v1::PlanPickResponse all = RunPlanPick(ValidatePlanPick(request, defaults), defaults, 1, nullptr);
  request.mutable_options()->set_max_plans(2);
  const v1::PlanPickResponse two = RunPlanPick(ValidatePlanPick(request, defaults), defaults, 1, nullptr);
  ASSERT_GT(all.plans_size(), 2);
  ASSERT_EQ(two.plans_size(), 2);
  for (int i = 0; i < 2; ++i) EXPECT_EQ(two.plans(i).SerializeAsString(), all.plans(i).SerializeAsString());
  request.mutable_options()->set_max_plans(100000);
  EXPECT_EQ(RunPlanPick(ValidatePlanPick(request, defaults), defaults, 1, nullptr).plans_size(),
            all.plans_size());
}

TEST(RunPlanPick, StoppedTokenCancels) {
  const PlanningDefaults defaults;
  const v1::PlanPickRequest job_request = Request(ThreeTubesCloud());
  const PlanningJob job = ValidatePlanPick(job_request, defaults);
  StopToken stopped;
  stopped.RequestStop();
  try {
    RunPlanPick(job, defaults, 1, &stopped);
    FAIL() << "expected Cancelled";
  } catch (const Cancelled& e) {
    EXPECT_FALSE(e.deadline_exceeded());
  }
  EXPECT_THROW(RunModelTubes(job, 1, &stopped), Cancelled);
  const StopToken expired(StopToken::Clock::now() - std::chrono::milliseconds(1));
  try {
    RunModelTubes(job, 1, &expired);
    FAIL() << "expected Cancelled";
  } catch (const Cancelled& e) {
    EXPECT_TRUE(e.deadline_exceeded());
  }
}

TEST(RunPlanPick, StopDuringModelingEndsTheCallPromptly) {
  const PlanningDefaults defaults;
  const v1::PlanPickRequest job_request = Request(WeaveCloud());
  const PlanningJob job = ValidatePlanPick(job_request, defaults);
  StopToken token;
  std::chrono::steady_clock::time_point stopped_at;
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    stopped_at = std::chrono::steady_clock::now();
    token.RequestStop();
  });
  EXPECT_THROW(RunPlanPick(job, defaults, 1, &token), Cancelled);
  const auto returned_at = std::chrono::steady_clock::now();
  stopper.join();
  // Generous bound (the requirement is 100 ms; this is a unit test on a shared machine).
  EXPECT_LT(returned_at - stopped_at, std::chrono::seconds(1) * tubepick::testing::kTimeScale);
}

TEST(RunPlanPick, StopDuringSimulationEndsTheCallPromptly) {
  // The woven tubes are all occluded, so planning simulates; a slow gripper stretches each simulated
  // lift to minutes of simulated time, so the stop lands inside the Bullet loop, well after modeling
  // (also in a sanitizer build, where modeling is instrumented and slow but Bullet is not). The call
  // is stopped long before: the slower the gripper, the surer the stop finds it simulating.
  PlanningDefaults defaults;
  defaults.simulation.gripper_speed = 0.0002;
  const v1::PlanPickRequest job_request = Request(WeaveCloud());
  const PlanningJob job = ValidatePlanPick(job_request, defaults);
  const auto model_start = std::chrono::steady_clock::now();
  (void)RunModelTubes(job, 1, nullptr);
  const auto modeling = std::chrono::steady_clock::now() - model_start;

  StopToken token;
  std::chrono::steady_clock::time_point stopped_at;
  std::thread stopper([&] {
    std::this_thread::sleep_for(3 * modeling + std::chrono::milliseconds(300));
    stopped_at = std::chrono::steady_clock::now();
    token.RequestStop();
  });
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(RunPlanPick(job, defaults, 1, &token), Cancelled);
  const auto returned_at = std::chrono::steady_clock::now();
  stopper.join();
  const double stop_ms = std::chrono::duration<double, std::milli>(returned_at - stopped_at).count();
  RecordProperty("stop_to_return_ms", std::to_string(stop_ms));
  EXPECT_GT(stopped_at - start, modeling);  // the stop came after modeling, during the simulation
  // Generous bound (the requirement is 100 ms; this is a unit test on a shared machine).
  EXPECT_LT(stop_ms, 1000.0 * tubepick::testing::kTimeScale);
}

// ---- AnalyzeWrench ------------------------------------------------------------------------------

constexpr double kMass = 0.055;
constexpr double kWeight = kMass * 9.81;  // 0.53955 N
constexpr double kGripper = 12.0;         // N, the empty gripper's weight on the sensor

// A vertical grasp TCP (z pointing down), yawed 30° about the bin's z, 0.3 m above the floor.
Eigen::Isometry3d GraspTcp() {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = (Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.1, -0.05, 0.3);
  return X;
}

// Readings in the sensor (= TCP) frame: weight pulls along the bin's −z, i.e. the TCP's +z.
v1::AnalyzeWrenchRequest WrenchRequest(double held_tubes, const Eigen::Vector3d& delta_torque,
                                       v1::ResolutionVariant variant = v1::RESOLUTION_VARIANT_UNSPECIFIED) {
  v1::AnalyzeWrenchRequest r;
  r.mutable_reference()->mutable_force()->set_z(kGripper);
  r.mutable_reference()->mutable_torque()->set_x(0.002);
  r.mutable_current()->mutable_force()->set_z(kGripper + held_tubes * kWeight);
  r.mutable_current()->mutable_torque()->set_x(0.002 + delta_torque.x());
  r.mutable_current()->mutable_torque()->set_y(delta_torque.y());
  r.mutable_current()->mutable_torque()->set_z(delta_torque.z());
  r.set_tube_mass(kMass);
  *r.mutable_tcp_pose() = ToProto(GraspTcp());
  r.set_variant(variant);
  return r;
}

v1::AnalyzeWrenchResponse Analyze(const v1::AnalyzeWrenchRequest& r) {
  return RunAnalyzeWrench(ValidateAnalyzeWrench(r, PlanningDefaults{}));
}

Eigen::Vector3d FromProto(const v1::Vector3& v) { return {v.x(), v.y(), v.z()}; }
Eigen::Quaterniond FromProto(const v1::Quaternion& q) { return {q.w(), q.x(), q.y(), q.z()}; }

TEST(RunAnalyzeWrench, OneTubeIsSingle) {
  const v1::AnalyzeWrenchResponse r = Analyze(WrenchRequest(1.0, {0.03, 0.0, 0.0}));
  EXPECT_EQ(r.outcome(), v1::HELD_OUTCOME_SINGLE);
  EXPECT_EQ(r.estimated_count(), 1u);
  EXPECT_NEAR(r.tube_weight(), 0.53955, 1e-12);
  // Upward force = force · up, up = (0, 0, −1) in this TCP: F_z_ref = −12 N.
  EXPECT_NEAR(r.expected_force(), -kGripper - 0.53955, 1e-12);
  EXPECT_NEAR(r.held_weight(), 0.53955, 1e-12);
  EXPECT_NEAR(r.tube_ratio(), 1.0, 1e-12);
  EXPECT_EQ(r.resolution_motions_size(), 0);
  EXPECT_FALSE(r.has_delta_torque_tcp());
}

TEST(RunAnalyzeWrench, BandEdgesFollowAlgorithm3) {
  // The thesis profile: F_tol = 0.25 N: 0.28 N gained (< weight − F_tol = 0.28955) is none, 0.30 N
  // single; 0.78 N single, 0.80 N (> weight + F_tol = 0.78955) multiple.
  PlanningDefaults thesis;
  thesis.profile = "thesis";
  const auto outcome = [&](double gained_newtons) {
    return RunAnalyzeWrench(ValidateAnalyzeWrench(
                                WrenchRequest(gained_newtons / kWeight, Eigen::Vector3d::Zero()), thesis))
        .outcome();
  };
  EXPECT_EQ(outcome(0.0), v1::HELD_OUTCOME_NONE);
  EXPECT_EQ(outcome(0.28), v1::HELD_OUTCOME_NONE);
  EXPECT_EQ(outcome(0.30), v1::HELD_OUTCOME_SINGLE);
  EXPECT_EQ(outcome(0.78), v1::HELD_OUTCOME_SINGLE);
  EXPECT_EQ(outcome(0.80), v1::HELD_OUTCOME_MULTIPLE);
}

TEST(RunAnalyzeWrench, TheFastProfilesBandIsAFifthOfATubesWeight) {
  // F_tol = min(0.25 N, 0.2 · 0.53955 N) = 0.10791 N: single from 0.43164 to 0.64746 N gained.
  // A tube with a third of another hanging from it (1.3 tubes, 0.70 N) is several, as it is not
  // with the thesis' 0.25 N (up to 1.46 tubes).
  const auto analyze = [](double gained_newtons) {
    return Analyze(WrenchRequest(gained_newtons / kWeight, {0.03, 0.0, 0.0}));
  };
  EXPECT_NEAR(analyze(0.5).force_tolerance(), 0.2 * kWeight, 1e-12);
  EXPECT_EQ(analyze(0.42).outcome(), v1::HELD_OUTCOME_NONE);
  EXPECT_EQ(analyze(0.44).outcome(), v1::HELD_OUTCOME_SINGLE);
  EXPECT_EQ(analyze(0.64).outcome(), v1::HELD_OUTCOME_SINGLE);
  EXPECT_EQ(analyze(0.66).outcome(), v1::HELD_OUTCOME_MULTIPLE);
  const v1::AnalyzeWrenchResponse partial = analyze(1.3 * kWeight);
  EXPECT_EQ(partial.outcome(), v1::HELD_OUTCOME_MULTIPLE);
  EXPECT_GT(partial.resolution_motions_size(), 0);
}

TEST(RunAnalyzeWrench, NothingHeldIsNone) {
  const v1::AnalyzeWrenchResponse r = Analyze(WrenchRequest(0.05 / kWeight, {0.04, 0.0, 0.0}));
  EXPECT_EQ(r.outcome(), v1::HELD_OUTCOME_NONE);
  EXPECT_EQ(r.estimated_count(), 0u);
  EXPECT_NEAR(r.held_weight(), 0.05, 1e-12);
  EXPECT_EQ(r.resolution_motions_size(), 0);
}

TEST(RunAnalyzeWrench, ThreeTubesGiveARotationAboutTheTcp) {
  // ΔM = (0.08, −0.06, 0.01) N·m: horizontal part (0.08, −0.06, 0), |ΔM| = 0.1, axis (0.8, −0.6, 0).
  const v1::AnalyzeWrenchResponse r = Analyze(WrenchRequest(3.0, {0.08, -0.06, 0.01}));
  EXPECT_EQ(r.outcome(), v1::HELD_OUTCOME_MULTIPLE);
  EXPECT_EQ(r.estimated_count(), 3u);
  EXPECT_NEAR(r.held_weight(), 3.0 * 0.53955, 1e-12);
  EXPECT_NEAR(r.tube_ratio(), 3.0, 1e-12);
  ASSERT_TRUE(r.has_delta_torque_tcp());
  EXPECT_LT((FromProto(r.delta_torque_tcp()) - Eigen::Vector3d(0.08, -0.06, 0.0)).norm(), 1e-12);

  // The profile's variant, torque_axis_then_perpendicular: about the torque axis, then (several
  // still hanging) about the horizontal axis perpendicular to it, by the same angle.
  ASSERT_EQ(r.resolution_motions_size(), 2);
  const v1::ResolutionMotion& m = r.resolution_motions(0);
  const Eigen::Vector3d axis(0.8, -0.6, 0.0);
  EXPECT_LT((FromProto(m.axis_tcp()) - axis).norm(), 1e-12);
  const double angle = ProfileParams("fast").wrench.rotation_angle;  // the server's default profile
  EXPECT_NEAR(angle, 55.0 * M_PI / 180.0, 1e-12);
  EXPECT_NEAR(m.angle(), angle, 1e-12);
  EXPECT_EQ(m.yaw(), 0.0);
  EXPECT_FALSE(m.description().empty());
  ASSERT_EQ(m.waypoints_size(), 1);
  const v1::Pose& pose = m.waypoints(0).tcp_pose();
  // A pure rotation about the TCP origin: the position stays, the orientation turns by 55° about
  // the torque axis of the lift-time TCP frame.
  EXPECT_LT((FromProto(pose.position()) - GraspTcp().translation()).norm(), 1e-12);
  const Eigen::Matrix3d expected = GraspTcp().linear() * Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  EXPECT_TRUE(FromProto(pose.orientation()).toRotationMatrix().isApprox(expected, 1e-12));
  const v1::ResolutionMotion& second = r.resolution_motions(1);
  const Eigen::Vector3d perpendicular = FromProto(second.axis_tcp());
  EXPECT_NEAR(perpendicular.norm(), 1.0, 1e-12);
  EXPECT_NEAR(perpendicular.dot(axis), 0.0, 1e-12);
  EXPECT_NEAR(perpendicular.z(), 0.0, 1e-12);  // horizontal
  EXPECT_NEAR(second.angle(), angle, 1e-12);
}

TEST(RunAnalyzeWrench, VariantsOfTheRequestAreUsed) {
  const Eigen::Vector3d delta(0.0, 0.05, 0.0);
  const v1::AnalyzeWrenchResponse perpendicular =
      Analyze(WrenchRequest(2.0, delta, v1::RESOLUTION_VARIANT_PERPENDICULAR));
  ASSERT_EQ(perpendicular.resolution_motions_size(), 2);
  const double angle = ProfileParams("fast").wrench.rotation_angle;
  EXPECT_NEAR(perpendicular.resolution_motions(0).angle(), angle, 1e-12);
  EXPECT_NEAR(perpendicular.resolution_motions(1).angle(), -angle, 1e-12);
  // Perpendicular to ΔM (along y) and to the vertical: ±x.
  EXPECT_NEAR(std::abs(perpendicular.resolution_motions(0).axis_tcp().x()), 1.0, 1e-12);

  const v1::AnalyzeWrenchResponse joint_safe =
      Analyze(WrenchRequest(2.0, delta, v1::RESOLUTION_VARIANT_JOINT_SAFE));
  ASSERT_EQ(joint_safe.resolution_motions_size(), 1);
  const v1::ResolutionMotion& m = joint_safe.resolution_motions(0);
  ASSERT_EQ(m.waypoints_size(), 2);  // yaw, then tilt
  EXPECT_NEAR(std::abs(m.yaw()), M_PI / 2, 1e-9);
  for (const v1::ResolutionWaypoint& w : m.waypoints()) {
    EXPECT_LT((FromProto(w.tcp_pose().position()) - GraspTcp().translation()).norm(), 1e-12);
  }
  // The yaw waypoint keeps the tool axis vertical.
  const Eigen::Matrix3d R_yawed = FromProto(m.waypoints(0).tcp_pose().orientation()).toRotationMatrix();
  EXPECT_NEAR((R_yawed * Eigen::Vector3d::UnitZ()).z(), -1.0, 1e-12);
}

TEST(RunAnalyzeWrench, MultipleWithoutATorqueChangeHasNoMotion) {
  const v1::AnalyzeWrenchResponse r = Analyze(WrenchRequest(2.0, {0.001, 0.002, 0.3}));
  EXPECT_EQ(r.outcome(), v1::HELD_OUTCOME_MULTIPLE);
  EXPECT_EQ(r.estimated_count(), 2u);
  EXPECT_EQ(r.resolution_motions_size(), 0);  // |ΔM| 0.0022 < min_torque 0.005
  ASSERT_TRUE(r.has_delta_torque_tcp());
  EXPECT_LT((FromProto(r.delta_torque_tcp()) - Eigen::Vector3d(0.001, 0.002, 0.0)).norm(), 1e-12);
}

TEST(ProtoConvert, EnumsRoundTrip) {
  for (const ResolutionVariant v : {ResolutionVariant::kTorqueAxis, ResolutionVariant::kTorqueAxisNegative,
                                    ResolutionVariant::kPerpendicular, ResolutionVariant::kJointSafe,
                                    ResolutionVariant::kTorqueAxisThenPerpendicular}) {
    EXPECT_EQ(tubepick::FromProto(ToProto(v)), v);
  }
  EXPECT_EQ(tubepick::FromProto(v1::RESOLUTION_VARIANT_UNSPECIFIED), std::nullopt);
  EXPECT_EQ(tubepick::FromProto(static_cast<v1::ResolutionVariant>(42)), std::nullopt);
  EXPECT_EQ(ToProto(HeldOutcome::kNone), v1::HELD_OUTCOME_NONE);
  EXPECT_EQ(ToProto(HeldOutcome::kSingle), v1::HELD_OUTCOME_SINGLE);
  EXPECT_EQ(ToProto(HeldOutcome::kMultiple), v1::HELD_OUTCOME_MULTIPLE);
}

}  // namespace
}  // namespace tubepick::server
