#include "server/request_validation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/common/errors.h"
#include "core/testing/error_of.h"
#include "wire/packed_cloud.h"

namespace tubepick::server {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using tubepick::testing::ErrorOf;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

std::string Encode(const std::vector<Eigen::Vector3f>& points) {
  std::string bytes(points.size() * 12, '\0');
  for (std::size_t i = 0; i < points.size(); ++i) std::memcpy(&bytes[12 * i], points[i].data(), 12);
  return bytes;
}

void SetPose(v1::Pose* pose, const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  pose->mutable_position()->set_x(p.x());
  pose->mutable_position()->set_y(p.y());
  pose->mutable_position()->set_z(p.z());
  pose->mutable_orientation()->set_x(q.x());
  pose->mutable_orientation()->set_y(q.y());
  pose->mutable_orientation()->set_z(q.z());
  pose->mutable_orientation()->set_w(q.w());
}

// A request every check accepts: 3 points, a complete cell different from the defaults.
v1::PlanPickRequest ValidRequest() {
  v1::PlanPickRequest r;
  r.mutable_cloud()->set_xyz(Encode({{0.f, 0.f, 1.f}, {0.1f, -0.2f, 1.05f}, {-0.3f, 0.2f, 1.1f}}));
  v1::CellDescription* cell = r.mutable_cell();
  cell->mutable_bin_inner_size()->set_x(0.6);
  cell->mutable_bin_inner_size()->set_y(0.4);
  cell->mutable_bin_inner_size()->set_z(0.25);
  SetPose(cell->mutable_sensor_pose(), {0.0, 0.0, 1.2},
          Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX())));
  cell->set_tube_radius(0.01);
  cell->set_tube_length(0.4);
  cell->set_tube_mass(0.04);
  SetPose(cell->mutable_place_pose(), {0.1, 0.7, 0.05}, Eigen::Quaterniond::Identity());
  r.mutable_options()->set_profile("thesis");
  r.mutable_options()->set_seed(17);
  r.mutable_options()->set_max_plans(4);
  r.mutable_options()->set_disable_simulation(true);
  return r;
}

// One rule: a mutation of a valid request and the substrings its message must contain.
struct PlanCase {
  std::string name;
  std::function<void(v1::PlanPickRequest&)> mutate;
  std::vector<std::string> expected;
};

