#include "core/evaluation/tube_evaluation.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/common/errors.h"
#include "core/common/tube_graph.h"

namespace tubepick {
namespace {

void RequireFraction(double value, const std::string& name) {
  if (!(value > 0.0 && value <= 1.0)) {
    throw InvalidArgument("evaluation." + name + ": must be in (0, 1], got " + std::to_string(value));
  }
}

double Ratio(std::uint64_t numerator, std::uint64_t denominator) {
  return denominator == 0 ? 0.0 : static_cast<double>(numerator) / static_cast<double>(denominator);
}

// Per cylinder of one virtual tube: its points per real tube (the background last).
using CylinderCounts = std::vector<std::vector<std::uint32_t>>;

// The real tube holding most of a cylinder's points, or −1 (too few points, or background).
std::int32_t CylinderMajority(const std::vector<std::uint32_t>& counts, const EvaluationParams& params) {
  std::uint64_t total = 0;
  for (const std::uint32_t c : counts) total += c;
  if (total < params.touch_min_points) return -1;
  const auto best = std::max_element(counts.begin(), counts.end() - 1);
  return *best == 0 ? -1 : static_cast<std::int32_t>(best - counts.begin());
}

// Where a virtual tube mixes real tubes: impure cylinders, joints and junction nodes between
// cylinders of different real tubes.
void CountMixing(const Tube& tube, const CylinderCounts& counts, const EvaluationParams& params,
                 VirtualTubeEvaluation* v) {
  std::vector<std::int32_t> majority(counts.size());
  for (std::size_t c = 0; c < counts.size(); ++c) {
    majority[c] = CylinderMajority(counts[c], params);
    std::uint64_t total = 0;
    for (const std::uint32_t k : counts[c]) total += k;
    if (majority[c] >= 0 && Ratio(counts[c][static_cast<std::size_t>(majority[c])], total) < params.purity) {
      ++v->mixed_cylinders;
    }
  }
  // Per node: the real tube of each branch's cylinder nearest it.
  std::vector<std::vector<std::int32_t>> at_node(NodesOf(tube).size());
  for (const TubeBranch& b : BranchesOf(tube)) {
    std::int32_t first = -1, previous = -1;
    for (std::uint32_t c = b.first_cylinder; c < b.first_cylinder + b.cylinder_count; ++c) {
      if (majority[c] < 0) continue;
      if (previous >= 0 && majority[c] != previous) ++v->mixed_joints;
      if (first < 0) first = majority[c];
      previous = majority[c];
    }
    if (first >= 0) {
      at_node[b.from_node].push_back(first);
      at_node[b.to_node].push_back(previous);
    }
  }
  for (std::vector<std::int32_t>& reals : at_node) {
    std::sort(reals.begin(), reals.end());
    if (std::unique(reals.begin(), reals.end()) - reals.begin() > 1) ++v->mixed_nodes;
  }
}

}  // namespace

void EvaluationParams::Validate() const {
  RequireFraction(purity, "purity");
  RequireFraction(cylinder_purity, "cylinder_purity");
  RequireFraction(coverage, "coverage");
  if (!(touch_fraction >= 0.0 && touch_fraction <= 1.0)) {
    throw InvalidArgument("evaluation.touch_fraction: must be in [0, 1], got " +
                          std::to_string(touch_fraction));
  }
  if (touch_min_points == 0) throw InvalidArgument("evaluation.touch_min_points: must be > 0, got 0");
}

std::string ToString(TubeVerdict verdict) {
  switch (verdict) {
    case TubeVerdict::kCorrect:
      return "correct";
    case TubeVerdict::kPartiallyCorrect:
      return "partially_correct";
    case TubeVerdict::kNotCorrect:
      return "not_correct";
    case TubeVerdict::kHidden:
      return "hidden";
  }
  return "?";
}

std::string ToString(TubeFailure failure) {
  switch (failure) {
    case TubeFailure::kNone:
      return "";
    case TubeFailure::kMissed:
      return "missed";
    case TubeFailure::kMerged:
      return "merged";
    case TubeFailure::kUnderCovered:
      return "under_covered";
  }
  return "?";
}

double SceneEvaluation::micro_recall() const { return Ratio(matched_points, real_points); }
double SceneEvaluation::micro_precision() const { return Ratio(matched_points, labelled_points); }
double SceneEvaluation::accuracy() const {
  return Ratio(matched_points + background_null, real_points + background_points);
}

ConfusionMatrix BuildConfusion(const std::vector<std::int32_t>& virtual_label,
                               const std::vector<std::int32_t>& truth, std::uint32_t virtual_tubes,
                               std::uint32_t real_tubes) {
  if (virtual_label.size() != truth.size()) {
    throw InvalidArgument("confusion: " + std::to_string(virtual_label.size()) + " virtual labels for " +
                          std::to_string(truth.size()) + " ground-truth labels");
  }
  ConfusionMatrix m;
  m.virtual_tubes = virtual_tubes;
  m.real_tubes = real_tubes;
  m.counts.assign(static_cast<std::size_t>(virtual_tubes + 1) * (real_tubes + 1), 0);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const std::int32_t v = virtual_label[i];
    if (v >= static_cast<std::int32_t>(virtual_tubes)) {
      throw InvalidArgument("confusion: point " + std::to_string(i) + " has virtual tube " +
                            std::to_string(v) + " of " + std::to_string(virtual_tubes));
    }
    const std::uint32_t row = v < 0 ? m.null_row() : static_cast<std::uint32_t>(v);
    const std::int32_t t = truth[i];
    const std::uint32_t column = (t < 0 || t >= static_cast<std::int32_t>(real_tubes))
                                     ? m.background_column()
                                     : static_cast<std::uint32_t>(t);
    ++m.at(row, column);
  }
  return m;
}

