#include "devices/sim/sim_tubes.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include "core/common/errors.h"

namespace tubepick::devices::sim {
namespace {

using physics::FromBt;
using physics::ToBt;

/// A body's collision shape (owned by the world), its principal inertia for its mass, and where
/// its frame C (centre of mass, principal axes) is.
struct BodyShape {
  btCollisionShape* shape = nullptr;
  btVector3 inertia{0, 0, 0};
  Eigen::Isometry3d X_BinC = Eigen::Isometry3d::Identity();
  double radius = 0.0;
  /// The farthest point of its surface from its centre of mass, metres.
  double reach = 0.0;
};

/// The compound of physics::MakeTubeShape (capsules, flat free ends).
BodyShape CompoundShape(physics::BulletWorld& world, const std::vector<physics::TubeSegment>& segments,
                        double mass, double margin) {
  world.tube_shapes.push_back(physics::MakeTubeShape(segments, mass, margin));
  const physics::TubeShape& s = world.tube_shapes.back();
  return {s.compound.get(), s.inertia, s.X_TubeC, s.radius, s.reach};
}

btRigidBody* AddBody(physics::BulletWorld& world, const BodyShape& s, double mass,
                     const TubeBodyOptions& options, std::size_t tube_index, int link_index) {
  btRigidBody::btRigidBodyConstructionInfo info(mass, nullptr, s.shape, s.inertia);
  info.m_startWorldTransform = ToBt(s.X_BinC);
  info.m_friction = options.body_friction;
  info.m_rollingFriction = options.material.rolling_friction;
  info.m_restitution = options.body_restitution;
  info.m_linearDamping = options.linear_damping;
  info.m_angularDamping = options.angular_damping;
  info.m_linearSleepingThreshold = options.sleep_linear_velocity;
  info.m_angularSleepingThreshold =
      options.rubber && s.reach > 0.0
          ? std::max(options.sleep_angular_velocity, options.sleep_linear_velocity / s.reach)
          : options.sleep_angular_velocity;
  btRigidBody* body = world.AddBody(info);
  // Continuous collision: a swept sphere inside the tube whenever a step moves it more than R.
  body->setCcdMotionThreshold(s.radius);
  body->setCcdSweptSphereRadius(0.8 * s.radius);
  body->setUserIndex(static_cast<int>(tube_index));
  body->setUserIndex2(link_index);
  return body;
}

std::vector<Eigen::Vector3d> ToBodyFrame(const BodyShape& shape,
                                         const std::vector<Eigen::Vector3d>& points_Bin) {
  const Eigen::Isometry3d X_CBin = shape.X_BinC.inverse();
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector3d& p : points_Bin) out.push_back(X_CBin * p);
  return out;
}

/// Moment of inertia of `body` about the world axis `axis_Bin` through its centre of mass.
double InertiaAbout(const btRigidBody& body, const Eigen::Vector3d& axis_Bin) {
  const btVector3 a = ToBt(axis_Bin);
  return 1.0 / a.dot(body.getInvInertiaTensorWorld() * a);
}

/// Rubber: a joint at p_Bin_joint between links a and b; its frame's z runs along link b.
/// Translation and twist are locked; bending about x and y is an implicit angular spring.
///
/// Bullet solves a locked row with error-reduction e and constraint-force mixing c as the implicit
/// spring-damper of ODE: for stiffness k and damping d at step h, e = h·k/(h·k + d) and, since
/// Bullet's mixing is relative to the row's effective inertia J (its jacDiagABInv),
/// c = J/(h·(h·k + d)). At rest the row holds a bend θ with the torque k·θ exactly. Unlike an
/// explicit spring (btGeneric6DofSpring2Constraint's enableSpring), it is stable at any stiffness
/// and settles with friction (explicit springs on links this light made bent hoses creep).
std::unique_ptr<btGeneric6DofSpring2Constraint> MakeJoint(btRigidBody& a, btRigidBody& b,
                                                          const Eigen::Vector3d& p_Bin_joint,
                                                          const Eigen::Vector3d& direction_Bin, double link_a,
                                                          double link_b, double mass_a, double mass_b,
                                                          const SimMaterialParams& m, double h) {
  Eigen::Isometry3d X_BinJ = Eigen::Isometry3d::Identity();
  X_BinJ.linear() = physics::RotationFromZ(direction_Bin).toRotationMatrix();
  X_BinJ.translation() = p_Bin_joint;
  const btTransform frame_a = a.getCenterOfMassTransform().inverse() * ToBt(X_BinJ);
  const btTransform frame_b = b.getCenterOfMassTransform().inverse() * ToBt(X_BinJ);
  auto joint = std::make_unique<btGeneric6DofSpring2Constraint>(a, b, frame_a, frame_b, RO_XYZ);
  joint->setLinearLowerLimit(btVector3(0, 0, 0));
  joint->setLinearUpperLimit(btVector3(0, 0, 0));
  joint->setAngularLowerLimit(btVector3(0, 0, 0));
  joint->setAngularUpperLimit(btVector3(0, 0, 0));
  // A discretised beam: a joint stands for the mean length of its two links.
  const double stiffness = m.bending_stiffness / (0.5 * (link_a + link_b));
  for (int axis = 3; axis <= 4; ++axis) {
    const Eigen::Vector3d axis_Bin = X_BinJ.linear().col(axis - 3);
    // The row's effective inertia as Bullet computes it (both links turning about their centres,
    // with Bullet's own capsule inertia), and the damping that makes the lighter link, turning
    // about the joint, damped by damping_ratio.
    const double inertia_a = InertiaAbout(a, axis_Bin), inertia_b = InertiaAbout(b, axis_Bin);
    const double row_inertia = 1.0 / (1.0 / inertia_a + 1.0 / inertia_b);
    const double about_joint =
        std::min(inertia_a + mass_a * 0.25 * link_a * link_a, inertia_b + mass_b * 0.25 * link_b * link_b);
    const double damping = 2.0 * m.damping_ratio * std::sqrt(stiffness * about_joint);
    joint->setParam(BT_CONSTRAINT_STOP_ERP, h * stiffness / (h * stiffness + damping), axis);
    joint->setParam(BT_CONSTRAINT_STOP_CFM, row_inertia / (h * (h * stiffness + damping)), axis);
  }
  return joint;
}

/// A branched pvc tube: one rigid compound of its whole tree; its geometry kept in the body frame.
SimTube AddRigidTree(physics::BulletWorld& world, const physics::TubeGeometry& tube_Bin,
                     std::size_t tube_index, const TubeBodyOptions& options, SimTube tube) {
  const BodyShape shape = CompoundShape(world, physics::MakeTubeSegments(tube_Bin.ToTube(), 0.001),
                                        options.mass, options.collision_margin);
  SimLink link;
  link.mass = options.mass;
  link.body = AddBody(world, shape, options.mass, options, tube_index, 0);
  tube.links.push_back(std::move(link));
  tube.tree_C = tube_Bin.Transformed(shape.X_BinC.inverse());
  return tube;
}

/// Rubber: one link per pair of consecutive `points`, each of mass options.mass × its length /
/// `chord_total`, joined in order by spring joints (MakeJoint); a free end is flat, the others
/// round. Appends the links to `tube`; returns the index of the first.
std::size_t AddLinkChain(physics::BulletWorld& world, const std::vector<Eigen::Vector3d>& points,
                         bool free_front, bool free_back, double chord_total, std::size_t tube_index,
                         const TubeBodyOptions& options, SimTube& tube) {
  const std::size_t first = tube.links.size();
  const std::size_t links = points.size() - 1;
  for (std::size_t j = 0; j < links; ++j) {
    physics::TubeSegment seg;
    seg.a = points[j];
    seg.b = points[j + 1];
    seg.radius = tube.radius;
    seg.sphere_a = j > 0 || !free_front;
    seg.sphere_b = j + 1 < links || !free_back;
    const double mass = options.mass * (seg.b - seg.a).norm() / chord_total;
    // A one-child compound even for the inner links: bare capsules collide analytically but with a
    // single contact point per pair, which let piles of hoses rock instead of coming to rest (a
    // pick cycle cost 40 % more).
    const BodyShape shape = CompoundShape(world, {seg}, mass, options.collision_margin);
    SimLink link;
    link.p_C_points = ToBodyFrame(shape, {seg.a, seg.b});
    link.mass = mass;
    link.body = AddBody(world, shape, mass, options, tube_index, static_cast<int>(tube.links.size()));
    tube.links.push_back(std::move(link));
  }
  for (std::size_t j = 1; j < links; ++j) {
    const SimLink& a = tube.links[first + j - 1];
    const SimLink& b = tube.links[first + j];
    tube.joints.push_back(MakeJoint(*a.body, *b.body, points[j], points[j + 1] - points[j],
                                    (points[j] - points[j - 1]).norm(), (points[j + 1] - points[j]).norm(),
                                    a.mass, b.mass, options.material, options.time_step));
    world.world->addConstraint(tube.joints.back().get(), /*disableCollisionsBetweenLinkedBodies=*/true);
  }
  return first;
}

/// The summed lengths of consecutive points' segments.
double ChordLength(const std::vector<Eigen::Vector3d>& points) {
  double length = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) length += (points[i] - points[i - 1]).norm();
  return length;
}

