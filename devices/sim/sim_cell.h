#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/common/cell_config.h"
#include "core/wrench/wrench.h"
#include "devices/force_torque_sensor.h"
#include "devices/gripper.h"
#include "devices/robot.h"
#include "devices/scanner.h"
#include "physics/random_tubes.h"
#include "physics/tube_geometry.h"
#include "physics/virtual_scanner.h"

namespace tubepick::devices::sim {

/// Tube material of the simulated cell, like the thesis' sets A and B (Table 5.2).
enum class Material {
  /// Rigid bent PVC pipe: one rigid body per tube, low friction.
  kPvc,
  /// Semi-rigid rubber hose: a chain of bodies linked by spring joints, high friction.
  kRubber,
};
/// "pvc", "rubber". ParseMaterial throws InvalidArgument naming `field` for anything else.
std::string ToString(Material material);
Material ParseMaterial(const std::string& text, const std::string& field);

/// The tubes of the thesis' Table 5.2: set A (PVC) r = 1.25 cm, 50 cm, 55 g; set B (rubber)
/// r = 1.00 cm, 40 cm, 110 g. Use it for CellConfig::tube to simulate the thesis' sets.
TubeConfig ThesisTubes(Material material);

/// Contact and stiffness properties of the tube material. Friction values are the effective
/// Coulomb coefficients of a contact pair (Bullet multiplies the two bodies' values; the cell sets
/// the body values so that the products are these).
struct SimMaterialParams {
  /// Tube–tube friction (the thesis gives none; PVC on PVC ≈ 0.3, rubber on rubber ≈ 1).
  double tube_friction = 0.3;
  /// Tube–bin and tube–ground friction.
  double bin_friction = 0.3;
  /// Tube–finger-pad friction (only for tubes touching a pad without being held).
  double pad_friction = 0.8;
  /// Restitution of tube contacts.
  double restitution = 0.1;
  /// Rolling friction of tubes, metres (lever arm; damps rolling on the floor).
  double rolling_friction = 0.001;
  /// Rubber only: target length of one rigid link of the chain, metres. The tube's centreline is
  /// resampled into n = max(2, round(length / link_length)) links of equal arc length (chords of
  /// the generated polyline).
  double link_length = 0.05;
  /// Rubber only: bending stiffness EI of the hose, N·m². A joint between links of mean length ℓ
  /// is an angular spring of EI/ℓ N·m/rad about both bending axes (a discretised beam). 0.1 N·m² ≈
  /// a reinforced rubber hose of 2 cm diameter (E ≈ 10 MPa): a straight 40 cm, 110 g hose held
  /// horizontally 2.5 cm from one end sags ≈ 7 cm at the other (beam theory: 6.7 cm).
  double bending_stiffness = 0.1;
  /// Rubber only: damping ratio of each joint spring (for the lighter link turning about it).
  double damping_ratio = 0.7;

