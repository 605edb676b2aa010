#include "devices/robotiq_2f85.h"

#include <modbus/modbus.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <thread>
#include <utility>

namespace tubepick::devices {
namespace robotiq {
namespace {

std::uint8_t LinearToByte(double v, double lo, double hi) {
  if (!std::isfinite(v)) v = lo;
  const double c = std::clamp(v, lo, hi);
  return static_cast<std::uint8_t>(std::lround((c - lo) / (hi - lo) * 255.0));
}

}  // namespace

std::uint8_t OpeningToPosition(double opening) {
  if (!std::isfinite(opening)) opening = kStroke;
  const double c = std::clamp(opening, 0.0, kStroke);
  return static_cast<std::uint8_t>(std::lround((kStroke - c) / kStroke * 255.0));
}

double PositionToOpening(std::uint8_t position) { return kStroke * (255.0 - position) / 255.0; }

std::uint8_t SpeedToByte(double speed) { return LinearToByte(speed, kMinSpeed, kMaxSpeed); }
double ByteToSpeed(std::uint8_t b) { return kMinSpeed + (kMaxSpeed - kMinSpeed) * b / 255.0; }
std::uint8_t ForceToByte(double force) { return LinearToByte(force, kMinForce, kMaxForce); }
double ByteToForce(std::uint8_t b) { return kMinForce + (kMaxForce - kMinForce) * b / 255.0; }

std::array<std::uint16_t, kRegisterCount> EncodeRequest(std::uint8_t action, std::uint8_t position,
                                                        std::uint8_t speed, std::uint8_t force) {
  return {static_cast<std::uint16_t>(action << 8), static_cast<std::uint16_t>(position),
          static_cast<std::uint16_t>((speed << 8) | force)};
}

InputState DecodeInput(const std::array<std::uint16_t, kRegisterCount>& regs) {
  InputState s;
  const std::uint8_t status = static_cast<std::uint8_t>(regs[0] >> 8);
  s.gact = (status & 0x01) != 0;
  s.ggto = (status & 0x08) != 0;
  s.gsta = static_cast<std::uint8_t>((status >> 4) & 0x03);
  s.gobj = static_cast<std::uint8_t>((status >> 6) & 0x03);
  s.gflt = static_cast<std::uint8_t>((regs[1] >> 8) & 0x0F);
  s.position_echo = static_cast<std::uint8_t>(regs[1] & 0xFF);
  s.position = static_cast<std::uint8_t>(regs[2] >> 8);
  s.current = static_cast<std::uint8_t>(regs[2] & 0xFF);
  return s;
}

std::array<std::uint16_t, kRegisterCount> EncodeInput(const InputState& s) {
  const unsigned status =
      (s.gact ? 0x01u : 0u) | (s.ggto ? 0x08u : 0u) | ((s.gsta & 0x03u) << 4) | ((s.gobj & 0x03u) << 6);
  return {static_cast<std::uint16_t>(status << 8),
          static_cast<std::uint16_t>(((s.gflt & 0x0Fu) << 8) | s.position_echo),
          static_cast<std::uint16_t>((s.position << 8) | s.current)};
}

std::string FaultText(std::uint8_t code) {
  switch (code) {
    case 0x00:
      return "no fault";
    case 0x05:
      return "action delayed: activation (reactivation) must be completed prior to performing the action";
    case 0x07:
      return "the activation bit must be set prior to performing the action";
    case 0x08:
      return "maximum operating temperature exceeded: wait for cool-down";
    case 0x09:
      return "no communication during at least 1 second";
    case 0x0A:
      return "under minimum operating voltage";
    case 0x0B:
      return "automatic release in progress";
    case 0x0C:
      return "internal fault: contact support";
    case 0x0D:
      return "activation fault: verify that no interference or other error occurred";
    case 0x0E:
      return "overcurrent triggered";
    case 0x0F:
      return "automatic release completed";
    default:
      return "unknown fault";
  }
}

}  // namespace robotiq

namespace {

std::string Hex(std::uint8_t code) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", code);
  return buf;
}

}  // namespace

Robotiq2F85::Robotiq2F85(Robotiq2F85Params params) : params_(std::move(params)) {
  ctx_ = modbus_new_rtu(params_.device.c_str(), params_.baud, 'N', 8, 1);
  if (ctx_ == nullptr) {
    throw DeviceFault("Robotiq2F85: cannot create RTU context for " + params_.device + ": " +
                      modbus_strerror(errno));
  }
  const auto us = std::chrono::duration_cast<std::chrono::microseconds>(params_.response_timeout).count();
  if (modbus_set_slave(ctx_, params_.slave_id) != 0 ||
      modbus_set_response_timeout(ctx_, static_cast<std::uint32_t>(us / 1000000),
                                  static_cast<std::uint32_t>(us % 1000000)) != 0 ||
      modbus_connect(ctx_) != 0) {
    const std::string why = modbus_strerror(errno);
    modbus_free(ctx_);
    ctx_ = nullptr;
    throw DeviceFault("Robotiq2F85: cannot open " + params_.device + ": " + why);
  }
}

Robotiq2F85::~Robotiq2F85() {
  if (ctx_ != nullptr) {
    modbus_close(ctx_);
    modbus_free(ctx_);
  }
}

