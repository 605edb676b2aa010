// Every unary RPC of tubepick.v1.PickPlannerService against a real in-process server and a real
// gRPC client: happy paths with real numbers, request ids, and every validation error path.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "tests/service_test_support.h"

namespace tubepick::service_test {
namespace {

using ::testing::HasSubstr;
using ::testing::MatchesRegex;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

class ServiceRpc : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { server_ = new TestServer(TestConfig(2, 8)); }
  static void TearDownTestSuite() {
    delete server_;
    server_ = nullptr;
  }
  static v1::PickPlannerService::Stub& stub() { return server_->stub(); }

  static grpc::Status ModelTubes(const v1::ModelTubesRequest& request,
                                 v1::ModelTubesResponse* response = nullptr) {
    grpc::ClientContext context;
    SetTimeout(&context, std::chrono::seconds(60));
    v1::ModelTubesResponse ignored;
    return stub().ModelTubes(&context, request, response ? response : &ignored);
  }
  static grpc::Status PlanPick(const v1::PlanPickRequest& request, v1::PlanPickResponse* response = nullptr) {
    grpc::ClientContext context;
    SetTimeout(&context, std::chrono::seconds(60));
    v1::PlanPickResponse ignored;
    return stub().PlanPick(&context, request, response ? response : &ignored);
  }
  static grpc::Status AnalyzeWrench(const v1::AnalyzeWrenchRequest& request,
                                    v1::AnalyzeWrenchResponse* response = nullptr) {
    grpc::ClientContext context;
    SetTimeout(&context, std::chrono::seconds(10));
    v1::AnalyzeWrenchResponse ignored;
    return stub().AnalyzeWrench(&context, request, response ? response : &ignored);
  }

  static TestServer* server_;
};

TestServer* ServiceRpc::server_ = nullptr;

void SetVector(v1::Vector3* v, double x, double y, double z) {
  v->set_x(x);
  v->set_y(y);
  v->set_z(z);
}

void SetPose(v1::Pose* pose, double x, double y, double z, double qx, double qy, double qz, double qw) {
  SetVector(pose->mutable_position(), x, y, z);
  pose->mutable_orientation()->set_x(qx);
  pose->mutable_orientation()->set_y(qy);
  pose->mutable_orientation()->set_z(qz);
  pose->mutable_orientation()->set_w(qw);
}

// The default cell, spelled out as a request's CellDescription.
v1::CellDescription DefaultCell() {
  v1::CellDescription cell;
  SetVector(cell.mutable_bin_inner_size(), 0.8, 0.6, 0.2);
  SetPose(cell.mutable_sensor_pose(), 0.0, 0.0, 1.1, 1.0, 0.0, 0.0, 0.0);
  cell.set_tube_radius(0.0125);
  cell.set_tube_length(0.5);
  cell.set_tube_mass(0.055);
  SetPose(cell.mutable_place_pose(), 0.0, 0.8, 0.1, 0.0, 0.0, 0.0, 1.0);
  return cell;
}

// One F/T lift with a TCP pointing down (z along the approach), reference reading zero: the payload
// of n tubes pulls along +z_Tcp with n·m·g, and a torque about x when tubes hang off-centre.
v1::AnalyzeWrenchRequest WrenchRequest(double tubes_held, double torque_x = 0.0) {
  v1::AnalyzeWrenchRequest request;
  SetVector(request.mutable_reference()->mutable_force(), 0.0, 0.0, 0.0);
  SetVector(request.mutable_reference()->mutable_torque(), 0.0, 0.0, 0.0);
  SetVector(request.mutable_current()->mutable_force(), 0.0, 0.0, tubes_held * 0.055 * 9.81);
  SetVector(request.mutable_current()->mutable_torque(), torque_x, 0.0, 0.0);
  request.set_tube_mass(0.055);
  SetPose(request.mutable_tcp_pose(), 0.1, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0);
  return request;
}

void ExpectInvalid(const grpc::Status& status, const std::string& field, const std::string& reason = "") {
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr(field));
  if (!reason.empty()) {
    EXPECT_THAT(status.error_message(), HasSubstr(reason));
  }
}

// --- happy paths ----------------------------------------------------------------------------------

