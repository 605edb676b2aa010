#include "physics/trajectory_simulator.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <utility>

#include <spdlog/spdlog.h>

#include "core/common/errors.h"
#include "core/common/thread_budget.h"

namespace tubepick::physics {
namespace {

constexpr double kGravity = 9.81;
/// Tolerated contact penetration (see bin_drop.cc: with two cached friction directions it stops the
/// slow creep of stacked cylinders).
constexpr double kLinearSlop = 0.0005;
/// The first waypoint must be the grasp pose: (0, 0, 0) within this, metres.
constexpr double kFirstWaypointTol = 1e-9;
constexpr char kWhere[] = "trajectory simulation";

void Require(bool ok, const std::string& field, double value, const std::string& expected) {
  if (!ok) {
    throw InvalidArgument("trajectory simulation: " + field + " = " + std::to_string(value) + ": expected " +
                          expected);
  }
}

bool Finite(double x) { return std::isfinite(x); }

/// A world configured like every other in this file: gravity, solver, bin.
void ConfigureWorld(BulletWorld& w, const TrajectorySimParams& params) {
  w.world->setGravity(btVector3(0, 0, -kGravity));
  btContactSolverInfo& info = w.world->getSolverInfo();
  info.m_numIterations = params.solver_iterations;
  info.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS | SOLVER_ENABLE_FRICTION_DIRECTION_CACHING;
  info.m_linearSlop = kLinearSlop;
  AddBinBodies(w, params.bin, params.wall_thickness, params.bin_friction, params.bin_restitution,
               params.collision_margin);
}

/// Adds the tube made of `segments` (Bin frame) with its body frame C at X_BinC, or where the
/// segments put it when X_BinC is null: a dynamic body, or a kinematic one (infinite mass, moved
/// by its owner).
btRigidBody* AddTube(BulletWorld& w, const std::vector<TubeSegment>& segments,
                     const Eigen::Isometry3d* X_BinC, const TrajectorySimParams& params, bool kinematic) {
  w.tube_shapes.push_back(MakeTubeShape(segments, params.tube_mass, params.collision_margin));
  const TubeShape& shape = w.tube_shapes.back();
  const double mass = kinematic ? 0.0 : params.tube_mass;
  const btVector3 inertia = kinematic ? btVector3(0, 0, 0) : shape.inertia;
  btRigidBody::btRigidBodyConstructionInfo info(mass, nullptr, shape.compound.get(), inertia);
  info.m_startWorldTransform = ToBt(X_BinC != nullptr ? *X_BinC : shape.X_TubeC);
  info.m_friction = params.tube_friction;
  info.m_rollingFriction = params.tube_rolling_friction;
  info.m_restitution = params.tube_restitution;
  info.m_linearDamping = params.linear_damping;
  info.m_angularDamping = params.angular_damping;
  info.m_linearSleepingThreshold = params.sleep_linear_velocity;
  info.m_angularSleepingThreshold = params.sleep_angular_velocity;
  btRigidBody* body = w.AddBody(info, kinematic);
  if (!kinematic) {
    // Continuous collision: a swept sphere inside the tube whenever a step moves it more than R
    // (a tube dropped from a lifted one falls fast).
    body->setCcdMotionThreshold(shape.radius);
    body->setCcdSweptSphereRadius(0.8 * shape.radius);
  }
  return body;
}

bool AtRest(const btRigidBody& body, const TrajectorySimParams& params) {
  return body.getLinearVelocity().length() < params.linear_rest_velocity &&
         body.getAngularVelocity().length() < params.angular_rest_velocity;
}

/// The waypoints as a polyline parametrised by arc length.
class Path {
 public:
  explicit Path(const std::vector<Eigen::Vector3d>& waypoints) : points_(waypoints) {
    cumulative_.push_back(0.0);
    for (std::size_t i = 1; i < points_.size(); ++i) {
      cumulative_.push_back(cumulative_.back() + (points_[i] - points_[i - 1]).norm());
    }
  }

  double length() const { return cumulative_.back(); }

  /// The point at arc length s (clamped to [0, length]).
  Eigen::Vector3d At(double s) const {
    if (s >= length()) return points_.back();
    if (s <= 0.0) return points_.front();
    // First vertex beyond s; the segment [k-1, k] has positive length and contains s.
    const std::size_t k = std::upper_bound(cumulative_.begin(), cumulative_.end(), s) - cumulative_.begin();
    const double t = (s - cumulative_[k - 1]) / (cumulative_[k] - cumulative_[k - 1]);
    return points_[k - 1] + t * (points_[k] - points_[k - 1]);
  }

