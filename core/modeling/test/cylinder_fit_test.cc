#include "core/modeling/cylinder_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/modeling/normals.h"
#include "core/testing/synthetic_cloud.h"

namespace tubepick {
namespace {

using testing::FloorTube;
using ::testing::HasSubstr;
using testing::RenderSyntheticCloud;
using testing::StraightTube;
using testing::SyntheticCloudParams;
using testing::SyntheticTube;

constexpr double kDeg = M_PI / 180.0;
constexpr double kRadius = 0.0125;
constexpr double kRadiusTol = 0.001;
constexpr double kAxisTol = 2.0 * kDeg;
constexpr double kEndpointTol = 0.01;

// The tube rendered by the default scanner (0.3 mm depth noise), floor (z < 4 mm) removed, with
// normals; the whole cloud is one segment.
struct Scene {
  OrientedPoints cloud;
  Segment segment;
};

Scene MakeScene(const SyntheticTube& tube, std::uint64_t render_seed = 1) {
  SyntheticCloudParams params;
  params.half_fov_x = 0.25;
  params.half_fov_y = 0.2;
  params.seed = render_seed;
  const testing::SyntheticCloud rendered = RenderSyntheticCloud({tube}, params);
  Points points_Bin;
  for (const Eigen::Vector3f& p_Sensor : rendered.points_Sensor) {
    const Eigen::Vector3f p_Bin = (params.X_BinSensor * p_Sensor.cast<double>()).cast<float>();
    if (p_Bin.z() >= 0.004f) points_Bin.push_back(p_Bin);
  }
  Scene scene;
  scene.cloud =
      EstimateNormals(points_Bin, points_Bin, NormalParams{}, params.X_BinSensor.translation().cast<float>());
  for (std::uint32_t i = 0; i < scene.cloud.size(); ++i) {
    if (scene.cloud.normals[i].allFinite()) scene.segment.push_back(i);
  }
  return scene;
}

double AxisAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
  return std::min(angle, M_PI - angle);
}

// Distance between the endpoint pairs, matched in the better of the two orders.
double EndpointError(const Cylinder& c, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::min(std::max((c.start - a).norm(), (c.end - b).norm()),
                  std::max((c.start - b).norm(), (c.end - a).norm()));
}

// Length of cylinder b's axis segment that lies inside cylinder a (finite, radius a.radius).
double AxisOverlap(const Cylinder& a, const Cylinder& b) {
  constexpr int kSamples = 1000;
  const Eigen::Vector3d axis = a.axis();
  double inside = 0.0;
  for (int i = 0; i < kSamples; ++i) {
    const Eigen::Vector3d p = b.start + (static_cast<double>(i) + 0.5) / kSamples * (b.end - b.start);
    const double t = (p - a.start).dot(axis);
    if (t < 0.0 || t > a.length()) continue;
    if ((p - a.start - t * axis).norm() <= a.radius) inside += b.length() / kSamples;
  }
  return inside;
}

void ExpectStraightTubeFit(const std::vector<FittedCylinder>& fits, const Eigen::Vector3d& a,
                           const Eigen::Vector3d& b) {
  ASSERT_EQ(fits.size(), 1u);
  const Cylinder& c = fits[0].cylinder;
  EXPECT_NEAR(c.radius, kRadius, kRadiusTol);
  EXPECT_LT(AxisAngle(c.axis(), (b - a).normalized()), kAxisTol);
  // The visible extent runs from a to b; the spherical caps add at most a few millimetres.
  EXPECT_LT(EndpointError(c, a, b), kEndpointTol)
      << "start " << c.start.transpose() << " end " << c.end.transpose();
  EXPECT_EQ(c.inlier_count, fits[0].inliers.size());
}

TEST(FitCylinders, StraightTubeGivesOneAccurateCylinder) {
  const Eigen::Vector3d a(-0.15, -0.05, 0.03), b(0.15, 0.04, 0.05);
  const Scene scene = MakeScene(StraightTube(a, b, kRadius));
  ASSERT_GT(scene.segment.size(), 5000u);
  const std::vector<FittedCylinder> fits =
      FitCylinders(scene.cloud, scene.segment, 7, CylinderFitParams{}, 42);
  ExpectStraightTubeFit(fits, a, b);
  ASSERT_FALSE(fits.empty());
  EXPECT_EQ(fits[0].cylinder.segment_id, 7u);
  EXPECT_GT(fits[0].inliers.size(), scene.segment.size() * 9 / 10);
  for (std::uint32_t i : fits[0].inliers) ASSERT_LT(i, scene.cloud.size());
}

TEST(FitCylinders, TightThresholdsAndSparseSegmentStillFit) {
  // A pipeline-like segment: ~2000 points of a floor tube, tight inlier thresholds.
  const Eigen::Vector3d a(-0.2, 0.0, kRadius), b(0.2, 0.0, kRadius);
  const Scene scene = MakeScene(FloorTube({a.head<2>(), b.head<2>()}, kRadius));
  Segment sparse;
  for (std::size_t i = 0; i < scene.segment.size(); i += scene.segment.size() / 2000)
    sparse.push_back(scene.segment[i]);
  CylinderFitParams params;
  params.min_inliers = 60;
  params.max_radius = 0.018;
  params.distance_threshold = 0.004;
  params.normal_distance_weight = 0.1;
  params.max_iterations = 300;
  ExpectStraightTubeFit(FitCylinders(scene.cloud, sparse, 0, params, 5), a, b);
}

TEST(FitCylinders, SameSeedSameResultOtherSeedStillCorrect) {
  const Eigen::Vector3d a(-0.12, 0.08, kRadius), b(0.14, -0.06, kRadius);
  const Scene scene = MakeScene(FloorTube({a.head<2>(), b.head<2>()}, kRadius));
  const auto first = FitCylinders(scene.cloud, scene.segment, 0, CylinderFitParams{}, 123);
  const auto again = FitCylinders(scene.cloud, scene.segment, 0, CylinderFitParams{}, 123);
  ASSERT_EQ(first.size(), again.size());
  for (std::size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(first[i].cylinder.start, again[i].cylinder.start);
    EXPECT_EQ(first[i].cylinder.end, again[i].cylinder.end);
    EXPECT_EQ(first[i].cylinder.radius, again[i].cylinder.radius);
    EXPECT_EQ(first[i].inliers, again[i].inliers);
  }
  ExpectStraightTubeFit(first, a, b);
  for (std::uint64_t seed : {1u, 2u, 3u, 99u}) {
    SCOPED_TRACE(seed);
    ExpectStraightTubeFit(FitCylinders(scene.cloud, scene.segment, 0, CylinderFitParams{}, seed), a, b);
  }
}

TEST(FitCylinders, IsThreadSafe) {
  const Scene scene = MakeScene(FloorTube({{-0.15, 0.0}, {0.15, 0.02}}, kRadius));
  const auto expected = FitCylinders(scene.cloud, scene.segment, 0, CylinderFitParams{}, 11);
  std::vector<std::vector<FittedCylinder>> results(4);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < results.size(); ++t) {
    threads.emplace_back(
        [&, t] { results[t] = FitCylinders(scene.cloud, scene.segment, 0, CylinderFitParams{}, 11); });
  }
  for (std::thread& thread : threads) thread.join();
  for (const auto& result : results) {
    ASSERT_EQ(result.size(), expected.size());
    for (std::size_t i = 0; i < result.size(); ++i) EXPECT_EQ(result[i].inliers, expected[i].inliers);
  }
}

