#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "devices/robot.h"
#include "devices/udp_client.h"

namespace tubepick::devices {

/// Yaskawa High Speed Ethernet Server (HSES) protocol over UDP: a 32-byte header (8-byte
/// sub-header included) followed by the command data; all integers little-endian
/// (YRC1000 "High Speed Ethernet Server Function Manual").
namespace hses {

inline constexpr std::uint16_t kDefaultPort = 10040;
inline constexpr std::size_t kHeaderSize = 32;
inline constexpr std::uint32_t kAnswerBlockNumber = 0x80000000;

/// Robot-control command numbers used by the driver.
enum class Command : std::uint16_t {
  kStatusRead = 0x72,     // status information (instance 1; attribute 1 = data 1, 2 = data 2)
  kPositionRead = 0x75,   // robot position (instance 1..8 pulse, 101..108 base cartesian)
  kHoldServo = 0x83,      // instance 1 = hold, 2 = servo, 3 = HLOCK; data int32 1 on / 2 off
  kMoveCartesian = 0x8A,  // instance 1 = link abs, 2 = straight abs, 3 = straight increment
};

inline constexpr std::uint8_t kServiceGetAll = 0x01;
inline constexpr std::uint8_t kServiceSetAll = 0x02;
inline constexpr std::uint8_t kServiceGetSingle = 0x0E;
inline constexpr std::uint8_t kServiceSetSingle = 0x10;

inline constexpr std::uint16_t kServoInstance = 2;
inline constexpr std::int32_t kOn = 1;
inline constexpr std::int32_t kOff = 2;
inline constexpr std::uint16_t kStraightAbsolute = 2;
inline constexpr std::uint16_t kBasePositionInstance = 101;  // robot 1, base coordinates
inline constexpr std::int32_t kCoordinateBase = 16;
inline constexpr std::int32_t kCoordinateUser = 18;
inline constexpr std::int32_t kSpeedClassV = 1;  // V: 0.1 mm/s
inline constexpr std::size_t kMoveWords = 26;
inline constexpr std::size_t kPositionWords = 13;

/// Status data 1 / data 2 bits.
inline constexpr std::uint32_t kStatus1Running = 1u << 3;
inline constexpr std::uint32_t kStatus2Alarm = 1u << 4;
inline constexpr std::uint32_t kStatus2Error = 1u << 5;
inline constexpr std::uint32_t kStatus2ServoOn = 1u << 6;

struct Request {
  std::uint8_t request_id = 0;
  std::uint16_t command = 0;
  std::uint16_t instance = 0;
  std::uint8_t attribute = 0;
  std::uint8_t service = 0;
  std::vector<std::uint8_t> data;
};

struct Answer {
  std::uint8_t request_id = 0;
  std::uint8_t service = 0;  // request service | 0x80
  std::uint8_t status = 0;
  std::uint8_t added_status_size = 0;
  std::uint16_t added_status = 0;
  std::vector<std::uint8_t> data;
};

std::vector<std::uint8_t> EncodeRequest(const Request& request);
/// nullopt when the bytes are not a well-formed HSES request.
std::optional<Request> DecodeRequest(std::span<const std::uint8_t> bytes);
std::vector<std::uint8_t> EncodeAnswer(const Answer& answer);
/// nullopt when the bytes are not a well-formed HSES answer.
std::optional<Answer> DecodeAnswer(std::span<const std::uint8_t> bytes);

std::vector<std::uint8_t> EncodeWords(std::span<const std::int32_t> words);
/// Little-endian int32 words; a trailing partial word is ignored.
std::vector<std::int32_t> DecodeWords(std::span<const std::uint8_t> bytes);

/// x, y, z in µm and Rx, Ry, Rz in 0.0001° (fixed-axis XYZ: R = Rz·Ry·Rx), rounded.
std::array<std::int32_t, 6> PoseToWords(const Eigen::Isometry3d& X_BaseTcp);
Eigen::Isometry3d PoseFromWords(std::span<const std::int32_t, 6> words);

/// The frame and tool a move is given in: base coordinates (user_frame 0) or user frame
/// `user_frame` (1..63), with tool file `tool` (0..63).
struct MoveFrame {
  int tool = 0;
  int user_frame = 0;
};

/// The 26 words of a straight move of robot 1 to `X_FrameTcp` (base, or the user frame of `frame`)
/// at `speed` m/s (class V).
std::array<std::int32_t, kMoveWords> MoveData(const Eigen::Isometry3d& X_FrameTcp, double speed,
                                              MoveFrame frame = {});

}  // namespace hses

struct YaskawaHsesParams {
  std::string host = "192.168.255.1";
  std::uint16_t port = hses::kDefaultPort;
  /// The bin frame in the robot base frame.
  Eigen::Isometry3d X_BaseBin = Eigen::Isometry3d::Identity();
  /// Tool file number the TCP is defined by on the controller (0..63).
  int tool = 0;
  /// User frame the moves are given in (1..63, as taught on the pendant), or 0: base coordinates.
  int user_frame = 0;
  /// That user frame in the base frame (used when user_frame > 0; positions are read in base).
  Eigen::Isometry3d X_BaseUser = Eigen::Isometry3d::Identity();
  /// Longest wait for one answer; an unanswered status or position read is sent again within
  /// the call's timeout (UDP may drop a datagram), a move is not.
  Timeout request_timeout{500};
  /// Used when MoveTo/MoveThrough get a non-positive speed, m/s.
  double default_speed = 0.1;
  /// Reach (bin frame), tilt and speed limits of this installation (the controller's own soft
  /// limits are the authority; these let callers skip plans the arm would refuse).
  RobotLimits limits;
  /// Interval between status polls while a move runs.
  Timeout poll_interval{10};
};

/// A Yaskawa YRC1000 (robot 1) driven over HSES. Not thread-safe: one caller at a time.
class YaskawaHses final : public Robot {
 public:
  /// @throws DeviceFault when the host does not resolve or the socket cannot be created.
  explicit YaskawaHses(YaskawaHsesParams params);

  /// Straight move (0x8A), then status polls (0x72) until the running bit clears.
  /// @throws DeviceTimeout, DeviceFault (answer status/added status in hex, alarm/error bit).
  void MoveTo(const Eigen::Isometry3d& X_BinTcp, double speed, Timeout timeout) override;
  /// Successive MoveTo calls from the current pose, sharing one timeout.
  void MoveThrough(const std::vector<Eigen::Vector3d>& waypoints, double speed, Timeout timeout) override;
  Eigen::Isometry3d CurrentPose(Timeout timeout) override;
  void ServoOn(Timeout timeout) override;
  /// Status read (0x72): data 1 running bit, data 2 servo-on, alarm and error bits.
  std::optional<RobotStatus> Status(Timeout timeout) override;
  RobotLimits Limits() const override { return params_.limits; }

  const YaskawaHsesParams& params() const { return params_; }

 private:
  using TimePoint = std::chrono::steady_clock::time_point;
  /// Sends the request and waits for its answer until `deadline`; checks the answer status.
  hses::Answer Transact(hses::Request request, TimePoint deadline, Timeout timeout);
  void MoveUntil(const Eigen::Isometry3d& X_BinTcp, double speed, TimePoint deadline, Timeout timeout);
  Eigen::Isometry3d PoseUntil(TimePoint deadline, Timeout timeout);

  YaskawaHsesParams params_;
  UdpClient udp_;
  std::uint8_t next_request_id_ = 0;
};

}  // namespace tubepick::devices
