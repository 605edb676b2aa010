#include "devices/yaskawa_hses.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <thread>
#include <utility>

namespace tubepick::devices {
namespace hses {
namespace {

constexpr std::uint8_t kReserve1 = 3;
constexpr std::uint8_t kDivisionRobot = 1;
constexpr char kMagic[4] = {'Y', 'E', 'R', 'C'};
constexpr char kReserve2[8] = {'9', '9', '9', '9', '9', '9', '9', '9'};

void PutU16(std::uint8_t* out, std::uint16_t v) {
  out[0] = static_cast<std::uint8_t>(v);
  out[1] = static_cast<std::uint8_t>(v >> 8);
}

void PutU32(std::uint8_t* out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) {
    out[i] = static_cast<std::uint8_t>(v >> (8 * i));
  }
}

std::uint16_t GetU16(const std::uint8_t* in) { return static_cast<std::uint16_t>(in[0] | (in[1] << 8)); }

std::uint32_t GetU32(const std::uint8_t* in) {
  return std::uint32_t{in[0]} | (std::uint32_t{in[1]} << 8) | (std::uint32_t{in[2]} << 16) |
         (std::uint32_t{in[3]} << 24);
}

std::vector<std::uint8_t> Header(std::size_t data_size, bool answer, std::uint8_t request_id) {
  std::vector<std::uint8_t> out(kHeaderSize + data_size, 0);
  std::memcpy(out.data(), kMagic, 4);
  PutU16(out.data() + 4, static_cast<std::uint16_t>(kHeaderSize));
  PutU16(out.data() + 6, static_cast<std::uint16_t>(data_size));
  out[8] = kReserve1;
  out[9] = kDivisionRobot;
  out[10] = answer ? 1 : 0;
  out[11] = request_id;
  PutU32(out.data() + 12, answer ? kAnswerBlockNumber : 0);
  std::memcpy(out.data() + 16, kReserve2, 8);
  return out;
}

/// Checks magic, header size and data size; returns whether the ACK byte says "answer".
std::optional<bool> CheckHeader(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kHeaderSize || std::memcmp(bytes.data(), kMagic, 4) != 0 ||
      GetU16(bytes.data() + 4) != kHeaderSize || GetU16(bytes.data() + 6) != bytes.size() - kHeaderSize) {
    return std::nullopt;
  }
  return bytes[10] != 0;
}

std::int32_t Round(double v) { return static_cast<std::int32_t>(std::lround(v)); }

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

}  // namespace

std::vector<std::uint8_t> EncodeRequest(const Request& request) {
  std::vector<std::uint8_t> out = Header(request.data.size(), false, request.request_id);
  PutU16(out.data() + 24, request.command);
  PutU16(out.data() + 26, request.instance);
  out[28] = request.attribute;
  out[29] = request.service;
  std::copy(request.data.begin(), request.data.end(), out.begin() + kHeaderSize);
  return out;
}

std::optional<Request> DecodeRequest(std::span<const std::uint8_t> bytes) {
  const auto answer = CheckHeader(bytes);
  if (!answer || *answer) {
    return std::nullopt;
  }
  Request request;
  request.request_id = bytes[11];
  request.command = GetU16(bytes.data() + 24);
  request.instance = GetU16(bytes.data() + 26);
  request.attribute = bytes[28];
  request.service = bytes[29];
  request.data.assign(bytes.begin() + kHeaderSize, bytes.end());
  return request;
}

std::vector<std::uint8_t> EncodeAnswer(const Answer& answer) {
  std::vector<std::uint8_t> out = Header(answer.data.size(), true, answer.request_id);
  out[24] = answer.service;
  out[25] = answer.status;
  out[26] = answer.added_status_size;
  PutU16(out.data() + 28, answer.added_status);
  std::copy(answer.data.begin(), answer.data.end(), out.begin() + kHeaderSize);
  return out;
}

std::optional<Answer> DecodeAnswer(std::span<const std::uint8_t> bytes) {
  const auto answer_flag = CheckHeader(bytes);
  if (!answer_flag || !*answer_flag) {
    return std::nullopt;
  }
  Answer answer;
  answer.request_id = bytes[11];
  answer.service = bytes[24];
  answer.status = bytes[25];
  answer.added_status_size = bytes[26];
  answer.added_status = GetU16(bytes.data() + 28);
  answer.data.assign(bytes.begin() + kHeaderSize, bytes.end());
  return answer;
}

