#include "devices/virtual/hses_server.h"

#include <array>
#include <cstdio>
#include <utility>

#include <spdlog/spdlog.h>

#include "devices/virtual/device_lock.h"

namespace tubepick::devices {
namespace {

// Answer status (YRC1000 HSES manual): 0x1F = abnormal with an added status; others carry none.
constexpr std::uint8_t kStatusUndefinedCommand = 0x08;
constexpr std::uint8_t kStatusError = 0x1F;

// Added status codes.
constexpr std::uint16_t kAddedCommandError = 0x1010;
constexpr std::uint16_t kAddedOperating = 0x2010;     // manipulator operating
constexpr std::uint16_t kAddedAlarm = 0x2060;         // error/alarm occurring
constexpr std::uint16_t kAddedServoOff = 0x2070;      // servo OFF
constexpr std::uint16_t kAddedServoRefused = 0x3450;  // servo power cannot be turned ON
constexpr std::uint16_t kAddedInstance = 0xA001;      // instance error
constexpr std::uint16_t kAddedAttribute = 0xA002;     // attribute error
constexpr std::uint16_t kAddedDataSize = 0xB003;      // requiring data size error
constexpr std::uint16_t kAddedDataRange = 0xB004;     // out of range the data
constexpr std::uint16_t kAddedControlGroup = 0xB008;  // control group setting error
constexpr std::uint16_t kAddedSpeed = 0xB009;         // speed setting error
constexpr std::uint16_t kAddedCoordinate = 0xB00B;    // operation coordinate system setting error
constexpr std::uint16_t kAddedToolNumber = 0xB00D;    // tool no. setting error
constexpr std::uint16_t kAddedUserNumber = 0xB00E;    // user no. setting error

// Status data 1 bits besides "running": a robot driven over HSES is in remote play mode.
constexpr std::uint32_t kStatus1Continuous = 1u << 2;
constexpr std::uint32_t kStatus1Play = 1u << 6;
constexpr std::uint32_t kStatus1CommandRemote = 1u << 7;

// Move data word indices (hses::MoveData).
constexpr std::size_t kMoveRobot = 0;
constexpr std::size_t kMoveSpeedClass = 2;
constexpr std::size_t kMoveSpeed = 3;
constexpr std::size_t kMoveCoordinate = 4;
constexpr std::size_t kMovePose = 5;
constexpr std::size_t kMoveTool = 15;
constexpr std::size_t kMoveUserFrame = 16;

// Move coordinates: base, or a user frame (robot and tool coordinates are not emulated).
constexpr std::int32_t kCoordinateBase = 16;
constexpr std::int32_t kCoordinateUser = 18;

std::string Hex(unsigned v, int digits) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*X", digits, v);
  return buf;
}

hses::Answer Ok(const hses::Request& request) {
  hses::Answer answer;
  answer.request_id = request.request_id;
  answer.service = static_cast<std::uint8_t>(request.service | 0x80);
  return answer;
}

hses::Answer Fail(const hses::Request& request, std::uint8_t status, std::uint16_t added) {
  hses::Answer answer = Ok(request);
  answer.status = status;
  answer.added_status_size = added != 0 ? 1 : 0;
  answer.added_status = added;
  if (added != 0) {
    spdlog::warn("HSES server: command {} instance {} rejected: status {}, added status {}",
                 Hex(request.command, 2), request.instance, Hex(status, 2), Hex(added, 4));
  } else {
    spdlog::warn("HSES server: command {} rejected: status {}", Hex(request.command, 2), Hex(status, 2));
  }
  return answer;
}

hses::Answer Error(const hses::Request& request, std::uint16_t added) {
  return Fail(request, kStatusError, added);
}

/// A get-all (all words) or get-single (attribute k = word k, from 1) read of `words`.
template <std::size_t N>
hses::Answer ReadWords(const hses::Request& request, const std::array<std::int32_t, N>& words) {
  hses::Answer answer = Ok(request);
  if (request.service == hses::kServiceGetAll) {
    answer.data = hses::EncodeWords(words);
  } else if (request.service == hses::kServiceGetSingle) {
    if (request.attribute < 1 || request.attribute > N) return Error(request, kAddedAttribute);
    answer.data = hses::EncodeWords(std::span<const std::int32_t>(&words[request.attribute - 1], 1));
  } else {
    return Error(request, kAddedCommandError);
  }
  return answer;
}

}  // namespace

HsesServer::HsesServer(Robot& robot, std::mutex& device_lock, HsesServerOptions options)
    : robot_(robot),
      device_lock_(device_lock),
      options_(std::move(options)),
      udp_("HSES server", options_.host, options_.port,
           [this](std::span<const std::uint8_t> d, const UdpPeer& from) { return Serve(d, from); }) {
  {
    std::lock_guard device(device_lock_);
    try {
      const Eigen::Isometry3d X_BinTcp = robot_.CurrentPose(options_.call_timeout);
      std::lock_guard lock(mutex_);
      last_X_BinTcp_ = X_BinTcp;
    } catch (const std::exception& e) {
      spdlog::warn("HSES server: no initial robot pose: {}", e.what());
    }
  }
  worker_ = std::thread([this] { RunMoves(); });
  spdlog::info("HSES server on {}:{} (UDP)", udp_.host(), udp_.port());
}