 private:
  std::vector<Eigen::Vector3d> points_;
  std::vector<double> cumulative_;
};

void CheckTrajectoryAgainst(const Trajectory& trajectory, std::size_t tube_count, const std::string& name) {
  if (trajectory.tube_index >= tube_count) {
    throw InvalidArgument(name + ": tube_index = " + std::to_string(trajectory.tube_index) +
                          ", but there are " + std::to_string(tube_count) + " tubes");
  }
  if (trajectory.waypoints.empty()) throw InvalidArgument(name + ": no waypoints");
  for (std::size_t k = 0; k < trajectory.waypoints.size(); ++k) {
    if (!trajectory.waypoints[k].allFinite()) {
      throw InvalidArgument(name + ": waypoint " + std::to_string(k) + " is not finite");
    }
  }
  if (trajectory.waypoints.front().norm() > kFirstWaypointTol) {
    throw InvalidArgument(name + ": the first waypoint must be (0, 0, 0), got a translation of " +
                          std::to_string(trajectory.waypoints.front().norm()) + " m");
  }
}

}  // namespace

void TrajectorySimParams::Validate() const {
  // Lower bounds keep the step counts (path / (v·dt), post_motion_time / dt) well inside an int.
  Require(gripper_speed >= 1e-4 && gripper_speed <= 10.0, "gripper_speed", gripper_speed,
          "0.1 mm/s ≤ v ≤ 10 m/s");
  Require(time_step >= 1e-4 && time_step <= 0.1, "time_step", time_step, "0.1 ms ≤ dt ≤ 0.1 s");
  Require(solver_iterations >= 1 && solver_iterations <= 1000, "solver_iterations", solver_iterations,
          "1 … 1000");
  Require(settle_time >= 0.0 && settle_time <= 3600.0, "settle_time", settle_time, "0 ≤ t ≤ 3600 s");
  Require(rest_time >= 0.0 && Finite(rest_time), "rest_time", rest_time, "≥ 0 s");
  Require(linear_rest_velocity > 0.0 && Finite(linear_rest_velocity), "linear_rest_velocity",
          linear_rest_velocity, "> 0 m/s");
  Require(angular_rest_velocity > 0.0 && Finite(angular_rest_velocity), "angular_rest_velocity",
          angular_rest_velocity, "> 0 rad/s");
  Require(post_motion_time >= 0.0 && post_motion_time <= 3600.0, "post_motion_time", post_motion_time,
          "0 ≤ t ≤ 3600 s");
  Require(disp_max > 0.0 && !std::isnan(disp_max), "disp_max", disp_max, "> 0 m");
  Require(tube_mass > 0.0 && Finite(tube_mass), "tube_mass", tube_mass, "> 0 kg");
  Require(tube_friction >= 0.0 && Finite(tube_friction), "tube_friction", tube_friction, "≥ 0");
  Require(bin_friction >= 0.0 && Finite(bin_friction), "bin_friction", bin_friction, "≥ 0");
  Require(tube_rolling_friction >= 0.0 && Finite(tube_rolling_friction), "tube_rolling_friction",
          tube_rolling_friction, "≥ 0 m");
  Require(tube_restitution >= 0.0 && tube_restitution <= 1.0, "tube_restitution", tube_restitution,
          "in [0, 1]");
  Require(bin_restitution >= 0.0 && bin_restitution <= 1.0, "bin_restitution", bin_restitution, "in [0, 1]");
  Require(linear_damping >= 0.0 && linear_damping <= 1.0, "linear_damping", linear_damping, "in [0, 1]");
  Require(angular_damping >= 0.0 && angular_damping <= 1.0, "angular_damping", angular_damping, "in [0, 1]");
  Require(collision_margin > 0.0 && collision_margin < 0.01, "collision_margin", collision_margin,
          "0 < m < 1 cm");
  Require(joint_min_length >= 0.0 && Finite(joint_min_length), "joint_min_length", joint_min_length, "≥ 0 m");
  Require(sleep_linear_velocity >= 0.0 && Finite(sleep_linear_velocity), "sleep_linear_velocity",
          sleep_linear_velocity, "≥ 0 m/s");
  Require(sleep_angular_velocity >= 0.0 && Finite(sleep_angular_velocity), "sleep_angular_velocity",
          sleep_angular_velocity, "≥ 0 rad/s");
  Require(wall_thickness > 0.0 && wall_thickness <= 1.0, "wall_thickness", wall_thickness, "0 < t ≤ 1 m");
  Require(threads >= 0 && threads <= 1024, "threads", threads, "0 (all cores) … 1024");
  for (int i = 0; i < 3; ++i) {
    Require(bin.inner_size[i] > 0.0 && Finite(bin.inner_size[i]), "bin.inner_size[" + std::to_string(i) + "]",
            bin.inner_size[i], "> 0 m");
  }
}

SettledTubes::SettledTubes(const std::vector<Tube>& tubes, const TrajectorySimParams& params,
                           const StopToken* stop)
    : params_(params) {
  params_.Validate();
  for (const Tube& tube : tubes) segments_.push_back(MakeTubeSegments(tube, params_.joint_min_length));
  ThrowIfStopped(stop, kWhere);

  BulletWorld w;
  ConfigureWorld(w, params_);
  std::vector<btRigidBody*> bodies;
  for (const std::vector<TubeSegment>& segments : segments_) {
    bodies.push_back(AddTube(w, segments, /*X_BinC=*/nullptr, params_, /*kinematic=*/false));
  }

  const int max_steps = static_cast<int>(std::ceil(params_.settle_time / params_.time_step - 1e-9));
  double rest = 0.0;
  int steps = 0;
  while (steps < max_steps && !bodies.empty() && rest < params_.rest_time) {
    ThrowIfStopped(stop, kWhere);
    w.world->stepSimulation(params_.time_step, 0);
    ++steps;
    const bool all_at_rest =
        std::all_of(bodies.begin(), bodies.end(), [&](const btRigidBody* b) { return AtRest(*b, params_); });
    rest = all_at_rest ? rest + params_.time_step : 0.0;
  }
  at_rest_ = bodies.empty() || rest >= params_.rest_time;
  settle_seconds_ = steps * params_.time_step;
  for (const btRigidBody* body : bodies) X_BinC_.push_back(FromBt(body->getWorldTransform()));
  spdlog::debug("trajectory simulation: {} tubes {} after {:.2f} s of settling", bodies.size(),
                at_rest_ ? "at rest" : "NOT at rest", settle_seconds_);
}

void SettledTubes::CheckTrajectory(const Trajectory& trajectory) const {
  CheckTrajectoryAgainst(trajectory, segments_.size(), "trajectory");
}

TrajectoryRun SettledTubes::Run(const Trajectory& trajectory, const StopToken* stop) const {
  return RunImpl(trajectory, stop, nullptr);
}

TrajectoryRun SettledTubes::RunImpl(const Trajectory& trajectory, const StopToken* stop,
                                    const StopToken* abort) const {
  CheckTrajectory(trajectory);
  const std::size_t grasped = trajectory.tube_index;
  const std::size_t n = segments_.size();

  // A fresh world rebuilt from the snapshot in a fixed order: no contact, solver or broadphase
  // cache survives from an earlier trajectory, so the result does not depend on which worker ran
  // what before.
  BulletWorld w;
  ConfigureWorld(w, params_);
  std::vector<btRigidBody*> bodies;
  for (std::size_t i = 0; i < n; ++i) {
    bodies.push_back(AddTube(w, segments_[i], &X_BinC_[i], params_, /*kinematic=*/i == grasped));
    // The snapshot is at rest: the other tubes start asleep and wake when something touches them
    // (Bullet wakes whatever a moving kinematic body or an awake neighbour touches), so tubes the
    // trajectory never reaches stay exactly where they settled.
    if (i != grasped) bodies.back()->setActivationState(ISLAND_SLEEPING);
  }
  const TubeShape& grasped_shape = w.tube_shapes[grasped];

  const Path path(trajectory.waypoints);
  const double dt = params_.time_step;
  const int motion_steps =
      path.length() > 0.0 ? static_cast<int>(std::ceil(path.length() / (params_.gripper_speed * dt) - 1e-9))
                          : 0;
  const int post_steps = static_cast<int>(std::ceil(params_.post_motion_time / dt - 1e-9));
  const Eigen::Isometry3d& X_BinC0 = X_BinC_[grasped];

  TrajectoryRun run;
  run.max_com_z.resize(n);
  for (std::size_t i = 0; i < n; ++i) run.max_com_z[i] = X_BinC_[i].translation().z();
  TrajectoryOutcome& out = run.outcome;
  for (int step = 1; step <= motion_steps + post_steps; ++step) {
    ThrowIfStopped(stop, kWhere);
    ThrowIfStopped(abort, kWhere);
    // Commanded pose at the end of this step: the settled pose translated by the waypoint path.
    const double s = std::min(step, motion_steps) * dt * params_.gripper_speed;
    Eigen::Isometry3d X_BinC_cmd = X_BinC0;
    X_BinC_cmd.translation() += path.At(s);
    bodies[grasped]->setWorldTransform(ToBt(X_BinC_cmd));
    w.world->stepSimulation(dt, 0);
    ++run.steps;

    const Eigen::Isometry3d X_BinC = FromBt(bodies[grasped]->getWorldTransform());
    const Eigen::Isometry3d X_err = X_BinC_cmd.inverse() * X_BinC;
    const double error =
        X_err.translation().norm() + Eigen::AngleAxisd(X_err.linear()).angle() * grasped_shape.reach;
    out.max_tracking_error = std::max(out.max_tracking_error, error);

    out.displacement = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const btVector3& p = bodies[i]->getWorldTransform().getOrigin();
      run.max_com_z[i] = std::max(run.max_com_z[i], static_cast<double>(p.z()));
      if (i != grasped) out.displacement += (FromBt(p) - X_BinC_[i].translation()).norm();
    }
    if (out.displacement > params_.disp_max) {
      out.stopped_early = true;
      break;
    }
  }
  out.simulated_time = run.steps * dt;
  for (const btRigidBody* body : bodies)
    run.p_BinCo_final.push_back(FromBt(body->getWorldTransform().getOrigin()));
  return run;
}

