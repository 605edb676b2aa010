// Robot::Hold's default: a real arm keeps its pose under servo control while the caller waits.

#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "devices/robot.h"

namespace tubepick::devices {

void Robot::Hold(double seconds, Timeout timeout) {
  if (!std::isfinite(seconds) || seconds < 0.0)
    throw DeviceFault(fmt::format("robot: hold for {} s (a wait, at least 0)", seconds));
  const std::chrono::duration<double> wait(seconds);
  if (wait > timeout) {
    std::this_thread::sleep_for(timeout);
    throw DeviceTimeout(fmt::format("robot: a hold of {:.2f} s exceeds the timeout of {:.3f} s", seconds,
                                    std::chrono::duration<double>(timeout).count()));
  }
  std::this_thread::sleep_for(wait);
}

}  // namespace tubepick::devices