SceneEvaluation EvaluateScene(const ModelingResult& result, const std::vector<std::int32_t>& truth_of_input,
                              std::uint32_t real_tube_count, const EvaluationParams& params) {
  params.Validate();
  const Points& points = result.filtered.points;
  const std::size_t n_points = points.size();
  if (result.filtered_source_index.size() != n_points || result.tube_of_point.size() != n_points) {
    throw InvalidArgument("evaluation: the modeling result has " + std::to_string(n_points) +
                          " filtered points but " + std::to_string(result.filtered_source_index.size()) +
                          " source indices and " + std::to_string(result.tube_of_point.size()) +
                          " tube labels");
  }
  std::vector<std::int32_t> truth(n_points);
  for (std::size_t i = 0; i < n_points; ++i) {
    const std::uint32_t source = result.filtered_source_index[i];
    if (source >= truth_of_input.size()) {
      throw InvalidArgument("evaluation: filtered point " + std::to_string(i) + " comes from input point " +
                            std::to_string(source) + " but there are " +
                            std::to_string(truth_of_input.size()) + " ground-truth labels");
    }
    const std::int32_t t = truth_of_input[source];
    truth[i] = (t < 0 || t >= static_cast<std::int32_t>(real_tube_count)) ? -1 : t;
  }

  const VirtualLabels labels =
      LabelVirtualTubes(points, result.tube_of_point, result.tubes, params.labelling);
  const auto m = static_cast<std::uint32_t>(result.tubes.size());
  const std::uint32_t n = real_tube_count;

  SceneEvaluation out;
  out.real_tube_count = n;
  out.filtered_points = static_cast<std::uint32_t>(n_points);
  out.confusion = BuildConfusion(labels.tube, truth, m, n);
  out.joins = AuditJoins(result, truth);
  const ConfusionMatrix& cm = out.confusion;

  // Virtual tubes: majority, purity, stray cylinders.
  out.virtual_tubes.resize(m);
  for (std::uint32_t i = 0; i < m; ++i) {
    VirtualTubeEvaluation& v = out.virtual_tubes[i];
    const Tube& tube = result.tubes[i];
    v.id = tube.id;
    v.length = tube.length();
    v.cylinders = static_cast<std::uint32_t>(tube.cylinders.size());
    std::uint64_t total = 0, best = 0;
    for (std::uint32_t j = 0; j <= n; ++j) total += cm.at(i, j);
    for (std::uint32_t j = 0; j < n; ++j) {
      if (cm.at(i, j) > best) {
        best = cm.at(i, j);
        v.majority = static_cast<std::int32_t>(j);
      }
    }
    v.points = static_cast<std::uint32_t>(total);
    v.purity = Ratio(best, total);
  }
  {
    // Per cylinder: points attributed to it, and how many of them are on the tube's majority.
    std::vector<CylinderCounts> counts(m);
    for (std::uint32_t i = 0; i < m; ++i) {
      counts[i].assign(result.tubes[i].cylinders.size(), std::vector<std::uint32_t>(n + 1, 0));
    }
    for (std::size_t p = 0; p < n_points; ++p) {
      const std::int32_t v = labels.tube[p];
      if (v < 0 || labels.cylinder[p] < 0) continue;
      ++counts[v][labels.cylinder[p]][truth[p] >= 0 ? static_cast<std::uint32_t>(truth[p]) : n];
    }
    for (std::uint32_t i = 0; i < m; ++i) {
      VirtualTubeEvaluation& v = out.virtual_tubes[i];
      for (const std::vector<std::uint32_t>& on_cylinder : counts[i]) {
        std::uint64_t total = 0;
        for (const std::uint32_t k : on_cylinder) total += k;
        if (total == 0) continue;
        const std::uint64_t on_majority =
            v.majority >= 0 ? on_cylinder[static_cast<std::size_t>(v.majority)] : 0;
        if (Ratio(on_majority, total) < params.cylinder_purity) ++v.stray_cylinders;
      }
      v.pure = v.majority >= 0 && v.purity >= params.purity && v.stray_cylinders == 0;
      CountMixing(result.tubes[i], counts[i], params, &v);
    }
  }

  // Optimal one-to-one matching on shared points (§4.5.2).
  std::vector<std::vector<std::uint64_t>> overlap(m, std::vector<std::uint64_t>(n, 0));
  for (std::uint32_t i = 0; i < m; ++i)
    for (std::uint32_t j = 0; j < n; ++j) overlap[i][j] = cm.at(i, j);
  const Assignment matching = MatchMaxOverlap(overlap, n);
  for (std::uint32_t i = 0; i < m; ++i) out.virtual_tubes[i].matched_real = matching.column_of_row[i];

  // Real tubes: visibility, sections, verdicts.
  const std::vector<std::uint32_t> sections = CountVisibleSections(points, truth, n, params.sections);
  out.real_tubes.resize(n);
  for (std::uint32_t j = 0; j < n; ++j) {
    RealTubeEvaluation& r = out.real_tubes[j];
    r.sections = sections[j];
    r.matched_virtual = matching.row_of_column[j];
    std::uint64_t visible = 0;
    for (std::uint32_t i = 0; i <= m; ++i) visible += cm.at(i, j);
    r.visible_points = static_cast<std::uint32_t>(visible);
    if (visible < params.min_visible_points) {
      r.verdict = TubeVerdict::kHidden;
      ++out.hidden;
      continue;
    }
    const double touch =
        std::max<double>(params.touch_min_points, params.touch_fraction * static_cast<double>(visible));
    std::uint64_t covered = 0;
    bool merged = false;
    for (std::uint32_t i = 0; i < m; ++i) {
      if (static_cast<double>(cm.at(i, j)) < touch) continue;
      r.touching.push_back(static_cast<std::int32_t>(i));
      const VirtualTubeEvaluation& v = out.virtual_tubes[i];
      if (v.pure && v.majority == static_cast<std::int32_t>(j)) {
        covered += cm.at(i, j);
      } else {
        merged = true;
      }
    }
    r.coverage = Ratio(covered, visible);
    if (r.touching.empty()) {
      r.verdict = TubeVerdict::kNotCorrect;
      r.failure = TubeFailure::kMissed;
    } else if (merged) {
      r.verdict = TubeVerdict::kNotCorrect;
      r.failure = TubeFailure::kMerged;
    } else if (r.coverage < params.coverage) {
      r.verdict = TubeVerdict::kNotCorrect;
      r.failure = TubeFailure::kUnderCovered;
    } else {
      r.verdict = r.touching.size() == 1 ? TubeVerdict::kCorrect : TubeVerdict::kPartiallyCorrect;
    }
    switch (r.verdict) {
      case TubeVerdict::kCorrect:
        ++out.correct;
        break;
      case TubeVerdict::kPartiallyCorrect:
        ++out.partially_correct;
        break;
      default:
        ++out.not_correct;
        break;
    }
  }

  // Table 4.5 figures.
  out.segments = result.segment_count;
  for (std::uint32_t s : sections) out.visible_sections += s;
  if (out.visible_sections > 0) {
    out.segmentation_error =
        std::abs(static_cast<double>(out.segments) - static_cast<double>(out.visible_sections)) /
        static_cast<double>(out.visible_sections);
  }
  if (m > 0) {
    double sum = 0.0, sum2 = 0.0;
    for (const VirtualTubeEvaluation& v : out.virtual_tubes) sum += v.length;
    const double mean = sum / m;
    for (const VirtualTubeEvaluation& v : out.virtual_tubes) sum2 += (v.length - mean) * (v.length - mean);
    out.mean_length = mean;
    out.stddev_length = std::sqrt(sum2 / m);
  }

  // Point tallies.
  for (std::uint32_t i = 0; i < m; ++i) {
    if (matching.column_of_row[i] >= 0) out.matched_points += cm.at(i, matching.column_of_row[i]);
    for (std::uint32_t j = 0; j <= n; ++j) out.labelled_points += cm.at(i, j);
  }
  for (std::uint32_t j = 0; j < n; ++j) {
    out.real_points += out.real_tubes[j].visible_points;
    out.real_null += cm.at(cm.null_row(), j);
  }
  for (std::uint32_t i = 0; i <= m; ++i) out.background_points += cm.at(i, cm.background_column());
  out.background_null = cm.at(cm.null_row(), cm.background_column());

  out.timings = result.timings;
  out.total_seconds = result.total_seconds;
  return out;
}

}  // namespace tubepick
