#include "devices/sim/sim_motion.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace tubepick::devices::sim {

TrapezoidProfile::TrapezoidProfile(double length, double speed, double acceleration)
    : length_(length), speed_(speed), acceleration_(acceleration) {
  assert(length >= 0.0 && speed > 0.0 && acceleration > 0.0);
  if (length_ * acceleration_ < speed_ * speed_) speed_ = std::sqrt(length_ * acceleration_);  // triangle
  ramp_time_ = speed_ / acceleration_;
  duration_ = speed_ > 0.0 ? length_ / speed_ + ramp_time_ : 0.0;
}

double TrapezoidProfile::DistanceAt(double t) const {
  if (t <= 0.0 || duration_ <= 0.0) return 0.0;
  if (t >= duration_) return length_;
  const double ramp = 0.5 * acceleration_ * ramp_time_ * ramp_time_;
  if (t < ramp_time_) return 0.5 * acceleration_ * t * t;
  if (t > duration_ - ramp_time_) {
    const double r = duration_ - t;
    return length_ - 0.5 * acceleration_ * r * r;
  }
  return ramp + speed_ * (t - ramp_time_);
}

PoseSegment::PoseSegment(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to)
    : p0_(from.translation()),
      p1_(to.translation()),
      q0_(Eigen::Quaterniond(from.linear()).normalized()),
      q1_(Eigen::Quaterniond(to.linear()).normalized()) {
  if (q0_.dot(q1_) < 0.0) q1_.coeffs() = -q1_.coeffs();  // the short way round
}

Eigen::Isometry3d PoseSegment::At(double u) const {
  u = std::clamp(u, 0.0, 1.0);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = q0_.slerp(u, q1_).normalized().toRotationMatrix();
  X.translation() = p0_ + u * (p1_ - p0_);
  return X;
}

Polyline::Polyline(std::vector<Eigen::Vector3d> points) : points_(std::move(points)) {
  cumulative_.push_back(0.0);
  for (std::size_t i = 1; i < points_.size(); ++i) {
    cumulative_.push_back(cumulative_.back() + (points_[i] - points_[i - 1]).norm());
  }
}

Eigen::Vector3d Polyline::At(double s) const {
  if (points_.empty()) return Eigen::Vector3d::Zero();
  if (s >= length()) return points_.back();
  if (s <= 0.0) return points_.front();
  const std::size_t k = std::upper_bound(cumulative_.begin(), cumulative_.end(), s) - cumulative_.begin();
  const double t = (s - cumulative_[k - 1]) / (cumulative_[k] - cumulative_[k - 1]);
  return points_[k - 1] + t * (points_[k] - points_[k - 1]);
}

double TiltFromVertical(const Eigen::Isometry3d& X_BinTcp) {
  const double c = std::clamp(-X_BinTcp.linear()(2, 2), -1.0, 1.0);
  return std::acos(c);
}

}  // namespace tubepick::devices::sim
