#include "clients/cli/cell/round_view.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "wire/proto_convert.h"

namespace tubepick::cli {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// Answers PlanPick from a queue: a response, or a PlannerError when `fail` is set.
class QueuePlanner final : public cell::PlannerClient {
 public:
  struct Answer {
    v1::PlanPickResponse response;
    bool fail = false;
  };
  std::deque<Answer> answers;
  int cancels = 0;

  v1::PlanPickResponse PlanPick(const v1::PlanPickRequest&, std::chrono::milliseconds) override {
    Answer a = answers.front();
    answers.pop_front();
    if (a.fail) throw cell::PlannerError("PlanPick", grpc::StatusCode::UNAVAILABLE, "planner gone", 3);
    return a.response;
  }
  v1::AnalyzeWrenchResponse AnalyzeWrench(const v1::AnalyzeWrenchRequest&,
                                          std::chrono::milliseconds) override {
    return {};
  }
  void CancelCalls() override { ++cancels; }
};

v1::PlanPickRequest Request(int points) {
  Points cloud;
  for (int i = 0; i < points; ++i) cloud.emplace_back(0.001f * i, 0.0f, 1.0f);
  v1::PlanPickRequest request;
  std::string bytes(cloud.size() * 12, '\0');
  std::memcpy(bytes.data(), cloud.data(), bytes.size());
  request.mutable_cloud()->set_xyz(bytes);
  *request.mutable_cell() = ToCellDescription(CellConfig{}, CellConfig{}.sensor.X_BinSensor);
  return request;
}

v1::PlanPickResponse Plans(int tubes, int plans) {
  v1::PlanPickResponse r;
  for (int t = 0; t < tubes; ++t) r.add_tubes()->set_id(static_cast<std::uint32_t>(t));
  for (int p = 0; p < plans; ++p) r.add_plans()->set_tube_id(static_cast<std::uint32_t>(p % tubes));
  return r;
}

nlohmann::json PageData(const fs::path& page) {
  std::ifstream in(page);
  std::stringstream text;
  text << in.rdbuf();
  const std::string html = text.str();
  const std::string open = "id=\"tubepick-data\">";
  const std::size_t begin = html.find(open) + open.size();
  return nlohmann::json::parse(html.substr(begin, html.find("</script>", begin) - begin));
}

TEST(RoundViewRecorder, APageStepsThroughTheRoundsScansWithThePickAndItsOutcome) {
  const fs::path dir = fs::temp_directory_path() / "tubepick_round_view_test";
  fs::remove_all(dir);
  QueuePlanner planner;
  planner.answers = {{Plans(3, 5)}, {Plans(2, 4)}, {{}, true}};
  cell::MemoryRecordSink memory;
  RoundViewRecorder view(planner, memory, dir.string(), 100, ToolParams{});

  EXPECT_EQ(view.PlanPick(Request(1000), std::chrono::seconds(1)).plans_size(), 5);
  view.Write({{"type", "attempt"},
              {"round", 2},
              {"attempt", 1},
              {"plan_rank", 1},
              {"tube", 1},
              {"trajectory_kind", "upward"},
              {"result", "picked"},
              {"analysis", {{"outcome", "single"}}}});
  view.PlanPick(Request(50), std::chrono::seconds(1));
  EXPECT_THROW(view.PlanPick(Request(50), std::chrono::seconds(1)), cell::PlannerError);
  view.Write({{"type", "safe_stop"}, {"round", 2}, {"reason", "fault"}, {"message", "planner unreachable"}});
  view.CancelCalls();
  EXPECT_EQ(planner.cancels, 1);
  EXPECT_TRUE(view.pages().empty());
  view.Write({{"type", "end"}, {"round", 2}, {"message", "safe stop"}});

  // Every record went on unchanged; the round's page holds one frame per PlanPick.
  EXPECT_EQ(memory.records().size(), 3u);
  ASSERT_EQ(view.pages().size(), 1u);
  EXPECT_EQ(fs::path(view.pages()[0]).filename(), "round_002.html");
  const nlohmann::json data = PageData(view.pages()[0]);
  ASSERT_EQ(data["frames"].size(), 3u);
  const nlohmann::json& first = data["frames"][0];
  EXPECT_EQ(first["label"], "scan 1");
  EXPECT_EQ(first["chosen_plan"], 1);
  EXPECT_EQ(first["plan"]["plans"].size(), 5u);
  EXPECT_EQ(first["cloud"]["points"], 100);  // 1000 points thinned to 100
  EXPECT_EQ(first["cloud"]["total_points"], 1000);
  EXPECT_THAT(first["note"].get<std::string>(), HasSubstr("attempt 1: plan #2 (tube 1, upward) → picked"));
  EXPECT_THAT(first["note"].get<std::string>(), HasSubstr("lifted: single"));
  EXPECT_FALSE(data["frames"][1].contains("chosen_plan"));
  const nlohmann::json& failed = data["frames"][2];
  EXPECT_THAT(failed["error"].get<std::string>(), HasSubstr("planner gone"));
  EXPECT_THAT(failed["note"].get<std::string>(), HasSubstr("safe stop (fault): planner unreachable"));
  EXPECT_EQ(failed["cloud"]["points"], 50);

  // The next round starts with no frames of this one.
  planner.answers = {{Plans(1, 1)}};
  view.PlanPick(Request(10), std::chrono::seconds(1));
  view.Write({{"type", "end"}, {"round", 3}, {"message", "bin empty"}});
  EXPECT_EQ(PageData(view.pages()[1])["frames"].size(), 1u);
  fs::remove_all(dir);
}

TEST(RoundViewRecorder, AScanWithoutAPlanNotesTheNudgeAndChoosesNoPlan) {
  // The record the controller writes for a scan without a plan: "attempt" is null. The page's note
  // once read it as a number and threw, which stopped the cell (a safe stop with nothing held).
  const fs::path dir = fs::temp_directory_path() / "tubepick_round_view_nudge_test";
  fs::remove_all(dir);
  QueuePlanner planner;
  planner.answers = {{Plans(1, 0)}, {Plans(1, 2)}};
  cell::MemoryRecordSink memory;
  RoundViewRecorder view(planner, memory, dir.string(), 100, ToolParams{});

  view.PlanPick(Request(100), std::chrono::seconds(1));
  EXPECT_NO_THROW(view.Write({{"type", "attempt"},
                              {"round", 0},
                              {"attempt", nullptr},
                              {"plan_rank", 0},
                              {"plans", 0},
                              {"skipped_plans", nlohmann::json::array()},
                              {"result", "nudge"},
                              {"nudge", {{"tube", 3}}}}));
  view.PlanPick(Request(100), std::chrono::seconds(1));
  view.Write({{"type", "attempt"},
              {"round", 0},
              {"attempt", nullptr},
              {"plan_rank", 0},
              {"plans", 2},
              {"skipped_plans", nlohmann::json::array({{{"rank", 0}}, {{"rank", 1}}})},
              {"result", "no_plan"}});
  view.Write({{"type", "end"}, {"round", 0}, {"message", "attempt limit"}});

  EXPECT_EQ(memory.records().size(), 3u);
  const nlohmann::json data = PageData(view.pages().at(0));
  ASSERT_EQ(data["frames"].size(), 2u);
  EXPECT_EQ(data["frames"][0]["note"], "no plan, nudged tube 3");
  EXPECT_FALSE(data["frames"][0].contains("chosen_plan"));
  EXPECT_EQ(data["frames"][1]["note"], "no plan (2 of 2 skipped)");
  EXPECT_FALSE(data["frames"][1].contains("chosen_plan"));
  fs::remove_all(dir);
}

TEST(RoundViewRecorder, APageThatCannotBeWrittenDoesNotStopTheCell) {
  // The directory is gone when the round ends (a file stands in its place): the page is lost and
  // logged, the end record still reaches the controller's sink, and nothing is thrown.
  const fs::path dir = fs::temp_directory_path() / "tubepick_round_view_unwritable_test";
  fs::remove_all(dir);
  QueuePlanner planner;
  planner.answers = {{Plans(1, 1)}};
  cell::MemoryRecordSink memory;
  RoundViewRecorder view(planner, memory, dir.string(), 100, ToolParams{});
  view.PlanPick(Request(10), std::chrono::seconds(1));
  fs::remove_all(dir);
  std::ofstream(dir.string()) << "not a directory";
  EXPECT_NO_THROW(view.Write({{"type", "end"}, {"round", 0}, {"message", "bin empty"}}));
  EXPECT_EQ(memory.records().size(), 1u);
  EXPECT_TRUE(view.pages().empty());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace tubepick::cli
