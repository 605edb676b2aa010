#include "physics/bin_drop.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>

#include <btBulletDynamicsCommon.h>
#include <spdlog/spdlog.h>

#include "core/common/errors.h"
#include "physics/bin_solids.h"

namespace tubepick::physics {
namespace {

static_assert(sizeof(btScalar) == sizeof(double), "tubepick needs Bullet in double precision");

constexpr double kGravity = 9.81;
constexpr int kOrientationDraws = 100;
constexpr double kLinearSlop = 0.0005;

btVector3 ToBt(const Eigen::Vector3d& v) { return btVector3(v.x(), v.y(), v.z()); }

btTransform ToBt(const Eigen::Isometry3d& X) {
  const Eigen::Matrix3d& R = X.linear();
  return btTransform(
      btMatrix3x3(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
      ToBt(X.translation()));
}

Eigen::Isometry3d FromBt(const btTransform& T) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) X.linear()(r, c) = T.getBasis()[r][c];
    X.translation()[r] = T.getOrigin()[r];
  }
  return X;
}

/// Owns one Bullet world and everything in it. Members are destroyed in reverse order: the world
/// first (it references the rest), then bodies, shapes and the world's helpers.
struct World {
  std::unique_ptr<btDefaultCollisionConfiguration> config =
      std::make_unique<btDefaultCollisionConfiguration>();
  std::unique_ptr<btCollisionDispatcher> dispatcher = std::make_unique<btCollisionDispatcher>(config.get());
  std::unique_ptr<btBroadphaseInterface> broadphase = std::make_unique<btDbvtBroadphase>();
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver =
      std::make_unique<btSequentialImpulseConstraintSolver>();
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::unique_ptr<btDiscreteDynamicsWorld> world = std::make_unique<btDiscreteDynamicsWorld>(
      dispatcher.get(), broadphase.get(), solver.get(), config.get());

  template <typename Shape, typename... Args>
  Shape* AddShape(Args&&... args) {
    auto shape = std::make_unique<Shape>(std::forward<Args>(args)...);
    Shape* raw = shape.get();
    shapes.push_back(std::move(shape));
    return raw;
  }

  btRigidBody* AddBody(const btRigidBody::btRigidBodyConstructionInfo& info) {
    bodies.push_back(std::make_unique<btRigidBody>(info));
    world->addRigidBody(bodies.back().get());
    return bodies.back().get();
  }
};

void AddBin(World& w, const BinConfig& bin, const DropParams& params) {
  const BinSolids solids = MakeBinSolids(bin, params.wall_thickness);
  auto add_static = [&](btCollisionShape* shape, const btTransform& pose) {
    btRigidBody::btRigidBodyConstructionInfo info(0.0, nullptr, shape);
    info.m_startWorldTransform = pose;
    info.m_friction = params.bin_friction;
    info.m_rollingFriction = 0.0;
    info.m_restitution = params.bin_restitution;
    w.AddBody(info);
  };
  for (const AlignedBox& box : solids.boxes) {
    auto* shape = w.AddShape<btBoxShape>(ToBt(box.half_size));
    shape->setMargin(params.collision_margin);
    add_static(shape, btTransform(btQuaternion::getIdentity(), ToBt(box.centre)));
  }
  add_static(w.AddShape<btStaticPlaneShape>(btVector3(0, 0, 1), solids.ground_z), btTransform::getIdentity());
}

/// A tube body: its compound shape is centred on the centre of mass, so the body's transform is
/// X_BinTube · X_TubeCom. Returns X_TubeCom.
struct TubeShape {
  btCompoundShape* compound = nullptr;
  btVector3 inertia;
  Eigen::Isometry3d X_TubeCom = Eigen::Isometry3d::Identity();
  double radius = 0.0;
};

