#pragma once

#include <vector>

#include <Eigen/Geometry>

namespace tubepick::devices::sim {

/// Trapezoidal speed profile along a path of `length` metres: accelerate at `acceleration` up to
/// `speed`, cruise, decelerate to rest (a triangle when the path is too short to reach `speed`).
class TrapezoidProfile {
 public:
  /// @pre length ≥ 0, speed > 0, acceleration > 0.
  TrapezoidProfile(double length, double speed, double acceleration);

  /// Seconds from start to rest.
  double duration() const { return duration_; }
  /// Distance along the path at time t (clamped to [0, length]).
  double DistanceAt(double t) const;

 private:
  double length_;
  double speed_;
  double acceleration_;
  double ramp_time_;
  double duration_;
};

/// A straight TCP motion from one pose to another: translation interpolated linearly, rotation by
/// slerp, both at the same fraction u ∈ [0, 1] of the path.
class PoseSegment {
 public:
  PoseSegment(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to);

  Eigen::Isometry3d At(double u) const;
  double distance() const { return (p1_ - p0_).norm(); }
  /// Rotation angle from `from` to `to`, radians.
  double angle() const { return q0_.angularDistance(q1_); }

 private:
  Eigen::Vector3d p0_, p1_;
  Eigen::Quaterniond q0_, q1_;
};

/// A polyline parametrised by arc length.
class Polyline {
 public:
  explicit Polyline(std::vector<Eigen::Vector3d> points);

  double length() const { return cumulative_.back(); }
  /// The point at arc length s (clamped to [0, length]).
  Eigen::Vector3d At(double s) const;

 private:
  std::vector<Eigen::Vector3d> points_;
  std::vector<double> cumulative_;
};

/// Angle between z of `X_BinTcp` and the downward vertical −z_Bin, radians.
double TiltFromVertical(const Eigen::Isometry3d& X_BinTcp);

}  // namespace tubepick::devices::sim
