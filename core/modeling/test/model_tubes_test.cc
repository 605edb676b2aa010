// End-to-end tests of Algorithm 1 on analytic clouds with known answers.
#include "core/modeling/model_tubes.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>

#include "core/common/errors.h"
#include "core/params.h"
#include "core/testing/synthetic_cloud.h"

namespace tubepick {
namespace {

using testing::FloorTube;
using ::testing::HasSubstr;
using testing::RenderSyntheticCloud;
using testing::SyntheticCloudParams;
using testing::SyntheticTube;

constexpr double kRadius = 0.0125;
constexpr double kRadiusTol = 0.001;           // 1 mm
constexpr double kAxisTol = 2.0 * M_PI / 180;  // 2°

ModelingResult Model(const Points& points_Sensor, std::uint64_t seed = 7,
                     const ModelingParams& params = FastModelingProfile(),
                     LengthUnit unit = LengthUnit::kMetre) {
  ModelingInput input;
  input.points_Sensor = &points_Sensor;
  input.unit = unit;
  input.seed = seed;
  return ModelTubes(input, params);
}

Points Render(const std::vector<SyntheticTube>& tubes, std::uint64_t seed = 3) {
  SyntheticCloudParams p;
  p.seed = seed;
  return RenderSyntheticCloud(tubes, p).points_Sensor;
}

// Segments used by the cylinders of a tube.
std::set<std::uint32_t> SegmentsOf(const Tube& t) {
  std::set<std::uint32_t> s;
  for (const auto& c : t.cylinders) s.insert(c.segment_id);
  return s;
}

// The tube whose cylinders come closest to point p (bin frame, xy).
const Tube* TubeNear(const std::vector<Tube>& tubes, const Eigen::Vector2d& p) {
  const Tube* best = nullptr;
  double best_d = std::numeric_limits<double>::infinity();
  for (const Tube& t : tubes) {
    for (const Cylinder& c : t.cylinders) {
      const Eigen::Vector2d a = c.start.head<2>(), b = c.end.head<2>();
      const double s = std::clamp((p - a).dot(b - a) / std::max(1e-12, (b - a).squaredNorm()), 0.0, 1.0);
      const double d = (a + s * (b - a) - p).norm();
      if (d < best_d) best_d = d, best = &t;
    }
  }
  return best_d < 0.03 ? best : nullptr;
}

TEST(ModelTubes, StraightTubeOnFloorGivesOneCylinder) {
  const auto r = Model(Render({FloorTube({{-0.15, 0.02}, {0.15, 0.02}})}));
  ASSERT_EQ(r.tubes.size(), 1u);
  ASSERT_EQ(r.tubes[0].cylinders.size(), 1u);
  const Cylinder& c = r.tubes[0].cylinders[0];
  EXPECT_NEAR(c.radius, kRadius, kRadiusTol);
  EXPECT_LT(std::acos(std::abs(c.axis().dot(Eigen::Vector3d::UnitX()))), kAxisTol);
  EXPECT_NEAR(r.tubes[0].length(), 0.30, 0.03);
  EXPECT_GT(r.max_height, 0.02);
  EXPECT_LT(r.max_height, 0.027);
}

TEST(ModelTubes, BentTubeOfThreeSectionsIsOneTube) {
  // Bends of about 30° and 45°.
  const SyntheticTube bent = FloorTube({{-0.22, -0.08}, {-0.07, 0.0}, {0.07, -0.02}, {0.20, 0.07}});
  const auto r = Model(Render({bent}));
  ASSERT_EQ(r.tubes.size(), 1u);
  EXPECT_EQ(r.tubes[0].cylinders.size(), 3u);
  EXPECT_NEAR(r.tubes[0].length(), bent.length(), 0.05 * bent.length());
}

TEST(ModelTubes, GentlyBentTubeIsOneTube) {
  // A 6° bend that one cylinder may span: the safety zone must swallow what it leaves behind.
  const SyntheticTube bent = FloorTube({{-0.22, -0.06}, {-0.06, 0.0}, {0.08, 0.07}, {0.22, 0.02}});
  const auto r = Model(Render({bent}));
  ASSERT_EQ(r.tubes.size(), 1u);
  EXPECT_NEAR(r.tubes[0].length(), bent.length(), 0.05 * bent.length());
}

TEST(ModelTubes, CrossingTubesJoinLowerPartsNeverBridgeToUpper) {
  const SyntheticTube lower = FloorTube({{-0.20, 0.0}, {0.20, 0.0}});
  const SyntheticTube upper = FloorTube({{0.0, -0.18}, {0.0, 0.18}}, kRadius, 2.0 * kRadius);
  const auto r = Model(Render({lower, upper}));
  ASSERT_EQ(r.tubes.size(), 2u);
  const Tube* t_lower = TubeNear(r.tubes, {-0.15, 0.0});
  const Tube* t_upper = TubeNear(r.tubes, {0.0, 0.15});
  ASSERT_NE(t_lower, nullptr);
  ASSERT_NE(t_upper, nullptr);
  ASSERT_NE(t_lower, t_upper);
  // The lower tube's two visible parts are one tube, through an occluded joint.
  EXPECT_EQ(TubeNear(r.tubes, {0.15, 0.0}), t_lower);
  EXPECT_GE(SegmentsOf(*t_lower).size(), 2u);
  // No cylinder of the upper tube is in the lower one.
  for (std::uint32_t s : SegmentsOf(*t_upper)) EXPECT_EQ(SegmentsOf(*t_lower).count(s), 0u);
  EXPECT_NEAR(t_lower->length(), lower.length(), 0.05 * lower.length());
}

TEST(ModelTubes, GapWithNothingAboveIsNotJoined) {
  // Two collinear tubes with a 4 cm gap of bare floor between them.
  const auto r =
      Model(Render({FloorTube({{-0.22, 0.0}, {-0.02, 0.0}}), FloorTube({{0.02, 0.0}, {0.22, 0.0}})}));
  EXPECT_EQ(r.tubes.size(), 2u);
}

TEST(ModelTubes, LengthConstraintPreventsOverlongTube) {
  const SyntheticTube lower = FloorTube({{-0.35, 0.0}, {0.35, 0.0}});  // 0.70 m, longer than 0.60
  const SyntheticTube upper = FloorTube({{0.0, -0.18}, {0.0, 0.18}}, kRadius, 2.0 * kRadius);
  const Points cloud = Render({lower, upper});
  ModelingParams params = FastModelingProfile();
  params.joining.max_tube_length = 0.60;
  EXPECT_EQ(Model(cloud, 7, params).tubes.size(), 3u);
  params.joining.max_tube_length = 0.80;
  EXPECT_EQ(Model(cloud, 7, params).tubes.size(), 2u);
}

// Two free 0.40 m tubes and a 0.70 m one under a crossing tube: within max_tube_length (0.80).
Points WholeTubesAndALongOne() {
  return Render({FloorTube({{-0.20, -0.25}, {0.20, -0.25}}), FloorTube({{-0.20, 0.25}, {0.20, 0.25}}),
                 FloorTube({{-0.35, 0.0}, {0.35, 0.0}}),
                 FloorTube({{0.0, -0.18}, {0.0, 0.18}}, kRadius, 2.0 * kRadius)});
}

TEST(ModelTubes, TheCellsTubeLengthBoundsLinearJoining) {
  const Points cloud = WholeTubesAndALongOne();
  ModelingParams params = FastModelingProfile();
  params.joining.max_tube_length = 0.80;
  ASSERT_DOUBLE_EQ(params.joining.max_length_share, 1.04);
  ModelingInput input;
  input.points_Sensor = &cloud;
  input.seed = 7;
  auto model = [&](double tube_length) {
    input.tube_length = tube_length;
    return ModelTubes(input, params);
  };
  EXPECT_EQ(model(0.0).tubes.size(), 4u);  // unknown: max_tube_length alone
  // A cell of 0.40 m tubes cannot have a 0.70 m one: two pieces (the whole tubes the scan shows
  // are 0.40 m, the median of 0.36, 0.40, 0.40 and 0.70).
  const ModelingResult bounded = model(0.40);
  EXPECT_EQ(bounded.tubes.size(), 5u);
  EXPECT_TRUE(bounded.warnings.empty());
  params.joining.max_length_share = 0.0;  // off
  EXPECT_EQ(model(0.40).tubes.size(), 4u);
}

TEST(ModelTubes, ATubeLengthShorterThanTheScanShowsIsNotBelieved) {
  // The same scene in a cell that says its tubes are 0.30 m: every tube seen whole is longer
  // (median 0.40 m), so joining bounds them by that and flags the disagreement.
  const Points cloud = WholeTubesAndALongOne();
  ModelingParams params = FastModelingProfile();
  params.joining.max_tube_length = 0.80;
  ModelingInput input;
  input.points_Sensor = &cloud;
  input.seed = 7;
  input.tube_length = 0.30;
  const ModelingResult r = ModelTubes(input, params);
  ASSERT_EQ(r.warnings.size(), 1u);
  const ModelingWarning& w = r.warnings[0];
  EXPECT_EQ(w.code, "tube_length_shorter_than_scan");
  EXPECT_DOUBLE_EQ(w.stated, 0.30);
  EXPECT_NEAR(w.observed, 0.40, 0.02);
  EXPECT_NE(w.message.find("tube.length 0.300 m"), std::string::npos) << w.message;
  EXPECT_EQ(r.tubes.size(), 5u);
  // A cell of topology `auto` whose scene is linear: the same warning, about linear tubes.
  input.topology = TubeTopology::kAuto;
  const ModelingResult a = ModelTubes(input, params);
  ASSERT_EQ(a.warnings.size(), 1u);
  EXPECT_THAT(a.warnings[0].message, ::testing::HasSubstr("the tubes this scan shows"));
  EXPECT_THAT(a.warnings[0].message, ::testing::HasSubstr("the parts' whole curve length"));
}

TEST(ModelTubes, ACellRadiusTheFitCannotFindIsRefusedNamingBothRanges) {
  // A 20 mm tube radius (or a 25 mm diameter given as radius) with the fast profile's fit radii of
  // 7-18 mm: every cylinder would come out at 18 mm, a plausible but wrong model. Refused.
  const Points cloud = WholeTubesAndALongOne();
  ModelingInput input;
  input.points_Sensor = &cloud;
  input.tube_radius = 0.020;
  try {
    ModelTubes(input, FastModelingProfile());
    FAIL() << "a radius outside the fit's radii was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(),
                ::testing::HasSubstr("tube.radius: 0.0200 m lies outside the radii the modeling fits, "
                                     "[0.0070, 0.0180] m"));
  }
  input.tube_radius = 0.0050;
  EXPECT_THROW(ModelTubes(input, FastModelingProfile()), InvalidArgument);
  input.tube_radius = 0.0180;  // the bound itself is fittable
  EXPECT_NO_THROW(ModelTubes(input, FastModelingProfile()));
}

TEST(ModelTubes, ACellRadiusTheScanDoesNotShowIsWarnedAbout) {
  // The rendered tubes are 12.5 mm in radius: a cell that says 9 mm is told (the fitted median),
  // one that says 12.5 or 11 mm is not.
  const Points cloud = WholeTubesAndALongOne();
  ModelingInput input;
  input.points_Sensor = &cloud;
  input.seed = 7;
  auto warnings = [&](double radius) {
    input.tube_radius = radius;
    return ModelTubes(input, FastModelingProfile()).warnings;
  };
  const std::vector<ModelingWarning> told = warnings(0.009);
  ASSERT_EQ(told.size(), 1u);
  EXPECT_EQ(told[0].code, "tube_radius_differs_from_scan");
  EXPECT_DOUBLE_EQ(told[0].stated, 0.009);
  EXPECT_NEAR(told[0].observed, 0.0125, 0.0008);
  EXPECT_THAT(told[0].message, ::testing::HasSubstr("tube.radius 0.0090 m"));
  EXPECT_TRUE(warnings(0.0125).empty());
  EXPECT_TRUE(warnings(0.011).empty());
  EXPECT_TRUE(warnings(0.0).empty());  // unknown
}

TEST(ModelTubes, MillimetreInputEqualsMetreInput) {
  const Points metres = Render({FloorTube({{-0.15, -0.1}, {0.0, 0.0}, {0.15, 0.05}})});
  Points millimetres = metres;
  for (auto& p : millimetres) p *= 1000.0f;
  const auto a = Model(metres);
  const auto b = Model(millimetres, 7, FastModelingProfile(), LengthUnit::kMillimetre);
  ASSERT_EQ(a.tubes.size(), b.tubes.size());
  ASSERT_EQ(a.filtered.size(), b.filtered.size());
  for (std::size_t i = 0; i < a.tubes.size(); ++i) {
    EXPECT_NEAR(a.tubes[i].length(), b.tubes[i].length(), 1e-3);
  }
}

TEST(ModelTubes, NonFinitePointsAreDroppedAndCounted) {
  const Points clean = Render({FloorTube({{-0.15, 0.0}, {0.15, 0.0}})});
  Points dirty = clean;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  dirty.insert(dirty.begin() + 10, Eigen::Vector3f(nan, 0.f, 1.f));
  dirty.insert(dirty.begin() + 500, Eigen::Vector3f(0.f, inf, 1.f));
  dirty.push_back(Eigen::Vector3f(nan, nan, nan));
  const auto a = Model(clean);
  const auto b = Model(dirty);
  EXPECT_EQ(b.dropped_non_finite, 3u);
  // Source indices skip the dropped points: filtered point i is dirty[source[i]].
  ASSERT_EQ(b.filtered_source_index.size(), b.filtered.size());
  for (std::size_t i = 0; i < b.filtered.size(); i += 97) {
    EXPECT_TRUE(dirty[b.filtered_source_index[i]].allFinite());
  }
  EXPECT_EQ(b.input_points, clean.size() + 3);
  ASSERT_EQ(a.tubes.size(), b.tubes.size());
  for (std::size_t i = 0; i < a.tubes.size(); ++i) {
    ASSERT_EQ(a.tubes[i].cylinders.size(), b.tubes[i].cylinders.size());
    EXPECT_EQ(a.tubes[i].cylinders[0].start, b.tubes[i].cylinders[0].start);
  }
}

TEST(ModelTubes, EmptyOrAllNaNCloudIsAClearError) {
  EXPECT_THAT([] { Model(Points{}); }, ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("no points")));
  const Points all_nan(100, Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  EXPECT_THAT([&] { Model(all_nan); }, ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("100")));
}