TEST_F(ServiceRpc, ModelTubesFindsTheThreeTubes) {
  v1::ModelTubesResponse response;
  const grpc::Status status = ModelTubes(ModelRequest(ThreeTubeCloud()), &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(response.tubes_size(), 3);
  // Longest first: the rendered tubes are 0.50, 0.48 and 0.46 m long.
  const double expected[] = {0.50, 0.48, 0.46};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(response.tubes(i).length(), expected[i], 0.05 * expected[i]) << "tube " << i;
    ASSERT_GE(response.tubes(i).cylinders_size(), 1);
    EXPECT_NEAR(response.tubes(i).cylinders(0).radius(), 0.0125, 0.0015);
  }
  EXPECT_EQ(response.input_points(), ThreeTubeCloud().size() / 12);
  EXPECT_GT(response.max_height(), 0.02);
  EXPECT_LT(response.max_height(), 0.03);
  EXPECT_EQ(response.profile(), "fast");
  EXPECT_EQ(response.seed(), 7u);
  EXPECT_GT(response.total_seconds(), 0.0);
}

TEST_F(ServiceRpc, PlanPickRanksPlansByCost) {
  v1::PlanPickResponse response;
  const grpc::Status status = PlanPick(PlanRequest(ThreeTubeCloud()), &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.tubes_size(), 3);
  EXPECT_FALSE(response.bin_empty());
  EXPECT_FALSE(response.used_simulation());
  // The modeling summary travels along; its tubes are the classified ones above.
  EXPECT_EQ(response.modeling().input_points(), ThreeTubeCloud().size() / 12);
  EXPECT_EQ(response.modeling().profile(), "fast");
  ASSERT_GE(response.plans_size(), 3);
  for (int i = 0; i < response.plans_size(); ++i) {
    const v1::PickPlan& plan = response.plans(i);
    if (i > 0) {
      EXPECT_LE(response.plans(i - 1).cost().total(), plan.cost().total()) << "plan " << i;
    }
    EXPECT_GE(plan.cost().total(), 0.0);
    EXPECT_LE(plan.cost().total(), 1.0);
    // Nothing lies on these tubes: straight up, no simulated displacement.
    EXPECT_EQ(plan.trajectory_kind(), v1::TRAJECTORY_KIND_UPWARD);
    EXPECT_EQ(plan.simulated_displacement(), 0.0);
    EXPECT_LT(std::abs(plan.grasp().tcp_pose().position().x()), 0.4);
    EXPECT_LT(std::abs(plan.grasp().tcp_pose().position().y()), 0.3);
    EXPECT_TRUE(plan.has_place_tcp_pose());
  }
  // max_plans truncates the same ranking.
  v1::PlanPickRequest two = PlanRequest(ThreeTubeCloud());
  two.mutable_options()->set_max_plans(2);
  v1::PlanPickResponse truncated;
  ASSERT_TRUE(PlanPick(two, &truncated).ok());
  ASSERT_EQ(truncated.plans_size(), 2);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(truncated.plans(i).tube_id(), response.plans(i).tube_id());
    EXPECT_DOUBLE_EQ(truncated.plans(i).cost().total(), response.plans(i).cost().total());
  }
}

TEST_F(ServiceRpc, SameRequestSameAnswer) {
  v1::PlanPickResponse a, b;
  ASSERT_TRUE(PlanPick(PlanRequest(ThreeTubeCloud()), &a).ok());
  ASSERT_TRUE(PlanPick(PlanRequest(ThreeTubeCloud()), &b).ok());
  ASSERT_EQ(a.plans_size(), b.plans_size());
  for (int i = 0; i < a.plans_size(); ++i) {
    EXPECT_EQ(a.plans(i).tube_id(), b.plans(i).tube_id());
    EXPECT_EQ(a.plans(i).cost().total(), b.plans(i).cost().total());
  }
}

