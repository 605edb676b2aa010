#include "core/wrench/held_count.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "core/common/errors.h"
#include "core/common/require.h"

namespace tubepick {

std::string ToString(HeldOutcome outcome) {
  switch (outcome) {
    case HeldOutcome::kNone:
      return "none";
    case HeldOutcome::kSingle:
      return "single";
    case HeldOutcome::kMultiple:
      return "multiple";
  }
  return "unknown";
}

HeldCount CountHeldTubes(double fz_ref, double fz, double tube_mass, const WrenchParams& params) {
  params.Validate();
  RequireFinite(fz_ref, "fz_ref");
  RequireFinite(fz, "fz");
  RequirePositive(tube_mass, "tube.mass");

  HeldCount result;
  // Algorithm 3, lines 1-2.
  result.tube_weight = tube_mass * params.gravity;
  result.expected_force = fz_ref - result.tube_weight;
  result.force_tolerance = EffectiveForceTolerance(params, result.tube_weight);
  if (!(params.force_tolerance < result.tube_weight)) {
    std::ostringstream s;
    s << "wrench.force_tolerance: " << params.force_tolerance
      << " N is not below the weight of one tube (tube.mass " << tube_mass << " kg x wrench.gravity "
      << params.gravity << " m/s^2 = " << result.tube_weight
      << " N); an empty gripper would read as holding one tube";
    throw InvalidArgument(s.str());
  }
  // Lines 3-8: strict comparisons, the band edges are kSingle.
  if (fz < result.expected_force - result.force_tolerance) {
    result.outcome = HeldOutcome::kMultiple;
  } else if (fz > result.expected_force + result.force_tolerance) {
    result.outcome = HeldOutcome::kNone;
  } else {
    result.outcome = HeldOutcome::kSingle;
  }

  result.held_weight = fz_ref - fz;
  result.tube_ratio = result.held_weight / result.tube_weight;
  const double rounded = std::max(0.0, std::round(result.tube_ratio));
  switch (result.outcome) {
    case HeldOutcome::kNone:
      result.estimated_count = 0;
      break;
    case HeldOutcome::kSingle:
      result.estimated_count = 1;
      break;
    case HeldOutcome::kMultiple:
      // Bounded so a wild reading cannot overflow the integer.
      result.estimated_count = static_cast<std::uint32_t>(std::clamp(rounded, 2.0, 1e6));
      break;
  }
  return result;
}

HeldCount CountHeldTubes(const Wrench& reference, const Wrench& current, double tube_mass,
                         const WrenchParams& params) {
  params.Validate();
  RequireFiniteVector(reference.force, "reference.force");
  RequireFiniteVector(current.force, "current.force");
  const Eigen::Vector3d up = params.up_Tcp.normalized();
  return CountHeldTubes(reference.force.dot(up), current.force.dot(up), tube_mass, params);
}

}  // namespace tubepick
