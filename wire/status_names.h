#pragma once

#include <string>

#include <grpcpp/support/status.h>

namespace tubepick {

/// Canonical upper-case name of a gRPC status code ("OK", "RESOURCE_EXHAUSTED", ...), as metrics
/// labels, logs and reports spell it; "CODE_<n>" for a number outside the canonical set.
std::string StatusCodeName(grpc::StatusCode code);

}  // namespace tubepick
