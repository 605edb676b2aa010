#include "wire/packed_cloud.h"

#include "core/modeling/cloud_prepare.h"

#include <bit>
#include <cassert>
#include <cstdint>
#include <cstring>

namespace tubepick {

std::string PackXyz(const Points& points) {
  std::string xyz(points.size() * 12, '\0');
  if constexpr (std::endian::native == std::endian::little) {
    static_assert(sizeof(Eigen::Vector3f) == 12);
    if (!points.empty()) std::memcpy(xyz.data(), static_cast<const void*>(points.data()), xyz.size());
  } else {
    std::size_t i = 0;
    for (const Eigen::Vector3f& p : points) {
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t bits = std::bit_cast<std::uint32_t>(p[k]);
        for (int b = 0; b < 4; ++b) xyz[i++] = static_cast<char>((bits >> (8 * b)) & 0xffu);
      }
    }
  }
  return xyz;
}

Points UnpackXyz(std::string_view xyz) {
  assert(xyz.size() % 12 == 0);
  const PackedXyz packed{xyz};
  Points points(packed.size());
  if constexpr (std::endian::native == std::endian::little) {
    if (!points.empty()) std::memcpy(static_cast<void*>(points.data()), xyz.data(), xyz.size());
  } else {
    for (std::size_t i = 0; i < points.size(); ++i) points[i] = packed.Point(i);
  }
  return points;
}

}  // namespace tubepick
