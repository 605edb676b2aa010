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

RssSummary SummarizeRss(std::vector<RssSample> samples, double window_seconds,
                        std::optional<double> end_seconds, double settle_seconds) {
  RssSummary s;
  s.window_seconds = window_seconds;
  s.settle_seconds = settle_seconds;
  s.samples = std::move(samples);
  if (s.samples.empty()) {
    s.end_seconds = end_seconds.value_or(0.0);
    return s;
  }
  const double begin = s.FirstWindowBegin();
  const double end = end_seconds.value_or(s.samples.back().seconds);
  s.end_seconds = end;
  std::vector<std::uint64_t> first;
  std::vector<std::uint64_t> last;
  std::vector<std::uint64_t> first_allocated;
  std::vector<std::uint64_t> last_allocated;
  for (const RssSample& r : s.samples) {
    s.peak = std::max(s.peak, r.bytes);
    if (r.seconds >= begin && r.seconds <= begin + window_seconds) {
      first.push_back(r.bytes);
      first_allocated.push_back(r.allocated_bytes);
    }
    if (r.seconds >= end - window_seconds && r.seconds <= end) {
      last.push_back(r.bytes);
      last_allocated.push_back(r.allocated_bytes);
    }
  }
  // The change from `from` to `to`, percent; 0 when there is nothing to compare with.
  const auto percent = [](double from, double to) { return from > 0.0 ? 100.0 * (to - from) / from : 0.0; };
  const auto median = [](std::vector<std::uint64_t>& v) -> std::uint64_t {
    if (v.empty()) return 0;
    // Nearest rank: the ceil(n / 2)-th smallest.
    const std::size_t rank = (v.size() + 1) / 2 - 1;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(rank), v.end());
    return v[rank];
  };
  const auto mean = [](const std::vector<std::uint64_t>& v) {
    double sum = 0.0;
    for (const std::uint64_t b : v) sum += static_cast<double>(b);
    return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
  };
  s.first_window_mean = mean(first);
  s.last_window_mean = mean(last);
  s.mean_growth_percent = percent(s.first_window_mean, s.last_window_mean);
  if (!first.empty()) s.first_window_max = *std::max_element(first.begin(), first.end());
  if (!last.empty()) s.last_window_max = *std::max_element(last.begin(), last.end());
  s.first_window_samples = first.size();
  s.last_window_samples = last.size();
  s.first_window_median = median(first);
  s.last_window_median = median(last);
  s.growth_percent = percent(static_cast<double>(s.first_window_max), static_cast<double>(s.last_window_max));
  s.median_growth_percent =
      percent(static_cast<double>(s.first_window_median), static_cast<double>(s.last_window_median));
  const auto all_have = [](const std::vector<std::uint64_t>& v) {
    return !v.empty() && std::find(v.begin(), v.end(), 0u) == v.end();
  };
  if (all_have(first_allocated) && all_have(last_allocated)) {
    s.first_window_allocated_mean = mean(first_allocated);
    s.last_window_allocated_mean = mean(last_allocated);
    s.allocated_growth_percent = percent(s.first_window_allocated_mean, s.last_window_allocated_mean);
  }
  return s;
}

void AddCallsInFlight(RssSummary& s, const std::vector<CallSpan>& calls) {
  // Call-seconds inside [from, to], over its length.
  const auto in_flight = [&calls](double from, double to) {
    double busy = 0.0;
    for (const CallSpan& c : calls)
      busy += std::max(0.0, std::min(to, c.start + c.seconds) - std::max(from, c.start));
    return to > from ? busy / (to - from) : 0.0;
  };
  if (s.samples.empty()) return;
  const double begin = s.FirstWindowBegin();
  const double first = in_flight(begin, begin + s.window_seconds);
  const double last = in_flight(s.end_seconds - s.window_seconds, s.end_seconds);
  if (!(first > 0.0) || !(last > 0.0) || !(s.first_window_allocated_mean > 0.0)) return;
  s.first_window_calls_in_flight = first;
  s.last_window_calls_in_flight = last;
  s.allocated_per_call_growth_percent =
      100.0 * ((s.last_window_allocated_mean / last) / (s.first_window_allocated_mean / first) - 1.0);
}

