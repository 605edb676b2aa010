// report.md: the tables of thesis §4.4.4 (Tables 4.4, 4.5) and §4.5.2 (Table 4.6) per number of tubes.
#include <fmt/core.h>

#include <algorithm>

#include "clients/cli/eval/eval_report.h"

namespace tubepick::cli {
namespace {

std::string Opt(const std::optional<double>& v, const char* format = "{:.3f}") {
  return v ? fmt::format(fmt::runtime(format), *v) : "–";
}

std::string Percent(double fraction) { return fmt::format("{:.1f} %", 100.0 * fraction); }

double Stage(const EvaluationAggregate& a, const std::string& stage) {
  for (const StageTiming& t : a.mean_timings)
    if (t.stage == stage) return t.seconds;
  return 0.0;
}

std::string Failures(const SceneEvaluation& e) {
  std::string out;
  for (std::size_t j = 0; j < e.real_tubes.size(); ++j) {
    const RealTubeEvaluation& r = e.real_tubes[j];
    if (r.verdict != TubeVerdict::kNotCorrect) continue;
    out += fmt::format("{}T{} {}", out.empty() ? "" : ", ", j, ToString(r.failure));
  }
  return out;
}

// Junction joining's decisions against the ground truth, over all scenes.
std::string JoinAuditSection(const JoinAudit& audit) {
  std::string md = "## Junction joining against the ground truth\n\n";
  md +=
      "Every node and link junction joining decided, over all scenes. *Right*: every chain it joins is "
      "mostly one real tube (the ground truth of the segments its cylinders were fitted to); a wrong one "
      "kept merges two tubes. *Taken back*: refused because the tree it made does not fit the part's "
      "junction layout (tube.junctions, junction_spacing, branch_length).\n\n";
  md += "| decision | kept: right | kept: wrong | taken back: right | taken back: wrong |\n";
  md += "|---|---:|---:|---:|---:|\n";
  for (std::size_t k = 0; k < audit.kinds.size(); ++k) {
    const JoinAudit::Kind& kind = audit.kinds[k];
    md += fmt::format("| {} | {} | {} | {} | {} |\n", ToString(static_cast<JoinDecision::Kind>(k)),
                      kind.accepted.right, kind.accepted.wrong, kind.refused.right, kind.refused.wrong);
  }
  md += fmt::format(
      "\nThe linear chains it started from: {}, of which {} join segments of different real tubes (the "
      "linear joining before the junctions merged them).\n\n",
      audit.chains, audit.mixed_chains);
  return md;
}

std::string PlanCheckSection(const EvalRun& run) {
  std::vector<const PlanCheck*> checks;
  for (const EvaluatedScene& s : run.scenes) checks.push_back(&*s.plan_check);
  const PlanCheckSummary c = SummarizePlanChecks(checks);
  std::string md = "## Best plans against the ground truth (`--plans`)\n\n";
  md +=
      "Each scene is planned as the service plans it (simulation on); the best plan is then checked on the "
      "real tubes: the real tube nearest its grasp point, whether a real tube lies on that one, and its "
      "trajectory replayed in a Bullet world of the real tubes (the grasped tube held kinematically): a real "
      "tube raised by more than half the lift counts as lifted.\n\n";
  md += "| | scenes |\n|---|---:|\n";
  md += fmt::format("| planned | {} of {} |\n", c.planned, c.scenes);
  md +=
      fmt::format("| best plan sure / simulated / unsure | {} / {} / {} |\n", c.sure, c.simulated, c.unsure);
  md += fmt::format("| grasp on a free real tube | {} |\n", c.grasped_free);
  md += fmt::format("| grasp on a real tube lain on while a free one existed | {} |\n",
                    c.grasped_lain_on_while_free);
  md += fmt::format("| grasp on no real tube | {} |\n", c.off_tube);
  md += fmt::format("| lifted one tube alone | {} |\n", c.lifted_alone);
  md += fmt::format("| lifted several tubes | {} |\n", c.lifted_several);
  md += fmt::format("| lifted nothing | {} |\n\n", c.lifted_none);
  md += "| scene | certainty | trajectory | modeled class | real tube | free | free real tubes | lifted |\n";
  md += "|---|---|---|---|---:|---|---:|---:|\n";
  for (const EvaluatedScene& s : run.scenes) {
    const PlanCheck& p = *s.plan_check;
    if (!p.planned) {
      md += fmt::format("| {} | no plan | | | | | {} | |\n", s.name, p.free_real_tubes);
      continue;
    }
    md += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} |\n", s.name, p.certainty, p.trajectory,
                      p.modeled_class, p.real_tube >= 0 ? std::to_string(p.real_tube) : "-",
                      p.real_tube_free ? "yes" : "no", p.free_real_tubes, p.lifted);
  }
  return md + "\n";
}

}  // namespace

