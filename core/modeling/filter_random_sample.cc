// random_sample: a uniform subset of fixed size, reproducible from the seed.

#include <algorithm>
#include <numeric>

#include "core/modeling/filters_internal.h"

namespace tubepick::internal {

std::vector<std::uint32_t> RandomSampleFilter(const RandomSampleParams& params, std::size_t point_count,
                                              std::uint64_t seed, const StopToken* stop) {
  std::vector<std::uint32_t> order(point_count);
  std::iota(order.begin(), order.end(), 0u);
  if (params.count >= point_count) return order;
  // Partial Fisher–Yates: the first `count` entries become a uniform random subset.
  std::mt19937_64 rng(seed);
  for (std::size_t i = 0; i < params.count; ++i) {
    if (i % kStopPollInterval == 0) ThrowIfStopped(stop, "filter random_sample");
    const std::size_t j = i + UniformIndex(rng, point_count - i);
    std::swap(order[i], order[j]);
  }
  order.resize(params.count);
  std::sort(order.begin(), order.end());
  return order;
}

}  // namespace tubepick::internal
