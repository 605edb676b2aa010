#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

namespace tubepick::cli {

/// GET of an http:// or https:// URL ("http://HOST:PORT/PATH"; no path = /metrics) with libcurl;
/// returns the body of a 200 answer (a Prometheus scrape). No redirects are followed.
/// @throws std::runtime_error naming the URL when it cannot connect, times out or gets no 200.
std::string HttpGet(const std::string& url, std::chrono::milliseconds timeout);

/// The value of the first sample of metric `name` in a Prometheus text exposition whose labels
/// all match `labels` (e.g. `method="ModelTubes"`; empty = any sample of that name, with or without
/// labels). std::nullopt when there is none.
std::optional<double> PrometheusSample(std::string_view text, std::string_view name,
                                       std::string_view labels = {});

/// One scrape of the server's resident memory.
struct RssSample {
  /// Since the sampler started, seconds.
  double seconds = 0.0;
  std::uint64_t bytes = 0;
};

/// What the samples say about the server's memory over a run (the "RSS flat within 10 %" check).
struct RssSummary {
  std::string url;
  double interval_seconds = 0.0;
  std::vector<RssSample> samples;
  /// Scrapes that failed (connection refused, no process_resident_memory_bytes, ...).
  std::uint64_t failed_scrapes = 0;
  /// Window length of the first and last comparison windows, seconds (60).
  double window_seconds = 60.0;
  /// Highest RSS in [0, window] and in [end − window, end], and over the whole run, bytes.
  std::uint64_t first_window_max = 0;
  std::uint64_t last_window_max = 0;
  std::uint64_t peak = 0;
  /// (last_window_max − first_window_max) / first_window_max, percent.
  double growth_percent = 0.0;
};

/// Summarises samples (sorted by time) over windows of `window_seconds`.
RssSummary SummarizeRss(std::vector<RssSample> samples, double window_seconds);

/// Scrapes process_resident_memory_bytes from a Prometheus endpoint every `interval` on its own
/// thread, from construction until Stop().
class RssSampler {
 public:
  RssSampler(std::string url, std::chrono::milliseconds interval);
  ~RssSampler();
  RssSampler(const RssSampler&) = delete;
  RssSampler& operator=(const RssSampler&) = delete;

  /// Takes a last sample, stops the thread and summarises (60 s windows). Call once.
  RssSummary Stop();

 private:
  void Loop();
  void SampleOnce();

  std::string url_;
  std::chrono::milliseconds interval_;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::vector<RssSample> samples_;
  std::uint64_t failed_ = 0;
  std::thread thread_;
};

}  // namespace tubepick::cli