  /// pvc: μ 0.3 (tubes), 0.3 (bin), 0.8 (pads). rubber: μ 1.0, 0.8, 1.0 and the hose stiffness above.
  static SimMaterialParams Defaults(Material material);
};

/// The simulated gripper (Robotiq 2F-85-like). Frames as in core/planning/grasp_filters.h: the
/// pads are boxes in the TCP frame centred at (0, ±(opening + finger_thickness)/2,
/// finger_tip_depth − finger_length/2); z_Tcp points down along the approach.
struct SimGripperParams {
  /// Largest opening between the pads' inner faces, metres.
  double stroke = 0.085;
  /// Pad size along x_Tcp (along the grasped tube), y_Tcp (closing direction) and z_Tcp, metres.
  double finger_width = 0.022;
  double finger_thickness = 0.010;
  double finger_length = 0.050;
  /// How far the fingertips reach past the TCP along z_Tcp, metres.
  double finger_tip_depth = 0.005;
  /// The gripper housing: a box of this size (x, y, z in the TCP frame, metres; 0 = none) whose
  /// bottom is housing_gap above the pads' top (the fingertips reach 75 mm below it). It pushes
  /// tubes like the pads do. With a housing, each finger goes on up to it (its linkage: a box of
  /// the pad's width and thickness over the gap, part of the pad's body, not of its gripping
  /// face), so no tube wedges between a pad's top and the housing. Keep it equal to the controller's tool
  /// model (clients/cell/tool_clearance.h ToolGeometry), which plans around it.
  Eigen::Vector3d housing_size{0.06, 0.13, 0.09};
  double housing_gap = 0.02;
  /// Finger speed range (rate of change of the opening), m/s; requests are clamped into it.
  double min_speed = 0.02;
  double max_speed = 0.15;
  /// Grip force range, N; requests are clamped into it. A pad pushing something the other pad
  /// does not reach stops the gripper once its contact force exceeds the requested force.
  double min_force = 20.0;
  double max_force = 235.0;
  /// Tool load the F/T sensor carries besides the payload (gripper mass, kg, and its centre of
  /// mass in the TCP frame). 0 = the tool is gravity-compensated, as a controller with a
  /// configured tool load does: only the payload and the sensor offset are read.
  double tool_mass = 0.0;
  Eigen::Vector3d p_TcpToolCom{0.0, 0.0, -0.10};
};

/// The simulated arm: it moves the TCP in straight lines (trapezoidal speed, orientation slerp).
struct SimRobotParams {
  /// Pose at construction: 0.5 m above the bin floor centre, z_Tcp down, x_Tcp along x_Bin.
  Eigen::Isometry3d X_BinTcp_start = DefaultStart();
  /// Used when a move gets a non-positive speed, m/s; requests above max_speed are clamped.
  double default_speed = 0.1;
  double max_speed = 1.0;
  /// Acceleration and deceleration of the TCP along its path, m/s².
  double acceleration = 0.5;
  /// Rotations run at speed / rotation_radius rad/s (a point this far from the TCP moves at the
  /// requested speed), metres.
  double rotation_radius = 0.2;
  /// Reach: the TCP must stay in the box around the bin (inner box, floor to wall top) and the
  /// place frame's origin, widened by reach_margin on every side in x and y, with z in
  /// [min_height, max_height] (bin frame). Targets outside ⇒ DeviceFault.
  double reach_margin = 0.3;
  double min_height = -0.02;
  double max_height = 1.0;
  /// Joint limit: largest angle between z_Tcp and the downward vertical, radians.
  double max_tilt = 60.0 * M_PI / 180.0;
  /// Protective stop: the gripper penetrating the bin or the ground deeper than this, metres,
  /// stops the robot (servo off) with a DeviceFault. Moving out of a collision is allowed.
  double collision_depth = 0.002;
  /// The housing (not only the pads) hitting the bin or the ground stops the robot too. The
  /// planner's finger filter sees the walls in the cloud but knows nothing of the housing, so a
  /// grasp next to a wall can put the housing into it: the controller must check the tool's
  /// clearance itself. false: the housing passes through the bin with a logged warning (it still
  /// pushes tubes).
  bool housing_stop = true;