std::vector<PlanCase> PlanCases() {
  auto cell = [](v1::PlanPickRequest& r) { return r.mutable_cell(); };
  return {
      {"EmptyCloud", [](auto& r) { r.mutable_cloud()->clear_xyz(); }, {"cloud.xyz", "empty", "0 bytes"}},
      {"AbsentCloud", [](auto& r) { r.clear_cloud(); }, {"cloud.xyz", "empty"}},
      {"CloudNotMultipleOf12",
       [](auto& r) { r.mutable_cloud()->mutable_xyz()->push_back('\0'); },
       {"cloud.xyz", "37 bytes", "multiple of 12"}},
      {"TooManyPoints",
       [](auto& r) { r.mutable_cloud()->set_xyz(std::string(12 * 1001, '\0')); },
       {"cloud.xyz", "1001 points", "1000", "max_cloud_points"}},
      {"UnknownUnit",
       [](auto& r) { r.mutable_cloud()->set_unit(static_cast<v1::LengthUnit>(7)); },
       {"cloud.unit", "7"}},
      {"BinSizeRequired",
       [=](auto& r) { cell(r)->clear_bin_inner_size(); },
       {"cell.bin_inner_size", "required"}},
      {"BinSizeNaN",
       [=](auto& r) { cell(r)->mutable_bin_inner_size()->set_y(kNaN); },
       {"cell.bin_inner_size.y", "finite", "nan"}},
      {"BinSizeZero",
       [=](auto& r) { cell(r)->mutable_bin_inner_size()->set_x(0.0); },
       {"cell.bin_inner_size.x", "0 m", "out of range"}},
      {"BinSizeAbsurd",
       [=](auto& r) { cell(r)->mutable_bin_inner_size()->set_z(11.0); },
       {"cell.bin_inner_size.z", "11 m", "10"}},
      {"SensorPoseRequired",
       [=](auto& r) { cell(r)->clear_sensor_pose(); },
       {"cell.sensor_pose", "required"}},
      {"SensorPositionInfinite",
       [=](auto& r) { cell(r)->mutable_sensor_pose()->mutable_position()->set_x(kInf); },
       {"cell.sensor_pose.position.x", "finite", "inf"}},
      {"SensorBelowFloor",
       [=](auto& r) { cell(r)->mutable_sensor_pose()->mutable_position()->set_z(-0.5); },
       {"cell.sensor_pose.position.z", "-0.5", "above the bin floor"}},
      {"SensorOrientationAbsent",
       [=](auto& r) { cell(r)->mutable_sensor_pose()->clear_orientation(); },
       {"cell.sensor_pose.orientation", "|q| = 0"}},
      {"SensorOrientationNotUnit",
       [=](auto& r) {
         SetPose(cell(r)->mutable_sensor_pose(), {0, 0, 1.2}, Eigen::Quaterniond(0.0, 1.01, 0.0, 0.0));
       },
       {"cell.sensor_pose.orientation", "|q| = 1.01", "not unit"}},
      {"SensorOrientationNaN",
       [=](auto& r) { cell(r)->mutable_sensor_pose()->mutable_orientation()->set_w(kNaN); },
       {"cell.sensor_pose.orientation.w", "finite"}},
      {"TubeRadiusZero", [=](auto& r) { cell(r)->set_tube_radius(0.0); }, {"cell.tube_radius", "0 m"}},
      {"TubeRadiusTooLarge", [=](auto& r) { cell(r)->set_tube_radius(0.6); }, {"cell.tube_radius", "0.6 m"}},
      {"TubeRadiusNaN", [=](auto& r) { cell(r)->set_tube_radius(kNaN); }, {"cell.tube_radius", "finite"}},
      {"TubeLengthNegative",
       [=](auto& r) { cell(r)->set_tube_length(-0.1); },
       {"cell.tube_length", "-0.1 m"}},
      {"TubeLengthAbsurd", [=](auto& r) { cell(r)->set_tube_length(11.0); }, {"cell.tube_length", "11 m"}},
      {"TubeMassZero", [=](auto& r) { cell(r)->set_tube_mass(0.0); }, {"cell.tube_mass", "0 kg"}},
      {"TubeMassAbsurd", [=](auto& r) { cell(r)->set_tube_mass(120.0); }, {"cell.tube_mass", "120 kg"}},
      {"TubeMassInfinite", [=](auto& r) { cell(r)->set_tube_mass(-kInf); }, {"cell.tube_mass", "-inf"}},
      {"PlacePoseRequired", [=](auto& r) { cell(r)->clear_place_pose(); }, {"cell.place_pose", "required"}},
      {"PlaceOrientationZero",
       [=](auto& r) {
         SetPose(cell(r)->mutable_place_pose(), {0, 0.7, 0}, Eigen::Quaterniond(0.0, 0.0, 0.0, 0.0));
       },
       {"cell.place_pose.orientation", "|q| = 0"}},
      {"PlacePositionNaN",
       [=](auto& r) { cell(r)->mutable_place_pose()->mutable_position()->set_y(kNaN); },
       {"cell.place_pose.position.y", "finite"}},
      {"UnknownProfile",
       [](auto& r) { r.mutable_options()->set_profile("slow"); },
       {"options.profile", "'slow'", "fast, thesis"}},
  };
}

class PlanPickRule : public ::testing::TestWithParam<PlanCase> {};

TEST_P(PlanPickRule, MessageNamesTheField) {
  PlanningDefaults defaults;
  defaults.max_cloud_points = 1000;
  v1::PlanPickRequest request = ValidRequest();
  ASSERT_NO_THROW(ValidatePlanPick(request, defaults));
  GetParam().mutate(request);
  const std::string message = ErrorOf([&] { ValidatePlanPick(request, defaults); });
  for (const std::string& part : GetParam().expected) EXPECT_THAT(message, HasSubstr(part));

  // ModelTubes checks the same fields the same way.
  v1::ModelTubesRequest model;
  *model.mutable_cloud() = request.cloud();
  if (request.has_cell()) *model.mutable_cell() = request.cell();
  *model.mutable_options() = request.options();
  EXPECT_EQ(ErrorOf([&] { ValidateModelTubes(model, defaults); }), message);
}

