// Writes the evaluation report directory and picks the scenes worth a picture.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "clients/cli/eval/eval_report.h"
#include "clients/cli/inputs/cli_inputs.h"

namespace tubepick::cli {

std::vector<const EvaluatedScene*> SelectPictureScenes(const EvalRun& run, std::uint32_t per_count) {
  std::map<std::uint32_t, std::vector<const EvaluatedScene*>> by_count;
  for (const EvaluatedScene& s : run.scenes) by_count[s.tube_count].push_back(&s);
  std::vector<const EvaluatedScene*> chosen;
  for (auto& [count, group] : by_count) {
    // Worst first: fewest correct, then lowest micro-recall, then name (deterministic).
    std::vector<const EvaluatedScene*> sorted = group;
    std::sort(sorted.begin(), sorted.end(), [](const EvaluatedScene* a, const EvaluatedScene* b) {
      const auto& ea = a->evaluation;
      const auto& eb = b->evaluation;
      if (ea.correct != eb.correct) return ea.correct < eb.correct;
      if (ea.micro_recall() != eb.micro_recall()) return ea.micro_recall() < eb.micro_recall();
      return a->name < b->name;
    });
    std::vector<const EvaluatedScene*> picks;
    if (per_count >= 1) picks.push_back(sorted.front());
    if (per_count >= 2 && sorted.size() > 1) {
      // Typical: the median scene of that order (median correct count, recall near the median).
      const EvaluatedScene* typical = sorted[sorted.size() / 2];
      if (typical == picks.front()) typical = sorted.back();
      picks.push_back(typical);
    }
    for (std::size_t k = 2; k < per_count && k < sorted.size(); ++k)
      picks.push_back(sorted[sorted.size() - 1 - (k - 2)]);
    std::vector<const EvaluatedScene*> unique;
    for (const EvaluatedScene* p : picks)
      if (std::find(unique.begin(), unique.end(), p) == unique.end()) unique.push_back(p);
    chosen.insert(chosen.end(), unique.begin(), unique.end());
  }
  return chosen;
}

void WriteReport(const EvalRun& run, const std::string& directory, std::uint32_t pictures_per_count) {
  namespace fs = std::filesystem;
  const fs::path dir(directory);
  fs::create_directories(dir / "images");
  std::vector<ReportImage> images;
  WriteTextFile((dir / "images" / "accuracy_time.svg").string(), RenderAccuracyPlotSvg(run.rows));
  images.push_back(
      {"images/accuracy_time.svg", "Accuracy and mean modeling time against the number of tubes", ""});
  std::map<std::uint32_t, int> rank_in_count;
  for (const EvaluatedScene* s : SelectPictureScenes(run, pictures_per_count)) {
    const int rank = rank_in_count[s->tube_count]++;
    std::string safe = s->name;
    for (char& c : safe)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') c = '_';
    const std::string file = "images/scene_" + safe + ".svg";
    WriteTextFile((dir / file).string(), RenderSceneSvg(*s));
    const SceneEvaluation& e = s->evaluation;
    images.push_back(
        {file,
         fmt::format("{} tube{}, {} scene {}: {} correct, {} partially correct, {} not correct, {} hidden",
                     s->tube_count, s->tube_count == 1 ? "" : "s",
                     rank == 0   ? "worst"
                     : rank == 1 ? "typical"
                                 : "another",
                     s->name, e.correct, e.partially_correct, e.not_correct, e.hidden),
         s->name});
  }
  WriteTextFile((dir / "report.md").string(), FormatMarkdownReport(run, images));
  WriteTextFile((dir / "report.json").string(), FormatJsonReport(run, images));
}

}  // namespace tubepick::cli
