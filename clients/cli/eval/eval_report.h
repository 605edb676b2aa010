#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "clients/cli/eval/plan_check.h"
#include "core/common/cell_config.h"
#include "core/common/types.h"
#include "core/evaluation/aggregation.h"
#include "core/evaluation/tube_evaluation.h"

namespace tubepick::cli {

/// What a top-down picture of a scene needs (kept for every scene, a few are drawn).
struct SceneSnapshot {
  /// The filtered cloud (Bin frame), thinned to at most kSnapshotPoints points.
  Points points_Bin;
  /// Per kept point: real tube index or −1, virtual tube index or −1, segment or −1.
  std::vector<std::int32_t> truth;
  std::vector<std::int32_t> virtual_label;
  std::vector<std::int32_t> segment;
  /// The modeled tubes.
  std::vector<Tube> tubes;
  /// Ground-truth centre lines of the real tubes (Bin frame); empty for a branched tube.
  std::vector<std::vector<Eigen::Vector3d>> real_centrelines;
  BinConfig bin;
};
inline constexpr std::size_t kSnapshotPoints = 12000;

struct EvaluatedScene {
  /// Short unique name: "n10_s10005" for generated scenes, the relative path otherwise.
  std::string name;
  /// "generated", or the scene directory / configuration file.
  std::string source;
  std::uint32_t tube_count = 0;
  /// Seed of a generated scene (`tubepick scene --tubes N --seed S` reproduces it); −1 otherwise.
  std::int64_t scene_seed = -1;
  std::uint64_t input_points = 0;
  /// The cell's tube.length the scene was modeled with, metres (0 = unknown).
  double tube_length = 0.0;
  SceneEvaluation evaluation;
  SceneSnapshot snapshot;
  /// The best plan against the ground truth (`--plans`).
  std::optional<PlanCheck> plan_check;
  /// Its 3-D page relative to the report directory ("views/n10_s10005.html"); empty = none written.
  std::string view_file;
};

/// One `tubepick eval` run.
struct EvalRun {
  std::string command_line;
  /// Where the scenes came from, for the report header.
  std::string source;
  std::string profile;
  std::string params_path;
  std::string joining_strategy;
  /// The tube topology modeled ("linear", "branched", "auto").
  std::string topology = "linear";
  /// The junction shape expected ("any", "wye", "tee").
  std::string junction_shape = "any";
  /// The full params YAML used (DumpParams).
  std::string params_yaml;
  EvaluationParams evaluation_params;
  std::uint64_t modeling_seed = 0;
  std::uint32_t jobs = 1;
  std::uint32_t modeling_threads = 0;
  double wall_seconds = 0.0;
  std::vector<EvaluatedScene> scenes;
  std::vector<EvaluationAggregate> rows;
  EvaluationAggregate overall;
};

/// A picture written next to the report.
struct ReportImage {
  std::string file;  ///< relative to the report directory, e.g. "images/scene_n10_s10005.svg"
  std::string caption;
  std::string scene;  ///< scene name, empty for plots
};

/// Scenes worth a picture: per number of tubes the worst (fewest correct, then lowest recall)
/// and a typical one (median correct count, recall nearest the median), up to `per_count` each.
std::vector<const EvaluatedScene*> SelectPictureScenes(const EvalRun& run, std::uint32_t per_count);

/// report.md text.
std::string FormatMarkdownReport(const EvalRun& run, const std::vector<ReportImage>& images);
/// report.json text.
std::string FormatJsonReport(const EvalRun& run, const std::vector<ReportImage>& images);
/// Top-down SVG of one scene: the filtered cloud by ground truth, the segments, the cylinders and
/// the virtual tubes, in four panels.
std::string RenderSceneSvg(const EvaluatedScene& scene);
/// SVG plot of accuracy and modeling time against the number of tubes.
std::string RenderAccuracyPlotSvg(const std::vector<EvaluationAggregate>& rows);

/// Writes report.md, report.json and images/ into `directory` (created).
/// @throws InvalidArgument when a file cannot be written.
void WriteReport(const EvalRun& run, const std::string& directory, std::uint32_t pictures_per_count);

}  // namespace tubepick::cli