  static Eigen::Isometry3d DefaultStart();
};

/// Stepping and timing of the simulation.
struct SimPhysicsParams {
  /// Control step, seconds; each is split into `substeps` Bullet steps.
  double time_step = 1.0 / 240.0;
  /// Bullet steps per control step; 0 = the material's default (pvc 2, rubber 4: the hose's
  /// chain needs the shorter step for its joints and contacts to settle).
  int substeps = 0;
  /// Sequential-impulse solver iterations per Bullet step.
  int solver_iterations = 20;
  /// Longest settling after the tubes are placed, seconds (ends early once every tube has been at
  /// rest for 0.2 s).
  double settle_time = 5.0;
  /// Simulated time one scan takes (the world keeps running), seconds.
  double scan_duration = 0.5;
  /// One F/T read or bias averages the wrench over this much simulated time, seconds.
  double ft_window = 0.05;
  /// Bin wall thickness in the physics world, metres (inner faces as in the cell; thick walls
  /// stop tubes pushed by the fingers from tunnelling through).
  double wall_thickness = 0.05;
  /// A tube body whose centre of mass moves faster than this, m/s, is a runaway (SimRunaway):
  /// nothing in the cell moves a tube that fast (the arm at most 1 m/s, a tube falling from the
  /// transit height onto the ground 3-4 m/s; the fastest body of rounds without a blow-up
  /// 1.0-2.5 m/s, docs/ACCURACY.md). Spin is no criterion: a rubber hose's short links spin at up
  /// to 110 rad/s in such rounds, a pvc tree at 21, the blow-up traced at 41-62.
  double runaway_speed = 6.0;
};

/// A tube that moved faster than anything in the cell can move it (SimPhysicsParams::runaway_speed):
/// the solver put energy into it (a blow-up of the simulation, e.g. rigid trees locked into each
/// other), and where it goes next is the simulator's doing, not the cell's. The first such step of
/// each tube.
struct SimRunaway {
  /// Index into SimCell::TubesBin.
  std::size_t tube = 0;
  /// SimCell::SimulatedSeconds when it happened (negative: while the bin settled).
  double seconds = 0.0;
  /// The fastest of the tube's bodies then, m/s and rad/s.
  double speed = 0.0;
  double angular_speed = 0.0;
};

/// The fastest any tube body moved, m/s and rad/s.
struct SimPeakSpeeds {
  double linear = 0.0;
  double angular = 0.0;
};

/// Everything that defines one simulated cell. Same params (incl. seed) ⇒ same cell, same scans,
/// same readings.
struct SimCellParams {
  Material material = Material::kPvc;
  /// Tubes dropped into the bin at construction.
  std::uint32_t tubes = 7;
  std::uint64_t seed = 1;
  /// The cell (bin, sensor pose, tube radius/length/mass, place frame). tube.mass is per tube.
  CellConfig cell;
  /// What the simulated tubes really weigh, kg, when it is not cell.tube.mass (what the cell says):
  /// to see what a wrong tube.mass does to a cell. nullopt = cell.tube.mass.
  std::optional<double> world_tube_mass;

  /// The simulated tubes' mass, kg.
  double WorldTubeMass() const { return world_tube_mass.value_or(cell.tube.mass); }
  /// F/T noise, standard deviation per axis of each reading (and of the reading Bias takes, so a
  /// biased reading deviates by σ·√2): N and N·m.
  double force_noise = 0.02;
  double torque_noise = 0.002;
  /// Constant F/T offsets (a strain-gauge sensor's zero drift), N and N·m, sensor frame; Bias()
  /// removes them.
  Eigen::Vector3d force_offset{0.4, -0.3, 1.2};
  Eigen::Vector3d torque_offset{0.02, -0.01, 0.005};
  /// Material properties; nullopt = SimMaterialParams::Defaults(material).
  std::optional<SimMaterialParams> material_params;
  /// Tube shapes (Algorithm 2); nullopt = set A (pvc) or set B (rubber) with cell.tube's radius and
  /// length. Branched shapes (set C) with pvc only: each tree is one rigid body.
  std::optional<physics::RandomTubeParams> tube_shape;
  /// The place zone: a table or conveyor beside the bin, centred under cell.place.X_BinPlace's
  /// origin, this size along x_Bin and y_Bin, metres. Tubes at rest in it count as placed. The
  /// default (0.8 × 0.9 m around the thesis cell's place frame at y = 0.8 m) reaches the bin's
  /// outer wall, so a tube that slips in transit falls into the bin or onto the zone.
  Eigen::Vector2d place_zone_size{0.8, 0.9};
  /// The place zone is a conveyor: before every scan (between picks) it carries off each tube at
  /// rest on it (the tube leaves the world and still counts as placed), as a real cell's conveyor
  /// or an operator clears its place zone. false: a table, where placed tubes pile up until later
  /// ones push them off or a held tube lands on the pile.
  bool place_zone_conveyor = true;
  /// The virtual scanner (its wall_thickness is the rendered walls').
  physics::ScannerParams scanner;
  SimGripperParams gripper;
  SimRobotParams robot;
  SimPhysicsParams physics;

