#include "viewer/view_page.h"

#include <chrono>
#include <cstring>

#include <fmt/chrono.h>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "wire/proto_convert.h"

namespace tubepick::viewer {
namespace {

using nlohmann::json;

json Vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

json PoseJson(const Eigen::Isometry3d& X) {
  const Eigen::Quaterniond q(X.rotation());
  return {{"position", Vec(X.translation())}, {"orientation", json::array({q.x(), q.y(), q.z(), q.w()})}};
}

json CellJson(const CellConfig& cell, const ToolParams& tool) {
  return {
      {"bin", {{"inner_size", Vec(cell.bin.inner_size)}}},
      {"X_BinPlace", PoseJson(cell.place.X_BinPlace)},
      {"tube", {{"radius", cell.tube.radius}, {"length", cell.tube.length}, {"mass", cell.tube.mass}}},
      {"gripper",
       {{"finger_size", Vec(tool.finger_size)},
        {"finger_tip_depth", tool.finger_tip_depth},
        {"housing_size", Vec(tool.housing_size)},
        {"housing_gap", tool.housing_gap}}},
  };
}

std::string CloudBytes(const ViewCloud& cloud) {
  // Little-endian float32 triples: the in-memory layout on the hosts we build for.
  static_assert(sizeof(float) == 4);
  std::string bytes(cloud.xyz_Bin.size() * sizeof(float), '\0');
  if (!bytes.empty()) std::memcpy(bytes.data(), cloud.xyz_Bin.data(), bytes.size());
  return bytes;
}

// A frame's JSON text: small fields through nlohmann, the responses spliced in as proto3 JSON.
std::string FrameJson(const ViewFrame& frame) {
  json head = {{"label", frame.label}};
  if (!frame.note.empty()) head["note"] = frame.note;
  if (!frame.error.empty()) head["error"] = frame.error;
  if (frame.chosen_plan) head["chosen_plan"] = *frame.chosen_plan;
  if (frame.cloud) {
    head["cloud"] = {{"points", frame.cloud->size()},
                     {"total_points", frame.cloud->total_points},
                     {"xyz", Base64(CloudBytes(*frame.cloud))}};
  }
  std::string text = head.dump();
  text.pop_back();  // the closing brace: the responses follow
  if (frame.plan) text += ",\"plan\":" + ToJson(*frame.plan, false);
  if (frame.modeling) text += ",\"modeling\":" + ToJson(*frame.modeling, false);
  text += '}';
  return text;
}

std::string NowUtc() {
  return fmt::format("{:%Y-%m-%dT%H:%M:%SZ}",
                     fmt::gmtime(std::chrono::system_clock::to_time_t(std::chrono::system_clock::now())));
}

}  // namespace

std::string PageDataJson(const ViewPage& page) {
  json links = json::array();
  for (const ViewLink& l : page.links) links.push_back({{"label", l.label}, {"href", l.href}});
  json head = {{"format", "tubepick-view/1"}, {"title", page.title},
               {"generated", NowUtc()},       {"source", page.source},
               {"links", std::move(links)},   {"cell", CellJson(page.cell, page.tool)}};
  std::string text = head.dump();
  text.pop_back();
  text += ",\"frames\":[";
  for (std::size_t i = 0; i < page.frames.size(); ++i) {
    if (i > 0) text += ',';
    text += FrameJson(page.frames[i]);
  }
  text += "]}";
  return text;
}

std::string PageHtml(const ViewPage& page) {
  const std::string data = PageDataJson(page);
  const std::string_view script = ViewerBundle();
  std::string html;
  html.reserve(data.size() + script.size() + 512);
  html +=
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"><title>";
  html += HtmlEscape(page.title);
  html += "</title></head>\n<body>\n<script type=\"application/json\" id=\"tubepick-data\">";
  // '<' occurs in JSON only inside strings, where \u003c means the same: no "</script" or "<!--"
  // can end or bend the element.
  for (const char c : data) {
    if (c == '<')
      html += "\\u003c";
    else
      html += c;
  }
  html += "</script>\n<script>";
  html += script;
  html += "</script>\n</body></html>\n";
  return html;
}

std::string HtmlEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string Base64(std::string_view bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const std::uint32_t v = (std::uint32_t(std::uint8_t(bytes[i])) << 16) |
                            (std::uint32_t(std::uint8_t(bytes[i + 1])) << 8) | std::uint8_t(bytes[i + 2]);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {
    std::uint32_t v = std::uint32_t(std::uint8_t(bytes[i])) << 16;
    if (rest == 2) v |= std::uint32_t(std::uint8_t(bytes[i + 1])) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

}  // namespace tubepick::viewer
