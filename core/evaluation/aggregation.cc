#include "core/evaluation/aggregation.h"

#include <algorithm>
#include <map>

namespace tubepick {
namespace {

double Ratio(std::uint64_t numerator, std::uint64_t denominator) {
  return denominator == 0 ? 0.0 : static_cast<double>(numerator) / static_cast<double>(denominator);
}

// Mean of the defined values, or empty.
struct OptionalMean {
  double sum = 0.0;
  std::uint32_t count = 0;
  void Add(const std::optional<double>& v) {
    if (!v) return;
    sum += *v;
    ++count;
  }
  std::optional<double> Get() const {
    if (count == 0) return std::nullopt;
    return sum / count;
  }
};

}  // namespace

EvaluationAggregate Aggregate(const std::vector<const SceneEvaluation*>& scenes) {
  EvaluationAggregate a;
  a.scenes = static_cast<std::uint32_t>(scenes.size());
  if (scenes.empty()) return a;
  a.tube_count = scenes.front()->real_tube_count;
  OptionalMean segmentation_error, mean_length, stddev_length;
  std::vector<std::string> stage_order;
  std::map<std::string, double> stage_sum;
  double virtual_sum = 0.0;
  for (const SceneEvaluation* s : scenes) {
    if (s->real_tube_count != a.tube_count) a.tube_count = 0;
    a.real_tubes += s->real_tube_count;
    segmentation_error.Add(s->segmentation_error);
    mean_length.Add(s->mean_length);
    stddev_length.Add(s->stddev_length);
    virtual_sum += static_cast<double>(s->virtual_tubes.size());
    a.total_correct += s->correct;
    a.total_partially_correct += s->partially_correct;
    a.total_not_correct += s->not_correct;
    a.total_hidden += s->hidden;
    for (const RealTubeEvaluation& r : s->real_tubes) {
      if (r.failure == TubeFailure::kMerged) ++a.merged;
      if (r.failure == TubeFailure::kMissed) ++a.missed;
      if (r.failure == TubeFailure::kUnderCovered) ++a.under_covered;
    }
    if (s->correct == s->real_tube_count) ++a.scenes_all_correct;
    a.matched_points += s->matched_points;
    a.real_points += s->real_points;
    a.labelled_points += s->labelled_points;
    a.background_points += s->background_points;
    a.background_null += s->background_null;
    a.real_null += s->real_null;
    for (const StageTiming& t : s->timings) {
      if (!stage_sum.count(t.stage)) stage_order.push_back(t.stage);
      stage_sum[t.stage] += t.seconds;
    }
    a.mean_total_seconds += s->total_seconds;
    a.max_total_seconds = std::max(a.max_total_seconds, s->total_seconds);
    a.joins += s->joins;
  }
  const double n = static_cast<double>(scenes.size());
  a.segmentation_error = segmentation_error.Get();
  a.mean_length = mean_length.Get();
  a.stddev_length = stddev_length.Get();
  a.virtual_tubes = virtual_sum / n;
  a.correct = a.total_correct / n;
  a.partially_correct = a.total_partially_correct / n;
  a.not_correct = a.total_not_correct / n;
  a.hidden = a.total_hidden / n;
  a.correct_fraction = Ratio(a.total_correct, a.real_tubes);
  a.correct_fraction_visible = Ratio(a.total_correct, a.real_tubes - a.total_hidden);
  a.micro_recall = Ratio(a.matched_points, a.real_points);
  a.micro_precision = Ratio(a.matched_points, a.labelled_points);
  a.accuracy = Ratio(a.matched_points + a.background_null, a.real_points + a.background_points);
  for (const std::string& stage : stage_order) a.mean_timings.push_back({stage, stage_sum[stage] / n});
  a.mean_total_seconds /= n;
  return a;
}

std::vector<EvaluationAggregate> AggregateByTubeCount(const std::vector<SceneEvaluation>& scenes) {
  std::map<std::uint32_t, std::vector<const SceneEvaluation*>> by_count;
  for (const SceneEvaluation& s : scenes) by_count[s.real_tube_count].push_back(&s);
  std::vector<EvaluationAggregate> rows;
  for (const auto& [count, group] : by_count) rows.push_back(Aggregate(group));
  return rows;
}

}  // namespace tubepick
