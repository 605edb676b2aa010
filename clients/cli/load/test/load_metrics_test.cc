// The metrics scrape of the load tool: Prometheus text parsing, the RSS summary, HTTP errors.
#include "clients/cli/load/load_metrics.h"

#include <gtest/gtest.h>

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
