#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "core/common/types.h"

namespace tubepick {

/// A depth image of a cloud seen from the sensor origin (thesis §4.3.4, visibility constraint).
/// Pixels are square in the angular coordinates (x/z, y/z) of the sensor optical frame; each
/// stores the smallest depth (optical z) of the points that fall in it.
class RangeImage {
 public:
  /// @param pixel_angle angular pixel size, radians (> 0). The image spans the angular extent
  ///        of the points in front of the sensor; an empty cloud gives a 0 × 0 image.
  /// @throws InvalidArgument for a non-positive pixel_angle, a non-finite pose, or an image that
  ///         would exceed 64 Mi pixels (named "pixel_angle").
  RangeImage(const Points& points_Bin, const Eigen::Isometry3d& X_BinSensor, double pixel_angle);

  /// True when some pixel within `window` pixels (Chebyshev) of the projection of the midpoint
  /// of the projections of `a_Bin` and `b_Bin` holds a depth smaller than the larger depth of the
  /// two endpoints minus `margin`: something lies between the gap and the sensor. False when the
  /// midpoint falls outside the image or an endpoint is not in front of the sensor.
  bool IsGapCovered(const Eigen::Vector3d& a_Bin, const Eigen::Vector3d& b_Bin, int window,
                    double margin = 0.0) const;

  /// The same test at one point: some pixel within `window` pixels of p_Bin's projection holds a
  /// depth smaller than p_Bin's minus `margin` (a negative margin also counts a surface that far
  /// behind p_Bin). False outside the image or behind the sensor.
  bool IsPointCovered(const Eigen::Vector3d& p_Bin, int window, double margin = 0.0) const;

  int width() const { return width_; }
  int height() const { return height_; }
  /// Depth at pixel (u, v); +inf when empty.
  float depth(int u, int v) const { return depth_[static_cast<std::size_t>(v) * width_ + u]; }

 private:
  /// Whether a pixel within `window` of continuous pixel coordinates (mu, mv) holds a depth below
  /// `threshold`; false outside the image.
  bool AnyNearerAround(double mu, double mv, double threshold, int window) const;

  Eigen::Isometry3d X_SensorBin_;
  double pixel_angle_;
  double u0_ = 0.0, v0_ = 0.0;  // angular coordinate of pixel (0, 0)
  int width_ = 0, height_ = 0;
  std::vector<float> depth_;
};

}  // namespace tubepick