/// A branch of a tree: the chain of edges from one end or junction node to the next, as node ids.
struct TreeBranch {
  std::vector<int> nodes;
};

/// The tree's branches, each walked from a node of degree other than 2 to the next.
std::vector<TreeBranch> TreeBranches(const physics::TubeGeometry& tree) {
  std::map<int, std::vector<std::pair<int, std::size_t>>> next;  // node -> (neighbour, edge)
  for (std::size_t e = 0; e < tree.edges.size(); ++e) {
    next[tree.edges[e].node1].emplace_back(tree.edges[e].node2, e);
    next[tree.edges[e].node2].emplace_back(tree.edges[e].node1, e);
  }
  std::vector<char> walked(tree.edges.size(), 0);
  std::vector<TreeBranch> out;
  for (const auto& [start, around] : next) {
    if (around.size() == 2) continue;
    for (const auto& [first, first_edge] : around) {
      if (walked[first_edge] != 0) continue;
      TreeBranch branch{{start}};
      int at = first;
      std::size_t edge = first_edge;
      while (true) {
        walked[edge] = 1;
        branch.nodes.push_back(at);
        const auto& here = next.at(at);
        if (here.size() != 2) break;
        const auto& onward = here[0].second == edge ? here[1] : here[0];
        at = onward.first;
        edge = onward.second;
      }
      out.push_back(std::move(branch));
    }
  }
  return out;
}

