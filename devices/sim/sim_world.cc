#include "devices/sim/sim_world.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <spdlog/spdlog.h>

#include "core/common/errors.h"

namespace tubepick::devices::sim {
namespace {

using physics::FromBt;
using physics::ToBt;

constexpr double kGravity = 9.81;
/// Tolerated contact penetration, as in physics/ (stops the creep of stacked cylinders).
constexpr double kLinearSlop = 0.0005;
/// Settling: a tube is at rest below these velocities (m/s, rad/s), for this long (s).
constexpr double kRestLinear = 0.01;
constexpr double kRestAngular = 0.1;
constexpr double kRestTime = 0.2;
/// A pad touches a link when their distance is at most this, metres.
constexpr double kTouchDistance = 1e-4;
/// A contact is on a pad's inner face when its normal is within 45° of the closing direction.
constexpr double kInnerFaceCos = 0.7071;
/// Constraint force mixing of the grip's translation and rotation rows. With Bullet's default
/// ERP 0.2 a row behaves like a spring of stiffness ≈ ERP·m/(CFM·dt²): ≈ 2·10⁴ N/m for a tube or a
/// hose link at the default steps (the held tube sinks ≈ 0.03 mm per newton).
constexpr double kGripLinearCfm = 0.1;
constexpr double kGripAngularCfm = 0.02;

int DefaultSubsteps(Material material) { return material == Material::kRubber ? 4 : 2; }

/// Records the deepest contact of one pair test.
struct DepthCallback : btCollisionWorld::ContactResultCallback {
  double min_distance = 0.0;
  btScalar addSingleResult(btManifoldPoint& cp, const btCollisionObjectWrapper*, int, int,
                           const btCollisionObjectWrapper*, int, int) override {
    min_distance = std::min(min_distance, static_cast<double>(cp.getDistance()));
    return 0;
  }
};

bool AabbOverlap(const btCollisionObject& a, const btCollisionObject& b) {
  btVector3 a_lo, a_hi, b_lo, b_hi;
  a.getCollisionShape()->getAabb(a.getWorldTransform(), a_lo, a_hi);
  b.getCollisionShape()->getAabb(b.getWorldTransform(), b_lo, b_hi);
  for (int i = 0; i < 3; ++i) {
    if (a_hi[i] < b_lo[i] || b_hi[i] < a_lo[i]) return false;
  }
  return true;
}

}  // namespace

SimWorld::SimWorld(const SimCellParams& params, const std::vector<physics::TubeGeometry>& tubes_Bin)
    : params_(params), world_(std::make_unique<physics::BulletWorld>()) {
  const SimMaterialParams material =
      params_.material_params.value_or(SimMaterialParams::Defaults(params_.material));
  substeps_ = params_.physics.substeps > 0 ? params_.physics.substeps : DefaultSubsteps(params_.material);
  substep_ = params_.physics.time_step / substeps_;

  if (params_.material == Material::kRubber) {
    // A hose's links are compounds of one or two shapes: collide each link's shapes with the other
    // link (and so with its shapes) one by one. Bullet 3.24's compound-compound algorithm builds
    // four contact manifolds on the stack for every pair at every step, a sixth of a dense hose
    // heap's step; the shape pairs and their contacts are the same. pvc trees, a dozen shapes
    // each, keep it: its tree-against-tree culling pays there (20 pvc trees per bin stepped 29 %
    // slower shape by shape).
    world_->dispatcher->registerCollisionCreateFunc(
        COMPOUND_SHAPE_PROXYTYPE, COMPOUND_SHAPE_PROXYTYPE,
        world_->config->getCollisionAlgorithmCreateFunc(COMPOUND_SHAPE_PROXYTYPE, CAPSULE_SHAPE_PROXYTYPE));
  }
  btDiscreteDynamicsWorld& w = *world_->world;
  w.setGravity(btVector3(0, 0, -kGravity));
  btContactSolverInfo& info = w.getSolverInfo();
  info.m_numIterations = params_.physics.solver_iterations;
  info.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS | SOLVER_ENABLE_FRICTION_DIRECTION_CACHING;
  info.m_linearSlop = kLinearSlop;

  // Bullet multiplies the two bodies' friction (and restitution) values: choose the per-body
  // factors so that every pair gets its effective coefficient.
  const double tube_factor = std::sqrt(material.tube_friction);
  const double restitution_factor = std::sqrt(material.restitution);
  physics::AddBinBodies(*world_, params_.cell.bin, params_.physics.wall_thickness,
                        material.bin_friction / tube_factor, restitution_factor, 0.001);
  for (const auto& body : world_->bodies) {
    body->setUserIndex(kStaticUserIndex);
    static_bodies_.push_back(body.get());
  }

  TubeBodyOptions options;
  options.rubber = params_.material == Material::kRubber;
  options.mass = params_.WorldTubeMass();
  options.material = material;
  options.body_friction = tube_factor;
  options.body_restitution = restitution_factor;
  options.time_step = substep_;
  for (std::size_t i = 0; i < tubes_Bin.size(); ++i) {
    tubes_.push_back(AddSimTube(*world_, tubes_Bin[i], i, options));
  }
  carried_off_.assign(tubes_.size(), false);
  ran_away_.assign(tubes_.size(), false);

  // The gripper: kinematic bodies (moved pose by pose; they push tubes with infinite mass).
  const SimGripperParams& g = params_.gripper;
  auto add_kinematic = [&](btCollisionShape* shape) {
    btRigidBody::btRigidBodyConstructionInfo body_info(0.0, nullptr, shape);
    body_info.m_friction = material.pad_friction / tube_factor;
    body_info.m_restitution = 0.0;
    btRigidBody* body = world_->AddBody(body_info, /*kinematic=*/true);
    body->setUserIndex(kGripperUserIndex);
    return body;
  };
  const bool housing = (g.housing_size.array() > 0.0).all();
  if (housing) {
    auto box = std::make_unique<btBoxShape>(ToBt(0.5 * g.housing_size));
    box->setMargin(0.001);
    auto compound = std::make_unique<btCompoundShape>();
    const double z = g.finger_tip_depth - g.finger_length - g.housing_gap - 0.5 * g.housing_size.z();
    compound->addChildShape(btTransform(btQuaternion::getIdentity(), btVector3(0, 0, z)), box.get());
    world_->shapes.push_back(std::move(box));
    world_->shapes.push_back(std::move(compound));
  } else {
    world_->shapes.push_back(std::make_unique<btEmptyShape>());
  }
  hand_ = add_kinematic(world_->shapes.back().get());
  auto pad = std::make_unique<btBoxShape>(
      btVector3(0.5 * g.finger_width, 0.5 * g.finger_thickness, 0.5 * g.finger_length));
  pad->setMargin(0.001);
  world_->shapes.push_back(std::move(pad));
  if (housing && g.housing_gap > 0.0) {
    // The finger's linkage: from the pad's top up to the housing, as on the 2F-85. Without it a
    // tube could wedge in the open slot between a pad's top and the housing and hang on the open
    // tool (seen: 600-800 N of contact in a simulated 20-tree bin), where the real fingers leave
    // no room.
    btCollisionShape* pad_shape = world_->shapes.back().get();
    auto linkage = std::make_unique<btBoxShape>(
        btVector3(0.5 * g.finger_width, 0.5 * g.finger_thickness, 0.5 * g.housing_gap));
    linkage->setMargin(0.001);
    auto finger = std::make_unique<btCompoundShape>();
    finger->addChildShape(btTransform::getIdentity(), pad_shape);
    finger->addChildShape(
        btTransform(btQuaternion::getIdentity(), btVector3(0, 0, -0.5 * (g.finger_length + g.housing_gap))),
        linkage.get());
    world_->shapes.push_back(std::move(linkage));
    world_->shapes.push_back(std::move(finger));
  }
  for (btRigidBody*& p : pads_) p = add_kinematic(world_->shapes.back().get());

  X_BinTcp_ = params_.robot.X_BinTcp_start;
  opening_ = g.stroke;
  PlaceGripperBodies();
  for (btRigidBody* body : {hand_, pads_[0], pads_[1]})
    body->setInterpolationWorldTransform(body->getWorldTransform());
}

SimWorld::~SimWorld() {
  ReleaseAll();
  for (std::size_t i = 0; i < tubes_.size(); ++i) {
    if (carried_off_[i]) continue;
    for (auto& joint : tubes_[i].joints) world_->world->removeConstraint(joint.get());
  }
}

namespace {

bool AtRest(const SimTube& tube) {
  return std::all_of(tube.links.begin(), tube.links.end(), [](const SimLink& link) {
    return link.body->getLinearVelocity().length() < kRestLinear &&
           link.body->getAngularVelocity().length() < kRestAngular;
  });
}

}  // namespace

bool SimWorld::Settle(double max_seconds) {
  double rest = 0.0;
  const double start = time_;
  while (time_ - start < max_seconds - 1e-12 && rest < kRestTime) {
    ControlStep();
    bool all_at_rest = true;
    for (std::size_t i = 0; i < tubes_.size(); ++i) {
      if (!carried_off_[i] && !AtRest(tubes_[i])) all_at_rest = false;
    }
    rest = all_at_rest ? rest + params_.physics.time_step : 0.0;
  }
  return rest >= kRestTime || tubes_.empty();
}

void SimWorld::SetGripper(const Eigen::Isometry3d& X_BinTcp, double opening) {
  X_BinTcp_ = X_BinTcp;
  opening_ = opening;
}

void SimWorld::PlaceGripperBodies() {
  const SimGripperParams& g = params_.gripper;
  hand_->setWorldTransform(ToBt(X_BinTcp_));
  for (int i = 0; i < 2; ++i) {
    const double side = i == 0 ? 1.0 : -1.0;
    const Eigen::Vector3d p_Tcp(0.0, side * 0.5 * (opening_ + g.finger_thickness),
                                g.finger_tip_depth - 0.5 * g.finger_length);
    Eigen::Isometry3d X_BinPad = X_BinTcp_;
    X_BinPad.translation() = X_BinTcp_ * p_Tcp;
    pads_[i]->setWorldTransform(ToBt(X_BinPad));
  }
}

void SimWorld::Step() {
  PlaceGripperBodies();
  world_->world->stepSimulation(substep_, 0);
  time_ += substep_;
  WatchSpeeds();
  last_wrench_ = MeasureWrench();
  window_sum_.force += last_wrench_.force;
  window_sum_.torque += last_wrench_.torque;
  ++window_steps_;
}

void SimWorld::WatchSpeeds() {
  const SimPhysicsParams& limit = params_.physics;
  for (std::size_t i = 0; i < tubes_.size(); ++i) {
    if (carried_off_[i]) continue;
    double speed = 0.0;
    double angular_speed = 0.0;
    for (const SimLink& link : tubes_[i].links) {
      if (!link.body->isActive()) continue;  // asleep: at rest
      speed = std::max(speed, static_cast<double>(link.body->getLinearVelocity().length()));
      angular_speed = std::max(angular_speed, static_cast<double>(link.body->getAngularVelocity().length()));
    }
    peak_speeds_.linear = std::max(peak_speeds_.linear, speed);
    peak_speeds_.angular = std::max(peak_speeds_.angular, angular_speed);
    if (ran_away_[i] || speed <= limit.runaway_speed) continue;
    ran_away_[i] = true;
    runaways_.push_back({i, time_, speed, angular_speed});
  }
}

void SimWorld::ControlStep() {
  for (int i = 0; i < substeps_; ++i) Step();
}

void SimWorld::BeginWindow() {
  window_sum_ = Wrench{};
  window_steps_ = 0;
}

Wrench SimWorld::WindowMean() const {
  if (window_steps_ == 0) return last_wrench_;
  Wrench mean;
  mean.force = window_sum_.force / window_steps_;
  mean.torque = window_sum_.torque / window_steps_;
  return mean;
}

int SimWorld::GripperPart(const btCollisionObject* object) const {
  if (object == pads_[0]) return 0;
  if (object == pads_[1]) return 1;
  if (object == hand_) return 2;
  return -1;
}

Wrench SimWorld::MeasureWrench() const {
  const Eigen::Vector3d p_BinTcp = X_BinTcp_.translation();
  Eigen::Vector3d force_Bin = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_Bin = Eigen::Vector3d::Zero();  // about the TCP
  // Held links: the constraint's reaction on the hand, whose centre of mass is the TCP.
  for (const auto& grasp : grasps_) {
    force_Bin += FromBt(grasp->feedback->m_appliedForceBodyA);
    torque_Bin += FromBt(grasp->feedback->m_appliedTorqueBodyA);
  }
  // Everything else pressing on the pads or the housing.
  btDispatcher& dispatcher = *world_->world->getDispatcher();
  for (int i = 0; i < dispatcher.getNumManifolds(); ++i) {
    const btPersistentManifold& m = *dispatcher.getManifoldByIndexInternal(i);
    const bool gripper0 = GripperPart(m.getBody0()) >= 0;
    const bool gripper1 = GripperPart(m.getBody1()) >= 0;
    if (gripper0 == gripper1) continue;
    for (int k = 0; k < m.getNumContacts(); ++k) {
      const btManifoldPoint& cp = m.getContactPoint(k);
      // The solver's impulses on body 0: normal along normalWorldOnB, friction along the two
      // lateral directions.
      const btVector3 impulse = cp.m_normalWorldOnB * cp.m_appliedImpulse +
                                cp.m_lateralFrictionDir1 * cp.m_appliedImpulseLateral1 +
                                cp.m_lateralFrictionDir2 * cp.m_appliedImpulseLateral2;
      Eigen::Vector3d f = FromBt(impulse) / substep_;
      Eigen::Vector3d p;
      if (gripper0) {
        p = FromBt(cp.getPositionWorldOnA());
      } else {
        f = -f;
        p = FromBt(cp.getPositionWorldOnB());
      }
      force_Bin += f;
      torque_Bin += (p - p_BinTcp).cross(f);
    }
  }
  const SimGripperParams& g = params_.gripper;
  if (g.tool_mass > 0.0) {
    const Eigen::Vector3d f = g.tool_mass * Eigen::Vector3d(0.0, 0.0, -kGravity);
    force_Bin += f;
    torque_Bin += (X_BinTcp_.linear() * g.p_TcpToolCom).cross(f);
  }
  const Eigen::Matrix3d R_TcpBin = X_BinTcp_.linear().transpose();
  Wrench w;
  w.force = R_TcpBin * force_Bin;
  w.torque = R_TcpBin * torque_Bin;
  return w;
}

PadContacts SimWorld::QueryPads() const {
  PadContacts out;
  std::set<LinkId> links;
  const Eigen::Vector3d y_Bin = X_BinTcp_.linear().col(1);
  const Eigen::Isometry3d X_TcpBin = X_BinTcp_.inverse();
  const double pad_top_z = params_.gripper.finger_tip_depth - params_.gripper.finger_length;
  btDispatcher& dispatcher = *world_->world->getDispatcher();
  for (int i = 0; i < dispatcher.getNumManifolds(); ++i) {
    const btPersistentManifold& m = *dispatcher.getManifoldByIndexInternal(i);
    int pad = GripperPart(m.getBody0());
    const btCollisionObject* other = m.getBody1();
    const bool pad_is_body0 = pad == 0 || pad == 1;
    if (!pad_is_body0) {
      pad = GripperPart(m.getBody1());
      other = m.getBody0();
    }
    if (pad < 0 || pad > 1 || other->getUserIndex() < 0) continue;
    for (int k = 0; k < m.getNumContacts(); ++k) {
      const btManifoldPoint& cp = m.getContactPoint(k);
      if (cp.getDistance() > kTouchDistance) continue;
      if (std::abs(FromBt(cp.m_normalWorldOnB).dot(y_Bin)) < kInnerFaceCos) continue;
      // The pad's face, not the linkage above it.
      const Eigen::Vector3d p_Tcp =
          X_TcpBin * FromBt(pad_is_body0 ? cp.getPositionWorldOnA() : cp.getPositionWorldOnB());
      if (p_Tcp.z() < pad_top_z - kTouchDistance) continue;
      out.touching[pad] = true;
      out.force[pad] += cp.m_appliedImpulse / substep_;
      links.insert({static_cast<std::size_t>(other->getUserIndex()),
                    static_cast<std::size_t>(other->getUserIndex2())});
    }
  }
  out.links.assign(links.begin(), links.end());
  return out;
}

GripperCollision SimWorld::QueryCollision(bool pads, bool housing) const {
  GripperCollision out;
  for (btRigidBody* part : {pads_[0], pads_[1], hand_}) {
    if (part == hand_ ? !housing : !pads) continue;
    for (std::size_t s = 0; s < static_bodies_.size(); ++s) {
      btRigidBody* fixed = static_bodies_[s];
      if (s > 0 && !AabbOverlap(*part, *fixed)) continue;  // s == 0: the ground plane (no finite AABB)
      DepthCallback callback;
      world_->world->contactPairTest(part, fixed, callback);
      if (-callback.min_distance > out.depth) {
        out.depth = -callback.min_distance;
        out.what = std::string(part == hand_ ? "the gripper housing" : "a finger") + " hit " +
                   (s == 0 ? "the bin floor or the ground" : "a bin wall");
      }
    }
  }
  return out;
}

void SimWorld::Attach(const std::vector<LinkId>& links) {
  auto& pair_cache = *world_->world->getBroadphase()->getOverlappingPairCache();
  for (const LinkId& id : links) {
    btRigidBody& body = LinkBody(id);
    auto grasp = std::make_unique<Grasp>();
    grasp->link = id;
    const btTransform frame_hand =
        hand_->getCenterOfMassTransform().inverse() * body.getCenterOfMassTransform();
    grasp->constraint =
        std::make_unique<btFixedConstraint>(*hand_, body, frame_hand, btTransform::getIdentity());
    // A slightly compliant grip (the pads): with a rigid joint, a tube still lying on the floor
    // would hang from the gripper rather than rest on the floor (the solver splits statically
    // indeterminate loads arbitrarily), and the F/T sensor would read its weight before the lift.
    for (int axis = 0; axis < 6; ++axis) {
      grasp->constraint->setParam(BT_CONSTRAINT_STOP_CFM, axis < 3 ? kGripLinearCfm : kGripAngularCfm, axis);
    }
    grasp->feedback = std::make_unique<btJointFeedback>();
    grasp->constraint->setJointFeedback(grasp->feedback.get());
    world_->world->addConstraint(grasp->constraint.get(), /*disableCollisionsBetweenLinkedBodies=*/true);
    for (btRigidBody* pad : pads_) {
      body.setIgnoreCollisionCheck(pad, true);
      pad->setIgnoreCollisionCheck(&body, true);
    }
    // Drop the link's cached contacts with the pads: they would keep pushing. Its other contacts
    // (the floor's) keep their warm start.
    for (btRigidBody* pad : pads_) {
      btBroadphasePair* pair = pair_cache.findPair(body.getBroadphaseHandle(), pad->getBroadphaseHandle());
      if (pair != nullptr) pair_cache.cleanOverlappingPair(*pair, world_->world->getDispatcher());
    }
    body.forceActivationState(DISABLE_DEACTIVATION);
    grasps_.push_back(std::move(grasp));
  }
}

void SimWorld::ReleaseAll() {
  for (auto& grasp : grasps_) {
    btRigidBody& body = LinkBody(grasp->link);
    world_->world->removeConstraint(grasp->constraint.get());
    for (btRigidBody* pad : pads_) {
      body.setIgnoreCollisionCheck(pad, false);
      pad->setIgnoreCollisionCheck(&body, false);
    }
    body.forceActivationState(ACTIVE_TAG);
    body.activate(true);
  }
  grasps_.clear();
}

std::vector<std::size_t> SimWorld::HeldTubes() const {
  std::set<std::size_t> tubes;
  for (const auto& grasp : grasps_) tubes.insert(grasp->link.first);
  return {tubes.begin(), tubes.end()};
}

std::uint32_t SimWorld::AwakeTubeBodies() const {
  std::uint32_t awake = 0;
  for (std::size_t i = 0; i < tubes_.size(); ++i) {
    if (carried_off_[i]) continue;
    for (const SimLink& link : tubes_[i].links) awake += link.body->isActive() ? 1 : 0;
  }
  return awake;
}

std::vector<physics::TubeGeometry> SimWorld::TubesBin() const {
  std::vector<physics::TubeGeometry> out;
  for (const SimTube& tube : tubes_) out.push_back(CurrentGeometry(tube));
  return out;
}

std::vector<physics::TubeGeometry> SimWorld::TubesInWorldBin() const {
  std::vector<physics::TubeGeometry> out;
  for (std::size_t i = 0; i < tubes_.size(); ++i) {
    if (!carried_off_[i]) out.push_back(CurrentGeometry(tubes_[i]));
  }
  return out;
}

std::uint32_t SimWorld::CarryOff(const std::function<bool(const Eigen::Vector3d&)>& where) {
  const std::vector<std::size_t> held = HeldTubes();
  std::uint32_t count = 0;
  for (std::size_t i = 0; i < tubes_.size(); ++i) {
    if (carried_off_[i] || std::binary_search(held.begin(), held.end(), i) || !AtRest(tubes_[i]) ||
        !where(TubeCentreOfMass(i))) {
      continue;
    }
    for (auto& joint : tubes_[i].joints) world_->world->removeConstraint(joint.get());
    for (const SimLink& link : tubes_[i].links) world_->world->removeRigidBody(link.body);
    carried_off_[i] = true;
    ++count;
  }
  return count;
}

}  // namespace tubepick::devices::sim