TEST(FitCylinders, BentTubeGivesOneCylinderPerSectionWithoutOverlap) {
  // Three straight sections joined by ~38° bends, one segment.
  const std::vector<Eigen::Vector2d> xy = {{-0.2, -0.1}, {-0.07, 0.0}, {0.07, 0.0}, {0.2, -0.1}};
  const Scene scene = MakeScene(FloorTube(xy, kRadius));
  for (std::uint64_t seed : {7u, 8u}) {
    SCOPED_TRACE(seed);
    const std::vector<FittedCylinder> fits =
        FitCylinders(scene.cloud, scene.segment, 3, CylinderFitParams{}, seed);
    ASSERT_EQ(fits.size(), 3u);
    // Each section is matched by one cylinder along it.
    std::vector<int> matched(3, 0);
    for (const FittedCylinder& fit : fits) {
      const Cylinder& c = fit.cylinder;
      EXPECT_NEAR(c.radius, kRadius, kRadiusTol);
      EXPECT_EQ(c.segment_id, 3u);
      for (int s = 0; s < 3; ++s) {
        const Eigen::Vector3d a(xy[s].x(), xy[s].y(), kRadius), b(xy[s + 1].x(), xy[s + 1].y(), kRadius);
        const Eigen::Vector3d direction = (b - a).normalized();
        const double offset = (c.centre() - a - (c.centre() - a).dot(direction) * direction).norm();
        if (AxisAngle(c.axis(), direction) < 3.0 * kDeg && offset < 0.003) ++matched[s];
      }
    }
    EXPECT_EQ(matched, (std::vector<int>{1, 1, 1}));
    // The safety zone keeps the cylinders from overlapping.
    for (std::size_t i = 0; i < fits.size(); ++i) {
      for (std::size_t j = 0; j < fits.size(); ++j) {
        if (i == j) continue;
        EXPECT_LT(AxisOverlap(fits[i].cylinder, fits[j].cylinder), 0.01) << i << " " << j;
      }
    }
    // Inliers are disjoint.
    std::vector<int> seen(scene.cloud.size(), 0);
    for (const FittedCylinder& fit : fits) {
      for (std::uint32_t i : fit.inliers) EXPECT_EQ(seen[i]++, 0);
    }
  }
}

