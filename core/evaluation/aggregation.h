#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/evaluation/tube_evaluation.h"

namespace tubepick {

/// Scenes summarised together (Tables 4.4 and 4.5: one row per number of tubes).
struct EvaluationAggregate {
  /// Number of real tubes of the scenes in this row; 0 for a row over all scenes.
  std::uint32_t tube_count = 0;
  std::uint32_t scenes = 0;
  std::uint32_t real_tubes = 0;  ///< summed over the scenes

  /// Means over scenes (Table 4.5). Segmentation error and lengths average the scenes where they
  /// are defined; empty when none is.
  std::optional<double> segmentation_error;
  std::optional<double> mean_length;
  std::optional<double> stddev_length;
  double virtual_tubes = 0.0;
  double correct = 0.0;
  double partially_correct = 0.0;
  double not_correct = 0.0;
  double hidden = 0.0;

  /// Summed counts, and correct / all real tubes, correct / visible real tubes.
  std::uint32_t total_correct = 0;
  std::uint32_t total_partially_correct = 0;
  std::uint32_t total_not_correct = 0;
  std::uint32_t total_hidden = 0;
  std::uint32_t merged = 0;
  std::uint32_t missed = 0;
  std::uint32_t under_covered = 0;
  double correct_fraction = 0.0;
  double correct_fraction_visible = 0.0;
  /// Scenes in which every real tube is correct.
  std::uint32_t scenes_all_correct = 0;

  /// Pooled point tallies (micro averages over every point of every scene).
  std::uint64_t matched_points = 0;
  std::uint64_t real_points = 0;
  std::uint64_t labelled_points = 0;
  std::uint64_t background_points = 0;
  std::uint64_t background_null = 0;
  std::uint64_t real_null = 0;
  double micro_recall = 0.0;
  double micro_precision = 0.0;
  double accuracy = 0.0;

  /// Mean seconds per stage (Table 4.4), stages in the order of the first scene; and of the total.
  std::vector<StageTiming> mean_timings;
  double mean_total_seconds = 0.0;
  double max_total_seconds = 0.0;

  /// Junction joining's decisions against the ground truth, summed.
  JoinAudit joins;
};

/// Summarises `scenes` into one row (tube_count = their common count, or 0 when they differ).
EvaluationAggregate Aggregate(const std::vector<const SceneEvaluation*>& scenes);

/// One row per distinct number of real tubes, ascending.
std::vector<EvaluationAggregate> AggregateByTubeCount(const std::vector<SceneEvaluation>& scenes);

}  // namespace tubepick
