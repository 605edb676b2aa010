#include "devices/sim/sim_cell.h"

#include <cmath>
#include <cstdint>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "devices/sim/test/sim_test_util.h"

namespace tubepick::devices::sim {
namespace {

using namespace testing;  // NOLINT: the sim test helpers
using ::testing::HasSubstr;

/// Force along the vertical within this of the expected weight, N (noise σ 0.02 N per read, two
/// reads, plus the solver's residual).
constexpr double kForceTol = 0.08;

/// A straight tube along x on the floor, centred at x = 0, through five nodes.
physics::TubeGeometry StraightTube(int id, double radius, double length, double y = 0.0) {
  return PolylineTube(id,
                      {{-0.5 * length, y, radius},
                       {-0.25 * length, y, radius},
                       {0.0, y, radius},
                       {0.25 * length, y, radius},
                       {0.5 * length, y, radius}},
                      radius);
}

/// The sensor's upward force component: −weight held.
double UpForce(const WrenchReading& reading, const Eigen::Isometry3d& X_BinTcp) {
  return reading.force.dot(UpTcp(X_BinTcp));
}

TEST(SimCell, MaterialNamesRoundTrip) {
  EXPECT_EQ(ParseMaterial("pvc", "material"), Material::kPvc);
  EXPECT_EQ(ParseMaterial(ToString(Material::kRubber), "material"), Material::kRubber);
  try {
    ParseMaterial("steel", "cell.material");
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("cell.material"));
    EXPECT_THAT(e.what(), HasSubstr("steel"));
  }
  EXPECT_DOUBLE_EQ(ThesisTubes(Material::kRubber).mass, 0.110);
  EXPECT_DOUBLE_EQ(ThesisTubes(Material::kPvc).radius, 0.0125);
}

TEST(SimCell, InvalidParamsNameTheField) {
  SimCellParams params;
  params.physics.time_step = 0.0;
  try {
    SimCell cell(params);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("physics.time_step"));
  }
}

TEST(SimCell, ConstructionDropsEveryTubeIntoTheBin) {
  for (Material material : {Material::kPvc, Material::kRubber}) {
    SCOPED_TRACE(ToString(material));
    const SimCell cell(SimCellParams::Thesis(material, 7, 11));
    EXPECT_TRUE(cell.settled());
    EXPECT_EQ(cell.TubesInBin(), 7u);
    EXPECT_EQ(cell.TubesOutsideBin(), 0u);
    EXPECT_EQ(cell.TubesBin().size(), 7u);
    EXPECT_DOUBLE_EQ(cell.SimulatedSeconds(), 0.0);
    for (const Eigen::Vector3d& p : cell.TubeCentresOfMass()) {
      EXPECT_LT(p.z(), 0.12);  // lying in the bin, not balanced on a wall
    }
  }
}

/// The thesis cell with `trees` set-C trees (as published) of `material`.
SimCellParams TreeCell(Material material, std::uint32_t trees, std::uint64_t seed) {
  SimCellParams params = SimCellParams::Thesis(material, trees, seed);
  params.tube_shape = physics::RandomTubeParams::SetC();
  params.tube_shape->radius = params.cell.tube.radius;
  return params;
}

TEST(SimCell, BranchedTreesAreRigidInPvcAndJointedChainsInRubber) {
  SimCellParams params = TreeCell(Material::kPvc, 3, 5);
  SimCell cell(params);
  EXPECT_EQ(cell.TubesInBin(), 3u);
  const std::vector<physics::TubeGeometry> before = cell.TubesBin();
  ASSERT_EQ(before.size(), 3u);
  for (const physics::TubeGeometry& tree : before) {
    EXPECT_FALSE(tree.IsLinear());
    const Tube core = tree.ToTube();
    EXPECT_TRUE(core.branched());
    EXPECT_NEAR(core.length(), 0.75, 0.02);  // trunk 30 cm, branches 10 + 10 + 15 + 10 cm
  }
  // A scan moves nothing but time: every tree keeps its edge lengths (one rigid body each).
  (void)cell.scanner().Scan(kLong);
  const std::vector<physics::TubeGeometry> after = cell.TubesBin();
  for (std::size_t t = 0; t < before.size(); ++t) {
    ASSERT_EQ(after[t].edges.size(), before[t].edges.size());
    for (std::size_t e = 0; e < before[t].edges.size(); ++e) {
      const auto span = [](const physics::TubeGeometry& g, const physics::TubeEdge& edge) {
        return (g.Node(edge.node2).centre - g.Node(edge.node1).centre).norm();
      };
      EXPECT_NEAR(span(after[t], after[t].edges[e]), span(before[t], before[t].edges[e]), 1e-9);
    }
  }

  // Rubber trees: a chain of links per branch, held at the junctions by spring joints. They keep
  // their topology and their length, and the joints hold (every link keeps its length as the
  // tree settles and bends).
  params.material = Material::kRubber;
  SimCell rubber(params);
  EXPECT_EQ(rubber.TubesInBin(), 3u);
  const std::vector<physics::TubeGeometry> hoses = rubber.TubesBin();
  ASSERT_EQ(hoses.size(), 3u);
  for (const physics::TubeGeometry& tree : hoses) {
    EXPECT_FALSE(tree.IsLinear());
    const Tube core = tree.ToTube();
    ASSERT_TRUE(core.branched());
    EXPECT_EQ(core.nodes.size(), 6u);        // four free ends, two junctions
    EXPECT_NEAR(core.length(), 0.75, 0.03);  // link chords are a little shorter than the arcs
  }
  (void)rubber.scanner().Scan(kLong);
  rubber.Advance(1.0);
  const std::vector<physics::TubeGeometry> later = rubber.TubesBin();
  for (std::size_t t = 0; t < hoses.size(); ++t) {
    ASSERT_EQ(later[t].edges.size(), hoses[t].edges.size());
    for (std::size_t e = 0; e < hoses[t].edges.size(); ++e) {
      EXPECT_NEAR(later[t].edges[e].length, hoses[t].edges[e].length, 0.003) << "tree " << t << " link " << e;
    }
  }
}

