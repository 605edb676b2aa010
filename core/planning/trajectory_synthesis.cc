#include "core/planning/trajectory_synthesis.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "core/common/tube_graph.h"

namespace tubepick {
namespace {

constexpr double kMinEscapeLineXy = 1e-6;  // metres; shorter joint projections are degenerate
constexpr double kDirectionEps = 1e-12;

Eigen::Vector3d Xy(const Eigen::Vector3d& v) { return Eigen::Vector3d(v.x(), v.y(), 0.0); }

// Largest |u·(ep − occl)| over the endpoints of the cylinders in `section`.
double FarthestProjection(const Tube& tube, const CylinderRange& section, const Eigen::Vector3d& occl,
                          const Eigen::Vector3d& u) {
  double farthest = 0.0;
  for (std::uint32_t i = section.begin; i < section.end; ++i) {
    const Cylinder& c = tube.cylinders[i];
    farthest = std::max(farthest, std::abs(u.dot(c.start - occl)));
    farthest = std::max(farthest, std::abs(u.dot(c.end - occl)));
  }
  return farthest;
}

Trajectory MakeTrajectory(std::uint32_t tube_index, TrajectoryKind kind, const CylinderRange& section) {
  Trajectory t;
  t.tube_index = tube_index;
  t.kind = kind;
  t.section_begin = section.begin;
  t.section_end = section.end;
  return t;
}

}  // namespace

SafetyZone MakeSafetyZone(const BinConfig& bin, double margin) {
  SafetyZone zone;
  for (int k = 0; k < 2; ++k) {
    const double half = std::max(0.0, 0.5 * bin.inner_size[k] - margin);
    zone.min[k] = -half;
    zone.max[k] = half;
  }
  return zone;
}

SafetyZone TubeBoundingBoxXy(const Tube& tube) {
  SafetyZone box;
  box.min.setConstant(std::numeric_limits<double>::infinity());
  box.max.setConstant(-std::numeric_limits<double>::infinity());
  for (const Cylinder& c : tube.cylinders) {
    for (const Eigen::Vector3d* p : {&c.start, &c.end}) {
      for (int k = 0; k < 2; ++k) {
        box.min[k] = std::min(box.min[k], (*p)[k] - c.radius);
        box.max[k] = std::max(box.max[k], (*p)[k] + c.radius);
      }
    }
  }
  return box;
}

double SafetyZoneLimit(const Tube& tube, const Eigen::Vector3d& direction, const SafetyZone& zone) {
  const SafetyZone box = TubeBoundingBoxXy(tube);
  double limit = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 2; ++k) {
    if (direction[k] > kDirectionEps) {
      limit = std::min(limit, (zone.max[k] - box.max[k]) / direction[k]);
    } else if (direction[k] < -kDirectionEps) {
      limit = std::min(limit, (zone.min[k] - box.min[k]) / direction[k]);
    }
  }
  return limit;
}

std::optional<Eigen::Vector3d> EscapeLineDirection(const Tube& tube, std::uint32_t joint) {
  assert(joint + 1 < tube.cylinders.size());
  const Cylinder& a = tube.cylinders[joint];
  const Cylinder& b = tube.cylinders[joint + 1];
  Eigen::Vector3d d = Xy(b.start - a.end);
  if (d.norm() >= kMinEscapeLineXy) return d.normalized();
  // The joint is (nearly) vertical: follow the tube's own direction at the joint.
  d = Xy((a.end - a.start).normalized() + (b.end - b.start).normalized());
  if (d.allFinite() && d.norm() >= kMinEscapeLineXy) return d.normalized();
  return std::nullopt;
}

std::optional<std::array<EscapeCandidate, 2>> EscapeCandidates(const Tube& tube, std::uint32_t joint,
                                                               double constant_distance,
                                                               const SafetyZone& zone) {
  const std::optional<Eigen::Vector3d> u = EscapeLineDirection(tube, joint);
  if (!u) return std::nullopt;
  const auto [first, second] = SplitAtJoint(tube, joint);
  std::array<EscapeCandidate, 2> out;
  for (int i = 0; i < 2; ++i) {
    EscapeCandidate& e = out[i];
    e.joint = joint;
    e.towards_end = i == 0;
    e.direction = e.towards_end ? *u : Eigen::Vector3d(-*u);
    e.trailing = e.towards_end ? first : second;
    e.leading = e.towards_end ? second : first;
    // occl: the joint endpoint on the trailing section.
    const Eigen::Vector3d& occl = e.towards_end ? tube.cylinders[joint].end : tube.cylinders[joint + 1].start;
    e.variable_distance = FarthestProjection(tube, e.trailing, occl, *u);
    e.constant_distance = constant_distance;
    e.escape_distance = e.variable_distance + e.constant_distance;
    e.zone_limit = SafetyZoneLimit(tube, e.direction, zone);
    e.distance = std::max(0.0, std::min(e.escape_distance, e.zone_limit));
  }
  return out;
}

