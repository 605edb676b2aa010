// Parameters of the simulated cell: presets, parsing and validation.

#include <cmath>
#include <string>

#include "core/common/errors.h"
#include "devices/sim/sim_cell.h"

namespace tubepick::devices::sim {
namespace {

void Require(bool ok, const std::string& field, double value, const std::string& expected) {
  if (!ok)
    throw InvalidArgument("sim cell: " + field + " = " + std::to_string(value) + ": expected " + expected);
}

bool Finite(double x) { return std::isfinite(x); }

bool FiniteRigid(const Eigen::Isometry3d& X) {
  if (!X.matrix().allFinite()) return false;
  const Eigen::Matrix3d R = X.linear();
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-6 && R.determinant() > 0.0;
}

}  // namespace

std::string ToString(Material material) {
  switch (material) {
    case Material::kPvc:
      return "pvc";
    case Material::kRubber:
      return "rubber";
  }
  return "unknown";
}

Material ParseMaterial(const std::string& text, const std::string& field) {
  if (text == "pvc") return Material::kPvc;
  if (text == "rubber") return Material::kRubber;
  throw InvalidArgument(field + ": unknown material '" + text + "', expected pvc or rubber");
}

TubeConfig ThesisTubes(Material material) {
  TubeConfig tube;
  if (material == Material::kRubber) {
    tube.radius = 0.010;
    tube.length = 0.40;
    tube.mass = 0.110;
  } else {
    tube.radius = 0.0125;
    tube.length = 0.50;
    tube.mass = 0.055;
  }
  return tube;
}

SimMaterialParams SimMaterialParams::Defaults(Material material) {
  SimMaterialParams p;
  if (material == Material::kRubber) {
    p.tube_friction = 1.0;
    p.bin_friction = 0.8;
    p.pad_friction = 1.0;
    p.restitution = 0.05;
  }
  return p;
}

Eigen::Isometry3d SimRobotParams::DefaultStart() {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();  // z_Tcp = −z_Bin
  X.translation() = Eigen::Vector3d(0.0, 0.0, 0.5);
  return X;
}

SimCellParams SimCellParams::Thesis(Material material, std::uint32_t tubes, std::uint64_t seed) {
  SimCellParams p;
  p.material = material;
  p.tubes = tubes;
  p.seed = seed;
  p.cell.tube = ThesisTubes(material);
  return p;
}

void SimCellParams::Validate() const {
  cell.Validate();
  Require(tubes <= 100, "tubes", tubes, "≤ 100");
  Require(force_noise >= 0.0 && Finite(force_noise), "force_noise", force_noise, "≥ 0 N");
  Require(torque_noise >= 0.0 && Finite(torque_noise), "torque_noise", torque_noise, "≥ 0 N·m");
  Require(place_zone_size.allFinite() && place_zone_size.minCoeff() > 0.0, "place_zone_size",
          place_zone_size.minCoeff(), "> 0 m on both axes");
  Require(force_offset.allFinite(), "force_offset", force_offset.norm(), "finite");
  Require(torque_offset.allFinite(), "torque_offset", torque_offset.norm(), "finite");

  const SimMaterialParams m = material_params.value_or(SimMaterialParams::Defaults(material));
  Require(m.tube_friction >= 0.0 && m.tube_friction <= 5.0, "material.tube_friction", m.tube_friction,
          "in [0, 5]");
  Require(m.tube_friction > 0.0, "material.tube_friction", m.tube_friction, "> 0");
  Require(m.bin_friction >= 0.0 && m.bin_friction <= 5.0, "material.bin_friction", m.bin_friction,
          "in [0, 5]");
  Require(m.pad_friction >= 0.0 && m.pad_friction <= 5.0, "material.pad_friction", m.pad_friction,
          "in [0, 5]");
  Require(m.restitution >= 0.0 && m.restitution <= 1.0, "material.restitution", m.restitution, "in [0, 1]");
  Require(m.rolling_friction >= 0.0 && m.rolling_friction < 0.1, "material.rolling_friction",
          m.rolling_friction, "in [0, 0.1) m");
  Require(m.link_length >= 0.01 && m.link_length <= 1.0, "material.link_length", m.link_length,
          "in [0.01, 1] m");
  Require(m.bending_stiffness > 0.0 && Finite(m.bending_stiffness), "material.bending_stiffness",
          m.bending_stiffness, "> 0 N·m²");
  Require(m.damping_ratio > 0.0 && m.damping_ratio <= 10.0, "material.damping_ratio", m.damping_ratio,
          "in (0, 10]");
  if (tube_shape) tube_shape->Validate();
  scanner.Validate();

  const SimGripperParams& g = gripper;
  Require(g.stroke > 0.0 && g.stroke <= 0.5, "gripper.stroke", g.stroke, "in (0, 0.5] m");
  Require(g.finger_width > 0.0 && g.finger_width <= 0.2, "gripper.finger_width", g.finger_width,
          "in (0, 0.2] m");
  Require(g.finger_thickness > 0.0 && g.finger_thickness <= 0.1, "gripper.finger_thickness",
          g.finger_thickness, "in (0, 0.1] m");
  Require(g.finger_length > 0.0 && g.finger_length <= 0.3, "gripper.finger_length", g.finger_length,
          "in (0, 0.3] m");
  Require(Finite(g.finger_tip_depth) && std::abs(g.finger_tip_depth) < g.finger_length,
          "gripper.finger_tip_depth", g.finger_tip_depth, "|depth| < finger_length");
  Require(g.housing_size.allFinite() && (g.housing_size.array() >= 0.0).all(), "gripper.housing_size",
          g.housing_size.minCoeff(), "≥ 0 m (0 = no housing)");
  Require(g.housing_gap >= 0.0 && Finite(g.housing_gap), "gripper.housing_gap", g.housing_gap, "≥ 0 m");
  Require(g.min_speed > 0.0 && g.min_speed <= g.max_speed && Finite(g.max_speed), "gripper.min_speed",
          g.min_speed, "0 < min_speed ≤ max_speed");
  Require(g.min_force > 0.0 && g.min_force <= g.max_force && Finite(g.max_force), "gripper.min_force",
          g.min_force, "0 < min_force ≤ max_force");
  Require(g.tool_mass >= 0.0 && g.tool_mass <= 20.0, "gripper.tool_mass", g.tool_mass, "in [0, 20] kg");
  Require(g.p_TcpToolCom.allFinite(), "gripper.p_TcpToolCom", g.p_TcpToolCom.norm(), "finite");

  const SimRobotParams& r = robot;
  Require(FiniteRigid(r.X_BinTcp_start), "robot.X_BinTcp_start", r.X_BinTcp_start.translation().norm(),
          "a finite rigid transform");
  Require(r.default_speed > 0.0 && r.default_speed <= r.max_speed, "robot.default_speed", r.default_speed,
          "0 < v ≤ max_speed");
  Require(r.max_speed > 0.0 && r.max_speed <= 5.0, "robot.max_speed", r.max_speed, "in (0, 5] m/s");
  Require(r.acceleration > 0.0 && r.acceleration <= 50.0, "robot.acceleration", r.acceleration,
          "in (0, 50] m/s²");
  Require(r.rotation_radius > 0.0 && r.rotation_radius <= 2.0, "robot.rotation_radius", r.rotation_radius,
          "in (0, 2] m");
  Require(r.reach_margin >= 0.0 && r.reach_margin <= 5.0, "robot.reach_margin", r.reach_margin,
          "in [0, 5] m");
  Require(Finite(r.min_height) && r.min_height < r.max_height && Finite(r.max_height), "robot.min_height",
          r.min_height, "< max_height");
  Require(r.max_tilt > 0.0 && r.max_tilt <= M_PI, "robot.max_tilt", r.max_tilt, "in (0, π] rad");
  Require(r.collision_depth > 0.0 && r.collision_depth < 0.1, "robot.collision_depth", r.collision_depth,
          "in (0, 0.1) m");

  const SimPhysicsParams& s = physics;
  Require(s.time_step > 0.0 && s.time_step <= 0.05, "physics.time_step", s.time_step, "in (0, 0.05] s");
  Require(s.substeps >= 0 && s.substeps <= 100, "physics.substeps", s.substeps, "0 (default) … 100");
  Require(s.solver_iterations >= 1 && s.solver_iterations <= 1000, "physics.solver_iterations",
          s.solver_iterations, "1 … 1000");
  Require(s.settle_time >= 0.0 && s.settle_time <= 600.0, "physics.settle_time", s.settle_time,
          "in [0, 600] s");
  Require(s.scan_duration >= 0.0 && s.scan_duration <= 60.0, "physics.scan_duration", s.scan_duration,
          "in [0, 60] s");
  Require(s.ft_window > 0.0 && s.ft_window <= 10.0, "physics.ft_window", s.ft_window, "in (0, 10] s");
  Require(s.wall_thickness > 0.0 && s.wall_thickness <= 1.0, "physics.wall_thickness", s.wall_thickness,
          "in (0, 1] m");
  Require(s.runaway_speed > 0.0, "physics.runaway_speed", s.runaway_speed, "> 0 m/s");
}

}  // namespace tubepick::devices::sim
