#include "physics/tube_bodies.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/common/errors.h"
#include "core/common/tube_graph.h"
#include "physics/bin_solids.h"
#include "physics/tube_geometry.h"

namespace tubepick::physics {
namespace {

static_assert(sizeof(btScalar) == sizeof(double), "tubepick needs Bullet in double precision");

/// Pose of a child shape whose local z axis runs from p to q, centred between them.
Eigen::Isometry3d AlongZ(const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  if ((q - p).norm() > 0.0) X.linear() = RotationFromZ(q - p).toRotationMatrix();
  X.translation() = 0.5 * (p + q);
  return X;
}

/// Collects the children of one compound shape and their share of the tube's volume.
struct ShapeBuilder {
  TubeShape& out;
  std::vector<btScalar>& volumes;
  double margin;

  void Add(std::unique_ptr<btCollisionShape> shape, const Eigen::Isometry3d& X_TubeChild, double volume) {
    out.children.push_back(std::move(shape));
    out.compound->addChildShape(ToBt(X_TubeChild), out.children.back().get());
    volumes.push_back(volume);
  }
  /// A capsule whose cap centres are p and q.
  void Capsule(const Eigen::Vector3d& p, const Eigen::Vector3d& q, double r) {
    const double h = (q - p).norm();
    Add(std::make_unique<btCapsuleShapeZ>(r, h), AlongZ(p, q), M_PI * r * r * h);
  }
  /// A cylinder with flat bases centred on p and q.
  void Cylinder(const Eigen::Vector3d& p, const Eigen::Vector3d& q, double r) {
    const double h = (q - p).norm();
    auto shape = std::make_unique<btCylinderShapeZ>(btVector3(r, r, 0.5 * h));
    shape->setMargin(margin);
    Add(std::move(shape), AlongZ(p, q), M_PI * r * r * h);
  }
  /// A joint sphere whose volume is already counted by its cylinder.
  void Sphere(const Eigen::Vector3d& c, double r) {
    Add(std::make_unique<btSphereShape>(r), AlongZ(c, c), 0.0);
  }
};

}  // namespace

btVector3 ToBt(const Eigen::Vector3d& v) { return btVector3(v.x(), v.y(), v.z()); }

btTransform ToBt(const Eigen::Isometry3d& X) {
  const Eigen::Matrix3d& R = X.linear();
  return btTransform(
      btMatrix3x3(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
      ToBt(X.translation()));
}

Eigen::Vector3d FromBt(const btVector3& v) { return Eigen::Vector3d(v.x(), v.y(), v.z()); }

Eigen::Isometry3d FromBt(const btTransform& X) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out.linear()(r, c) = X.getBasis()[r][c];
    out.translation()[r] = X.getOrigin()[r];
  }
  return out;
}

std::vector<TubeSegment> MakeTubeSegments(const Tube& tube, double joint_min_length) {
  const std::string name = "tube " + std::to_string(tube.id);
  if (tube.cylinders.empty()) throw InvalidArgument(name + " has no cylinders");
  for (std::size_t i = 0; i < tube.cylinders.size(); ++i) {
    const Cylinder& c = tube.cylinders[i];
    const std::string where = name + ", cylinder " + std::to_string(i);
    if (!c.start.allFinite() || !c.end.allFinite()) throw InvalidArgument(where + ": non-finite endpoint");
    if (!(c.radius > 0.0 && std::isfinite(c.radius))) {
      throw InvalidArgument(where + ": radius = " + std::to_string(c.radius) + ", expected > 0");
    }
    if (!(c.length() > 0.0)) throw InvalidArgument(where + ": length = 0, expected > 0");
  }
  ValidateTubeGraph(tube, name);
  // A sphere closes every cylinder end where the tube goes on: a joint, or a junction node.
  const std::size_t n = tube.cylinders.size();
  std::vector<bool> sphere_start(n, false), sphere_end(n, false);
  const std::vector<TubeJoint> joints = TubeJoints(tube);
  for (const TubeJoint& j : joints) {
    if (j.cylinder_a >= 0) sphere_end[static_cast<std::size_t>(j.cylinder_a)] = true;
    if (j.cylinder_b >= 0) sphere_start[static_cast<std::size_t>(j.cylinder_b)] = true;
  }
  const std::vector<std::uint32_t> degree = NodeDegrees(tube);
  for (const TubeBranch& b : BranchesOf(tube)) {
    if (degree[b.from_node] > 1) sphere_start[b.first_cylinder] = true;
    if (degree[b.to_node] > 1) sphere_end[b.first_cylinder + b.cylinder_count - 1] = true;
  }
  std::vector<TubeSegment> segments;
  for (std::size_t i = 0; i < n; ++i) {
    const Cylinder& c = tube.cylinders[i];
    segments.push_back({c.start, c.end, c.radius, sphere_start[i], sphere_end[i], /*joint=*/false});
  }
  for (const TubeJoint& j : joints) {
    if (j.length() > joint_min_length) segments.push_back({j.a, j.b, j.radius, true, true, /*joint=*/true});
  }
  return segments;
}