namespace {

std::vector<std::uint8_t> SideOfJointA(const Tube& tube, const std::vector<TubeJoint>& joints,
                                       std::uint32_t joint) {
  const std::vector<TubeBranch> branches = BranchesOf(tube);
  assert(joint < joints.size());
  // Vertices: cylinders 0..n−1, then nodes n..n+m−1; joined by every joint but `joint`, and by
  // the branch ends that start or end on their node without a link.
  const std::size_t n = tube.cylinders.size();
  std::vector<std::size_t> parent(n + NodesOf(tube).size());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = i;
  const auto find = [&parent](std::size_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  const auto vertex = [&](std::int32_t cylinder, const TubeJoint& j, bool at_a) -> std::size_t {
    if (cylinder >= 0) return static_cast<std::size_t>(cylinder);
    const TubeBranch& b = branches[j.branch];
    return n + (at_a ? b.from_node : b.to_node);
  };
  std::vector<bool> linked_start(branches.size(), false), linked_end(branches.size(), false);
  for (std::size_t k = 0; k < joints.size(); ++k) {
    const TubeJoint& j = joints[k];
    if (j.cylinder_a < 0) linked_start[j.branch] = true;
    if (j.cylinder_b < 0) linked_end[j.branch] = true;
    if (k != joint) parent[find(vertex(j.cylinder_a, j, true))] = find(vertex(j.cylinder_b, j, false));
  }
  for (std::size_t b = 0; b < branches.size(); ++b) {
    const TubeBranch& br = branches[b];
    if (br.cylinder_count == 0) continue;
    if (!linked_start[b]) parent[find(br.first_cylinder)] = find(n + br.from_node);
    if (!linked_end[b]) parent[find(br.first_cylinder + br.cylinder_count - 1)] = find(n + br.to_node);
  }
  const std::size_t side_a = find(vertex(joints[joint].cylinder_a, joints[joint], true));
  std::vector<std::uint8_t> mask(n, 0);
  for (std::size_t i = 0; i < n; ++i) mask[i] = find(i) == side_a ? 1 : 0;
  return mask;
}

}  // namespace

std::vector<std::uint8_t> SideOfJointA(const Tube& tube, std::uint32_t joint) {
  return SideOfJointA(tube, TubeJoints(tube), joint);
}

std::optional<std::array<TreeEscapeCandidate, 2>> TreeEscapeCandidates(const Tube& tube, std::uint32_t joint,
                                                                       double constant_distance,
                                                                       const SafetyZone& zone) {
  const std::vector<TubeJoint> joints = TubeJoints(tube);
  const TubeJoint& j = joints.at(joint);
  const Eigen::Vector3d line = Xy(j.b - j.a);
  if (line.norm() < kMinEscapeLineXy) return std::nullopt;
  const Eigen::Vector3d u = line.normalized();
  const std::vector<std::uint8_t> side_a = SideOfJointA(tube, joints, joint);
  std::array<TreeEscapeCandidate, 2> out;
  for (int i = 0; i < 2; ++i) {
    const bool towards_b = i == 0;  // the a side trails
    EscapeCandidate& e = out[i].escape;
    e.joint = joint;
    e.towards_end = towards_b;
    e.direction = towards_b ? u : Eigen::Vector3d(-u);
    const Eigen::Vector3d& occl = towards_b ? j.a : j.b;
    double farthest = 0.0;
    out[i].leading_mask.assign(tube.cylinders.size(), 0);
    for (std::size_t c = 0; c < tube.cylinders.size(); ++c) {
      const bool trailing = (side_a[c] != 0) == towards_b;
      out[i].leading_mask[c] = trailing ? 0 : 1;
      if (!trailing) continue;
      farthest = std::max({farthest, std::abs(u.dot(tube.cylinders[c].start - occl)),
                           std::abs(u.dot(tube.cylinders[c].end - occl))});
    }
    e.variable_distance = farthest;
    e.constant_distance = constant_distance;
    e.escape_distance = e.variable_distance + e.constant_distance;
    e.zone_limit = SafetyZoneLimit(tube, e.direction, zone);
    e.distance = std::max(0.0, std::min(e.escape_distance, e.zone_limit));
  }
  return out;
}

Trajectory UpwardTrajectory(std::uint32_t tube_index, const Tube& tube, const TrajectoryParams& params) {
  Trajectory t = MakeTrajectory(tube_index, TrajectoryKind::kUpward,
                                CylinderRange{0, static_cast<std::uint32_t>(tube.cylinders.size())});
  t.waypoints = {Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 0.0, params.upward_distance)};
  return t;
}