TEST(FitCylinders, TooFewPointsGiveNoCylinder) {
  const Scene scene = MakeScene(FloorTube({{-0.15, 0.0}, {0.15, 0.0}}, kRadius));
  CylinderFitParams params;
  params.min_inliers = static_cast<std::uint32_t>(scene.segment.size()) + 1;
  EXPECT_TRUE(FitCylinders(scene.cloud, scene.segment, 0, params, 1).empty());
  EXPECT_TRUE(FitCylinders(scene.cloud, Segment{}, 0, CylinderFitParams{}, 1).empty());
}

TEST(FitCylinders, RadiiStayWithinTheLimits) {
  // A 30 mm tube with radius limits 7–15 mm: whatever is fitted (thin strips of the surface can
  // pass the inlier test) respects the limits.
  const Scene scene = MakeScene(FloorTube({{-0.15, 0.0}, {0.15, 0.0}}, 0.03));
  CylinderFitParams tight;
  tight.distance_threshold = 0.004;
  tight.normal_distance_weight = 0.1;
  for (const CylinderFitParams& params : {CylinderFitParams{}, tight}) {
    for (const FittedCylinder& fit : FitCylinders(scene.cloud, scene.segment, 0, params, 1)) {
      EXPECT_GE(fit.cylinder.radius, params.min_radius);
      EXPECT_LE(fit.cylinder.radius, params.max_radius);
    }
  }
}

TEST(FitCylinders, StopsWhenCancelled) {
  const Scene scene = MakeScene(FloorTube({{-0.15, 0.0}, {0.15, 0.0}}, kRadius));
  StopToken token;
  token.RequestStop();
  EXPECT_THROW(FitCylinders(scene.cloud, scene.segment, 0, CylinderFitParams{}, 1, &token), Cancelled);
}

