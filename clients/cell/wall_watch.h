#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/cell_config.h"
#include "devices/scanner.h"
#include "tubepick/v1/planning.pb.h"

namespace tubepick::cell {

/// Which scans count a tube as hanging over a wall, and when it is gone.
struct WallWatchParams {
  /// Off: nothing is watched.
  bool enabled = true;
  /// A tube hangs over a wall where the top of its surface at a point of its axis (the axis point
  /// raised by the cylinder's radius) lies no lower than this below the wall top, m, ...
  double below_top = 0.0;
  /// ... and the point no farther than this inside the wall's inner face (or past it), m. Wider
  /// limits name more falls and warn more often for tubes that only slid inside the bin: on ten
  /// simulated 20-tree bins (seeds 11-20, docs/ACCURACY.md "Hard bins"), where seed 14 lost three
  /// trees together 1.8-3.5 cm from the walls, their tops 0.1-3 cm under the wall top, the limits
  /// (0, 0) named none of them and warned once for a tree that stayed in the bin; (0.005, 0.02)
  /// named them and warned 5 times; (0.02, 0.04) 9 times.
  double from_wall = 0.0;
  /// Gone when the next scan has fewer than `min_points` points within this of that point, m,
  /// leaving out the wall's own (its inner face and its top).
  double gone_distance = 0.03;
  std::uint32_t min_points = 20;

  /// @throws InvalidArgument naming the first bad field and its value.
  void Validate() const;
};

/// A tube a scan shows hanging over a bin wall: its top reaches the wall's top at the wall. Such
/// a tube leans on the wall and on what lies under it; when that moves it can fall out of the bin,
/// where no scan of the bin sees it (in a simulated 20-tree bin, a tree leaning on the -y wall fell
/// over it when the tree it leaned on was picked).
struct TubeOverWall {
  std::uint32_t tube_id = 0;
  /// The highest such point of its axis, bin frame, m.
  Eigen::Vector3d p_Bin = Eigen::Vector3d::Zero();
  /// "+x", "-x", "+y" or "-y": the wall it hangs over.
  std::string wall;
  /// The scan that showed it.
  std::uint32_t scan = 0;
};

/// The tubes of `response` that hang over a wall of `bin` (one entry per tube, its highest point).
std::vector<TubeOverWall> TubesOverWalls(const v1::PlanPickResponse& response, const BinConfig& bin,
                                         std::uint32_t scan, const WallWatchParams& params);

/// Points of `capture` within `distance` of p_Bin, leaving out the walls of `bin` (points at or
/// below the wall top within 5 mm of an inner face, or past it).
std::size_t PointsNear(const devices::Capture& capture, const Eigen::Vector3d& p_Bin, double distance,
                       const BinConfig& bin);

/// Those of `before` that the next scan, `after`, no longer shows (fewer than min_points points
/// within gone_distance of their point: the cloud, not the next model, which may split or renumber
/// a tube that is still there) and that no attempt or nudge since took (`touched`: their tube ids
/// in before's scan).
std::vector<TubeOverWall> VanishedOverWalls(const std::vector<TubeOverWall>& before,
                                            const devices::Capture& after, const BinConfig& bin,
                                            const std::vector<std::uint32_t>& touched,
                                            const WallWatchParams& params);

/// "over the -y wall at (-0.030, -0.304, 0.220) m, not seen again after scan 5".
std::string Describe(const TubeOverWall& tube);

}  // namespace tubepick::cell
