// Robot::Hold: its checks for every driver, and the default hold (a real arm keeps its pose under
// servo control while the caller waits).

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "devices/robot.h"

namespace tubepick::devices {

void Robot::Hold(double seconds, Timeout timeout) {
  if (!std::isfinite(seconds) || seconds < 0.0)
    throw DeviceFault(fmt::format("robot: hold for {} s (a wait, at least 0)", seconds));
  const double limit = std::chrono::duration<double>(timeout).count();
  HoldFor(std::min(seconds, limit));
  if (seconds > limit)
    throw DeviceTimeout(
        fmt::format("robot: a hold of {:.2f} s exceeds the timeout of {:.3f} s", seconds, limit));
}

void Robot::HoldFor(double seconds) { std::this_thread::sleep_for(std::chrono::duration<double>(seconds)); }

}  // namespace tubepick::devices