TEST(SimCell, AHeapOfHosesAtRestFallsAsleepUntilTheToolTouchesIt) {
  // Ten rubber trees, 150 links of 7 g: contact noise spun links about their own axes at 0.2-0.5
  // rad/s, above the sleeping threshold, and kept the whole heap awake (every step simulated).
  SimCell cell(TreeCell(Material::kRubber, 10, 1));
  ASSERT_EQ(cell.TubesInBin(), 10u);
  cell.Advance(3.0);
  EXPECT_EQ(cell.AwakeTubeBodies(), 0u);

  // The gripper closes on the heap's highest link: what it touches wakes, and with it the heap
  // that link rests on.
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  for (const physics::TubeGeometry& tree : cell.TubesBin()) {
    for (const physics::TubeEdge& edge : tree.edges) {
      const Eigen::Vector3d p = tree.Node(edge.node1).centre, q = tree.Node(edge.node2).centre;
      if (p.z() + q.z() > a.z() + b.z()) a = p, b = q;
    }
  }
  const Eigen::Isometry3d X_grasp = *GraspFrame(0.5 * (a + b), b - a);
  cell.robot().ServoOn(kLong);
  cell.robot().MoveTo(Raised(X_grasp, 0.1), 0.25, kLong);
  EXPECT_EQ(cell.AwakeTubeBodies(), 0u);  // 10 cm above it
  EXPECT_EQ(Grasp(cell, X_grasp).object, GripperObject::kStoppedClosing);
  EXPECT_EQ(cell.HeldTubes().size(), 1u);
  cell.Advance(0.05);
  EXPECT_GT(cell.AwakeTubeBodies(), 10u);
  EXPECT_EQ(cell.TubesInBin(), 10u);
}

TEST(SimCell, IsolatedTubeLiftReadsItsWeightAndPlacesOutside) {
  SimCellParams params;
  params.seed = 4;
  const double r = params.cell.tube.radius, m = params.cell.tube.mass;
  SimCell cell(params, {StraightTube(1, r, 0.5)});
  ASSERT_TRUE(cell.settled());
  ASSERT_EQ(cell.TubesInBin(), 1u);
  cell.robot().ServoOn(kLong);
  cell.gripper().Activate(kLong);
  cell.ft_sensor().Bias(kLong);
  const WrenchReading empty = cell.ft_sensor().Read(kLong);
  EXPECT_NEAR(empty.force.norm(), 0.0, 0.08);  // biased: offsets gone, noise left

  // Grasp 15 cm from the −x end: the centre of mass is 10 cm along +x from the TCP.
  const Eigen::Isometry3d X_grasp = GraspAt(cell.TubesBin()[0], 0.15);
  const GripperStatus status = Grasp(cell, X_grasp);
  EXPECT_EQ(status.object, GripperObject::kStoppedClosing);
  EXPECT_NEAR(status.opening, 2 * r, 0.002);
  EXPECT_EQ(cell.HeldTubes(), std::vector<std::size_t>{0});
  // Closed on a tube that still lies on the floor: the floor carries it.
  const WrenchReading before = cell.ft_sensor().Read(kLong);
  EXPECT_NEAR(UpForce(before, cell.X_BinTcp()), 0.0, kForceTol);

  cell.robot().MoveThrough({Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.3)}, 0.25, kLong);
  EXPECT_NEAR(cell.X_BinTcp().translation().z(), X_grasp.translation().z() + 0.3, 1e-9);
  const WrenchReading after = cell.ft_sensor().Read(kLong);
  // Sign convention (core/wrench/wrench.h): the force the payload exerts on the sensor, so its
  // upward component is −m·g; with z_Tcp down, F_z = +m·g in the sensor axes.
  const double up = UpForce(after, cell.X_BinTcp()) - UpForce(before, cell.X_BinTcp());
  EXPECT_NEAR(up, -m * kG, kForceTol);
  EXPECT_NEAR(after.force.z(), m * kG, kForceTol);
  // Torque about the TCP: r × F with r = 0.1 m along the tube (x_Bin), F = −m·g z_Bin.
  const Eigen::Vector3d torque_Bin = cell.X_BinTcp().linear() * after.torque;
  EXPECT_NEAR(torque_Bin.y(), 0.1 * m * kG, 0.01);
  EXPECT_NEAR(torque_Bin.x(), 0.0, 0.01);
  EXPECT_EQ(cell.TubesInBin(), 0u);       // carried out of the bin volume
  EXPECT_EQ(cell.TubesOutsideBin(), 0u);  // but still held

  // Place: over the wall, down to the place frame, open.
  Eigen::Isometry3d X_place = cell.X_BinTcp();
  X_place.translation() = cell.cell().place.X_BinPlace.translation() + Eigen::Vector3d(0, 0, 0.05);
  cell.robot().MoveTo(Raised(X_place, 0.3), 0.25, kLong);
  cell.robot().MoveTo(X_place, 0.25, kLong);
  const GripperStatus opened = cell.gripper().Open(kLong);
  EXPECT_EQ(opened.object, GripperObject::kAtPosition);
  EXPECT_TRUE(cell.HeldTubes().empty());
  cell.Advance(1.0);
  EXPECT_EQ(cell.TubesOutsideBin(), 1u);
  EXPECT_EQ(cell.TubesInBin(), 0u);
  EXPECT_EQ(cell.TubesInPlaceZone(), 1u);
  EXPECT_EQ(cell.TubesElsewhere(), 0u);
  EXPECT_LT(cell.TubeCentresOfMass()[0].z(), 0.03);  // on the ground
}