namespace {

// An unanswered request, one answered with a bad CRC (a noisy RS-485 line) or with an answer that
// does not fit it (EMBBADDATA: a late answer to an earlier request that timed out, arriving after
// the flush) is sent again while the call's deadline leaves time for a whole response_timeout; both
// requests are idempotent (a status read, the action request registers written again). Throws when
// out of time.
template <typename Request>
void WithRetries(Request&& request, std::chrono::steady_clock::time_point deadline,
                 std::chrono::milliseconds response_timeout, const std::string& what,
                 const std::string& device) {
  for (int tries = 1;; ++tries) {
    const int err = request();
    if (err == 0) return;
    const bool retriable = err == ETIMEDOUT || err == EMBBADCRC || err == EMBBADDATA;
    if (retriable && std::chrono::steady_clock::now() + response_timeout <= deadline) continue;
    const std::string count = std::to_string(tries) + (tries == 1 ? " try" : " tries");
    if (err == ETIMEDOUT)
      throw DeviceTimeout("Robotiq2F85: no answer to " + what + " on " + device + " (" + count + ")");
    throw DeviceFault("Robotiq2F85: " + what + " failed on " + device + " (" + count +
                      "): " + modbus_strerror(err));
  }
}

}  // namespace

robotiq::InputState Robotiq2F85::ReadInput(std::chrono::steady_clock::time_point deadline) {
  std::array<std::uint16_t, robotiq::kRegisterCount> regs{};
  WithRetries(
      [&] {
        modbus_flush(ctx_);  // drop a late answer to an earlier, timed-out request
        return modbus_read_input_registers(ctx_, robotiq::kInputAddress, robotiq::kRegisterCount,
                                           regs.data()) == robotiq::kRegisterCount
                   ? 0
                   : errno;
      },
      deadline, params_.response_timeout, "status read", params_.device);
  return robotiq::DecodeInput(regs);
}

void Robotiq2F85::WriteOutput(const std::array<std::uint16_t, robotiq::kRegisterCount>& regs,
                              std::chrono::steady_clock::time_point deadline) {
  WithRetries(
      [&] {
        modbus_flush(ctx_);
        return modbus_write_registers(ctx_, robotiq::kOutputAddress, robotiq::kRegisterCount, regs.data()) ==
                       robotiq::kRegisterCount
                   ? 0
                   : errno;
      },
      deadline, params_.response_timeout, "request write", params_.device);
}

GripperStatus Robotiq2F85::ToStatus(const robotiq::InputState& s) {
  GripperStatus st;
  st.activated = s.gact && s.gsta == 3;
  switch (s.gobj) {
    case 0:
      st.object = GripperObject::kMoving;
      break;
    case 1:
      st.object = GripperObject::kStoppedOpening;
      break;
    case 2:
      st.object = GripperObject::kStoppedClosing;
      break;
    default:
      st.object = GripperObject::kAtPosition;
      break;
  }
  st.opening = robotiq::PositionToOpening(s.position);
  st.fault = s.gflt;
  st.fault_text = robotiq::FaultText(s.gflt);
  return st;
}

void Robotiq2F85::ThrowIfFault(const robotiq::InputState& s) {
  if (s.gflt != 0) {
    throw DeviceFault("Robotiq2F85: gripper fault " + Hex(s.gflt) + ": " + robotiq::FaultText(s.gflt));
  }
}

void Robotiq2F85::Activate(Timeout timeout) {
  std::lock_guard lock(mutex_);
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  WriteOutput(robotiq::EncodeRequest(0, 0, 0, 0), deadline);  // clear rACT: resets faults
  WriteOutput(robotiq::EncodeRequest(robotiq::kRact, 0, 0, 0), deadline);
  for (;;) {
    const auto s = ReadInput(deadline);
    ThrowIfFault(s);
    if (s.gsta == 3) return;
    if (std::chrono::steady_clock::now() >= deadline) {
      throw DeviceTimeout("Robotiq2F85: activation not complete after " + std::to_string(timeout.count()) +
                          " ms (gSTA=" + std::to_string(s.gsta) + ")");
    }
    std::this_thread::sleep_for(params_.poll_period);
  }
}

GripperStatus Robotiq2F85::MoveTo(double opening, double speed, double force, Timeout timeout) {
  std::lock_guard lock(mutex_);
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  const std::uint8_t pos = robotiq::OpeningToPosition(opening);
  WriteOutput(robotiq::EncodeRequest(robotiq::kRact | robotiq::kRgto, pos, robotiq::SpeedToByte(speed),
                                     robotiq::ForceToByte(force)),
              deadline);
  for (;;) {
    const auto s = ReadInput(deadline);
    ThrowIfFault(s);
    // The echo tells us the status belongs to this request, not the previous one.
    if (s.position_echo == pos && s.ggto && s.gobj != 0) return ToStatus(s);
    if (std::chrono::steady_clock::now() >= deadline) {
      throw DeviceTimeout("Robotiq2F85: motion to position " + std::to_string(pos) + " not finished after " +
                          std::to_string(timeout.count()) + " ms (gPO=" + std::to_string(s.position) + ")");
    }
    std::this_thread::sleep_for(params_.poll_period);
  }
}

GripperStatus Robotiq2F85::Open(Timeout timeout) {
  return MoveTo(robotiq::kStroke, robotiq::kMaxSpeed, robotiq::kMinForce, timeout);
}

GripperStatus Robotiq2F85::Close(double speed, double force, Timeout timeout) {
  return MoveTo(0.0, speed, force, timeout);
}

GripperStatus Robotiq2F85::Status(Timeout timeout) {
  std::lock_guard lock(mutex_);
  // A fault is reported in the status (fault, fault_text), not thrown: this is how callers inspect it.
  return ToStatus(ReadInput(std::chrono::steady_clock::now() + timeout));
}

}  // namespace tubepick::devices
