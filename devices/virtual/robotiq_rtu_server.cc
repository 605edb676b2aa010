#include "devices/virtual/robotiq_rtu_server.h"

#include <fcntl.h>
#include <modbus/modbus.h>
#include <poll.h>
#include <stdlib.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

#include <spdlog/spdlog.h>

#include "devices/virtual/device_lock.h"

namespace tubepick::devices {
namespace {

std::uint8_t ObjectCode(GripperObject object) {
  switch (object) {
    case GripperObject::kMoving:
      return 0;
    case GripperObject::kStoppedOpening:
      return 1;
    case GripperObject::kStoppedClosing:
      return 2;
    case GripperObject::kAtPosition:
      return 3;
  }
  return 3;
}

int Register(const std::uint8_t* at) { return (at[0] << 8) | at[1]; }

/// Whether [address, address + count) lies within the `count`-register block at `start`.
bool Within(int address, int count, int start, int size) {
  return count >= 1 && address >= start && address + count <= start + size;
}

}  // namespace

RobotiqRtuServer::RobotiqRtuServer(Gripper& gripper, std::mutex& device_lock, RobotiqRtuServerOptions options)
    : gripper_(gripper), device_lock_(device_lock), options_(std::move(options)) {
  const auto fail = [this](const std::string& what) {
    const std::runtime_error error("RobotiqRtuServer: " + what + ": " + std::strerror(errno));
    if (map_ != nullptr) modbus_mapping_free(map_);
    if (ctx_ != nullptr) modbus_free(ctx_);
    for (int fd : {master_fd_, slave_keepalive_fd_, wake_[0], wake_[1]}) {
      if (fd >= 0) ::close(fd);
    }
    return error;
  };
  master_fd_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master_fd_ < 0 || ::grantpt(master_fd_) != 0 || ::unlockpt(master_fd_) != 0)
    throw fail("pseudo-terminal");
  char name[128];
  if (::ptsname_r(master_fd_, name, sizeof name) != 0) throw fail("ptsname");
  slave_path_ = name;
  // Keep the slave side open so the master never reads a hang-up between driver connections, and
  // make the line raw (no echo of the driver's bytes back to us) before the driver configures it.
  slave_keepalive_fd_ = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (slave_keepalive_fd_ < 0) throw fail("open " + slave_path_);
  termios tio{};
  if (::tcgetattr(slave_keepalive_fd_, &tio) != 0) throw fail("tcgetattr");
  ::cfmakeraw(&tio);
  if (::tcsetattr(slave_keepalive_fd_, TCSANOW, &tio) != 0) throw fail("tcsetattr");
  if (::pipe2(wake_, O_CLOEXEC) != 0) throw fail("pipe");
  // The RTU backend only needs the descriptor: the path is never opened (no modbus_connect).
  ctx_ = modbus_new_rtu(name, robotiq::kDefaultBaud, 'N', 8, 1);
  if (ctx_ == nullptr) throw fail("modbus_new_rtu");
  map_ = modbus_mapping_new_start_address(0, 0, 0, 0, robotiq::kOutputAddress, robotiq::kRegisterCount,
                                          robotiq::kInputAddress, robotiq::kRegisterCount);
  if (map_ == nullptr) throw fail("modbus_mapping_new_start_address");
  if (modbus_set_slave(ctx_, options_.slave_id) != 0)
    throw fail("slave id " + std::to_string(options_.slave_id));
  modbus_set_socket(ctx_, master_fd_);
  modbus_set_indication_timeout(ctx_, 1, 0);  // only called once poll saw bytes

  {
    std::lock_guard device(device_lock_);
    try {
      const GripperStatus status = gripper_.Status(options_.call_timeout);
      std::lock_guard lock(mutex_);
      gpo_ = robotiq::OpeningToPosition(status.opening);
    } catch (const std::exception& e) {
      spdlog::warn("Robotiq RTU server: no initial gripper status: {}", e.what());
    }
  }
  worker_ = std::thread([this] { RunJobs(); });
  thread_ = std::thread([this] { Serve(); });
  spdlog::info("Robotiq RTU server on {} (slave {})", slave_path_, options_.slave_id);
}