/// An isolated tube grasped in the middle and lifted 0.3 m.
void GraspAndLift(SimCell& cell) {
  cell.robot().ServoOn(kLong);
  cell.gripper().Activate(kLong);
  ASSERT_EQ(Grasp(cell, GraspAt(cell.TubesBin()[0], 0.25)).object, GripperObject::kStoppedClosing);
  cell.robot().MoveThrough({Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.3)}, 0.25, kLong);
  ASSERT_EQ(cell.HeldTubes().size(), 1u);
}

TEST(SimCell, ArmedSlipDropsTheHeldTubeMidMotionAndTheGripperSaysSo) {
  SimCellParams params;
  SimCell cell(params, {StraightTube(1, params.cell.tube.radius, 0.5)});
  GraspAndLift(cell);
  const double y_start = cell.X_BinTcp().translation().y();
  cell.ArmSlip(0.5);  // half a second into the next motion
  Eigen::Isometry3d X_across = cell.X_BinTcp();
  X_across.translation().y() = 0.8;
  cell.robot().MoveTo(X_across, 0.25, kLong);
  EXPECT_TRUE(cell.HeldTubes().empty());
  EXPECT_EQ(cell.fault_events().slips, 1u);
  EXPECT_EQ(cell.gripper().Status(kLong).object, GripperObject::kAtPosition);
  cell.Advance(2.0);
  // It fell soon after the start, over the bin (0.5 s at 0.5 m/s² moves the TCP 6 cm), and slid a
  // little further with the motion's momentum.
  EXPECT_EQ(cell.TubesInBin(), 1u);
  EXPECT_GT(cell.TubeCentresOfMass()[0].y(), y_start);
  EXPECT_LT(cell.TubeCentresOfMass()[0].y(), 0.5 * params.cell.bin.inner_size.y());
  EXPECT_EQ(cell.TubesElsewhere(), 0u);
}

TEST(SimCell, AHoldKeepsTheToolStillWhileTheSimulationRuns) {
  SimCellParams params;
  SimCell cell(params, {StraightTube(1, params.cell.tube.radius, 0.5)});
  GraspAndLift(cell);
  const Eigen::Isometry3d X_held = cell.X_BinTcp();
  const double t0 = cell.SimulatedSeconds();
  cell.ArmSlip(0.5);  // injected faults tick on while the arm holds still
  cell.robot().Hold(1.0, kLong);
  EXPECT_NEAR(cell.SimulatedSeconds() - t0, 1.0, params.physics.time_step);
  EXPECT_TRUE(cell.X_BinTcp().isApprox(X_held, 1e-12));
  EXPECT_EQ(cell.fault_events().slips, 1u);
  EXPECT_TRUE(cell.HeldTubes().empty());
  // The tube fell during the hold: half a second of falling from 0.3 m put it on the floor.
  EXPECT_LT(cell.TubeCentresOfMass()[0].z(), 0.05);

  EXPECT_THAT([&] { cell.robot().Hold(-1.0, kLong); },
              ::testing::ThrowsMessage<DeviceFault>(HasSubstr("-1 s")));
  EXPECT_THROW(cell.robot().Hold(std::nan(""), kLong), DeviceFault);
  const double t1 = cell.SimulatedSeconds();
  EXPECT_THAT([&] { cell.robot().Hold(2.0, Timeout(500)); },
              ::testing::ThrowsMessage<DeviceTimeout>(HasSubstr("exceeds the timeout of 0.500 s")));
  EXPECT_NEAR(cell.SimulatedSeconds() - t1, 0.5, params.physics.time_step);
}

