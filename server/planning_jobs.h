#pragma once

#include <cstdint>

#include "core/common/stop_token.h"
#include "server/request_validation.h"
#include "server/server_config.h"
#include "tubepick/v1/modeling.pb.h"
#include "tubepick/v1/planning.pb.h"
#include "tubepick/v1/wrench.pb.h"

namespace tubepick::server {

/// The work behind each RPC, independent of gRPC (runs on a planning worker). `stop` is polled in
/// modeling and simulation loops: a cancelled or expired call throws tubepick::Cancelled within
/// ~100 ms. Core InvalidArgument (e.g. a degenerate cloud) propagates. `threads` is the call's
/// thread budget (ThreadsPerCall): every parallel region of modeling and simulation runs on at most
/// that many threads, in place of the profile's modeling.threads (0 = the available cores). The
/// outcome does not depend on it.

v1::ModelTubesResponse RunModelTubes(const PlanningJob& job, std::uint32_t threads, const StopToken* stop);

/// Models, classifies, simulates (unless job.disable_simulation), ranks, truncates to
/// job.max_plans (0 = all), attaches placements. Same job ⇒ the same response except its timings.
v1::PlanPickResponse RunPlanPick(const PlanningJob& job, const PlanningDefaults& defaults,
                                 std::uint32_t threads, const StopToken* stop);

}  // namespace tubepick::server
