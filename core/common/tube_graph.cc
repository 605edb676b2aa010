#include "core/common/tube_graph.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/common/errors.h"

namespace tubepick {

std::vector<TubeBranch> BranchesOf(const Tube& tube) {
  if (!tube.branches.empty() || tube.cylinders.empty()) return tube.branches;
  return {TubeBranch{0, 1, 0, static_cast<std::uint32_t>(tube.cylinders.size())}};
}

std::vector<TubeNode> NodesOf(const Tube& tube) {
  if (!tube.branches.empty() || tube.cylinders.empty()) return tube.nodes;
  return {TubeNode{tube.cylinders.front().start}, TubeNode{tube.cylinders.back().end}};
}

Tube WithExplicitGraph(Tube tube) {
  if (tube.branches.empty() && !tube.cylinders.empty()) {
    tube.nodes = NodesOf(tube);
    tube.branches = BranchesOf(tube);
  }
  return tube;
}

Tube WithoutPassThroughNodes(Tube tube) {
  if (tube.branches.empty()) return tube;
  // Branches as explicit cylinder lists, oriented from_node -> to_node.
  struct Run {
    std::uint32_t from, to;
    std::vector<Cylinder> cylinders;
  };
  std::vector<Run> runs;
  for (const TubeBranch& b : tube.branches) {
    runs.push_back({b.from_node, b.to_node,
                    std::vector<Cylinder>(tube.cylinders.begin() + b.first_cylinder,
                                          tube.cylinders.begin() + b.first_cylinder + b.cylinder_count)});
  }
  auto reverse = [](Run& r) {
    std::swap(r.from, r.to);
    std::reverse(r.cylinders.begin(), r.cylinders.end());
    for (Cylinder& c : r.cylinders) std::swap(c.start, c.end);
  };
  for (bool merged = true; merged;) {
    merged = false;
    std::vector<std::uint32_t> degree(tube.nodes.size(), 0);
    for (const Run& r : runs) {
      ++degree[r.from];
      ++degree[r.to];
    }
    for (std::uint32_t n = 0; n < degree.size() && !merged; ++n) {
      if (degree[n] != 2) continue;
      std::vector<std::size_t> at;
      for (std::size_t k = 0; k < runs.size(); ++k) {
        if (runs[k].from == n || runs[k].to == n) at.push_back(k);
      }
      if (at.size() != 2) continue;  // a loop on one branch: not a tree, leave it
      Run& a = runs[at[0]];
      Run b = runs[at[1]];
      if (a.to != n) reverse(a);
      if (b.from != n) reverse(b);
      a.to = b.to;
      a.cylinders.insert(a.cylinders.end(), b.cylinders.begin(), b.cylinders.end());
      runs.erase(runs.begin() + static_cast<std::ptrdiff_t>(at[1]));
      merged = true;
    }
  }
  // Renumber the nodes still used, in their old order.
  std::vector<std::int64_t> new_id(tube.nodes.size(), -1);
  for (const Run& r : runs) new_id[r.from] = new_id[r.to] = 0;
  std::vector<TubeNode> nodes;
  for (std::size_t n = 0; n < tube.nodes.size(); ++n) {
    if (new_id[n] < 0) continue;
    new_id[n] = static_cast<std::int64_t>(nodes.size());
    nodes.push_back(tube.nodes[n]);
  }
  tube.nodes = std::move(nodes);
  tube.cylinders.clear();
  tube.branches.clear();
  for (const Run& r : runs) {
    tube.branches.push_back(TubeBranch{
        static_cast<std::uint32_t>(new_id[r.from]), static_cast<std::uint32_t>(new_id[r.to]),
        static_cast<std::uint32_t>(tube.cylinders.size()), static_cast<std::uint32_t>(r.cylinders.size())});
    tube.cylinders.insert(tube.cylinders.end(), r.cylinders.begin(), r.cylinders.end());
  }
  return tube;
}

std::vector<std::uint32_t> NodeDegrees(const Tube& tube) {
  std::vector<std::uint32_t> degree(NodesOf(tube).size(), 0);
  for (const TubeBranch& b : BranchesOf(tube)) {
    ++degree.at(b.from_node);
    ++degree.at(b.to_node);
  }
  return degree;
}

std::vector<TubeJoint> TubeJoints(const Tube& tube) {
  const std::vector<TubeNode> nodes = NodesOf(tube);
  const std::vector<TubeBranch> branches = BranchesOf(tube);
  std::vector<TubeJoint> joints;
  constexpr double kCoincident = 1e-9;  // metres: a node at the cylinder's endpoint needs no link
  for (std::uint32_t k = 0; k < branches.size(); ++k) {
    const TubeBranch& br = branches[k];
    if (br.cylinder_count == 0) continue;
    const auto first = static_cast<std::int32_t>(br.first_cylinder);
    const auto last = static_cast<std::int32_t>(br.first_cylinder + br.cylinder_count - 1);
    const Cylinder& c_first = tube.cylinders.at(static_cast<std::size_t>(first));
    const Cylinder& c_last = tube.cylinders.at(static_cast<std::size_t>(last));
    const Eigen::Vector3d& p_from = nodes.at(br.from_node).p_Bin;
    if ((c_first.start - p_from).norm() > kCoincident) {
      joints.push_back({p_from, c_first.start, -1, first, c_first.radius, k});
    }
    for (std::int32_t i = first; i < last; ++i) {
      const Cylinder& c0 = tube.cylinders[static_cast<std::size_t>(i)];
      const Cylinder& c1 = tube.cylinders[static_cast<std::size_t>(i) + 1];
      joints.push_back({c0.end, c1.start, i, i + 1, 0.5 * (c0.radius + c1.radius), k});
    }
    const Eigen::Vector3d& p_to = nodes.at(br.to_node).p_Bin;
    if ((c_last.end - p_to).norm() > kCoincident) {
      joints.push_back({c_last.end, p_to, last, -1, c_last.radius, k});
    }
  }
  return joints;
}

std::vector<AxisPiece> TubeAxisPieces(const Tube& tube) {
  const std::vector<TubeJoint> joints = TubeJoints(tube);
  std::vector<AxisPiece> pieces;
  std::size_t j = 0;  // joints are in branch order, as the pieces
  auto joint_if = [&](std::uint32_t branch, std::int32_t cylinder_a) {
    if (j < joints.size() && joints[j].branch == branch && joints[j].cylinder_a == cylinder_a) {
      pieces.push_back({joints[j].a, joints[j].b, joints[j].radius, -1});
      ++j;
    }
  };
  const std::vector<TubeBranch> branches = BranchesOf(tube);
  for (std::uint32_t k = 0; k < branches.size(); ++k) {
    const TubeBranch& br = branches[k];
    joint_if(k, -1);
    for (std::uint32_t i = br.first_cylinder; i < br.first_cylinder + br.cylinder_count; ++i) {
      const Cylinder& c = tube.cylinders[i];
      pieces.push_back({c.start, c.end, c.radius, static_cast<std::int32_t>(i)});
      joint_if(k, static_cast<std::int32_t>(i));
    }
  }
  return pieces;
}

bool Tube::branched() const {
  if (branches.size() < 3) return false;
  const std::vector<std::uint32_t> degree = NodeDegrees(*this);
  return std::any_of(degree.begin(), degree.end(), [](std::uint32_t d) { return d >= 3; });
}

double Tube::length() const {
  double sum = 0.0;
  for (const Cylinder& c : cylinders) sum += c.length();
  for (const TubeJoint& j : TubeJoints(*this)) sum += j.length();
  return sum;
}

Eigen::Vector3d TubeMassCentre(const Tube& tube) {
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  double total = 0.0;
  for (const Cylinder& c : tube.cylinders) {
    weighted += c.length() * c.centre();
    total += c.length();
  }
  for (const TubeJoint& j : TubeJoints(tube)) {
    weighted += j.length() * 0.5 * (j.a + j.b);
    total += j.length();
  }
  return weighted / total;
}

std::vector<double> BranchLengths(const Tube& tube) {
  const std::vector<TubeBranch> branches = BranchesOf(tube);
  std::vector<double> out(branches.size(), 0.0);
  for (std::size_t b = 0; b < branches.size(); ++b) {
    for (std::uint32_t k = 0; k < branches[b].cylinder_count; ++k)
      out[b] += tube.cylinders[branches[b].first_cylinder + k].length();
  }
  for (const TubeJoint& joint : TubeJoints(tube)) out[joint.branch] += joint.length();
  return out;
}

void ValidateTubeGraph(const Tube& tube, const std::string& name) {
  for (std::size_t c = 0; c < tube.cylinders.size(); ++c) {
    const Cylinder& cyl = tube.cylinders[c];
    if (!cyl.start.allFinite() || !cyl.end.allFinite() || !std::isfinite(cyl.radius)) {
      throw InvalidArgument(name + ".cylinders[" + std::to_string(c) + "]: non-finite endpoint or radius");
    }
  }
  if (tube.branches.empty()) {
    if (!tube.nodes.empty()) {
      throw InvalidArgument(name + ": has " + std::to_string(tube.nodes.size()) +
                            " nodes but no branches (a linear tube may leave both empty)");
    }
    return;
  }
  std::vector<bool> used(tube.nodes.size(), false);
  std::uint32_t next = 0;
  for (std::size_t k = 0; k < tube.branches.size(); ++k) {
    const TubeBranch& b = tube.branches[k];
    const std::string where = name + ".branches[" + std::to_string(k) + "]";
    for (const std::uint32_t node : {b.from_node, b.to_node}) {
      if (node >= tube.nodes.size()) {
        throw InvalidArgument(where + ": node " + std::to_string(node) + " does not exist (the tube has " +
                              std::to_string(tube.nodes.size()) + " nodes)");
      }
      used[node] = true;
    }
    if (b.cylinder_count == 0) throw InvalidArgument(where + ": has no cylinders (cylinder_count = 0)");
    if (b.first_cylinder != next) {
      throw InvalidArgument(where + ": first_cylinder = " + std::to_string(b.first_cylinder) + ", expected " +
                            std::to_string(next) + " (branches list the cylinders in order, without gaps)");
    }
    next += b.cylinder_count;
  }
  if (next != tube.cylinders.size()) {
    throw InvalidArgument(name + ": the branches cover " + std::to_string(next) +
                          " cylinders but the tube has " + std::to_string(tube.cylinders.size()));
  }
  for (std::size_t n = 0; n < tube.nodes.size(); ++n) {
    if (!tube.nodes[n].p_Bin.allFinite()) {
      throw InvalidArgument(name + ".nodes[" + std::to_string(n) + "]: non-finite position");
    }
    if (!used[n]) throw InvalidArgument(name + ".nodes[" + std::to_string(n) + "]: no branch uses it");
  }
  // One tree: every node reached from node 0, and one branch fewer than nodes (no cycle).
  std::vector<bool> reached(tube.nodes.size(), false);
  reached[0] = true;
  for (bool grew = true; grew;) {
    grew = false;
    for (const TubeBranch& b : tube.branches) {
      if (reached[b.from_node] != reached[b.to_node]) {
        reached[b.from_node] = reached[b.to_node] = true;
        grew = true;
      }
    }
  }
  const auto apart = std::find(reached.begin(), reached.end(), false);
  if (apart != reached.end()) {
    throw InvalidArgument(name + ": nodes 0 and " + std::to_string(apart - reached.begin()) +
                          " are not joined by any path of branches (a tube is one tree)");
  }
  if (tube.branches.size() + 1 != tube.nodes.size()) {
    throw InvalidArgument(name + ": has " + std::to_string(tube.branches.size()) + " branches for " +
                          std::to_string(tube.nodes.size()) +
                          " nodes, so a cycle (a tree of N nodes has N - 1 branches)");
  }
}

}  // namespace tubepick
