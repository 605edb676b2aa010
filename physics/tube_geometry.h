#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/common/types.h"

namespace tubepick::physics {

/// A node of a ground-truth tube: an endpoint, a joint between two cylinders or a bifurcation.
/// Nodes of degree ≥ 2 carry a joint sphere of `radius` (thesis §4.5.1); endpoints do not.
struct TubeNode {
  int id = 0;
  /// Sphere centre, metres, in the frame of the owning TubeGeometry.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

/// One cylinder of a ground-truth tube, from node1 to node2 (the published `tube_configurations`
/// edge). `centre`, `orientation` and `length` are redundant with the node centres; they are kept
/// because the published files carry them (SetEdgeFromNodes recomputes them).
struct TubeEdge {
  /// "e_<node1>_<node2>" in generated tubes; any token in read files.
  std::string name;
  int node1 = 0;
  int node2 = 0;
  /// Position (1..P) of this cylinder along the chain of cylinders between two branch/end nodes.
  int order = 1;
  double radius = 0.0;
  /// Midpoint of node1 and node2.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  /// Rotation whose local z axis is (node2 − node1)/|node2 − node1|; roll about z is arbitrary.
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  /// |node2 − node1|, metres.
  double length = 0.0;
};

/// A ground-truth tube as plain data: a graph of nodes joined by straight cylinders (edges).
/// Linear tubes are paths; branched tubes (set C) are trees. All positions are in one frame,
/// usually Bin.
struct TubeGeometry {
  int id = 0;
  std::vector<TubeNode> nodes;
  std::vector<TubeEdge> edges;

  /// Index into `nodes` of the node with `node_id`, or −1.
  int FindNode(int node_id) const;
  /// The node with `node_id`. @throws InvalidArgument when there is none.
  const TubeNode& Node(int node_id) const;
  /// Number of edges that touch the node.
  int Degree(int node_id) const;
  /// True when a joint sphere sits on the node (degree ≥ 2).
  bool IsJoint(int node_id) const { return Degree(node_id) >= 2; }

  /// One cylinder per edge, in edge order, start = node1 centre, end = node2 centre (Bin frame
  /// when the geometry is). segment_id is the edge index.
  std::vector<Cylinder> Cylinders() const;
  /// Sum of the edge lengths (computed from the node centres), metres.
  double Length() const;
  /// Connected, acyclic, no node of degree > 2 and at least one edge.
  bool IsLinear() const;
  /// Centre points along a linear tube, from one end to the other: starts at the end node whose
  /// edge has the lowest `order` (ties: the lower node id), so generated and read tubes run
  /// node1 → node2 of the first chain. @throws InvalidArgument when the tube is not linear.
  std::vector<Eigen::Vector3d> Centreline() const;
  /// The tube as a core Tube: a linear tube's cylinders ordered along the centreline (joints of
  /// zero length, no explicit graph); a tree's with its graph (a node per end and junction, a
  /// branch per chain of edges between them; segment_id is the edge index).
  /// @throws InvalidArgument when the tube is neither (a cycle, or not connected).
  Tube ToTube() const;

  /// This geometry moved rigidly by X_NewOld (nodes, edge centres and orientations).
  TubeGeometry Transformed(const Eigen::Isometry3d& X_NewOld) const;
};

/// Recomputes centre, orientation (minimal rotation from +z) and length of `edge` from the
/// centres of its nodes in `tube`. @throws InvalidArgument for unknown nodes.
void SetEdgeFromNodes(const TubeGeometry& tube, TubeEdge& edge);

/// Quaternion rotating +z onto `direction` (non-zero) by the smallest angle; a half turn about x
/// when `direction` points along −z.
Eigen::Quaterniond RotationFromZ(const Eigen::Vector3d& direction);

}  // namespace tubepick::physics