RobotiqRtuServer::~RobotiqRtuServer() {
  const char byte = 0;
  [[maybe_unused]] const ssize_t n = ::write(wake_[1], &byte, 1);
  thread_.join();
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_worker_.notify_all();
  worker_.join();
  modbus_mapping_free(map_);
  modbus_free(ctx_);  // not modbus_close: the descriptors are ours
  for (int fd : {master_fd_, slave_keepalive_fd_, wake_[0], wake_[1]}) ::close(fd);
}

std::string RobotiqRtuServer::fault() const {
  std::lock_guard lock(mutex_);
  return fault_ != 0 ? fault_text_ : std::string();
}

void RobotiqRtuServer::Serve() {
  std::uint8_t request[MODBUS_RTU_MAX_ADU_LENGTH];
  for (;;) {
    pollfd fds[2] = {{master_fd_, POLLIN, 0}, {wake_[0], POLLIN, 0}};
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      spdlog::error("Robotiq RTU server: poll failed: {}; the server stops", std::strerror(errno));
      return;
    }
    if (fds[1].revents != 0) return;
    if ((fds[0].revents & POLLIN) == 0) {
      // POLLHUP cannot last while the keep-alive descriptor is open; do not spin if it does.
      if (fds[0].revents != 0) ::poll(nullptr, 0, 10);
      continue;
    }
    const int length = modbus_receive(ctx_, request);
    if (length <= 0) continue;  // a bad frame, or a request to another slave
    OnRequest(request, length);
  }
}

void RobotiqRtuServer::OnRequest(const std::uint8_t* request, int length) {
  const int offset = modbus_get_header_length(ctx_);
  const int function = request[offset];
  const int address = Register(request + offset + 1);
  if (function == MODBUS_FC_READ_INPUT_REGISTERS) {
    try {
      if (!Refresh()) return;  // the gripper did not answer: neither do we
    } catch (const std::exception& e) {
      spdlog::error("Robotiq RTU server: status failed: {}", e.what());
      modbus_reply_exception(ctx_, request, MODBUS_EXCEPTION_SLAVE_OR_SERVER_FAILURE);
      return;
    }
    const auto registers = InputRegisters();
    std::copy(registers.begin(), registers.end(), map_->tab_input_registers);
  }
  if (modbus_reply(ctx_, request, length, map_) < 0) {
    spdlog::warn("Robotiq RTU server: reply failed: {}", modbus_strerror(errno));
  }
  bool wrote = false;
  if (function == MODBUS_FC_WRITE_MULTIPLE_REGISTERS) {
    wrote = Within(address, Register(request + offset + 3), robotiq::kOutputAddress, robotiq::kRegisterCount);
  } else if (function == MODBUS_FC_WRITE_SINGLE_REGISTER) {
    wrote = Within(address, 1, robotiq::kOutputAddress, robotiq::kRegisterCount);
  } else if (function == MODBUS_FC_WRITE_AND_READ_REGISTERS) {
    wrote = Within(Register(request + offset + 5), Register(request + offset + 7), robotiq::kOutputAddress,
                   robotiq::kRegisterCount) &&
            Within(address, Register(request + offset + 3), robotiq::kOutputAddress, robotiq::kRegisterCount);
  }
  if (wrote) {
    std::array<std::uint16_t, robotiq::kRegisterCount> registers{};
    std::copy(map_->tab_registers, map_->tab_registers + robotiq::kRegisterCount, registers.begin());
    OnWrite(registers);
  }
}

