#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tubepick {

/// A point cloud as plain data: xyz in metres, in the frame its owner names (usually Bin).
using Points = std::vector<Eigen::Vector3f>;

/// Points with unit surface normals (oriented towards the sensor) and PCL-style surface
/// curvature λ0/(λ0+λ1+λ2). All three vectors have the same size.
struct OrientedPoints {
  Points points;
  Points normals;
  std::vector<float> curvature;

  std::size_t size() const { return points.size(); }
};

/// A straight cylinder fitted to part of a tube. `start`/`end` are the centres of its bases
/// (the cylinder's endpoints), in the Bin frame; within a Tube they are ordered along the tube.
struct Cylinder {
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  Eigen::Vector3d end = Eigen::Vector3d::Zero();
  double radius = 0.0;
  /// Index of the segment (region-growing cluster) whose points produced this cylinder.
  std::uint32_t segment_id = 0;
  /// Number of RANSAC inliers that support it.
  std::uint32_t inlier_count = 0;

  double length() const { return (end - start).norm(); }
  Eigen::Vector3d axis() const { return (end - start).normalized(); }
  Eigen::Vector3d centre() const { return 0.5 * (start + end); }
};

enum class Occlusion { kUnspecified = 0, kNone = 1, kWeak = 2, kStrong = 3 };

/// A node of a tube's graph: a free end of the tube or a junction where three or more branches
/// meet. Bin frame.
struct TubeNode {
  Eigen::Vector3d p_Bin = Eigen::Vector3d::Zero();
};

/// One branch of a tube: the chain of cylinders [first_cylinder, first_cylinder + cylinder_count)
/// of Tube::cylinders, ordered and oriented from node `from_node` to node `to_node`. Consecutive
/// cylinders of a branch are linked by a joint; the branch's first cylinder starts at its
/// from_node's position or is linked to it by a joint (a junction), and likewise at its end.
struct TubeBranch {
  std::uint32_t from_node = 0;
  std::uint32_t to_node = 0;
  std::uint32_t first_cylinder = 0;
  std::uint32_t cylinder_count = 0;

  bool operator==(const TubeBranch&) const = default;
};

/// A virtual tube (thesis Def. 4.2.2), generalised to a tree: branches of cylinders between
/// nodes (ends and junctions). A linear tube is the one-branch case and may leave `nodes` and
/// `branches` empty: its cylinders are then one branch, consecutive cylinders linked by a joint
/// from cylinders[i].end to cylinders[i+1].start (core/common/tube_graph.h reads both forms).
struct Tube {
  std::uint32_t id = 0;
  /// All cylinders, branch by branch.
  std::vector<Cylinder> cylinders;
  /// Empty for a linear tube given by its cylinders alone.
  std::vector<TubeNode> nodes;
  /// Empty for a linear tube given by its cylinders alone; otherwise they cover `cylinders`.
  std::vector<TubeBranch> branches;
  Occlusion occlusion = Occlusion::kUnspecified;
  std::uint32_t occluded_joint_count = 0;

  /// Has a junction: a node where three or more branches meet.
  bool branched() const;
  /// Cylinder lengths plus joint lengths (Def. 4.2.6), over all branches.
  double length() const;
};

}  // namespace tubepick
