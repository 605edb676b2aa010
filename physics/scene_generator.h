#pragma once

#include <cstdint>

#include "core/common/cell_config.h"
#include "physics/bin_drop.h"
#include "physics/random_tubes.h"

namespace tubepick::physics {

/// A random settled bin: Algorithm 2 tubes dropped into the bin (thesis §4.5.1).
struct SceneParams {
  /// N: number of tubes.
  int tube_count = 10;
  /// Shape of the tubes (presets A, B, C).
  RandomTubeParams tubes = RandomTubeParams::SetA();
  /// The bin they fall into.
  BinConfig bin;
  /// How they fall.
  DropParams drop;
};

/// Generates tubes (ids 1..N) and drops them; the same params and seed give bitwise the same
/// scene. The tube shapes and the spawn poses draw from separate streams of `seed`.
/// @throws InvalidArgument for invalid parameters.
DropResult GenerateScene(const SceneParams& params, std::uint64_t seed);

}  // namespace tubepick::physics
