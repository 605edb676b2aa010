#pragma once

#include <chrono>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <spdlog/formatter.h>

namespace tubepick::server {

/// Everything the one log line per RPC says. Times in milliseconds.
struct CallRecord {
  std::string rpc;
  std::string request_id;
  std::string peer;
  /// gRPC status code name ("OK", "INVALID_ARGUMENT", ...) and, when not OK, its message.
  std::string code;
  std::string message;
  /// Cloud points received (bytes / 12; a stream's announced size).
  std::uint64_t points = 0;
  /// Tubes modeled and plans returned (0 when the call failed or does not plan).
  std::uint32_t tubes = 0;
  std::uint32_t plans = 0;
  /// Waiting for a worker, running on it, and arrival to answer.
  double queue_ms = 0.0;
  double run_ms = 0.0;
  double total_ms = 0.0;
  /// Cancelled or expired calls: from the stop request (cancel or deadline) until the worker was
  /// free again — the cancellation latency the service promises to keep under 100 ms.
  std::optional<double> stop_ms;
  /// Codes of the modeling's warnings in the answer (ModelingWarning.code), e.g.
  /// "tube_length_shorter_than_scan": the call succeeded, but a cell input probably does not fit.
  std::vector<std::string> warnings;
};

/// `call rpc=PlanPick id=… peer=… code=OK points=… tubes=… plans=… queue_ms=… run_ms=… total_ms=…`
/// (+ `stop_ms=…`, `warnings=a,b` and `message="…"` when set).
std::string FormatCallText(const CallRecord& record);
/// The same fields as one JSON object (`{"event":"call","rpc":…}`), strings escaped.
std::string FormatCallJson(const CallRecord& record);
/// "2026-12-02T17:45:14.586Z": a time in UTC to the millisecond (log lines, /debug/calls).
std::string UtcText(std::chrono::system_clock::time_point time);
/// `text` with JSON string escaping, without the quotes.
std::string JsonEscape(const std::string& text);
/// `["a","b"]`: the strings escaped (JsonEscape), as a JSON array.
std::string JsonStringArray(const std::vector<std::string>& strings);

/// spdlog formatter writing one JSON object per line: {"time":"…Z","level":"info","msg":"…"}.
/// A message that is itself a JSON object ({…}, as LogCall writes in JSON mode) is merged into the
/// line instead of quoted, so call records stay machine-readable fields.
class JsonLineFormatter final : public spdlog::formatter {
 public:
  void format(const spdlog::details::log_msg& msg, spdlog::memory_buf_t& dest) override;
  std::unique_ptr<spdlog::formatter> clone() const override;
};

/// Sets the default logger's level (spdlog name) and format ("text": spdlog's default pattern;
/// "json": JsonLineFormatter), and flushes every line at info and above.
/// @throws InvalidArgument for an unknown level or format.
void ConfigureLogging(const std::string& level, const std::string& format);

/// Writes the call's line to the default logger in the configured format: info, or warn for
/// INTERNAL / UNKNOWN / DATA_LOSS.
void LogCall(const CallRecord& record);

}  // namespace tubepick::server
