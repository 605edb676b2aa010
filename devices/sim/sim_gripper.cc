// The simulated two-finger gripper: pads that close until they touch, and hold what they touch.

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "devices/sim/sim_devices.h"

namespace tubepick::devices::sim {
namespace {

/// Robotiq gFLT 0x0E, reported while a fault is injected.
constexpr std::uint8_t kInjectedFaultCode = 0x0E;

}  // namespace

GripperStatus SimGripper::Current() const {
  GripperStatus status;
  status.activated = state_.gripper_activated;
  status.object = state_.gripper_object;
  status.opening = state_.world->opening();
  if (state_.faults[static_cast<int>(SimDevice::kGripper)] == SimFault::kFault) {
    status.fault = kInjectedFaultCode;
    status.fault_text = "overcurrent triggered (injected)";
  }
  return status;
}

void SimGripper::CheckReady() const {
  state_.ThrowIfInjected(SimDevice::kGripper, "gripper");
  if (!state_.gripper_activated) throw DeviceFault("gripper: not activated (call Activate first)");
}

void SimGripper::Activate(Timeout /*timeout*/) {
  state_.ThrowIfInjected(SimDevice::kGripper, "gripper");
  state_.gripper_activated = true;
}

GripperStatus SimGripper::MoveTo(double opening, double speed, double force, Timeout timeout) {
  CheckReady();
  if (!std::isfinite(opening)) throw DeviceFault("gripper: non-finite opening");
  const SimGripperParams& g = state_.params.gripper;
  SimWorld& world = *state_.world;
  const double target = std::clamp(opening, 0.0, g.stroke);
  const double rate = std::isfinite(speed) ? std::clamp(speed, g.min_speed, g.max_speed) : g.min_speed;
  const double force_limit = std::isfinite(force) ? std::clamp(force, g.min_force, g.max_force) : g.min_force;
  const double dt = world.substep();
  const double limit = Seconds(timeout);
  double elapsed = 0.0;
  auto tick = [&] {
    elapsed += dt;
    if (elapsed > limit + 1e-12) {
      throw DeviceTimeout(
          fmt::format("gripper: motion to {:.1f} mm not finished within {:.3f} s", target * 1e3, limit));
    }
  };

  double current = world.opening();
  if (target >= current) {  // opening (or staying): let go of whatever is held
    if (state_.snag_next_open && world.holding()) {
      state_.snag_next_open = false;  // caught on the tool: it stays, whatever the fingers do
      ++state_.events.snags;
    } else {
      world.ReleaseAll();
    }
    state_.slip_in = -1.0;
    state_.gripper_object = GripperObject::kAtPosition;
    while (current < target) {
      tick();
      current = std::min(target, current + rate * dt);
      world.SetGripper(world.X_BinTcp(), current);
      world.Step();
    }
    return Current();
  }
  if (world.holding()) return Current();  // already closed on something: it cannot close further

  state_.gripper_object = GripperObject::kMoving;
  while (true) {
    tick();
    current = std::max(target, current - rate * dt);
    world.SetGripper(world.X_BinTcp(), current);
    world.Step();
    const PadContacts pads = world.QueryPads();
    if (pads.touching[0] && pads.touching[1]) {
      // Both pads on something: the gripper stops and what touches the pads is held.
      world.Attach(pads.links);
      state_.gripper_object = GripperObject::kStoppedClosing;
      break;
    }
    if ((pads.touching[0] && pads.force[0] > force_limit) ||
        (pads.touching[1] && pads.force[1] > force_limit)) {
      // One pad pushes something it cannot move: the motor stalls without a grip.
      state_.gripper_object = GripperObject::kStoppedClosing;
      break;
    }
    if (current <= target) {
      state_.gripper_object = GripperObject::kAtPosition;
      break;
    }
  }
  return Current();
}

GripperStatus SimGripper::Open(Timeout timeout) {
  const SimGripperParams& g = state_.params.gripper;
  return MoveTo(g.stroke, g.max_speed, g.min_force, timeout);
}

GripperStatus SimGripper::Close(double speed, double force, Timeout timeout) {
  return MoveTo(0.0, speed, force, timeout);
}

GripperStatus SimGripper::Status(Timeout /*timeout*/) {
  if (state_.faults[static_cast<int>(SimDevice::kGripper)] == SimFault::kTimeout) {
    throw DeviceTimeout("gripper: no answer (injected timeout)");
  }
  return Current();
}

}  // namespace tubepick::devices::sim