void RobotiqRtuServer::OnWrite(const std::array<std::uint16_t, robotiq::kRegisterCount>& registers) {
  const auto action = static_cast<std::uint8_t>(registers[0] >> 8);
  {
    std::lock_guard lock(mutex_);
    const bool was_active = (action_ & robotiq::kRact) != 0;
    action_ = action;
    rpr_ = static_cast<std::uint8_t>(registers[1] & 0xFF);
    rsp_ = static_cast<std::uint8_t>(registers[2] >> 8);
    rfr_ = static_cast<std::uint8_t>(registers[2] & 0xFF);
    if ((action & robotiq::kRact) == 0) {
      // Reset: what runs or waits is void, faults clear.
      if (activation_ != Activation::kReset || fault_ != 0) spdlog::info("Robotiq RTU server: reset");
      ++epoch_;
      jobs_.clear();
      activation_ = Activation::kReset;
      motion_running_ = false;
      fault_ = 0;
      fault_text_.clear();
      if ((action & robotiq::kRgto) != 0) {
        fault_ = 0x07;  // "the activation bit must be set prior to performing the action"
        fault_text_ = robotiq::FaultText(fault_);
      }
      return;
    }
    if (!was_active) {
      if (fault_ == 0x07) fault_ = 0;
      activation_ = Activation::kActivating;
      jobs_.push_back(Job{.activate = true, .epoch = epoch_});
    }
    if ((action & robotiq::kRgto) != 0) {
      if (fault_ != 0) {
        spdlog::warn("Robotiq RTU server: motion to rPR {} refused: fault 0x{:02X} latched (clear rACT)",
                     rpr_, fault_);
      } else {
        motion_running_ = true;
        jobs_.push_back(
            Job{.epoch = epoch_, .motion = ++motions_, .position = rpr_, .speed = rsp_, .force = rfr_});
      }
    }
  }
  wake_worker_.notify_all();
}

bool RobotiqRtuServer::Refresh() {
  {
    std::lock_guard lock(mutex_);
    if (activation_ != Activation::kActive || motion_running_ || !jobs_.empty()) return true;
  }
  // A job that has just published its outcome still holds the device for a moment: wait for it
  // (lock_wait) rather than answer the state from before the job's end.
  std::unique_lock device = LockWithin(device_lock_, options_.lock_wait);
  if (!device.owns_lock()) return true;  // the last known state
  GripperStatus status;
  try {
    status = gripper_.Status(options_.call_timeout);
  } catch (const DeviceTimeout& e) {
    spdlog::warn("Robotiq RTU server: status unanswered: {}", e.what());
    return false;
  }
  // Only this thread queues jobs: the gripper is still idle.
  std::lock_guard lock(mutex_);
  Apply(status);
  return true;
}

void RobotiqRtuServer::Apply(const GripperStatus& status) {
  gpo_ = robotiq::OpeningToPosition(status.opening);
  gobj_ = ObjectCode(status.object);
  device_fault_ = static_cast<std::uint8_t>(status.fault & 0x0F);
}

std::array<std::uint16_t, robotiq::kRegisterCount> RobotiqRtuServer::InputRegisters() const {
  std::lock_guard lock(mutex_);
  robotiq::InputState s;
  s.gact = (action_ & robotiq::kRact) != 0;
  s.ggto = (action_ & robotiq::kRgto) != 0;
  s.gsta = activation_ == Activation::kActive ? 3 : (activation_ == Activation::kActivating ? 1 : 0);
  s.gobj = activation_ == Activation::kActive && !motion_running_ ? gobj_ : 0;
  s.gflt = fault_ != 0 ? fault_ : device_fault_;
  s.position_echo = rpr_;
  s.position = gpo_;
  s.current = 0;
  return robotiq::EncodeInput(s);
}

void RobotiqRtuServer::RunJobs() {
  for (;;) {
    Job job;
    {
      std::unique_lock lock(mutex_);
      wake_worker_.wait(lock, [this] { return stop_ || !jobs_.empty(); });
      if (stop_) return;
      job = jobs_.front();
      jobs_.pop_front();
    }
    RunJob(job);
  }
}

