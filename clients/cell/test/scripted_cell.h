#pragma once

// Scripted devices and a scripted planner for the cell controller's state-machine tests: hardware
// cannot run in CI, so each fake answers from a queue the test fills and records what it was asked.

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "clients/cell/planner_client.h"
#include "devices/force_torque_sensor.h"
#include "devices/gripper.h"
#include "devices/robot.h"
#include "devices/scanner.h"
#include "wire/proto_convert.h"

namespace tubepick::cell::testing {

/// A failure a fake throws: a timeout or a device fault with a message.
struct Failure {
  bool timeout = false;
  std::string message;
  [[noreturn]] void Throw() const {
    if (timeout) throw devices::DeviceTimeout(message);
    throw devices::DeviceFault(message);
  }
};

class ScriptedScanner final : public devices::Scanner {
 public:
  /// Failures by call index (0-based); other calls return a few points.
  std::vector<std::optional<Failure>> failures;
  /// Calls (0-based) that return no point.
  std::vector<int> empty_at;
  /// Further points every capture holds, bin frame (a tube that stays where it is).
  std::vector<Eigen::Vector3d> points_Bin;
  int calls = 0;

  devices::Capture Scan(devices::Timeout) override {
    const int i = calls++;
    if (i < static_cast<int>(failures.size()) && failures[i]) failures[i]->Throw();
    devices::Capture c;
    if (std::find(empty_at.begin(), empty_at.end(), i) != empty_at.end()) return c;
    c.points_Sensor = {Eigen::Vector3f(0.f, 0.f, 1.f), Eigen::Vector3f(0.01f, 0.f, 1.f)};
    for (const Eigen::Vector3d& p : points_Bin)
      c.points_Sensor.push_back((c.X_BinSensor.inverse() * p).cast<float>());
    return c;
  }
};

/// The robot: follows every command exactly (CurrentPose is the last target) and logs it.
class ScriptedRobot final : public devices::Robot {
 public:
  struct Move {
    bool through = false;  ///< MoveThrough (else MoveTo)
    /// Where the TCP ended up.
    Eigen::Isometry3d X_BinTcpTarget = Eigen::Isometry3d::Identity();
    /// MoveThrough's TCP translations, bin axes.
    std::vector<Eigen::Vector3d> waypoints_Bin;
    double speed = 0.0;
  };
  /// The TCP in the bin frame.
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 1.0));
  std::vector<Move> moves;
  bool servo_on = false;
  /// Fails every MoveThrough from the n-th on (0-based), or every motion when fail_always.
  std::optional<int> fail_through_from;
  bool fail_always = false;
  Failure failure{false, "YRC1000 alarm 4107: out of range (joint T)"};
  /// An alarm on the first MoveTo whose target this returns true for (and every motion after it).
  std::function<bool(const Eigen::Isometry3d&)> alarm_on_move_to;
  int throughs = 0;
  /// Every motion command (and servo on) fails the test: a dry run must not move.
  bool forbid_motion = false;

  void MoveTo(const Eigen::Isometry3d& X_BinTcpTarget, double speed, devices::Timeout) override {
    if (forbid_motion) ADD_FAILURE() << "Robot::MoveTo called";
    if (alarm_on_move_to && alarm_on_move_to(X_BinTcpTarget)) fail_always = true;
    if (fail_always) failure.Throw();
    moves.push_back({false, X_BinTcpTarget, {}, speed});
    X_BinTcp = X_BinTcpTarget;
  }
  devices::RobotLimits limits;
  devices::RobotLimits Limits() const override { return limits; }
  void MoveThrough(const std::vector<Eigen::Vector3d>& waypoints_Bin, double speed,
                   devices::Timeout) override {
    if (forbid_motion) ADD_FAILURE() << "Robot::MoveThrough called";
    const int i = throughs++;
    if (fail_always || (fail_through_from && i >= *fail_through_from)) {
      fail_always = true;  // a robot in alarm refuses every further motion
      failure.Throw();
    }
    Eigen::Isometry3d X_BinTcpTarget = X_BinTcp;
    X_BinTcpTarget.translation() += waypoints_Bin.back();
    moves.push_back({true, X_BinTcpTarget, waypoints_Bin, speed});
    X_BinTcp = X_BinTcpTarget;
  }
  /// A Hold: where, how long, and how many moves came before it.
  struct HoldCall {
    Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();
    double seconds = 0.0;
    std::size_t after_moves = 0;
  };
  std::vector<HoldCall> holds;
  Eigen::Isometry3d CurrentPose(devices::Timeout) override { return X_BinTcp; }
  void ServoOn(devices::Timeout) override {
    if (forbid_motion) ADD_FAILURE() << "Robot::ServoOn called";
    servo_on = true;
  }

  /// Whether some MoveTo / MoveThrough ended at `X_BinTcpVisited` (within 1e-9).
  bool Visited(const Eigen::Isometry3d& X_BinTcpVisited) const {
    for (const Move& m : moves)
      if (m.X_BinTcpTarget.isApprox(X_BinTcpVisited, 1e-9)) return true;
    return false;
  }

 protected:
  void HoldFor(double seconds) override {
    if (forbid_motion) ADD_FAILURE() << "Robot::Hold called";
    if (fail_always) failure.Throw();
    holds.push_back({X_BinTcp, seconds, moves.size()});
  }
};

