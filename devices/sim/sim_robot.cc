// The simulated arm: straight TCP motions of the kinematic gripper.

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "devices/sim/sim_devices.h"
#include "devices/sim/sim_motion.h"

namespace tubepick::devices::sim {
namespace {

constexpr double kDeg = 180.0 / M_PI;

std::string Format(const Eigen::Vector3d& p) {
  return fmt::format("({:.3f}, {:.3f}, {:.3f})", p.x(), p.y(), p.z());
}

bool FiniteRigid(const Eigen::Isometry3d& X) {
  if (!X.matrix().allFinite()) return false;
  const Eigen::Matrix3d R = X.linear();
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-6 && R.determinant() > 0.0;
}

}  // namespace

void SimRobot::CheckReady() const {
  state_.ThrowIfInjected(SimDevice::kRobot, "robot");
  if (!state_.servo_on) throw DeviceFault("robot: servo off (call ServoOn before moving)");
}

void SimRobot::CheckTarget(const Eigen::Isometry3d& X_BinTcp) const {
  if (!FiniteRigid(X_BinTcp)) throw DeviceFault("robot: invalid target pose (not a finite rigid transform)");
  const Eigen::Vector3d p = X_BinTcp.translation();
  const Eigen::AlignedBox3d& box = state_.workspace;
  if (!box.contains(p)) {
    throw DeviceFault(fmt::format(
        "robot: target {} m is out of reach (workspace x [{:.2f}, {:.2f}], y [{:.2f}, "
        "{:.2f}], z [{:.2f}, {:.2f}] m)",
        Format(p), box.min().x(), box.max().x(), box.min().y(), box.max().y(), box.min().z(), box.max().z()));
  }
  const double tilt = TiltFromVertical(X_BinTcp);
  if (tilt > state_.params.robot.max_tilt + 1e-9) {
    throw DeviceFault(
        fmt::format("robot: joint limit: the target at {} m tilts the tool {:.1f}° from vertical "
                    "(limit {:.1f}°)",
                    Format(p), tilt * kDeg, state_.params.robot.max_tilt * kDeg));
  }
}

RobotLimits SimRobot::Limits() const {
  RobotLimits limits;
  limits.max_speed = state_.params.robot.max_speed;
  limits.reach_Bin = state_.workspace;
  limits.max_tilt = state_.params.robot.max_tilt;
  return limits;
}

double SimRobot::EffectiveSpeed(double speed) const {
  const SimRobotParams& r = state_.params.robot;
  if (!(speed > 0.0) || !std::isfinite(speed)) return r.default_speed;
  return std::min(speed, r.max_speed);
}

template <typename PoseAt>
void SimRobot::Run(double length, double speed, const PoseAt& pose_at, const Eigen::Isometry3d& X_BinTcp_end,
                   Timeout timeout) {
  SimWorld& world = *state_.world;
  const TrapezoidProfile profile(length, speed, state_.params.robot.acceleration);
  const double dt = world.substep();
  const int steps = static_cast<int>(std::ceil(profile.duration() / dt - 1e-9));
  const double limit = Seconds(timeout);
  // A move out of a collision (after a protective stop) is allowed: only going deeper stops.
  const bool housing_stop = state_.params.robot.housing_stop;
  double allowed_depth =
      std::max(state_.params.robot.collision_depth, world.QueryCollision(true, housing_stop).depth);
  bool warned = housing_stop;
  for (int k = 1; k <= steps; ++k) {
    const double t = k * dt;
    if (t > limit + 1e-12) {
      throw DeviceTimeout(
          fmt::format("robot: move not finished within {:.3f} s (needs {:.3f} s); stopped at {} m", limit,
                      profile.duration(), Format(world.X_BinTcp().translation())));
    }
    world.SetGripper(k == steps ? X_BinTcp_end : pose_at(profile.DistanceAt(t)), world.opening());
    Tick();
    if (k % world.substeps() == 0 || k == steps) {
      const GripperCollision collision = world.QueryCollision(true, housing_stop);
      if (!warned) {
        const GripperCollision housing = world.QueryCollision(false, true);
        if (housing.depth > allowed_depth + 1e-4) {
          spdlog::warn("sim robot: {} ({:.1f} mm deep) at {} m; a real robot would stop (robot.housing_stop)",
                       housing.what, housing.depth * 1e3, Format(world.X_BinTcp().translation()));
          warned = true;
        }
      }
      if (collision.depth > allowed_depth + 1e-4) {
        state_.servo_on = false;
        throw DeviceFault(fmt::format("robot: protective stop: {} ({:.1f} mm deep) at {} m; servo off",
                                      collision.what, collision.depth * 1e3,
                                      Format(world.X_BinTcp().translation())));
      }
      allowed_depth = std::max(state_.params.robot.collision_depth, std::min(allowed_depth, collision.depth));
    }
  }
  world.SetGripper(X_BinTcp_end, world.opening());
}

void SimRobot::MoveTo(const Eigen::Isometry3d& X_BinTcp, double speed, Timeout timeout) {
  CheckReady();
  CheckTarget(X_BinTcp);
  const PoseSegment segment(state_.world->X_BinTcp(), X_BinTcp);
  // Rotations run at speed / rotation_radius: the path is as long as the longer of both.
  const double length = std::max(segment.distance(), segment.angle() * state_.params.robot.rotation_radius);
  Run(
      length, EffectiveSpeed(speed), [&](double s) { return segment.At(length > 0.0 ? s / length : 1.0); },
      X_BinTcp, timeout);
}

void SimRobot::MoveThrough(const std::vector<Eigen::Vector3d>& waypoints, double speed, Timeout timeout) {
  CheckReady();
  const Eigen::Isometry3d start = state_.world->X_BinTcp();
  std::vector<Eigen::Vector3d> points{start.translation()};
  for (const Eigen::Vector3d& offset : waypoints) {
    if (!offset.allFinite()) throw DeviceFault("robot: non-finite waypoint");
    Eigen::Isometry3d target = start;
    target.translation() += offset;
    CheckTarget(target);
    points.push_back(target.translation());
  }
  const Polyline path(std::move(points));
  Eigen::Isometry3d end = start;
  end.translation() = path.At(path.length());
  Run(
      path.length(), EffectiveSpeed(speed),
      [&](double s) {
        Eigen::Isometry3d X = start;
        X.translation() = path.At(s);
        return X;
      },
      end, timeout);
}

Eigen::Isometry3d SimRobot::CurrentPose(Timeout /*timeout*/) {
  state_.ThrowIfInjected(SimDevice::kRobot, "robot");
  return state_.world->X_BinTcp();
}

std::optional<RobotStatus> SimRobot::Status(Timeout /*timeout*/) {
  RobotStatus status;
  status.servo_on = state_.servo_on;
  status.alarm = state_.faults[static_cast<std::size_t>(SimDevice::kRobot)] != SimFault::kNone;
  status.detail = status.servo_on ? "simulated, servo on" : "simulated, servo off";
  return status;
}

void SimRobot::Tick() {
  state_.world->Step();
  state_.TickSlip(state_.world->substep());
  state_.TickRobotAlarm(state_.world->substep());
}

void SimRobot::HoldFor(double seconds) {
  CheckReady();
  for (int k = static_cast<int>(std::ceil(seconds / state_.world->substep() - 1e-9)); k > 0; --k) Tick();
}

void SimRobot::ServoOn(Timeout /*timeout*/) {
  state_.ThrowIfInjected(SimDevice::kRobot, "robot");
  state_.servo_on = true;
}

}  // namespace tubepick::devices::sim
