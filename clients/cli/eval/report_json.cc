// report.json: everything the markdown shows plus per-scene detail, for scripts.
#include <nlohmann/json.hpp>

#include "clients/cli/eval/eval_report.h"

namespace tubepick::cli {
namespace {

using nlohmann::json;

json Optional(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

json Timings(const std::vector<StageTiming>& timings) {
  json out = json::object();
  for (const StageTiming& t : timings) out[t.stage] = t.seconds;
  return out;
}

// Per kind of junction-joining decision: right and wrong ones kept and taken back by the layout;
// null without junction joining.
json JoinsJson(const JoinAudit& audit) {
  if (audit.empty()) return nullptr;
  json out = {{"chains", audit.chains}, {"mixed_chains", audit.mixed_chains}};
  for (std::size_t k = 0; k < audit.kinds.size(); ++k) {
    const JoinAudit::Kind& kind = audit.kinds[k];
    out[ToString(static_cast<JoinDecision::Kind>(k))] = {
        {"accepted", {{"right", kind.accepted.right}, {"wrong", kind.accepted.wrong}}},
        {"refused_by_layout", {{"right", kind.refused.right}, {"wrong", kind.refused.wrong}}}};
  }
  return out;
}

json AggregateJson(const EvaluationAggregate& a) {
  return json{{"tube_count", a.tube_count},
              {"scenes", a.scenes},
              {"real_tubes", a.real_tubes},
              {"segmentation_error", Optional(a.segmentation_error)},
              {"mean_length", Optional(a.mean_length)},
              {"stddev_length", Optional(a.stddev_length)},
              {"virtual_tubes", a.virtual_tubes},
              {"correct", a.correct},
              {"partially_correct", a.partially_correct},
              {"not_correct", a.not_correct},
              {"hidden", a.hidden},
              {"total_correct", a.total_correct},
              {"total_partially_correct", a.total_partially_correct},
              {"total_not_correct", a.total_not_correct},
              {"total_hidden", a.total_hidden},
              {"merged", a.merged},
              {"missed", a.missed},
              {"under_covered", a.under_covered},
              {"correct_fraction", a.correct_fraction},
              {"correct_fraction_visible", a.correct_fraction_visible},
              {"scenes_all_correct", a.scenes_all_correct},
              {"matched_points", a.matched_points},
              {"real_points", a.real_points},
              {"labelled_points", a.labelled_points},
              {"background_points", a.background_points},
              {"background_null", a.background_null},
              {"real_null", a.real_null},
              {"micro_recall", a.micro_recall},
              {"micro_precision", a.micro_precision},
              {"accuracy", a.accuracy},
              {"mean_timings", Timings(a.mean_timings)},
              {"mean_total_seconds", a.mean_total_seconds},
              {"max_total_seconds", a.max_total_seconds},
              {"joins", JoinsJson(a.joins)}};
}

json PlanCheckJson(const std::optional<PlanCheck>& c) {
  if (!c) return nullptr;
  if (!c->planned) return json{{"planned", false}, {"free_real_tubes", c->free_real_tubes}};
  return json{{"planned", true},
              {"certainty", c->certainty},
              {"trajectory", c->trajectory},
              {"modeled_class", c->modeled_class},
              {"real_tube", c->real_tube >= 0 ? json(c->real_tube) : json(nullptr)},
              {"grasp_offset", c->grasp_offset},
              {"real_tube_free", c->real_tube_free},
              {"free_real_tubes", c->free_real_tubes},
              {"lifted", c->lifted},
              {"displacement", c->displacement}};
}

json SceneJson(const EvaluatedScene& s) {
  const SceneEvaluation& e = s.evaluation;
  json real = json::array();
  for (std::size_t j = 0; j < e.real_tubes.size(); ++j) {
    const RealTubeEvaluation& r = e.real_tubes[j];
    real.push_back({{"index", j},
                    {"visible_points", r.visible_points},
                    {"sections", r.sections},
                    {"verdict", ToString(r.verdict)},
                    {"failure", ToString(r.failure)},
                    {"touching", r.touching},
                    {"coverage", r.coverage},
                    {"matched_virtual", r.matched_virtual}});
  }
  json virt = json::array();
  for (const VirtualTubeEvaluation& v : e.virtual_tubes) {
    virt.push_back({{"id", v.id},
                    {"length", v.length},
                    {"cylinders", v.cylinders},
                    {"points", v.points},
                    {"majority", v.majority},
                    {"purity", v.purity},
                    {"stray_cylinders", v.stray_cylinders},
                    {"mixed_cylinders", v.mixed_cylinders},
                    {"mixed_joints", v.mixed_joints},
                    {"mixed_nodes", v.mixed_nodes},
                    {"pure", v.pure},
                    {"matched_real", v.matched_real}});
  }
  const ConfusionMatrix& cm = e.confusion;
  json rows = json::array();
  for (std::uint32_t i = 0; i <= cm.virtual_tubes; ++i) {
    json row = json::array();
    for (std::uint32_t j = 0; j <= cm.real_tubes; ++j) row.push_back(cm.at(i, j));
    rows.push_back(row);
  }
  json confusion = json::object();
  confusion["rows"] = "virtual tubes in modeled order, then the null label c0";
  confusion["columns"] = "real tubes, then the background (bin, ground, outliers)";
  confusion["counts"] = rows;
  return json{{"name", s.name},
              {"source", s.source},
              {"best_plan", PlanCheckJson(s.plan_check)},
              {"view", s.view_file.empty() ? json(nullptr) : json(s.view_file)},
              {"tube_count", s.tube_count},
              {"scene_seed", s.scene_seed >= 0 ? json(s.scene_seed) : json(nullptr)},
              {"input_points", s.input_points},
              {"tube_length", s.tube_length},
              {"filtered_points", e.filtered_points},
              {"segments", e.segments},
              {"visible_sections", e.visible_sections},
              {"segmentation_error", Optional(e.segmentation_error)},
              {"virtual_tube_count", e.virtual_tubes.size()},
              {"mean_length", Optional(e.mean_length)},
              {"stddev_length", Optional(e.stddev_length)},
              {"correct", e.correct},
              {"partially_correct", e.partially_correct},
              {"not_correct", e.not_correct},
              {"hidden", e.hidden},
              {"micro_recall", e.micro_recall()},
              {"micro_precision", e.micro_precision()},
              {"accuracy", e.accuracy()},
              {"timings", Timings(e.timings)},
              {"total_seconds", e.total_seconds},
              {"joins", JoinsJson(e.joins)},
              {"real_tubes", real},
              {"virtual_tubes", virt},
              {"confusion", confusion}};
}

}  // namespace

std::string FormatJsonReport(const EvalRun& run, const std::vector<ReportImage>& images) {
  const EvaluationParams& p = run.evaluation_params;
  json j;
  j["command"] = run.command_line;
  j["source"] = run.source;
  j["profile"] = run.profile;
  j["params_file"] = run.params_path;
  j["joining_strategy"] = run.joining_strategy;
  j["topology"] = run.topology;
  j["junction_shape"] = run.junction_shape;
  j["modeling_seed"] = run.modeling_seed;
  j["jobs"] = run.jobs;
  j["modeling_threads"] = run.modeling_threads;
  j["wall_seconds"] = run.wall_seconds;
  j["evaluation_params"] = {{"labelling_tolerance", p.labelling.tolerance},
                            {"label_inside_cylinders", p.labelling.label_inside_cylinders},
                            {"section_link_radius", p.sections.link_radius},
                            {"section_min_points", p.sections.min_points},
                            {"min_visible_points", p.min_visible_points},
                            {"purity", p.purity},
                            {"cylinder_purity", p.cylinder_purity},
                            {"coverage", p.coverage},
                            {"touch_fraction", p.touch_fraction},
                            {"touch_min_points", p.touch_min_points}};
  j["overall"] = AggregateJson(run.overall);
  j["per_tube_count"] = json::array();
  for (const EvaluationAggregate& a : run.rows) j["per_tube_count"].push_back(AggregateJson(a));
  j["images"] = json::array();
  for (const ReportImage& im : images)
    j["images"].push_back({{"file", im.file}, {"caption", im.caption}, {"scene", im.scene}});
  j["scenes"] = json::array();
  for (const EvaluatedScene& s : run.scenes) j["scenes"].push_back(SceneJson(s));
  j["params_yaml"] = run.params_yaml;
  return j.dump(1) + "\n";
}

}  // namespace tubepick::cli
