#include "clients/cli/cell/round_view.h"

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <filesystem>

#include "clients/cell/attempt_record.h"
#include "clients/cli/inputs/cli_inputs.h"
#include "core/common/errors.h"
#include "wire/proto_convert.h"

namespace tubepick::cli {
namespace {

// The cell a request describes (the controller always sends its own; its sensor pose is the scan's).
CellConfig CellOf(const v1::CellDescription& d, const CellConfig& fallback) {
  CellConfig cell = fallback;
  if (d.has_bin_inner_size()) cell.bin.inner_size = FromProto(d.bin_inner_size(), "cell.bin_inner_size");
  if (d.has_sensor_pose()) cell.sensor.X_BinSensor = FromProto(d.sensor_pose(), "cell.sensor_pose");
  if (d.has_place_pose()) cell.place.X_BinPlace = FromProto(d.place_pose(), "cell.place_pose");
  if (d.tube_radius() > 0) cell.tube.radius = d.tube_radius();
  if (d.tube_length() > 0) cell.tube.length = d.tube_length();
  if (d.tube_mass() > 0) cell.tube.mass = d.tube_mass();
  if (const std::optional<TubeTopology> topology = FromProto(d.tube_topology()))
    cell.tube.topology = *topology;
  if (const std::optional<JunctionShape> shape = FromProto(d.tube_junction_shape()))
    cell.tube.junction_shape = *shape;
  if (d.tube_junctions() > 0) cell.tube.layout.junctions = d.tube_junctions();
  if (d.tube_junction_spacing() > 0) cell.tube.layout.junction_spacing = d.tube_junction_spacing();
  if (d.tube_branch_length() > 0) cell.tube.layout.branch_length = d.tube_branch_length();
  return cell;
}

// A record's whole number at `key`, or `fallback` when it is missing or not a number (a scan
// without a plan has "attempt": null).
int Count(const nlohmann::json& r, const char* key, int fallback) {
  const auto it = r.find(key);
  return it != r.end() && it->is_number() ? it->get<int>() : fallback;
}

// A picking attempt's record; a scan without a plan (perhaps a nudge) has "attempt": null.
bool IsPickingAttempt(const nlohmann::json& r) { return r.contains("attempt") && r["attempt"].is_number(); }

std::string AttemptNote(const nlohmann::json& r) {
  if (!IsPickingAttempt(r)) return cell::DescribeAttemptBriefly(r);
  std::string note = fmt::format(
      "attempt {}: plan #{} (tube {}, {}) → {}", Count(r, "attempt", 0), Count(r, "plan_rank", 0) + 1,
      Count(r, "tube", 0), r.value("trajectory_kind", std::string("-")), r.value("result", std::string("-")));
  if (r.contains("analysis") && r["analysis"].is_object() && r["analysis"].contains("outcome"))
    note += fmt::format(", lifted: {}", r["analysis"]["outcome"].get<std::string>());
  if (r.contains("resolution") && r["resolution"].is_object() && r["resolution"].value("used", 0) > 0)
    note += fmt::format(", resolution rotation {}",
                        r["resolution"].value("succeeded", false) ? "freed it" : "tried");
  if (r.contains("skipped_plans") && r["skipped_plans"].is_array() && !r["skipped_plans"].empty())
    note += fmt::format(", {} plan(s) skipped by the cell's checks", r["skipped_plans"].size());
  return note;
}

}  // namespace

RoundViewRecorder::RoundViewRecorder(cell::PlannerClient& planner, cell::RecordSink& next,
                                     std::string directory, std::size_t max_points, ToolParams tool)
    : planner_(planner), next_(next), directory_(std::move(directory)), max_points_(max_points), tool_(tool) {
  std::error_code ec;
  std::filesystem::create_directories(directory_, ec);
  if (ec)
    throw InvalidArgument(
        fmt::format("--view {}: cannot create the directory: {}", directory_, ec.message()));
}

viewer::ViewFrame RoundViewRecorder::FrameOf(const v1::PlanPickRequest& request) {
  cell_ = CellOf(request.cell(), cell_);
  viewer::ViewFrame frame;
  frame.label = fmt::format("scan {}", frames_.size() + 1);
  const LengthUnit unit =
      request.cloud().unit() == v1::LENGTH_UNIT_MILLIMETRE ? LengthUnit::kMillimetre : cell_.sensor.unit;
  frame.cloud =
      viewer::ThinToBin(PackedXyz{request.cloud().xyz()}, unit, cell_.sensor.X_BinSensor, max_points_);
  return frame;
}

template <typename F>
bool RoundViewRecorder::Guarded(const char* what, F&& f) {
  try {
    f();
    return true;
  } catch (const std::exception& e) {
    spdlog::error("cell --view: {} failed, the round page misses it (the cell goes on): {}", what, e.what());
    return false;
  }
}

v1::PlanPickResponse RoundViewRecorder::PlanPick(const v1::PlanPickRequest& request,
                                                 std::chrono::milliseconds deadline) {
  viewer::ViewFrame frame;
  if (!Guarded("the scan's cloud", [&] { frame = FrameOf(request); }))
    frame.label = fmt::format("scan {}", frames_.size() + 1);
  try {
    v1::PlanPickResponse response = planner_.PlanPick(request, deadline);
    frame.plan = response;
    if (response.bin_empty()) frame.note = "the planner saw the bin empty";
    frames_.push_back(std::move(frame));
    return response;
  } catch (const cell::PlannerError& e) {
    frame.error = e.what();
    frames_.push_back(std::move(frame));
    throw;
  }
}

v1::AnalyzeWrenchResponse RoundViewRecorder::AnalyzeWrench(const v1::AnalyzeWrenchRequest& request,
                                                           std::chrono::milliseconds deadline) {
  return planner_.AnalyzeWrench(request, deadline);
}

void RoundViewRecorder::Annotate(const nlohmann::json& record) {
  if (frames_.empty()) return;
  viewer::ViewFrame& last = frames_.back();
  const std::string type = record.value("type", std::string());
  if (type == "attempt") {
    // A scan without a plan records plan_rank 0 with "attempt": null: no plan was chosen.
    if (IsPickingAttempt(record) && record.contains("plan_rank") && record["plan_rank"].is_number())
      last.chosen_plan = record["plan_rank"].get<int>();
    last.note = AttemptNote(record);
  } else if (type == "safe_stop") {
    last.note += (last.note.empty() ? "" : "; ") + fmt::format("safe stop ({}): {}",
                                                               record.value("reason", std::string("-")),
                                                               record.value("message", std::string("-")));
  }
}

void RoundViewRecorder::WriteRound(const nlohmann::json& end) {
  const std::uint32_t round = end.value("round", 0u);
  viewer::ViewPage page;
  page.title = fmt::format("tubepick cell: round {}", round);
  page.source = fmt::format("tubepick cell, round {}: {}", round, end.value("message", std::string()));
  page.cell = cell_;
  page.tool = tool_;
  page.frames = std::move(frames_);
  frames_.clear();
  if (page.frames.empty()) {
    viewer::ViewFrame none;
    none.label = "no scan";
    none.error = end.value("message", std::string("the round ended before its first plan"));
    page.frames.push_back(std::move(none));
  }
  const std::string path =
      (std::filesystem::path(directory_) / fmt::format("round_{:03d}.html", round)).string();
  WriteTextFile(path, viewer::PageHtml(page));
  pages_.push_back(path);
}

void RoundViewRecorder::Write(const nlohmann::json& record) {
  next_.Write(record);
  // The page is a diagnostic: whatever goes wrong with it must not stop the cell.
  if (record.value("type", std::string()) == "end")
    Guarded("writing the round page", [&] { WriteRound(record); });
  else
    Guarded("noting the record on the page", [&] { Annotate(record); });
}

}  // namespace tubepick::cli