TEST(FitCylinders, RejectsBadInputNamingTheKey) {
  OrientedPoints cloud;
  cloud.points.assign(3, Eigen::Vector3f::Zero());
  cloud.normals.assign(3, Eigen::Vector3f::UnitZ());
  cloud.curvature.assign(3, 0.0f);
  auto error_of = [&](const CylinderFitParams& params, const Segment& segment) -> std::string {
    try {
      FitCylinders(cloud, segment, 0, params, 1);
    } catch (const InvalidArgument& e) {
      return e.what();
    }
    return "";
  };
  CylinderFitParams params;
  params.min_radius = 0.02;
  params.max_radius = 0.01;
  EXPECT_THAT(error_of(params, {0, 1, 2}),
              HasSubstr("cylinders.min_radius: 0.02 exceeds cylinders.max_radius 0.01"));
  params = CylinderFitParams{};
  params.normal_distance_weight = 1.5;
  EXPECT_THAT(error_of(params, {0, 1, 2}), HasSubstr("cylinders.normal_distance_weight"));
  EXPECT_THAT(error_of(params, {0, 1, 2}), HasSubstr("1.5"));
  params = CylinderFitParams{};
  params.normal_distance_weight = -0.1;
  EXPECT_THAT(error_of(params, {0, 1, 2}), HasSubstr("cylinders.normal_distance_weight"));
  params = CylinderFitParams{};
  params.probability = 1.0;
  EXPECT_THAT(error_of(params, {0, 1, 2}), HasSubstr("cylinders.probability"));
  params = CylinderFitParams{};
  params.distance_threshold = 0.0;
  EXPECT_THAT(error_of(params, {0, 1, 2}), HasSubstr("cylinders.distance_threshold"));
  EXPECT_THAT(error_of(CylinderFitParams{}, {0, 5}), HasSubstr("point index 5"));
}

// Keeps the points of `scene`'s segment whose x (bin frame) satisfies `keep`.
template <typename Keep>
Segment SegmentWhere(const Scene& scene, Keep keep) {
  Segment out;
  for (std::uint32_t i : scene.segment)
    if (keep(scene.cloud.points[i].x())) out.push_back(i);
  return out;
}

TEST(FitCylinders, NoCylinderSpansAHoleInTheSegment) {
  // One straight tube whose middle 6 cm were taken by an earlier cylinder (§4.6.2): the two
  // sides are collinear, but a cylinder must not bridge the hole (it would overlap the earlier
  // one). Each side gets its own cylinder.
  const Scene scene = MakeScene(FloorTube({{-0.15, 0.0}, {0.15, 0.0}}, kRadius));
  const Segment sides = SegmentWhere(scene, [](float x) { return std::abs(x) > 0.03f; });
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    const std::vector<FittedCylinder> fits = FitCylinders(scene.cloud, sides, 0, CylinderFitParams{}, seed);
    ASSERT_EQ(fits.size(), 2u);
    for (const FittedCylinder& fit : fits) {
      EXPECT_LT(fit.cylinder.length(), 0.13);
      EXPECT_GT(fit.cylinder.start.x() * fit.cylinder.end.x(), 0.0) << "crosses the hole";
    }
  }
}

TEST(FitCylinders, PieceShorterThanItsRadiusGivesNoCylinder) {
  // A 1 cm long piece of tube (enough points, but shorter than the 12.5 mm radius): its axis
  // direction is unreliable, so no cylinder is made.
  const Scene scene = MakeScene(FloorTube({{-0.15, 0.0}, {0.15, 0.0}}, kRadius));
  const Segment piece = SegmentWhere(scene, [](float x) { return std::abs(x) < 0.005f; });
  CylinderFitParams params;
  params.min_inliers = 30;
  ASSERT_GT(piece.size(), 2 * params.min_inliers);
  EXPECT_TRUE(FitCylinders(scene.cloud, piece, 0, params, 1).empty());
}

TEST(FitCylinders, StrictNormalTermStillFitsEverySeed) {
  // Normals with a few degrees of error (as from small neighbourhoods in dense scans) and an
  // inlier test that allows only ~2° of it: many valid samples then have no inlier at all. The
  // search must go on until it finds a real model instead of stopping after the first sample.
  Scene scene = MakeScene(FloorTube({{-0.15, 0.0}, {0.15, 0.0}}, kRadius));
  std::mt19937_64 rng(11);
  std::normal_distribution<float> tilt(0.0f, static_cast<float>(2.5 * kDeg));
  for (Eigen::Vector3f& n : scene.cloud.normals) {
    if (n.allFinite()) n = (n + Eigen::Vector3f(tilt(rng), tilt(rng), tilt(rng))).normalized();
  }
  CylinderFitParams strict;
  strict.distance_threshold = 0.004;
  strict.normal_distance_weight = 0.1;
  for (std::uint64_t seed = 0; seed < 30; ++seed) {
    EXPECT_FALSE(FitCylinders(scene.cloud, scene.segment, 0, strict, seed).empty()) << "seed " << seed;
  }
}

}  // namespace
}  // namespace tubepick