namespace {

// Why either window is too thin to judge (the endpoint was not answering), or std::nullopt.
std::optional<std::string> TooFewSamples(const RssSummary& s, std::size_t min_window_samples) {
  if (s.first_window_samples >= min_window_samples && s.last_window_samples >= min_window_samples)
    return std::nullopt;
  return fmt::format(
      "too few RSS samples to judge: {} in the first {:.0f} s, {} in the last, at least {} needed ({} failed "
      "scrapes)",
      s.first_window_samples, s.window_seconds, s.last_window_samples, min_window_samples, s.failed_scrapes);
}

}  // namespace

std::optional<std::string> RssGrowthFailure(const RssSummary& s, double max_growth_percent,
                                            std::size_t min_window_samples) {
  if (auto thin = TooFewSamples(s, min_window_samples)) return thin;
  if (s.mean_growth_percent > max_growth_percent)
    return fmt::format(
        "server RSS grew {:+.1f} % (mean of the last {:.0f} s {:.1f} MB against {:.1f} MB in the first "
        "{:.0f} s after {:.0f} s of settling), more than the {:.1f} % allowed",
        s.mean_growth_percent, s.window_seconds, s.last_window_mean / 1e6, s.first_window_mean / 1e6,
        s.window_seconds, s.settle_seconds, max_growth_percent);
  return std::nullopt;
}

std::optional<std::string> AllocatedGrowthFailure(const RssSummary& s, double max_growth_percent,
                                                  std::size_t min_window_samples) {
  if (auto thin = TooFewSamples(s, min_window_samples)) return thin;
  if (s.first_window_allocated_mean <= 0.0 || s.last_window_allocated_mean <= 0.0)
    return std::string(
        "the server exported no tubepick_allocator_allocated_bytes in every scrape of both windows (a server "
        "without jemalloc, e.g. a sanitizer build): its live bytes cannot be judged");
  if (s.first_window_calls_in_flight > 0.0) {
    if (s.allocated_per_call_growth_percent <= max_growth_percent) return std::nullopt;
    return fmt::format(
        "the server's live bytes per call in flight grew {:+.1f} % (tubepick_allocator_allocated_bytes, "
        "mean of the last {:.0f} s {:.1f} MB at {:.2f} calls in flight against {:.1f} MB at {:.2f} in the "
        "first {:.0f} s after {:.0f} s of settling), more than the {:.1f} % allowed: a leak",
        s.allocated_per_call_growth_percent, s.window_seconds, s.last_window_allocated_mean / 1e6,
        s.last_window_calls_in_flight, s.first_window_allocated_mean / 1e6, s.first_window_calls_in_flight,
        s.window_seconds, s.settle_seconds, max_growth_percent);
  }
  if (s.allocated_growth_percent > max_growth_percent)
    return fmt::format(
        "the server's live bytes grew {:+.1f} % (tubepick_allocator_allocated_bytes, mean of the last "
        "{:.0f} s {:.1f} MB against {:.1f} MB in the first {:.0f} s after {:.0f} s of settling), more than "
        "the {:.1f} % allowed: a leak",
        s.allocated_growth_percent, s.window_seconds, s.last_window_allocated_mean / 1e6,
        s.first_window_allocated_mean / 1e6, s.window_seconds, s.settle_seconds, max_growth_percent);
  return std::nullopt;
}

RssSampler::RssSampler(std::string url, std::chrono::milliseconds interval)
    : url_(std::move(url)),
      interval_(interval),
      start_(Clock::now()),
      start_unix_seconds_(
          std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count()),
      thread_([this] { Loop(); }) {}

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
  std::optional<double> allocated;
  try {
    const std::string text = HttpGet(url_, std::chrono::seconds(5));
    bytes = PrometheusSample(text, "process_resident_memory_bytes");
    allocated = PrometheusSample(text, "tubepick_allocator_allocated_bytes");
  } catch (const std::exception&) {
  }
  std::lock_guard lock(mutex_);
  if (bytes && *bytes >= 0)
    samples_.push_back({t, static_cast<std::uint64_t>(*bytes),
                        allocated && *allocated > 0 ? static_cast<std::uint64_t>(*allocated) : 0});
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

RssSummary RssSampler::Stop(double window_seconds, std::optional<double> end_seconds, double settle_seconds) {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  SampleOnce();
  std::lock_guard lock(mutex_);
  RssSummary summary = SummarizeRss(samples_, window_seconds, end_seconds, settle_seconds);
  summary.url = url_;
  summary.interval_seconds = std::chrono::duration<double>(interval_).count();
  summary.failed_scrapes = failed_;
  summary.start_unix_seconds = start_unix_seconds_;
  return summary;
}

}  // namespace tubepick::cli
