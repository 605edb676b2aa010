#pragma once

#include <CLI/CLI.hpp>

namespace tubepick::cli {

/// `tubepick load --target HOST:PORT --clouds DIR --concurrency C (--total N | --duration D)
///  [--rpc plan|model|plan-stream[,...]] [--no-sim] [--profile P] [--seed S] [--deadline S] [--warmup N]
///  [--json FILE] [--metrics-url URL [--rss-window S] [--rss-settle S] [--max-rss-growth PERCENT]
///  [--max-allocated-growth PERCENT]] [--fail-on-error]`:
/// a ghz-like load test of a running tubepick-server over recorded clouds (see load_engine.h); prints
/// requests/s, latency percentiles of successful calls and calls by status code, and with --metrics-url
/// the server's RSS (and its allocator's live bytes) over the run. --fail-on-error, --max-rss-growth and
/// --max-allocated-growth turn it into a check (exit 1).
void AddLoadCommand(CLI::App& app);

}  // namespace tubepick::cli
