#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include <btBulletDynamicsCommon.h>
#include <Eigen/Core>

#include "devices/sim/sim_cell.h"
#include "physics/tube_bodies.h"
#include "physics/tube_geometry.h"

namespace tubepick::devices::sim {

/// btCollisionObject user index of bodies that are not tube links.
inline constexpr int kStaticUserIndex = -1;
inline constexpr int kGripperUserIndex = -2;

/// One rigid body of a simulated tube (the whole tube for pvc, one chain link for rubber).
struct SimLink {
  btRigidBody* body = nullptr;
  /// Centreline points of this body, in order along the tube, in its body frame C (centre of mass,
  /// principal axes).
  std::vector<Eigen::Vector3d> p_C_points;
  double mass = 0.0;
};

/// A tube of the cell: its bodies and, for rubber, the spring joints between consecutive links.
struct SimTube {
  int id = 0;
  double radius = 0.0;
  double mass = 0.0;
  std::vector<SimLink> links;
  std::vector<std::unique_ptr<btGeneric6DofSpring2Constraint>> joints;
  /// A branched pvc tube: its tree in the frame C of its one body.
  std::optional<physics::TubeGeometry> tree_C;
  /// A branched rubber tube: the node ids of each link's two centreline points (links[l].p_C_points
  /// front and back); links meeting at a node share its id, a junction's three links one id.
  std::vector<std::pair<int, int>> link_nodes;
};

/// How tube bodies are made.
struct TubeBodyOptions {
  bool rubber = false;
  /// Mass of one tube, kg.
  double mass = 0.055;
  SimMaterialParams material;
  /// Bullet body friction and restitution (the per-body factors of the pair products).
  double body_friction = 0.5;
  double body_restitution = 0.3;
  double collision_margin = 0.001;
  /// Bullet's sleeping thresholds: a body whose speeds stay below them for 2 s sleeps (until
  /// something touches it). m/s, rad/s.
  double sleep_linear_velocity = 0.02;
  /// A rubber link takes sleep_linear_velocity over its reach (the farthest point of its surface
  /// from its centre of mass) when that is larger: turning at it, no point of the link moves faster
  /// than a link may slide and still sleep (0.57 rad/s for 5 cm links of 1 cm radius). Links this
  /// light are spun about their own axis by contact noise at 0.2-0.5 rad/s (their surface moving
  /// at millimetres a second), which kept whole piles of hoses awake.
  double sleep_angular_velocity = 0.2;
  double linear_damping = 0.05;
  double angular_damping = 0.2;
  /// Bullet step, seconds (the rubber joints' implicit springs are tuned for it).
  double time_step = 1.0 / 480.0;
};

/// Adds `tube_Bin` (bin frame) to `world` where it is: one rigid capsule compound (pvc, linear or
/// branched, physics::MakeTubeShape) or a chain of capsule links joined at the centreline by
/// btGeneric6DofSpring2Constraints (rubber: locked translation and twist, implicit angular springs
/// about both bending axes whose rest angle is the generated shape). A branched rubber tube is a
/// chain per branch (between its end and junction nodes); at a junction one of the branches'
/// links holds the others by such joints, so the fitting keeps its angles as a spring.
/// Links within two of each other (through shared nodes) do not collide. Every body's user index
/// is `tube_index` and user index 2 its link index.
/// @throws InvalidArgument when the tube has no length.
SimTube AddSimTube(physics::BulletWorld& world, const physics::TubeGeometry& tube_Bin, std::size_t tube_index,
                   const TubeBodyOptions& options);

/// The tube as it is now, bin frame: a branched pvc tube's tree moved with its body; a linear
/// tube's centreline points as nodes (ids 1..n, in order; a joint shared by two links is the mean
/// of both), an edge between consecutive nodes ("e_<i>_<i+1>", order i, the tube's radius); a
/// branched rubber tube's link ends as nodes (a node shared by links is their mean), an edge per
/// link.
physics::TubeGeometry CurrentGeometry(const SimTube& tube);

/// Mass-weighted centre of the tube's bodies, bin frame.
Eigen::Vector3d CentreOfMass(const SimTube& tube);

/// Points at equal arc-length spacing along the polyline, both ends included (count ≥ 2).
std::vector<Eigen::Vector3d> ResamplePolyline(const std::vector<Eigen::Vector3d>& line, int count);

}  // namespace tubepick::devices::sim
