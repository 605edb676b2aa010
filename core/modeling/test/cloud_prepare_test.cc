#include "core/modeling/cloud_prepare.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/modeling/filters.h"

namespace tubepick {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kTol = 1e-6;  // metres; float rounding of sub-metre coordinates

Eigen::Isometry3d TiltedSensorPose() {
  Eigen::Isometry3d X_BinSensor = Eigen::Isometry3d::Identity();
  X_BinSensor.linear() =
      (Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  X_BinSensor.translation() = Eigen::Vector3d(0.1, -0.05, 1.2);
  return X_BinSensor;
}

TEST(PrepareCloud, TransformsIntoTheBinFrame) {
  // Default mount: 1.1 m above the floor centre, looking down (x right, y down, z forward).
  const Points points_Sensor = {Eigen::Vector3f(0.0f, 0.0f, 1.1f), Eigen::Vector3f(0.1f, 0.2f, 1.0f)};
  const PreparedCloud prepared =
      PrepareCloud(points_Sensor, LengthUnit::kMetre, SensorConfig::DefaultX_BinSensor(), {});
  ASSERT_EQ(prepared.working_Bin.size(), 2u);
  EXPECT_LT(prepared.working_Bin[0].norm(), kTol);
  EXPECT_LT((prepared.working_Bin[1] - Eigen::Vector3f(0.1f, -0.2f, 0.1f)).norm(), kTol);
  EXPECT_EQ(prepared.dropped_non_finite, 0u);
}

TEST(PrepareCloud, MillimetresAndMetresGiveTheSameBinPoints) {
  const Points points_m = {Eigen::Vector3f(0.01f, -0.2f, 1.05f), Eigen::Vector3f(-0.3f, 0.25f, 0.9f),
                           Eigen::Vector3f(0.0f, 0.0f, 1.2f)};
  Points points_mm;
  for (const Eigen::Vector3f& p : points_m) points_mm.push_back(1000.0f * p);
  const Eigen::Isometry3d X_BinSensor = TiltedSensorPose();
  const PreparedCloud from_m = PrepareCloud(points_m, LengthUnit::kMetre, X_BinSensor, {});
  const PreparedCloud from_mm = PrepareCloud(points_mm, LengthUnit::kMillimetre, X_BinSensor, {});
  ASSERT_EQ(from_m.working_Bin.size(), points_m.size());
  ASSERT_EQ(from_mm.working_Bin.size(), points_m.size());
  for (std::size_t i = 0; i < points_m.size(); ++i) {
    EXPECT_LT((from_m.working_Bin[i] - from_mm.working_Bin[i]).norm(), kTol) << "point " << i;
    const Eigen::Vector3d expected = X_BinSensor * points_m[i].cast<double>();
    EXPECT_LT((from_m.working_Bin[i].cast<double>() - expected).norm(), kTol) << "point " << i;
  }
}

TEST(PrepareCloud, DropsAndCountsNonFinitePoints) {
  const Points points_Sensor = {Eigen::Vector3f(0.0f, 0.0f, 1.0f),  Eigen::Vector3f(kNaN, 0.0f, 1.0f),
                                Eigen::Vector3f(0.1f, 0.0f, 1.0f),  Eigen::Vector3f(0.0f, kInf, 1.0f),
                                Eigen::Vector3f(0.0f, 0.0f, -kInf), Eigen::Vector3f(0.2f, 0.0f, 1.0f)};
  const PreparedCloud prepared =
      PrepareCloud(points_Sensor, LengthUnit::kMetre, Eigen::Isometry3d::Identity(), {});
  EXPECT_EQ(prepared.dropped_non_finite, 3u);
  ASSERT_EQ(prepared.working_Bin.size(), 3u);
  // The finite points keep their order.
  EXPECT_FLOAT_EQ(prepared.working_Bin[0].x(), 0.0f);
  EXPECT_FLOAT_EQ(prepared.working_Bin[1].x(), 0.1f);
  EXPECT_FLOAT_EQ(prepared.working_Bin[2].x(), 0.2f);
  EXPECT_THAT(prepared.working_source_index, ElementsAre(0u, 2u, 5u));
  EXPECT_EQ(prepared.plausibility.points, 3u);
}

TEST(PrepareCloud, EmptyCloudIsAnError) {
  try {
    PrepareCloud(Points{}, LengthUnit::kMetre, Eigen::Isometry3d::Identity(), {});
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("0 points"));
  }
}

TEST(PrepareCloud, AllNonFiniteIsAnError) {
  const Points points_Sensor(5, Eigen::Vector3f(kNaN, kNaN, kNaN));
  try {
    PrepareCloud(points_Sensor, LengthUnit::kMillimetre, Eigen::Isometry3d::Identity(), {});
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("5 points arrived"));
    EXPECT_THAT(e.what(), HasSubstr("5 of them were non-finite"));
  }
}