Trajectory EscapeTrajectory(std::uint32_t tube_index, const EscapeCandidate& candidate, TrajectoryKind kind,
                            const CylinderRange& grasp_section, const TrajectoryParams& params) {
  Trajectory t = MakeTrajectory(tube_index, kind, grasp_section);
  t.escape_direction = candidate.direction;
  const Eigen::Vector3d lateral = candidate.distance * candidate.direction;
  const double h1 = params.escape_first_lift;
  const double h2 = params.escape_second_lift;
  t.waypoints = {Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 0.0, h1),
                 lateral + Eigen::Vector3d(0.0, 0.0, h1), lateral + Eigen::Vector3d(0.0, 0.0, h1 + h2)};
  return t;
}

std::vector<Trajectory> SynthesizeTrajectories(std::uint32_t tube_index, const Tube& tube,
                                               const TubeClass& cls, double tube_radius,
                                               const SafetyZone& zone, const TrajectoryParams& params) {
  std::vector<Trajectory> out;
  out.push_back(UpwardTrajectory(tube_index, tube, params));
  const double d_const = params.escape_constant > 0.0 ? params.escape_constant : 3.0 * tube_radius;
  const auto n = static_cast<std::uint32_t>(tube.cylinders.size());
  if (BranchesOf(tube).size() > 1) {
    // A tree: its sections are subtrees (cylinder masks). Weakly occluded: both escapes of the
    // joint; strongly occluded trees are lifted straight up (and simulated).
    if (cls.occlusion != Occlusion::kWeak) return out;
    const auto candidates = TreeEscapeCandidates(tube, cls.occluded_joints.front(), d_const, zone);
    if (!candidates) return out;
    for (const TreeEscapeCandidate& c : *candidates) {
      if (c.escape.distance < params.min_escape_distance) continue;
      Trajectory t =
          EscapeTrajectory(tube_index, c.escape, TrajectoryKind::kEscape, CylinderRange{0, n}, params);
      t.section_mask = c.leading_mask;
      out.push_back(std::move(t));
    }
    return out;
  }

  if (cls.occlusion == Occlusion::kWeak) {
    assert(cls.occluded_joints.size() == 1);
    const auto candidates = EscapeCandidates(tube, cls.occluded_joints.front(), d_const, zone);
    if (!candidates) return out;
    for (const EscapeCandidate& e : *candidates) {
      if (e.distance < params.min_escape_distance) continue;
      out.push_back(EscapeTrajectory(tube_index, e, TrajectoryKind::kEscape, e.leading, params));
    }
  } else if (cls.occlusion == Occlusion::kStrong && params.occlusion_escapes) {
    assert(!cls.occluded_joints.empty());
    const CylinderRange end_section{cls.occluded_joints.back() + 1, n};
    const CylinderRange start_section{0, cls.occluded_joints.front() + 1};
    for (std::uint32_t joint : cls.occluded_joints) {
      const auto candidates = EscapeCandidates(tube, joint, d_const, zone);
      if (!candidates) continue;
      const EscapeCandidate& e = (*candidates)[1].variable_distance < (*candidates)[0].variable_distance
                                     ? (*candidates)[1]
                                     : (*candidates)[0];
      if (e.distance < params.min_escape_distance) continue;
      out.push_back(EscapeTrajectory(tube_index, e, TrajectoryKind::kOcclusionEscape,
                                     e.towards_end ? end_section : start_section, params));
    }
  }
  return out;
}

}  // namespace tubepick
