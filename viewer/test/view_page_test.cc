#include "viewer/view_page.h"

#include <cstring>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/common/errors.h"

namespace tubepick::viewer {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

TEST(Base64, MatchesRfc4648Vectors) {
  EXPECT_EQ(Base64(""), "");
  EXPECT_EQ(Base64("f"), "Zg==");
  EXPECT_EQ(Base64("fo"), "Zm8=");
  EXPECT_EQ(Base64("foo"), "Zm9v");
  EXPECT_EQ(Base64("foob"), "Zm9vYg==");
  EXPECT_EQ(Base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(Base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(Base64(std::string("\xff\x00\x80", 3)), "/wCA");
}

TEST(ThinToBin, KeepsEveryKthFinitePointInTheBinFrameInMetres) {
  Points points_Sensor;
  for (int i = 0; i < 1000; ++i) points_Sensor.emplace_back(float(i), 0.0f, 1000.0f);
  points_Sensor[10] = Eigen::Vector3f(NAN, 0, 0);
  Eigen::Isometry3d X_BinSensor = Eigen::Isometry3d::Identity();
  X_BinSensor.translation() = Eigen::Vector3d(0.0, 0.0, 1.1);
  X_BinSensor.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const ViewCloud cloud = ThinToBin(points_Sensor, LengthUnit::kMillimetre, X_BinSensor, 300);
  // stride ceil(1000 / 300) = 4: points 0, 4, ..., 996 (250), none of them the NaN at 10.
  EXPECT_EQ(cloud.total_points, 1000u);
  ASSERT_EQ(cloud.size(), 250u);
  EXPECT_FLOAT_EQ(cloud.xyz_Bin[3 * 1 + 0], 0.004f);
  EXPECT_NEAR(cloud.xyz_Bin[3 * 1 + 2], 0.1f, 1e-6);  // 1.1 m − 1000 mm
  const ViewCloud with_nan = ThinToBin(points_Sensor, LengthUnit::kMillimetre, X_BinSensor, 500);
  EXPECT_EQ(with_nan.size(), 499u);  // stride 2: 500 points, the NaN at 10 dropped
  EXPECT_THROW(ThinToBin(points_Sensor, LengthUnit::kMetre, X_BinSensor, 0), InvalidArgument);
}

TEST(ThinToBin, PackedBytesGiveTheSamePointsAsDecodedOnes) {
  Points points_Sensor;
  for (int i = 0; i < 77; ++i) points_Sensor.emplace_back(0.01f * i, -0.02f * i, 0.9f);
  std::string bytes(points_Sensor.size() * 12, '\0');
  std::memcpy(bytes.data(), points_Sensor.data(), bytes.size());
  const Eigen::Isometry3d X = CellConfig().sensor.X_BinSensor;
  EXPECT_EQ(ThinToBin(PackedXyz{bytes}, LengthUnit::kMetre, X, 10).xyz_Bin,
            ThinToBin(points_Sensor, LengthUnit::kMetre, X, 10).xyz_Bin);
}

ViewPage SamplePage() {
  ViewPage page;
  page.title = "bin <3> & co";
  page.source = "test";
  ViewFrame frame;
  frame.label = "scan 1";
  frame.note = "</script><!-- <script>";
  frame.chosen_plan = 0;
  frame.cloud = ViewCloud{{0.1f, 0.2f, 0.3f, -0.1f, 0.0f, 0.05f}, 9};
  v1::PlanPickResponse plan;
  plan.add_tubes()->set_id(4);
  plan.add_tubes()->set_id(7);
  plan.add_plans()->set_tube_id(7);
  frame.plan = plan;
  page.frames.push_back(frame);
  ViewFrame failed;
  failed.label = "scan 2";
  failed.error = "FAILED_PRECONDITION: the cloud looks like millimetres";
  page.frames.push_back(failed);
  return page;
}

TEST(PageDataJson, HoldsTheCellTheFramesTheResponsesAndTheCloud) {
  const nlohmann::json data = nlohmann::json::parse(PageDataJson(SamplePage()));
  EXPECT_EQ(data["format"], "tubepick-view/1");
  EXPECT_EQ(data["cell"]["bin"]["inner_size"][0], 0.80);
  EXPECT_EQ(data["cell"]["gripper"]["finger_size"][2], 0.05);
  ASSERT_EQ(data["frames"].size(), 2u);
  const nlohmann::json& f = data["frames"][0];
  EXPECT_EQ(f["chosen_plan"], 0);
  EXPECT_EQ(f["plan"]["tubes"].size(), 2u);
  EXPECT_EQ(f["plan"]["plans"][0]["tubeId"], 7);
  EXPECT_EQ(f["cloud"]["points"], 2);
  EXPECT_EQ(f["cloud"]["total_points"], 9);
  // 6 floats = 24 bytes = 32 base64 characters; the first float 0.1f is CD CC CC 3D.
  EXPECT_EQ(f["cloud"]["xyz"].get<std::string>().size(), 32u);
  EXPECT_EQ(f["cloud"]["xyz"].get<std::string>().substr(0, 4), "zczM");
  EXPECT_EQ(data["frames"][1]["error"], "FAILED_PRECONDITION: the cloud looks like millimetres");
  EXPECT_FALSE(data["frames"][1].contains("cloud"));
}

TEST(PageHtml, TextFromTheDataCannotEndTheScriptElement) {
  const std::string html = PageHtml(SamplePage());
  EXPECT_THAT(html, HasSubstr("<title>bin &lt;3&gt; &amp; co</title>"));
  const std::size_t open = html.find("<script type=\"application/json\" id=\"tubepick-data\">");
  ASSERT_NE(open, std::string::npos);
  const std::size_t body = html.find('>', open) + 1;
  const std::size_t close = html.find("</script>", body);
  const std::string data = html.substr(body, close - body);
  EXPECT_THAT(data, Not(HasSubstr("<")));
  EXPECT_EQ(nlohmann::json::parse(data)["frames"][0]["note"], "</script><!-- <script>");
  // The bundled script follows, whole.
  EXPECT_GT(ViewerBundle().size(), 10000u);
  EXPECT_THAT(html, HasSubstr(std::string(ViewerBundle().substr(0, 200))));
}

}  // namespace
}  // namespace tubepick::viewer
