#pragma once

#include <CLI/CLI.hpp>

namespace tubepick::cli {

/// `tubepick virtual-cell --tubes N --material pvc|rubber --seed S --devices-out FILE`: the simulated
/// cell (devices/sim) behind the real wire protocols, for commissioning rehearsals and CI: the robot
/// as a YRC1000 HSES server (UDP, loopback), the F/T sensor as a Net F/T RDT server (UDP), the
/// gripper as a Robotiq 2F-85 Modbus RTU slave on a pseudo-terminal, the scanner behind an `exec`
/// command (`tubepick virtual-cell scan`, talking to the cell over a UNIX socket). Writes the
/// devices YAML that points at itself (and the cell YAML beside it), prints "virtual-cell: ready",
/// then serves until SIGINT/SIGTERM and prints
///   virtual-cell: tubes_in_bin=N placed=M outside=K
/// (K: tubes anywhere but the bin or the place zone, the gripper included). Exit 0 when K = 0.
void AddVirtualCellCommand(CLI::App& app);

}  // namespace tubepick::cli