/// Ignores collisions between links that share a node or a neighbour: at a joint or a junction
/// their capsules overlap by construction.
void IgnoreNearLinks(SimTube& tube) {
  std::map<int, std::vector<std::size_t>> at_node;
  for (std::size_t l = 0; l < tube.link_nodes.size(); ++l) {
    at_node[tube.link_nodes[l].first].push_back(l);
    at_node[tube.link_nodes[l].second].push_back(l);
  }
  const auto neighbours = [&](std::size_t l) {
    std::set<std::size_t> out;
    for (const int node : {tube.link_nodes[l].first, tube.link_nodes[l].second}) {
      for (const std::size_t k : at_node[node]) out.insert(k);
    }
    return out;
  };
  for (std::size_t l = 0; l < tube.links.size(); ++l) {
    std::set<std::size_t> near;
    for (const std::size_t k : neighbours(l)) {
      for (const std::size_t j : neighbours(k)) near.insert(j);
    }
    for (const std::size_t j : near) {
      if (j != l) tube.links[l].body->setIgnoreCollisionCheck(tube.links[j].body, true);
    }
  }
}

/// A branched rubber tube: a chain of links per branch, the branches held together at each
/// junction by joints to one of the links that meet there.
SimTube AddRubberTree(physics::BulletWorld& world, const physics::TubeGeometry& tube_Bin,
                      std::size_t tube_index, const TubeBodyOptions& options, SimTube tube) {
  const std::vector<TreeBranch> branches = TreeBranches(tube_Bin);
  // Each branch's link ends along its centreline; link masses share the tube's mass by length.
  std::vector<std::vector<Eigen::Vector3d>> branch_points;
  double chord_total = 0.0;
  for (const TreeBranch& branch : branches) {
    std::vector<Eigen::Vector3d> line;
    for (const int id : branch.nodes) line.push_back(tube_Bin.Node(id).centre);
    const int links =
        std::max(1, static_cast<int>(std::lround(ChordLength(line) / options.material.link_length)));
    branch_points.push_back(ResamplePolyline(line, links + 1));
    chord_total += ChordLength(branch_points.back());
  }
  int next_id = 0;
  for (const physics::TubeNode& n : tube_Bin.nodes) next_id = std::max(next_id, n.id + 1);
  struct Piece {
    std::size_t link;
    Eigen::Vector3d p_node, away;  // the link's end at the node, and its direction from there
    double length;
  };
  std::map<int, std::vector<Piece>> at_junction;
  for (std::size_t b = 0; b < branches.size(); ++b) {
    const std::vector<int>& nodes = branches[b].nodes;
    const std::vector<Eigen::Vector3d>& points = branch_points[b];
    const std::size_t links = points.size() - 1;
    const bool free_front = tube_Bin.Degree(nodes.front()) == 1;
    const bool free_back = tube_Bin.Degree(nodes.back()) == 1;
    const std::size_t first =
        AddLinkChain(world, points, free_front, free_back, chord_total, tube_index, options, tube);
    for (std::size_t j = 0; j < links; ++j) {
      const int a = j == 0 ? nodes.front() : next_id - 1;
      const int z = j + 1 == links ? nodes.back() : next_id++;
      tube.link_nodes.emplace_back(a, z);
    }
    if (!free_front) {
      at_junction[nodes.front()].push_back(
          {first, points[0], points[1] - points[0], (points[1] - points[0]).norm()});
    }
    if (!free_back) {
      at_junction[nodes.back()].push_back({first + links - 1, points[links],
                                           points[links - 1] - points[links],
                                           (points[links] - points[links - 1]).norm()});
    }
  }
  for (const auto& [node, pieces] : at_junction) {
    const Piece& hub = pieces.front();
    for (std::size_t k = 1; k < pieces.size(); ++k) {
      const Piece& other = pieces[k];
      tube.joints.push_back(MakeJoint(*tube.links[hub.link].body, *tube.links[other.link].body, other.p_node,
                                      other.away, hub.length, other.length, tube.links[hub.link].mass,
                                      tube.links[other.link].mass, options.material, options.time_step));
      world.world->addConstraint(tube.joints.back().get(), /*disableCollisionsBetweenLinkedBodies=*/true);
    }
  }
  IgnoreNearLinks(tube);
  return tube;
}

