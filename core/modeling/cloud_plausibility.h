#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/cell_config.h"
#include "core/common/types.h"
#include "core/modeling/bin_walls.h"

namespace tubepick {

/// Thresholds of the check that a cloud, once in the bin frame, looks like the cell: a wrong
/// unit or sensor pose must fail loudly instead of cropping every point away ("bin empty").
struct PlausibilityParams {
  /// false skips the check (the evidence is still computed; bin_empty still needs the floor).
  bool check = true;
  /// The bin volume: the bin's inner x/y extent grown by margin_xy, z from -below_floor to the
  /// wall height + above_walls, metres.
  double margin_xy = 0.05;
  double below_floor = 0.05;
  double above_walls = 0.25;
  /// Fewest of the finite points that must fall inside the bin volume, share in [0, 1].
  double min_inside_share = 0.25;
  /// A point lies on the floor when |z| <= floor_tolerance inside the bin's x/y extent, metres.
  double floor_tolerance = 0.03;
  /// The floor is seen when at least min_floor_points points, and at least min_floor_share of the
  /// points inside the bin volume, lie on it.
  std::uint32_t min_floor_points = 50;
  double min_floor_share = 0.01;
  /// The bin's inner wall faces, where the scan shows them (FindBinWalls), must lie within this of
  /// where bin.inner_size puts them, metres; 0 = no wall check.
  double wall_tolerance = 0.04;
  /// A wall face counts as seen with at least this many sampled points per height band.
  std::uint32_t wall_min_points = 30;

  /// @throws InvalidArgument naming the key ("modeling.plausibility.floor_tolerance", ...).
  void Validate() const;
};

/// The evidence of CheckCloudAgainstCell.
struct CloudPlausibility {
  std::uint64_t points = 0;    ///< finite points checked
  std::uint64_t inside = 0;    ///< inside the bin volume
  std::uint64_t on_floor = 0;  ///< within floor_tolerance of z = 0 inside the bin's x/y extent
  double inside_share = 0.0;   ///< inside / points
  double floor_share = 0.0;    ///< on_floor / inside (0 when nothing is inside)
  bool enough_inside = false;  ///< inside_share >= min_inside_share
  bool floor_seen = false;     ///< on_floor passes min_floor_points and min_floor_share
  /// Robust (1st to 99th percentile) axis-aligned extent of the cloud in the bin frame, metres,
  /// and its median point.
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();
  Eigen::Vector3d median = Eigen::Vector3d::Zero();
  /// Largest extent over the bin's largest inner size (about 1 for a scan of the cell, about 1000
  /// for millimetres read as metres, about 0.001 for metres read as millimetres).
  double extent_ratio = 0.0;
  /// The inner wall faces the scan shows, against the cell's bin.
  BinWalls walls;

  bool plausible() const { return enough_inside && floor_seen && walls.fit(); }
};

/// The evidence of CheckCloudAgainstCell, gathered one point at a time, so that the pass that brings
/// a cloud into the bin frame measures it too (cloud_prepare.h). Add the finite points in order, then
/// Finish once.
class PlausibilityTally {
 public:
  /// `expected_points`: how many points may be added (sets the stride of the extent sample: every
  /// k-th point, about 100 k of them).
  PlausibilityTally(const BinConfig& bin, const PlausibilityParams& params, std::size_t expected_points);

  /// Adds n finite points given as coordinate arrays: the same as Add() of each, in order.
  void Add(const float* x_Bin, const float* y_Bin, const float* z_Bin, std::size_t n);

  void Add(const Eigen::Vector3f& p_Bin) {
    const float x = std::abs(p_Bin.x()), y = std::abs(p_Bin.y()), z = p_Bin.z();
    inside_ += (x <= volume_x_ && y <= volume_y_ && z >= volume_z_lo_ && z <= volume_z_hi_) ? 1 : 0;
    on_floor_ += (x <= floor_x_ && y <= floor_y_ && std::abs(z) <= floor_tolerance_) ? 1 : 0;
    if (until_sample_-- == 0) {
      sample_.push_back(p_Bin);
      until_sample_ = stride_ - 1;
    }
    ++points_;
  }

  CloudPlausibility Finish() const;

 private:
  const BinConfig& bin_;
  const PlausibilityParams& params_;
  float volume_x_, volume_y_, volume_z_lo_, volume_z_hi_, floor_x_, floor_y_, floor_tolerance_;
  std::size_t stride_ = 1, until_sample_ = 0;
  std::uint64_t points_ = 0, inside_ = 0, on_floor_ = 0;
  Points sample_;
};

/// Measures how well `points_Bin` (metres, bin frame) fits `bin`. Pure; O(n).
CloudPlausibility CheckCloudAgainstCell(const Points& points_Bin, const BinConfig& bin,
                                        const PlausibilityParams& params);

/// The message for an implausible cloud: the evidence and the likely cause (the unit when the
/// extent is ~1000× or ~1/1000 of the bin's, else the sensor pose).
std::string DescribeImplausibleCloud(const CloudPlausibility& evidence, const BinConfig& bin, LengthUnit unit,
                                     const Eigen::Isometry3d& X_BinSensor, const PlausibilityParams& params);

/// Throws when `evidence` says the cloud does not look like the cell (params.check = false: never).
/// @throws FailedPrecondition with DescribeImplausibleCloud's message.
void RequirePlausible(const CloudPlausibility& evidence, const BinConfig& bin, LengthUnit unit,
                      const Eigen::Isometry3d& X_BinSensor, const PlausibilityParams& params);

}  // namespace tubepick
