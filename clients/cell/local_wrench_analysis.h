#pragma once

#include <string>

#include "core/wrench/wrench_params.h"
#include "tubepick/v1/wrench.pb.h"

namespace tubepick::cell {

/// The wrench parameters of `profile` ("" = "fast", the server's default profile), as the
/// planner's AnalyzeWrench uses them.
WrenchParams ProfileWrenchParams(const std::string& profile);

/// AnalyzeWrench run in the controller's process, for when the planner cannot be reached while a
/// tube is held: the server's analysis (wire/wrench_analysis.h) with the wrench parameters of
/// `profile` ("" = "fast", the server's default profile) and the request's variant.
/// @throws InvalidArgument for a request the server would reject (same messages).
v1::AnalyzeWrenchResponse LocalAnalyzeWrench(const v1::AnalyzeWrenchRequest& request,
                                             const std::string& profile);

}  // namespace tubepick::cell