INSTANTIATE_TEST_SUITE_P(Rules, PlanPickRule, ::testing::ValuesIn(PlanCases()),
                         [](const auto& info) { return info.param.name; });

TEST(ValidatePlanPick, TubeMustFitTheGripperOpening) {
  const PlanningDefaults defaults;
  v1::PlanPickRequest request = ValidRequest();
  request.mutable_cell()->set_tube_radius(0.03);  // 6 cm > the 4.5 cm opening
  EXPECT_THAT(ErrorOf([&] { ValidatePlanPick(request, defaults); }),
              AllOf(HasSubstr("cell.tube_radius"), HasSubstr("0.03 m"), HasSubstr("0.045 m")));
  // Modeling needs no gripper.
  v1::ModelTubesRequest model;
  *model.mutable_cloud() = request.cloud();
  *model.mutable_cell() = request.cell();
  EXPECT_NO_THROW(ValidateModelTubes(model, defaults));
}

TEST(CheckCloudBytes, ReturnsTheBytesInPlace) {
  const std::vector<Eigen::Vector3f> points = {{1.5f, -2.25f, 1e-3f}, {0.f, 3.f, -7.f}};
  // Bytes of 1.5f little-endian: 00 00 C0 3F.
  const std::string bytes = Encode(points);
  EXPECT_EQ(bytes.substr(0, 4), std::string("\x00\x00\xC0\x3F", 4));
  const std::string_view checked = CheckCloudBytes(bytes, 10, "cloud.xyz");
  EXPECT_EQ(checked.data(), bytes.data());  // not copied
  EXPECT_EQ(checked.size(), 24u);
  EXPECT_EQ(CheckCloudBytes(bytes, 2, "cloud.xyz").size(), 24u);  // the limit is inclusive
  EXPECT_THROW(CheckCloudBytes(bytes, 1, "cloud.xyz"), TooLarge);
}

TEST(ValidatePlanPick, CopiesEveryField) {
  PlanningDefaults defaults;
  const v1::PlanPickRequest request = ValidRequest();  // the job views its cloud bytes
  const PlanningJob job = ValidatePlanPick(request, defaults);
  ASSERT_EQ(job.xyz_Sensor.size(), 36u);
  EXPECT_EQ(UnpackXyz(job.xyz_Sensor)[1], Eigen::Vector3f(0.1f, -0.2f, 1.05f));
  EXPECT_EQ(job.cell.bin.inner_size, Eigen::Vector3d(0.6, 0.4, 0.25));
  EXPECT_NEAR(job.cell.sensor.X_BinSensor.translation().z(), 1.2, 1e-15);
  EXPECT_NEAR((job.cell.sensor.X_BinSensor.linear() * Eigen::Vector3d::UnitZ()).z(), -1.0, 1e-12);
  EXPECT_EQ(job.cell.tube.radius, 0.01);
  EXPECT_EQ(job.cell.tube.length, 0.4);
  EXPECT_EQ(job.cell.tube.mass, 0.04);
  EXPECT_NEAR(job.cell.place.X_BinPlace.translation().y(), 0.7, 1e-15);
  EXPECT_EQ(job.profile, "thesis");
  EXPECT_EQ(DumpParams(job.params), DumpParams(ProfileParams("thesis")));
  EXPECT_EQ(job.seed, 17u);
  EXPECT_EQ(job.max_plans, 4u);
  EXPECT_TRUE(job.disable_simulation);
  EXPECT_EQ(job.unit, LengthUnit::kMetre);  // UNSPECIFIED ⇒ the server cell's sensor unit
}

