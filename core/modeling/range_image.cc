#include "core/modeling/range_image.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "core/common/errors.h"

namespace tubepick {
namespace {

constexpr float kEmpty = std::numeric_limits<float>::infinity();
// Points closer to the sensor plane than this (optical z, metres) have no usable projection.
constexpr double kMinDepth = 1e-6;
// Guards against absurd allocations (a tiny pixel angle or points almost in the sensor plane).
constexpr double kMaxPixels = 64.0 * 1024.0 * 1024.0;

}  // namespace

RangeImage::RangeImage(const Points& points_Bin, const Eigen::Isometry3d& X_BinSensor, double pixel_angle)
    : X_SensorBin_(X_BinSensor.inverse()), pixel_angle_(pixel_angle) {
  if (!std::isfinite(pixel_angle) || !(pixel_angle > 0.0)) {
    throw InvalidArgument("pixel_angle: must be finite and > 0, got " + std::to_string(pixel_angle));
  }
  if (!X_BinSensor.matrix().allFinite()) throw InvalidArgument("X_BinSensor: non-finite pose");

  // Pass 1: project, keep the angular extent.
  struct Projected {
    double u, v, depth;
  };
  std::vector<Projected> projected;
  projected.reserve(points_Bin.size());
  double u_min = std::numeric_limits<double>::infinity(), u_max = -u_min;
  double v_min = u_min, v_max = -u_min;
  for (const Eigen::Vector3f& p : points_Bin) {
    const Eigen::Vector3d p_S = X_SensorBin_ * p.cast<double>();
    if (!p_S.allFinite() || p_S.z() <= kMinDepth) continue;
    const double u = p_S.x() / p_S.z();
    const double v = p_S.y() / p_S.z();
    projected.push_back({u, v, p_S.z()});
    u_min = std::min(u_min, u);
    u_max = std::max(u_max, u);
    v_min = std::min(v_min, v);
    v_max = std::max(v_max, v);
  }
  if (projected.empty()) return;  // 0 × 0: nothing is ever covered.

  const double w = std::floor((u_max - u_min) / pixel_angle) + 1.0;
  const double h = std::floor((v_max - v_min) / pixel_angle) + 1.0;
  if (w * h > kMaxPixels) {
    std::ostringstream s;
    s << "pixel_angle: " << pixel_angle << " rad gives a " << w << " x " << h
      << " range image for the cloud's angular extent [" << u_min << ", " << u_max << "] x [" << v_min << ", "
      << v_max << "]; use a larger pixel angle or crop the cloud";
    throw InvalidArgument(s.str());
  }
  u0_ = u_min;
  v0_ = v_min;
  width_ = static_cast<int>(w);
  height_ = static_cast<int>(h);
  depth_.assign(static_cast<std::size_t>(width_) * height_, kEmpty);

  // Pass 2: per pixel, the smallest depth.
  for (const Projected& q : projected) {
    const int iu = std::min(width_ - 1, static_cast<int>((q.u - u0_) / pixel_angle_));
    const int iv = std::min(height_ - 1, static_cast<int>((q.v - v0_) / pixel_angle_));
    float& d = depth_[static_cast<std::size_t>(iv) * width_ + iu];
    d = std::min(d, static_cast<float>(q.depth));
  }
}

bool RangeImage::IsGapCovered(const Eigen::Vector3d& a_Bin, const Eigen::Vector3d& b_Bin, int window,
                              double margin) const {
  if (width_ == 0 || height_ == 0) return false;
  const Eigen::Vector3d a_S = X_SensorBin_ * a_Bin;
  const Eigen::Vector3d b_S = X_SensorBin_ * b_Bin;
  if (!a_S.allFinite() || !b_S.allFinite() || a_S.z() <= kMinDepth || b_S.z() <= kMinDepth) return false;

  // Midpoint of the two projections, in (continuous) pixel coordinates.
  const double mu = 0.5 * ((a_S.x() / a_S.z() - u0_) + (b_S.x() / b_S.z() - u0_)) / pixel_angle_;
  const double mv = 0.5 * ((a_S.y() / a_S.z() - v0_) + (b_S.y() / b_S.z() - v0_)) / pixel_angle_;
  return AnyNearerAround(mu, mv, std::max(a_S.z(), b_S.z()) - margin, window);
}

bool RangeImage::IsPointCovered(const Eigen::Vector3d& p_Bin, int window, double margin) const {
  if (width_ == 0 || height_ == 0) return false;
  const Eigen::Vector3d p_S = X_SensorBin_ * p_Bin;
  if (!p_S.allFinite() || p_S.z() <= kMinDepth) return false;
  return AnyNearerAround((p_S.x() / p_S.z() - u0_) / pixel_angle_, (p_S.y() / p_S.z() - v0_) / pixel_angle_,
                         p_S.z() - margin, window);
}

bool RangeImage::AnyNearerAround(double mu, double mv, double threshold, int window) const {
  const double cu = std::floor(mu);
  const double cv = std::floor(mv);
  if (cu < 0.0 || cv < 0.0 || cu >= width_ || cv >= height_) return false;  // out of the image
  const int iu = static_cast<int>(cu);
  const int iv = static_cast<int>(cv);
  const int r = std::max(0, window);
  const int u_lo = std::max(0, iu - r), u_hi = std::min(width_ - 1, iu + r);
  const int v_lo = std::max(0, iv - r), v_hi = std::min(height_ - 1, iv + r);
  for (int v = v_lo; v <= v_hi; ++v) {
    for (int u = u_lo; u <= u_hi; ++u) {
      if (static_cast<double>(depth(u, v)) < threshold) return true;
    }
  }
  return false;
}

}  // namespace tubepick