TEST_F(ServiceRpc, AnalyzeWrenchCountsTubes) {
  v1::AnalyzeWrenchResponse none, single, multiple;
  ASSERT_TRUE(AnalyzeWrench(WrenchRequest(0.0), &none).ok());
  EXPECT_EQ(none.outcome(), v1::HELD_OUTCOME_NONE);
  EXPECT_EQ(none.estimated_count(), 0u);

  ASSERT_TRUE(AnalyzeWrench(WrenchRequest(1.0), &single).ok());
  EXPECT_EQ(single.outcome(), v1::HELD_OUTCOME_SINGLE);
  EXPECT_EQ(single.estimated_count(), 1u);
  EXPECT_NEAR(single.tube_weight(), 0.055 * 9.81, 1e-9);
  EXPECT_NEAR(single.held_weight(), 0.055 * 9.81, 1e-9);
  EXPECT_NEAR(single.tube_ratio(), 1.0, 1e-9);
  EXPECT_EQ(single.resolution_motions_size(), 0);

  ASSERT_TRUE(AnalyzeWrench(WrenchRequest(3.0, 0.05), &multiple).ok());
  EXPECT_EQ(multiple.outcome(), v1::HELD_OUTCOME_MULTIPLE);
  EXPECT_EQ(multiple.estimated_count(), 3u);
  EXPECT_NEAR(multiple.tube_ratio(), 3.0, 1e-9);
  ASSERT_GE(multiple.resolution_motions_size(), 1);
  EXPECT_NEAR(std::abs(multiple.resolution_motions(0).angle()), 55.0 * M_PI / 180.0, 1e-9);  // fast profile
  EXPECT_GE(multiple.resolution_motions(0).waypoints_size(), 1);
  EXPECT_NEAR(multiple.delta_torque_tcp().x(), 0.05, 1e-9);
}

TEST_F(ServiceRpc, EchoesTheClientsRequestId) {
  grpc::ClientContext context;
  context.AddMetadata("x-request-id", "cell-7-pick-42");
  v1::AnalyzeWrenchResponse response;
  ASSERT_TRUE(stub().AnalyzeWrench(&context, WrenchRequest(1.0), &response).ok());
  const auto& metadata = context.GetServerInitialMetadata();
  const auto it = metadata.find("x-request-id");
  ASSERT_NE(it, metadata.end());
  EXPECT_EQ(std::string(it->second.data(), it->second.size()), "cell-7-pick-42");
}

