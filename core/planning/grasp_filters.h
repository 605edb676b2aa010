#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/common/types.h"
#include "core/planning/grasp_synthesis.h"
#include "core/planning/tool_clearance.h"
#include "core/planning/trajectory.h"

namespace tubepick {

/// The three grasp viability tests (thesis §5.2.4.1, Table 5.3).
struct GraspFilterParams {
  /// Finger box size across the tube (along the closing direction y_Tcp), metres.
  double finger_thickness = 0.01;
  /// Finger box size along the tube (x_Tcp), metres (Robotiq 2F-85 pad: 22 mm).
  double finger_width = 0.022;
  /// Finger box size along the approach (z_Tcp, vertical), metres.
  double finger_length = 0.05;
  /// How far the fingertips reach past the grasp point along the approach (below the tube axis),
  /// metres.
  double finger_tip_depth = 0.005;
  /// A grasp is rejected when more than this many raw points lie inside the finger boxes
  /// (Table 5.3: 20).
  std::uint32_t max_points_in_fingers = 20;
  /// Beyond the thesis: the tool's way down. A grasp is rejected when more than
  /// max_points_in_approach raw points lie in the columns the pads and the housing sweep on the
  /// vertical approach (ApproachColumns), from above the finger boxes and from the housing's
  /// bottom (ToolParams) up to approach_column_height above the grasp point. The finger test
  /// looks at the grasp pose only: a branch standing up beside the grasp, or a tube crossing
  /// higher up, meets the gripper on its way down (in the simulated cell: the F/T reference at
  /// the pre-grasp pose disturbed, a safe stop).
  bool approach_check = true;
  std::uint32_t max_points_in_approach = 20;
  double approach_column_height = 0.5;
  /// Cell size of the xy grid the raw cloud is binned into once per plan, metres.
  double grid_cell_size = 0.01;
  /// Workspace box, bin frame: every waypoint added to the grasp point must lie inside, metres.
  Eigen::Vector3d workspace_min{-0.50, -0.40, -0.05};
  Eigen::Vector3d workspace_max{0.50, 0.40, 1.00};
};

/// A box of half extents `half_size` centred at X_BinBox's origin, axes along its rotation.
struct OrientedBox {
  Eigen::Isometry3d X_BinBox = Eigen::Isometry3d::Identity();
  Eigen::Vector3d half_size = Eigen::Vector3d::Zero();

  bool Contains(const Eigen::Vector3d& p_Bin) const;
};

/// The raw cloud binned once into an xy grid (counting sort: points stored cell by cell), so a
/// box query only visits the cells under the box's xy footprint. Building is O(N); the grid
/// spans the kept points' xy bounds and doubles its cell size while it would exceed 4 M cells.
class RawCloudIndex {
 public:
  /// Keeps the finite points with z in [z_min, z_max]: queries are exact for boxes within that
  /// band (the planner passes the band every finger box lies in, which drops the floor).
  /// @pre cell_size > 0
  RawCloudIndex(const Points& points_Bin, double cell_size,
                double z_min = -std::numeric_limits<double>::infinity(),
                double z_max = std::numeric_limits<double>::infinity());

  /// Number of points inside `box`, counting at most up to `limit` + 1 (stops early).
  std::size_t CountInBox(const OrientedBox& box, std::size_t limit) const;

  std::size_t size() const { return points_.size(); }
  double cell_size() const { return cell_; }

 private:
  double cell_ = 0.01;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  int nx_ = 0;
  int ny_ = 0;
  /// Points of cell c (c = iy·nx + ix) are points_[cell_start_[c], cell_start_[c + 1]).
  std::vector<std::uint32_t> cell_start_;
  Points points_;
};

/// The two finger boxes at the pre-grasp pose (open fingers, TCP at the grasp point): in the TCP
/// frame, centred at (0, ±(opening_width + finger_thickness)/2, finger_tip_depth −
/// finger_length/2) with half sizes (finger_width, finger_thickness, finger_length)/2.
std::array<OrientedBox, 2> FingerBoxes(const Grasp& grasp, const GraspFilterParams& params);

/// The z band [lo, hi] every finger box of a grasp on `tubes` lies in: a grasp point's z is
/// between its cylinder's endpoint heights and the boxes span [G_z − finger_tip_depth,
/// G_z − finger_tip_depth + finger_length] (a vertical TCP z axis); with approach_check, up
/// to the approach columns' top (G_z + approach_column_height). Empty tubes ⇒ (0, 0).
/// Tilted grasps (GraspParams::max_tilt) reach lower and higher by the pads' reach across the
/// tube (half the opening plus a pad) times sin(max_tilt).
std::pair<double, double> FingerBandZ(const std::vector<Tube>& tubes, const GraspFilterParams& params,
                                      const GraspParams& grasps = GraspParams{});

/// The columns the tool sweeps on its vertical approach to `grasp` (opened to its opening width):
/// above each finger box (the pads, GraspFilterParams' finger size) and above the housing's bottom
/// (ToolParams: housing_size centred on the TCP's z axis, its bottom housing_gap above the pads'
/// top), each up to approach_column_height above the grasp point.
std::array<OrientedBox, 3> ApproachColumns(const Grasp& grasp, const GraspFilterParams& params,
                                           const ToolParams& tool);

/// More than max_points_in_approach raw points in the approach columns (together).
bool ApproachBlocked(const Grasp& grasp, const RawCloudIndex& raw, const GraspFilterParams& params,
                     const ToolParams& tool);

/// Filter (a): more than max_points_in_fingers raw points inside the finger boxes (together).
bool FingersCollide(const Grasp& grasp, const RawCloudIndex& raw, const GraspFilterParams& params);

/// Filter (b): the grasp point plus every waypoint lies inside the workspace box (inclusive).
bool InsideWorkspace(const Grasp& grasp, const Trajectory& trajectory, const GraspFilterParams& params);

/// Filter (c): the grasp's cylinder is in [section_begin, section_end) of the trajectory, or, when
/// the trajectory has a section_mask (a branched tube's escape), marked in it.
bool InAllowedSection(const Grasp& grasp, const Trajectory& trajectory);

}  // namespace tubepick