TubeShape MakeTubeShape(World& w, const TubeGeometry& tube, const DropParams& params) {
  if (tube.edges.empty()) throw InvalidArgument("drop: tube " + std::to_string(tube.id) + " has no edges");
  TubeShape out;
  out.compound = w.AddShape<btCompoundShape>();
  std::vector<btScalar> masses;
  double volume = 0.0;
  for (const TubeEdge& e : tube.edges) {
    const Eigen::Vector3d a = tube.Node(e.node1).centre, b = tube.Node(e.node2).centre;
    const double length = (b - a).norm();
    if (!(e.radius > 0.0) || !(length > 0.0)) {
      throw InvalidArgument("drop: tube " + std::to_string(tube.id) + ", edge " + e.name +
                            ": radius and length must be > 0");
    }
    auto* cylinder = w.AddShape<btCylinderShapeZ>(btVector3(e.radius, e.radius, 0.5 * length));
    cylinder->setMargin(params.collision_margin);
    Eigen::Isometry3d X_TubeCyl = Eigen::Isometry3d::Identity();
    X_TubeCyl.linear() = RotationFromZ(b - a).toRotationMatrix();
    X_TubeCyl.translation() = 0.5 * (a + b);
    out.compound->addChildShape(ToBt(X_TubeCyl), cylinder);
    masses.push_back(M_PI * e.radius * e.radius * length);
    out.radius = std::max(out.radius, e.radius);
  }
  for (const TubeNode& n : tube.nodes) {
    if (!tube.IsJoint(n.id)) continue;
    auto* sphere = w.AddShape<btSphereShape>(n.radius);
    out.compound->addChildShape(btTransform(btQuaternion::getIdentity(), ToBt(n.centre)), sphere);
    masses.push_back(4.0 / 3.0 * M_PI * n.radius * n.radius * n.radius);
  }
  for (btScalar m : masses) volume += m;
  for (btScalar& m : masses) m *= params.tube_mass / volume;

  btTransform principal;
  out.compound->calculatePrincipalAxisTransform(masses.data(), principal, out.inertia);
  const btTransform inverse = principal.inverse();
  for (int i = 0; i < out.compound->getNumChildShapes(); ++i) {
    out.compound->updateChildTransform(i, inverse * out.compound->getChildTransform(i), false);
  }
  out.compound->recalculateLocalAabb();
  out.X_TubeCom = FromBt(principal);
  return out;
}

/// Random spawn pose X_BinTube (see DropParams): an orientation whose bounding box fits the
/// footprint and max_spawn_height (else the draw that overflows least), xy inside the footprint,
/// lowest point `drop_clearance` above `top_z`.
Eigen::Isometry3d SpawnPose(const TubeGeometry& tube, double radius, const BinConfig& bin, double top_z,
                            const DropParams& params, std::mt19937_64& rng) {
  const Eigen::Vector2d room(bin.inner_size.x() - 2.0 * params.spawn_margin,
                             bin.inner_size.y() - 2.0 * params.spawn_margin);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Eigen::Matrix3d best_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d best_lo = Eigen::Vector3d::Zero(), best_hi = Eigen::Vector3d::Zero();
  double best_overflow = std::numeric_limits<double>::infinity();
  for (int draw = 0; draw < kOrientationDraws && best_overflow > 0.0; ++draw) {
    Eigen::Quaterniond q;
    do {
      q.coeffs() << normal(rng), normal(rng), normal(rng), normal(rng);
    } while (q.coeffs().norm() < 1e-6);
    const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const TubeNode& n : tube.nodes) {
      lo = lo.cwiseMin(R * n.centre);
      hi = hi.cwiseMax(R * n.centre);
    }
    lo.array() -= radius;
    hi.array() += radius;
    const Eigen::Vector3d extent = hi - lo;
    const double overflow =
        std::max({0.0, extent.x() - room.x(), extent.y() - room.y(), extent.z() - params.max_spawn_height});
    if (overflow < best_overflow) {
      best_overflow = overflow;
      best_rotation = R;
      best_lo = lo;
      best_hi = hi;
    }
  }
  const Eigen::Vector3d half_extent = 0.5 * (best_hi - best_lo);
  const Eigen::Vector3d box_centre = 0.5 * (best_hi + best_lo);
  Eigen::Vector3d target;  // where the bounding-box centre goes
  for (int k = 0; k < 2; ++k) {
    const double slack = std::max(0.0, 0.5 * room[k] - half_extent[k]);
    target[k] = -slack + 2.0 * slack * unit(rng);
  }
  target.z() = top_z + params.drop_clearance + half_extent.z();
  Eigen::Isometry3d X_BinTube = Eigen::Isometry3d::Identity();
  X_BinTube.linear() = best_rotation;
  X_BinTube.translation() = target - box_centre;
  return X_BinTube;
}

