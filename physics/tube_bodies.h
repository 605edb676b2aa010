#pragma once

#include <memory>
#include <vector>

#include <btBulletDynamicsCommon.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/common/cell_config.h"
#include "core/common/types.h"

namespace tubepick::physics {

/// One solid of a simulated tube, in the frame its tube is given in (usually Bin): a cylinder of
/// `radius` from `a` to `b` whose ends are flat, or carry a sphere of `radius` (a joint sphere).
struct TubeSegment {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double radius = 0.0;
  bool sphere_a = false;
  bool sphere_b = false;
  /// A joint cylinder (between two modeled cylinders) rather than a modeled cylinder.
  bool joint = false;

  double length() const { return (b - a).norm(); }
};

/// The solids that model a virtual tube in simulation (thesis §5.2.3.2): one segment per modeled
/// cylinder, in order, then, for every joint cylinders[i].end → cylinders[i+1].start longer than
/// `joint_min_length`, a joint segment between the two endpoints (radius: the mean of the two
/// cylinders'). Every endpoint involved in a joint carries a sphere of its cylinder's radius; the
/// tube's two free ends are flat. So the tube has no gaps.
/// @throws InvalidArgument when the tube has no cylinders, or a cylinder has a non-finite endpoint,
/// a radius that is not > 0 or a length that is not > 0 (the message names tube id and cylinder).
std::vector<TubeSegment> MakeTubeSegments(const Tube& tube, double joint_min_length);

/// A tube as one Bullet compound shape centred on its centre of mass and aligned with its principal
/// axes (mass spread along the segments in proportion to their cylinder volumes). The body frame C
/// of a tube body is that principal frame: the body's world transform is X_BinC.
///
/// A cylinder with a sphere on each end is exactly a capsule, which Bullet collides analytically
/// (capsule–capsule, capsule–plane) instead of by GJK, 3–5× faster per step. So a segment with two
/// spheres is one btCapsuleShapeZ; a segment with one flat end (a tube's free end) is a capsule
/// from R inside the flat end to the sphere end plus a flat btCylinderShapeZ of length R at the
/// flat end (their union is the cylinder and its sphere exactly, for segments at least R long);
/// a segment with two flat ends (a one-cylinder tube) is a btCylinderShapeZ. A joint segment is a
/// capsule of the mean radius, within |r_i − r_i+1|/2 of the thesis' spheres of radius r_i, r_i+1.
struct TubeShape {
  std::vector<std::unique_ptr<btCollisionShape>> children;
  std::unique_ptr<btCompoundShape> compound;
  /// Principal moments of inertia for the tube's mass, kg·m².
  btVector3 inertia{0, 0, 0};
  /// X_TubeC: pose of the principal frame in the frame the segments are given in.
  Eigen::Isometry3d X_TubeC = Eigen::Isometry3d::Identity();
  /// Largest distance from the centre of mass to a point of the tube, metres.
  double reach = 0.0;
  /// Largest segment radius, metres.
  double radius = 0.0;
};

/// Builds the compound shape of `segments` (non-empty, as from MakeTubeSegments) for a tube of
/// `mass` kg; flat cylinders get `collision_margin` (a capsule's margin is its radius).
/// Deterministic: the same segments give bitwise the same shape and frame.
TubeShape MakeTubeShape(const std::vector<TubeSegment>& segments, double mass, double collision_margin);

/// One Bullet world and everything in it (one per thread: nothing is shared). Members are
/// destroyed in reverse order: the world first (it references the rest), then bodies, shapes and
/// the world's helpers.
struct BulletWorld {
  BulletWorld();
  BulletWorld(const BulletWorld&) = delete;
  BulletWorld& operator=(const BulletWorld&) = delete;

  std::unique_ptr<btDefaultCollisionConfiguration> config;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btBroadphaseInterface> broadphase;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver;
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<TubeShape> tube_shapes;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::unique_ptr<btDiscreteDynamicsWorld> world;

  /// Creates a body from `info` and adds it to the world (bodies are stepped in insertion order).
  /// A `kinematic` body (give it mass 0) is moved by its owner through setWorldTransform before each
  /// step; Bullet then derives its velocity from the last two poses, so contacts see its motion and
  /// it pushes dynamic bodies with infinite mass. It never sleeps.
  btRigidBody* AddBody(const btRigidBody::btRigidBodyConstructionInfo& info, bool kinematic = false);
};

/// Adds the bin as static bodies: the four walls of MakeBinSolids and, for its floor slab and the
/// ground, one plane z = 0 (the slab's top face; a capsule lying on a plane is analytic, on a box it
/// needs GJK, which tripled the cost of a step). Outside the bin the ground is then at z = 0
/// instead of −wall_thickness.
/// @throws InvalidArgument for an invalid wall_thickness.
void AddBinBodies(BulletWorld& world, const BinConfig& bin, double wall_thickness, double friction,
                  double restitution, double collision_margin);

btVector3 ToBt(const Eigen::Vector3d& v);
btTransform ToBt(const Eigen::Isometry3d& X);
Eigen::Vector3d FromBt(const btVector3& v);
Eigen::Isometry3d FromBt(const btTransform& X);

}  // namespace tubepick::physics