// A scan-like cloud in the sensor frame: a floor grid under the default mount with a band of
// raised points, wall points outside the bin and a few non-finite points.
Points SceneLikeCloud() {
  Points points_Bin;
  for (int i = -45; i <= 45; ++i) {
    for (int j = -35; j <= 35; ++j) {
      const float x = 0.01f * i, y = 0.01f * j;
      const bool inside = std::abs(x) < 0.4f && std::abs(y) < 0.3f;
      const float z = inside ? (std::abs(x) < 0.1f ? 0.02f + 0.001f * (j % 5) : 0.0005f * (i % 3)) : -0.01f;
      points_Bin.emplace_back(x, y, z);
    }
  }
  for (int k = 0; k < 50; ++k) points_Bin.emplace_back(0.4f, -0.3f + 0.012f * k, 0.2f);  // a wall
  const Eigen::Isometry3f X_SensorBin = SensorConfig::DefaultX_BinSensor().inverse().cast<float>();
  Points points_Sensor;
  for (const Eigen::Vector3f& p : points_Bin) points_Sensor.push_back(X_SensorBin * p);
  points_Sensor[17] = Eigen::Vector3f(kNaN, 0.f, 1.f);
  points_Sensor[4000] = Eigen::Vector3f(0.f, kInf, 1.f);
  return points_Sensor;
}

// Little-endian float32 x, y, z, as on the wire.
std::string Packed(const Points& points) {
  std::string bytes(points.size() * 12, '\0');
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const auto bits = std::bit_cast<std::uint32_t>(points[i][k]);
      for (int b = 0; b < 4; ++b) bytes[12 * i + 4 * k + b] = static_cast<char>((bits >> (8 * b)) & 0xffu);
    }
  }
  return bytes;
}

TEST(PrepareCloud, PackedBytesGiveTheSameCloudAsDecodedPoints) {
  const Points points_Sensor = SceneLikeCloud();
  const std::string bytes = Packed(points_Sensor);
  PrepareSpec spec;
  spec.crop_Bin = CropBoxBounds(CropBoxParams{}, spec.bin);
  spec.raw_region_Bin.min_z = 0.002;
  spec.raw_region_Bin.any_xy_above_z = 0.15;
  spec.raw_region_Bin.half_xy = Eigen::Vector2d(0.39, 0.29);
  const Eigen::Isometry3d X = SensorConfig::DefaultX_BinSensor();
  const PreparedCloud a = PrepareCloud(points_Sensor, LengthUnit::kMetre, X, spec);
  const PreparedCloud b = PrepareCloud(PackedXyz{bytes}, LengthUnit::kMetre, X, spec);
  EXPECT_EQ(a.working_Bin, b.working_Bin);
  EXPECT_EQ(a.working_source_index, b.working_source_index);
  EXPECT_EQ(a.raw_Bin, b.raw_Bin);
  EXPECT_EQ(a.dropped_non_finite, 2u);
  EXPECT_EQ(b.dropped_non_finite, 2u);
  EXPECT_EQ(a.plausibility.inside, b.plausibility.inside);
  EXPECT_EQ(a.plausibility.extent, b.plausibility.extent);
}

