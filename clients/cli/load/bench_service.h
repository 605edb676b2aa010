#pragma once

#include <CLI/CLI.hpp>

namespace tubepick::cli {

/// `tubepick bench service`: the path users run, measured against the in-process pipeline in one
/// run. Starts a real tubepick-server (the sibling executable) on loopback and, per profile:
/// - the in-process pipeline (modeling, planning without simulation, placements) on a fresh copy of
///   the packed cloud per call, on the server's thread budget per call;
/// - PlanPick through the server at each concurrency: the client's pack time, the whole call, the
///   server-side time per stage (from the response) and the rest (transfer, parsing, queueing);
/// then the server's peak RSS after a run at the highest concurrency. Medians, ratios to the
/// in-process pipeline, plans/s; no warm-up call.
void AddBenchServiceCommand(CLI::App& bench);

}  // namespace tubepick::cli