TEST(SimCell, ASnaggedTubeStaysOnTheOpenToolUntilItOpensAgain) {
  SimCellParams params;
  SimCell cell(params, {StraightTube(1, params.cell.tube.radius, 0.5)});
  GraspAndLift(cell);
  cell.ft_sensor().Bias(kLong);  // zero with the tube held: its weight reads as the loss of it
  cell.ArmSnag();
  const GripperStatus opened = cell.gripper().Open(kLong);
  EXPECT_EQ(opened.object, GripperObject::kAtPosition);  // the fingers opened: no object
  EXPECT_GT(opened.opening, 0.05);
  EXPECT_EQ(cell.fault_events().snags, 1u);
  cell.Advance(1.0);
  ASSERT_EQ(cell.HeldTubes().size(), 1u);  // but the tube still hangs on the tool
  EXPECT_EQ(cell.TubesInBin(), 0u);
  EXPECT_NEAR(cell.ft_sensor().Read(kLong).force.z(), 0.0, kForceTol);  // the load has not changed
  // Opening again sheds it: it falls back into the bin.
  cell.gripper().Open(kLong);
  EXPECT_TRUE(cell.HeldTubes().empty());
  EXPECT_NEAR(cell.ft_sensor().Read(kLong).force.z(), -params.cell.tube.mass * kG, kForceTol);
  cell.Advance(2.0);
  EXPECT_EQ(cell.TubesInBin(), 1u);
  EXPECT_EQ(cell.fault_events().snags, 1u);  // armed once: the second opening let go
}

TEST(SimCell, TheFingersReachTheHousingSoNoTubeWedgesAboveAPad) {
  // A thin tube lies across the tops of the ±x walls of a low, narrow bin, at the height of the
  // 20 mm between the pads' tops and the housing. The open tool comes at it sideways at that
  // height: a finger's linkage meets it and pushes it along (the real 2F-85 has no open slot
  // there; without the linkage the tube passed through under the housing untouched, and in a
  // heap such a tube wedged there and hung on the open tool).
  SimCellParams params;
  params.cell.bin.inner_size = Eigen::Vector3d(0.40, 0.60, 0.08);
  const double radius = 0.008;
  const double z = params.cell.bin.inner_size.z() + radius;
  SimCell cell(params, {PolylineTube(1, {{-0.25, 0.0, z}, {0.0, 0.0, z}, {0.25, 0.0, z}}, radius)});
  ASSERT_EQ(cell.TubesBin().size(), 1u);
  const double y_before = cell.TubeCentresOfMass()[0].y();
  cell.robot().ServoOn(kLong);
  cell.gripper().Activate(kLong);
  cell.gripper().Open(kLong);
  const SimGripperParams& g = params.gripper;
  const double slot_middle = -(g.finger_tip_depth - g.finger_length - 0.5 * g.housing_gap);  // above the TCP
  Eigen::Isometry3d X = SimRobotParams::DefaultStart();
  X.translation() = Eigen::Vector3d(0.0, -0.15, 0.3);
  cell.robot().MoveTo(X, 0.25, kLong);
  X.translation().z() = z - slot_middle;
  cell.robot().MoveTo(X, 0.25, kLong);
  EXPECT_NEAR(cell.TubeCentresOfMass()[0].y(), y_before, 1e-3);  // not touched on the way down
  X.translation().y() = 0.10;
  cell.robot().MoveTo(X, 0.05, kLong);
  cell.Advance(0.5);
  // Pushed along by the leading finger's linkage (pad 1, 47.5 mm from the TCP towards +y_Bin): met at
  // TCP y ≈ −0.06 m, the tube ends about 0.16 m from where it lay.
  EXPECT_GT(cell.TubeCentresOfMass()[0].y() - y_before, 0.10);
}

TEST(SimCell, TubeDroppedBesideThePlaceZoneCountsAsElsewhere) {
  SimCellParams params;
  SimCell cell(params, {StraightTube(1, params.cell.tube.radius, 0.5)});
  GraspAndLift(cell);
  Eigen::Isometry3d X_beside = cell.X_BinTcp();
  X_beside.translation() = Eigen::Vector3d(0.65, 0.8, 0.3);  // past the zone's +x edge at 0.4 m
  cell.robot().MoveTo(X_beside, 0.25, kLong);
  cell.gripper().Open(kLong);
  cell.Advance(2.0);
  EXPECT_EQ(cell.TubesInBin(), 0u);
  EXPECT_EQ(cell.TubesInPlaceZone(), 0u);
  EXPECT_EQ(cell.TubesElsewhere(), 1u);
}

/// A tube at rest on the place zone (along x under the place frame's origin) and one in the bin.
std::vector<physics::TubeGeometry> PlacedAndInBin(const SimCellParams& params) {
  const double r = params.cell.tube.radius;
  physics::TubeGeometry placed = StraightTube(1, r, 0.5, params.cell.place.X_BinPlace.translation().y());
  return {placed, StraightTube(2, r, 0.5)};
}

TEST(SimCell, ThePlaceZoneConveyorCarriesOffPlacedTubesBeforeEachScan) {
  SimCellParams params;
  SimCell cell(params, PlacedAndInBin(params));
  ASSERT_EQ(cell.TubesInPlaceZone(), 1u);
  EXPECT_EQ(cell.TubesCarriedOff(), 0u);
  cell.scanner().Scan(kLong);
  EXPECT_EQ(cell.TubesCarriedOff(), 1u);
  // Still counted as placed, where it was carried off; the tube in the bin stays.
  EXPECT_EQ(cell.TubesInPlaceZone(), 1u);
  EXPECT_EQ(cell.TubesInBin(), 1u);
  EXPECT_EQ(cell.TubesElsewhere(), 0u);
  EXPECT_EQ(cell.TubesBin().size(), 2u);
  cell.scanner().Scan(kLong);
  EXPECT_EQ(cell.TubesCarriedOff(), 1u);

  SimCellParams table = params;
  table.place_zone_conveyor = false;
  SimCell piled(table, PlacedAndInBin(table));
  piled.scanner().Scan(kLong);
  EXPECT_EQ(piled.TubesCarriedOff(), 0u);
  EXPECT_EQ(piled.TubesInPlaceZone(), 1u);
}

