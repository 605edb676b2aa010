#include "core/wrench/wrench_params.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "core/common/errors.h"
#include "core/common/require.h"

namespace tubepick {
namespace {

// Cosine tolerance for "perpendicular": about 0.06°.
constexpr double kPerpendicularTol = 1e-3;

std::string Format(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return s.str();
}

void RequireNonZeroVector(const Eigen::Vector3d& v, const std::string& key) {
  if (!v.allFinite() || v.norm() < 1e-9)
    throw InvalidArgument(key + ": must be a finite non-zero vector, got " + Format(v));
}

void RequirePerpendicular(const Eigen::Vector3d& v, const std::string& key, const Eigen::Vector3d& to,
                          const std::string& to_name) {
  if (std::abs(v.normalized().dot(to.normalized())) > kPerpendicularTol) {
    throw InvalidArgument(key + ": " + Format(v) + " must be perpendicular to " + to_name + " " + Format(to));
  }
}

}  // namespace

void WrenchParams::Validate() const {
  RequirePositive(gravity, "wrench.gravity");
  RequireNonNegative(force_tolerance, "wrench.force_tolerance");
  RequireFinite(force_tolerance_share, "wrench.force_tolerance_share");
  if (!(force_tolerance_share >= 0.0 && force_tolerance_share < 1.0)) {
    std::ostringstream s;
    s << "wrench.force_tolerance_share: " << force_tolerance_share
      << " is out of range [0, 1) (a share of one tube's weight; 0 = wrench.force_tolerance alone)";
    throw InvalidArgument(s.str());
  }
  RequireNonZeroVector(up_Tcp, "wrench.up_Tcp");
  RequireInRange(max_tilt, 0.0, M_PI / 2.0, "wrench.max_tilt");
  RequireFinite(rotation_angle, "wrench.rotation_angle");
  if (!(rotation_angle > 0.0 && rotation_angle <= M_PI)) {
    std::ostringstream s;
    s << "wrench.rotation_angle: " << rotation_angle << " rad is out of range (0, pi]";
    throw InvalidArgument(s.str());
  }
  RequirePositive(min_torque, "wrench.min_torque");
  switch (variant) {
    case ResolutionVariant::kTorqueAxis:
    case ResolutionVariant::kTorqueAxisNegative:
    case ResolutionVariant::kPerpendicular:
    case ResolutionVariant::kJointSafe:
    case ResolutionVariant::kTorqueAxisThenPerpendicular:
      break;
    default:
      throw InvalidArgument("wrench.variant: unknown value " + std::to_string(static_cast<int>(variant)));
  }
  RequireNonZeroVector(joint_safe_axis, "wrench.joint_safe_axis");
  switch (joint_safe_frame) {
    case JointSafeFrame::kTcp:
      RequirePerpendicular(joint_safe_axis, "wrench.joint_safe_axis", up_Tcp, "wrench.up_Tcp");
      break;
    case JointSafeFrame::kBin:
      RequirePerpendicular(joint_safe_axis, "wrench.joint_safe_axis", Eigen::Vector3d::UnitZ(),
                           "the bin's z");
      break;
    default:
      throw InvalidArgument("wrench.joint_safe_frame: unknown value " +
                            std::to_string(static_cast<int>(joint_safe_frame)));
  }
}

double EffectiveForceTolerance(const WrenchParams& params, double tube_weight) {
  if (params.force_tolerance_share <= 0.0) return params.force_tolerance;
  return std::min(params.force_tolerance, params.force_tolerance_share * tube_weight);
}

std::string ToString(ResolutionVariant variant) {
  switch (variant) {
    case ResolutionVariant::kTorqueAxis:
      return "torque_axis";
    case ResolutionVariant::kTorqueAxisNegative:
      return "torque_axis_negative";
    case ResolutionVariant::kPerpendicular:
      return "perpendicular";
    case ResolutionVariant::kJointSafe:
      return "joint_safe";
    case ResolutionVariant::kTorqueAxisThenPerpendicular:
      return "torque_axis_then_perpendicular";
  }
  return "unknown";
}

ResolutionVariant ParseResolutionVariant(const std::string& text, const std::string& field) {
  for (ResolutionVariant v : {ResolutionVariant::kTorqueAxis, ResolutionVariant::kTorqueAxisNegative,
                              ResolutionVariant::kPerpendicular, ResolutionVariant::kJointSafe,
                              ResolutionVariant::kTorqueAxisThenPerpendicular}) {
    if (text == ToString(v)) return v;
  }
  throw InvalidArgument(field + ": unknown resolution variant '" + text +
                        "' (expected torque_axis, torque_axis_negative, perpendicular, joint_safe or "
                        "torque_axis_then_perpendicular)");
}

std::string ToString(JointSafeFrame frame) {
  switch (frame) {
    case JointSafeFrame::kTcp:
      return "tcp";
    case JointSafeFrame::kBin:
      return "bin";
  }
  return "unknown";
}

JointSafeFrame ParseJointSafeFrame(const std::string& text, const std::string& field) {
  if (text == "tcp") return JointSafeFrame::kTcp;
  if (text == "bin") return JointSafeFrame::kBin;
  throw InvalidArgument(field + ": unknown frame '" + text + "' (expected tcp or bin)");
}

}  // namespace tubepick
