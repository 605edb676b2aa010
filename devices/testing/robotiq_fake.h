#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

struct _modbus;
struct _modbus_mapping_t;

namespace tubepick::devices {

/// A simulated Robotiq 2F-85: a libmodbus RTU server on the master side of a pseudo-terminal.
/// The driver opens `device_path()` (the pty slave) like a USB-RS485 adapter. Simulates
/// activation (gSTA 1 -> 3), finger motion (gPO ramps toward rPR at rSP), object contact while
/// closing (gOBJ = 2 at the scripted object width), arrival (gOBJ = 3) and scripted faults.
class RobotiqFake {
 public:
  struct Options {
    int slave_id = 9;
    std::chrono::milliseconds activation_time{100};
    /// Simulated time runs this many times faster than wall time (finger motion only).
    double time_scale = 4.0;
  };
  RobotiqFake();
  explicit RobotiqFake(Options options);
  ~RobotiqFake();
  RobotiqFake(const RobotiqFake&) = delete;
  RobotiqFake& operator=(const RobotiqFake&) = delete;

  /// Path of the pty slave the driver should open.
  const std::string& device_path() const { return slave_path_; }

  /// An object between the fingers: closing stops there with gOBJ = 2. nullopt = none.
  void SetObjectWidth(std::optional<double> metres);
  /// Report gFLT = code (0 clears); clearing rACT also clears it, as on the real gripper.
  void SetFault(std::uint8_t code);
  /// Stop answering requests (requests are read and dropped).
  void SetMute(bool mute);
  /// Read and drop the next `count` requests (a noisy line losing frames), then answer again.
  void DropNext(int count);
  /// Answer the next `count` register writes with a register read's response, not applying them:
  /// what a late answer to an earlier request looks like to the driver.
  void AnswerNextWritesWithARead(int count);
  /// Current simulated finger position (0 open .. 255 closed).
  double position() const;
  int requests_served() const { return served_.load(); }

 private:
  void Run();
  void Step(double dt_s);  // mutex_ held
  void OnWrite();          // mutex_ held

  Options options_;
  int master_fd_ = -1;
  int slave_keepalive_fd_ = -1;
  std::string slave_path_;
  _modbus* ctx_ = nullptr;
  _modbus_mapping_t* map_ = nullptr;

  mutable std::mutex mutex_;
  std::optional<double> object_width_;
  std::uint8_t fault_ = 0;
  bool mute_ = false;
  int drop_ = 0;
  int writes_answered_with_a_read_ = 0;
  bool activated_ = false;
  bool activating_ = false;
  std::chrono::steady_clock::time_point activation_start_;
  std::uint8_t action_ = 0, rpr_ = 0, rsp_ = 0, rfr_ = 0;
  double pos_ = 0.0;
  std::uint8_t gobj_ = 3;
  bool moving_ = false;

  std::atomic<bool> stop_{false};
  std::atomic<int> served_{0};
  std::thread thread_;
};

}  // namespace tubepick::devices