std::string FormatMarkdownReport(const EvalRun& run, const std::vector<ReportImage>& images) {
  const EvaluationAggregate& all = run.overall;
  const EvaluationParams& p = run.evaluation_params;
  std::string md = "# Tube modeling evaluation\n\n";
  md += fmt::format("- Command: `{}`\n", run.command_line);
  md += fmt::format("- Scenes: {} ({})\n", all.scenes, run.source);
  if (!run.scenes.empty() && !run.scenes.front().view_file.empty()) {
    md +=
        "- 3-D pages: `views/SCENE.html`, one per scene (its cloud and modeled tubes; open in a browser, "
        "no network needed); the scene names below link them\n";
  }
  md += fmt::format("- Modeling: profile `{}`{}, joining `{}`, topology `{}`, modeling seed {}\n",
                    run.profile, run.params_path.empty() ? "" : fmt::format(" + `{}`", run.params_path),
                    run.joining_strategy, run.topology, run.modeling_seed);
  md += fmt::format(
      "- Run: {} concurrent job(s){}, wall time {:.1f} s ({:.2f} s per scene: simulation or loading, "
      "scan, modeling, evaluation)\n\n",
      run.jobs,
      run.jobs > 1 ? " — stage times below were measured with concurrent jobs and are not representative"
                   : "",
      run.wall_seconds, run.wall_seconds / std::max(1u, all.scenes));

  md += "## Summary\n\n";
  md += fmt::format(
      "{} real tubes in {} scenes: **{} correct ({})**, {} partially correct, {} not correct ({} merged, {} "
      "missed, "
      "{} under-covered), {} hidden. Correct among visible tubes: {}. Scenes with every tube correct: {} of "
      "{}.\n\n",
      all.real_tubes, all.scenes, all.total_correct, Percent(all.correct_fraction),
      all.total_partially_correct, all.total_not_correct, all.merged, all.missed, all.under_covered,
      all.total_hidden, Percent(all.correct_fraction_visible), all.scenes_all_correct, all.scenes);
  md += fmt::format(
      "Points (Table 4.6 pooled): micro-recall {:.4f}, micro-precision {:.4f}, accuracy {:.4f}. "
      "Mean modeling time {:.3f} s (max {:.3f} s).\n\n",
      all.micro_recall, all.micro_precision, all.accuracy, all.mean_total_seconds, all.max_total_seconds);
  if (!images.empty()) md += fmt::format("![{}]({})\n\n", images.front().caption, images.front().file);

  md += "## Accuracy per number of tubes (as thesis Table 4.5)\n\n";
  md +=
      "| tubes | scenes | segmentation error | avg. length (m) | std. dev. length (m) | virtual tubes | "
      "correct | "
      "partially correct | not correct | hidden | correct % | micro-recall | micro-precision |\n";
  md += "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const EvaluationAggregate& a : run.rows) {
    md += fmt::format(
        "| {} | {} | {} | {} | {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {} | {:.3f} | {:.3f} |\n",
        a.tube_count, a.scenes, Opt(a.segmentation_error, "{:.2f}"), Opt(a.mean_length),
        Opt(a.stddev_length, "{:.4f}"), a.virtual_tubes, a.correct, a.partially_correct, a.not_correct,
        a.hidden, Percent(a.correct_fraction), a.micro_recall, a.micro_precision);
  }
  md +=
      "\nMeans per scene, except correct % (correct / all real tubes, pooled) and the micro scores (pooled "
      "points).\n\n";

  if (!all.joins.empty()) md += JoinAuditSection(all.joins);
  if (!run.scenes.empty() && run.scenes.front().plan_check) md += PlanCheckSection(run);

  md += "## Modeling time per number of tubes (as thesis Table 4.4)\n\n";
  md +=
      "Mean seconds per scene. The thesis' *filtering* column corresponds to prepare + filter + normals.\n\n";
  md += "| tubes | prepare | filter | normals | segmentation | cylinders | joining | total | max total |\n";
  md += "|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const EvaluationAggregate& a : run.rows) {
    md += fmt::format("| {} | {:.4f} | {:.4f} | {:.4f} | {:.4f} | {:.4f} | {:.5f} | {:.3f} | {:.3f} |\n",
                      a.tube_count, Stage(a, "prepare"), Stage(a, "filter"), Stage(a, "normals"),
                      Stage(a, "segmentation"), Stage(a, "cylinders"), Stage(a, "joining"),
                      a.mean_total_seconds, a.max_total_seconds);
  }

  md += "\n## Confusion summary (Table 4.6, pooled per number of tubes)\n\n";
  md +=
      "Points of the filtered cloud. *Matched* = n_ii, the points of a real tube on the virtual tube matched "
      "to it "
      "(optimal assignment); *other virtual* = on a virtual tube matched elsewhere or unmatched; *c∅* = on "
      "no "
      "virtual tube.\n\n";
  md +=
      "| tubes | tube points | matched (n_ii) | other virtual | c∅ | background points | background on a "
      "virtual "
      "tube |\n|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const EvaluationAggregate& a : run.rows) {
    const std::uint64_t other = a.real_points - a.matched_points - a.real_null;
    const std::uint64_t bg_virtual = a.background_points - a.background_null;
    const double rp = static_cast<double>(std::max<std::uint64_t>(1, a.real_points));
    md += fmt::format("| {} | {} | {:.1f} % | {:.1f} % | {:.1f} % | {} | {} |\n", a.tube_count, a.real_points,
                      100.0 * a.matched_points / rp, 100.0 * other / rp, 100.0 * a.real_null / rp,
                      a.background_points, bg_virtual);
  }

  // The full matrix of the worst scene of the largest count, in Table 4.6's layout.
  const EvaluatedScene* worst = nullptr;
  for (const EvaluatedScene& s : run.scenes) {
    if (!worst || s.tube_count > worst->tube_count ||
        (s.tube_count == worst->tube_count &&
         (s.evaluation.correct < worst->evaluation.correct ||
          (s.evaluation.correct == worst->evaluation.correct &&
           s.evaluation.micro_recall() < worst->evaluation.micro_recall())))) {
      worst = &s;
    }
  }
  if (worst) {
    const SceneEvaluation& e = worst->evaluation;
    const ConfusionMatrix& cm = e.confusion;
    md += fmt::format(
        "\nConfusion matrix of scene `{}` (the worst with {} tubes). Rows: virtual tubes, ordered to "
        "face their matched real tube, then unmatched ones and c∅; columns: real tubes T0.., then "
        "background.\n\n",
        worst->name, worst->tube_count);
    std::vector<std::int32_t> order;
    for (std::uint32_t j = 0; j < cm.real_tubes; ++j)
      if (e.real_tubes[j].matched_virtual >= 0) order.push_back(e.real_tubes[j].matched_virtual);
    for (std::uint32_t i = 0; i < cm.virtual_tubes; ++i)
      if (e.virtual_tubes[i].matched_real < 0) order.push_back(static_cast<std::int32_t>(i));
    order.push_back(static_cast<std::int32_t>(cm.null_row()));
    md += "| |";
    for (std::uint32_t j = 0; j < cm.real_tubes; ++j) md += fmt::format(" T{} |", j);
    md += " bg |\n|---|";
    for (std::uint32_t j = 0; j <= cm.real_tubes; ++j) md += "---:|";
    md += "\n";
    for (std::int32_t row : order) {
      const bool null_row = row == static_cast<std::int32_t>(cm.null_row());
      md += null_row ? "| c∅ |"
                     : fmt::format("| v{}{} |", row,
                                   e.virtual_tubes[row].matched_real >= 0
                                       ? fmt::format(" (T{})", e.virtual_tubes[row].matched_real)
                                       : "");
      for (std::uint32_t j = 0; j <= cm.real_tubes; ++j) {
        const std::uint64_t v = cm.at(static_cast<std::uint32_t>(row), j);
        const bool diagonal = !null_row && e.virtual_tubes[row].matched_real == static_cast<std::int32_t>(j);
        md += v == 0 ? " · |" : diagonal ? fmt::format(" **{}** |", v) : fmt::format(" {} |", v);
      }
      md += "\n";
    }
  }

  // Scenes with failures.
  std::vector<const EvaluatedScene*> failing;
  for (const EvaluatedScene& s : run.scenes)
    if (s.evaluation.not_correct + s.evaluation.partially_correct > 0) failing.push_back(&s);
  std::stable_sort(failing.begin(), failing.end(), [](const EvaluatedScene* a, const EvaluatedScene* b) {
    const double fa = static_cast<double>(a->evaluation.correct) / std::max(1u, a->tube_count);
    const double fb = static_cast<double>(b->evaluation.correct) / std::max(1u, b->tube_count);
    return fa < fb;
  });
  constexpr std::size_t kMaxRows = 40;
  md += fmt::format("\n## Scenes with a tube not fully correct ({} of {}{})\n\n", failing.size(),
                    run.scenes.size(),
                    failing.size() > kMaxRows ? fmt::format(", the {} worst shown", kMaxRows) : "");
  if (failing.empty()) {
    md += "None.\n";
  } else {
    md +=
        "| scene | tubes | correct | partially | not correct | hidden | micro-recall | segments / sections | "
        "virtual tubes |\n|---|---:|---:|---:|---|---:|---:|---:|---:|\n";
    for (std::size_t k = 0; k < failing.size() && k < kMaxRows; ++k) {
      const EvaluatedScene& s = *failing[k];
      const SceneEvaluation& e = s.evaluation;
      const std::string name = s.view_file.empty() ? s.name : fmt::format("[{}]({})", s.name, s.view_file);
      md += fmt::format("| {} | {} | {} | {} | {} | {} | {:.3f} | {} / {} | {} |\n", name, s.tube_count,
                        e.correct, e.partially_correct, Failures(e).empty() ? "0" : Failures(e), e.hidden,
                        e.micro_recall(), e.segments, e.visible_sections, e.virtual_tubes.size());
    }
  }
  if (!failing.empty() && failing.front()->scene_seed >= 0) {
    md += fmt::format(
        "\nReproduce a generated scene: `tubepick scene --tubes N --seed S --out DIR` (the seed is in "
        "the name, e.g. `{}`), then `tubepick model --cloud DIR/cloud.ply --dump-stages ...`.\n",
        failing.front()->name);
  }

  if (images.size() > 1) {
    md +=
        "\n## Pictures\n\nTop view of the filtered cloud (x right, y up, the bin outlined). Panel 1: ground "
        "truth with each real tube's verdict (ok, part = partially correct, merged, missed, under = "
        "under-covered, hidden); 2: segments; 3: cylinders; 4: virtual tubes coloured like their matched "
        "real "
        "tube (`v3=T5` = virtual tube 3 matched to real tube 5, `!` = not pure).\n\n";
    for (std::size_t k = 1; k < images.size(); ++k) {
      md += fmt::format("**{}**\n\n![{}]({})\n\n", images[k].caption, images[k].caption, images[k].file);
    }
  }

  md += "## Definitions\n\n";
  md += fmt::format(
      "Per scene, on the filtered cloud (the points the modeling saw), every point has a ground-truth label "
      "(real "
      "tube C_j or background) and a virtual label: cylinder inliers keep their virtual tube; other points "
      "within "
      "radius + {:.1f} mm of a joint (segment between consecutive cylinders' endpoints) or of a cylinder's "
      "axis "
      "segment get that tube (the nearest surface wins); the rest get c∅ (§4.5.2).\n\n",
      1e3 * p.labelling.tolerance);
  md += fmt::format(
      "- A virtual tube is *pure* for C_j when ≥ {:.0f} % of its points are C_j's and each of its cylinders "
      "has ≥ "
      "{:.0f} % of its points on C_j (no cylinder where the tube is not).\n"
      "- A virtual tube *touches* C_j when it holds ≥ max({}, {:.0f} % of C_j's visible points).\n"
      "- C_j is *hidden* with fewer than {} visible (filtered) points; hidden tubes count as not correct in "
      "*correct %*.\n"
      "- **Correct**: exactly one virtual tube touches C_j, it is pure for C_j and holds ≥ {:.0f} % of its "
      "visible "
      "points.\n"
      "- **Partially correct**: ≥ 2 virtual tubes touch C_j, all pure for it, together holding ≥ {:.0f} %.\n"
      "- **Not correct** otherwise: *merged* (a touching virtual tube is not pure for C_j — a virtual tube "
      "joining "
      "two real tubes makes neither correct), *missed* (nothing touches it) or *under-covered*.\n"
      "- Matching for Table 4.6: virtual ↔ real tubes one-to-one maximising the shared points (Hungarian "
      "method). "
      "Micro-recall = Σ n_ii / tube points; micro-precision = Σ n_ii / points on a virtual tube; accuracy = "
      "(Σ n_ii + background points on c∅) / all points.\n"
      "- Segmentation error = |segments − visible sections| / visible sections, a visible section being a "
      "connected "
      "component (link {:.0f} mm) of a real tube's filtered points with ≥ {} points.\n"
      "- Lengths: mean and population standard deviation of the virtual tubes' lengths (Def. 4.2.6) in a "
      "scene.\n",
      100 * p.purity, 100 * p.cylinder_purity, p.touch_min_points, 100 * p.touch_fraction,
      p.min_visible_points, 100 * p.coverage, 100 * p.coverage, 1e3 * p.sections.link_radius,
      p.sections.min_points);
  md +=
      "\n<details><summary>Parameters used</summary>\n\n```yaml\n" + run.params_yaml + "```\n\n</details>\n";
  return md;
}

}  // namespace tubepick::cli
