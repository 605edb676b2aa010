#include "devices/sim/sim_cell.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "devices/sim/sim_devices.h"
#include "physics/scene_generator.h"
#include "physics/seeds.h"

namespace tubepick::devices::sim {
namespace {

/// Margin above the wall top up to which a tube still counts as in (or beside) the bin, metres.
constexpr double kCountMargin = 0.05;

physics::RandomTubeParams DefaultShape(const SimCellParams& p) {
  physics::RandomTubeParams shape =
      p.material == Material::kRubber ? physics::RandomTubeParams::SetB() : physics::RandomTubeParams::SetA();
  shape.radius = p.cell.tube.radius;
  if (p.cell.tube.length > 0.0) shape.branches.front().length = p.cell.tube.length;
  return shape;
}

/// Algorithm 2 tubes dropped into the bin (GenerateScene) with the material's friction.
std::vector<physics::TubeGeometry> GenerateTubes(const SimCellParams& p) {
  const SimMaterialParams material = p.material_params.value_or(SimMaterialParams::Defaults(p.material));
  physics::SceneParams scene;
  scene.tube_count = static_cast<int>(p.tubes);
  scene.tubes = p.tube_shape.value_or(DefaultShape(p));
  scene.bin = p.cell.bin;
  scene.drop.tube_mass = p.WorldTubeMass();
  scene.drop.tube_friction = std::sqrt(material.tube_friction);
  scene.drop.bin_friction = material.bin_friction / std::sqrt(material.tube_friction);
  const physics::DropResult drop = physics::GenerateScene(scene, physics::DeriveSeed(p.seed, 1));
  spdlog::debug("sim cell: dropped {} tubes in {:.2f} s simulated ({})", drop.tubes.size(),
                drop.simulated_time, drop.settled ? "settled" : "not settled");
  return drop.tubes;
}

/// A tube's centre of mass inside the bin: the inner footprint, from the floor to the wall top (each
/// with kCountMargin).
bool InBin(const Eigen::Vector3d& p, const BinConfig& bin) {
  const Eigen::Vector3d& size = bin.inner_size;
  return std::abs(p.x()) <= 0.5 * size.x() && std::abs(p.y()) <= 0.5 * size.y() && p.z() >= -kCountMargin &&
         p.z() <= size.z() + kCountMargin;
}

/// Outside the inner footprint, not above the wall top + kCountMargin (on the floor, a table, a wall).
bool BesideBin(const Eigen::Vector3d& p, const BinConfig& bin) {
  const Eigen::Vector3d& size = bin.inner_size;
  const bool beside = std::abs(p.x()) > 0.5 * size.x() || std::abs(p.y()) > 0.5 * size.y();
  return beside && p.z() <= size.z() + kCountMargin;
}

/// Over the place zone: zone_size (x_Bin, y_Bin) centred under the place frame's origin.
bool OverPlaceZone(const Eigen::Vector3d& p, const CellConfig& cell, const Eigen::Vector2d& zone_size) {
  const Eigen::Vector3d centre = cell.place.X_BinPlace.translation();
  return std::abs(p.x() - centre.x()) <= 0.5 * zone_size.x() &&
         std::abs(p.y() - centre.y()) <= 0.5 * zone_size.y();
}

/// Tubes whose centre of mass satisfies `where`; held ones only when `with_held`.
template <typename Where>
std::uint32_t CountTubes(const SimCellState& state, bool with_held, const Where& where) {
  const SimWorld& world = *state.world;
  const std::vector<std::size_t> held = world.HeldTubes();
  std::uint32_t count = 0;
  for (std::size_t i = 0; i < world.tube_count(); ++i) {
    if (!with_held && std::binary_search(held.begin(), held.end(), i)) continue;
    if (where(world.TubeCentreOfMass(i))) ++count;
  }
  return count;
}

const SimCellParams& Validated(const SimCellParams& params) {
  params.Validate();
  return params;
}

}  // namespace

double Seconds(Timeout timeout) { return std::chrono::duration<double>(timeout).count(); }

SimCellState::SimCellState(const SimCellParams& p, const std::vector<physics::TubeGeometry>& tubes_Bin)
    : params(p), noise_rng(physics::DeriveSeed(p.seed, 3)) {
  world = std::make_unique<SimWorld>(params, tubes_Bin);
  settled = world->Settle(params.physics.settle_time);
  if (!settled)
    spdlog::warn("sim cell: tubes still moving after {:.1f} s of settling", params.physics.settle_time);
  start_time = world->time();

  const BinConfig& bin = params.cell.bin;
  const Eigen::Vector3d place = params.cell.place.X_BinPlace.translation();
  const double margin = params.robot.reach_margin;
  workspace.min() << std::min(-0.5 * bin.inner_size.x(), place.x()) - margin,
      std::min(-0.5 * bin.inner_size.y(), place.y()) - margin, params.robot.min_height;
  workspace.max() << std::max(0.5 * bin.inner_size.x(), place.x()) + margin,
      std::max(0.5 * bin.inner_size.y(), place.y()) + margin, params.robot.max_height;
}

void SimCellState::ThrowIfInjected(SimDevice device, const std::string& who) const {
  const int d = static_cast<int>(device);
  const SimFault fault = faults[d];
  if (fault == SimFault::kNone) return;
  if (fault_once[d]) {
    faults[d] = SimFault::kNone;
    fault_once[d] = false;
  }
  ++const_cast<SimFaultEvents&>(events).device_failures;
  if (fault == SimFault::kTimeout) throw DeviceTimeout(who + ": no answer (injected timeout)");
  throw DeviceFault(who + ": fault (injected)");
}

void SimCellState::TickSlip(double dt) {
  if (slip_in < 0.0) return;
  slip_in -= dt;
  if (slip_in > 0.0) return;
  slip_in = -1.0;
  if (!world->holding()) return;
  world->ReleaseAll();
  gripper_object = GripperObject::kAtPosition;
  ++events.slips;
  spdlog::debug("sim cell: the held tube slipped out at {:.3f} {:.3f} {:.3f}",
                world->X_BinTcp().translation().x(), world->X_BinTcp().translation().y(),
                world->X_BinTcp().translation().z());
}

void SimCellState::TickRobotAlarm(double dt) {
  if (robot_alarm_in < 0.0) return;
  robot_alarm_in -= dt;
  if (robot_alarm_in > 0.0) return;
  robot_alarm_in = -1.0;
  servo_on = false;
  ++events.robot_alarms;
  const Eigen::Vector3d p = world->X_BinTcp().translation();
  throw DeviceFault(fmt::format(
      "robot: alarm 4100 (injected: overrun) at ({:.3f}, {:.3f}, {:.3f}) m; servo off", p.x(), p.y(), p.z()));
}

void SimCellState::ClearPlaceZone() {
  if (!params.place_zone_conveyor) return;
  const std::uint32_t carried = world->CarryOff([&](const Eigen::Vector3d& p) {
    return BesideBin(p, params.cell.bin) && OverPlaceZone(p, params.cell, params.place_zone_size);
  });
  if (carried > 0) spdlog::debug("sim cell: the conveyor carried off {} placed tube(s)", carried);
}

void SimCellState::Advance(double seconds) {
  const int steps = static_cast<int>(std::ceil(seconds / params.physics.time_step - 1e-9));
  for (int i = 0; i < steps; ++i) world->ControlStep();
}

Wrench SimCellState::RawFtReading() {
  world->BeginWindow();
  Advance(params.physics.ft_window);
  Wrench w = world->WindowMean();
  std::normal_distribution<double> force_noise(0.0, params.force_noise);
  std::normal_distribution<double> torque_noise(0.0, params.torque_noise);
  for (int i = 0; i < 3; ++i) {
    w.force[i] += params.force_offset[i] + (params.force_noise > 0.0 ? force_noise(noise_rng) : 0.0);
  }
  for (int i = 0; i < 3; ++i) {
    w.torque[i] += params.torque_offset[i] + (params.torque_noise > 0.0 ? torque_noise(noise_rng) : 0.0);
  }
  return w;
}

struct SimCell::Impl {
  Impl(const SimCellParams& params, const std::vector<physics::TubeGeometry>& tubes_Bin)
      : state(params, tubes_Bin), scanner(state), robot(state), gripper(state), ft(state) {}