std::vector<std::uint8_t> EncodeWords(std::span<const std::int32_t> words) {
  std::vector<std::uint8_t> out(4 * words.size());
  for (std::size_t i = 0; i < words.size(); ++i) {
    PutU32(out.data() + 4 * i, static_cast<std::uint32_t>(words[i]));
  }
  return out;
}

std::vector<std::int32_t> DecodeWords(std::span<const std::uint8_t> bytes) {
  std::vector<std::int32_t> out(bytes.size() / 4);
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = static_cast<std::int32_t>(GetU32(bytes.data() + 4 * i));
  }
  return out;
}

std::array<std::int32_t, 6> PoseToWords(const Eigen::Isometry3d& X_BaseTcp) {
  const Eigen::Vector3d p = X_BaseTcp.translation() * 1e6;  // m -> µm
  // R = Rz·Ry·Rx with Ry in [-90°, 90°] and Rx, Rz in [-180°, 180°] (the pendant's ranges).
  const Eigen::Matrix3d R = X_BaseTcp.rotation();
  const double ry = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double rx = std::atan2(R(2, 1), R(2, 2));
  const double rz = std::atan2(R(1, 0), R(0, 0));
  const Eigen::Vector3d zyx = Eigen::Vector3d(rz, ry, rx) * kDegPerRad * 1e4;
  return {Round(p.x()), Round(p.y()), Round(p.z()), Round(zyx[2]), Round(zyx[1]), Round(zyx[0])};
}

