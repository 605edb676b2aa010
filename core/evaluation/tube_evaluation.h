#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/evaluation/assignment.h"
#include "core/evaluation/join_audit.h"
#include "core/evaluation/virtual_labelling.h"
#include "core/evaluation/visible_sections.h"
#include "core/modeling/model_tubes.h"

namespace tubepick {

/// Thresholds of the automated evaluation (thesis §4.4.4 definitions made precise, §4.5.2).
///
/// Definitions, per scene, on the filtered cloud (the points the modeling saw), each point with
/// a ground-truth label (real tube C_j, or background: bin, ground, outlier) and a virtual label
/// (virtual tube c_i, or c∅; see LabelVirtualTubes):
/// - V_j: the filtered points of real tube C_j; |V_j| its visible points.
/// - n_ij: points with virtual label c_i and ground truth C_j (the confusion matrix, Table 4.6).
/// - c_i is *pure for C_j* when C_j holds ≥ `purity` of all points labelled c_i (background
///   included) and every cylinder of c_i has ≥ `cylinder_purity` of its points (each point of c_i
///   counted for the cylinder whose axis is nearest) on C_j: it has no cylinder where C_j is not.
/// - c_i *touches* C_j when n_ij ≥ max(touch_min_points, touch_fraction · |V_j|).
/// - C_j is *hidden* when |V_j| < min_visible_points (fully or almost fully occluded; it is
///   reported separately and is never correct).
/// - C_j is *correct* when exactly one virtual tube touches it, that tube is pure for C_j and
///   holds ≥ `coverage` of V_j.
/// - C_j is *partially correct* when ≥ 2 virtual tubes touch it, all of them are pure for C_j and
///   together they hold ≥ `coverage` of V_j (a tube split into several models).
/// - Otherwise C_j is *not correct*: missed (nothing touches it), merged (a touching virtual tube
///   is not pure for it: it also models another tube or the background), or under-covered (its
///   pure virtual tubes hold < `coverage` of V_j). A virtual tube merging two real tubes thus
///   makes neither correct.
/// Point-level scores use the optimal one-to-one matching of virtual to real tubes (maximum
/// summed n_ij, Hungarian method): micro-recall Σ n_ii / Σ |V_j|, micro-precision Σ n_ii / (points
/// with a virtual tube), accuracy (Σ n_ii + background points labelled c∅) / all points.
struct EvaluationParams {
  /// How points outside every cylinder get a virtual tube (joints, cylinder interiors).
  VirtualLabellingParams labelling;
  /// What counts as one visible section of a real tube (segmentation error).
  VisibleSectionParams sections;
  /// A real tube with fewer visible (filtered) points is hidden.
  std::uint32_t min_visible_points = 60;
  /// Share of a virtual tube's points that must be on one real tube for it to be pure.
  double purity = 0.90;
  /// Share of each cylinder's points that must be on that real tube.
  double cylinder_purity = 0.50;
  /// Share of a real tube's visible points its pure virtual tubes must hold.
  double coverage = 0.80;
  /// A virtual tube touches a real tube with at least this share of its visible points ...
  double touch_fraction = 0.05;
  /// ... and at least this many points.
  std::uint32_t touch_min_points = 30;

