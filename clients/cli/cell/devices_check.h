#pragma once

#include <CLI/CLI.hpp>

namespace tubepick::cli {

/// `tubepick devices check --devices FILE [--cell FILE] [--json FILE]`: connects to each device of
/// the devices file and reads what it can say without moving anything: the robot's TCP pose (bin
/// frame) and servo/alarm state, the gripper's activation, object status and fault, the F/T sensor's
/// mean and noise over 1 s, one scan's point count and extent in the bin frame with the planner's
/// cloud-vs-cell plausibility check. One row per device, PASS or FAIL with the reason; exit 0 only
/// when every device passes, 5 otherwise. What an integrator runs first.
void AddDevicesCommand(CLI::App& app);

}  // namespace tubepick::cli