HsesServer::~HsesServer() {
  udp_.Stop();
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  worker_.join();
}

std::string HsesServer::alarm() const {
  std::lock_guard lock(mutex_);
  return alarm_ ? alarm_text_ : std::string();
}

bool HsesServer::servo_on() const {
  std::lock_guard lock(mutex_);
  return servo_on_;
}

bool HsesServer::moving() const {
  std::lock_guard lock(mutex_);
  return moving_;
}

std::vector<UdpServer::Datagram> HsesServer::Serve(std::span<const std::uint8_t> datagram,
                                                   const UdpPeer& from) {
  const std::optional<hses::Request> request = hses::DecodeRequest(datagram);
  if (!request) {
    spdlog::debug("HSES server: ignored a malformed datagram of {} bytes from {}", datagram.size(),
                  from.ToString());
    return {};
  }
  const std::optional<hses::Answer> answer = Handle(*request);
  if (!answer) return {};
  return {hses::EncodeAnswer(*answer)};
}

std::optional<hses::Answer> HsesServer::Handle(const hses::Request& request) {
  switch (static_cast<hses::Command>(request.command)) {
    case hses::Command::kStatusRead:
      return StatusRead(request);
    case hses::Command::kPositionRead:
      return PositionRead(request);
    case hses::Command::kHoldServo:
      return Servo(request);
    case hses::Command::kMoveCartesian:
      return StartMove(request);
  }
  return Fail(request, kStatusUndefinedCommand, 0);
}

hses::Answer HsesServer::StatusRead(const hses::Request& request) {
  if (request.instance != 1) return Error(request, kAddedInstance);
  std::array<std::int32_t, 2> data{};
  {
    std::lock_guard lock(mutex_);
    data[0] = static_cast<std::int32_t>(kStatus1Continuous | kStatus1Play | kStatus1CommandRemote |
                                        (moving_ ? hses::kStatus1Running : 0u));
    data[1] = static_cast<std::int32_t>((servo_on_ ? hses::kStatus2ServoOn : 0u) |
                                        (alarm_ ? hses::kStatus2Alarm : 0u));
  }
  return ReadWords(request, data);
}

std::optional<hses::Answer> HsesServer::PositionRead(const hses::Request& request) {
  if (request.instance != hses::kBasePositionInstance) return Error(request, kAddedInstance);
  if (request.service != hses::kServiceGetAll && request.service != hses::kServiceGetSingle) {
    return Error(request, kAddedCommandError);
  }
  std::optional<Eigen::Isometry3d> X_BinTcp;
  bool moving = false;
  {
    std::lock_guard lock(mutex_);
    moving = moving_;
    if (moving) X_BinTcp = last_X_BinTcp_;
  }
  if (moving) {
    // The worker holds the device for the whole move: the last known pose, without waiting.
    if (!X_BinTcp) return Error(request, kAddedOperating);
  } else {
    // Only this thread starts moves, so none starts before this read ends.
    std::unique_lock device = LockWithin(device_lock_, options_.lock_wait);
    if (!device.owns_lock()) {
      {
        std::lock_guard lock(mutex_);
        X_BinTcp = last_X_BinTcp_;
      }
      if (!X_BinTcp) device.lock();
    }
    if (device.owns_lock()) {
      try {
        X_BinTcp = robot_.CurrentPose(options_.call_timeout);
      } catch (const DeviceTimeout& e) {
        spdlog::warn("HSES server: position read unanswered: {}", e.what());
        return std::nullopt;
      } catch (const std::exception& e) {
        spdlog::error("HSES server: position read failed: {}", e.what());
        return Error(request, kAddedAlarm);
      }
      std::lock_guard lock(mutex_);
      last_X_BinTcp_ = X_BinTcp;
    }
  }
  std::array<std::int32_t, hses::kPositionWords> words{};
  words[0] = kCoordinateBase;  // data type; [1] form, [3] user frame, [4] extended form: 0
  words[2] = options_.tool;
  const std::array<std::int32_t, 6> pose = hses::PoseToWords(options_.X_BaseBin * *X_BinTcp);
  std::copy(pose.begin(), pose.end(), words.begin() + 5);
  return ReadWords(request, words);
}

