#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "core/common/cell_config.h"
#include "core/planning/tool_clearance.h"
#include "server/request_log.h"
#include "viewer/view_page.h"

namespace tubepick::server {

/// What a planning call leaves for the viewer while it runs: its cloud (thinned, bin frame), the
/// cell it was planned in and, once there, its response.
struct DebugCapture {
  CellConfig cell;
  ToolParams tool;
  viewer::ViewFrame frame;
};

/// One kept call.
struct DebugCall {
  std::uint64_t id = 0;
  std::chrono::system_clock::time_point finished;
  CallRecord record;
  /// Absent when the call ended before its request was valid (then only the record is shown).
  std::optional<DebugCapture> capture;
};

/// The last `keep_last` planning calls (debug.keep_last), for /debug/calls. Thread-safe; a call's
/// page is built outside the lock from an immutable copy.
class DebugCallStore {
 public:
  DebugCallStore(std::uint32_t keep_last, std::uint32_t max_points);

  std::uint32_t max_points() const { return max_points_; }
  /// Keeps the call (dropping the oldest beyond keep_last) and returns its id (1, 2, ...).
  std::uint64_t Add(const CallRecord& record, std::optional<DebugCapture> capture);

  /// The kept calls, newest first.
  std::deque<std::shared_ptr<const DebugCall>> Calls() const;
  std::shared_ptr<const DebugCall> Find(std::uint64_t id) const;

  /// /debug/calls: an HTML table of the kept calls, newest first, each linking its page.
  std::string ListHtml() const;
  /// /debug/calls.json: the same as JSON.
  std::string ListJson() const;
  /// The viewer page of one call (a link back to the list included).
  viewer::ViewPage PageOf(const DebugCall& call) const;

 private:
  const std::uint32_t keep_last_;
  const std::uint32_t max_points_;
  mutable std::mutex mu_;
  std::deque<std::shared_ptr<const DebugCall>> calls_;  // newest first
  std::uint64_t next_id_ = 1;
};

}  // namespace tubepick::server