TEST(ModelTubes, SameSeedSameAnswer) {
  const Points cloud =
      Render({FloorTube({{-0.2, -0.1}, {0.2, 0.1}}), FloorTube({{-0.2, 0.15}, {0.1, -0.15}})});
  const auto a = Model(cloud, 42);
  const auto b = Model(cloud, 42);
  ASSERT_EQ(a.tubes.size(), b.tubes.size());
  for (std::size_t i = 0; i < a.tubes.size(); ++i) {
    ASSERT_EQ(a.tubes[i].cylinders.size(), b.tubes[i].cylinders.size());
    for (std::size_t k = 0; k < a.tubes[i].cylinders.size(); ++k) {
      EXPECT_EQ(a.tubes[i].cylinders[k].start, b.tubes[i].cylinders[k].start);
      EXPECT_EQ(a.tubes[i].cylinders[k].end, b.tubes[i].cylinders[k].end);
      EXPECT_EQ(a.tubes[i].cylinders[k].radius, b.tubes[i].cylinders[k].radius);
    }
  }
  // Any seed still finds the two tubes.
  EXPECT_EQ(Model(cloud, 43).tubes.size(), 2u);
}

TEST(ModelTubes, SameAnswerWhateverTheThreadCount) {
  const Points cloud =
      Render({FloorTube({{-0.2, -0.1}, {0.0, 0.0}, {0.2, 0.1}}), FloorTube({{-0.2, 0.15}, {0.1, -0.15}})});
  ModelingParams one = FastModelingProfile(), two = FastModelingProfile();
  one.threads = 1;
  two.threads = 2;
  const auto a = Model(cloud, 5, one);
  const auto b = Model(cloud, 5, two);
  ASSERT_EQ(a.cylinder_count, b.cylinder_count);
  ASSERT_EQ(a.tubes.size(), b.tubes.size());
  for (std::size_t i = 0; i < a.tubes.size(); ++i) EXPECT_EQ(a.tubes[i].length(), b.tubes[i].length());
}

