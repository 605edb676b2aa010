#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/common/cell_config.h"
#include "core/planning/tool_clearance.h"
#include "tubepick/v1/modeling.pb.h"
#include "tubepick/v1/planning.pb.h"
#include "viewer/view_cloud.h"

namespace tubepick::viewer {

/// One step a page shows (a planning call, or one scan of a cell round). Every part is optional: a
/// failed call has its error and perhaps its cloud, a modeling call no plan.
struct ViewFrame {
  std::string label;
  /// Free text under the label (what the cell did with the plan).
  std::string note;
  /// The call's error, shown prominently.
  std::string error;
  /// Index into plan->plans of the plan the cell executed.
  std::optional<int> chosen_plan;
  std::optional<ViewCloud> cloud;
  std::optional<v1::PlanPickResponse> plan;
  /// Modeling alone (ModelTubes); a plan carries its own modeling.
  std::optional<v1::ModelTubesResponse> modeling;
};

struct ViewLink {
  std::string label;
  std::string href;
};

/// A self-contained page: the data format "tubepick-view/1" (docs/VIEWER.md) and the bundled
/// script. The tool is drawn at each grasp.
struct ViewPage {
  std::string title;
  /// What produced the page (a command line, a call id).
  std::string source;
  std::vector<ViewLink> links;
  CellConfig cell;
  ToolParams tool;
  std::vector<ViewFrame> frames;
};

/// The page's data as JSON text (the plans and models in proto3 JSON, the cloud as base64 of
/// little-endian float32 triples), with `generated` as the ISO-8601 UTC time of the call.
std::string PageDataJson(const ViewPage& page);

/// The page as one HTML file that opens from disk with no network: the data in a
/// <script type="application/json" id="tubepick-data"> (every '<' written as \u003c) and the
/// bundled script inline.
std::string PageHtml(const ViewPage& page);

/// `text` with &, <, >, " and ' as HTML entities.
std::string HtmlEscape(std::string_view text);

/// RFC 4648 base64 with padding.
std::string Base64(std::string_view bytes);

/// The bundled page script (generated from viewer/src at build time).
std::string_view ViewerBundle();

}  // namespace tubepick::viewer