TEST(PrepareCloud, CropInThePassKeepsWhatTheCropFilterKeeps) {
  const Points points_Sensor = SceneLikeCloud();
  const Eigen::Isometry3d X = SensorConfig::DefaultX_BinSensor();
  const PreparedCloud all = PrepareCloud(points_Sensor, LengthUnit::kMetre, X, {});
  PrepareSpec spec;
  spec.crop_Bin = CropBoxBounds(CropBoxParams{}, spec.bin);
  const PreparedCloud cropped = PrepareCloud(points_Sensor, LengthUnit::kMetre, X, spec);

  const std::vector<std::uint32_t> keep =
      ApplyFilter(CropBoxParams{}, all.working_Bin, nullptr, FilterContext{X, spec.bin}, 0);
  ASSERT_GT(keep.size(), 100u);
  ASSERT_LT(keep.size(), all.working_Bin.size() / 2);  // the floor and the wall are gone
  ASSERT_EQ(cropped.working_Bin.size(), keep.size());
  for (std::size_t k = 0; k < keep.size(); ++k) {
    EXPECT_EQ(cropped.working_Bin[k], all.working_Bin[keep[k]]) << k;
    EXPECT_EQ(cropped.working_source_index[k], all.working_source_index[keep[k]]) << k;
  }
  // The evidence is about every finite point, crop or not.
  EXPECT_EQ(cropped.plausibility.points, all.plausibility.points);
  EXPECT_EQ(cropped.plausibility.on_floor, all.plausibility.on_floor);
}

TEST(PrepareCloud, RawPointsKeptInTheRawRegion) {
  const Points points_Sensor = SceneLikeCloud();
  const Eigen::Isometry3d X = SensorConfig::DefaultX_BinSensor();
  const PreparedCloud all = PrepareCloud(points_Sensor, LengthUnit::kMetre, X, {});
  EXPECT_EQ(all.raw_Bin, all.working_Bin);  // default: every finite point
  const auto count = [&](const RawRegion& r) {
    std::size_t n = 0;
    for (const Eigen::Vector3f& p : all.working_Bin) {
      n += (p.z() >= r.any_xy_above_z ||
            (p.z() >= r.min_z && std::abs(p.x()) <= r.half_xy.x() && std::abs(p.y()) <= r.half_xy.y()))
               ? 1
               : 0;
    }
    return n;
  };
  PrepareSpec spec;
  spec.raw_region_Bin = RawRegion::None();
  spec.raw_region_Bin.min_z = 0.01;                           // the raised band, not the floor ...
  spec.raw_region_Bin.half_xy = Eigen::Vector2d(0.39, 0.29);  // ... nor the wall at x = 0.4
  const PreparedCloud band = PrepareCloud(points_Sensor, LengthUnit::kMetre, X, spec);
  ASSERT_GT(band.raw_Bin.size(), 100u);
  EXPECT_EQ(band.raw_Bin.size(), count(spec.raw_region_Bin));
  for (const Eigen::Vector3f& p : band.raw_Bin) {
    EXPECT_GE(p.z(), 0.01f);
    EXPECT_LT(p.x(), 0.39f);
  }
  spec.raw_region_Bin.any_xy_above_z = 0.15;  // and the wall's points above 0.15 m
  const PreparedCloud with_wall = PrepareCloud(points_Sensor, LengthUnit::kMetre, X, spec);
  EXPECT_EQ(with_wall.raw_Bin.size(), band.raw_Bin.size() + 50);
  EXPECT_EQ(with_wall.raw_Bin.size(), count(spec.raw_region_Bin));
  spec.raw_region_Bin = RawRegion::None();
  EXPECT_TRUE(PrepareCloud(points_Sensor, LengthUnit::kMetre, X, spec).raw_Bin.empty());
}

TEST(PrepareCloud, EvidenceEqualsTheCheckOnTheFinitePoints) {
  const Points points_Sensor = SceneLikeCloud();
  const Eigen::Isometry3d X = SensorConfig::DefaultX_BinSensor();
  const PreparedCloud prepared = PrepareCloud(points_Sensor, LengthUnit::kMetre, X, {});
  // Two points are non-finite, so the sample strides differ only when the cloud exceeds 100 k.
  const CloudPlausibility e = CheckCloudAgainstCell(prepared.working_Bin, BinConfig{}, PlausibilityParams{});
  EXPECT_EQ(prepared.plausibility.points, e.points);
  EXPECT_EQ(prepared.plausibility.inside, e.inside);
  EXPECT_EQ(prepared.plausibility.on_floor, e.on_floor);
  EXPECT_EQ(prepared.plausibility.extent, e.extent);
  EXPECT_EQ(prepared.plausibility.median, e.median);
  EXPECT_TRUE(prepared.plausibility.plausible());
}