std::optional<GripperStatus> RobotiqRtuServer::StatusAfterFault() {
  try {
    return gripper_.Status(options_.call_timeout);
  } catch (const std::exception& e) {
    spdlog::warn("Robotiq RTU server: no status after the fault: {}", e.what());
    return std::nullopt;
  }
}

void RobotiqRtuServer::RunJob(const Job& job) {
  {
    std::lock_guard lock(mutex_);
    if (job.epoch != epoch_ || (!job.activate && job.motion != motions_)) return;  // void
    if (!job.activate && activation_ != Activation::kActive) {
      motion_running_ = false;  // activation failed before it
      return;
    }
  }
  std::lock_guard device(device_lock_);
  if (job.activate) {
    try {
      gripper_.Activate(options_.activate_timeout);
    } catch (const DeviceTimeout& e) {
      spdlog::warn("Robotiq RTU server: activation unfinished (gSTA stays 1): {}", e.what());
      return;
    } catch (const std::exception& e) {
      spdlog::error("Robotiq RTU server: activation fault (gFLT 0x{:02X}): {}", kActivationFault, e.what());
      const std::optional<GripperStatus> status = StatusAfterFault();
      std::lock_guard lock(mutex_);
      if (job.epoch != epoch_) return;
      activation_ = Activation::kReset;
      fault_ = kActivationFault;
      fault_text_ = e.what();
      if (status) Apply(*status);
      return;
    }
    std::optional<GripperStatus> status;
    try {
      status = gripper_.Status(options_.call_timeout);
    } catch (const std::exception& e) {
      spdlog::warn("Robotiq RTU server: no status after activation: {}", e.what());
    }
    std::lock_guard lock(mutex_);
    if (job.epoch != epoch_) return;
    activation_ = Activation::kActive;
    gobj_ = 3;
    if (status) {
      gpo_ = robotiq::OpeningToPosition(status->opening);
      device_fault_ = static_cast<std::uint8_t>(status->fault & 0x0F);
    }
    spdlog::info("Robotiq RTU server: activated");
    return;
  }

  const double speed = robotiq::ByteToSpeed(job.speed);
  const double force = robotiq::ByteToForce(job.force);
  const bool close = job.position >= options_.close_position;
  GripperStatus status;
  try {
    status = close ? gripper_.Close(speed, force, options_.motion_timeout)
                   : gripper_.MoveTo(robotiq::PositionToOpening(job.position), speed, force,
                                     options_.motion_timeout);
  } catch (const DeviceTimeout& e) {
    spdlog::warn("Robotiq RTU server: motion to rPR {} unfinished (gOBJ stays 0): {}", job.position,
                 e.what());
    return;
  } catch (const std::exception& e) {
    spdlog::error("Robotiq RTU server: motion fault (gFLT 0x{:02X}): {}", kMotionFault, e.what());
    const std::optional<GripperStatus> after = StatusAfterFault();
    std::lock_guard lock(mutex_);
    if (job.epoch != epoch_) return;
    fault_ = kMotionFault;
    fault_text_ = e.what();
    if (job.motion == motions_) motion_running_ = false;
    if (after) Apply(*after);
    return;
  }
  std::lock_guard lock(mutex_);
  if (job.epoch != epoch_) return;
  gpo_ = robotiq::OpeningToPosition(status.opening);
  device_fault_ = static_cast<std::uint8_t>(status.fault & 0x0F);
  if (job.motion == motions_) {
    gobj_ = ObjectCode(status.object);
    motion_running_ = false;
  }
  spdlog::debug("Robotiq RTU server: {} to rPR {} done: gOBJ {}, gPO {}", close ? "close" : "move",
                job.position, ObjectCode(status.object), gpo_);
}

}  // namespace tubepick::devices