bool InsideBin(const TubeGeometry& tube_Bin, const BinConfig& bin) {
  constexpr double kTol = 1e-9;
  for (const TubeNode& n : tube_Bin.nodes) {
    if (std::abs(n.centre.x()) > 0.5 * bin.inner_size.x() + kTol) return false;
    if (std::abs(n.centre.y()) > 0.5 * bin.inner_size.y() + kTol) return false;
    if (n.centre.z() < -kTol) return false;
  }
  return true;
}

}  // namespace

void DropParams::Validate() const {
  auto require = [](bool ok, const std::string& field, double value, const std::string& expected) {
    if (!ok)
      throw InvalidArgument("drop: " + field + " = " + std::to_string(value) + ": expected " + expected);
  };
  require(wall_thickness > 0.0 && wall_thickness <= 1.0, "wall_thickness", wall_thickness, "0 < t ≤ 1 m");
  require(tube_mass > 0.0 && std::isfinite(tube_mass), "tube_mass", tube_mass, "> 0 kg");
  require(tube_friction >= 0.0 && std::isfinite(tube_friction), "tube_friction", tube_friction, "≥ 0");
  require(bin_friction >= 0.0 && std::isfinite(bin_friction), "bin_friction", bin_friction, "≥ 0");
  require(tube_rolling_friction >= 0.0 && std::isfinite(tube_rolling_friction), "tube_rolling_friction",
          tube_rolling_friction, "≥ 0");
  require(tube_restitution >= 0.0 && tube_restitution <= 1.0, "tube_restitution", tube_restitution,
          "in [0, 1]");
  require(bin_restitution >= 0.0 && bin_restitution <= 1.0, "bin_restitution", bin_restitution, "in [0, 1]");
  require(linear_damping >= 0.0 && linear_damping <= 1.0, "linear_damping", linear_damping, "in [0, 1]");
  require(angular_damping >= 0.0 && angular_damping <= 1.0, "angular_damping", angular_damping, "in [0, 1]");
  require(time_step > 0.0 && time_step <= 0.1, "time_step", time_step, "0 < dt ≤ 0.1 s");
  require(solver_iterations >= 1, "solver_iterations", solver_iterations, "≥ 1");
  require(collision_margin > 0.0 && collision_margin < 0.01, "collision_margin", collision_margin,
          "0 < m < 1 cm");
  require(spawn_interval >= 0.0 && std::isfinite(spawn_interval), "spawn_interval", spawn_interval, "≥ 0 s");
  require(drop_clearance >= 0.0 && std::isfinite(drop_clearance), "drop_clearance", drop_clearance, "≥ 0 m");
  require(spawn_margin >= 0.0 && std::isfinite(spawn_margin), "spawn_margin", spawn_margin, "≥ 0 m");
  require(max_spawn_height > 0.0 && std::isfinite(max_spawn_height), "max_spawn_height", max_spawn_height,
          "> 0 m");
  require(linear_rest_velocity > 0.0, "linear_rest_velocity", linear_rest_velocity, "> 0 m/s");
  require(angular_rest_velocity > 0.0, "angular_rest_velocity", angular_rest_velocity, "> 0 rad/s");
  require(sleep_linear_velocity >= 0.0 && std::isfinite(sleep_linear_velocity), "sleep_linear_velocity",
          sleep_linear_velocity, "≥ 0 m/s");
  require(sleep_angular_velocity >= 0.0 && std::isfinite(sleep_angular_velocity), "sleep_angular_velocity",
          sleep_angular_velocity, "≥ 0 rad/s");
  require(settle_time >= 0.0 && std::isfinite(settle_time), "settle_time", settle_time, "≥ 0 s");
  require(max_time > 0.0 && max_time <= 3600.0, "max_time", max_time, "0 < t ≤ 3600 s");
}