  SimCellState state;
  SimScanner scanner;
  SimRobot robot;
  SimGripper gripper;
  SimForceTorqueSensor ft;
};

SimCell::SimCell(const SimCellParams& params)
    : impl_(std::make_unique<Impl>(params, GenerateTubes(Validated(params)))) {}

SimCell::SimCell(const SimCellParams& params, const std::vector<physics::TubeGeometry>& tubes_Bin)
    : impl_(std::make_unique<Impl>(Validated(params), tubes_Bin)) {}

SimCell::~SimCell() = default;

Scanner& SimCell::scanner() { return impl_->scanner; }
Robot& SimCell::robot() { return impl_->robot; }
Gripper& SimCell::gripper() { return impl_->gripper; }
ForceTorqueSensor& SimCell::ft_sensor() { return impl_->ft; }

const CellConfig& SimCell::cell() const { return impl_->state.params.cell; }
const SimCellParams& SimCell::params() const { return impl_->state.params; }

std::uint32_t SimCell::TubesInBin() const {
  return CountTubes(impl_->state, true, [&](const Eigen::Vector3d& p) { return InBin(p, cell().bin); });
}

std::uint32_t SimCell::TubesOutsideBin() const {
  return CountTubes(impl_->state, false, [&](const Eigen::Vector3d& p) { return BesideBin(p, cell().bin); });
}

std::uint32_t SimCell::TubesInPlaceZone() const {
  return CountTubes(impl_->state, false, [&](const Eigen::Vector3d& p) {
    return BesideBin(p, cell().bin) && OverPlaceZone(p, cell(), params().place_zone_size);
  });
}

std::uint32_t SimCell::TubesCarriedOff() const {
  const SimWorld& world = *impl_->state.world;
  std::uint32_t count = 0;
  for (std::size_t i = 0; i < world.tube_count(); ++i) count += world.carried_off(i) ? 1 : 0;
  return count;
}

std::uint32_t SimCell::TubesElsewhere() const {
  return CountTubes(impl_->state, false, [&](const Eigen::Vector3d& p) {
    return !InBin(p, cell().bin) &&
           !(BesideBin(p, cell().bin) && OverPlaceZone(p, cell(), params().place_zone_size));
  });
}

double SimCell::SimulatedSeconds() const { return impl_->state.world->time() - impl_->state.start_time; }

std::uint32_t SimCell::AwakeTubeBodies() const { return impl_->state.world->AwakeTubeBodies(); }

std::vector<physics::TubeGeometry> SimCell::TubesBin() const { return impl_->state.world->TubesBin(); }

std::vector<Eigen::Vector3d> SimCell::TubeCentresOfMass() const {
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = 0; i < impl_->state.world->tube_count(); ++i) {
    out.push_back(impl_->state.world->TubeCentreOfMass(i));
  }
  return out;
}