TEST_F(ServiceRpc, GeneratesARequestIdAlsoForErrors) {
  grpc::ClientContext context;
  v1::ModelTubesResponse response;
  v1::ModelTubesRequest request = ModelRequest(std::string(13, '\0'));
  ASSERT_EQ(stub().ModelTubes(&context, request, &response).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  const auto& metadata = context.GetServerInitialMetadata();
  const auto it = metadata.find("x-request-id");
  ASSERT_NE(it, metadata.end());
  EXPECT_THAT(std::string(it->second.data(), it->second.size()), MatchesRegex("[0-9a-f]{16}"));
}

// --- error paths -----------------------------------------------------------------------------------

TEST_F(ServiceRpc, CloudLengthNotAMultipleOf12IsInvalid) {
  ExpectInvalid(ModelTubes(ModelRequest(std::string(12 * 100 + 5, '\0'))), "cloud.xyz", "multiple of 12");
  ExpectInvalid(PlanPick(PlanRequest(std::string(7, '\0'))), "cloud.xyz", "multiple of 12");
}

TEST_F(ServiceRpc, EmptyCloudIsInvalid) {
  ExpectInvalid(ModelTubes(ModelRequest("")), "cloud.xyz", "empty");
  ExpectInvalid(PlanPick(PlanRequest("")), "cloud.xyz", "empty");
}

TEST_F(ServiceRpc, UnknownUnitIsInvalid) {
  v1::ModelTubesRequest request = ModelRequest(ThreeTubeCloud());
  request.mutable_cloud()->set_unit(static_cast<v1::LengthUnit>(7));
  ExpectInvalid(ModelTubes(request), "cloud.unit", "7");
}

TEST_F(ServiceRpc, UnknownProfileIsInvalid) {
  v1::PlanPickRequest request = PlanRequest(ThreeTubeCloud());
  request.mutable_options()->set_profile("turbo");
  ExpectInvalid(PlanPick(request), "options.profile", "turbo");
}

TEST_F(ServiceRpc, OutOfRangeTubeRadiusAndMassAreInvalid) {
  v1::PlanPickRequest request = PlanRequest(ThreeTubeCloud());
  *request.mutable_cell() = DefaultCell();
  request.mutable_cell()->set_tube_radius(0.7);
  ExpectInvalid(PlanPick(request), "cell.tube_radius", "0.7");
  request.mutable_cell()->set_tube_radius(0.0);
  ExpectInvalid(PlanPick(request), "cell.tube_radius");

  *request.mutable_cell() = DefaultCell();
  request.mutable_cell()->set_tube_mass(-1.0);
  ExpectInvalid(PlanPick(request), "cell.tube_mass", "-1");
  request.mutable_cell()->set_tube_mass(1000.0);
  ExpectInvalid(PlanPick(request), "cell.tube_mass", "1000");

  v1::AnalyzeWrenchRequest wrench = WrenchRequest(1.0);
  wrench.set_tube_mass(0.0);
  ExpectInvalid(AnalyzeWrench(wrench), "tube_mass");
}

TEST_F(ServiceRpc, NonFiniteNumbersAreInvalid) {
  v1::PlanPickRequest request = PlanRequest(ThreeTubeCloud());
  *request.mutable_cell() = DefaultCell();
  request.mutable_cell()->set_tube_radius(kNaN);
  ExpectInvalid(PlanPick(request), "cell.tube_radius");

  *request.mutable_cell() = DefaultCell();
  request.mutable_cell()->mutable_sensor_pose()->mutable_position()->set_x(
      std::numeric_limits<double>::infinity());
  ExpectInvalid(PlanPick(request), "cell.sensor_pose");

  v1::AnalyzeWrenchRequest wrench = WrenchRequest(1.0);
  wrench.mutable_current()->mutable_force()->set_z(kNaN);
  ExpectInvalid(AnalyzeWrench(wrench), "current.force");
}

TEST_F(ServiceRpc, ACellMissingFieldsIsInvalid) {
  v1::ModelTubesRequest request = ModelRequest(ThreeTubeCloud());
  request.mutable_cell()->set_tube_radius(0.0125);  // present but incomplete
  ExpectInvalid(ModelTubes(request), "cell.bin_inner_size", "required");

  v1::AnalyzeWrenchRequest wrench = WrenchRequest(1.0);
  wrench.clear_tcp_pose();
  ExpectInvalid(AnalyzeWrench(wrench), "tcp_pose", "required");
}

TEST_F(ServiceRpc, AFullyGivenCellIsUsed) {
  // The same cell the server has by default, given explicitly: the same tubes.
  v1::ModelTubesRequest request = ModelRequest(ThreeTubeCloud());
  *request.mutable_cell() = DefaultCell();
  v1::ModelTubesResponse response;
  ASSERT_TRUE(ModelTubes(request, &response).ok());
  EXPECT_EQ(response.tubes_size(), 3);
}

TEST_F(ServiceRpc, ATubeLengthShorterThanTheScanShowsIsAnsweredWithAWarning) {
  // The three rendered tubes are 0.46-0.50 m long; a cell that says 0.30 m gets its tubes whole
  // (joined within the length the scan shows), and a warning with both lengths, in ModelTubes and
  // PlanPick alike, counted in the metrics by code.
  const std::string series = "tubepick_modeling_warnings_total{code=\"tube_length_shorter_than_scan\"}";
  const double before = MetricValue(ScrapeMetrics(server_->metrics_port()), series).value_or(0.0);
  v1::ModelTubesRequest model = ModelRequest(ThreeTubeCloud());
  *model.mutable_cell() = DefaultCell();
  model.mutable_cell()->set_tube_length(0.30);
  v1::ModelTubesResponse modeled;
  ASSERT_TRUE(ModelTubes(model, &modeled).ok());
  EXPECT_EQ(modeled.tubes_size(), 3);
  ASSERT_EQ(modeled.warnings_size(), 1);
  const v1::ModelingWarning& w = modeled.warnings(0);
  EXPECT_EQ(w.code(), "tube_length_shorter_than_scan");
  EXPECT_DOUBLE_EQ(w.stated(), 0.30);
  EXPECT_NEAR(w.observed(), 0.48, 0.03);
  EXPECT_THAT(w.message(), HasSubstr("tube.length 0.300 m"));
  EXPECT_THAT(w.message(), HasSubstr("whole curve length"));

  v1::PlanPickRequest plan = PlanRequest(ThreeTubeCloud());
  *plan.mutable_cell() = DefaultCell();
  plan.mutable_cell()->set_tube_length(0.30);
  v1::PlanPickResponse planned;
  ASSERT_TRUE(PlanPick(plan, &planned).ok());
  ASSERT_EQ(planned.modeling().warnings_size(), 1);
  EXPECT_EQ(planned.modeling().warnings(0).code(), "tube_length_shorter_than_scan");
  EXPECT_EQ(planned.tubes_size(), 3);
  EXPECT_EQ(MetricValue(ScrapeMetrics(server_->metrics_port()), series).value_or(0.0), before + 2.0);

  // The right length: no warning.
  model.mutable_cell()->set_tube_length(0.50);
  ASSERT_TRUE(ModelTubes(model, &modeled).ok());
  EXPECT_EQ(modeled.warnings_size(), 0);
}

TEST_F(ServiceRpc, ACellRadiusTheModelingCannotFitIsInvalidAndOneTheScanDoesNotShowIsWarned) {
  v1::ModelTubesRequest request = ModelRequest(ThreeTubeCloud());
  *request.mutable_cell() = DefaultCell();
  request.mutable_cell()->set_tube_radius(0.020);  // the fast profile fits 7-18 mm
  ExpectInvalid(ModelTubes(request), "tube.radius: 0.0200 m", "outside the radii the modeling fits");
  request.mutable_cell()->set_tube_radius(0.009);  // the rendered tubes are 12.5 mm
  v1::ModelTubesResponse response;
  ASSERT_TRUE(ModelTubes(request, &response).ok());
  EXPECT_EQ(response.tubes_size(), 3);
  ASSERT_EQ(response.warnings_size(), 1);
  EXPECT_EQ(response.warnings(0).code(), "tube_radius_differs_from_scan");
  EXPECT_NEAR(response.warnings(0).observed(), 0.0125, 0.001);
}

TEST_F(ServiceRpc, ACellWhoseBinIsLargerThanTheScannedOneIsAFailedPrecondition) {
  // BusyBinCloud scans the 0.8 x 0.6 m bin with its walls; a cell of 1.0 x 0.8 m would model them.
  v1::PlanPickRequest request = PlanRequest(BusyBinCloud());
  *request.mutable_cell() = DefaultCell();
  SetVector(request.mutable_cell()->mutable_bin_inner_size(), 1.0, 0.8, 0.2);
  const grpc::Status status = PlanPick(request);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << status.error_message();
  EXPECT_THAT(status.error_message(),
              HasSubstr("cloud does not fit the cell's bin: the -x wall at x = -0.40"));
  EXPECT_THAT(status.error_message(), HasSubstr("Is bin.inner_size [1, 0.8, 0.2] m the bin's inner size"));
  SetVector(request.mutable_cell()->mutable_bin_inner_size(), 0.8, 0.6, 0.2);
  EXPECT_TRUE(PlanPick(request).ok());
}

TEST_F(ServiceRpc, GarbageCloudsNeverCrashTheServer) {
  // Random bytes (NaNs, infinities, 1e38 coordinates, denormals) and all-NaN clouds: each answer is
  // OK, INVALID_ARGUMENT or (a cloud that misses the bin) FAILED_PRECONDITION, never INTERNAL, and
  // the server keeps serving.
  std::mt19937_64 rng(5);
  std::vector<std::string> clouds;
  for (int i = 0; i < 3; ++i) {
    std::string bytes(12 * 5000, '\0');
    for (char& c : bytes) c = static_cast<char>(rng());
    clouds.push_back(bytes);
  }
  Points nan_points(1000, Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  clouds.push_back(PackCloud(nan_points));
  Points far_points(1000, Eigen::Vector3f(1e30f, -1e30f, 1e30f));
  clouds.push_back(PackCloud(far_points));
  for (const std::string& cloud : clouds) {
    v1::PlanPickResponse response;
    const grpc::Status status = PlanPick(PlanRequest(cloud), &response);
    EXPECT_TRUE(status.ok() || status.error_code() == grpc::StatusCode::INVALID_ARGUMENT ||
                status.error_code() == grpc::StatusCode::FAILED_PRECONDITION)
        << status.error_code() << ": " << status.error_message();
    if (status.ok()) {
      EXPECT_EQ(response.tubes_size(), 0);
    }
  }
  v1::ModelTubesResponse response;
  ASSERT_TRUE(ModelTubes(ModelRequest(ThreeTubeCloud()), &response).ok());
  EXPECT_EQ(response.tubes_size(), 3);
}

// --- clouds that do not fit the cell: FAILED_PRECONDITION, never "bin empty" -----------------------

void ExpectMisfit(const grpc::Status& status, const std::string& cause) {
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("cloud does not fit the cell: 0 of "));
  EXPECT_THAT(status.error_message(), HasSubstr(cause));
}

std::string ScaledCloud(const std::string& xyz, float factor) {
  std::string out = xyz;
  for (std::size_t i = 0; i + 4 <= out.size(); i += 4) {
    float v;
    std::memcpy(&v, out.data() + i, 4);
    v *= factor;
    std::memcpy(out.data() + i, &v, 4);
  }
  return out;
}

TEST_F(ServiceRpc, MetresSentAsMillimetresIsAFailedPrecondition) {
  v1::ModelTubesRequest model = ModelRequest(ThreeTubeCloud());
  model.mutable_cloud()->set_unit(v1::LENGTH_UNIT_MILLIMETRE);
  ExpectMisfit(ModelTubes(model), "is the unit m rather than mm");

  v1::PlanPickRequest plan = PlanRequest(ThreeTubeCloud());
  plan.mutable_cloud()->set_unit(v1::LENGTH_UNIT_MILLIMETRE);
  v1::PlanPickResponse response;
  ExpectMisfit(PlanPick(plan, &response), "is the unit m rather than mm");
  EXPECT_FALSE(response.bin_empty());
}

TEST_F(ServiceRpc, MillimetresSentAsMetresIsAFailedPrecondition) {
  const std::string mm = ScaledCloud(ThreeTubeCloud(), 1000.0f);
  ExpectMisfit(PlanPick(PlanRequest(mm)), "is the unit mm rather than m");
  v1::PlanPickRequest right = PlanRequest(mm);
  right.mutable_cloud()->set_unit(v1::LENGTH_UNIT_MILLIMETRE);
  v1::PlanPickResponse response;
  ASSERT_TRUE(PlanPick(right, &response).ok());
  EXPECT_EQ(response.tubes_size(), 3);
}

TEST_F(ServiceRpc, AWrongSensorPoseIsAFailedPrecondition) {
  v1::PlanPickRequest flipped = PlanRequest(ThreeTubeCloud());
  *flipped.mutable_cell() = DefaultCell();
  SetPose(flipped.mutable_cell()->mutable_sensor_pose(), 0.0, 0.0, 1.1, 0.0, 0.0, 0.0, 1.0);  // looks up
  ExpectMisfit(PlanPick(flipped), "is the sensor pose right (sensor.pose_in_bin, X_BinSensor)?");

  v1::ModelTubesRequest shifted = ModelRequest(ThreeTubeCloud());
  *shifted.mutable_cell() = DefaultCell();
  SetPose(shifted.mutable_cell()->mutable_sensor_pose(), 0.0, 0.0, 1.6, 1.0, 0.0, 0.0, 0.0);  // 0.5 m up
  ExpectMisfit(ModelTubes(shifted), "puts the sensor at (0.000, 0.000, 1.600) m");
}

TEST_F(ServiceRpc, AnEmptyBinIsBinEmpty) {
  v1::PlanPickResponse response;
  const grpc::Status status = PlanPick(PlanRequest(EmptyBinCloud()), &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_TRUE(response.bin_empty());
  EXPECT_EQ(response.tubes_size(), 0);
  EXPECT_EQ(response.plans_size(), 0);
}

TEST(ServiceLimits, AMessageOverTheSizeLimitIsResourceExhausted) {
  server::ServerConfig config = TestConfig(1, 2);
  config.max_message_bytes = 1 << 20;  // 1 MiB
  TestServer server(config);
  // 2.4 MB of cloud: gRPC itself refuses it before any of our code runs.
  grpc::ClientContext context;
  v1::ModelTubesResponse response;
  const grpc::Status status =
      server.stub().ModelTubes(&context, ModelRequest(std::string(12 * 200'000, '\0')), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
  // Below the limit the same server answers.
  grpc::ClientContext ok_context;
  EXPECT_TRUE(server.stub().ModelTubes(&ok_context, ModelRequest(ThreeTubeCloud()), &response).ok());
  EXPECT_EQ(response.tubes_size(), 3);
}

}  // namespace
}  // namespace tubepick::service_test
