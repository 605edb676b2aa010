#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "clients/cell/cell_records.h"
#include "clients/cell/planner_client.h"
#include "core/planning/tool_clearance.h"
#include "viewer/view_page.h"

namespace tubepick::cli {

/// `tubepick cell --view DIR`: one 3-D page per round (DIR/round_NNN.html) that steps through the
/// round's scans: each PlanPick's cloud (thinned, bin frame) and answer or error, the plan the cell
/// executed and what came of it (the attempt, safe-stop and end records). It sits between the
/// controller and its planner and record sink, passing everything on unchanged; a failure of its own
/// (a page that cannot be written) is logged, never thrown into the controller.
class RoundViewRecorder final : public cell::PlannerClient, public cell::RecordSink {
 public:
  /// `planner` and `next` must outlive the recorder. @throws InvalidArgument when `directory`
  /// cannot be created.
  RoundViewRecorder(cell::PlannerClient& planner, cell::RecordSink& next, std::string directory,
                    std::size_t max_points, ToolParams tool);

  v1::PlanPickResponse PlanPick(const v1::PlanPickRequest& request,
                                std::chrono::milliseconds deadline) override;
  v1::AnalyzeWrenchResponse AnalyzeWrench(const v1::AnalyzeWrenchRequest& request,
                                          std::chrono::milliseconds deadline) override;
  void CancelCalls() override { planner_.CancelCalls(); }

  void Write(const nlohmann::json& record) override;

  /// Pages written so far.
  const std::vector<std::string>& pages() const { return pages_; }

 private:
  viewer::ViewFrame FrameOf(const v1::PlanPickRequest& request);
  /// Runs f; an exception is logged and swallowed (false): the page is a diagnostic, the cell goes on.
  template <typename F>
  bool Guarded(const char* what, F&& f);
  void Annotate(const nlohmann::json& record);
  void WriteRound(const nlohmann::json& end);

  cell::PlannerClient& planner_;
  cell::RecordSink& next_;
  std::string directory_;
  std::size_t max_points_;
  ToolParams tool_;
  CellConfig cell_;
  std::vector<viewer::ViewFrame> frames_;
  std::vector<std::string> pages_;
};

}  // namespace tubepick::cli
