#pragma once

// Small scripted devices behind the protocol servers in the tests: they do what the test says and
// record what they were asked.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <numbers>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Geometry>

#include "devices/force_torque_sensor.h"
#include "devices/gripper.h"
#include "devices/robot.h"

namespace tubepick::devices::scripted {

inline constexpr double kDeg = std::numbers::pi / 180.0;

/// X = (x, y, z) with R = Rz·Ry·Rx (degrees), the pendant's convention.
inline Eigen::Isometry3d Pose(double x, double y, double z, double rx_deg, double ry_deg, double rz_deg) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(x, y, z);
  X.linear() = (Eigen::AngleAxisd(rz_deg * kDeg, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(ry_deg * kDeg, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(rx_deg * kDeg, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return X;
}

/// Angle of the rotation between two poses, radians.
inline double AngleBetween(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

/// A gate a scripted call can wait at until the test opens it.
class Gate {
 public:
  void Close() {
    std::lock_guard lock(mutex_);
    open_ = false;
  }
  void Open() {
    {
      std::lock_guard lock(mutex_);
      open_ = true;
    }
    cv_.notify_all();
  }
  void Pass() {
    std::unique_lock lock(mutex_);
    ++waiting_;
    cv_.notify_all();
    cv_.wait(lock, [this] { return open_; });
    --waiting_;
  }
  /// Waits until a call waits at the closed gate; false after `timeout`.
  bool AwaitWaiter(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, timeout, [this] { return waiting_ > 0; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool open_ = true;
  int waiting_ = 0;
};

/// A robot that moves instantly (after `move_time`) and can fail a given move halfway.
class ScriptedRobot final : public Robot {
 public:
  struct MoveCall {
    Eigen::Isometry3d X_BinTcp;
    double speed = 0.0;
  };

  explicit ScriptedRobot(Eigen::Isometry3d X_BinTcp_start) : X_BinTcp_(X_BinTcp_start) {}

  void MoveTo(const Eigen::Isometry3d& X_BinTcp, double speed, Timeout /*timeout*/) override {
    std::size_t index = 0;
    {
      std::lock_guard lock(mutex_);
      moves_.push_back({X_BinTcp, speed});
      index = moves_.size();
      if (!servo_on_) throw DeviceFault("scripted robot: servo off");
    }
    gate.Pass();
    std::this_thread::sleep_for(move_time.load());
    std::lock_guard lock(mutex_);
    if (index == fail_move_) {
      X_BinTcp_.translation() = 0.5 * (X_BinTcp_.translation() + X_BinTcp.translation());
      servo_on_ = false;
      throw DeviceFault("scripted robot: joint 3 overload");
    }
    X_BinTcp_ = X_BinTcp;
  }
  void MoveThrough(const std::vector<Eigen::Vector3d>& /*waypoints*/, double /*speed*/,
                   Timeout /*timeout*/) override {
    throw DeviceFault("scripted robot: MoveThrough is not scripted");
  }
  Eigen::Isometry3d CurrentPose(Timeout /*timeout*/) override {
    std::lock_guard lock(mutex_);
    ++pose_reads_;
    if (pose_timeout_) throw DeviceTimeout("scripted robot: no answer");
    return X_BinTcp_;
  }
  void ServoOn(Timeout /*timeout*/) override {
    std::lock_guard lock(mutex_);
    ++servo_on_calls_;
    servo_on_ = true;
  }
  RobotLimits Limits() const override { return {}; }

  /// The n-th MoveTo (from 1) stops halfway with a DeviceFault and servo off; 0 = none.
  void FailMove(std::size_t n) {
    std::lock_guard lock(mutex_);
    fail_move_ = n;
  }
  void SetPoseTimeout(bool on) {
    std::lock_guard lock(mutex_);
    pose_timeout_ = on;
  }
  std::vector<MoveCall> moves() const {
    std::lock_guard lock(mutex_);
    return moves_;
  }
  Eigen::Isometry3d X_BinTcp() const {
    std::lock_guard lock(mutex_);
    return X_BinTcp_;
  }
  int servo_on_calls() const {
    std::lock_guard lock(mutex_);
    return servo_on_calls_;
  }
  int pose_reads() const {
    std::lock_guard lock(mutex_);
    return pose_reads_;
  }

  /// MoveTo waits here (after recording the call) while the test keeps it closed.
  Gate gate;
  std::atomic<std::chrono::milliseconds> move_time{std::chrono::milliseconds(20)};

 private:
  mutable std::mutex mutex_;
  Eigen::Isometry3d X_BinTcp_;
  bool servo_on_ = false;
  bool pose_timeout_ = false;
  std::size_t fail_move_ = 0;
  std::vector<MoveCall> moves_;
  int servo_on_calls_ = 0;
  int pose_reads_ = 0;
};

/// A gripper whose fingers stop on an object of a given width while closing.
class ScriptedGripper final : public Gripper {
 public:
  struct MotionCall {
    bool close = false;  ///< Close(), else MoveTo()
    double opening = 0.0;
    double speed = 0.0;
    double force = 0.0;
  };

  void Activate(Timeout /*timeout*/) override {
    activation_gate.Pass();
    std::lock_guard lock(mutex_);
    ++activations_;
    activated_ = true;
  }
  GripperStatus MoveTo(double opening, double speed, double force, Timeout /*timeout*/) override {
    return Motion({false, opening, speed, force});
  }
  GripperStatus Open(Timeout timeout) override { return MoveTo(0.085, 0.15, 20.0, timeout); }
  GripperStatus Close(double speed, double force, Timeout /*timeout*/) override {
    return Motion({true, 0.0, speed, force});
  }
  GripperStatus Status(Timeout /*timeout*/) override {
    std::lock_guard lock(mutex_);
    ++status_reads_;
    if (status_error_ == 1) throw DeviceTimeout("scripted gripper: no answer");
    if (status_error_ == 2) throw DeviceFault("scripted gripper: link down");
    return Current();
  }

  void SetObjectWidth(std::optional<double> width) {
    std::lock_guard lock(mutex_);
    object_width_ = width;
  }
  /// What a slip does: the object is gone, the fingers stay.
  void DropObject() {
    std::lock_guard lock(mutex_);
    object_ = GripperObject::kAtPosition;
  }
  void FailNextMotion() {
    std::lock_guard lock(mutex_);
    fail_next_motion_ = true;
  }
  /// 0 = answer, 1 = DeviceTimeout, 2 = DeviceFault from Status.
  void SetStatusError(int error) {
    std::lock_guard lock(mutex_);
    status_error_ = error;
  }
  std::vector<MotionCall> motions() const {
    std::lock_guard lock(mutex_);
    return motions_;
  }
  int activations() const {
    std::lock_guard lock(mutex_);
    return activations_;
  }
  int status_reads() const {
    std::lock_guard lock(mutex_);
    return status_reads_;
  }

  /// Activate and motions wait at these while the test keeps them closed.
  Gate activation_gate;
  Gate motion_gate;

 private:
  GripperStatus Motion(const MotionCall& call) {
    {
      std::lock_guard lock(mutex_);
      motions_.push_back(call);
      if (!activated_) throw DeviceFault("scripted gripper: not activated");
      if (fail_next_motion_) {
        fail_next_motion_ = false;
        throw DeviceFault("scripted gripper: finger motor stalled");
      }
    }
    motion_gate.Pass();
    std::lock_guard lock(mutex_);
    const double target = call.opening;
    if (object_width_ && target < *object_width_ && *object_width_ <= opening_) {
      opening_ = *object_width_;
      object_ = GripperObject::kStoppedClosing;
    } else {
      opening_ = target;
      object_ = GripperObject::kAtPosition;
    }
    return Current();
  }
  GripperStatus Current() const {
    GripperStatus status;
    status.activated = activated_;
    status.object = object_;
    status.opening = opening_;
    return status;
  }

  mutable std::mutex mutex_;
  bool activated_ = false;
  double opening_ = 0.085;
  GripperObject object_ = GripperObject::kAtPosition;
  std::optional<double> object_width_;
  bool fail_next_motion_ = false;
  int status_error_ = 0;
  std::vector<MotionCall> motions_;
  int activations_ = 0;
  int status_reads_ = 0;
};

/// A sensor that reads what the test set, or fails as told.
class ScriptedSensor final : public ForceTorqueSensor {
 public:
  enum class Mode { kAnswer, kTimeout, kFault };

  WrenchReading Read(Timeout /*timeout*/) override {
    std::this_thread::sleep_for(read_time.load());
    std::lock_guard lock(mutex_);
    ++reads_;
    if (mode_ == Mode::kTimeout) throw DeviceTimeout("scripted sensor: no answer");
    if (mode_ == Mode::kFault) throw DeviceFault("scripted sensor: gauge broken");
    WrenchReading reading = reading_;
    if (reading.sequence != 0) reading.sequence += static_cast<std::uint64_t>(reads_);
    return reading;
  }
  void Bias(Timeout /*timeout*/) override {
    std::lock_guard lock(mutex_);
    ++biases_;
  }

  /// Every read returns `reading`; a non-zero sequence grows by one per read from it.
  void Set(const WrenchReading& reading) {
    std::lock_guard lock(mutex_);
    reading_ = reading;
  }
  void SetMode(Mode mode) {
    std::lock_guard lock(mutex_);
    mode_ = mode;
  }
  int reads() const {
    std::lock_guard lock(mutex_);
    return reads_;
  }
  int biases() const {
    std::lock_guard lock(mutex_);
    return biases_;
  }

  std::atomic<std::chrono::milliseconds> read_time{std::chrono::milliseconds(0)};

 private:
  mutable std::mutex mutex_;
  WrenchReading reading_;
  Mode mode_ = Mode::kAnswer;
  int reads_ = 0;
  int biases_ = 0;
};

}  // namespace tubepick::devices::scripted
