#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/types.h"

namespace tubepick {

/// The branches of a tube: Tube::branches, or for a linear tube given by its cylinders alone the
/// one branch over all of them, from node 0 to node 1.
std::vector<TubeBranch> BranchesOf(const Tube& tube);

/// The nodes of a tube: Tube::nodes, or for a linear tube given by its cylinders alone its two
/// ends (the first cylinder's start, the last one's end). Empty for a tube without cylinders.
std::vector<TubeNode> NodesOf(const Tube& tube);

/// The tube with explicit nodes and branches (a linear tube given by its cylinders alone gets its
/// one branch and two end nodes); otherwise unchanged.
Tube WithExplicitGraph(Tube tube);

/// The same tube without nodes where exactly two branches meet: each such pair of branches
/// becomes one branch (a joint links them where the node was). A tree whose only nodes of
/// degree > 1 had degree 2 becomes a one-branch (linear) tube. Cylinders keep their geometry;
/// they are reordered branch by branch and oriented along their branch.
Tube WithoutPassThroughNodes(Tube tube);

/// Number of branches meeting at each node (its degree): 1 at an end, ≥ 3 at a junction.
std::vector<std::uint32_t> NodeDegrees(const Tube& tube);

/// A joint: the straight link between two consecutive cylinders of a branch, or between a
/// junction node and the first (last) cylinder of a branch that leaves (reaches) it.
struct TubeJoint {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  /// Cylinder at `a`, or −1 when `a` is a junction node.
  std::int32_t cylinder_a = -1;
  /// Cylinder at `b`, or −1 when `b` is a junction node.
  std::int32_t cylinder_b = -1;
  /// Mean radius of the cylinders it links.
  double radius = 0.0;
  std::uint32_t branch = 0;

  /// A link to a junction node (not between two cylinders).
  bool junction_link() const { return cylinder_a < 0 || cylinder_b < 0; }
  double length() const { return (b - a).norm(); }
};

/// Every joint of the tube, branch by branch: the link from the branch's from_node when the node
/// is not where the first cylinder starts, the joints between consecutive cylinders, the link to
/// the to_node likewise. For a linear tube joint i links cylinders[i].end to cylinders[i+1].start.
std::vector<TubeJoint> TubeJoints(const Tube& tube);

/// A straight piece of a tube's axis: a cylinder or a joint.
struct AxisPiece {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double radius = 0.0;
  /// The cylinder's index, or −1 for a joint.
  std::int32_t cylinder = -1;
};

/// The tube's axis as straight pieces, branch by branch: the branch's link from its from_node,
/// then each cylinder followed by its joint to the next, then the link to its to_node. For a
/// linear tube: cylinder 0, joint 0, cylinder 1, ...
std::vector<AxisPiece> TubeAxisPieces(const Tube& tube);

/// Length of each branch's axis (BranchesOf order): its cylinders, the joints between them and
/// its links to its nodes (TubeJoints).
std::vector<double> BranchLengths(const Tube& tube);

/// Length-weighted centre of the tube's axis (cylinders and joints): the mass centre of a tube of
/// uniform section. @pre the tube has a cylinder of non-zero length.
Eigen::Vector3d TubeMassCentre(const Tube& tube);

/// Checks the graph of a tube from outside (a request, a file): branches cover the cylinders in
/// order without gaps or overlaps, every branch has a cylinder, node indices exist, every node
/// is used, nodes and cylinders are finite. `name` prefixes the messages ("tubes[3]").
/// @throws InvalidArgument naming the field and the value.
void ValidateTubeGraph(const Tube& tube, const std::string& name);

}  // namespace tubepick
