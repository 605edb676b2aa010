#pragma once

#include <cstdint>
#include <string>

#include "core/common/cell_config.h"
#include "physics/bin_drop.h"
#include "physics/virtual_scanner.h"

namespace tubepick::cli {

/// A simulated bin: random tubes dropped into the cell's bin and scanned from its sensor.
struct SimulatedScene {
  physics::DropResult drop;
  /// Points in the sensor frame, metres, with per-point labels (index into drop.tubes).
  physics::ScanResult scan;
};

/// The cell that describes `preset`'s tubes: tube.length is the preset's total curve length, a
/// branched preset (C, CY) makes a linear cell's topology branched (an `auto` cell stays auto), a
/// cell expecting any junction shape gets the preset's (PresetJunctionShape) and a cell that knows
/// nothing of the junctions' layout the preset's (PresetJunctionLayout).
/// @throws InvalidArgument for an unknown preset.
CellConfig CellForPreset(CellConfig cell, const std::string& preset);

/// The fitting at `preset`'s junctions: wye when every branch leaves its split node 120° from the
/// trunk (set CY), else any (linear sets; set C's random directions).
/// @throws InvalidArgument for an unknown preset.
JunctionShape PresetJunctionShape(const std::string& preset);

/// Where `preset`'s junctions are, from its branches: nodes of three or more branches are
/// junctions, a branch between two of them their spacing (0 when such branches differ in length),
/// the longest branch from one to a free end the branch length. Set C and CY: 2, 0.30 m, 0.15 m;
/// linear sets: all 0. @throws InvalidArgument for an unknown preset.
JunctionLayout PresetJunctionLayout(const std::string& preset);

/// `tube_count` tubes of `preset` ("A", "B", "C"; radius and mass from the cell) dropped into
/// the cell's bin and scanned with the default scanner, all driven by `seed`. With preset A this
/// is the same scene as the built-in one of `tubepick model --tubes N --seed S`.
/// @throws InvalidArgument for an unknown preset or invalid parameters.
SimulatedScene SimulateScene(const CellConfig& cell, int tube_count, const std::string& preset,
                             std::uint64_t seed);

}  // namespace tubepick::cli