TEST(SimCell, TheConveyorLeavesAHeldTubeOverThePlaceZone) {
  SimCellParams params;
  SimCell cell(params, {StraightTube(1, params.cell.tube.radius, 0.5)});
  GraspAndLift(cell);
  Eigen::Isometry3d X_over = cell.X_BinTcp();
  X_over.translation() = params.cell.place.X_BinPlace.translation() + Eigen::Vector3d(0, 0, 0.1);
  cell.robot().MoveTo(X_over, 0.25, kLong);
  cell.Advance(1.0);  // held still: the tube is at rest in the gripper
  cell.scanner().Scan(kLong);
  EXPECT_EQ(cell.TubesCarriedOff(), 0u);
  EXPECT_EQ(cell.HeldTubes().size(), 1u);
  // Released, at rest on the zone: the next scan's conveyor takes it.
  cell.gripper().Open(kLong);
  cell.Advance(2.0);
  cell.scanner().Scan(kLong);
  EXPECT_EQ(cell.TubesCarriedOff(), 1u);
  EXPECT_EQ(cell.TubesInPlaceZone(), 1u);
}

TEST(SimCell, ArmedRobotAlarmStopsTheMotionAndTheServo) {
  SimCellParams params;
  SimCell cell(params, {StraightTube(1, params.cell.tube.radius, 0.5)});
  cell.robot().ServoOn(kLong);
  const Eigen::Isometry3d X_start = cell.X_BinTcp();
  cell.ArmRobotAlarm(0.4);
  EXPECT_THAT([&] { cell.robot().MoveTo(Raised(X_start, -0.3), 0.25, kLong); },
              ::testing::ThrowsMessage<DeviceFault>(HasSubstr("alarm 4100 (injected")));
  const double moved = (cell.X_BinTcp().translation() - X_start.translation()).norm();
  EXPECT_GT(moved, 0.01);
  EXPECT_LT(moved, 0.1);  // 0.4 s of a 0.3 m move: stopped partway
  EXPECT_EQ(cell.fault_events().robot_alarms, 1u);
  EXPECT_THAT([&] { cell.robot().MoveTo(X_start, 0.25, kLong); },
              ::testing::ThrowsMessage<DeviceFault>(HasSubstr("servo off")));
  EXPECT_TRUE(cell.robot().CurrentPose(kLong).isApprox(cell.X_BinTcp()));  // still reports where it is
}

TEST(SimCell, OneShotFaultsSpikesAndEmptyScans) {
  SimCellParams params;
  SimCell cell(params, {StraightTube(1, params.cell.tube.radius, 0.5)});
  cell.InjectFaultOnce(SimDevice::kForceTorque, SimFault::kTimeout);
  EXPECT_THROW(cell.ft_sensor().Read(kLong), DeviceTimeout);
  const WrenchReading quiet = cell.ft_sensor().Read(kLong);  // the next read works
  cell.InjectFtSpike();
  EXPECT_NEAR(cell.ft_sensor().Read(kLong).force.z() - quiet.force.z(), 25.0, 0.2);
  EXPECT_NEAR(cell.ft_sensor().Read(kLong).force.z(), quiet.force.z(), 0.2);
  cell.InjectEmptyScan();
  EXPECT_TRUE(cell.scanner().Scan(kLong).points_Sensor.empty());
  EXPECT_FALSE(cell.scanner().Scan(kLong).points_Sensor.empty());
  const SimFaultEvents& events = cell.fault_events();
  EXPECT_EQ(events.device_failures, 1u);
  EXPECT_EQ(events.ft_spikes, 1u);
  EXPECT_EQ(events.empty_scans, 1u);
}

TEST(SimCell, CloseOnNothingReachesFullyClosed) {
  SimCellParams params;
  SimCell cell(params, {StraightTube(1, params.cell.tube.radius, 0.5)});
  cell.robot().ServoOn(kLong);
  cell.gripper().Activate(kLong);
  Eigen::Isometry3d X = SimRobotParams::DefaultStart();
  X.translation() = Eigen::Vector3d(0.0, 0.2, 0.05);  // beside the tube
  cell.robot().MoveTo(X, 0.25, kLong);
  const GripperStatus status = cell.gripper().Close(0.1, 50.0, kLong);
  EXPECT_EQ(status.object, GripperObject::kAtPosition);
  EXPECT_NEAR(status.opening, 0.0, 1e-12);
  EXPECT_TRUE(cell.HeldTubes().empty());
}

/// Tube A along x on the floor; tube B a bridge across A at x = 0.05: its flat middle rests on A,
/// its legs reach down to the floor on both sides. Lifting A carries B hanging over it.
std::vector<physics::TubeGeometry> BridgedTubes(double r) {
  const double top = 3.0 * r + 0.001;
  return {StraightTube(1, r, 0.4),
          PolylineTube(2, {{0.05, -0.22, r}, {0.05, -0.03, top}, {0.05, 0.03, top}, {0.05, 0.22, r}}, r)};
}

