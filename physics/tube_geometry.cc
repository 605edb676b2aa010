#include "physics/tube_geometry.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "core/common/errors.h"

namespace tubepick::physics {

int TubeGeometry::FindNode(int node_id) const {
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i].id == node_id) return static_cast<int>(i);
  }
  return -1;
}

const TubeNode& TubeGeometry::Node(int node_id) const {
  const int index = FindNode(node_id);
  if (index < 0) {
    throw InvalidArgument("tube " + std::to_string(id) + ": no node with id " + std::to_string(node_id));
  }
  return nodes[index];
}

int TubeGeometry::Degree(int node_id) const {
  int degree = 0;
  for (const TubeEdge& e : edges) degree += (e.node1 == node_id) + (e.node2 == node_id);
  return degree;
}

std::vector<Cylinder> TubeGeometry::Cylinders() const {
  std::vector<Cylinder> cylinders;
  cylinders.reserve(edges.size());
  for (std::size_t i = 0; i < edges.size(); ++i) {
    Cylinder c;
    c.start = Node(edges[i].node1).centre;
    c.end = Node(edges[i].node2).centre;
    c.radius = edges[i].radius;
    c.segment_id = static_cast<std::uint32_t>(i);
    cylinders.push_back(c);
  }
  return cylinders;
}

double TubeGeometry::Length() const {
  double sum = 0.0;
  for (const TubeEdge& e : edges) sum += (Node(e.node2).centre - Node(e.node1).centre).norm();
  return sum;
}

bool TubeGeometry::IsLinear() const {
  if (edges.empty()) return false;
  std::map<int, int> degree;
  for (const TubeEdge& e : edges) {
    if (e.node1 == e.node2 || FindNode(e.node1) < 0 || FindNode(e.node2) < 0) return false;
    ++degree[e.node1];
    ++degree[e.node2];
  }
  int ends = 0;
  for (const auto& [node_id, d] : degree) {
    if (d > 2) return false;
    ends += (d == 1);
  }
  // A path has exactly two ends and |V| = |E| + 1 over the nodes it touches; a cycle has no ends,
  // a path plus a separate cycle would have |V| = |E|.
  return ends == 2 && degree.size() == edges.size() + 1;
}

std::vector<Eigen::Vector3d> TubeGeometry::Centreline() const {
  if (!IsLinear()) {
    throw InvalidArgument("tube " + std::to_string(id) + " is not linear (branched, cyclic or empty)");
  }
  // Start at an end node: the one of the lowest-order edge that has degree 1.
  std::vector<std::size_t> by_order(edges.size());
  std::iota(by_order.begin(), by_order.end(), 0);
  std::stable_sort(by_order.begin(), by_order.end(),
                   [&](std::size_t a, std::size_t b) { return edges[a].order < edges[b].order; });
  int start = -1;
  for (std::size_t k : by_order) {
    const int d1 = Degree(edges[k].node1);
    const int d2 = Degree(edges[k].node2);
    if (d1 == 1 && d2 == 1) {
      start = std::min(edges[k].node1, edges[k].node2);
    } else if (d1 == 1) {
      start = edges[k].node1;
    } else if (d2 == 1) {
      start = edges[k].node2;
    }
    if (start >= 0) break;
  }
  std::vector<Eigen::Vector3d> line{Node(start).centre};
  std::vector<bool> used(edges.size(), false);
  int current = start;
  for (std::size_t step = 0; step < edges.size(); ++step) {
    for (std::size_t k = 0; k < edges.size(); ++k) {
      if (used[k] || (edges[k].node1 != current && edges[k].node2 != current)) continue;
      used[k] = true;
      current = edges[k].node1 == current ? edges[k].node2 : edges[k].node1;
      line.push_back(Node(current).centre);
      break;
    }
  }
  return line;
}