class ScriptedGripper final : public devices::Gripper {
 public:
  /// What each Close reports, in order; when empty, an object is held.
  std::deque<devices::GripperStatus> close_results;
  /// Open fails with this from the n-th call on (0-based).
  std::optional<int> fail_open_from;
  Failure open_failure{true, "Robotiq 2F-85: no Modbus reply within 10000 ms"};
  int activations = 0, opens = 0, closes = 0, moves = 0, statuses = 0;
  bool open = false;
  /// An object is held: the last Close stopped on one and no Open since.
  bool holding = false;
  /// From the n-th Status call on (0-based), the object is gone (a slip).
  std::optional<int> drop_at_status;
  /// Where the TCP was at every successful Open and Close (set by the test to the robot's pose).
  const Eigen::Isometry3d* tcp = nullptr;
  std::vector<Eigen::Vector3d> opened_at, closed_at;
  std::vector<double> openings;
  /// Every command that moves the fingers (and activation) fails the test: a dry run must not move.
  bool forbid_motion = false;

  void Activate(devices::Timeout) override {
    if (forbid_motion) ADD_FAILURE() << "Gripper::Activate called";
    ++activations;
  }
  devices::GripperStatus MoveTo(double opening, double, double, devices::Timeout) override {
    if (forbid_motion) ADD_FAILURE() << "Gripper::MoveTo called";
    ++moves;
    openings.push_back(opening);
    return Current();
  }
  devices::GripperStatus Open(devices::Timeout) override {
    if (forbid_motion) ADD_FAILURE() << "Gripper::Open called";
    const int i = opens++;
    if (fail_open_from && i >= *fail_open_from) open_failure.Throw();
    open = true;
    holding = false;
    if (tcp) opened_at.push_back(tcp->translation());
    devices::GripperStatus s = Current();
    s.opening = 0.085;
    return s;
  }
  devices::GripperStatus Close(double, double, devices::Timeout) override {
    if (forbid_motion) ADD_FAILURE() << "Gripper::Close called";
    ++closes;
    open = false;
    if (tcp) closed_at.push_back(tcp->translation());
    devices::GripperStatus s;
    s.activated = true;
    s.object = devices::GripperObject::kStoppedClosing;
    s.opening = 0.025;
    if (!close_results.empty()) {
      s = close_results.front();
      close_results.pop_front();
    }
    holding = s.object == devices::GripperObject::kStoppedClosing && s.fault == 0;
    return s;
  }
  devices::GripperStatus Status(devices::Timeout) override {
    const int i = statuses++;
    if (drop_at_status && i >= *drop_at_status) holding = false;
    return Current();
  }
  devices::GripperStatus Current() const {
    devices::GripperStatus s;
    s.activated = activations > 0;
    s.object = holding ? devices::GripperObject::kStoppedClosing : devices::GripperObject::kAtPosition;
    s.opening = holding ? 0.025 : 0.0;
    return s;
  }
};