TEST(ValidatePlanPick, AbsentFieldsTakeTheServerDefaults) {
  PlanningDefaults defaults;
  defaults.profile = "thesis";
  defaults.profiles["thesis"].planning.max_plans = 9;
  defaults.seed = 1234;
  defaults.cell.tube.radius = 0.007;
  defaults.cell.sensor.unit = LengthUnit::kMillimetre;
  v1::PlanPickRequest request;
  request.mutable_cloud()->set_xyz(Encode({{0.f, 0.f, 1000.f}}));
  const PlanningJob job = ValidatePlanPick(request, defaults);
  EXPECT_EQ(job.profile, "thesis");
  EXPECT_EQ(job.params.planning.max_plans, 9u);
  EXPECT_EQ(job.seed, 1234u);
  EXPECT_EQ(job.cell.tube.radius, 0.007);
  EXPECT_EQ(job.unit, LengthUnit::kMillimetre);
  EXPECT_EQ(job.max_plans, 0u);
  EXPECT_FALSE(job.disable_simulation);

  // An explicit seed 0 is a seed, not "absent".
  request.mutable_options()->set_seed(0);
  EXPECT_EQ(ValidatePlanPick(request, defaults).seed, 0u);
  // An explicit unit wins over the cell's.
  request.mutable_cloud()->set_unit(v1::LENGTH_UNIT_METRE);
  EXPECT_EQ(ValidatePlanPick(request, defaults).unit, LengthUnit::kMetre);
  request.mutable_cloud()->set_unit(v1::LENGTH_UNIT_MILLIMETRE);
  EXPECT_EQ(ValidatePlanPick(request, defaults).unit, LengthUnit::kMillimetre);
  // A request's cell keeps the server's sensor unit (CellDescription has none).
  request.mutable_cloud()->set_unit(v1::LENGTH_UNIT_UNSPECIFIED);
  *request.mutable_cell() = ValidRequest().cell();
  EXPECT_EQ(ValidatePlanPick(request, defaults).unit, LengthUnit::kMillimetre);
}

TEST(ValidatePlanPick, TubeTopologyComesFromTheCellOrTheServer) {
  PlanningDefaults defaults;
  defaults.cell.tube.topology = TubeTopology::kAuto;
  v1::PlanPickRequest request = ValidRequest();
  // Unspecified: the server's configured topology, even when the request carries a cell.
  EXPECT_EQ(ValidatePlanPick(request, defaults).cell.tube.topology, TubeTopology::kAuto);
  request.mutable_cell()->set_tube_topology(v1::TUBE_TOPOLOGY_BRANCHED);
  EXPECT_EQ(ValidatePlanPick(request, defaults).cell.tube.topology, TubeTopology::kBranched);
  request.mutable_cell()->set_tube_topology(v1::TUBE_TOPOLOGY_LINEAR);
  EXPECT_EQ(ValidatePlanPick(request, defaults).cell.tube.topology, TubeTopology::kLinear);
  // A number the enum does not define (proto3 enums are open) is refused, naming the field.
  request.mutable_cell()->set_tube_topology(static_cast<v1::TubeTopology>(9));
  try {
    (void)ValidatePlanPick(request, defaults);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("cell.tube_topology: unknown value 9"));
  }
}

TEST(ValidatePlanPick, JunctionShapeComesFromTheCellOrTheServer) {
  PlanningDefaults defaults;
  defaults.cell.tube.junction_shape = JunctionShape::kTee;
  v1::PlanPickRequest request = ValidRequest();
  EXPECT_EQ(ValidatePlanPick(request, defaults).cell.tube.junction_shape, JunctionShape::kTee);
  request.mutable_cell()->set_tube_junction_shape(v1::JUNCTION_SHAPE_WYE);
  EXPECT_EQ(ValidatePlanPick(request, defaults).cell.tube.junction_shape, JunctionShape::kWye);
  request.mutable_cell()->set_tube_junction_shape(v1::JUNCTION_SHAPE_ANY);
  EXPECT_EQ(ValidatePlanPick(request, defaults).cell.tube.junction_shape, JunctionShape::kAny);
  request.mutable_cell()->set_tube_junction_shape(static_cast<v1::JunctionShape>(7));
  try {
    (void)ValidatePlanPick(request, defaults);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("cell.tube_junction_shape: unknown value 7"));
  }
}

