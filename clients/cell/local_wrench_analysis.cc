#include "clients/cell/local_wrench_analysis.h"

#include "core/common/errors.h"
#include "core/params.h"
#include "wire/proto_convert.h"
#include "wire/wrench_analysis.h"

namespace tubepick::cell {

WrenchParams ProfileWrenchParams(const std::string& profile) {
  return ProfileParams(profile.empty() ? "fast" : profile).wrench;
}

v1::AnalyzeWrenchResponse LocalAnalyzeWrench(const v1::AnalyzeWrenchRequest& request,
                                             const std::string& profile) {
  WrenchJob job;
  job.reference.force = FromProto(request.reference().force(), "reference.force");
  job.reference.torque = FromProto(request.reference().torque(), "reference.torque");
  job.current.force = FromProto(request.current().force(), "current.force");
  job.current.torque = FromProto(request.current().torque(), "current.torque");
  job.tube_mass = request.tube_mass();
  job.X_BinTcp = FromProto(request.tcp_pose(), "tcp_pose");
  WrenchParams params = ProfileWrenchParams(profile);
  if (request.variant() != v1::RESOLUTION_VARIANT_UNSPECIFIED) {
    const std::optional<ResolutionVariant> variant = FromProto(request.variant());
    if (!variant) throw InvalidArgument("variant: unknown ResolutionVariant value");
    params.variant = *variant;
  }
  job.params = WrenchParamsAtPose(params, job.X_BinTcp);
  job.params.Validate();
  return RunAnalyzeWrench(job);
}

}  // namespace tubepick::cell
