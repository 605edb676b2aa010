#pragma once

#include <array>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "devices/gripper.h"
#include "devices/robotiq_2f85.h"

struct _modbus;
struct _modbus_mapping_t;

namespace tubepick::devices {

struct RobotiqRtuServerOptions {
  /// Modbus slave id the server answers (the driver's Robotiq2F85Params::slave_id).
  int slave_id = robotiq::kDefaultSlaveId;
  /// Timeouts of Gripper::Activate, of one motion (MoveTo, Close) and of Gripper::Status.
  Timeout activate_timeout{std::chrono::seconds(10)};
  Timeout motion_timeout{std::chrono::seconds(30)};
  Timeout call_timeout{1000};
  /// How long a status read waits for the device lock (another device's call may hold it) to
  /// refresh from Gripper::Status before it answers the last known state instead.
  Timeout lock_wait{50};
  /// A requested position rPR at or above this closes (Gripper::Close: until contact or fully
  /// closed) rather than moving to an opening; 250 ≈ 1.7 mm. The driver's Close sends 255.
  std::uint8_t close_position = 250;
};

/// Serves a Gripper as a Robotiq 2F-85 on Modbus RTU, as the Robotiq2F85 driver speaks it: a
/// libmodbus RTU slave on the master side of a pseudo-terminal; the driver opens device_path()
/// (the slave side) as it would a USB-RS485 adapter. The server keeps the slave side open too, so
/// the terminal does not hang up between driver connections.
///
/// - FC16 writes of the 3 output registers at 0x03E8 (ACTION REQUEST, rPR, rSP, rFR; FC06 and FC23
///   writes too): rACT 0 resets (gSTA 0, faults cleared); rACT 0 → 1 runs Gripper::Activate on the
///   worker (gSTA 1, then 3); every write with rACT and rGTO starts a motion on the worker:
///   Gripper::Close(speed, force) for rPR ≥ close_position, else Gripper::MoveTo(opening, speed,
///   force), with robotiq:: conversions. While it runs: gOBJ 0, echo = rPR; then gOBJ and gPO from
///   the returned GripperStatus. A motion asked for during activation runs after it.
/// - FC04 reads of the 3 input registers at 0x07D0: the state; when nothing runs, refreshed from
///   Gripper::Status first (a tube that slipped out reads gOBJ 3, not a stale 2; the gripper's own
///   fault code is reported in gFLT). A DeviceTimeout of Status is no answer, a DeviceFault the
///   Modbus exception "server device failure".
/// - A DeviceFault of Activate latches gFLT 0x0D (activation fault), of a motion gFLT 0x0E
///   (overcurrent triggered), until rACT is cleared; no motion starts while it is latched. A
///   DeviceTimeout leaves gSTA 1 or gOBJ 0 (the driver times out, as with a stuck gripper).
/// Other addresses get the Modbus exception "illegal data address".
///
/// Every Gripper call holds `device_lock`. One thread on the terminal and one worker for
/// Activate and motions; the destructor stops both, waiting for a running gripper call.
class RobotiqRtuServer {
 public:
  /// gFLT latched by a DeviceFault of Activate and of a motion.
  static constexpr std::uint8_t kActivationFault = 0x0D;
  static constexpr std::uint8_t kMotionFault = 0x0E;

  /// Opens the pseudo-terminal. @throws std::runtime_error when it cannot be opened.
  RobotiqRtuServer(Gripper& gripper, std::mutex& device_lock, RobotiqRtuServerOptions options = {});
  ~RobotiqRtuServer();
  RobotiqRtuServer(const RobotiqRtuServer&) = delete;
  RobotiqRtuServer& operator=(const RobotiqRtuServer&) = delete;

  /// The pseudo-terminal the driver opens (Robotiq2F85Params::device).
  const std::string& device_path() const { return slave_path_; }
  /// The text of the gripper error that latched gFLT, empty when none.
  std::string fault() const;

 private:
  enum class Activation { kReset, kActivating, kActive };
  struct Job {
    bool activate = false;
    std::uint64_t epoch = 0;   // resets (rACT 0) so far: a job of an earlier epoch is void
    std::uint64_t motion = 0;  // motions so far: a motion superseded by a newer one is void
    std::uint8_t position = 0, speed = 0, force = 0;
  };

  void Serve();
  void OnRequest(const std::uint8_t* request, int length);
  void OnWrite(const std::array<std::uint16_t, robotiq::kRegisterCount>& registers);
  /// Refreshes the state from Gripper::Status when nothing runs; false = no answer (DeviceTimeout),
  /// throws DeviceFault for an exception answer.
  bool Refresh();
  std::array<std::uint16_t, robotiq::kRegisterCount> InputRegisters() const;
  void RunJobs();
  void RunJob(const Job& job);
  /// Gripper::Status for the state after a failed call; nullopt when it fails too. device_lock_ held.
  std::optional<GripperStatus> StatusAfterFault();
  void Apply(const GripperStatus& status);

  Gripper& gripper_;
  std::mutex& device_lock_;
  RobotiqRtuServerOptions options_;
  int master_fd_ = -1;
  int slave_keepalive_fd_ = -1;
  int wake_[2] = {-1, -1};
  std::string slave_path_;
  _modbus* ctx_ = nullptr;
  _modbus_mapping_t* map_ = nullptr;  // only the server thread touches it

  mutable std::mutex mutex_;  // the state below; never held while waiting for device_lock_
  std::condition_variable wake_worker_;
  std::uint8_t action_ = 0, rpr_ = 0, rsp_ = 0, rfr_ = 0;
  Activation activation_ = Activation::kReset;
  bool motion_running_ = false;
  std::uint8_t gobj_ = 3;
  std::uint8_t gpo_ = 0;
  std::uint8_t fault_ = 0;         // latched by a DeviceFault
  std::uint8_t device_fault_ = 0;  // the gripper's own GripperStatus::fault
  std::string fault_text_;
  std::uint64_t epoch_ = 0;
  std::uint64_t motions_ = 0;
  std::deque<Job> jobs_;
  bool stop_ = false;

  std::thread worker_;
  std::thread thread_;
};

}  // namespace tubepick::devices