TEST(ValidatePlanPick, TheJunctionLayoutComesFromTheCellAndIsRangeChecked) {
  PlanningDefaults defaults;
  v1::PlanPickRequest request = ValidRequest();
  EXPECT_FALSE(ValidatePlanPick(request, defaults).cell.tube.layout.known());  // 0 = unknown
  request.mutable_cell()->set_tube_junctions(2);
  request.mutable_cell()->set_tube_junction_spacing(0.30);
  request.mutable_cell()->set_tube_branch_length(0.15);
  const JunctionLayout layout = ValidatePlanPick(request, defaults).cell.tube.layout;
  EXPECT_EQ(layout.junctions, 2u);
  EXPECT_DOUBLE_EQ(layout.junction_spacing, 0.30);
  EXPECT_DOUBLE_EQ(layout.branch_length, 0.15);
  request.mutable_cell()->set_tube_branch_length(-0.15);
  EXPECT_THAT([&] { (void)ValidatePlanPick(request, defaults); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("cell.tube_branch_length")));
  // Millimetres sent as metres: a run longer than the whole tube.
  request.mutable_cell()->set_tube_branch_length(0.15);
  request.mutable_cell()->set_tube_junction_spacing(300.0);
  EXPECT_THAT([&] { (void)ValidatePlanPick(request, defaults); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("cell.tube_junction_spacing")));
}

TEST(ValidatePlanPick, NearlyUnitQuaternionIsNormalised) {
  v1::PlanPickRequest request = ValidRequest();
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
  Eigen::Quaterniond scaled = q;
  scaled.coeffs() *= 1.0009;
  SetPose(request.mutable_cell()->mutable_place_pose(), {0, 0.7, 0}, scaled);
  const PlanningJob job = ValidatePlanPick(request, PlanningDefaults{});
  const Eigen::Matrix3d R = job.cell.place.X_BinPlace.linear();
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_TRUE(R.isApprox(q.toRotationMatrix(), 1e-12));
}

TEST(ValidatePlanPickStream, HeaderCloudMustBeEmptyAndFieldsArePrefixed) {
  const PlanningDefaults defaults;
  v1::PlanPickRequest request = ValidRequest();
  EXPECT_THAT(ErrorOf([&] { ValidatePlanPick(request, "", defaults); }),
              AllOf(HasSubstr("header.request.cloud.xyz"), HasSubstr("36 bytes")));
  const std::string bytes = request.cloud().xyz();
  request.mutable_cloud()->clear_xyz();
  const PlanningJob job = ValidatePlanPick(request, bytes, defaults);
  EXPECT_EQ(job.xyz_Sensor.size(), 36u);
  EXPECT_EQ(job.xyz_Sensor.data(), bytes.data());
  EXPECT_EQ(job.seed, 17u);

  request.mutable_cell()->set_tube_radius(-1.0);
  EXPECT_THAT(ErrorOf([&] { ValidatePlanPick(request, bytes, defaults); }),
              HasSubstr("header.request.cell.tube_radius"));
  request = ValidRequest();
  request.mutable_cloud()->clear_xyz();
  EXPECT_THAT(ErrorOf([&] { ValidatePlanPick(request, bytes.substr(0, 30), defaults); }),
              AllOf(HasSubstr("30 bytes"), HasSubstr("multiple of 12")));
}

// ---- AnalyzeWrench ------------------------------------------------------------------------------

void SetVector(v1::Vector3* v, double x, double y, double z) {
  v->set_x(x);
  v->set_y(y);
  v->set_z(z);
}

// The TCP of a vertical grasp: z (approach) down, yawed by `yaw` about the bin's z.
Eigen::Quaterniond GraspOrientation(double yaw) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
}

v1::AnalyzeWrenchRequest ValidWrenchRequest() {
  v1::AnalyzeWrenchRequest r;
  SetVector(r.mutable_reference()->mutable_force(), 0.1, -0.2, -12.0);
  SetVector(r.mutable_reference()->mutable_torque(), 0.01, 0.02, 0.0);
  SetVector(r.mutable_current()->mutable_force(), 0.1, -0.2, -11.4);
  SetVector(r.mutable_current()->mutable_torque(), 0.05, -0.03, 0.001);
  SetPose(r.mutable_tcp_pose(), {0.1, 0.05, 0.3}, GraspOrientation(0.4));
  return r;
}