Eigen::Isometry3d PoseFromWords(std::span<const std::int32_t, 6> words) {
  const auto angle = [](std::int32_t w) { return w * 1e-4 / kDegPerRad; };
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(words[0], words[1], words[2]) * 1e-6;
  X.linear() = (Eigen::AngleAxisd(angle(words[5]), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(angle(words[4]), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(angle(words[3]), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return X;
}

std::array<std::int32_t, kMoveWords> MoveData(const Eigen::Isometry3d& X_FrameTcp, double speed,
                                              MoveFrame frame) {
  std::array<std::int32_t, kMoveWords> words{};
  words[0] = 1;                                                         // robot number
  words[1] = 0;                                                         // station number
  words[2] = kSpeedClassV;                                              // speed class
  words[3] = Round(speed * 1e4);                                        // m/s -> 0.1 mm/s
  words[4] = frame.user_frame > 0 ? kCoordinateUser : kCoordinateBase;  // coordinate
  const auto pose = PoseToWords(X_FrameTcp);
  std::copy(pose.begin(), pose.end(), words.begin() + 5);
  // [11], [12] reserve; [13] type; [14] expanded type: 0.
  words[15] = frame.tool;
  words[16] = frame.user_frame;
  // [17..19] base axes; [20..25] station axes: all 0.
  return words;
}

}  // namespace hses

namespace {

using Clock = std::chrono::steady_clock;

/// Within the words' rounding and a controller's positioning: 1 mm and 0.01 rad.
bool AtTarget(const Eigen::Isometry3d& X_BinTcp, const Eigen::Isometry3d& X_BinTcpTarget) {
  const double distance = (X_BinTcp.translation() - X_BinTcpTarget.translation()).norm();
  const double angle = Eigen::AngleAxisd(X_BinTcp.linear().transpose() * X_BinTcpTarget.linear()).angle();
  return distance <= 1e-3 && angle <= 1e-2;
}

std::string Hex(unsigned v, int digits) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*X", digits, v);
  return buf;
}

}  // namespace

YaskawaHses::YaskawaHses(YaskawaHsesParams params)
    : params_(std::move(params)), udp_(params_.host, params_.port, "Yaskawa HSES " + params_.host) {}

hses::Answer YaskawaHses::Transact(hses::Request request, TimePoint deadline, Timeout timeout) {
  const std::string who = "Yaskawa HSES " + params_.host + " command " + Hex(request.command, 2);
  std::uint8_t buf[512];
  // Reads change nothing on the controller, so an unanswered one is sent again; a move is not.
  const bool resend = request.command != static_cast<std::uint16_t>(hses::Command::kMoveCartesian) &&
                      request.command != static_cast<std::uint16_t>(hses::Command::kHoldServo);
  TimePoint answer_deadline{};
  auto send = [&] {
    udp_.DrainStale();  // late answers of an earlier, timed-out request must not answer this one
    request.request_id = next_request_id_++;
    udp_.Send(hses::EncodeRequest(request), deadline);
    answer_deadline = std::min(deadline, Clock::now() + params_.request_timeout);
  };
  send();
  for (;;) {
    const std::optional<std::size_t> got = udp_.Receive(buf, answer_deadline);
    if (!got && resend && Clock::now() < deadline) {
      send();
      continue;
    }
    if (!got)
      throw DeviceTimeout(who + ": no answer within " +
                          std::to_string(std::min(timeout, params_.request_timeout).count()) + " ms");
    const auto answer = hses::DecodeAnswer(std::span<const std::uint8_t>(buf, *got));
    if (!answer) {
      throw DeviceFault(who + ": malformed answer of " + std::to_string(*got) + " bytes");
    }
    if (answer->request_id != request.request_id) {
      continue;  // a stale answer
    }
    if (answer->service != (request.service | 0x80)) {
      throw DeviceFault(who + ": answer service " + Hex(answer->service, 2) + ", expected " +
                        Hex(request.service | 0x80u, 2));
    }
    if (answer->status != 0) {
      throw DeviceFault(who + ": status " + Hex(answer->status, 2) + ", added status " +
                        Hex(answer->added_status, 4));
    }
    return *answer;
  }
}

void YaskawaHses::ServoOn(Timeout timeout) {
  hses::Request request;
  request.command = static_cast<std::uint16_t>(hses::Command::kHoldServo);
  request.instance = hses::kServoInstance;
  request.attribute = 1;
  request.service = hses::kServiceSetSingle;
  const std::int32_t on = hses::kOn;
  request.data = hses::EncodeWords(std::span<const std::int32_t>(&on, 1));
  Transact(std::move(request), Clock::now() + timeout, timeout);
}

Eigen::Isometry3d YaskawaHses::PoseUntil(TimePoint deadline, Timeout timeout) {
  hses::Request request;
  request.command = static_cast<std::uint16_t>(hses::Command::kPositionRead);
  request.instance = hses::kBasePositionInstance;
  request.attribute = 0;
  request.service = hses::kServiceGetAll;
  const hses::Answer answer = Transact(std::move(request), deadline, timeout);
  const std::vector<std::int32_t> words = hses::DecodeWords(answer.data);
  if (words.size() < hses::kPositionWords) {
    throw DeviceFault("Yaskawa HSES: position answer of " + std::to_string(answer.data.size()) + " bytes");
  }
  if (words[0] != hses::kCoordinateBase) {
    throw DeviceFault("Yaskawa HSES: position data type " + std::to_string(words[0]) +
                      ", expected base (16)");
  }
  const Eigen::Isometry3d X_BaseTcp =
      hses::PoseFromWords(std::span<const std::int32_t, 6>(words.data() + 5, 6));
  return params_.X_BaseBin.inverse() * X_BaseTcp;
}

std::optional<RobotStatus> YaskawaHses::Status(Timeout timeout) {
  hses::Request request;
  request.command = static_cast<std::uint16_t>(hses::Command::kStatusRead);
  request.instance = 1;
  request.attribute = 0;
  request.service = hses::kServiceGetAll;
  const hses::Answer answer = Transact(std::move(request), Clock::now() + timeout, timeout);
  const std::vector<std::int32_t> data = hses::DecodeWords(answer.data);
  if (data.size() < 2)
    throw DeviceFault("Yaskawa HSES: status answer of " + std::to_string(answer.data.size()) + " bytes");
  const auto data1 = static_cast<std::uint32_t>(data[0]);
  const auto data2 = static_cast<std::uint32_t>(data[1]);
  RobotStatus status;
  status.running = (data1 & hses::kStatus1Running) != 0;
  status.servo_on = (data2 & hses::kStatus2ServoOn) != 0;
  status.alarm = (data2 & hses::kStatus2Alarm) != 0;
  status.error = (data2 & hses::kStatus2Error) != 0;
  status.detail = "data 1 " + Hex(data1, 8) + ", data 2 " + Hex(data2, 8);
  return status;
}

Eigen::Isometry3d YaskawaHses::CurrentPose(Timeout timeout) {
  return PoseUntil(Clock::now() + timeout, timeout);
}

void YaskawaHses::MoveUntil(const Eigen::Isometry3d& X_BinTcp, double speed, TimePoint deadline,
                            Timeout timeout) {
  hses::Request move;
  move.command = static_cast<std::uint16_t>(hses::Command::kMoveCartesian);
  move.instance = hses::kStraightAbsolute;
  move.attribute = 1;
  move.service = hses::kServiceSetAll;
  const Eigen::Isometry3d X_FrameBin =
      params_.user_frame > 0 ? params_.X_BaseUser.inverse() * params_.X_BaseBin : params_.X_BaseBin;
  const auto words = hses::MoveData(X_FrameBin * X_BinTcp, speed > 0.0 ? speed : params_.default_speed,
                                    {params_.tool, params_.user_frame});
  move.data = hses::EncodeWords(words);
  Transact(std::move(move), deadline, timeout);
  // A controller may answer the move before it sets the running bit: the move is over once the bit
  // was seen and cleared, or when the arm stands at the target.
  bool seen_running = false;
  for (;;) {
    hses::Request status;
    status.command = static_cast<std::uint16_t>(hses::Command::kStatusRead);
    status.instance = 1;
    status.attribute = 0;
    status.service = hses::kServiceGetAll;
    // The last status read may overrun the deadline by up to one poll interval, so a move that
    // finishes exactly at the deadline is not reported as a timeout.
    const hses::Answer answer =
        Transact(std::move(status), std::max(deadline, Clock::now() + params_.poll_interval), timeout);
    const std::vector<std::int32_t> data = hses::DecodeWords(answer.data);
    if (data.size() < 2) {
      throw DeviceFault("Yaskawa HSES: status answer of " + std::to_string(answer.data.size()) + " bytes");
    }
    const auto data1 = static_cast<std::uint32_t>(data[0]);
    const auto data2 = static_cast<std::uint32_t>(data[1]);
    if ((data2 & (hses::kStatus2Alarm | hses::kStatus2Error)) != 0) {
      throw DeviceFault("Yaskawa HSES: alarm/error during move (status data 2 " + Hex(data2, 8) + ")");
    }
    if ((data1 & hses::kStatus1Running) != 0) {
      seen_running = true;
    } else if (seen_running || AtTarget(PoseUntil(deadline, timeout), X_BinTcp)) {
      return;  // ran and stopped, or (a short move between two polls) already there
    }
    const auto left = deadline - Clock::now();
    if (left <= Clock::duration::zero()) {
      throw DeviceTimeout(
          seen_running ? "Yaskawa HSES: move still running after " + std::to_string(timeout.count()) + " ms"
                       : "Yaskawa HSES: move accepted but the arm neither ran nor reached the "
                         "target within " +
                             std::to_string(timeout.count()) + " ms");
    }
    std::this_thread::sleep_for(std::min<Clock::duration>(left, params_.poll_interval));
  }
}

void YaskawaHses::MoveTo(const Eigen::Isometry3d& X_BinTcp, double speed, Timeout timeout) {
  MoveUntil(X_BinTcp, speed, Clock::now() + timeout, timeout);
}

void YaskawaHses::MoveThrough(const std::vector<Eigen::Vector3d>& waypoints, double speed, Timeout timeout) {
  const TimePoint deadline = Clock::now() + timeout;
  const Eigen::Isometry3d start = PoseUntil(deadline, timeout);
  for (const Eigen::Vector3d& offset : waypoints) {
    Eigen::Isometry3d target = start;
    target.translation() += offset;
    MoveUntil(target, speed, deadline, timeout);
  }
}

}  // namespace tubepick::devices