std::optional<hses::Answer> HsesServer::Servo(const hses::Request& request) {
  if (request.instance != hses::kServoInstance) {
    // 1 = hold, 3 = HLOCK: not emulated (the Robot interface cannot hold a move).
    return Error(request, kAddedInstance);
  }
  if (request.attribute != 1) return Error(request, kAddedAttribute);
  if (request.service != hses::kServiceSetSingle) return Error(request, kAddedCommandError);
  const std::vector<std::int32_t> words = hses::DecodeWords(request.data);
  if (words.size() != 1 || request.data.size() != 4) return Error(request, kAddedDataSize);
  if (words[0] != hses::kOn && words[0] != hses::kOff) return Error(request, kAddedDataRange);
  {
    std::lock_guard lock(mutex_);
    if (moving_) {
      // Servo on while moving: it is on. Servo off cannot stop the Robot's move.
      if (words[0] == hses::kOn) return Ok(request);
      return Error(request, kAddedOperating);
    }
    if (words[0] == hses::kOff) {
      servo_on_ = false;
      spdlog::info("HSES server: servo off");
      return Ok(request);
    }
    if (alarm_) {
      spdlog::info("HSES server: servo on resets the alarm \"{}\"", alarm_text_);
      alarm_ = false;
    }
  }
  std::lock_guard device(device_lock_);
  try {
    robot_.ServoOn(options_.call_timeout);
  } catch (const DeviceTimeout& e) {
    spdlog::warn("HSES server: servo on unanswered: {}", e.what());
    return std::nullopt;
  } catch (const std::exception& e) {
    spdlog::error("HSES server: servo on refused: {}", e.what());
    return Error(request, kAddedServoRefused);
  }
  std::lock_guard lock(mutex_);
  servo_on_ = true;
  spdlog::info("HSES server: servo on");
  return Ok(request);
}

hses::Answer HsesServer::StartMove(const hses::Request& request) {
  if (request.instance != hses::kStraightAbsolute) {
    // 1 = link absolute, 3 = straight increment: not emulated (the driver uses neither).
    return Error(request, kAddedInstance);
  }
  if (request.attribute != 1) return Error(request, kAddedAttribute);
  if (request.service != hses::kServiceSetAll) return Error(request, kAddedCommandError);
  const std::vector<std::int32_t> words = hses::DecodeWords(request.data);
  if (words.size() != hses::kMoveWords || request.data.size() != 4 * hses::kMoveWords) {
    return Error(request, kAddedDataSize);
  }
  if (words[kMoveRobot] != 1) return Error(request, kAddedControlGroup);
  if (words[kMoveSpeedClass] != hses::kSpeedClassV || words[kMoveSpeed] <= 0)
    return Error(request, kAddedSpeed);
  const std::int32_t coordinate = words[kMoveCoordinate];
  if (coordinate != kCoordinateBase && coordinate != kCoordinateUser) return Error(request, kAddedCoordinate);
  if (words[kMoveTool] != options_.tool) return Error(request, kAddedToolNumber);
  Eigen::Isometry3d X_BaseFrame = Eigen::Isometry3d::Identity();
  if (coordinate == kCoordinateUser) {
    const auto user = options_.user_frames.find(words[kMoveUserFrame]);
    if (user == options_.user_frames.end()) return Error(request, kAddedUserNumber);
    X_BaseFrame = user->second;
  }

  const Eigen::Isometry3d X_BaseTcp =
      X_BaseFrame * hses::PoseFromWords(std::span<const std::int32_t, 6>(words.data() + kMovePose, 6));
  Move move{options_.X_BaseBin.inverse() * X_BaseTcp, words[kMoveSpeed] * 1e-4};  // 0.1 mm/s -> m/s
  {
    std::lock_guard lock(mutex_);
    if (alarm_) return Error(request, kAddedAlarm);
    if (!servo_on_) return Error(request, kAddedServoOff);
    if (moving_) return Error(request, kAddedOperating);
    // Running from now: the driver's first status poll must see the move.
    moving_ = true;
    next_move_ = std::move(move);
  }
  wake_.notify_all();
  const Eigen::Vector3d p = X_BaseTcp.translation();
  spdlog::info("HSES server: straight move to base ({:.4f}, {:.4f}, {:.4f}) m at {:.4f} m/s", p.x(), p.y(),
               p.z(), words[kMoveSpeed] * 1e-4);
  return Ok(request);
}

void HsesServer::RunMoves() {
  for (;;) {
    Move move;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || next_move_.has_value(); });
      if (stop_) return;
      move = *next_move_;
      next_move_.reset();
    }
    std::optional<std::string> alarm;
    std::optional<Eigen::Isometry3d> X_BinTcp;
    {
      std::lock_guard device(device_lock_);
      try {
        robot_.MoveTo(move.X_BinTcp, move.speed, options_.move_timeout);
      } catch (const std::exception& e) {  // DeviceFault, DeviceTimeout, or anything the robot throws
        alarm = e.what();
      }
      try {
        X_BinTcp = robot_.CurrentPose(options_.call_timeout);
      } catch (const std::exception& e) {
        spdlog::warn("HSES server: no pose after the move: {}", e.what());
      }
    }
    std::lock_guard lock(mutex_);
    if (X_BinTcp) last_X_BinTcp_ = X_BinTcp;
    if (alarm) {
      alarm_ = true;
      alarm_text_ = *alarm;
      servo_on_ = false;
      spdlog::error("HSES server: robot alarm, servo off: {}", *alarm);
    }
    moving_ = false;
  }
}

}  // namespace tubepick::devices
