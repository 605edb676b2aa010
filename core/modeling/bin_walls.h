#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "core/common/cell_config.h"
#include "core/common/types.h"

namespace tubepick {

/// Where a scan shows the bin's four inner wall faces, to check the cell's bin against it: a cell
/// whose bin is larger than the real one would model the real walls' faces and rims as tubes (and
/// plan grasps on them); a smaller one, or a shifted sensor pose, crops real tubes away.
struct BinWallParams {
  /// A wall face seen more than this from where bin.inner_size puts it does not fit, metres;
  /// 0 = no wall check.
  double tolerance = 0.04;
  /// Fewest points (of the about 100 000 sampled) a wall face must show in each of the four
  /// height bands between 40 % and 90 % of the wall height to count as seen.
  std::uint32_t min_points = 30;
  /// How far beyond the cell's walls a face is looked for, metres (a real bin that much larger).
  double search_beyond = 0.25;
};

/// The four walls: −x, +x, −y, +y (the bin frame's axes; x along the bin's length).
inline constexpr std::array<const char*, 4> kWallNames = {"-x", "+x", "-y", "+y"};

struct BinWalls {
  /// Per wall (kWallNames order): the coordinate of its inner face as the scan shows it (x for the
  /// x walls, y for the y walls), metres; nullopt where no face stands out (not seen, too few
  /// points: no evidence either way).
  std::array<std::optional<double>, 4> seen;
  /// Per wall: where the cell puts it (±inner_size / 2).
  std::array<double, 4> expected{};
  /// Per wall: seen more than the tolerance from where the cell puts it.
  std::array<bool, 4> off{};

  /// Every seen wall within the tolerance of where the cell puts it.
  bool fit() const { return off == std::array<bool, 4>{}; }
};

/// Finds the inner wall faces in `sample_Bin` (metres, bin frame; a sample of the cloud's finite
/// points): per wall, the points between 40 % and 90 % of the wall height, away from the corners,
/// binned by their distance from the bin's centre line in 1 cm bins per height band; a face is the
/// pair of adjacent bins that is the fullest in every one of four height bands (a tube lying at
/// mid-height fills one band, a wall all of them) with at least min_points in each, and whose
/// points in each band spread over 6 of 8 segments along the wall (a tube standing against it fills
/// one).
BinWalls FindBinWalls(const Points& sample_Bin, const BinConfig& bin, const BinWallParams& params);

/// "the −x wall at x = −0.400 m (the cell: −0.500 m), ...": every seen wall, misfits first.
std::string DescribeBinWalls(const BinWalls& walls);

}  // namespace tubepick
