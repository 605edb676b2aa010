#include "server/request_log.h"

#include <fmt/chrono.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/details/log_msg.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <iterator>

#include "core/common/errors.h"

namespace tubepick::server {
namespace {

// Chosen by ConfigureLogging; process-wide like the default logger itself.
std::atomic<bool> g_json_logs{false};

std::string Ms(double ms) { return fmt::format("{:.1f}", ms); }

}  // namespace

std::string UtcText(std::chrono::system_clock::time_point time) {
  const auto since_epoch = time.time_since_epoch();
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(since_epoch);
  const auto millis = std::chrono::duration_cast<std::chrono::milliseconds>(since_epoch - seconds).count();
  return fmt::format("{:%Y-%m-%dT%H:%M:%S}.{:03d}Z", fmt::gmtime(std::chrono::system_clock::to_time_t(time)),
                     millis);
}

std::string JsonEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += fmt::format("\\u{:04x}", static_cast<unsigned>(static_cast<unsigned char>(c)));
        } else {
          out += c;
        }
    }
  }
  return out;
}

std::string JsonStringArray(const std::vector<std::string>& strings) {
  std::string out = "[";
  for (const std::string& s : strings)
    out += fmt::format("{}\"{}\"", out.size() > 1 ? "," : "", JsonEscape(s));
  return out + "]";
}

std::string FormatCallText(const CallRecord& r) {
  std::string out = fmt::format(
      "call rpc={} id={} peer={} code={} points={} tubes={} plans={} queue_ms={} run_ms={} "
      "total_ms={}",
      r.rpc, r.request_id, r.peer, r.code, r.points, r.tubes, r.plans, Ms(r.queue_ms), Ms(r.run_ms),
      Ms(r.total_ms));
  if (r.stop_ms) out += fmt::format(" stop_ms={}", Ms(*r.stop_ms));
  if (!r.warnings.empty()) out += fmt::format(" warnings={}", fmt::join(r.warnings, ","));
  if (!r.message.empty()) out += fmt::format(" message=\"{}\"", JsonEscape(r.message));
  return out;
}

std::string FormatCallJson(const CallRecord& r) {
  std::string out = fmt::format(
      R"({{"event":"call","rpc":"{}","request_id":"{}","peer":"{}","code":"{}","points":{},"tubes":{},"plans":{},)"
      R"("queue_ms":{},"run_ms":{},"total_ms":{})",
      JsonEscape(r.rpc), JsonEscape(r.request_id), JsonEscape(r.peer), JsonEscape(r.code), r.points, r.tubes,
      r.plans, Ms(r.queue_ms), Ms(r.run_ms), Ms(r.total_ms));
  if (r.stop_ms) out += fmt::format(R"(,"stop_ms":{})", Ms(*r.stop_ms));
  if (!r.warnings.empty()) out += R"(,"warnings":)" + JsonStringArray(r.warnings);
  if (!r.message.empty()) out += fmt::format(R"(,"message":"{}")", JsonEscape(r.message));
  out += '}';
  return out;
}

void JsonLineFormatter::format(const spdlog::details::log_msg& msg, spdlog::memory_buf_t& dest) {
  const std::string payload(msg.payload.data(), msg.payload.size());
  const spdlog::string_view_t level = spdlog::level::to_string_view(msg.level);
  auto out = std::back_inserter(dest);
  fmt::format_to(out, R"({{"time":"{}","level":"{}")", UtcText(msg.time),
                 std::string_view(level.data(), level.size()));
  if (payload.size() >= 2 && payload.front() == '{' && payload.back() == '}') {
    if (payload.size() > 2)
      fmt::format_to(out, ",{}", std::string_view(payload).substr(1));
    else
      fmt::format_to(out, "}}");
  } else {
    fmt::format_to(out, R"(,"msg":"{}"}})", JsonEscape(payload));
  }
  dest.push_back('\n');
}

std::unique_ptr<spdlog::formatter> JsonLineFormatter::clone() const {
  return std::make_unique<JsonLineFormatter>();
}

void ConfigureLogging(const std::string& level, const std::string& format) {
  const spdlog::level::level_enum parsed = spdlog::level::from_str(level);
  if (parsed == spdlog::level::off && level != "off")
    throw InvalidArgument(
        fmt::format("log_level: unknown level '{}' (trace, debug, info, warn, error, "
                    "critical, off)",
                    level));
  if (format != "text" && format != "json")
    throw InvalidArgument(fmt::format("log_format: '{}' is neither text nor json", format));
  spdlog::set_level(parsed);
  if (format == "json") {
    spdlog::set_formatter(std::make_unique<JsonLineFormatter>());
  } else {
    spdlog::set_pattern("%+");  // spdlog's default: [time] [level] message
  }
  g_json_logs.store(format == "json");
  spdlog::flush_on(spdlog::level::info);
}

void LogCall(const CallRecord& record) {
  const bool serious = record.code == "INTERNAL" || record.code == "UNKNOWN" || record.code == "DATA_LOSS";
  const std::string line = g_json_logs.load() ? FormatCallJson(record) : FormatCallText(record);
  spdlog::log(serious ? spdlog::level::warn : spdlog::level::info, "{}", line);
}

}  // namespace tubepick::server
