// libFuzzer target: validation of the unary requests, as the service runs it on a received message.
//
// Input: one selector byte (0 PlanPickRequest, 1 ModelTubesRequest, 2 AnalyzeWrenchRequest; taken
// modulo 3), then the message's protobuf bytes. Accepted: a job, or the documented InvalidArgument /
// FailedPrecondition. Anything else (another exception, a sanitizer report, a job that breaks what
// validation promises) is a crash.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include <google/protobuf/stubs/common.h>

#include "core/common/errors.h"
#include "server/request_validation.h"
#include "server/server_config.h"

namespace {

using namespace tubepick;  // NOLINT(build/namespaces): a fuzz target's few names

const server::PlanningDefaults& Defaults() {
  static const server::PlanningDefaults defaults = [] {
    server::PlanningDefaults d;
    d.max_cloud_points = 1 << 16;  // small, so no input can ask for much memory
    return d;
  }();
  return defaults;
}

void Check(bool condition) {
  if (!condition) std::abort();
}

void CheckJob(const server::PlanningJob& job, std::size_t xyz_bytes) {
  Check(job.xyz_Sensor.size() == xyz_bytes && xyz_bytes % 12 == 0);
  Check(Defaults().profiles.count(job.profile) == 1);
  job.cell.Validate();  // validation promises a cell planning accepts: throwing here aborts below
}

template <typename Request>
bool Parse(const std::uint8_t* data, std::size_t size, Request* request) {
  return request->ParseFromArray(data, static_cast<int>(size));
}

}  // namespace

// protobuf logs every string field with invalid UTF-8 it parses; the parse result is what counts.
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  google::protobuf::SetLogHandler(nullptr);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const int selector = data[0] % 3;
  ++data;
  --size;
  try {
    if (selector == 0) {
      v1::PlanPickRequest request;
      if (!Parse(data, size, &request)) return 0;
      const server::PlanningJob job = server::ValidatePlanPick(request, Defaults());
      try {
        CheckJob(job, request.cloud().xyz().size());
      } catch (...) {
        std::abort();
      }
    } else if (selector == 1) {
      v1::ModelTubesRequest request;
      if (!Parse(data, size, &request)) return 0;
      const server::PlanningJob job = server::ValidateModelTubes(request, Defaults());
      try {
        CheckJob(job, request.cloud().xyz().size());
      } catch (...) {
        std::abort();
      }
    } else {
      v1::AnalyzeWrenchRequest request;
      if (!Parse(data, size, &request)) return 0;
      const WrenchJob job = server::ValidateAnalyzeWrench(request, Defaults());
      Check(std::isfinite(job.tube_mass) && job.tube_mass > 0.0);
      Check(job.reference.force.allFinite() && job.current.torque.allFinite());
      Check(job.X_BinTcp.matrix().allFinite());
    }
  } catch (const InvalidArgument&) {
  } catch (const FailedPrecondition&) {
  }
  return 0;
}
