#include "physics/bin_solids.h"

#include <cmath>
#include <string>

#include "core/common/errors.h"

namespace tubepick::physics {

BinSolids MakeBinSolids(const BinConfig& bin, double wall_thickness) {
  const double t = wall_thickness;
  if (!(t > 0.0 && t <= 1.0)) {
    throw InvalidArgument("bin wall_thickness = " + std::to_string(t) + " m: expected 0 < t ≤ 1");
  }
  const double hx = 0.5 * bin.inner_size.x(), hy = 0.5 * bin.inner_size.y(), h = bin.inner_size.z();
  BinSolids solids;
  solids.boxes = {
      {{0.0, 0.0, -0.5 * t}, {hx + t, hy + t, 0.5 * t}},            // floor slab under walls and interior
      {{hx + 0.5 * t, 0.0, 0.5 * h}, {0.5 * t, hy + t, 0.5 * h}},   // +x wall (covers the corners)
      {{-hx - 0.5 * t, 0.0, 0.5 * h}, {0.5 * t, hy + t, 0.5 * h}},  // −x wall
      {{0.0, hy + 0.5 * t, 0.5 * h}, {hx, 0.5 * t, 0.5 * h}},       // +y wall (between the x walls)
      {{0.0, -hy - 0.5 * t, 0.5 * h}, {hx, 0.5 * t, 0.5 * h}},      // −y wall
  };
  solids.ground_z = -t;
  return solids;
}

}  // namespace tubepick::physics
