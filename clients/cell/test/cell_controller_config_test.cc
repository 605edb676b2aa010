#include "clients/cell/cell_controller_config.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/common/errors.h"

namespace tubepick::cell {
namespace {

using std::chrono::milliseconds;

/// Every field of `a` and `b` equal (the home pose to 1e-12: it goes through a quaternion).
void ExpectSame(const CellControllerParams& a, const CellControllerParams& b) {
  EXPECT_EQ(a.transit_speed, b.transit_speed);
  EXPECT_EQ(a.approach_speed, b.approach_speed);
  EXPECT_EQ(a.lift_speed, b.lift_speed);
  EXPECT_EQ(a.resolution_speed, b.resolution_speed);
  EXPECT_EQ(a.resolution_hold_over_bin, b.resolution_hold_over_bin);
  EXPECT_EQ(a.resolution_wall_margin, b.resolution_wall_margin);
  EXPECT_EQ(a.resolution_dwell, b.resolution_dwell);
  EXPECT_EQ(a.resolution_replan, b.resolution_replan);
  EXPECT_EQ(a.resolution_extra_motions, b.resolution_extra_motions);
  EXPECT_EQ(a.resolution_rest_load, b.resolution_rest_load);
  EXPECT_EQ(a.approach_height, b.approach_height);
  EXPECT_EQ(a.transit_clearance, b.transit_clearance);
  EXPECT_EQ(a.release_height, b.release_height);
  EXPECT_EQ(a.place_approach_height, b.place_approach_height);
  ASSERT_EQ(a.X_BinHome.has_value(), b.X_BinHome.has_value());
  if (a.X_BinHome) {
    EXPECT_TRUE(a.X_BinHome->isApprox(*b.X_BinHome, 1e-12));
  }
  EXPECT_EQ(a.check_tool_clearance, b.check_tool_clearance);
  EXPECT_EQ(a.tool.finger_size, b.tool.finger_size);
  EXPECT_EQ(a.tool.finger_tip_depth, b.tool.finger_tip_depth);
  EXPECT_EQ(a.tool.housing_size, b.tool.housing_size);
  EXPECT_EQ(a.tool.housing_gap, b.tool.housing_gap);
  EXPECT_EQ(a.tool.margin, b.tool.margin);
  EXPECT_EQ(a.nudge.enabled, b.nudge.enabled);
  EXPECT_EQ(a.nudge.max_nudges_per_bin, b.nudge.max_nudges_per_bin);
  EXPECT_EQ(a.nudge.near_wall_distance, b.nudge.near_wall_distance);
  EXPECT_EQ(a.nudge.target_wall_distance, b.nudge.target_wall_distance);
  EXPECT_EQ(a.nudge.push_gain, b.nudge.push_gain);
  EXPECT_EQ(a.nudge.min_push, b.nudge.min_push);
  EXPECT_EQ(a.nudge.max_push, b.nudge.max_push);
  EXPECT_EQ(a.nudge.press_depth, b.nudge.press_depth);
  EXPECT_EQ(a.nudge.tilt, b.nudge.tilt);
  EXPECT_EQ(a.nudge.speed, b.nudge.speed);
  EXPECT_EQ(a.nudge.sample_spacing, b.nudge.sample_spacing);
  EXPECT_EQ(a.nudge.tube_clearance, b.nudge.tube_clearance);
  EXPECT_EQ(a.nudge.repeat_radius, b.nudge.repeat_radius);
  EXPECT_EQ(a.cell_check.enabled, b.cell_check.enabled);
  EXPECT_EQ(a.cell_check.bin_margin, b.cell_check.bin_margin);
  EXPECT_EQ(a.cell_check.place_position_tolerance, b.cell_check.place_position_tolerance);
  EXPECT_EQ(a.cell_check.place_rotation_tolerance, b.cell_check.place_rotation_tolerance);
  EXPECT_EQ(a.tube_mass_check.enabled, b.tube_mass_check.enabled);
  EXPECT_EQ(a.tube_mass_check.limits.window, b.tube_mass_check.limits.window);
  EXPECT_EQ(a.tube_mass_check.limits.min_lifts, b.tube_mass_check.limits.min_lifts);
  EXPECT_EQ(a.tube_mass_check.limits.max_tubes_per_lift, b.tube_mass_check.limits.max_tubes_per_lift);
  EXPECT_EQ(a.tube_mass_check.limits.max_off_whole, b.tube_mass_check.limits.max_off_whole);
  EXPECT_EQ(a.gripper_speed, b.gripper_speed);
  EXPECT_EQ(a.gripper_force, b.gripper_force);
  EXPECT_EQ(a.ft_settle_samples, b.ft_settle_samples);
  EXPECT_EQ(a.ft_samples, b.ft_samples);
  EXPECT_EQ(a.profile, b.profile);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.max_plans, b.max_plans);
  EXPECT_EQ(a.max_plans_per_scan, b.max_plans_per_scan);
  EXPECT_EQ(a.failed_grasp_radius, b.failed_grasp_radius);
  EXPECT_EQ(a.disable_simulation, b.disable_simulation);
  EXPECT_EQ(a.resolution_variant, b.resolution_variant);
  EXPECT_EQ(a.plan_deadline, b.plan_deadline);
  EXPECT_EQ(a.analyze_deadline, b.analyze_deadline);
  EXPECT_EQ(a.max_attempts_per_tube, b.max_attempts_per_tube);
  EXPECT_EQ(a.max_attempts_per_bin, b.max_attempts_per_bin);
  EXPECT_EQ(a.tubes_per_bin, b.tubes_per_bin);
  EXPECT_EQ(a.max_consecutive_failures, b.max_consecutive_failures);
  EXPECT_EQ(a.scanner_timeout, b.scanner_timeout);
  EXPECT_EQ(a.robot_timeout, b.robot_timeout);
  EXPECT_EQ(a.gripper_timeout, b.gripper_timeout);
  EXPECT_EQ(a.ft_timeout, b.ft_timeout);
}

/// The InvalidArgument message of parsing `yaml`, or "" when it parses.
std::string ParseError(const std::string& yaml) {
  try {
    ParseCellControllerParams(yaml);
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

TEST(CellControllerConfigTest, EmptyDocumentGivesTheDefaults) {
  ExpectSame(ParseCellControllerParams(""), CellControllerParams{});
}

TEST(CellControllerConfigTest, DumpOfTheDefaultsParsesBackToTheDefaults) {
  const std::string yaml = DumpCellControllerParams(CellControllerParams{});
  ExpectSame(ParseCellControllerParams(yaml), CellControllerParams{});
  // Durations are seconds, not milliseconds.
  EXPECT_NE(yaml.find("robot_timeout: 60"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("plan_deadline: 180"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("home_pose_in_bin: null"), std::string::npos) << yaml;
}

TEST(CellControllerConfigTest, DumpOfModifiedParamsParsesBackToThem) {
  CellControllerParams p;
  p.transit_speed = 0.3;
  p.approach_speed = 1.0 / 3.0;  // not a short decimal: needs all 17 digits
  p.release_height = 0.0;
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(2.5, Eigen::Vector3d(1.0, 0.2, -0.3).normalized()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.1, -0.25, 0.7);
  p.X_BinHome = X;
  p.check_tool_clearance = false;
  p.tool.finger_size = Eigen::Vector3d(0.03, 0.012, 0.06);
  p.tool.finger_tip_depth = -0.002;
  p.tool.margin = 0.0;
  p.nudge.enabled = false;
  p.nudge.max_nudges_per_bin = 0;
  p.nudge.tilt = 0.55;
  p.gripper_force = 120.0;
  p.ft_settle_samples = 0;
  p.profile = "thesis \"quoted\"";
  p.seed = 123456789012345ULL;
  p.max_plans = 0;
  p.disable_simulation = true;
  p.resolution_variant = v1::RESOLUTION_VARIANT_JOINT_SAFE;
  p.plan_deadline = milliseconds(1);
  p.analyze_deadline = milliseconds(12'345);
  p.max_attempts_per_bin = 1;
  p.ft_timeout = milliseconds(2'500);
  // Every other field off its default too, so a key the dump forgets fails the comparison.
  p.lift_speed = 0.11;
  p.resolution_speed = 0.12;
  p.resolution_hold_over_bin = false;
  p.resolution_wall_margin = 0.09;
  p.resolution_dwell = 0.25;
  p.resolution_replan = false;
  p.resolution_extra_motions = 2;
  p.resolution_rest_load = 1.5;
  p.tubes_per_bin = 20;
  p.approach_height = 0.13;
  p.transit_clearance = 0.31;
  p.place_approach_height = 0.14;
  p.tool.housing_size = Eigen::Vector3d(0.07, 0.14, 0.1);
  p.tool.housing_gap = 0.021;
  p.nudge.near_wall_distance = 0.11;
  p.nudge.target_wall_distance = 0.16;
  p.nudge.push_gain = 1.5;
  p.nudge.min_push = 0.05;
  p.nudge.max_push = 0.2;
  p.nudge.press_depth = 0.005;
  p.nudge.speed = 0.04;
  p.nudge.sample_spacing = 0.01;
  p.gripper_speed = 0.07;
  p.cell_check.enabled = false;
  p.cell_check.bin_margin = 0.035;
  p.cell_check.place_position_tolerance = 0.08;
  p.cell_check.place_rotation_tolerance = 0.25;
  p.tube_mass_check.enabled = false;
  p.tube_mass_check.limits.window = 7;
  p.tube_mass_check.limits.min_lifts = 4;
  p.tube_mass_check.limits.max_tubes_per_lift = 4;
  p.tube_mass_check.limits.max_off_whole = 0.15;
  p.ft_samples = 9;
  p.max_plans_per_scan = 3;
  p.failed_grasp_radius = 0.025;
  p.max_attempts_per_tube = 5;
  p.max_consecutive_failures = 7;
  p.scanner_timeout = milliseconds(31'000);
  p.robot_timeout = milliseconds(61'000);
  p.gripper_timeout = milliseconds(11'000);

  const std::string yaml = DumpCellControllerParams(p);
  const CellControllerParams back = ParseCellControllerParams(yaml);
  ExpectSame(back, p);
  EXPECT_NE(yaml.find("ft_timeout: 2.5"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("resolution_variant: joint_safe"), std::string::npos) << yaml;
  // The dump is stable: dumping what was read gives the same numbers (pose aside) and keys.
  ExpectSame(ParseCellControllerParams(DumpCellControllerParams(back)), p);
}

TEST(CellControllerConfigTest, PartialFileOverridesOnlyItsKeys) {
  const CellControllerParams p = ParseCellControllerParams(
      "lift_speed: 0.2\n"
      "robot_timeout: 90\n"
      "tool:\n  margin: 0.005\n"
      "nudge:\n  max_push: 0.3\n"
      "home_pose_in_bin:\n  position: [0.1, 0.2, 0.8]\n  orientation_xyzw: [1, 0, 0, 0]\n");
  EXPECT_EQ(p.lift_speed, 0.2);
  EXPECT_EQ(p.robot_timeout, milliseconds(90'000));
  EXPECT_EQ(p.tool.margin, 0.005);
  EXPECT_EQ(p.tool.housing_gap, ToolGeometry{}.housing_gap);
  EXPECT_EQ(p.nudge.max_push, 0.3);
  EXPECT_EQ(p.nudge.min_push, NudgeParams{}.min_push);
  ASSERT_TRUE(p.X_BinHome.has_value());
  EXPECT_TRUE(p.X_BinHome->translation().isApprox(Eigen::Vector3d(0.1, 0.2, 0.8)));
  // A half turn about x: the TCP's z points down.
  EXPECT_NEAR((p.X_BinHome->linear() * Eigen::Vector3d::UnitZ()).z(), -1.0, 1e-12);
  EXPECT_EQ(p.approach_speed, CellControllerParams{}.approach_speed);
}

TEST(CellControllerConfigTest, UnknownKeysAreErrorsNamingTheKeyPath) {
  EXPECT_NE(ParseError("transit_sped: 0.3\n").find("transit_sped"), std::string::npos);
  EXPECT_NE(ParseError("nudge:\n  max_psh: 0.3\n").find("nudge.max_psh"), std::string::npos);
  EXPECT_NE(ParseError("tool:\n  check: true\n").find("tool.check"), std::string::npos);
  EXPECT_NE(
      ParseError("home_pose_in_bin:\n  position: [0, 0, 1]\n  orientation_xyzw: [1, 0, 0, 0]\n  frame: bin\n")
          .find("home_pose_in_bin.frame"),
      std::string::npos);
  EXPECT_THROW(ParseCellControllerParams("robot_timeout_ms: 60000\n"), InvalidArgument);
}

TEST(CellControllerConfigTest, WrongTypesAreErrorsNamingTheKeyPath) {
  EXPECT_NE(ParseError("transit_speed: fast\n").find("transit_speed: expected"), std::string::npos)
      << ParseError("transit_speed: fast\n");
  EXPECT_NE(ParseError("nudge:\n  enabled: maybe\n").find("nudge.enabled"), std::string::npos);
  EXPECT_NE(ParseError("max_plans: -1\n").find("max_plans"), std::string::npos);
  EXPECT_NE(ParseError("max_plans: 2.5\n").find("max_plans"), std::string::npos);
  EXPECT_NE(ParseError("tool:\n  finger_size: [0.02, 0.01]\n").find("tool.finger_size"), std::string::npos);
  EXPECT_NE(ParseError("nudge: 3\n").find("nudge: expected a mapping"), std::string::npos)
      << ParseError("nudge: 3\n");
  EXPECT_NE(ParseError("robot_timeout: soon\n").find("robot_timeout"), std::string::npos);
  EXPECT_NE(
      ParseError("resolution_variant: sideways\n").find("resolution_variant: unknown variant 'sideways'"),
      std::string::npos);
  EXPECT_NE(ParseError("transit_speed: [\n").find("syntax error"), std::string::npos);
}

TEST(CellControllerConfigTest, OutOfRangeValuesNameTheFieldAndTheValue) {
  EXPECT_NE(ParseError("transit_speed: -0.5\n").find("transit_speed: must be a positive number, got -0.5"),
            std::string::npos)
      << ParseError("transit_speed: -0.5\n");
  EXPECT_NE(ParseError("max_attempts_per_bin: 0\n").find("max_attempts_per_bin: must be at least 1, got 0"),
            std::string::npos);
  EXPECT_NE(ParseError("robot_timeout: 0\n").find("robot_timeout: must be positive"), std::string::npos);
  EXPECT_NE(
      ParseError("resolution_dwell: -1\n").find("resolution_dwell: must be a non-negative number, got -1"),
      std::string::npos);
  EXPECT_NE(ParseError("resolution_extra_motions: 11\n")
                .find("resolution_extra_motions: 11 is more than 10 (each is a turn, a pause and a reading)"),
            std::string::npos)
      << ParseError("resolution_extra_motions: 11\n");
  // At or under one tube weight the grasped tube alone would do: never lighter, always the lowest.
  EXPECT_NE(ParseError("resolution_rest_load: 0.8\n")
                .find("resolution_rest_load: 0.8 tube weights; 0 (turn at the hold pose) or more than 1"),
            std::string::npos)
      << ParseError("resolution_rest_load: 0.8\n");
  EXPECT_NE(ParseError("resolution_rest_load: 12\n").find("and at most 10"), std::string::npos);
  // The pause is one robot call: it must end within the robot's timeout.
  EXPECT_NE(ParseError("resolution_dwell: 5\nrobot_timeout: 5\n")
                .find("resolution_dwell: 5 s is not below robot_timeout (5 s)"),
            std::string::npos)
      << ParseError("resolution_dwell: 5\nrobot_timeout: 5\n");
  EXPECT_NE(ParseError("failed_grasp_radius: -0.01\n")
                .find("failed_grasp_radius: must be a finite distance >= 0 m (0 = off), got -0.01"),
            std::string::npos)
      << ParseError("failed_grasp_radius: -0.01\n");
  // Below a millisecond rounds to 0 ms: rejected, not silently infinite or zero.
  EXPECT_NE(ParseError("ft_timeout: 0.0001\n").find("ft_timeout: must be positive"), std::string::npos);
  EXPECT_NE(
      ParseError("plan_deadline: -3\n").find("plan_deadline: must be positive (at least 0.001 s), got -3 s"),
      std::string::npos)
      << ParseError("plan_deadline: -3\n");
  EXPECT_NE(ParseError("scanner_timeout: 1e300\n").find("scanner_timeout: 1e+300 s is out of range"),
            std::string::npos)
      << ParseError("scanner_timeout: 1e300\n");
  EXPECT_NE(ParseError("tool:\n  finger_size: [0.02, 0, 0.05]\n").find("tool.finger_size[1]"),
            std::string::npos);
  EXPECT_NE(
      ParseError("tool:\n  margin: -0.001\n").find("tool.margin: must be a non-negative number, got -0.001"),
      std::string::npos);
  EXPECT_NE(ParseError("nudge:\n  min_push: 0.3\n").find("nudge.min_push: 0.3 exceeds nudge.max_push 0.22"),
            std::string::npos);
  EXPECT_NE(ParseError("nudge:\n  tilt: 1.6\n").find("nudge.tilt: must be in [0, pi/2) rad, got 1.6"),
            std::string::npos);
  EXPECT_NE(ParseError("home_pose_in_bin:\n  position: [0, 0, 1]\n  orientation_xyzw: [1, 1, 0, 0]\n")
                .find("home_pose_in_bin.orientation_xyzw: quaternion must be unit length"),
            std::string::npos);
  EXPECT_NE(ParseError("home_pose_in_bin:\n  position: [0, 0, 1]\n").find("home_pose_in_bin: needs"),
            std::string::npos);
  EXPECT_NE(ParseError("gripper_force: .nan\n").find("gripper_force"), std::string::npos);
  EXPECT_NE(
      ParseError("place_surface_height: .inf\n").find("place_surface_height: value must be finite, got inf"),
      std::string::npos)
      << ParseError("place_surface_height: .inf\n");
}

TEST(CellControllerConfigTest, FaultHandlingKeysRejectBadValuesNamingThem) {
  EXPECT_NE(
      ParseError("safe_release_height: 0\n").find("safe_release_height: must be a positive number, got 0"),
      std::string::npos)
      << ParseError("safe_release_height: 0\n");
  EXPECT_NE(ParseError("ft_spike_force: -1\n").find("ft_spike_force: must be a positive number, got -1"),
            std::string::npos);
  EXPECT_NE(ParseError("ft_spike_torque: .nan\n").find("ft_spike_torque"), std::string::npos);
  EXPECT_NE(ParseError("scan_retries: -1\n").find("scan_retries"), std::string::npos);
  EXPECT_NE(ParseError("ft_unsettled_retries: -1\n").find("ft_unsettled_retries: -1 is out of range"),
            std::string::npos)
      << ParseError("ft_unsettled_retries: -1\n");
  EXPECT_NE(ParseError("ft_read_retries: two\n").find("ft_read_retries"), std::string::npos);
  EXPECT_NE(ParseError("place_step: -0.02\n").find("place_step: must be a non-negative number, got -0.02"),
            std::string::npos)
      << ParseError("place_step: -0.02\n");
  EXPECT_EQ(ParseCellControllerParams("place_step: 0.01\n").place_step, 0.01);
  EXPECT_NE(ParseError("safe_release_step: -0.03\n")
                .find("safe_release_step: must be a non-negative number, got -0.03"),
            std::string::npos)
      << ParseError("safe_release_step: -0.03\n");
  EXPECT_EQ(ParseCellControllerParams("safe_release_step: 0.05\n").safe_release_step, 0.05);
  EXPECT_NE(
      ParseError("put_back_margin: -0.1\n").find("put_back_margin: must be a non-negative number, got -0.1"),
      std::string::npos)
      << ParseError("put_back_margin: -0.1\n");
  EXPECT_EQ(ParseCellControllerParams("put_back_margin: 0.2\n").put_back_margin, 0.2);
  EXPECT_NE(
      ParseError("put_back_step: -0.02\n").find("put_back_step: must be a non-negative number, got -0.02"),
      std::string::npos)
      << ParseError("put_back_step: -0.02\n");
  EXPECT_EQ(ParseCellControllerParams("put_back_step: 0\n").put_back_step, 0.0);
  EXPECT_NE(ParseError("wall_watch:\n  gone_distance: 0\n").find("wall_watch.gone_distance"),
            std::string::npos)
      << ParseError("wall_watch:\n  gone_distance: 0\n");
  EXPECT_NE(
      ParseError("wall_watch:\n  min_points: 0\n").find("wall_watch.min_points: must be at least 1, got 0"),
      std::string::npos)
      << ParseError("wall_watch:\n  min_points: 0\n");
  EXPECT_NE(ParseError("wall_watch:\n  from_wall: -0.01\n").find("wall_watch.from_wall"), std::string::npos);
  EXPECT_EQ(ParseCellControllerParams("wall_watch:\n  from_wall: 0.03\n").wall_watch.from_wall, 0.03);
}

TEST(CellControllerConfigTest, CellCheckKeysAreReadAndCheckedNamingThem) {
  const CellControllerParams p =
      ParseCellControllerParams("cell_check:\n  bin_margin: 0.05\n  place_rotation_tolerance: 0.2\n");
  EXPECT_EQ(p.cell_check.bin_margin, 0.05);
  EXPECT_EQ(p.cell_check.place_rotation_tolerance, 0.2);
  EXPECT_TRUE(p.cell_check.enabled);
  EXPECT_EQ(p.cell_check.place_position_tolerance, CellFrameCheckParams{}.place_position_tolerance);
  const std::string yaml = DumpCellControllerParams(CellControllerParams{});
  EXPECT_NE(yaml.find("cell_check:"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("place_position_tolerance: 0.05"), std::string::npos) << yaml;

  EXPECT_NE(ParseError("cell_check:\n  bin_margin: -0.01\n")
                .find("cell_check.bin_margin: must be a non-negative number, got -0.01"),
            std::string::npos)
      << ParseError("cell_check:\n  bin_margin: -0.01\n");
  EXPECT_NE(ParseError("cell_check:\n  place_position_tolerance: .nan\n")
                .find("cell_check.place_position_tolerance"),
            std::string::npos);
  EXPECT_NE(ParseError("cell_check:\n  place_rotation_tolerance: 20\n")
                .find("cell_check.place_rotation_tolerance: must be in [0, pi] rad, got 20 (degrees?)"),
            std::string::npos)
      << ParseError("cell_check:\n  place_rotation_tolerance: 20\n");
  EXPECT_NE(ParseError("cell_check:\n  grasp_above_walls: -0.3\n")
                .find("cell_check.grasp_above_walls: must be a non-negative number, got -0.3"),
            std::string::npos)
      << ParseError("cell_check:\n  grasp_above_walls: -0.3\n");
  EXPECT_EQ(
      ParseCellControllerParams("cell_check:\n  grasp_above_walls: 0.25\n").cell_check.grasp_above_walls,
      0.25);
  EXPECT_NE(ParseError("cell_check:\n  margin: 0.1\n").find("cell_check.margin"), std::string::npos);
  EXPECT_NE(ParseError("cell_check:\n  enabled: perhaps\n").find("cell_check.enabled"), std::string::npos);
}

TEST(CellControllerConfigTest, NudgeClearanceAndRepeatKeysAreReadAndCheckedNamingThem) {
  const CellControllerParams p =
      ParseCellControllerParams("nudge:\n  tube_clearance: 0.01\n  repeat_radius: 0.002\n");
  EXPECT_EQ(p.nudge.tube_clearance, 0.01);
  EXPECT_EQ(p.nudge.repeat_radius, 0.002);
  for (const std::string key : {"tube_clearance", "repeat_radius"}) {
    const std::string error = ParseError("nudge:\n  " + key + ": -0.01\n");
    EXPECT_NE(error.find("nudge." + key + ": must be a non-negative number, got -0.01"), std::string::npos)
        << error;
  }
}

TEST(CellControllerConfigTest, TubeMassCheckKeysAreReadAndCheckedNamingThem) {
  const CellControllerParams p =
      ParseCellControllerParams("tube_mass_check:\n  window: 8\n  max_off_whole: 0.25\n");
  EXPECT_EQ(p.tube_mass_check.limits.window, 8u);
  EXPECT_EQ(p.tube_mass_check.limits.max_off_whole, 0.25);
  EXPECT_TRUE(p.tube_mass_check.enabled);
  EXPECT_EQ(p.tube_mass_check.limits.min_lifts, TubeMassCheckParams{}.min_lifts);
  EXPECT_FALSE(ParseCellControllerParams("tube_mass_check:\n  enabled: false\n").tube_mass_check.enabled);
  const std::string yaml = DumpCellControllerParams(CellControllerParams{});
  EXPECT_NE(yaml.find("tube_mass_check:"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("max_off_whole: 0.2"), std::string::npos) << yaml;

  const std::string too_many = ParseError("tube_mass_check:\n  window: 2\n");
  EXPECT_NE(too_many.find("cell controller tube_mass_check.min_lifts: 3 is outside [1, window = 2]"),
            std::string::npos)
      << too_many;
  const std::string half = ParseError("tube_mass_check:\n  max_off_whole: 0.5\n");
  EXPECT_NE(half.find("tube_mass_check.max_off_whole: 0.5 is outside (0, 0.5)"), std::string::npos) << half;
  EXPECT_NE(ParseError("tube_mass_check:\n  tolerance: 0.1\n").find("tube_mass_check.tolerance"),
            std::string::npos);
}

TEST(CellControllerConfigTest, LoadNamesTheFile) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "tubepick_cell_controller_config_test.yaml";
  {
    std::ofstream out(path);
    out << "lift_speed: 0.15\nbogus: 1\n";
  }
  try {
    LoadCellControllerParams(path.string());
    ADD_FAILURE() << "an unknown key was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bogus"), std::string::npos) << e.what();
  }
  {
    std::ofstream out(path);
    out << "lift_speed: 0.15\n";
  }
  EXPECT_EQ(LoadCellControllerParams(path.string()).lift_speed, 0.15);
  std::filesystem::remove(path);
  EXPECT_THROW(LoadCellControllerParams(path.string()), InvalidArgument);
}

}  // namespace
}  // namespace tubepick::cell
