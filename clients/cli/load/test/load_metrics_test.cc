// The metrics scrape of the load tool: Prometheus text parsing, the RSS summary, HTTP errors.
#include "clients/cli/load/load_metrics.h"

#include <gtest/gtest.h>

#include <cmath>

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace tubepick::cli {
namespace {

TEST(LoadMetrics, PrometheusSampleMatchesNameAndLabels) {
  const std::string text =
      "# HELP process_resident_memory_bytes Resident memory.\n"
      "# TYPE process_resident_memory_bytes gauge\n"
      "process_resident_memory_bytes_total_bogus 1\n"
      "process_resident_memory_bytes 123456789\n"
      "tubepick_rpc_calls_total{method=\"PlanPick\",code=\"OK\"} 4\n"
      "tubepick_rpc_calls_total{method=\"ModelTubes\",code=\"OK\"} 7\n";
  EXPECT_EQ(PrometheusSample(text, "process_resident_memory_bytes"), 123456789.0);
  EXPECT_EQ(PrometheusSample(text, "tubepick_rpc_calls_total", "method=\"ModelTubes\""), 7.0);
  EXPECT_EQ(PrometheusSample(text, "tubepick_rpc_calls_total"), 4.0);
  EXPECT_FALSE(PrometheusSample(text, "process_virtual_memory_bytes").has_value());
}

TEST(LoadMetrics, SummarizeRssComparesFirstAndLastMinute) {
  // 10 minutes, one sample every 30 s: 100 MB in the first minute, 104 MB peak mid-run, 105 MB
  // in the last minute.
  std::vector<RssSample> samples;
  for (int i = 0; i <= 20; ++i) {
    std::uint64_t mb = i <= 2 ? 100 : (i >= 18 ? 105 : 104);
    if (i == 10) mb = 120;
    samples.push_back({30.0 * i, mb * 1'000'000});
  }
  const RssSummary s = SummarizeRss(samples, 60.0);
  EXPECT_EQ(s.first_window_max, 100'000'000u);
  EXPECT_EQ(s.last_window_max, 105'000'000u);
  EXPECT_EQ(s.peak, 120'000'000u);
  EXPECT_NEAR(s.growth_percent, 5.0, 1e-9);
}

TEST(LoadMetrics, SummarizeRssOverWindowsEndingAtTheMeasuredPhase) {
  // 120 s measured, a sample every second, then 3 s of draining calls. RSS follows the calls in
  // flight: it alternates 100 / 200 / 150 MB in the first 30 s and 110 / 210 / 160 MB in the last 30 s
  // (medians 150 and 160 MB), with one spike of 900 MB in each window that the maximum follows.
  std::vector<RssSample> samples;
  for (int t = 0; t <= 123; ++t) {
    const std::uint64_t base = t < 60 ? 100 : 110;
    std::uint64_t mb = base + (t % 3 == 1 ? 100 : (t % 3 == 2 ? 50 : 0));
    if (t == 10 || t == 100) mb = 900;
    if (t > 120) mb = 5000;  // draining: outside every window
    samples.push_back({static_cast<double>(t), mb * 1'000'000});
  }
  const RssSummary s = SummarizeRss(samples, 30.0, 120.0);
  EXPECT_EQ(s.end_seconds, 120.0);
  EXPECT_EQ(s.first_window_samples, 31u);  // t = 0 .. 30
  EXPECT_EQ(s.last_window_samples, 31u);   // t = 90 .. 120
  EXPECT_EQ(s.first_window_median, 150'000'000u);
  EXPECT_EQ(s.last_window_median, 160'000'000u);
  EXPECT_NEAR(s.median_growth_percent, 100.0 * 10.0 / 150.0, 1e-9);
  // Means (the judged figure): 11 × 100 + 9 × 200 + 900 + 10 × 150 = 5300 MB over 31 samples, and
  // 11 × 110 + 9 × 210 + 900 + 10 × 160 = 5600 MB.
  EXPECT_NEAR(s.first_window_mean, 5300e6 / 31.0, 1e-3);
  EXPECT_NEAR(s.last_window_mean, 5600e6 / 31.0, 1e-3);
  EXPECT_NEAR(s.mean_growth_percent, 100.0 * 300.0 / 5300.0, 1e-9);
  EXPECT_EQ(s.first_window_max, 900'000'000u);
  EXPECT_EQ(s.last_window_max, 900'000'000u);
  EXPECT_EQ(s.peak, 5'000'000'000u);
  EXPECT_FALSE(RssGrowthFailure(s, 10.0, 15).has_value());

  // Without an end the last window ends at the last sample and takes in the drain.
  const RssSummary to_last = SummarizeRss(samples, 30.0);
  EXPECT_EQ(to_last.end_seconds, 123.0);
  EXPECT_EQ(to_last.last_window_max, 5'000'000'000u);
}

TEST(LoadMetrics, TheFirstWindowBeginsAfterTheSettlingTime) {
  // A freshly loaded server's RSS climbs from 200 to 600 MB over its first 10 s (the allocator keeps
  // freed pages for ~10 s) and then stays at 600 MB: no leak. Compared from the first sample, the climb
  // reads as growth; compared after 30 s of settling, it does not.
  std::vector<RssSample> samples;
  for (int t = 0; t <= 120; ++t)
    samples.push_back(
        {static_cast<double>(t), static_cast<std::uint64_t>(std::min(t, 10) * 40 + 200) * 1'000'000});
  const RssSummary from_start = SummarizeRss(samples, 30.0, 120.0);
  EXPECT_GT(from_start.mean_growth_percent, 10.0);
  EXPECT_TRUE(RssGrowthFailure(from_start, 10.0, 15).has_value());

  const RssSummary settled = SummarizeRss(samples, 30.0, 120.0, 30.0);
  EXPECT_EQ(settled.settle_seconds, 30.0);
  EXPECT_EQ(settled.first_window_samples, 31u);  // t = 30 .. 60
  EXPECT_EQ(settled.first_window_mean, 600e6);
  EXPECT_EQ(settled.mean_growth_percent, 0.0);
  EXPECT_FALSE(RssGrowthFailure(settled, 10.0, 15).has_value());

  // A leak of 2 MB a second after the climb (+18 % between the windows) still fails, and the message says how
  // long it settled.
  for (RssSample& r : samples)
    if (r.seconds > 10.0) r.bytes += static_cast<std::uint64_t>(r.seconds - 10.0) * 2'000'000;
  const std::optional<std::string> leak =
      RssGrowthFailure(SummarizeRss(samples, 30.0, 120.0, 30.0), 10.0, 15);
  ASSERT_TRUE(leak.has_value());
  EXPECT_NE(leak->find("after 30 s of settling"), std::string::npos) << *leak;
}

TEST(LoadMetrics, TheAllocatorsLiveBytesAreComparedWhenEverySampleHasThem) {
  // RSS flat at 500 MB while the live bytes grow from 200 to 260 MB: a leak the allocator's cache hides.
  std::vector<RssSample> samples;
  for (int t = 0; t <= 120; ++t)
    samples.push_back(
        {static_cast<double>(t), 500'000'000u, static_cast<std::uint64_t>(200 + t / 2) * 1'000'000});
  const RssSummary s = SummarizeRss(samples, 30.0, 120.0);
  EXPECT_EQ(s.mean_growth_percent, 0.0);
  EXPECT_NEAR(s.first_window_allocated_mean, 207.25e6, 0.5e6);  // 200 + t/2 over t = 0 .. 30, rounded down
  EXPECT_NEAR(s.last_window_allocated_mean, 252.25e6, 0.5e6);
  EXPECT_NEAR(s.allocated_growth_percent, 100.0 * 45.0 / 207.25, 0.5);

  const std::optional<std::string> leak = AllocatedGrowthFailure(s, 10.0, 15);
  ASSERT_TRUE(leak.has_value());
  EXPECT_NE(leak->find("live bytes grew +21.7 %"), std::string::npos) << *leak;
  EXPECT_FALSE(AllocatedGrowthFailure(s, 25.0, 15).has_value());
  EXPECT_FALSE(RssGrowthFailure(s, 10.0, 15).has_value());  // the RSS alone would not see it

  // A server that does not export them (0 in any sample of a window): nothing to compare, and the check
  // says so rather than passing.
  samples[100].allocated_bytes = 0;
  const RssSummary partial = SummarizeRss(samples, 30.0, 120.0);
  EXPECT_EQ(partial.first_window_allocated_mean, 0.0);
  EXPECT_EQ(partial.allocated_growth_percent, 0.0);
  const std::optional<std::string> unknown = AllocatedGrowthFailure(partial, 10.0, 15);
  ASSERT_TRUE(unknown.has_value());
  EXPECT_NE(unknown->find("exported no tubepick_allocator_allocated_bytes"), std::string::npos) << *unknown;
}

TEST(LoadMetrics, TheLiveBytesAreJudgedPerCallInFlight) {
  // A fixed rate of one call a second; the calls take 0.5 s in the first window and 0.6 s in the last
  // (a busier machine), and each holds 100 MB while in flight: the live bytes' window means grow +20 %,
  // the live bytes per call in flight not at all.
  std::vector<RssSample> samples;
  std::vector<CallSpan> calls;
  for (int k = 0; k < 120; ++k) calls.push_back({static_cast<double>(k), k < 60 ? 0.5 : 0.6});
  for (int i = 0; i <= 1200; ++i) {
    const double t = 0.1 * i;
    const double into_call = t - std::floor(t);
    const bool busy = into_call < (t < 60.0 ? 0.5 : 0.6) - 1e-9;
    samples.push_back({t, 400'000'000, busy ? 100'000'000u : 1u});
  }
  RssSummary s = SummarizeRss(samples, 30.0, 120.0);
  EXPECT_NEAR(s.allocated_growth_percent, 20.0, 1.0);
  EXPECT_TRUE(
      AllocatedGrowthFailure(s, 10.0, 15).has_value());  // read raw, the slower calls look like a leak
  AddCallsInFlight(s, calls);
  EXPECT_NEAR(s.first_window_calls_in_flight, 0.5, 0.02);
  EXPECT_NEAR(s.last_window_calls_in_flight, 0.6, 0.02);
  EXPECT_NEAR(s.allocated_per_call_growth_percent, 0.0, 2.0);
  EXPECT_FALSE(AllocatedGrowthFailure(s, 10.0, 15).has_value());

  // 40 MB more held from the last window on (a leak): +40 % per call in flight, named so.
  for (RssSample& r : samples)
    if (r.seconds >= 90.0) r.allocated_bytes += 40'000'000;
  RssSummary leak = SummarizeRss(samples, 30.0, 120.0);
  AddCallsInFlight(leak, calls);
  EXPECT_GT(leak.allocated_per_call_growth_percent, 30.0);
  const std::optional<std::string> failure = AllocatedGrowthFailure(leak, 10.0, 15);
  ASSERT_TRUE(failure.has_value());
  EXPECT_NE(failure->find("live bytes per call in flight grew"), std::string::npos) << *failure;
  EXPECT_NE(failure->find("at 0.60 calls in flight against"), std::string::npos) << *failure;
}

TEST(LoadMetrics, MedianIsTheNearestRank) {
  // Four samples in the window: the nearest-rank median is the 2nd smallest.
  const RssSummary s = SummarizeRss({{0, 40}, {1, 10}, {2, 30}, {3, 20}}, 10.0);
  EXPECT_EQ(s.first_window_median, 20u);
  EXPECT_EQ(s.first_window_mean, 25.0);
  EXPECT_EQ(s.last_window_median, 20u);
  EXPECT_EQ(s.median_growth_percent, 0.0);
  EXPECT_EQ(SummarizeRss({}, 30.0, 120.0).first_window_median, 0u);
}

TEST(LoadMetrics, RssGrowthFailureNamesTheReason) {
  std::vector<RssSample> samples;
  for (int t = 0; t <= 60; ++t)
    samples.push_back({static_cast<double>(t), t < 30 ? 100'000'000u : 112'000'000u});
  const RssSummary grew = SummarizeRss(samples, 20.0, 60.0);
  EXPECT_NEAR(grew.mean_growth_percent, 12.0, 1e-9);
  const std::optional<std::string> failure = RssGrowthFailure(grew, 10.0, 10);
  ASSERT_TRUE(failure.has_value());
  EXPECT_NE(failure->find("+12.0 %"), std::string::npos) << *failure;
  EXPECT_NE(failure->find("10.0 % allowed"), std::string::npos) << *failure;
  EXPECT_FALSE(RssGrowthFailure(grew, 12.5, 10).has_value());

  // A fall is memory handed back, not a failure.
  std::reverse(samples.begin(), samples.end());
  for (int t = 0; t <= 60; ++t) samples[t].seconds = t;
  EXPECT_FALSE(RssGrowthFailure(SummarizeRss(samples, 20.0, 60.0), 10.0, 10).has_value());

  // Too few samples to judge (the endpoint stopped answering).
  const std::optional<std::string> sparse =
      RssGrowthFailure(SummarizeRss({{0, 1}, {60, 1}}, 20.0, 60.0), 10.0, 10);
  ASSERT_TRUE(sparse.has_value());
  EXPECT_NE(sparse->find("too few RSS samples"), std::string::npos) << *sparse;
}

TEST(LoadMetrics, HttpGetOfAClosedPortThrows) {
  EXPECT_THROW(HttpGet("http://127.0.0.1:1/metrics", std::chrono::seconds(2)), std::runtime_error);
  EXPECT_THROW(HttpGet("https://127.0.0.1:1/metrics", std::chrono::seconds(2)), std::runtime_error);
}

TEST(LoadMetrics, AUrlWithoutAPathScrapesMetrics) {
  try {
    HttpGet("http://127.0.0.1:1", std::chrono::seconds(2));
    FAIL() << "a closed port must throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("http://127.0.0.1:1/metrics"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tubepick::cli