TubeShape MakeTubeShape(const std::vector<TubeSegment>& segments, double mass, double collision_margin) {
  TubeShape out;
  out.compound = std::make_unique<btCompoundShape>(/*enableDynamicAabbTree=*/true,
                                                   static_cast<int>(2 * segments.size()));
  std::vector<btScalar> volumes;
  ShapeBuilder build{out, volumes, collision_margin};
  for (const TubeSegment& seg : segments) {
    const double r = seg.radius, length = seg.length();
    out.radius = std::max(out.radius, r);
    if (seg.sphere_a && seg.sphere_b) {
      build.Capsule(seg.a, seg.b, r);
    } else if (!seg.sphere_a && !seg.sphere_b) {
      build.Cylinder(seg.a, seg.b, r);
    } else {
      const Eigen::Vector3d& flat = seg.sphere_a ? seg.b : seg.a;
      const Eigen::Vector3d& round = seg.sphere_a ? seg.a : seg.b;
      if (length > r) {
        const Eigen::Vector3d inner = flat + r / length * (round - flat);
        build.Cylinder(flat, inner, r);
        build.Capsule(inner, round, r);
      } else {
        build.Cylinder(flat, round, r);
        build.Sphere(round, r);
      }
    }
  }
  double volume = 0.0;
  for (btScalar v : volumes) volume += v;
  std::vector<btScalar> masses;
  for (btScalar v : volumes) masses.push_back(mass * v / volume);

  btTransform principal;
  out.compound->calculatePrincipalAxisTransform(masses.data(), principal, out.inertia);
  const btTransform inverse = principal.inverse();
  for (int i = 0; i < out.compound->getNumChildShapes(); ++i) {
    out.compound->updateChildTransform(i, inverse * out.compound->getChildTransform(i), false);
  }
  out.compound->recalculateLocalAabb();
  out.X_TubeC = FromBt(principal);
  const Eigen::Vector3d p_TubeCo = out.X_TubeC.translation();
  for (const TubeSegment& seg : segments) {
    out.reach =
        std::max({out.reach, (seg.a - p_TubeCo).norm() + seg.radius, (seg.b - p_TubeCo).norm() + seg.radius});
  }
  return out;
}

namespace {

/// Bullet's default pools hold 4096 manifolds and 4096 collision algorithms (~5 MB, written when
/// the pools are built: 0.6 ms per world). A 10-tube bin uses a few hundred; past the pool Bullet
/// allocates from the heap.
btDefaultCollisionConstructionInfo PoolSizes() {
  btDefaultCollisionConstructionInfo info;
  info.m_defaultMaxPersistentManifoldPoolSize = 512;
  info.m_defaultMaxCollisionAlgorithmPoolSize = 512;
  return info;
}

}  // namespace

BulletWorld::BulletWorld()
    : config(std::make_unique<btDefaultCollisionConfiguration>(PoolSizes())),
      dispatcher(std::make_unique<btCollisionDispatcher>(config.get())),
      broadphase(std::make_unique<btDbvtBroadphase>()),
      solver(std::make_unique<btSequentialImpulseConstraintSolver>()),
      world(std::make_unique<btDiscreteDynamicsWorld>(dispatcher.get(), broadphase.get(), solver.get(),
                                                      config.get())) {}

btRigidBody* BulletWorld::AddBody(const btRigidBody::btRigidBodyConstructionInfo& info, bool kinematic) {
  bodies.push_back(std::make_unique<btRigidBody>(info));
  if (kinematic) {
    // Mass 0 marks the body static: clear that so Bullet books it as a moving body, and never let
    // it sleep (a sleeping kinematic body gets no velocity from its poses and wakes nothing).
    btRigidBody& body = *bodies.back();
    body.setCollisionFlags((body.getCollisionFlags() & ~btCollisionObject::CF_STATIC_OBJECT) |
                           btCollisionObject::CF_KINEMATIC_OBJECT);
    body.setActivationState(DISABLE_DEACTIVATION);
  }
  world->addRigidBody(bodies.back().get());
  return bodies.back().get();
}

void AddBinBodies(BulletWorld& world, const BinConfig& bin, double wall_thickness, double friction,
                  double restitution, double collision_margin) {
  const BinSolids solids = MakeBinSolids(bin, wall_thickness);
  auto add_static = [&](std::unique_ptr<btCollisionShape> shape, const btTransform& pose) {
    world.shapes.push_back(std::move(shape));
    btRigidBody::btRigidBodyConstructionInfo info(0.0, nullptr, world.shapes.back().get());
    info.m_startWorldTransform = pose;
    info.m_friction = friction;
    info.m_rollingFriction = 0.0;
    info.m_restitution = restitution;
    world.AddBody(info);
  };
  add_static(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0.0), btTransform::getIdentity());
  for (std::size_t i = 1; i < solids.boxes.size(); ++i) {  // boxes[0] is the floor slab
    const AlignedBox& box = solids.boxes[i];
    auto shape = std::make_unique<btBoxShape>(ToBt(box.half_size));
    shape->setMargin(collision_margin);
    add_static(std::move(shape), btTransform(btQuaternion::getIdentity(), ToBt(box.centre)));
  }
}

}  // namespace tubepick::physics
