// The evaluation report's logic: which scenes get a picture, the JSON report, SVG text escaping.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "clients/cli/eval/eval_report.h"
#include "clients/cli/eval/svg_util.h"

namespace tubepick::cli {
namespace {

using ::testing::HasSubstr;

/// A scene of `tubes` tubes with `correct` correct ones and micro-recall matched / 100.
EvaluatedScene Scene(const std::string& name, std::uint32_t tubes, std::uint32_t correct,
                     std::uint64_t matched) {
  EvaluatedScene s;
  s.name = name;
  s.tube_count = tubes;
  s.evaluation.real_tube_count = tubes;
  s.evaluation.correct = correct;
  s.evaluation.matched_points = matched;
  s.evaluation.real_points = 100;
  // No virtual tube: the confusion matrix is the null row, one column per real tube + background.
  s.evaluation.confusion = {.virtual_tubes = 0, .real_tubes = tubes, .counts = {}};
  s.evaluation.confusion.counts.assign(tubes + 1, 0);
  s.evaluation.confusion.at(0, 0) = matched;
  return s;
}

std::vector<std::string> Names(const std::vector<const EvaluatedScene*>& scenes) {
  std::vector<std::string> names;
  for (const EvaluatedScene* s : scenes) names.push_back(s->name);
  return names;
}

TEST(EvalReport, PicturesShowTheWorstAndATypicalSceneOfEachTubeCount) {
  EvalRun run;
  run.scenes = {Scene("n3_a", 3, 3, 99), Scene("n3_b", 3, 2, 90), Scene("n3_c", 3, 3, 95),
                Scene("n3_d", 3, 2, 80), Scene("n1_a", 1, 1, 100)};
  // Per count, worst first (fewest correct, then lowest recall): n3_d, n3_b, n3_c, n3_a; the
  // typical one is the median of that order, n3_c.
  EXPECT_THAT(Names(SelectPictureScenes(run, 2)), ::testing::ElementsAre("n1_a", "n3_d", "n3_c"));
  EXPECT_THAT(Names(SelectPictureScenes(run, 1)), ::testing::ElementsAre("n1_a", "n3_d"));
  EXPECT_TRUE(SelectPictureScenes(run, 0).empty());
}

TEST(EvalReport, JsonReportCarriesEveryScenesScores) {
  EvalRun run;
  run.profile = "fast";
  run.scenes = {Scene("n2_s7", 2, 1, 75)};
  run.scenes[0].scene_seed = 7;
  const nlohmann::json j = nlohmann::json::parse(FormatJsonReport(run, {{"images/x.svg", "cap", "n2_s7"}}));
  EXPECT_EQ(j["profile"], "fast");
  ASSERT_EQ(j["scenes"].size(), 1u);
  EXPECT_EQ(j["scenes"][0]["correct"], 1);
  EXPECT_EQ(j["scenes"][0]["scene_seed"], 7);
  EXPECT_DOUBLE_EQ(j["scenes"][0]["micro_recall"].get<double>(), 0.75);
  EXPECT_EQ(j["images"][0]["scene"], "n2_s7");
  EXPECT_EQ(j["scenes"][0]["confusion"]["counts"], nlohmann::json::parse("[[75, 0, 0]]"));
  EXPECT_TRUE(j["scenes"][0]["joins"].is_null());  // no junction joining
}

TEST(EvalReport, TheJunctionJoiningAuditIsInBothReports) {
  EvalRun run;
  run.scenes = {Scene("n2_s7", 2, 1, 75)};
  run.scenes[0].evaluation.real_tubes.resize(2);  // the markdown's confusion matrix reads them
  JoinAudit& audit = run.scenes[0].evaluation.joins;
  audit.chains = 9;
  audit.mixed_chains = 1;
  audit.kinds[static_cast<std::size_t>(JoinDecision::Kind::kTPiece)].accepted = {.right = 4, .wrong = 1};
  audit.kinds[static_cast<std::size_t>(JoinDecision::Kind::kLink)].refused = {.right = 2, .wrong = 3};
  run.overall = Aggregate({&run.scenes[0].evaluation});
  const nlohmann::json j = nlohmann::json::parse(FormatJsonReport(run, {}));
  EXPECT_EQ(j["scenes"][0]["joins"]["t_piece"]["accepted"]["wrong"], 1);
  EXPECT_EQ(j["scenes"][0]["joins"]["link"]["refused_by_layout"]["wrong"], 3);
  EXPECT_EQ(j["overall"]["joins"]["t_piece"]["accepted"]["right"], 4);
  EXPECT_EQ(j["overall"]["joins"]["mixed_chains"], 1);
  const std::string md = FormatMarkdownReport(run, {});
  EXPECT_THAT(md, HasSubstr("| t_piece | 4 | 1 | 0 | 0 |"));
  EXPECT_THAT(md, HasSubstr("| link | 0 | 0 | 2 | 3 |"));
  EXPECT_THAT(md, HasSubstr("The linear chains it started from: 9, of which 1 join"));
}

TEST(SvgUtil, EscapesMarkupAndColoursBackgroundGrey) {
  EXPECT_EQ(XmlEscape("a<b & \"c\">"), "a&lt;b &amp; &quot;c&quot;&gt;");
  EXPECT_EQ(PaletteColour(-1), "#c8c8c8");
  EXPECT_EQ(PaletteColour(0), "#4e79a7");
  EXPECT_NE(PaletteColour(10), PaletteColour(11));  // past the table: still distinct
  EXPECT_THAT(PaletteColour(12), ::testing::MatchesRegex("#[0-9a-f]{6}"));
}

}  // namespace
}  // namespace tubepick::cli
