#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

#include "devices/device_error.h"
#include "devices/gripper.h"

struct _modbus;  // libmodbus context (modbus_t); kept out of this header.

namespace tubepick::devices {

/// Robotiq 2F-85 register layout and unit conversions (Modbus RTU, Robotiq 2F-85 manual §4).
/// Registers are 16-bit, big-endian: register k holds bytes 2k (high) and 2k+1 (low).
namespace robotiq {

inline constexpr int kDefaultSlaveId = 9;
inline constexpr int kDefaultBaud = 115200;
inline constexpr int kOutputAddress = 0x03E8;  ///< ACTION REQUEST.. FORCE, written with FC16.
inline constexpr int kInputAddress = 0x07D0;   ///< GRIPPER STATUS.. CURRENT, read with FC04.
inline constexpr int kRegisterCount = 3;       ///< 6 bytes.

// ACTION REQUEST bits.
inline constexpr std::uint8_t kRact = 0x01;
inline constexpr std::uint8_t kRgto = 0x08;
inline constexpr std::uint8_t kRatr = 0x10;

/// 2F-85 stroke. Position 0 = fully open (85 mm), 255 = fully closed. The real gripper is not
/// exactly linear (and closes fully around 0xE3 depending on calibration); we use the linear
/// approximation opening = 85 mm * (255 - pos) / 255.
inline constexpr double kStroke = 0.085;
inline constexpr double kMinSpeed = 0.020;  ///< m/s at rSP = 0
inline constexpr double kMaxSpeed = 0.150;  ///< m/s at rSP = 255
inline constexpr double kMinForce = 20.0;   ///< N at rFR = 0
inline constexpr double kMaxForce = 235.0;  ///< N at rFR = 255

/// Opening (m, clamped to [0, kStroke]) -> rPR.
std::uint8_t OpeningToPosition(double opening);
/// gPO / rPR -> opening (m).
double PositionToOpening(std::uint8_t position);
/// Speed (m/s, clamped to [kMinSpeed, kMaxSpeed]) -> rSP, linear.
std::uint8_t SpeedToByte(double speed);
double ByteToSpeed(std::uint8_t b);
/// Force (N, clamped to [kMinForce, kMaxForce]) -> rFR, linear.
std::uint8_t ForceToByte(double force);
double ByteToForce(std::uint8_t b);

/// Output registers for ACTION REQUEST, rPR, rSP, rFR (reserved bytes 0).
std::array<std::uint16_t, kRegisterCount> EncodeRequest(std::uint8_t action, std::uint8_t position,
                                                        std::uint8_t speed, std::uint8_t force);

/// Decoded input registers.
struct InputState {
  bool gact = false;
  bool ggto = false;
  std::uint8_t gsta = 0;  ///< 0 reset, 1 activating, 3 activation complete
  std::uint8_t gobj = 0;  ///< 0 moving, 1 stopped opening, 2 stopped closing, 3 at position
  std::uint8_t gflt = 0;  ///< low nibble of FAULT STATUS
  std::uint8_t position_echo = 0;
  std::uint8_t position = 0;
  std::uint8_t current = 0;
};
InputState DecodeInput(const std::array<std::uint16_t, kRegisterCount>& regs);
std::array<std::uint16_t, kRegisterCount> EncodeInput(const InputState& s);

/// The manual's gFLT table ("0x0E: overcurrent triggered" ...); unknown codes say so.
std::string FaultText(std::uint8_t code);

}  // namespace robotiq

struct Robotiq2F85Params {
  std::string device = "/dev/ttyUSB0";
  int slave_id = robotiq::kDefaultSlaveId;
  int baud = robotiq::kDefaultBaud;  ///< 8N1
  /// Per Modbus request; an unanswered request is sent again while the call's timeout leaves this
  /// much, then DeviceTimeout.
  std::chrono::milliseconds response_timeout{200};
  std::chrono::milliseconds poll_period{10};
};

/// Robotiq 2F-85 over Modbus RTU (libmodbus). Thread-safe (one request at a time).
class Robotiq2F85 final : public Gripper {
 public:
  /// Opens the serial port. @throws DeviceFault if it cannot be opened/configured.
  explicit Robotiq2F85(Robotiq2F85Params params);
  ~Robotiq2F85() override;
  Robotiq2F85(const Robotiq2F85&) = delete;
  Robotiq2F85& operator=(const Robotiq2F85&) = delete;

  /// Clears then sets rACT and waits for gSTA == 3.
  void Activate(Timeout timeout) override;
  /// Writes rGTO|rACT, rPR, rSP, rFR and waits until the echo matches and gOBJ != 0.
  GripperStatus MoveTo(double opening, double speed, double force, Timeout timeout) override;
  GripperStatus Open(Timeout timeout) override;
  GripperStatus Close(double speed, double force, Timeout timeout) override;
  /// One status read; a gripper fault is returned in `fault`/`fault_text`, not thrown.
  GripperStatus Status(Timeout timeout) override;

 private:
  /// One Modbus request each, sent again while unanswered and `deadline` leaves a response_timeout.
  robotiq::InputState ReadInput(std::chrono::steady_clock::time_point deadline);
  void WriteOutput(const std::array<std::uint16_t, robotiq::kRegisterCount>& regs,
                   std::chrono::steady_clock::time_point deadline);
  static GripperStatus ToStatus(const robotiq::InputState& s);
  static void ThrowIfFault(const robotiq::InputState& s);

  Robotiq2F85Params params_;
  std::mutex mutex_;
  _modbus* ctx_ = nullptr;
};

}  // namespace tubepick::devices