/// Appends the edge node1 → node2 ("e_<node1>_<node2>") to g, whose nodes hold both.
void AddEdge(int node1, int node2, int order, double radius, physics::TubeGeometry* g) {
  physics::TubeEdge e;
  e.node1 = node1;
  e.node2 = node2;
  e.name = "e_" + std::to_string(node1) + "_" + std::to_string(node2);
  e.order = order;
  e.radius = radius;
  physics::SetEdgeFromNodes(*g, e);
  g->edges.push_back(e);
}

/// The branched rubber tube as it is now (CurrentGeometry).
physics::TubeGeometry CurrentTree(const SimTube& tube) {
  std::map<int, std::pair<Eigen::Vector3d, int>> sum;  // node -> (sum of positions, count)
  for (std::size_t l = 0; l < tube.links.size(); ++l) {
    const Eigen::Isometry3d X_BinC = FromBt(tube.links[l].body->getWorldTransform());
    for (const auto& [node, p_C] : {std::pair{tube.link_nodes[l].first, tube.links[l].p_C_points.front()},
                                    std::pair{tube.link_nodes[l].second, tube.links[l].p_C_points.back()}}) {
      auto& [p, n] = sum.try_emplace(node, Eigen::Vector3d::Zero(), 0).first->second;
      p += X_BinC * p_C;
      ++n;
    }
  }
  physics::TubeGeometry g;
  g.id = tube.id;
  for (const auto& [node, pn] : sum) g.nodes.push_back({node, pn.first / pn.second, tube.radius});
  for (std::size_t l = 0; l < tube.links.size(); ++l) {
    AddEdge(tube.link_nodes[l].first, tube.link_nodes[l].second, static_cast<int>(l + 1), tube.radius, &g);
  }
  return g;
}

}  // namespace

