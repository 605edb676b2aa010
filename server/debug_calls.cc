#include "server/debug_calls.h"

#include <fmt/chrono.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

namespace tubepick::server {
namespace {

std::string Label(const DebugCall& call) {
  return fmt::format("call {} · {} · {}", call.id, call.record.rpc, call.record.code);
}

}  // namespace

DebugCallStore::DebugCallStore(std::uint32_t keep_last, std::uint32_t max_points)
    : keep_last_(keep_last), max_points_(max_points) {}

std::uint64_t DebugCallStore::Add(const CallRecord& record, std::optional<DebugCapture> capture) {
  auto call = std::make_shared<DebugCall>();
  call->finished = std::chrono::system_clock::now();
  call->record = record;
  call->capture = std::move(capture);
  std::lock_guard lock(mu_);
  call->id = next_id_++;
  if (call->capture) call->capture->frame.label = Label(*call);
  calls_.push_front(std::move(call));
  while (calls_.size() > keep_last_) calls_.pop_back();
  return calls_.front()->id;
}

std::deque<std::shared_ptr<const DebugCall>> DebugCallStore::Calls() const {
  std::lock_guard lock(mu_);
  return calls_;
}

std::shared_ptr<const DebugCall> DebugCallStore::Find(std::uint64_t id) const {
  std::lock_guard lock(mu_);
  for (const auto& call : calls_) {
    if (call->id == id) return call;
  }
  return nullptr;
}

std::string DebugCallStore::ListHtml() const {
  std::string rows;
  for (const auto& call : Calls()) {
    const CallRecord& r = call->record;
    // An answered call's message column lists its modeling warnings (ModelingWarning.code).
    const std::string message = r.message.empty() && !r.warnings.empty()
                                    ? fmt::format("warnings: {}", fmt::join(r.warnings, ", "))
                                    : r.message;
    rows += fmt::format(
        "<tr class=\"{}\"><td><a data-call-id=\"{}\" href=\"/debug/calls/{}\">call {}</a></td><td>{}</td>"
        "<td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.0f}</td><td>{}</td><td>{}</td></tr>\n",
        r.code == "OK" ? "ok" : "failed", call->id, call->id, call->id, UtcText(call->finished),
        viewer::HtmlEscape(r.rpc), viewer::HtmlEscape(r.code), r.points, r.tubes, r.plans, r.total_ms,
        viewer::HtmlEscape(r.request_id), viewer::HtmlEscape(message));
  }
  return fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>tubepick: last calls</title>"
      "<style>body{{font:14px system-ui,sans-serif;margin:24px;background:#f6f7f9;color:#1d2430}}"
      "table{{border-collapse:collapse;background:#fff}}th,td{{padding:6px 10px;border-bottom:1px solid "
      "#e3e6ea;"
      "text-align:left;vertical-align:top}}th{{background:#eef1f4}}tr.failed td{{color:#a3261b}}"
      "td:nth-child(n+5):nth-child(-n+8){{text-align:right}}</style></head>\n<body>\n"
      "<h1>tubepick-server: the last {} planning calls</h1>\n<p>Newest first; {} kept (debug.keep_last). "
      "Each page is the 3-D viewer of that call: its cloud (at most {} points), tubes, grasps and "
      "trajectories. JSON: <a href=\"/debug/calls.json\">/debug/calls.json</a>.</p>\n"
      "<table id=\"calls\"><thead><tr><th>call</th><th>finished (UTC)</th><th>rpc</th><th>code</th>"
      "<th>points</th><th>tubes</th><th>plans</th><th>total ms</th><th>request id</th><th>message</th></tr>"
      "</thead><tbody>\n{}</tbody></table>\n</body></html>\n",
      keep_last_, keep_last_, max_points_, rows);
}

std::string DebugCallStore::ListJson() const {
  std::string out = "[";
  bool first = true;
  for (const auto& call : Calls()) {
    const CallRecord& r = call->record;
    out += fmt::format(
        "{}{{\"id\":{},\"href\":\"/debug/calls/{}\",\"finished\":\"{}\",\"rpc\":\"{}\",\"code\":\"{}\","
        "\"message\":\"{}\",\"request_id\":\"{}\",\"points\":{},\"tubes\":{},\"plans\":{},\"total_ms\":{:.1f}"
        ",\"warnings\":{},\"has_cloud\":{}}}",
        first ? "" : ",", call->id, call->id, UtcText(call->finished), JsonEscape(r.rpc), JsonEscape(r.code),
        JsonEscape(r.message), JsonEscape(r.request_id), r.points, r.tubes, r.plans, r.total_ms,
        JsonStringArray(r.warnings), call->capture && call->capture->frame.cloud ? "true" : "false");
    first = false;
  }
  return out + "]";
}

viewer::ViewPage DebugCallStore::PageOf(const DebugCall& call) const {
  viewer::ViewPage page;
  const CallRecord& r = call.record;
  page.title = fmt::format("tubepick call {}: {} {}", call.id, r.rpc, r.code);
  page.source = fmt::format("tubepick-server, call {} (request id {}, peer {}), finished {}", call.id,
                            r.request_id, r.peer, UtcText(call.finished));
  page.links.push_back({"all kept calls", "/debug/calls"});
  page.links.push_back({"this call as JSON", fmt::format("/debug/calls/{}.json", call.id)});
  viewer::ViewFrame frame;
  if (call.capture) {
    page.cell = call.capture->cell;
    page.tool = call.capture->tool;
    frame = call.capture->frame;
  } else {
    frame.label = Label(call);
  }
  frame.note =
      fmt::format("{} points, {} tubes, {} plans; queued {:.0f} ms, ran {:.0f} ms, answered after {:.0f} ms",
                  r.points, r.tubes, r.plans, r.queue_ms, r.run_ms, r.total_ms);
  if (r.code != "OK") frame.error = r.code + ": " + r.message;
  page.frames.push_back(std::move(frame));
  return page;
}

}  // namespace tubepick::server
