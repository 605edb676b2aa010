#pragma once

// Private to core/modeling's filter steps (filters.cc, filter_*.cc); not part of the API.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "core/modeling/filters.h"

namespace tubepick::internal {

/// Points processed between two polls of the stop token.
constexpr std::size_t kStopPollInterval = 4096;

/// A uniform integer in [0, n), n > 0, by rejection (no modulo bias). Unlike
/// std::uniform_int_distribution its output is the same with every standard library.
inline std::uint64_t UniformIndex(std::mt19937_64& rng, std::uint64_t n) {
  // Values below 2^64 mod n would make the low residues more likely: redraw them.
  const std::uint64_t reject_below = (std::numeric_limits<std::uint64_t>::max() - n + 1) % n;
  while (true) {
    const std::uint64_t x = rng();
    if (x >= reject_below) return x % n;
  }
}

// Each step takes validated parameters and returns kept indices in increasing order.
std::vector<std::uint32_t> CropBoxFilter(const CropBoxParams& params, const Points& points_Bin,
                                         const FilterContext& context, const StopToken* stop);
std::vector<std::uint32_t> PassThroughFilter(const PassThroughParams& params, const Points& points_Bin,
                                             const FilterContext& context, const StopToken* stop);
std::vector<std::uint32_t> VoxelGridFilter(const VoxelGridParams& params, const Points& points_Bin,
                                           const StopToken* stop);
std::vector<std::uint32_t> RandomSampleFilter(const RandomSampleParams& params, std::size_t point_count,
                                              std::uint64_t seed, const StopToken* stop);
std::vector<std::uint32_t> RadiusOutlierFilter(const RadiusOutlierParams& params, const Points& points_Bin,
                                               const StopToken* stop);
std::vector<std::uint32_t> StatisticalOutlierFilter(const StatisticalOutlierParams& params,
                                                    const Points& points_Bin, const StopToken* stop);
std::vector<std::uint32_t> PlaneRemovalFilter(const PlaneRemovalParams& params, const Points& points_Bin,
                                              const Points& normals_Bin, std::uint64_t seed,
                                              const StopToken* stop);

}  // namespace tubepick::internal
