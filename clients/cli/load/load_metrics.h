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
  /// The allocator's live bytes in the same scrape (tubepick_allocator_allocated_bytes); 0 when the
  /// server does not export them.
  std::uint64_t allocated_bytes = 0;
};

/// What the samples say about the server's memory over a run (the "RSS flat within 10 %" check).
struct RssSummary {
  std::string url;
  double interval_seconds = 0.0;
  std::vector<RssSample> samples;
  /// Scrapes that failed (connection refused, no process_resident_memory_bytes, ...).
  std::uint64_t failed_scrapes = 0;
  /// Length of the first and last comparison windows, seconds.
  double window_seconds = 60.0;
  /// How long after the first sample the first window begins, seconds. Under load the server's RSS
  /// climbs for a while before it swings about a steady level: jemalloc keeps freed pages for its
  /// ~10 s decay, so a freshly loaded server holds less than it will. A first window taken during
  /// that climb compares the climb, not a leak (measured: 280 MB at the first scrape, 700 MB 4 s later).
  double settle_seconds = 0.0;
  /// Where the last window ends, seconds: the end of a --duration run's measured phase (samples taken
  /// while its last calls drain fall in no window), else the last sample.
  double end_seconds = 0.0;
  /// Highest RSS in the first window [t0, t0 + window] (t0 = the first sample + settle) and in the last
  /// [end − window, end], and over all samples, bytes.
  std::uint64_t first_window_max = 0;
  std::uint64_t last_window_max = 0;
  std::uint64_t peak = 0;
  /// (last_window_max − first_window_max) / first_window_max, percent.
  double growth_percent = 0.0;
  /// Samples in each window.
  std::size_t first_window_samples = 0;
  std::size_t last_window_samples = 0;
  /// Mean of each window's samples, bytes: with evenly spaced samples, the time-averaged RSS. This is
  /// the figure the memory check compares. The server's RSS follows its calls in flight (it hands
  /// a call's memory back when the call ends), swinging by 100+ MB within a second; the time average
  /// adds up each call's memory whether or not concurrent calls happen to peak together, whereas a
  /// window's maximum hangs on one scrape and its median on how the calls' phases line up.
  double first_window_mean = 0.0;
  double last_window_mean = 0.0;
  /// (last_window_mean − first_window_mean) / first_window_mean, percent.
  double mean_growth_percent = 0.0;
  /// Medians of each window (nearest rank: the smallest sample with at least half of the window's
  /// samples at or below it), bytes, and their change, percent. Reported, not judged.
  std::uint64_t first_window_median = 0;
  std::uint64_t last_window_median = 0;
  double median_growth_percent = 0.0;
  /// Means of each window's allocator live bytes (RssSample::allocated_bytes) and their change,
  /// percent: a leak grows them, the allocator's cache of freed pages does not. Reported, not judged;
  /// 0 when a window has a sample without them.
  double first_window_allocated_mean = 0.0;
  double last_window_allocated_mean = 0.0;
  double allocated_growth_percent = 0.0;
  /// When the sampler started (the samples' 0), seconds since the Unix epoch; 0 when not known.
  double start_unix_seconds = 0.0;
  /// Mean number of calls in flight over each window (AddCallsInFlight; 0 when not added), and the
  /// change of the live bytes per call in flight, percent. Each call holds its cloud and what it
  /// builds from it, so at a fixed rate (tubepick load --rate) the live bytes follow the calls in
  /// flight, that is their latency, while a leak grows them per call; with a closed loop the calls in
  /// flight are the concurrency and the two changes are the same.
  double first_window_calls_in_flight = 0.0;
  double last_window_calls_in_flight = 0.0;
  double allocated_per_call_growth_percent = 0.0;

  /// Where the first window begins: settle_seconds after the first sample (0 without samples).
  double FirstWindowBegin() const { return samples.empty() ? 0.0 : samples.front().seconds + settle_seconds; }
};

/// One measured call on the samples' clock: its start (seconds since the sampler started) and length.
struct CallSpan {
  double start = 0.0;
  double seconds = 0.0;
};

/// Summarises samples (sorted by time) over windows of `window_seconds`: the first begins
/// `settle_seconds` after the first sample, the last ends at `end_seconds` when given, else at the last
/// sample.
RssSummary SummarizeRss(std::vector<RssSample> samples, double window_seconds,
                        std::optional<double> end_seconds = std::nullopt, double settle_seconds = 0.0);

/// Fills the calls-in-flight figures of `summary` (SummarizeRss's) from the run's calls: the time each
/// call overlaps a window, summed, over the window's length. Leaves them 0 when either window has
/// no call in flight or there are no live bytes to divide.
void AddCallsInFlight(RssSummary& summary, const std::vector<CallSpan>& calls);

/// Why a run fails the memory check, or std::nullopt when it passes: fails when either window holds
/// fewer than `min_window_samples` samples, or when the mean RSS of the last window is more than
/// `max_growth_percent` above the mean of the first. A fall is no failure (memory handed back).
std::optional<std::string> RssGrowthFailure(const RssSummary& summary, double max_growth_percent,
                                            std::size_t min_window_samples);

/// Why a run fails the leak check, or std::nullopt when it passes: as RssGrowthFailure on the
/// allocator's live bytes per call in flight when AddCallsInFlight filled them, else on the live bytes
/// (first_window_allocated_mean against last_window_allocated_mean); also fails when the server did not
/// export them.
std::optional<std::string> AllocatedGrowthFailure(const RssSummary& summary, double max_growth_percent,
                                                  std::size_t min_window_samples);

/// Scrapes process_resident_memory_bytes (and tubepick_allocator_allocated_bytes when exported) from a
/// Prometheus endpoint every `interval` on its own
/// thread, from construction until Stop().
class RssSampler {
 public:
  RssSampler(std::string url, std::chrono::milliseconds interval);
  ~RssSampler();
  RssSampler(const RssSampler&) = delete;
  RssSampler& operator=(const RssSampler&) = delete;

  /// Takes a last sample, stops the thread and summarises (see SummarizeRss). Call once.
  RssSummary Stop(double window_seconds = 60.0, std::optional<double> end_seconds = std::nullopt,
                  double settle_seconds = 0.0);

 private:
  void Loop();
  void SampleOnce();

  std::string url_;
  std::chrono::milliseconds interval_;
  std::chrono::steady_clock::time_point start_;
  double start_unix_seconds_ = 0.0;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::vector<RssSample> samples_;
  std::uint64_t failed_ = 0;
  std::thread thread_;
};

}  // namespace tubepick::cli
