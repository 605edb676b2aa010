#include "clients/cli/local/view_command.h"

#include <fmt/core.h>

#include <memory>

#include "clients/cli/inputs/cli_inputs.h"
#include "clients/cli/local/plan_command.h"
#include "core/common/errors.h"
#include "core/common/yaml_reader.h"
#include "viewer/view_page.h"
#include "wire/proto_convert.h"
#include "wire/response_convert.h"

namespace tubepick::cli {
namespace {

struct ViewOptions {
  InputOptions input;
  std::string plan_path;
  std::string model_path;
  std::string out_path;
  std::string title;
  bool no_sim = false;
  std::size_t max_points = 200'000;
};

// A plan or model drawn over another cloud would look right and be wrong: the response names the
// points it was made from.
void RequireSameCloud(std::uint64_t response_points, const CloudInput& cloud, const std::string& what) {
  if (response_points != cloud.points_Sensor.size()) {
    throw InvalidArgument(fmt::format(
        "{} was made from a cloud of {} points, but {} has {}: give the cloud it was made from (--cloud)",
        what, response_points, cloud.source, cloud.points_Sensor.size()));
  }
}

viewer::ViewFrame FrameFor(const ViewOptions& o, const CloudInput& cloud, const CellConfig& cell,
                           const Params& params) {
  viewer::ViewFrame frame;
  frame.label = cloud.source;
  frame.cloud = viewer::ThinToBin(cloud.points_Sensor, cloud.unit, cell.sensor.X_BinSensor, o.max_points);
  const CommonOptions& common = o.input.common;
  if (!o.plan_path.empty()) {
    v1::PlanPickResponse plan;
    FromJson(ReadTextFile(o.plan_path), &plan, o.plan_path);
    RequireSameCloud(plan.modeling().input_points(), cloud, o.plan_path);
    frame.note = "plan from " + o.plan_path;
    frame.plan = std::move(plan);
  } else if (!o.model_path.empty()) {
    v1::ModelTubesResponse model;
    FromJson(ReadTextFile(o.model_path), &model, o.model_path);
    RequireSameCloud(model.input_points(), cloud, o.model_path);
    frame.note = "model from " + o.model_path;
    frame.modeling = std::move(model);
  } else {
    const InProcessPlan planned = PlanInProcess(cloud, cell, params, common.seed, o.no_sim, 0);
    frame.note = fmt::format("planned here: profile {}, seed {}{}", common.profile, common.seed,
                             o.no_sim ? ", no simulation" : "");
    frame.plan = ToPlanPickResponse(planned.plan, planned.modeling, common.profile, common.seed);
  }
  return frame;
}

void Run(const ViewOptions& o) {
  const CommonOptions& common = o.input.common;
  const CellConfig cell = LoadCell(common);
  const Params params = LoadParamsFor(common);
  const CloudInput cloud = LoadCloudInput(o.input, cell);
  viewer::ViewPage page;
  page.title = o.title.empty() ? "tubepick view: " + cloud.source : o.title;
  page.source =
      fmt::format("tubepick view, cell {}", common.cell_path.empty() ? "embedded default" : common.cell_path);
  page.cell = cell;
  page.tool = params.planning.tool;
  page.frames.push_back(FrameFor(o, cloud, cell, params));
  const std::string html = viewer::PageHtml(page);
  WriteTextFile(o.out_path, html);
  const viewer::ViewFrame& f = page.frames.front();
  const int tubes = f.plan ? f.plan->tubes_size() : f.modeling->tubes_size();
  fmt::print("wrote {} ({:.1f} MB): {} of {} points, {} tubes, {} plans\n", o.out_path, html.size() / 1e6,
             f.cloud->size(), f.cloud->total_points, tubes, f.plan ? f.plan->plans_size() : 0);
}

}  // namespace

void AddViewCommand(CLI::App& app) {
  auto o = std::make_shared<ViewOptions>();
  CLI::App* cmd = app.add_subcommand(
      "view", "Write a self-contained 3-D HTML page of a cloud and its tubes, grasps and trajectories");
  AddInputOptions(cmd, o->input);
  CLI::Option* plan =
      cmd->add_option("--plan", o->plan_path, "PlanPickResponse JSON (tubepick plan --json) of the cloud")
          ->check(CLI::ExistingFile);
  cmd->add_option("--model", o->model_path, "ModelTubesResponse JSON (tubepick model --json) of the cloud")
      ->check(CLI::ExistingFile)
      ->excludes(plan);
  cmd->add_option("--out", o->out_path, "The HTML page to write")->required();
  cmd->add_option("--title", o->title, "Page title (default: the cloud's name)");
  cmd->add_flag("--no-sim", o->no_sim, "When planning here: never simulate trajectories");
  cmd->add_option("--max-points", o->max_points, "Cloud points drawn at most (every k-th point kept)")
      ->check(CLI::Range(1, 5'000'000))
      ->capture_default_str();
  cmd->callback([o] { Run(*o); });
}

}  // namespace tubepick::cli
