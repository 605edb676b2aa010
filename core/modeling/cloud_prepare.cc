#include "core/modeling/cloud_prepare.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include "core/common/errors.h"
#include "core/modeling/filters.h"

namespace tubepick {
namespace {

// Points between two polls of the stop token.
constexpr std::size_t kStopPollInterval = 1 << 16;
// Points mapped at a time: the pass runs as short loops over arrays (vectorised) and only the
// keeping of points branches per point.
constexpr std::size_t kChunk = 1024;
static_assert(kStopPollInterval % kChunk == 0);

// The affine map from the input's unit in the sensor frame to metres in the bin frame, in float
// (the points' precision; about 0.1 µm at 1 m). Each coordinate is summed in the order Eigen's
// `R * p + t` uses, so the map gives the points Eigen would.
struct BinMap {
  float r[3][3];
  float t[3];

  BinMap(LengthUnit unit, const Eigen::Isometry3d& X_BinSensor) {
    const Eigen::Matrix3f R = (X_BinSensor.linear() * MetresPer(unit)).cast<float>();
    const Eigen::Vector3f p = X_BinSensor.translation().cast<float>();
    for (int i = 0; i < 3; ++i) {
      for (int k = 0; k < 3; ++k) r[i][k] = R(i, k);
      t[i] = p[i];
    }
  }
};

// One chunk of input points in the bin frame, structure of arrays, and each one's input index.
struct Chunk {
  std::array<float, 3 * kChunk> input;  // the input's floats, copied: aligned, no aliasing
  std::array<float, kChunk> x, y, z;
  std::array<std::uint32_t, kChunk> source;
  std::size_t size = 0;
  std::array<std::uint8_t, kChunk> keep;  // bit 0: working set, bit 1: raw
};

// Maps the n points at `bytes` (packed float triples in host order) into `chunk`, keeping the
// finite ones (NaN/Inf propagate through the map; testing the result also catches overflow).
void MapChunk(const char* bytes, std::size_t n, std::size_t first_index, const BinMap& map, Chunk* chunk) {
  std::memcpy(chunk->input.data(), bytes, 3 * sizeof(float) * n);
  const float* xyz = chunk->input.data();
  const float(&r)[3][3] = map.r;
  std::uint32_t finite = 0;
  for (std::size_t j = 0; j < n; ++j) {
    const float px = xyz[3 * j], py = xyz[3 * j + 1], pz = xyz[3 * j + 2];
    const float x = r[0][0] * px + (r[0][1] * py + r[0][2] * pz) + map.t[0];
    const float y = r[1][0] * px + (r[1][1] * py + r[1][2] * pz) + map.t[1];
    const float z = r[2][0] * px + (r[2][1] * py + r[2][2] * pz) + map.t[2];
    chunk->x[j] = x;
    chunk->y[j] = y;
    chunk->z[j] = z;
    // x - x is 0 exactly for a finite x (NaN otherwise).
    finite += (x - x == 0.0f) & (y - y == 0.0f) & (z - z == 0.0f);
  }
  chunk->size = n;
  for (std::size_t j = 0; j < n; ++j) chunk->source[j] = static_cast<std::uint32_t>(first_index + j);
  if (finite == n) return;
  std::size_t m = 0;  // rare: drop the non-finite points
  for (std::size_t j = 0; j < n; ++j) {
    if (!(std::isfinite(chunk->x[j]) && std::isfinite(chunk->y[j]) && std::isfinite(chunk->z[j]))) continue;
    chunk->x[m] = chunk->x[j];
    chunk->y[m] = chunk->y[j];
    chunk->z[m] = chunk->z[j];
    chunk->source[m] = chunk->source[j];
    ++m;
  }
  chunk->size = m;
}

// The pass itself over `count` points of packed float triples in host order at `bytes`.
PreparedCloud Prepare(const char* bytes, std::size_t count, LengthUnit unit,
                      const Eigen::Isometry3d& X_BinSensor, const PrepareSpec& spec, const StopToken* stop) {
  if (count == 0) {
    throw InvalidArgument(
        "cloud: no points arrived (0 points); a scan must contain at least one finite point");
  }
  const BinMap map(unit, X_BinSensor);
  const bool crop = spec.crop_Bin.has_value();
  const Eigen::Vector3f lo = crop ? spec.crop_Bin->first : Eigen::Vector3f::Zero();
  const Eigen::Vector3f hi = crop ? spec.crop_Bin->second : Eigen::Vector3f::Zero();
  // In float like the points (±∞ stay infinite).
  const RawRegion& raw = spec.raw_region_Bin;
  const bool keep_all_raw = raw.KeepsAll();
  const bool keep_no_raw = raw.KeepsNone();
  const float raw_min_z = static_cast<float>(raw.min_z),
              raw_any_xy_z = static_cast<float>(raw.any_xy_above_z);
  const float raw_hx = static_cast<float>(raw.half_xy.x()), raw_hy = static_cast<float>(raw.half_xy.y());

  PreparedCloud out;
  out.input_points = count;
  // Reserved, not touched: only the pages actually written are faulted in.
  out.working_Bin.reserve(count);
  out.working_source_index.reserve(count);
  if (!keep_no_raw) out.raw_Bin.reserve(count);
  PlausibilityTally tally(spec.bin, spec.plausibility, count);
  Chunk chunk;
  for (std::size_t begin = 0; begin < count; begin += kChunk) {
    if (begin % kStopPollInterval == 0) ThrowIfStopped(stop, "prepare");
    MapChunk(bytes + 3 * sizeof(float) * begin, std::min(kChunk, count - begin), begin, map, &chunk);
    tally.Add(chunk.x.data(), chunk.y.data(), chunk.z.data(), chunk.size);
    // Which points each output keeps, as a mask over the chunk (vectorised), then the few kept.
    for (std::size_t j = 0; j < chunk.size; ++j) {
      const float x = chunk.x[j], y = chunk.y[j], z = chunk.z[j];
      const bool in_crop =
          (x >= lo.x()) & (x <= hi.x()) & (y >= lo.y()) & (y <= hi.y()) & (z >= lo.z()) & (z <= hi.z());
      const bool in_raw =
          (z >= raw_any_xy_z) | ((z >= raw_min_z) & (std::abs(x) <= raw_hx) & (std::abs(y) <= raw_hy));
      chunk.keep[j] = static_cast<std::uint8_t>((in_crop | !crop) | ((in_raw | keep_all_raw) << 1));
    }
    for (std::size_t j = 0; j < chunk.size; ++j) {
      if (chunk.keep[j] == 0) continue;
      const Eigen::Vector3f p_Bin(chunk.x[j], chunk.y[j], chunk.z[j]);
      if (chunk.keep[j] & 1) {
        out.working_Bin.push_back(p_Bin);
        out.working_source_index.push_back(chunk.source[j]);
      }
      if (chunk.keep[j] & 2) out.raw_Bin.push_back(p_Bin);
    }
  }
  out.plausibility = tally.Finish();
  out.dropped_non_finite = count - out.plausibility.points;
  if (out.plausibility.points == 0) {
    throw InvalidArgument("cloud: no finite point: " + std::to_string(count) + " points arrived and " +
                          std::to_string(out.dropped_non_finite) + " of them were non-finite (NaN or Inf)");
  }
  return out;
}

}  // namespace

Eigen::Vector3f PackedXyz::Point(std::size_t i) const {
  const char* p = bytes.data() + 12 * i;
  Eigen::Vector3f point;
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(point.data(), p, 12);
  } else {
    for (int k = 0; k < 3; ++k) {
      std::uint32_t bits = 0;
      for (int b = 0; b < 4; ++b)
        bits |= static_cast<std::uint32_t>(static_cast<unsigned char>(p[4 * k + b])) << (8 * b);
      point[k] = std::bit_cast<float>(bits);
    }
  }
  return point;
}

PreparedCloud PrepareCloud(const Points& points_Sensor, LengthUnit unit, const Eigen::Isometry3d& X_BinSensor,
                           const PrepareSpec& spec, const StopToken* stop) {
  // Eigen::Vector3f is three packed floats.
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
  return Prepare(reinterpret_cast<const char*>(points_Sensor.data()), points_Sensor.size(), unit, X_BinSensor,
                 spec, stop);
}

PreparedCloud PrepareCloud(PackedXyz xyz_Sensor, LengthUnit unit, const Eigen::Isometry3d& X_BinSensor,
                           const PrepareSpec& spec, const StopToken* stop) {
  if constexpr (std::endian::native == std::endian::little) {
    // The wire's little-endian floats are the host's: read in place.
    return Prepare(xyz_Sensor.bytes.data(), xyz_Sensor.size(), unit, X_BinSensor, spec, stop);
  } else {
    Points points(xyz_Sensor.size());
    for (std::size_t i = 0; i < points.size(); ++i) points[i] = xyz_Sensor.Point(i);
    return PrepareCloud(points, unit, X_BinSensor, spec, stop);
  }
}

}  // namespace tubepick