  /// With cell.tube set to ThesisTubes(material).
  static SimCellParams Thesis(Material material, std::uint32_t tubes, std::uint64_t seed);
  /// @throws InvalidArgument naming the first bad field and its value.
  void Validate() const;
};

/// Which device an injected fault hits (SimCell::InjectFault).
enum class SimDevice { kScanner, kRobot, kGripper, kForceTorque };
/// What an injected fault does to every following call of that device.
enum class SimFault {
  kNone,
  /// The call throws DeviceTimeout (nothing moves).
  kTimeout,
  /// The call throws DeviceFault; Gripper::Status does not throw but reports fault 0x0E.
  kFault,
};

/// Injected events that happened (not only armed).
struct SimFaultEvents {
  std::uint32_t robot_alarms = 0;
  std::uint32_t slips = 0;  ///< a tube was held and fell
  std::uint32_t snags = 0;  ///< an opening left what was held hanging on the tool
  std::uint32_t ft_spikes = 0;
  std::uint32_t empty_scans = 0;
  std::uint32_t device_failures = 0;  ///< calls that failed by InjectFault / InjectFaultOnce
};

/// One Bullet world behind all four devices: tubes from the scene generator dropped into the bin;
/// the scanner is the virtual scanner; the robot moves a kinematic two-finger gripper (TCP frame as
/// in core/planning/grasp_synthesis.h: z down along the approach, y the closing direction); closing
/// holds what lies between the fingers by constraint; the F/T sensor reports the load of everything
/// lifted — including tubes lifted by entanglement — with seeded noise. Device calls advance the
/// simulation synchronously (simulated time, as fast as the CPU allows). Not thread-safe: one
/// controller drives it.
///
/// Devices, as seen through their interfaces:
/// - Scanner: ScanScene on the current tube poses, points in the sensor frame in cell.sensor.unit,
///   X_BinSensor = cell.sensor.X_BinSensor; takes scan_duration. The robot and gripper are not
///   rendered (assumed out of the sensor's view while it scans).
/// - Robot: ServoOn first (else DeviceFault "servo off"). MoveTo/MoveThrough move the TCP at the
///   requested speed; a target out of reach or tilted beyond max_tilt ⇒ DeviceFault before moving;
///   a pad (or, with robot.housing_stop, the housing) hitting the bin or the ground ⇒ protective
///   stop (servo off, DeviceFault); a move longer than its timeout (simulated seconds) stops there
///   with DeviceTimeout.
/// - Gripper: Activate first (else DeviceFault). Close stops when both pads touch something
///   (status kStoppedClosing, opening ≈ what lies between them) — every tube link touching a pad
///   then hangs from the gripper by a fixed constraint — or closes fully (kAtPosition). Opening
///   releases.
/// - F/T sensor: the wrench the payload exerts on the sensor (core/wrench/wrench.h): held links'
///   constraint reactions plus every contact force on the pads and housing, about the TCP, in the
///   TCP axes, averaged over ft_window, plus the offsets and Gaussian noise; Bias zeroes it at the
///   current load. A held tube of mass m with the gripper vertical reads force ≈ (0, 0, +m·g) in
///   the TCP axes (z down), i.e. −m·g along the upward vertical.
class SimCell {
 public:
  /// Generates params.tubes tubes (GenerateScene: Algorithm 2 shapes dropped into the bin) and lets
  /// them settle in the cell's world. @throws InvalidArgument for invalid params.
  explicit SimCell(const SimCellParams& params);
  /// Test hook: the given tubes (bin frame, linear) instead of generated ones (params.tubes is
  /// ignored), placed where they are and settled. @throws InvalidArgument for invalid params or
  /// a tube that is not linear.
  SimCell(const SimCellParams& params, const std::vector<physics::TubeGeometry>& tubes_Bin);
  ~SimCell();
  SimCell(const SimCell&) = delete;
  SimCell& operator=(const SimCell&) = delete;

