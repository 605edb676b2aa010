#pragma once

#include <cstdint>

namespace tubepick {

/// A hash-map key of an integer grid cell: 21 bits per axis, for coordinates in [−2^20, 2^20)
/// (about ±1 km at cells of a millimetre).
inline std::uint64_t GridCellKey(std::int64_t x, std::int64_t y, std::int64_t z) {
  constexpr std::int64_t kOffset = std::int64_t{1} << 20;
  return (static_cast<std::uint64_t>(x + kOffset) << 42) | (static_cast<std::uint64_t>(y + kOffset) << 21) |
         static_cast<std::uint64_t>(z + kOffset);
}

}  // namespace tubepick