  /// @throws InvalidArgument naming the field and value.
  void Validate() const;
};

enum class TubeVerdict { kCorrect, kPartiallyCorrect, kNotCorrect, kHidden };
/// Why a visible tube is not correct.
enum class TubeFailure { kNone, kMissed, kMerged, kUnderCovered };

/// "correct", "partially_correct", "not_correct", "hidden".
std::string ToString(TubeVerdict verdict);
/// "", "missed", "merged", "under_covered".
std::string ToString(TubeFailure failure);

struct RealTubeEvaluation {
  std::uint32_t visible_points = 0;
  /// Visible continuous sections (CountVisibleSections).
  std::uint32_t sections = 0;
  TubeVerdict verdict = TubeVerdict::kHidden;
  TubeFailure failure = TubeFailure::kNone;
  /// Virtual tubes (indices into SceneEvaluation::virtual_tubes) that touch it.
  std::vector<std::int32_t> touching;
  /// Share of V_j held by the touching virtual tubes that are pure for it.
  double coverage = 0.0;
  /// Its virtual tube in the optimal matching, or −1.
  std::int32_t matched_virtual = -1;
};

struct VirtualTubeEvaluation {
  std::uint32_t id = 0;
  double length = 0.0;
  std::uint32_t cylinders = 0;
  /// Points labelled with it: cylinder inliers + joint / cylinder fill.
  std::uint32_t points = 0;
  /// Real tube holding most of its points, or −1 (background / no points).
  std::int32_t majority = -1;
  /// Share of its points on `majority`.
  double purity = 0.0;
  /// Cylinders whose points are mostly not on `majority`.
  std::uint32_t stray_cylinders = 0;
  /// Where it mixes real tubes (a diagnosis of merges): cylinders holding less than `purity`
  /// of their points on one real tube (segmentation or fitting), joints inside a branch between
  /// cylinders of different real tubes (end-to-end joining) and junction nodes whose branches
  /// start on different real tubes (junction joining). Cylinders with fewer than
  /// touch_min_points points are not counted.
  std::uint32_t mixed_cylinders = 0;
  std::uint32_t mixed_joints = 0;
  std::uint32_t mixed_nodes = 0;
  /// Pure for `majority` (see EvaluationParams).
  bool pure = false;
  /// Its real tube in the optimal matching, or −1.
  std::int32_t matched_real = -1;
};

/// Table 4.6: rows are the virtual tubes (modeled order) then c∅; columns the real tubes then
/// the background (bin, ground, outliers).
struct ConfusionMatrix {
  std::uint32_t virtual_tubes = 0;
  std::uint32_t real_tubes = 0;
  /// (virtual_tubes + 1) × (real_tubes + 1), row-major.
  std::vector<std::uint64_t> counts;

  std::uint64_t at(std::uint32_t row, std::uint32_t column) const {
    return counts[row * (real_tubes + 1) + column];
  }
  std::uint64_t& at(std::uint32_t row, std::uint32_t column) {
    return counts[row * (real_tubes + 1) + column];
  }
  std::uint32_t null_row() const { return virtual_tubes; }
  std::uint32_t background_column() const { return real_tubes; }
};

/// Builds the confusion matrix from per-point labels (virtual index or −1; real index or any
/// negative / ≥ real_tubes value for background).
/// @throws InvalidArgument when sizes differ or a virtual label is ≥ virtual_tubes.
ConfusionMatrix BuildConfusion(const std::vector<std::int32_t>& virtual_label,
                               const std::vector<std::int32_t>& truth, std::uint32_t virtual_tubes,
                               std::uint32_t real_tubes);

struct SceneEvaluation {
  std::uint32_t real_tube_count = 0;
  std::uint32_t filtered_points = 0;
  std::vector<RealTubeEvaluation> real_tubes;
  std::vector<VirtualTubeEvaluation> virtual_tubes;
  ConfusionMatrix confusion;

  std::uint32_t correct = 0;
  std::uint32_t partially_correct = 0;
  std::uint32_t not_correct = 0;
  std::uint32_t hidden = 0;

  /// Segments of the region growing and visible sections of the ground truth.
  std::uint32_t segments = 0;
  std::uint32_t visible_sections = 0;
  /// |segments − visible_sections| / visible_sections (Table 4.5); empty when no section is visible.
  std::optional<double> segmentation_error;
  /// Mean and population standard deviation of the virtual tube lengths, metres; empty when no
  /// tube was modeled.
  std::optional<double> mean_length;
  std::optional<double> stddev_length;

  /// Point tallies behind the micro scores (summed directly when aggregating).
  std::uint64_t matched_points = 0;     ///< Σ n_ii over matched pairs
  std::uint64_t real_points = 0;        ///< Σ |V_j|
  std::uint64_t labelled_points = 0;    ///< points with a virtual tube
  std::uint64_t background_points = 0;  ///< points whose ground truth is not a tube
  std::uint64_t background_null = 0;    ///< background points labelled c∅
  std::uint64_t real_null = 0;          ///< tube points labelled c∅ (Σ n_∅j)

  /// Per-stage timings and total of the modeling run evaluated.
  std::vector<StageTiming> timings;
  double total_seconds = 0.0;

  /// Junction joining's decisions against the ground truth (empty without junction joining).
  JoinAudit joins;

  double micro_recall() const;
  double micro_precision() const;
  double accuracy() const;
};

/// Evaluates one modeling run against per-point ground truth. `truth_of_input` has one label per
/// point of the modeling input cloud (tube index 0..real_tube_count−1; negative = background),
/// looked up through result.filtered_source_index.
/// @throws InvalidArgument for inconsistent sizes, an out-of-range source index or invalid params.
SceneEvaluation EvaluateScene(const ModelingResult& result, const std::vector<std::int32_t>& truth_of_input,
                              std::uint32_t real_tube_count, const EvaluationParams& params);

}  // namespace tubepick