struct WrenchCase {
  std::string name;
  std::function<void(v1::AnalyzeWrenchRequest&)> mutate;
  std::vector<std::string> expected;
};

std::vector<WrenchCase> WrenchCases() {
  return {
      {"ReferenceRequired", [](auto& r) { r.clear_reference(); }, {"reference", "required"}},
      {"CurrentRequired", [](auto& r) { r.clear_current(); }, {"current", "required"}},
      {"ReferenceForceNaN",
       [](auto& r) { r.mutable_reference()->mutable_force()->set_x(kNaN); },
       {"reference.force.x", "finite", "nan"}},
      {"ReferenceTorqueInfinite",
       [](auto& r) { r.mutable_reference()->mutable_torque()->set_y(kInf); },
       {"reference.torque.y", "inf"}},
      {"CurrentForceNaN",
       [](auto& r) { r.mutable_current()->mutable_force()->set_z(kNaN); },
       {"current.force.z", "finite"}},
      {"CurrentTorqueInfinite",
       [](auto& r) { r.mutable_current()->mutable_torque()->set_z(-kInf); },
       {"current.torque.z", "-inf"}},
      {"TubeMassZero", [](auto& r) { r.set_tube_mass(0.0); }, {"tube_mass", "0 kg", "out of range"}},
      {"TubeMassNegative", [](auto& r) { r.set_tube_mass(-0.05); }, {"tube_mass", "-0.05 kg"}},
      {"TubeMassAbsurd", [](auto& r) { r.set_tube_mass(120.0); }, {"tube_mass", "120 kg"}},
      {"TubeMassNaN", [](auto& r) { r.set_tube_mass(kNaN); }, {"tube_mass", "finite"}},
      {"TubeLighterThanForceTolerance",
       [](auto& r) { r.set_tube_mass(0.02); },
       {"tube_mass", "0.02 kg", "0.1962 N", "force_tolerance 0.25"}},
      {"TcpPoseRequired", [](auto& r) { r.clear_tcp_pose(); }, {"tcp_pose", "required"}},
      {"TcpOrientationAbsent",
       [](auto& r) { r.mutable_tcp_pose()->clear_orientation(); },
       {"tcp_pose.orientation", "|q| = 0"}},
      {"TcpOrientationNotUnit",
       [](auto& r) { r.mutable_tcp_pose()->mutable_orientation()->set_w(0.5); },
       {"tcp_pose.orientation", "not unit"}},
      {"TcpPositionNaN",
       [](auto& r) { r.mutable_tcp_pose()->mutable_position()->set_y(kNaN); },
       {"tcp_pose.position.y", "finite"}},
      {"TcpTilted",
       [](auto& r) {
         SetPose(r.mutable_tcp_pose(), {0, 0, 0.3},
                 Eigen::Quaterniond(Eigen::AngleAxisd(40.0 * M_PI / 180.0, Eigen::Vector3d::UnitY())) *
                     GraspOrientation(0.0));
       },
       {"tcp_pose.orientation", "40.0 deg", "max_tilt 35.0 deg", "vertical"}},
      {"UnknownVariant",
       [](auto& r) { r.set_variant(static_cast<v1::ResolutionVariant>(9)); },
       {"variant", "9"}},
  };
}

class AnalyzeWrenchRule : public ::testing::TestWithParam<WrenchCase> {};

TEST_P(AnalyzeWrenchRule, MessageNamesTheField) {
  const PlanningDefaults defaults;
  v1::AnalyzeWrenchRequest request = ValidWrenchRequest();
  ASSERT_NO_THROW(ValidateAnalyzeWrench(request, defaults));
  GetParam().mutate(request);
  const std::string message = ErrorOf([&] { ValidateAnalyzeWrench(request, defaults); });
  for (const std::string& part : GetParam().expected) EXPECT_THAT(message, HasSubstr(part));
}

INSTANTIATE_TEST_SUITE_P(Rules, AnalyzeWrenchRule, ::testing::ValuesIn(WrenchCases()),
                         [](const auto& info) { return info.param.name; });

