#include "clients/cli/load/load_metrics.h"

#include <curl/curl.h>
#include <fmt/core.h>

#include <algorithm>
#include <charconv>
#include <cstring>
#include <memory>
#include <stdexcept>

namespace tubepick::cli {
namespace {

using Clock = std::chrono::steady_clock;

/// libcurl's write callback: appends the received bytes to the std::string at `user`.
std::size_t AppendBody(char* data, std::size_t size, std::size_t count, void* user) {
  static_cast<std::string*>(user)->append(data, size * count);
  return size * count;
}

/// `url` with the default path /metrics when it names none ("http://host:9464").
std::string WithMetricsPath(const std::string& url) {
  const std::size_t scheme_end = url.find("://");
  const std::size_t authority = scheme_end == std::string::npos ? 0 : scheme_end + 3;
  return url.find('/', authority) == std::string::npos ? url + "/metrics" : url;
}

}  // namespace

std::string HttpGet(const std::string& url, std::chrono::milliseconds timeout) {
  static const bool initialised = curl_global_init(CURL_GLOBAL_DEFAULT) == CURLE_OK;
  const std::unique_ptr<CURL, decltype(&curl_easy_cleanup)> curl(curl_easy_init(), curl_easy_cleanup);
  if (!initialised || !curl) throw std::runtime_error(url + ": cannot initialise libcurl");
  const std::unique_ptr<curl_slist, decltype(&curl_slist_free_all)> headers(
      curl_slist_append(nullptr, "Accept: text/plain"), curl_slist_free_all);
  const std::string target = WithMetricsPath(url);
  std::string body;
  char error[CURL_ERROR_SIZE] = "";
  CURL* h = curl.get();
  curl_easy_setopt(h, CURLOPT_URL, target.c_str());
  curl_easy_setopt(h, CURLOPT_PROTOCOLS_STR, "http,https");
  curl_easy_setopt(h, CURLOPT_TIMEOUT_MS, static_cast<long>(timeout.count()));
  curl_easy_setopt(h, CURLOPT_NOSIGNAL, 1L);  // thread-safe timeouts
  curl_easy_setopt(h, CURLOPT_HTTPHEADER, headers.get());
  curl_easy_setopt(h, CURLOPT_ERRORBUFFER, error);
  curl_easy_setopt(h, CURLOPT_WRITEFUNCTION, AppendBody);
  curl_easy_setopt(h, CURLOPT_WRITEDATA, &body);
  if (const CURLcode rc = curl_easy_perform(h); rc != CURLE_OK)
    throw std::runtime_error(target + ": " + (error[0] != '\0' ? error : curl_easy_strerror(rc)));
  long status = 0;
  curl_easy_getinfo(h, CURLINFO_RESPONSE_CODE, &status);
  if (status != 200) throw std::runtime_error(fmt::format("{}: HTTP status {}", target, status));
  return body;
}

std::optional<double> PrometheusSample(std::string_view text, std::string_view name,
                                       std::string_view labels) {
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    if (line.empty() || line.front() == '#' || line.rfind(name, 0) != 0) continue;
    std::string_view rest = line.substr(name.size());
    std::string_view line_labels;
    if (!rest.empty() && rest.front() == '{') {
      const std::size_t close = rest.find('}');
      if (close == std::string_view::npos) continue;
      line_labels = rest.substr(1, close - 1);
      rest = rest.substr(close + 1);
    }
    if (rest.empty() || rest.front() != ' ') continue;  // a longer metric name with this prefix
    if (!labels.empty() && line_labels.find(labels) == std::string_view::npos) continue;
    while (!rest.empty() && rest.front() == ' ') rest.remove_prefix(1);
    const std::string value(rest.substr(0, rest.find(' ')));
    char* parse_end = nullptr;
    const double v = std::strtod(value.c_str(), &parse_end);
    if (parse_end == value.c_str()) continue;
    return v;
  }
  return std::nullopt;
}

RssSummary SummarizeRss(std::vector<RssSample> samples, double window_seconds) {
  RssSummary s;
  s.window_seconds = window_seconds;
  s.samples = std::move(samples);
  if (s.samples.empty()) return s;
  const double end = s.samples.back().seconds;
  for (const RssSample& r : s.samples) {
    s.peak = std::max(s.peak, r.bytes);
    if (r.seconds <= s.samples.front().seconds + window_seconds)
      s.first_window_max = std::max(s.first_window_max, r.bytes);
    if (r.seconds >= end - window_seconds) s.last_window_max = std::max(s.last_window_max, r.bytes);
  }
  if (s.first_window_max > 0)
    s.growth_percent = 100.0 *
                       (static_cast<double>(s.last_window_max) - static_cast<double>(s.first_window_max)) /
                       static_cast<double>(s.first_window_max);
  return s;
}

RssSampler::RssSampler(std::string url, std::chrono::milliseconds interval)
    : url_(std::move(url)), interval_(interval), start_(Clock::now()), thread_([this] { Loop(); }) {}

RssSampler::~RssSampler() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void RssSampler::SampleOnce() {
  const double t = std::chrono::duration<double>(Clock::now() - start_).count();
  std::optional<double> bytes;
  try {
    bytes = PrometheusSample(HttpGet(url_, std::chrono::seconds(5)), "process_resident_memory_bytes");
  } catch (const std::exception&) {
  }
  std::lock_guard lock(mutex_);
  if (bytes && *bytes >= 0)
    samples_.push_back({t, static_cast<std::uint64_t>(*bytes)});
  else
    ++failed_;
}

void RssSampler::Loop() {
  for (;;) {
    SampleOnce();
    std::unique_lock lock(mutex_);
    if (wake_.wait_for(lock, interval_, [this] { return stop_; })) return;
  }
}

RssSummary RssSampler::Stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  SampleOnce();
  std::lock_guard lock(mutex_);
  RssSummary summary = SummarizeRss(samples_, 60.0);
  summary.url = url_;
  summary.interval_seconds = std::chrono::duration<double>(interval_).count();
  summary.failed_scrapes = failed_;
  return summary;
}

}  // namespace tubepick::cli