TEST(SimCell, EntangledTubesReadTwoWeightsAndATorque) {
  SimCellParams params;
  const double r = params.cell.tube.radius, m = params.cell.tube.mass;
  SimCell cell(params, BridgedTubes(r));
  ASSERT_TRUE(cell.settled());
  ASSERT_EQ(cell.TubesInBin(), 2u);
  cell.robot().ServoOn(kLong);
  cell.gripper().Activate(kLong);
  cell.ft_sensor().Bias(kLong);
  const WrenchReading reference = cell.ft_sensor().Read(kLong);

  // Grasp A at x = −0.1: A's centre of mass is 0.10 m along +x from the TCP, B's 0.15 m.
  const Eigen::Isometry3d X_grasp = GraspAt(cell.TubesBin()[0], 0.1);
  ASSERT_NEAR(X_grasp.translation().x(), -0.1, 1e-9);
  ASSERT_EQ(Grasp(cell, X_grasp).object, GripperObject::kStoppedClosing);
  EXPECT_EQ(cell.HeldTubes(), std::vector<std::size_t>{0});  // only A is held by the fingers
  cell.robot().MoveThrough({Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.3)}, 0.25, kLong);
  const WrenchReading lifted = cell.ft_sensor().Read(kLong);
  EXPECT_EQ(cell.TubesInBin(), 0u);  // B came along

  const double up = UpForce(lifted, cell.X_BinTcp()) - UpForce(reference, cell.X_BinTcp());
  EXPECT_NEAR(up, -2.0 * m * kG, 2 * kForceTol);
  // Horizontal torque about the TCP: Σ r × F = (0, g·m·(0.10 + 0.15), 0) in the bin frame.
  const Eigen::Vector3d torque_Bin = cell.X_BinTcp().linear() * (lifted.torque - reference.torque);
  EXPECT_NEAR(torque_Bin.y(), m * kG * 0.25, 0.02);
  EXPECT_NEAR(torque_Bin.x(), 0.0, 0.02);
  EXPECT_NEAR(torque_Bin.z(), 0.0, 0.01);
}

TEST(SimCell, RubberSagsWhenLiftedAtOneEndPvcDoesNot) {
  double sag[2] = {0.0, 0.0};
  for (Material material : {Material::kPvc, Material::kRubber}) {
    SimCellParams params = SimCellParams::Thesis(Material::kRubber, 1, 1);  // same hose size for both
    params.material = material;
    const double r = params.cell.tube.radius, m = params.cell.tube.mass;
    SimCell cell(params, {StraightTube(1, r, 0.4)});
    cell.robot().ServoOn(kLong);
    cell.gripper().Activate(kLong);
    cell.ft_sensor().Bias(kLong);
    ASSERT_EQ(Grasp(cell, GraspAt(cell.TubesBin()[0], 0.025)).object, GripperObject::kStoppedClosing);
    cell.robot().MoveThrough({Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.3)}, 0.25, kLong);
    cell.Advance(0.5);
    const std::vector<Eigen::Vector3d> line = cell.TubesBin()[0].Centreline();
    const double far_end_z = line.front().x() > line.back().x() ? line.front().z() : line.back().z();
    sag[material == Material::kRubber] = cell.X_BinTcp().translation().z() - far_end_z;
    // Either way the sensor carries the whole tube.
    EXPECT_NEAR(UpForce(cell.ft_sensor().Read(kLong), cell.X_BinTcp()), -m * kG, kForceTol);
  }
  EXPECT_LT(std::abs(sag[0]), 0.003);  // rigid PVC: only the grip's compliance
  // Rubber: EI = 0.1 N·m², 110 g over 40 cm, 37.5 cm cantilever ⇒ beam theory 6.7 cm.
  EXPECT_GT(sag[1], 0.04);
  EXPECT_LT(sag[1], 0.10);
}

TEST(SimCell, ScanSeesTheTubes) {
  SimCellParams params;
  params.tubes = 3;
  params.cell.sensor.unit = LengthUnit::kMillimetre;
  SimCell cell(params);
  const Capture capture = cell.scanner().Scan(kLong);
  EXPECT_NEAR(cell.SimulatedSeconds(), params.physics.scan_duration, params.physics.time_step);
  EXPECT_EQ(capture.unit, LengthUnit::kMillimetre);
  EXPECT_TRUE(capture.X_BinSensor.isApprox(params.cell.sensor.X_BinSensor));
  ASSERT_GT(capture.points_Sensor.size(), 100000u);
  // Points on a tube's surface: at the tube's radius from its centreline.
  const std::vector<physics::TubeGeometry> tubes = cell.TubesBin();
  const double r = params.cell.tube.radius;
  std::size_t on_tubes = 0;
  for (std::size_t i = 0; i < capture.points_Sensor.size(); i += 10) {
    const Eigen::Vector3d p = capture.X_BinSensor * (capture.points_Sensor[i].cast<double>() * 1e-3);
    for (const physics::TubeGeometry& tube : tubes) {
      bool hit = false;
      for (const Cylinder& c : tube.Cylinders()) {
        const double t = std::clamp((p - c.start).dot(c.axis()), 0.0, c.length());
        if (std::abs((p - (c.start + t * c.axis())).norm() - r) < 0.002) hit = true;
      }
      if (hit) {
        ++on_tubes;
        break;
      }
    }
  }
  EXPECT_GT(on_tubes, 2000u);  // of every 10th point: > 20 000 points on tubes
  // A second scan has fresh noise: different points, same scene.
  const Capture again = cell.scanner().Scan(kLong);
  EXPECT_NE(again.points_Sensor.front(), capture.points_Sensor.front());
}

