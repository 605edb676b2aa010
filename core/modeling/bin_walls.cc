#include "core/modeling/bin_walls.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <vector>

#include <fmt/core.h>

namespace tubepick {
namespace {

constexpr int kBands = 4;
constexpr double kBandLow = 0.4, kBandHigh = 0.9;  // of the wall height
constexpr double kAwayFromCorners = 0.8;           // of the other half-extent
constexpr double kBinWidth = 0.01;                 // metres
constexpr int kSegments = 8;                       // along the wall, over its kAwayFromCorners span
constexpr int kMinSegments = 6;                    // a face spans the wall: points in this many

// Per height band, a histogram of the points' outward distance from the bin's centre line on one
// side of one axis, 1 cm bins from 0 to the wall + search_beyond.
struct WallHistogram {
  std::array<std::vector<std::uint32_t>, kBands> bands;
  // Per band and bin: the segments along the wall its points fall in (bit s for segment s).
  std::array<std::vector<std::uint8_t>, kBands> segments;

  explicit WallHistogram(std::size_t bins) {
    for (auto& b : bands) b.assign(bins, 0);
    for (auto& s : segments) s.assign(bins, 0);
  }
  // The fullest adjacent pair of bins of `band`, starting at `bin`.
  std::uint32_t Pair(int band, std::size_t bin) const {
    const auto& b = bands[band];
    return b[bin] + (bin + 1 < b.size() ? b[bin + 1] : 0);
  }
};

// The face of one wall: the adjacent pair of bins that is the fullest pair in every band (a tube
// lying along the wall fills one or two bands), with at least min_points in each, and in each band
// spread along the wall (a tube standing against it fills one segment). Its outward distance, metres.
std::optional<double> FaceOf(const WallHistogram& h, std::uint32_t min_points) {
  std::optional<std::size_t> face;
  for (int band = 0; band < kBands; ++band) {
    const auto& b = h.bands[band];
    std::size_t best = 0;
    for (std::size_t i = 1; i < b.size(); ++i) {
      if (h.Pair(band, i) > h.Pair(band, best)) best = i;
    }
    if (h.Pair(band, best) < min_points) return std::nullopt;
    // Another band's best pair may be its neighbour (the face split across bins): within one bin.
    if (face && (best + 1 < *face || best > *face + 1)) return std::nullopt;
    if (!face) face = best;
  }
  for (int band = 0; band < kBands; ++band) {
    const auto& s = h.segments[band];
    const std::uint8_t spread = s[*face] | (*face + 1 < s.size() ? s[*face + 1] : 0);
    if (std::popcount(spread) < kMinSegments) return std::nullopt;
  }
  return (static_cast<double>(*face) + 1.0) * kBinWidth;  // the middle of the pair
}

}  // namespace

BinWalls FindBinWalls(const Points& sample_Bin, const BinConfig& bin, const BinWallParams& params) {
  BinWalls walls;
  const std::array<double, 2> half = {0.5 * bin.inner_size.x(), 0.5 * bin.inner_size.y()};
  for (int w = 0; w < 4; ++w) walls.expected[w] = (w % 2 == 0 ? -1.0 : 1.0) * half[w / 2];
  if (!(params.tolerance > 0.0)) return walls;

  const double height = bin.inner_size.z();
  const double z_lo = kBandLow * height, band_height = (kBandHigh - kBandLow) * height / kBands;
  std::vector<WallHistogram> histograms;
  for (int w = 0; w < 4; ++w) {
    const double reach = half[w / 2] + params.search_beyond;
    histograms.emplace_back(static_cast<std::size_t>(std::ceil(reach / kBinWidth)) + 1);
  }
  for (const Eigen::Vector3f& p : sample_Bin) {
    const int band = static_cast<int>(std::floor((p.z() - z_lo) / band_height));
    if (band < 0 || band >= kBands) continue;
    for (int axis = 0; axis < 2; ++axis) {
      const double span = kAwayFromCorners * half[1 - axis];
      if (std::abs(p[1 - axis]) > span) continue;
      const double out = std::abs(p[axis]);
      const std::size_t bin_index = static_cast<std::size_t>(out / kBinWidth);
      WallHistogram& h = histograms[2 * axis + (p[axis] < 0.0f ? 0 : 1)];
      if (bin_index >= h.bands[band].size()) continue;
      ++h.bands[band][bin_index];
      const int segment =
          std::min(kSegments - 1, static_cast<int>((p[1 - axis] + span) / (2.0 * span) * kSegments));
      h.segments[band][bin_index] |= static_cast<std::uint8_t>(1u << segment);
    }
  }
  for (int w = 0; w < 4; ++w) {
    const std::optional<double> out = FaceOf(histograms[w], params.min_points);
    if (!out) continue;
    walls.seen[w] = (w % 2 == 0 ? -1.0 : 1.0) * *out;
    walls.off[w] = std::abs(*walls.seen[w] - walls.expected[w]) > params.tolerance;
  }
  return walls;
}

std::string DescribeBinWalls(const BinWalls& walls) {
  std::string misfits, fits;
  for (int w = 0; w < 4; ++w) {
    if (!walls.seen[w]) continue;
    const char axis = w < 2 ? 'x' : 'y';
    std::string& out = walls.off[w] ? misfits : fits;
    out += fmt::format("{}the {} wall at {} = {:+.3f} m (the cell: {:+.3f} m)", out.empty() ? "" : ", ",
                       kWallNames[w], axis, *walls.seen[w], walls.expected[w]);
  }
  if (misfits.empty()) return fits;
  return fits.empty() ? misfits : misfits + "; " + fits;
}

}  // namespace tubepick