// The pass maps points a chunk at a time: each point must still be the one Eigen's R * p + t
// gives (bit for bit), in input order with its input index, across chunk boundaries and around
// dropped points.
TEST(PrepareCloud, MapsEveryPointAsEigenDoesAcrossChunks) {
  Points points_Sensor;
  for (int i = 0; i < 5000; ++i) {  // not a multiple of any chunk size
    points_Sensor.emplace_back(0.37f * std::sin(0.1f * i) * 1000.f, 0.29f * std::cos(0.07f * i) * 1000.f,
                               (1.1f + 0.05f * std::sin(0.013f * i)) * 1000.f);
  }
  points_Sensor[1023] = Eigen::Vector3f(kNaN, 0.f, 1.f);
  points_Sensor[1024] = Eigen::Vector3f(0.f, 0.f, kInf);
  points_Sensor[4999] = Eigen::Vector3f(0.f, kNaN, 1.f);
  const Eigen::Isometry3d X = TiltedSensorPose();
  const PreparedCloud prepared = PrepareCloud(points_Sensor, LengthUnit::kMillimetre, X, {});
  const Eigen::Matrix3f R = (X.linear() * 0.001).cast<float>();
  const Eigen::Vector3f t = X.translation().cast<float>();
  ASSERT_EQ(prepared.working_Bin.size(), 4997u);
  std::size_t k = 0;
  for (std::uint32_t i = 0; i < points_Sensor.size(); ++i) {
    if (i == 1023 || i == 1024 || i == 4999) continue;
    const Eigen::Vector3f expected = R * points_Sensor[i] + t;
    ASSERT_EQ(prepared.working_source_index[k], i);
    ASSERT_EQ(std::bit_cast<std::uint32_t>(prepared.working_Bin[k].x()),
              std::bit_cast<std::uint32_t>(expected.x()))
        << i;
    ASSERT_EQ(std::bit_cast<std::uint32_t>(prepared.working_Bin[k].y()),
              std::bit_cast<std::uint32_t>(expected.y()))
        << i;
    ASSERT_EQ(std::bit_cast<std::uint32_t>(prepared.working_Bin[k].z()),
              std::bit_cast<std::uint32_t>(expected.z()))
        << i;
    ++k;
  }
  EXPECT_EQ(prepared.dropped_non_finite, 3u);
}

// Above 100 k points the evidence samples every k-th point; the pass must sample the same points
// as adding them one at a time, whatever the chunks.
TEST(PrepareCloud, EvidenceOfALargeCloudSamplesAsThePointByPointCheck) {
  Points points_Sensor;
  const Eigen::Isometry3f X_SensorBin = SensorConfig::DefaultX_BinSensor().inverse().cast<float>();
  std::mt19937 rng(7);  // irregular points: another sample gives other quantiles
  std::uniform_real_distribution<float> x(-0.35f, 0.35f), y(-0.18f, 0.18f), z(0.0f, 0.03f);
  for (int i = 0; i < 350003; ++i) {  // a sample stride of 3, which 1024 is no multiple of
    points_Sensor.push_back(X_SensorBin * Eigen::Vector3f(x(rng), y(rng), z(rng)));
  }
  const Eigen::Isometry3d X = SensorConfig::DefaultX_BinSensor();
  const PreparedCloud prepared = PrepareCloud(points_Sensor, LengthUnit::kMetre, X, {});
  const CloudPlausibility e = CheckCloudAgainstCell(prepared.working_Bin, BinConfig{}, PlausibilityParams{});
  EXPECT_EQ(prepared.plausibility.points, 350003u);
  EXPECT_EQ(prepared.plausibility.inside, e.inside);
  EXPECT_EQ(prepared.plausibility.on_floor, e.on_floor);
  EXPECT_GT(e.on_floor, 0u);
  EXPECT_EQ(prepared.plausibility.extent, e.extent);
  EXPECT_EQ(prepared.plausibility.median, e.median);
}

}  // namespace
}  // namespace tubepick
