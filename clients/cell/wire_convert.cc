#include "clients/cell/wire_convert.h"

#include <fmt/core.h>

#include <bit>
#include <cmath>
#include <cstdint>

#include "core/common/errors.h"

namespace tubepick::cell {

v1::Vector3 ToWire(const Eigen::Vector3d& v) {
  v1::Vector3 out;
  out.set_x(v.x());
  out.set_y(v.y());
  out.set_z(v.z());
  return out;
}

Eigen::Vector3d FromWire(const v1::Vector3& v) { return {v.x(), v.y(), v.z()}; }

v1::Pose ToWire(const Eigen::Isometry3d& X) {
  v1::Pose out;
  *out.mutable_position() = ToWire(Eigen::Vector3d(X.translation()));
  const Eigen::Quaterniond q(X.rotation());
  v1::Quaternion* o = out.mutable_orientation();
  o->set_x(q.x());
  o->set_y(q.y());
  o->set_z(q.z());
  o->set_w(q.w());
  return out;
}

Eigen::Isometry3d FromWire(const v1::Pose& pose, const std::string& field) {
  const v1::Quaternion& o = pose.orientation();
  Eigen::Quaterniond q(o.w(), o.x(), o.y(), o.z());
  const Eigen::Vector3d p = FromWire(pose.position());
  if (!p.allFinite() || !q.coeffs().allFinite() || q.norm() < 1e-6)
    throw InvalidArgument(
        fmt::format("{}: not a finite rigid pose (position ({}, {}, {}), quaternion xyzw "
                    "({}, {}, {}, {}))",
                    field, p.x(), p.y(), p.z(), o.x(), o.y(), o.z(), o.w()));
  q.normalize();
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = q.toRotationMatrix();
  X.translation() = p;
  return X;
}

v1::Wrench ToWire(const devices::WrenchReading& reading) {
  v1::Wrench out;
  *out.mutable_force() = ToWire(reading.force);
  *out.mutable_torque() = ToWire(reading.torque);
  return out;
}

v1::LengthUnit ToWire(LengthUnit unit) {
  return unit == LengthUnit::kMillimetre ? v1::LENGTH_UNIT_MILLIMETRE : v1::LENGTH_UNIT_METRE;
}

v1::CellDescription ToCellDescription(const CellConfig& cell, const Eigen::Isometry3d& X_BinSensor) {
  v1::CellDescription out;
  *out.mutable_bin_inner_size() = ToWire(cell.bin.inner_size);
  *out.mutable_sensor_pose() = ToWire(X_BinSensor);
  out.set_tube_radius(cell.tube.radius);
  out.set_tube_length(cell.tube.length);
  out.set_tube_mass(cell.tube.mass);
  *out.mutable_place_pose() = ToWire(cell.place.X_BinPlace);
  return out;
}

std::string TrajectoryKindName(v1::TrajectoryKind kind) {
  switch (kind) {
    case v1::TRAJECTORY_KIND_UPWARD:
      return "upward";
    case v1::TRAJECTORY_KIND_ESCAPE:
      return "escape";
    case v1::TRAJECTORY_KIND_OCCLUSION_ESCAPE:
      return "occlusion_escape";
    default:
      break;
  }
  return "unspecified";
}

std::string HeldOutcomeName(v1::HeldOutcome outcome) {
  switch (outcome) {
    case v1::HELD_OUTCOME_NONE:
      return "none";
    case v1::HELD_OUTCOME_SINGLE:
      return "single";
    case v1::HELD_OUTCOME_MULTIPLE:
      return "multiple";
    default:
      break;
  }
  return "unspecified";
}

}  // namespace tubepick::cell