std::vector<std::size_t> SimCell::HeldTubes() const { return impl_->state.world->HeldTubes(); }

Eigen::Isometry3d SimCell::X_BinTcp() const { return impl_->state.world->X_BinTcp(); }

Wrench SimCell::TrueWrench() const { return impl_->state.world->last_wrench(); }

void SimCell::Advance(double seconds) { impl_->state.Advance(seconds); }

void SimCell::InjectFault(SimDevice device, SimFault fault) {
  impl_->state.faults[static_cast<int>(device)] = fault;
  impl_->state.fault_once[static_cast<int>(device)] = false;
}

void SimCell::InjectFaultOnce(SimDevice device, SimFault fault) {
  impl_->state.faults[static_cast<int>(device)] = fault;
  impl_->state.fault_once[static_cast<int>(device)] = fault != SimFault::kNone;
}

void SimCell::ArmRobotAlarm(double seconds) { impl_->state.robot_alarm_in = std::max(0.0, seconds); }
void SimCell::ArmSlip(double seconds) { impl_->state.slip_in = std::max(0.0, seconds); }
void SimCell::ArmSnag() { impl_->state.snag_next_open = true; }
void SimCell::InjectFtSpike() { impl_->state.ft_spike_next = true; }
void SimCell::InjectEmptyScan() { impl_->state.empty_scan_next = true; }
const SimFaultEvents& SimCell::fault_events() const { return impl_->state.events; }

bool SimCell::settled() const { return impl_->state.settled; }

std::vector<SimRunaway> SimCell::runaways() const {
  std::vector<SimRunaway> out = impl_->state.world->runaways();
  for (SimRunaway& r : out) r.seconds -= impl_->state.start_time;
  return out;
}

SimPeakSpeeds SimCell::peak_speeds() const { return impl_->state.world->peak_speeds(); }

}  // namespace tubepick::devices::sim