  Scanner& scanner();
  Robot& robot();
  Gripper& gripper();
  ForceTorqueSensor& ft_sensor();

  const CellConfig& cell() const;
  const SimCellParams& params() const;
  /// Tubes whose centre of mass lies inside the bin (inner box, up to the wall top + 5 cm).
  std::uint32_t TubesInBin() const;
  /// Tubes outside the bin (centre of mass outside the inner footprint, below the wall top + 5 cm)
  /// and not held by the gripper: placed or lost.
  std::uint32_t TubesOutsideBin() const;
  /// Tubes outside the bin whose centre of mass lies over the place zone (SimCellParams::place_zone_size).
  std::uint32_t TubesInPlaceZone() const;
  /// Of them, the tubes the conveyor has carried off (SimCellParams::place_zone_conveyor).
  std::uint32_t TubesCarriedOff() const;
  /// Tubes neither in the bin, nor in the place zone, nor held: on the floor, on a wall, anywhere a
  /// tube must never be released.
  std::uint32_t TubesElsewhere() const;
  /// Simulated seconds since construction (the initial drop and settling not counted).
  double SimulatedSeconds() const;
  /// Tube bodies (a pvc tube, a rubber tube's link) Bullet still steps: a heap at rest falls
  /// asleep, and costs next to nothing, until something touches it.
  std::uint32_t AwakeTubeBodies() const;

  /// Ground truth: every tube as it is now, bin frame, in construction order (ids 1..N). A
  /// rubber tube's nodes are its chain's joints.
  std::vector<physics::TubeGeometry> TubesBin() const;
  /// Centre of mass of every tube, bin frame.
  std::vector<Eigen::Vector3d> TubeCentresOfMass() const;
  /// Indices (into TubesBin) of the tubes the gripper holds by constraint, ascending.
  std::vector<std::size_t> HeldTubes() const;
  /// The TCP pose now (the robot's CurrentPose without a device call).
  Eigen::Isometry3d X_BinTcp() const;
  /// The noise-free, unbiased payload wrench of the last Bullet step (sensor frame).
  Wrench TrueWrench() const;
  /// Lets `seconds` of simulated time pass with the robot and gripper still (a wait).
  void Advance(double seconds);
  /// Every following call to `device` fails as `fault` says, until injected kNone again.
  void InjectFault(SimDevice device, SimFault fault);
  /// The next call to `device` fails as `fault` says; the calls after it work again.
  void InjectFaultOnce(SimDevice device, SimFault fault);
  /// After `seconds` more of simulated robot motion the robot stops with an alarm (servo off,
  /// DeviceFault), wherever it is; it stays off (the cell needs an operator).
  void ArmRobotAlarm(double seconds);
  /// After `seconds` more of robot motion whatever the gripper holds slips out and falls in the
  /// world (a grip gives way while the tube is moved, not while it hangs still); the gripper then
  /// reports no object. Opening the gripper first disarms it.
  void ArmSlip(double seconds);
  /// The next opening of the gripper while it holds something leaves it hanging on the tool (a hose
  /// hooked over a pad or caught on the housing): the fingers open and report no object, the F/T
  /// sensor still feels the load, and it goes with the tool until the gripper opens again.
  void ArmSnag();
  /// The next F/T reading carries a 25 N spike along z (a hit cable, an EMI burst).
  void InjectFtSpike();
  /// The next scan returns no point (a projector or exposure failure).
  void InjectEmptyScan();
  /// The injected events that happened so far.
  const SimFaultEvents& fault_events() const;
  /// The tubes were at rest when construction ended (false: settle_time ran out).
  bool settled() const;
  /// Tubes that ran away (SimRunaway), in the order it happened; empty when the simulation stayed
  /// within what the cell can do.
  std::vector<SimRunaway> runaways() const;
  /// The fastest any tube body moved since construction (the settling included).
  SimPeakSpeeds peak_speeds() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tubepick::devices::sim