TEST(ModelTubes, ThesisProfileModelsCrossingTubes) {
  const SyntheticTube lower = FloorTube({{-0.20, 0.0}, {0.20, 0.0}});
  const SyntheticTube upper = FloorTube({{0.0, -0.18}, {0.0, 0.18}}, kRadius, 2.0 * kRadius);
  const auto r = Model(Render({lower, upper}), 7, ThesisModelingProfile());
  EXPECT_EQ(r.tubes.size(), 2u);
}

TEST(ModelTubes, CountsAndTimingsCoverEveryStep) {
  const auto r = Model(Render({FloorTube({{-0.15, 0.0}, {0.15, 0.0}})}));
  std::vector<std::string> steps;
  for (const auto& c : r.counts) steps.push_back(c.step);
  EXPECT_THAT(steps, ::testing::ElementsAre("input", "finite", "crop_box", "random_sample", "radius_outlier",
                                            "normals", "segmented", "cylinder_inliers"));
  std::vector<std::string> stages;
  for (const auto& t : r.timings) stages.push_back(t.stage);
  EXPECT_THAT(stages,
              ::testing::ElementsAre("prepare", "filter", "normals", "segmentation", "cylinders", "joining"));
  // Counts never grow along the filters.
  for (std::size_t i = 2; i < 5; ++i) EXPECT_LE(r.counts[i].points, r.counts[i - 1].points);
  // Every filtered point has a segment or -1, and tube labels refer to real tubes.
  ASSERT_EQ(r.segment_of_point.size(), r.filtered.size());
  for (int t : r.tube_of_point) EXPECT_LT(t, static_cast<int>(r.tubes.size()));
}

}  // namespace
}  // namespace tubepick
