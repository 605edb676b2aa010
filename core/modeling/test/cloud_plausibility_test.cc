// CheckCloudAgainstCell and its wiring into ModelTubes / IsBinEmpty: a cloud with a wrong unit or
// sensor pose is a FailedPrecondition naming the likely cause, never an empty bin.
#include "core/modeling/cloud_plausibility.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/common/errors.h"
#include "core/modeling/cloud_prepare.h"
#include "core/modeling/model_tubes.h"
#include "core/planning/pick_planner.h"
#include "core/testing/synthetic_cloud.h"

namespace tubepick {
namespace {

using ::testing::AllOf;
using testing::FloorTube;
using ::testing::HasSubstr;
using ::testing::Not;
using testing::RenderSyntheticCloud;
using testing::SyntheticCloudParams;
using testing::SyntheticTube;

// A default-cell scan (sensor 1.1 m above the floor centre, looking down) of the floor and
// `tubes`, 1.1 mm pixels: sensor frame, metres.
Points Scan(const std::vector<SyntheticTube>& tubes, double pixel_angle = 0.001) {
  SyntheticCloudParams p;
  p.pixel_angle = pixel_angle;
  p.seed = 5;
  return RenderSyntheticCloud(tubes, p).points_Sensor;
}

std::vector<SyntheticTube> TwoTubes() {
  return {FloorTube({{-0.25, -0.10}, {0.25, -0.10}}), FloorTube({{-0.20, 0.12}, {0.22, 0.15}})};
}

Points Scaled(const Points& points, float factor) {
  Points out = points;
  for (Eigen::Vector3f& p : out) p *= factor;
  return out;
}

// The cloud as ModelTubes checks it: `points_Sensor` read in `unit` and put in the bin frame with
// the cell's (possibly wrong) X_BinSensor.
CloudPlausibility Check(const Points& points_Sensor, LengthUnit unit, const Eigen::Isometry3d& X_BinSensor) {
  return PrepareCloud(points_Sensor, unit, X_BinSensor, PrepareSpec{}).plausibility;
}

// The FailedPrecondition message of ModelTubes, or "" when it did not throw one.
std::string ModelError(const Points& points_Sensor, LengthUnit unit, const Eigen::Isometry3d& X_BinSensor) {
  ModelingInput input;
  input.points_Sensor = &points_Sensor;
  input.unit = unit;
  input.X_BinSensor = X_BinSensor;
  try {
    ModelTubes(input, FastModelingProfile());
  } catch (const FailedPrecondition& e) {
    return e.what();
  }
  return "";
}

const Eigen::Isometry3d kPose = SensorConfig::DefaultX_BinSensor();

TEST(CloudPlausibility, ScanOfTheCellFits) {
  const Points cloud = Scan(TwoTubes());
  const CloudPlausibility e = Check(cloud, LengthUnit::kMetre, kPose);
  EXPECT_EQ(e.points, cloud.size());
  EXPECT_EQ(e.inside, e.points);  // the synthetic scan holds the bin floor and the tubes only
  EXPECT_TRUE(e.enough_inside);
  EXPECT_TRUE(e.floor_seen);
  EXPECT_GT(e.floor_share, 0.8);
  EXPECT_TRUE(e.plausible());
  EXPECT_NEAR(e.extent.x(), 0.8 * 0.98, 0.02);  // 1st..99th percentile of a 0.8 m floor
  EXPECT_NEAR(e.extent.y(), 0.6 * 0.98, 0.02);
  EXPECT_NEAR(e.extent_ratio, 0.98, 0.03);
}

TEST(CloudPlausibility, MetresSentAsMillimetresSuggestsMetres) {
  const Points cloud = Scan(TwoTubes());
  const CloudPlausibility e = Check(cloud, LengthUnit::kMillimetre, kPose);
  EXPECT_EQ(e.inside, 0u);  // all within 1.1 mm of the sensor, 1.1 m above the floor
  EXPECT_EQ(e.on_floor, 0u);
  EXPECT_FALSE(e.plausible());
  EXPECT_NEAR(e.extent_ratio, 0.00098, 0.00003);

  const std::string message = ModelError(cloud, LengthUnit::kMillimetre, kPose);
  EXPECT_THAT(message,
              AllOf(HasSubstr("cloud does not fit the cell: 0 of "), HasSubstr(" points (0.0 %) fall inside"),
                    HasSubstr("and 0 lie on its floor"), HasSubstr("the floor is not seen"),
                    HasSubstr("spans 0.000784 × 0.000589 × 2.54e-05 m around (0.000, 0.000, 1.099) m"),
                    HasSubstr("about 1/1020 of the bin"),
                    HasSubstr("is the unit m rather than mm (cloud.unit / --unit)?")));
}

TEST(CloudPlausibility, MillimetresSentAsMetresSuggestsMillimetres) {
  const Points cloud_mm = Scaled(Scan(TwoTubes(), 0.002), 1000.0f);
  const CloudPlausibility e = Check(cloud_mm, LengthUnit::kMetre, kPose);
  EXPECT_LT(e.inside, e.points / 100);
  EXPECT_FALSE(e.plausible());
  EXPECT_NEAR(e.extent_ratio, 980.0, 30.0);

  const std::string message = ModelError(cloud_mm, LengthUnit::kMetre, kPose);
  EXPECT_THAT(message, AllOf(HasSubstr("spans 785 × 587 × 25.4 m around (1.075, 1.099, -1098.879) m"),
                             HasSubstr("about 982× the bin"),
                             HasSubstr("is the unit mm rather than m (cloud.unit / --unit)?")));
  // Read in its true unit the same numbers fit.
  EXPECT_TRUE(Check(cloud_mm, LengthUnit::kMillimetre, kPose).plausible());
  EXPECT_EQ(ModelError(cloud_mm, LengthUnit::kMillimetre, kPose), "");
}

TEST(CloudPlausibility, SensorPoseFlipped180DegreesNamesThePose) {
  // The cell says the sensor looks up (rotated 180° about its optical x axis): the floor lands
  // 2.2 m above the bin.
  const Eigen::Isometry3d flipped = kPose * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX());
  const Points cloud = Scan(TwoTubes(), 0.002);
  const CloudPlausibility e = Check(cloud, LengthUnit::kMetre, flipped);
  EXPECT_EQ(e.inside, 0u);
  EXPECT_FALSE(e.floor_seen);
  EXPECT_NEAR(e.median.z(), 2.2, 0.01);
  EXPECT_NEAR(e.extent_ratio, 1.0, 0.05);  // the right size: not the unit

