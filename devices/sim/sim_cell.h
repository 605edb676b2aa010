#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "core/common/cell_config.h"
#include "devices/force_torque_sensor.h"
#include "devices/gripper.h"
#include "devices/robot.h"
#include "devices/scanner.h"

namespace tubepick::devices::sim {

/// Tube material of the simulated cell, like the thesis' sets A and B (Table 5.2).
enum class Material {
  /// Rigid bent PVC pipe: one rigid body per tube, low friction.
  kPvc,
  /// Semi-rigid rubber hose: a chain of bodies linked by spring joints, high friction.
  kRubber,
};
/// "pvc", "rubber". ParseMaterial throws InvalidArgument naming `field` for anything else.
std::string ToString(Material material);
Material ParseMaterial(const std::string& text, const std::string& field);

/// Everything that defines one simulated cell. Same params (incl. seed) ⇒ same cell, same scans,
/// same readings.
struct SimCellParams {
  Material material = Material::kPvc;
  /// Tubes dropped into the bin at construction.
  std::uint32_t tubes = 7;
  std::uint64_t seed = 1;
  /// The cell (bin, sensor pose, tube radius/length/mass, place frame). tube.mass is per tube.
  CellConfig cell;
  /// F/T noise, standard deviation per axis: N and N·m.
  double force_noise = 0.02;
  double torque_noise = 0.002;
};

/// One Bullet world behind all four devices: tubes from the scene generator dropped into the bin;
/// the scanner is the virtual scanner; the robot moves a kinematic two-finger gripper (TCP frame as
/// in core/planning/grasp_synthesis.h: z down along the approach, y the closing direction); closing
/// holds what lies between the fingers by constraint; the F/T sensor reports the load of everything
/// lifted — including tubes lifted by entanglement — with seeded noise. Device calls advance the
/// simulation synchronously (simulated time, as fast as the CPU allows). Not thread-safe: one
/// controller drives it.
class SimCell {
 public:
  explicit SimCell(const SimCellParams& params);
  ~SimCell();
  SimCell(const SimCell&) = delete;
  SimCell& operator=(const SimCell&) = delete;

  Scanner& scanner();
  Robot& robot();
  Gripper& gripper();
  ForceTorqueSensor& ft_sensor();

  const CellConfig& cell() const;
  /// Tubes whose centre of mass lies inside the bin (inner box, up to the wall top).
  std::uint32_t TubesInBin() const;
  /// Tubes dropped outside the bin after being carried out (placed or lost).
  std::uint32_t TubesOutsideBin() const;
  /// Simulated seconds since construction.
  double SimulatedSeconds() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tubepick::devices::sim
