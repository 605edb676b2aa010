#pragma once

#include <cstdint>

namespace tubepick::physics {

/// An independent seed for sub-stream `stream` of `seed` (SplitMix64 finaliser of both), so one
/// user seed can drive several generators (tube shapes, spawn poses, scanner rows) that do not
/// share draws.
constexpr std::uint64_t DeriveSeed(std::uint64_t seed, std::uint64_t stream) {
  auto mix = [](std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  };
  return mix(seed ^ mix(stream));
}

}  // namespace tubepick::physics