TEST(ValidateAnalyzeWrench, UpIsTheBinVerticalInTheTcpFrame) {
  const PlanningDefaults defaults;
  v1::AnalyzeWrenchRequest request = ValidWrenchRequest();
  // A grasp TCP (z down), yawed: up = (0, 0, −1).
  WrenchJob job = ValidateAnalyzeWrench(request, defaults);
  EXPECT_LT((job.params.up_Tcp - Eigen::Vector3d(0, 0, -1)).norm(), 1e-12);
  EXPECT_NEAR(job.X_BinTcp.translation().x(), 0.1, 1e-15);
  // A TCP aligned with the bin (the thesis sensor, z up): up = (0, 0, 1).
  SetPose(request.mutable_tcp_pose(), {0, 0, 0.3}, Eigen::Quaterniond::Identity());
  job = ValidateAnalyzeWrench(request, defaults);
  EXPECT_LT((job.params.up_Tcp - Eigen::Vector3d(0, 0, 1)).norm(), 1e-12);
  // 10° off vertical about the bin's y: up = R^T z, 10° from −z in the TCP frame.
  const Eigen::Quaterniond tilted =
      Eigen::Quaterniond(Eigen::AngleAxisd(10.0 * M_PI / 180.0, Eigen::Vector3d::UnitY())) *
      GraspOrientation(0);
  SetPose(request.mutable_tcp_pose(), {0, 0, 0.3}, tilted);
  job = ValidateAnalyzeWrench(request, defaults);
  const Eigen::Vector3d expected = tilted.toRotationMatrix().transpose() * Eigen::Vector3d::UnitZ();
  EXPECT_LT((job.params.up_Tcp - expected).norm(), 1e-12);
  EXPECT_NEAR(std::acos(-job.params.up_Tcp.z()), 10.0 * M_PI / 180.0, 1e-9);
  // The TCP-frame joint-safe axis is re-projected onto this horizontal plane.
  EXPECT_NEAR(job.params.joint_safe_axis.dot(job.params.up_Tcp), 0.0, 1e-12);
  EXPECT_NEAR(job.params.joint_safe_axis.norm(), 1.0, 1e-12);
}

TEST(ValidateAnalyzeWrench, DefaultsComeFromTheCellAndTheProfile) {
  PlanningDefaults defaults;
  defaults.cell.tube.mass = 0.07;
  defaults.profile = "thesis";
  defaults.profiles["thesis"].wrench.force_tolerance = 0.3;
  defaults.profiles["thesis"].wrench.variant = ResolutionVariant::kPerpendicular;
  v1::AnalyzeWrenchRequest request = ValidWrenchRequest();
  WrenchJob job = ValidateAnalyzeWrench(request, defaults);
  EXPECT_EQ(job.tube_mass, 0.07);
  EXPECT_EQ(job.params.force_tolerance, 0.3);
  EXPECT_EQ(job.params.variant, ResolutionVariant::kPerpendicular);
  EXPECT_EQ(job.reference.force, Eigen::Vector3d(0.1, -0.2, -12.0));
  EXPECT_EQ(job.current.torque, Eigen::Vector3d(0.05, -0.03, 0.001));

  request.set_tube_mass(0.055);
  request.set_variant(v1::RESOLUTION_VARIANT_JOINT_SAFE);
  job = ValidateAnalyzeWrench(request, defaults);
  EXPECT_EQ(job.tube_mass, 0.055);
  EXPECT_EQ(job.params.variant, ResolutionVariant::kJointSafe);
  request.set_variant(v1::RESOLUTION_VARIANT_TORQUE_AXIS_NEGATIVE);
  EXPECT_EQ(ValidateAnalyzeWrench(request, defaults).params.variant, ResolutionVariant::kTorqueAxisNegative);

  // The cell's mass is checked against the force tolerance too, and the message says where it came from.
  defaults.cell.tube.mass = 0.02;
  request.clear_tube_mass();
  EXPECT_THAT(ErrorOf([&] { ValidateAnalyzeWrench(request, defaults); }),
              AllOf(HasSubstr("tube_mass"), HasSubstr("server's cell")));
}

}  // namespace
}  // namespace tubepick::server