TEST(SimCell, RobotFaults) {
  SimCellParams params;
  SimCell cell(params, {StraightTube(1, params.cell.tube.radius, 0.5)});
  Eigen::Isometry3d X = SimRobotParams::DefaultStart();
  X.translation() = Eigen::Vector3d(0.1, 0.1, 0.3);
  EXPECT_THAT([&] { cell.robot().MoveTo(X, 0.25, kLong); },
              ::testing::ThrowsMessage<DeviceFault>(HasSubstr("servo off")));
  cell.robot().ServoOn(kLong);
  cell.robot().MoveTo(X, 0.25, kLong);
  EXPECT_TRUE(cell.robot().CurrentPose(kLong).isApprox(X, 1e-12));

  Eigen::Isometry3d far = X;
  far.translation() = Eigen::Vector3d(2.0, 0.0, 0.3);
  EXPECT_THAT([&] { cell.robot().MoveTo(far, 0.25, kLong); },
              ::testing::ThrowsMessage<DeviceFault>(HasSubstr("out of reach")));
  EXPECT_THAT(
      [&] {
        cell.robot().MoveThrough({Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 2.0)}, 0.25, kLong);
      },
      ::testing::ThrowsMessage<DeviceFault>(HasSubstr("out of reach")));
  Eigen::Isometry3d tilted = X;
  tilted.linear() = Eigen::AngleAxisd(70.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()) * X.linear();
  EXPECT_THAT([&] { cell.robot().MoveTo(tilted, 0.25, kLong); },
              ::testing::ThrowsMessage<DeviceFault>(HasSubstr("joint limit")));
  EXPECT_TRUE(cell.robot().CurrentPose(kLong).isApprox(X, 1e-12));  // nothing moved
  // 45° (the thesis' resolution rotation) is within the limit.
  tilted.linear() = Eigen::AngleAxisd(M_PI / 4.0, Eigen::Vector3d::UnitY()) * X.linear();
  cell.robot().MoveTo(tilted, 0.25, kLong);

  // A move that needs longer than its timeout stops on the way.
  cell.robot().MoveTo(X, 0.25, kLong);
  Eigen::Isometry3d low = X;
  low.translation().z() = 0.1;
  EXPECT_THROW(cell.robot().MoveTo(low, 0.1, Timeout(200)), DeviceTimeout);
  const double z = cell.robot().CurrentPose(kLong).translation().z();
  EXPECT_LT(z, 0.3);
  EXPECT_GT(z, 0.1);

  // Driving the fingers into the floor: protective stop, servo off.
  Eigen::Isometry3d floor = X;
  floor.translation() = Eigen::Vector3d(0.1, 0.2, -0.015);
  EXPECT_THAT([&] { cell.robot().MoveTo(floor, 0.25, kLong); },
              ::testing::ThrowsMessage<DeviceFault>(HasSubstr("protective stop")));
  EXPECT_GT(cell.robot().CurrentPose(kLong).translation().z(), -0.01);
  EXPECT_THAT([&] { cell.robot().MoveTo(X, 0.25, kLong); },
              ::testing::ThrowsMessage<DeviceFault>(HasSubstr("servo off")));
  cell.robot().ServoOn(kLong);
  cell.robot().MoveTo(X, 0.25, kLong);
}

TEST(SimCell, HousingInAWallStopsOnlyWhenAsked) {
  for (bool housing_stop : {false, true}) {
    SimCellParams params;
    params.robot.housing_stop = housing_stop;
    SimCell cell(params, {StraightTube(1, params.cell.tube.radius, 0.5, -0.15)});
    cell.robot().ServoOn(kLong);
    cell.gripper().Activate(kLong);
    cell.gripper().Close(0.15, 50.0, kLong);  // pads together: ±10 mm around the TCP
    // 3 cm from the +y wall: the pads clear it, the housing (±65 mm along y_Tcp) does not.
    Eigen::Isometry3d X = SimRobotParams::DefaultStart();
    X.translation() = Eigen::Vector3d(0.0, 0.27, 0.3);
    cell.robot().MoveTo(X, 0.25, kLong);
    X.translation().z() = 0.05;
    if (housing_stop) {
      EXPECT_THAT([&] { cell.robot().MoveTo(X, 0.25, kLong); },
                  ::testing::ThrowsMessage<DeviceFault>(HasSubstr("housing hit a bin wall")));
    } else {
      cell.robot().MoveTo(X, 0.25, kLong);  // logs a warning
      EXPECT_TRUE(cell.X_BinTcp().isApprox(X, 1e-12));
    }
  }
}