class ScriptedForceTorque final : public devices::ForceTorqueSensor {
 public:
  /// Readings in order; when they run out, the last one again while the gripper holds (or when
  /// `holding` is not set): the load has not changed. Once the gripper has let go, what is not
  /// scripted follows the gripper (an empty tool reads zero).
  std::deque<devices::WrenchReading> readings;
  devices::WrenchReading last;
  bool queued = false;
  /// Without scripted readings: held_force (N along z_Tcp, down) while *holding, else zero.
  const bool* holding = nullptr;
  double held_force = 0.54;
  /// Reads fail from the n-th call on (0-based).
  std::optional<int> fail_read_from;
  Failure failure{true, "ATI Net F/T: no RDT packet within 2000 ms"};
  /// Reads (0-based) that time out once.
  std::vector<int> fail_once_at;
  /// A heap under the tool: while the gripper holds and the TCP (`tcp`) is at or below this height
  /// (bin z), the held tube rests on it and the load reads as the empty tool's (zero).
  std::optional<double> rests_below_z;
  const Eigen::Isometry3d* tcp = nullptr;
  int biases = 0, reads = 0;

  devices::WrenchReading Read(devices::Timeout) override {
    const int i = reads++;
    if (fail_read_from && i >= *fail_read_from) failure.Throw();
    if (std::find(fail_once_at.begin(), fail_once_at.end(), i) != fail_once_at.end()) failure.Throw();
    if (rests_below_z && tcp && tcp->translation().z() <= *rests_below_z + 1e-9 && holding && *holding)
      return devices::WrenchReading{};
    if (readings.empty()) {
      if (queued && (!holding || *holding)) return last;  // the load has not changed
      devices::WrenchReading r;  // nothing scripted: the load follows what the gripper holds
      if (holding && *holding) r.force.z() = held_force;
      return r;
    }
    queued = true;
    last = readings.front();
    readings.pop_front();
    return last;
  }
  void Bias(devices::Timeout) override { ++biases; }
};

/// Answers from queues; a queued PlannerError is thrown instead of answering.
class ScriptedPlanner final : public PlannerClient {
 public:
  struct PlanAnswer {
    v1::PlanPickResponse response;
    std::optional<PlannerError> error;
  };
  std::deque<PlanAnswer> plan_answers;
  std::deque<v1::AnalyzeWrenchResponse> wrench_answers;
  /// Thrown by every AnalyzeWrench when set (the planner gone).
  std::optional<PlannerError> wrench_error;
  std::vector<v1::PlanPickRequest> plan_requests;
  std::vector<v1::AnalyzeWrenchRequest> wrench_requests;

  /// PlanPick blocks (a long plan) until CancelCalls, then throws CANCELLED.
  bool block_plans = false;
  std::atomic<int> cancels{0};

  v1::PlanPickResponse PlanPick(const v1::PlanPickRequest& request, std::chrono::milliseconds) override {
    plan_requests.push_back(request);
    if (block_plans) {
      std::unique_lock lock(block_mutex_);
      block_cv_.wait(lock, [this] { return cancels.load() > 0; });
      throw PlannerError("PlanPick", grpc::StatusCode::CANCELLED, "cancelled: the run is stopping", 1);
    }
    if (plan_answers.empty()) {  // nothing scripted: the bin is empty
      v1::PlanPickResponse empty;
      empty.set_bin_empty(true);
      return empty;
    }
    PlanAnswer a = plan_answers.front();
    plan_answers.pop_front();
    if (a.error) throw *a.error;
    return a.response;
  }
  void CancelCalls() override {
    std::lock_guard lock(block_mutex_);
    ++cancels;
    block_cv_.notify_all();
  }
  v1::AnalyzeWrenchResponse AnalyzeWrench(const v1::AnalyzeWrenchRequest& request,
                                          std::chrono::milliseconds) override {
    wrench_requests.push_back(request);
    if (wrench_error) throw *wrench_error;
    if (wrench_answers.empty())
      throw PlannerError("AnalyzeWrench", grpc::StatusCode::INTERNAL, "unscripted", 1);
    v1::AnalyzeWrenchResponse a = wrench_answers.front();
    wrench_answers.pop_front();
    return a;
  }