std::vector<Eigen::Vector3d> ResamplePolyline(const std::vector<Eigen::Vector3d>& line, int count) {
  std::vector<double> cumulative{0.0};
  for (std::size_t i = 1; i < line.size(); ++i)
    cumulative.push_back(cumulative.back() + (line[i] - line[i - 1]).norm());
  const double length = cumulative.back();
  std::vector<Eigen::Vector3d> out;
  std::size_t k = 1;
  for (int j = 0; j < count; ++j) {
    if (j == count - 1) {
      out.push_back(line.back());
      break;
    }
    const double s = length * j / (count - 1);
    while (k + 1 < line.size() && cumulative[k] < s) ++k;
    const double span = cumulative[k] - cumulative[k - 1];
    const double t = span > 0.0 ? (s - cumulative[k - 1]) / span : 0.0;
    out.push_back(line[k - 1] + std::clamp(t, 0.0, 1.0) * (line[k] - line[k - 1]));
  }
  return out;
}

SimTube AddSimTube(physics::BulletWorld& world, const physics::TubeGeometry& tube_Bin, std::size_t tube_index,
                   const TubeBodyOptions& options) {
  const double length = tube_Bin.edges.empty() ? 0.0 : tube_Bin.Length();
  if (!(length > 0.0))
    throw InvalidArgument("sim cell: tube " + std::to_string(tube_Bin.id) + " has no length");
  SimTube tube;
  tube.id = tube_Bin.id;
  tube.radius = tube_Bin.edges.front().radius;
  tube.mass = options.mass;
  if (!tube_Bin.IsLinear()) {
    return options.rubber ? AddRubberTree(world, tube_Bin, tube_index, options, std::move(tube))
                          : AddRigidTree(world, tube_Bin, tube_index, options, std::move(tube));
  }
  const std::vector<Eigen::Vector3d> line = tube_Bin.Centreline();

  if (!options.rubber) {
    const BodyShape shape = CompoundShape(world, physics::MakeTubeSegments(tube_Bin.ToTube(), 0.001),
                                          options.mass, options.collision_margin);
    SimLink link;
    link.p_C_points = ToBodyFrame(shape, line);
    link.mass = options.mass;
    link.body = AddBody(world, shape, options.mass, options, tube_index, 0);
    tube.links.push_back(std::move(link));
    return tube;
  }

  const int links = std::max(2, static_cast<int>(std::lround(length / options.material.link_length)));
  const std::vector<Eigen::Vector3d> points = ResamplePolyline(line, links + 1);
  AddLinkChain(world, points, /*free_front=*/true, /*free_back=*/true, ChordLength(points), tube_index,
               options, tube);
  // Links two apart may overlap at a sharp bend of the rest shape; farther ones cannot (Algorithm
  // 2 rejects self-intersecting tubes).
  for (int j = 2; j < links; ++j) {
    tube.links[j - 2].body->setIgnoreCollisionCheck(tube.links[j].body, true);
    tube.links[j].body->setIgnoreCollisionCheck(tube.links[j - 2].body, true);
  }
  return tube;
}

physics::TubeGeometry CurrentGeometry(const SimTube& tube) {
  if (tube.tree_C) return tube.tree_C->Transformed(FromBt(tube.links.front().body->getWorldTransform()));
  if (!tube.link_nodes.empty()) return CurrentTree(tube);
  std::vector<Eigen::Vector3d> points;
  for (std::size_t l = 0; l < tube.links.size(); ++l) {
    const SimLink& link = tube.links[l];
    const Eigen::Isometry3d X_BinC = FromBt(link.body->getWorldTransform());
    for (std::size_t k = 0; k < link.p_C_points.size(); ++k) {
      const Eigen::Vector3d p = X_BinC * link.p_C_points[k];
      if (l > 0 && k == 0) {
        points.back() = 0.5 * (points.back() + p);  // the joint both links share
      } else {
        points.push_back(p);
      }
    }
  }
  physics::TubeGeometry g;
  g.id = tube.id;
  for (std::size_t i = 0; i < points.size(); ++i) {
    g.nodes.push_back({static_cast<int>(i + 1), points[i], tube.radius});
  }
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    AddEdge(static_cast<int>(i + 1), static_cast<int>(i + 2), static_cast<int>(i + 1), tube.radius, &g);
  }
  return g;
}

Eigen::Vector3d CentreOfMass(const SimTube& tube) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double mass = 0.0;
  for (const SimLink& link : tube.links) {
    sum += link.mass * FromBt(link.body->getWorldTransform().getOrigin());
    mass += link.mass;
  }
  return sum / mass;
}

}  // namespace tubepick::devices::sim