TEST(SimCell, GripperAndSensorFaults) {
  SimCellParams params;
  SimCell cell(params, {StraightTube(1, params.cell.tube.radius, 0.5)});
  EXPECT_THAT([&] { cell.gripper().Close(0.05, 50.0, kLong); },
              ::testing::ThrowsMessage<DeviceFault>(HasSubstr("not activated")));
  EXPECT_FALSE(cell.gripper().Status(kLong).activated);
  cell.gripper().Activate(kLong);
  EXPECT_TRUE(cell.gripper().Status(kLong).activated);

  cell.InjectFault(SimDevice::kGripper, SimFault::kFault);
  EXPECT_THROW(cell.gripper().Open(kLong), DeviceFault);
  EXPECT_EQ(cell.gripper().Status(kLong).fault, 0x0E);  // reported, not thrown
  cell.InjectFault(SimDevice::kGripper, SimFault::kTimeout);
  EXPECT_THROW(cell.gripper().Status(kLong), DeviceTimeout);
  cell.InjectFault(SimDevice::kGripper, SimFault::kNone);
  EXPECT_EQ(cell.gripper().Status(kLong).fault, 0);

  cell.InjectFault(SimDevice::kForceTorque, SimFault::kTimeout);
  EXPECT_THROW(cell.ft_sensor().Read(kLong), DeviceTimeout);
  cell.InjectFault(SimDevice::kForceTorque, SimFault::kNone);
  // Unbiased, the sensor reads its offsets.
  EXPECT_NEAR((cell.ft_sensor().Read(kLong).force - params.force_offset).norm(), 0.0, 0.1);

  cell.InjectFault(SimDevice::kScanner, SimFault::kFault);
  EXPECT_THROW(cell.scanner().Scan(kLong), DeviceFault);
  cell.InjectFault(SimDevice::kScanner, SimFault::kNone);
  EXPECT_THROW(cell.scanner().Scan(Timeout(100)), DeviceTimeout);  // a scan takes 0.5 s
  cell.InjectFault(SimDevice::kRobot, SimFault::kTimeout);
  EXPECT_THROW(cell.robot().ServoOn(kLong), DeviceTimeout);
}

/// A short pick on a generated bin, returning what a controller would log.
struct PickLog {
  std::vector<WrenchReading> readings;
  std::vector<Eigen::Vector3d> centres;
  double seconds = 0.0;
};

PickLog PickTopTube(const SimCellParams& params) {
  SimCell cell(params);
  PickLog log;
  cell.robot().ServoOn(kLong);
  cell.gripper().Activate(kLong);
  cell.ft_sensor().Bias(kLong);
  const Capture capture = cell.scanner().Scan(kLong);
  log.centres.push_back(capture.X_BinSensor *
                        capture.points_Sensor[capture.points_Sensor.size() / 2].cast<double>());
  const std::vector<physics::TubeGeometry> tubes = cell.TubesBin();
  const std::vector<Eigen::Vector3d> coms = cell.TubeCentresOfMass();
  std::size_t top = 0;
  for (std::size_t i = 1; i < coms.size(); ++i) {
    if (coms[i].z() > coms[top].z()) top = i;
  }
  Grasp(cell, MiddleGrasp(tubes[top]));
  log.readings.push_back(cell.ft_sensor().Read(kLong));
  cell.robot().MoveThrough({Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.3)}, 0.25, kLong);
  log.readings.push_back(cell.ft_sensor().Read(kLong));
  for (const Eigen::Vector3d& p : cell.TubeCentresOfMass()) log.centres.push_back(p);
  log.seconds = cell.SimulatedSeconds();
  return log;
}

TEST(SimCell, SameParamsSameCell) {
  SimCellParams params = SimCellParams::Thesis(Material::kRubber, 4, 21);
  const PickLog a = PickTopTube(params);
  const PickLog b = PickTopTube(params);
  ASSERT_EQ(a.readings.size(), b.readings.size());
  for (std::size_t i = 0; i < a.readings.size(); ++i) {
    EXPECT_EQ(a.readings[i].force, b.readings[i].force);
    EXPECT_EQ(a.readings[i].torque, b.readings[i].torque);
  }
  EXPECT_EQ(a.centres, b.centres);
  EXPECT_EQ(a.seconds, b.seconds);
  params.seed = 22;
  EXPECT_NE(PickTopTube(params).centres, a.centres);
}

TEST(SimCell, ATubeFasterThanTheCellCanMoveOneIsARunaway) {
  // A tube 0.3 m above the floor falls while the bin settles: 2.4 m/s at the floor (√(2·g·0.3)).
  SimCellParams params;
  const double r = params.cell.tube.radius;
  const auto falling = [r] {
    physics::TubeGeometry tube = StraightTube(1, r, 0.5);
    for (auto& node : tube.nodes) node.centre.z() += 0.3;
    return tube;
  };
  {
    const SimCell cell(params, {falling()});
    EXPECT_TRUE(cell.runaways().empty());  // within the default 6 m/s
    EXPECT_NEAR(cell.peak_speeds().linear, std::sqrt(2.0 * kG * 0.3), 0.15);
  }
  params.physics.runaway_speed = 1.5;
  const SimCell cell(params, {falling()});
  ASSERT_EQ(cell.runaways().size(), 1u);  // once, though faster than 1.5 m/s for many steps
  const SimRunaway thrown = cell.runaways().front();
  EXPECT_EQ(thrown.tube, 0u);
  EXPECT_GT(thrown.speed, 1.5);
  EXPECT_LT(thrown.speed, 1.6);    // the first step past the limit
  EXPECT_LT(thrown.seconds, 0.0);  // while the bin settled, before the cell's clock starts
  EXPECT_THROW(
      {
        params.physics.runaway_speed = 0.0;
        SimCell bad(params, {falling()});
      },
      InvalidArgument);
}

}  // namespace
}  // namespace tubepick::devices::sim