  const std::string message = ModelError(cloud, LengthUnit::kMetre, flipped);
  EXPECT_THAT(
      message,
      AllOf(HasSubstr("0 of 99,008 points (0.0 %) fall inside"),
            HasSubstr("spans 0.785 × 0.587 × 0.0254 m around (0.001, 0.001, 2.200) m"),
            HasSubstr("is the sensor pose right (sensor.pose_in_bin, X_BinSensor)?"),
            HasSubstr("puts the sensor at (0.000, 0.000, 1.100) m looking along (0.00, 0.00, 1.00) in "
                      "the bin frame (cloud unit m)"),
            Not(HasSubstr("is the unit"))));
}

TEST(CloudPlausibility, SensorPoseShiftedHalfAMetreNamesThePose) {
  // The cell puts the sensor 0.5 m higher than it is: the floor appears at z = 0.5 m.
  Eigen::Isometry3d shifted = kPose;
  shifted.translation().z() += 0.5;
  const Points cloud = Scan(TwoTubes(), 0.002);
  const CloudPlausibility e = Check(cloud, LengthUnit::kMetre, shifted);
  EXPECT_EQ(e.inside, 0u);
  EXPECT_FALSE(e.floor_seen);
  EXPECT_NEAR(e.median.z(), 0.5, 0.01);

  const std::string message = ModelError(cloud, LengthUnit::kMetre, shifted);
  EXPECT_THAT(
      message,
      AllOf(HasSubstr("around (0.001, 0.001, 0.500) m"), HasSubstr("sensor.pose_in_bin"),
            HasSubstr("puts the sensor at (0.000, 0.000, 1.600) m looking along (0.00, 0.00, -1.00)")));

  // 0.5 m too low: the floor lands 0.5 m under the bin.
  shifted.translation().z() = kPose.translation().z() - 0.5;
  EXPECT_THAT(ModelError(cloud, LengthUnit::kMetre, shifted),
              AllOf(HasSubstr("around (0.001, 0.001, -0.500) m"),
                    HasSubstr("puts the sensor at (0.000, 0.000, 0.600) m")));
}

TEST(CloudPlausibility, FloorNotSeenIsAnErrorEvenInsideTheBin) {
  // A flat layer 10 cm above the floor fills the bin volume, but nothing lies on the floor.
  Points points_Bin;
  for (int i = -39; i <= 39; ++i)
    for (int j = -29; j <= 29; ++j) points_Bin.emplace_back(0.01f * i, 0.01f * j, 0.10f);
  const CloudPlausibility e = CheckCloudAgainstCell(points_Bin, BinConfig{}, PlausibilityParams{});
  EXPECT_TRUE(e.enough_inside);
  EXPECT_FALSE(e.floor_seen);
  EXPECT_THROW(RequirePlausible(e, BinConfig{}, LengthUnit::kMetre, kPose, PlausibilityParams{}),
               FailedPrecondition);
  PlausibilityParams off;
  off.check = false;  // evidence only
  EXPECT_NO_THROW(RequirePlausible(e, BinConfig{}, LengthUnit::kMetre, kPose, off));
}

TEST(CloudPlausibility, CheckOffModelsTheCloudAsBefore) {
  const Points cloud = Scan(TwoTubes(), 0.002);
  ModelingInput input;
  input.points_Sensor = &cloud;
  input.unit = LengthUnit::kMillimetre;
  ModelingParams params = FastModelingProfile();
  params.plausibility.check = false;
  const ModelingResult r = ModelTubes(input, params);
  EXPECT_TRUE(r.tubes.empty());
  EXPECT_FALSE(r.plausibility.plausible());
  EXPECT_FALSE(IsBinEmpty(r, PlanningParams{}));  // no floor seen: never "empty"
}

TEST(CloudPlausibility, EmptyBinIsEmptyNotAnError) {
  const Points cloud = Scan({});
  ModelingInput input;
  input.points_Sensor = &cloud;
  const ModelingResult r = ModelTubes(input, FastModelingProfile());
  EXPECT_TRUE(r.tubes.empty());
  EXPECT_TRUE(r.plausibility.floor_seen);
  EXPECT_EQ(r.plausibility.inside, cloud.size());
  const PickPlanResult plan = PlanPick(r, CellConfig{}, PlanningParams{}, nullptr, 1);
  EXPECT_TRUE(plan.bin_empty);
  EXPECT_TRUE(plan.plans.empty());
}

TEST(CloudPlausibility, ShortTubeEndIsModeledAndPlannedNormally) {
  // Only a 12 cm stub of a tube shows, in a corner of the bin.
  const Points cloud = Scan({FloorTube({{0.22, 0.15}, {0.34, 0.19}})});
  ModelingInput input;
  input.points_Sensor = &cloud;
  const ModelingResult r = ModelTubes(input, FastModelingProfile());
  EXPECT_TRUE(r.plausibility.plausible());
  ASSERT_EQ(r.tubes.size(), 1u);
  const PickPlanResult plan = PlanPick(r, CellConfig{}, PlanningParams{}, nullptr, 1);
  EXPECT_FALSE(plan.bin_empty);
  EXPECT_EQ(plan.counts.tubes, 1u);
}

TEST(CloudPlausibility, ParamsAreValidated) {
  PlausibilityParams p;
  p.floor_tolerance = 0.0;
  EXPECT_THAT([&] { p.Validate(); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("modeling.plausibility.floor_tolerance")));
  p = {};
  p.min_inside_share = 1.5;
  EXPECT_THROW(p.Validate(), InvalidArgument);
}

}  // namespace
}  // namespace tubepick
