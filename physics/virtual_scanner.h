#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "core/common/cell_config.h"
#include "core/common/types.h"
#include "physics/bin_solids.h"
#include "physics/tube_geometry.h"

namespace tubepick::physics {

/// Ground-truth label of a point on the bin or the ground.
constexpr std::int32_t kBinLabel = -1;
/// Ground-truth label of an outlier (a random depth along the ray).
constexpr std::int32_t kOutlierLabel = -2;

/// Pinhole camera of the scanner, pixels. Pixel (i, j) (column, row) looks along
/// ((i − cx)/fx, (j − cy)/fy, 1) in the optical frame (x right, y down, z forward).
///
/// Defaults: a Zivid-class 1920 × 1200 sensor with fx = fy = 1600 px (FOV 61.9° × 41.1°). From
/// the default X_BinSensor (1.1 m above the floor centre, looking down) the field of view spans
/// 1.32 × 0.83 m at floor height and 1.33 × 0.83 m on the ground 1 cm below: the 0.80 × 0.60 m
/// bin, its 1 cm walls and ≥ 10 cm of ground on every side (the ground right behind a wall is
/// hidden by it). One pixel is 0.69 mm on the floor.
struct PinholeIntrinsics {
  int width = 1920;
  int height = 1200;
  double fx = 1600.0;
  double fy = 1600.0;
  double cx = 959.5;
  double cy = 599.5;
};

/// A structured-light scanner simulated by analytic ray casting.
struct ScannerParams {
  PinholeIntrinsics intrinsics;
  /// σ of the Gaussian noise added to each return's range along its ray, metres.
  double depth_noise = 0.0003;
  /// No return where the angle between the ray and the surface normal exceeds this, radians.
  double max_incidence_angle = 80.0 * M_PI / 180.0;
  /// Fraction of returns replaced by an outlier: a range drawn uniformly in [min_range, true range].
  double outlier_fraction = 0.0005;
  /// Hits nearer than min_range or farther than max_range give no return, metres.
  double min_range = 0.2;
  double max_range = 3.0;
  /// ScanScene only: thickness of the bin's walls and floor (match DropParams), metres.
  double wall_thickness = 0.01;
  /// ScanScene only: render the bin solids and the ground plane.
  bool render_bin = true;
  bool render_ground = true;
  /// Threads that cast the rows' rays (OpenMP); 0 = the cores the process may use. The scan does
  /// not depend on it.
  std::uint32_t threads = 0;

  /// @throws InvalidArgument naming the first bad field and its value.
  void Validate() const;
};

/// What the scanner sees, Bin frame. Labels are free (≥ 0 for tubes by convention).
struct ScannerScene {
  struct Sphere {
    Eigen::Vector3d centre;
    double radius;
    std::int32_t label;
  };
  /// The side of a finite cylinder without caps (tubes are hollow).
  struct CylinderSide {
    Eigen::Vector3d start;
    Eigen::Vector3d end;
    double radius;
    std::int32_t label;
  };
  struct Box {
    AlignedBox box;
    std::int32_t label;
  };
  std::vector<Sphere> spheres;
  std::vector<CylinderSide> cylinders;
  std::vector<Box> boxes;
  /// Height of an infinite horizontal ground plane (label kBinLabel), if any.
  std::optional<double> ground_z;
};

/// Tubes (label = index in `tubes_Bin`; a cylinder per edge, a sphere per joint node) plus, when
/// `bin` is given, its boxes (kBinLabel) and ground plane.
ScannerScene MakeScannerScene(const std::vector<TubeGeometry>& tubes_Bin, const BinSolids* bin);

struct ScanResult {
  /// Returns in the sensor's optical frame, metres, row-major pixel order.
  Points points_Sensor;
  /// Per point: the label of the surface hit, or kOutlierLabel.
  std::vector<std::int32_t> labels;
  /// Per point: pixel index row · width + column.
  std::vector<std::uint32_t> pixels;
  /// Pixels whose ray hit something in range but returned nothing (grazing incidence).
  std::uint64_t grazing_dropped = 0;
  /// Points that are outliers.
  std::uint64_t outliers = 0;
};

/// Casts one ray per pixel from X_BinSensor, keeps the nearest hit (so occluded surfaces are
/// missing), drops grazing hits, adds range noise and outliers. Rows run in parallel (OpenMP);
/// every row draws from its own generator seeded from (seed, row), so the result does not depend
/// on the thread count. Primitives are culled per row with their screen-space bounds.
/// @throws InvalidArgument for invalid params or a non-finite pose.
ScanResult RenderScan(const ScannerScene& scene_Bin, const Eigen::Isometry3d& X_BinSensor,
                      const ScannerParams& params, std::uint64_t seed);

/// Scans settled tubes (Bin frame) in the cell's bin from the cell's sensor pose.
ScanResult ScanScene(const std::vector<TubeGeometry>& tubes_Bin, const CellConfig& cell,
                     const ScannerParams& params, std::uint64_t seed);

}  // namespace tubepick::physics