namespace {

// A tree's edges as a core Tube graph: a node for every end and junction (degree ≠ 2), a branch
// for every chain of edges between two of them.
Tube TreeToTube(const TubeGeometry& g) {
  std::map<int, std::vector<std::size_t>> incident;
  for (std::size_t e = 0; e < g.edges.size(); ++e) {
    incident[g.edges[e].node1].push_back(e);
    incident[g.edges[e].node2].push_back(e);
  }
  if (g.edges.empty() || incident.size() != g.edges.size() + 1) {
    throw InvalidArgument("tube " + std::to_string(g.id) + " is not a tree (" +
                          std::to_string(g.edges.size()) + " edges on " + std::to_string(incident.size()) +
                          " nodes)");
  }
  Tube tube;
  tube.id = static_cast<std::uint32_t>(g.id);
  std::map<int, std::uint32_t> node_index;
  for (const auto& [node_id, edges] : incident) {
    if (edges.size() == 2) continue;
    node_index[node_id] = static_cast<std::uint32_t>(tube.nodes.size());
    tube.nodes.push_back(tubepick::TubeNode{g.Node(node_id).centre});
  }
  std::vector<bool> used(g.edges.size(), false);
  for (const auto& [from, index] : node_index) {
    for (std::size_t first : incident.at(from)) {
      if (used[first]) continue;
      TubeBranch branch;
      branch.from_node = index;
      branch.first_cylinder = static_cast<std::uint32_t>(tube.cylinders.size());
      int at = from;
      for (std::size_t e = first;;) {
        used[e] = true;
        const int next = g.edges[e].node1 == at ? g.edges[e].node2 : g.edges[e].node1;
        Cylinder c;
        c.start = g.Node(at).centre;
        c.end = g.Node(next).centre;
        c.radius = g.edges[e].radius;
        c.segment_id = static_cast<std::uint32_t>(e);
        tube.cylinders.push_back(c);
        at = next;
        const std::vector<std::size_t>& around = incident.at(at);
        if (around.size() != 2) break;
        e = around[0] == e ? around[1] : around[0];
      }
      branch.to_node = node_index.at(at);
      branch.cylinder_count = static_cast<std::uint32_t>(tube.cylinders.size()) - branch.first_cylinder;
      tube.branches.push_back(branch);
    }
  }
  if (std::find(used.begin(), used.end(), false) != used.end())
    throw InvalidArgument("tube " + std::to_string(g.id) + " is not connected");
  return tube;
}

}  // namespace

Tube TubeGeometry::ToTube() const {
  if (!IsLinear()) return TreeToTube(*this);
  const std::vector<Eigen::Vector3d> line = Centreline();
  const double radius = edges.front().radius;
  Tube tube;
  tube.id = static_cast<std::uint32_t>(id);
  for (std::size_t i = 0; i + 1 < line.size(); ++i) {
    Cylinder c;
    c.start = line[i];
    c.end = line[i + 1];
    c.radius = radius;
    c.segment_id = static_cast<std::uint32_t>(i);
    tube.cylinders.push_back(c);
  }
  return tube;
}

TubeGeometry TubeGeometry::Transformed(const Eigen::Isometry3d& X_NewOld) const {
  TubeGeometry out = *this;
  const Eigen::Quaterniond q(X_NewOld.linear());
  for (TubeNode& n : out.nodes) n.centre = X_NewOld * n.centre;
  for (TubeEdge& e : out.edges) {
    e.centre = X_NewOld * e.centre;
    e.orientation = (q * e.orientation).normalized();
  }
  return out;
}

Eigen::Quaterniond RotationFromZ(const Eigen::Vector3d& direction) {
  const Eigen::Vector3d u = direction.normalized();
  if (u.z() < -1.0 + 1e-12) return Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), u);
}

void SetEdgeFromNodes(const TubeGeometry& tube, TubeEdge& edge) {
  const Eigen::Vector3d a = tube.Node(edge.node1).centre;
  const Eigen::Vector3d b = tube.Node(edge.node2).centre;
  edge.centre = 0.5 * (a + b);
  edge.length = (b - a).norm();
  if (edge.length <= 0.0) {
    throw InvalidArgument("tube " + std::to_string(tube.id) + ", edge " + edge.name +
                          ": nodes coincide (zero-length cylinder)");
  }
  edge.orientation = RotationFromZ(b - a);
}

}  // namespace tubepick::physics