TrajectorySimParams SimParamsForCell(TrajectorySimParams base, const CellConfig& cell, double disp_max,
                                     int threads) {
  base.bin = cell.bin;
  base.tube_mass = cell.tube.mass;
  base.disp_max = disp_max;
  base.threads = threads;
  return base;
}

BulletTrajectoryEvaluator::BulletTrajectoryEvaluator(TrajectorySimParams params)
    : params_(std::move(params)) {
  params_.Validate();
}

std::vector<TrajectoryOutcome> BulletTrajectoryEvaluator::Evaluate(
    const std::vector<Tube>& tubes, const std::vector<Trajectory>& trajectories, std::uint64_t /*seed*/,
    const StopToken* stop) {
  for (std::size_t k = 0; k < trajectories.size(); ++k)
    CheckTrajectoryAgainst(trajectories[k], tubes.size(), "trajectory " + std::to_string(k));
  if (trajectories.empty()) return {};
  const SettledTubes settled(tubes, params_, stop);

  const std::size_t count = trajectories.size();
  std::vector<TrajectoryOutcome> outcomes(count);
  std::size_t threads = static_cast<std::size_t>(ResolveThreads(static_cast<std::uint32_t>(params_.threads)));
  threads = std::min(threads, count);
  if (threads == 1) {
    for (std::size_t k = 0; k < count; ++k)
      outcomes[k] = settled.RunImpl(trajectories[k], stop, nullptr).outcome;
    return outcomes;
  }

  // Workers take the next trajectory in order; each simulates it in a world of its own and writes
  // its own slot. The first failure stops the others (they poll `abort` every step).
  std::atomic<std::size_t> next{0};
  StopToken abort;
  std::mutex error_mutex;
  std::exception_ptr error;
  auto work = [&] {
    for (std::size_t k; (k = next.fetch_add(1)) < count && !abort.stop_requested();) {
      try {
        outcomes[k] = settled.RunImpl(trajectories[k], stop, &abort).outcome;
      } catch (...) {
        std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        abort.RequestStop();
      }
    }
  };
  std::vector<std::thread> pool;
  try {
    for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(work);
  } catch (const std::exception& e) {  // std::system_error, std::bad_alloc: go on with fewer workers
    spdlog::warn("trajectory simulation: started {} of {} worker threads: {}", pool.size() + 1, threads,
                 e.what());
  }
  work();
  for (std::thread& thread : pool) thread.join();
  if (error) std::rethrow_exception(error);
  return outcomes;
}

}  // namespace tubepick::physics
