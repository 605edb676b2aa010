#include "devices/testing/robotiq_fake.h"

#include <fcntl.h>
#include <modbus/modbus.h>
#include <stdlib.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "devices/robotiq_2f85.h"

namespace tubepick::devices {

RobotiqFake::RobotiqFake() : RobotiqFake(Options{}) {}

RobotiqFake::RobotiqFake(Options options) : options_(options) {
  master_fd_ = posix_openpt(O_RDWR | O_NOCTTY);
  if (master_fd_ < 0 || grantpt(master_fd_) != 0 || unlockpt(master_fd_) != 0) {
    throw std::runtime_error(std::string("RobotiqFake: pty: ") + std::strerror(errno));
  }
  char name[128];
  if (ptsname_r(master_fd_, name, sizeof name) != 0) {
    throw std::runtime_error(std::string("RobotiqFake: ptsname: ") + std::strerror(errno));
  }
  slave_path_ = name;
  // Keep the slave open so the master never sees EIO (hang-up) between driver connections,
  // and put the line in raw mode before the driver configures it too.
  slave_keepalive_fd_ = ::open(name, O_RDWR | O_NOCTTY);
  if (slave_keepalive_fd_ >= 0) {
    termios tio{};
    if (tcgetattr(slave_keepalive_fd_, &tio) == 0) {
      cfmakeraw(&tio);
      tcsetattr(slave_keepalive_fd_, TCSANOW, &tio);
    }
  }
  // The RTU backend only needs a file descriptor: the path is never opened (no modbus_connect);
  // the server reads and writes the pty master directly.
  ctx_ = modbus_new_rtu(name, 115200, 'N', 8, 1);
  map_ = modbus_mapping_new_start_address(0, 0, 0, 0, robotiq::kOutputAddress, robotiq::kRegisterCount,
                                          robotiq::kInputAddress, robotiq::kRegisterCount);
  if (ctx_ == nullptr || map_ == nullptr)
    throw std::runtime_error("RobotiqFake: libmodbus allocation failed");
  modbus_set_slave(ctx_, options_.slave_id);
  modbus_set_socket(ctx_, master_fd_);
  modbus_set_indication_timeout(ctx_, 0, 10000);  // wake every 10 ms to simulate and check stop_
  {
    std::lock_guard lock(mutex_);
    Step(0.0);
  }
  thread_ = std::thread([this] { Run(); });
}

RobotiqFake::~RobotiqFake() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (map_ != nullptr) modbus_mapping_free(map_);
  if (ctx_ != nullptr) modbus_free(ctx_);  // not modbus_close: we own the fds
  if (slave_keepalive_fd_ >= 0) ::close(slave_keepalive_fd_);
  if (master_fd_ >= 0) ::close(master_fd_);
}

void RobotiqFake::SetObjectWidth(std::optional<double> metres) {
  std::lock_guard lock(mutex_);
  object_width_ = metres;
}

void RobotiqFake::SetFault(std::uint8_t code) {
  std::lock_guard lock(mutex_);
  fault_ = code;
  Step(0.0);
}

void RobotiqFake::SetMute(bool mute) {
  std::lock_guard lock(mutex_);
  mute_ = mute;
}

void RobotiqFake::DropNext(int count) {
  std::lock_guard lock(mutex_);
  drop_ = count;
}

void RobotiqFake::AnswerNextWritesWithARead(int count) {
  std::lock_guard lock(mutex_);
  writes_answered_with_a_read_ = count;
}

double RobotiqFake::position() const {
  std::lock_guard lock(mutex_);
  return pos_;
}

void RobotiqFake::Run() {
  std::uint8_t req[MODBUS_RTU_MAX_ADU_LENGTH];
  auto last = std::chrono::steady_clock::now();
  while (!stop_) {
    const int rc = modbus_receive(ctx_, req);
    const auto now = std::chrono::steady_clock::now();
    std::lock_guard lock(mutex_);
    Step(std::chrono::duration<double>(now - last).count());
    last = now;
    if (rc <= 0) continue;  // timeout, bad frame, or another slave's request
    if (mute_) continue;
    if (drop_ > 0) {
      --drop_;
      continue;
    }
    if (req[1] == MODBUS_FC_WRITE_MULTIPLE_REGISTERS && writes_answered_with_a_read_ > 0) {
      --writes_answered_with_a_read_;
      req[1] = MODBUS_FC_READ_HOLDING_REGISTERS;  // same address and count fields: a read's reply
      modbus_reply(ctx_, req, rc, map_);
      continue;
    }
    const int function = req[1];
    if (modbus_reply(ctx_, req, rc, map_) > 0) served_++;
    if (function == MODBUS_FC_WRITE_MULTIPLE_REGISTERS || function == MODBUS_FC_WRITE_SINGLE_REGISTER) {
      OnWrite();
      Step(0.0);
    }
  }
}

void RobotiqFake::OnWrite() {
  const std::uint16_t* r = map_->tab_registers;
  action_ = static_cast<std::uint8_t>(r[0] >> 8);
  rpr_ = static_cast<std::uint8_t>(r[1] & 0xFF);
  rsp_ = static_cast<std::uint8_t>(r[2] >> 8);
  rfr_ = static_cast<std::uint8_t>(r[2] & 0xFF);
  if ((action_ & robotiq::kRact) == 0) {
    activated_ = false;
    activating_ = false;
    fault_ = 0;  // reset clears faults
    moving_ = false;
    return;
  }
  if (!activated_ && !activating_) {
    activating_ = true;
    activation_start_ = std::chrono::steady_clock::now();
  }
  if (activated_ && (action_ & robotiq::kRgto) != 0) {
    moving_ = true;
    gobj_ = 0;
  }
}

void RobotiqFake::Step(double dt_s) {
  if (activating_ && std::chrono::steady_clock::now() - activation_start_ >= options_.activation_time) {
    activating_ = false;
    activated_ = true;
    pos_ = 0.0;  // activation ends fully open
    gobj_ = 3;
  }
  if (activated_ && moving_ && fault_ == 0) {
    const double speed_pos_per_s = robotiq::ByteToSpeed(rsp_) / robotiq::kStroke * 255.0;
    const double step = speed_pos_per_s * dt_s * options_.time_scale;
    const double target = rpr_;
    const bool closing = target > pos_;
    double next = closing ? std::min(target, pos_ + step) : std::max(target, pos_ - step);
    if (closing && object_width_) {
      const double contact = (robotiq::kStroke - *object_width_) / robotiq::kStroke * 255.0;
      if (pos_ <= contact && next >= contact) {
        pos_ = contact;
        moving_ = false;
        gobj_ = 2;
      }
    }
    if (moving_) {
      pos_ = next;
      if (pos_ == target) {
        moving_ = false;
        gobj_ = 3;
      }
    }
  }
  robotiq::InputState s;
  s.gact = activated_ || activating_;
  s.ggto = (action_ & robotiq::kRgto) != 0;
  s.gsta = activated_ ? 3 : (activating_ ? 1 : 0);
  s.gobj = activated_ ? gobj_ : 0;
  s.gflt = fault_;
  s.position_echo = rpr_;
  s.position = static_cast<std::uint8_t>(std::clamp(std::lround(pos_), 0L, 255L));
  s.current = moving_ ? static_cast<std::uint8_t>(rfr_ / 4) : 0;
  const auto regs = robotiq::EncodeInput(s);
  std::copy(regs.begin(), regs.end(), map_->tab_input_registers);
}

}  // namespace tubepick::devices
