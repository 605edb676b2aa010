#include "wire/packed_cloud.h"

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
  const std::size_t count = xyz.size() / 12;
  Points points(count);
  if constexpr (std::endian::native == std::endian::little) {
    if (count > 0) std::memcpy(static_cast<void*>(points.data()), xyz.data(), count * 12);
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      for (int k = 0; k < 3; ++k) {
        std::uint32_t bits = 0;
        for (int b = 0; b < 4; ++b)
          bits |= static_cast<std::uint32_t>(static_cast<unsigned char>(xyz[12 * i + 4 * k + b])) << (8 * b);
        points[i][k] = std::bit_cast<float>(bits);
      }
    }
  }
  return points;
}

}  // namespace tubepick