 private:
  std::mutex block_mutex_;
  std::condition_variable block_cv_;
};

/// X_BinTcp: the TCP pointing down (z_Tcp = -z_Bin) at `p_Bin_tcp`.
inline Eigen::Isometry3d DownPose(const Eigen::Vector3d& p_Bin_tcp) {
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();
  X_BinTcp.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  X_BinTcp.translation() = p_Bin_tcp;
  return X_BinTcp;
}

/// The place pose MakePlan gives every plan.
inline Eigen::Isometry3d PlacePose() { return DownPose(Eigen::Vector3d(0.0, 0.8, 0.12)); }

/// A plan for `tube` grasped at `p_Bin_grasp` (DownPose), lifted along `waypoints_Bin` (TCP
/// translations from the grasp pose; default straight up 0.4 m), placed at PlacePose().
inline v1::PickPlan MakePlan(std::uint32_t tube, const Eigen::Vector3d& p_Bin_grasp,
                             v1::TrajectoryKind kind = v1::TRAJECTORY_KIND_UPWARD,
                             std::vector<Eigen::Vector3d> waypoints_Bin = {Eigen::Vector3d::Zero(),
                                                                           Eigen::Vector3d(0, 0, 0.4)}) {
  v1::PickPlan plan;
  plan.set_tube_id(tube);
  *plan.mutable_grasp()->mutable_tcp_pose() = ToProto(DownPose(p_Bin_grasp));
  *plan.mutable_grasp()->mutable_approach() = ToProto(Eigen::Vector3d(0, 0, -1));
  plan.mutable_grasp()->set_opening_width(0.045);
  for (const Eigen::Vector3d& w : waypoints_Bin) *plan.add_waypoints() = ToProto(w);
  plan.set_trajectory_kind(kind);
  plan.mutable_cost()->set_total(0.1 * tube);
  *plan.mutable_place_tcp_pose() = ToProto(PlacePose());
  return plan;
}

/// A PlanPick answer with these plans, `tubes` modeled tubes.
inline ScriptedPlanner::PlanAnswer Plans(std::vector<v1::PickPlan> plans, int tubes, bool simulated = false) {
  ScriptedPlanner::PlanAnswer a;
  for (v1::PickPlan& p : plans) *a.response.add_plans() = p;
  for (int i = 0; i < tubes; ++i) a.response.add_tubes()->set_id(i);
  a.response.set_used_simulation(simulated);
  a.response.set_total_seconds(0.5);
  return a;
}

/// Adds tube `id` to `response`, its axis through `points` (bin frame), one 1 cm cylinder per pair.
inline void AddTubeAxis(v1::PlanPickResponse& response, std::uint32_t id,
                        const std::vector<Eigen::Vector3d>& points) {
  v1::Tube* tube = response.add_tubes();
  tube->set_id(id);
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    v1::Cylinder* c = tube->add_cylinders();
    *c->mutable_start() = ToProto(points[i]);
    *c->mutable_end() = ToProto(points[i + 1]);
    c->set_radius(0.01);
  }
}

inline v1::AnalyzeWrenchResponse Outcome(v1::HeldOutcome outcome, double ratio, int motions = 0) {
  v1::AnalyzeWrenchResponse r;
  r.set_outcome(outcome);
  r.set_tube_ratio(ratio);
  r.set_estimated_count(outcome == v1::HELD_OUTCOME_NONE ? 0 : outcome == v1::HELD_OUTCOME_SINGLE ? 1 : 2);
  for (int m = 0; m < motions; ++m) {
    v1::ResolutionMotion* motion = r.add_resolution_motions();
    motion->set_angle(m == 0 ? M_PI / 4 : -M_PI / 4);
    motion->set_description(m == 0 ? "+45 deg" : "-45 deg");
  }
  return r;
}

}  // namespace tubepick::cell::testing
