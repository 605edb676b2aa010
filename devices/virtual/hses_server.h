#pragma once

#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Geometry>

#include "devices/robot.h"
#include "devices/virtual/udp_server.h"
#include "devices/yaskawa_hses.h"

namespace tubepick::devices {

struct HsesServerOptions {
  /// Address to bind: an IPv4 address or a name that resolves to one.
  std::string host = "127.0.0.1";
  /// UDP port; 0 = an ephemeral port (HsesServer::port() tells which). A YRC1000 listens on 10040.
  std::uint16_t port = 0;
  /// The bin frame in the robot base frame: the driver's YaskawaHsesParams::X_BaseBin. The wire
  /// carries base-frame poses, the Robot interface takes bin-frame ones.
  Eigen::Isometry3d X_BaseBin = Eigen::Isometry3d::Identity();
  /// The tool file number whose TCP the Robot moves (the driver's YaskawaHsesParams::tool); moves
  /// naming another tool are refused.
  int tool = 0;
  /// User frames moves may be given in (coordinate 18): number (1..63) → X_BaseUser, the driver's
  /// YaskawaHsesParams::X_BaseUser. Moves in another user frame are refused.
  std::map<int, Eigen::Isometry3d> user_frames;
  /// Timeout of one Robot::MoveTo (a straight move).
  Timeout move_timeout{std::chrono::seconds(60)};
  /// Timeout of the other robot calls (CurrentPose, ServoOn).
  Timeout call_timeout{std::chrono::seconds(5)};
  /// How long a position read waits for the device lock (another device's call may hold it) before
  /// it answers the last known pose instead.
  Timeout lock_wait{50};
};

/// Serves a Robot through the Yaskawa YRC1000 High Speed Ethernet Server protocol (UDP), as the
/// YaskawaHses driver speaks it, so the driver can drive any Robot (e.g. the simulated cell's).
///
/// Answers (request id echoed, service | 0x80, block number 0x80000000):
/// - 0x72 status read (instance 1; get all → data 1 and 2, get single attribute 1|2 → one word):
///   data 1 = play | command remote | continuous, plus running while a move runs; data 2 = servo on,
///   alarm after a robot fault.
/// - 0x75 position read (instance 101, robot 1 base cartesian; 13 words): the robot's CurrentPose
///   (bin frame) in base coordinates; while a move runs, the last known pose (no device call).
/// - 0x83 servo (instance 2, attribute 1, set single, 1 on / 2 off): on clears an alarm (like an
///   operator's reset) and calls Robot::ServoOn; off only stops the server from accepting moves
///   (the Robot interface has no servo off).
/// - 0x8A straight absolute move (instance 2, attribute 1, set all, 26 words: robot 1, speed class V
///   (0.1 mm/s) > 0, base coordinates or a configured user frame, the configured tool): answered at
///   once; Robot::MoveTo runs on a worker thread. A DeviceFault or DeviceTimeout from it sets the
///   alarm bit and servo off.
/// Rejections as a YRC1000 gives them: status 0x08 (command not defined, no added status) for
/// other commands; status 0x1F with added status 0x1010 (service), 0xA001 (instance), 0xA002
/// (attribute), 0xB003 (data size), 0xB004 (data value), 0xB008 (robot number), 0xB009 (speed),
/// 0xB00B (coordinate), 0xB00D (tool number), 0xB00E (user frame number),
/// 0x2010 (a move runs), 0x2060 (alarm), 0x2070 (servo
/// off), 0x3450 (servo on refused by the robot). A DeviceTimeout of CurrentPose or ServoOn is no
/// answer (the driver times out, as with a real controller that does not answer).
///
/// Every Robot call holds `device_lock` (shared with the other servers of one device set). One
/// receive thread and one move worker; the destructor stops both, waiting for a running MoveTo.
class HsesServer {
 public:
  /// @throws InvalidArgument when options.host does not resolve; std::runtime_error when the
  /// socket cannot be bound.
  HsesServer(Robot& robot, std::mutex& device_lock, HsesServerOptions options = {});
  ~HsesServer();
  HsesServer(const HsesServer&) = delete;
  HsesServer& operator=(const HsesServer&) = delete;

  const std::string& host() const { return udp_.host(); }
  std::uint16_t port() const { return udp_.port(); }

  /// The active alarm's text (the robot's error message), empty when none.
  std::string alarm() const;
  bool servo_on() const;
  /// A move runs on the worker.
  bool moving() const;

 private:
  struct Move {
    Eigen::Isometry3d X_BinTcp;
    double speed = 0.0;
  };

  std::vector<UdpServer::Datagram> Serve(std::span<const std::uint8_t> datagram, const UdpPeer& from);
  /// nullopt = no answer.
  std::optional<hses::Answer> Handle(const hses::Request& request);
  hses::Answer StatusRead(const hses::Request& request);
  std::optional<hses::Answer> PositionRead(const hses::Request& request);
  std::optional<hses::Answer> Servo(const hses::Request& request);
  hses::Answer StartMove(const hses::Request& request);
  void RunMoves();

  Robot& robot_;
  std::mutex& device_lock_;
  HsesServerOptions options_;

  mutable std::mutex mutex_;  // the state below; never held while waiting for device_lock_
  std::condition_variable wake_;
  bool servo_on_ = false;
  bool alarm_ = false;
  std::string alarm_text_;
  bool moving_ = false;
  std::optional<Move> next_move_;
  std::optional<Eigen::Isometry3d> last_X_BinTcp_;
  bool stop_ = false;

  std::thread worker_;
  UdpServer udp_;  // last: its thread starts once the state above exists
};

}  // namespace tubepick::devices