DropResult DropTubes(const std::vector<TubeGeometry>& tubes, const BinConfig& bin, const DropParams& params,
                     std::uint64_t seed) {
  params.Validate();
  for (int i = 0; i < 3; ++i) {
    if (!(bin.inner_size[i] > 0.0 && std::isfinite(bin.inner_size[i]))) {
      throw InvalidArgument("drop: bin.inner_size[" + std::to_string(i) +
                            "] = " + std::to_string(bin.inner_size[i]) + ": expected > 0");
    }
  }
  DropResult result;
  if (tubes.empty()) {
    result.settled = true;
    return result;
  }
  World w;
  w.world->setGravity(btVector3(0, 0, -kGravity));
  w.world->getSolverInfo().m_numIterations = params.solver_iterations;
  // Two friction directions with cached directions and a little slop (0.5 mm of tolerated
  // penetration) stop the slow rocking/creep of stacked cylinders that otherwise keeps a pile from
  // ever coming to rest (measured: 16/16 ten-tube drops settle instead of 9/16).
  w.world->getSolverInfo().m_solverMode |=
      SOLVER_USE_2_FRICTION_DIRECTIONS | SOLVER_ENABLE_FRICTION_DIRECTION_CACHING;
  w.world->getSolverInfo().m_linearSlop = kLinearSlop;
  AddBin(w, bin, params);

  std::vector<TubeShape> shapes;
  for (const TubeGeometry& tube : tubes) shapes.push_back(MakeTubeShape(w, tube, params));

  std::mt19937_64 rng(seed);
  std::vector<btRigidBody*> bodies;
  auto spawn = [&](std::size_t i) {
    double top_z = 0.0;  // bin floor
    for (btRigidBody* body : bodies) {
      btVector3 lo, hi;
      body->getAabb(lo, hi);
      top_z = std::max(top_z, static_cast<double>(hi.z()));
    }
    const Eigen::Isometry3d X_BinTube = SpawnPose(tubes[i], shapes[i].radius, bin, top_z, params, rng);
    btRigidBody::btRigidBodyConstructionInfo info(params.tube_mass, nullptr, shapes[i].compound,
                                                  shapes[i].inertia);
    info.m_startWorldTransform = ToBt(X_BinTube * shapes[i].X_TubeCom);
    info.m_friction = params.tube_friction;
    info.m_rollingFriction = params.tube_rolling_friction;
    info.m_restitution = params.tube_restitution;
    info.m_linearDamping = params.linear_damping;
    info.m_angularDamping = params.angular_damping;
    info.m_linearSleepingThreshold = params.sleep_linear_velocity;
    info.m_angularSleepingThreshold = params.sleep_angular_velocity;
    btRigidBody* body = w.AddBody(info);
    // Continuous collision: a swept sphere inside the tube whenever a step moves it more than R.
    body->setCcdMotionThreshold(shapes[i].radius);
    body->setCcdSweptSphereRadius(0.8 * shapes[i].radius);
    bodies.push_back(body);
  };

  double since_spawn = 0.0;
  double rest_time = 0.0;
  spawn(0);
  while (bodies.size() < tubes.size() || (rest_time < params.settle_time && since_spawn < params.max_time)) {
    if (bodies.size() < tubes.size()) {
      const bool ready = params.wait_for_rest
                             ? (rest_time >= params.settle_time || since_spawn >= params.max_time)
                             : since_spawn >= params.spawn_interval;
      if (ready) {
        spawn(bodies.size());
        since_spawn = 0.0;
        rest_time = 0.0;
      }
    }
    w.world->stepSimulation(params.time_step, 0);
    ++result.steps;
    result.simulated_time += params.time_step;
    since_spawn += params.time_step;
    bool all_at_rest = true;
    for (const btRigidBody* body : bodies) {
      if (body->getLinearVelocity().length() >= params.linear_rest_velocity ||
          body->getAngularVelocity().length() >= params.angular_rest_velocity) {
        all_at_rest = false;
        break;
      }
    }
    rest_time = all_at_rest ? rest_time + params.time_step : 0.0;
  }
  result.settled = rest_time >= params.settle_time;
  if (!result.settled) {
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      spdlog::debug("drop: tube {} still moving: |v| = {:.4f} m/s, |w| = {:.4f} rad/s, z = {:.3f} m",
                    tubes[i].id, bodies[i]->getLinearVelocity().length(),
                    bodies[i]->getAngularVelocity().length(), bodies[i]->getWorldTransform().getOrigin().z());
    }
  }
  spdlog::debug("drop: {} tubes, {} in {:.2f} s simulated ({} steps)", tubes.size(),
                result.settled ? "settled" : "NOT settled", result.simulated_time, result.steps);

  for (std::size_t i = 0; i < tubes.size(); ++i) {
    const Eigen::Isometry3d X_BinTube =
        FromBt(bodies[i]->getWorldTransform()) * shapes[i].X_TubeCom.inverse();
    result.X_BinTube.push_back(X_BinTube);
    result.tubes.push_back(tubes[i].Transformed(X_BinTube));
    result.inside_bin.push_back(InsideBin(result.tubes.back(), bin));
  }
  return result;
}

}  // namespace tubepick::physics
