#include "core/planning/classification.h"

#include <cassert>
#include <cmath>
#include <string>

#include "core/common/errors.h"
#include "core/common/require.h"
#include "core/common/tube_graph.h"

namespace tubepick {

std::vector<std::uint32_t> OccludedJoints(const Tube& tube, const ClassificationParams& params) {
  std::vector<std::uint32_t> occluded;
  const std::vector<TubeJoint> joints = TubeJoints(tube);
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const TubeJoint& j = joints[i];
    const bool hidden = j.junction_link()
                            ? j.length() > j.radius + params.junction_gap
                            : tube.cylinders[static_cast<std::size_t>(j.cylinder_a)].segment_id !=
                                  tube.cylinders[static_cast<std::size_t>(j.cylinder_b)].segment_id;
    if (hidden) occluded.push_back(static_cast<std::uint32_t>(i));
  }
  return occluded;
}

std::string ToString(Occlusion occlusion) {
  switch (occlusion) {
    case Occlusion::kNone:
      return "none";
    case Occlusion::kWeak:
      return "weak";
    case Occlusion::kStrong:
      return "strong";
    case Occlusion::kUnspecified:
      break;
  }
  return "unspecified";
}

Occlusion OcclusionOf(std::size_t occluded_joint_count) {
  if (occluded_joint_count == 0) return Occlusion::kNone;
  if (occluded_joint_count == 1) return Occlusion::kWeak;
  return Occlusion::kStrong;
}

std::pair<CylinderRange, CylinderRange> SplitAtJoint(const Tube& tube, std::uint32_t joint) {
  const auto n = static_cast<std::uint32_t>(tube.cylinders.size());
  assert(joint + 1 < n);
  return {CylinderRange{0, joint + 1}, CylinderRange{joint + 1, n}};
}

double MinimumTubeLength(double expected_length, const ClassificationParams& params) {
  if (expected_length <= 0.0) return 0.0;
  const double minimum = expected_length - params.length_tolerance;
  return minimum > 0.0 ? minimum : 0.0;
}

ClassificationResult ClassifyTubes(const std::vector<Tube>& tubes, double expected_length,
                                   const ClassificationParams& params) {
  RequireNonNegative(params.length_tolerance, "planning.classification.length_tolerance");
  RequireNonNegative(params.junction_gap, "planning.classification.junction_gap");
  RequireNonNegative(expected_length, "tube.length");
  const double minimum = MinimumTubeLength(expected_length, params);

  ClassificationResult result;
  result.tubes = tubes;
  result.classes.resize(tubes.size());
  for (std::size_t t = 0; t < tubes.size(); ++t) {
    const Tube& tube = tubes[t];
    const std::string name = "tubes[" + std::to_string(t) + "]";
    if (tube.cylinders.empty()) throw InvalidArgument(name + ": has no cylinders");
    ValidateTubeGraph(tube, name);
    TubeClass& cls = result.classes[t];
    cls.occluded_joints = OccludedJoints(tube, params);
    cls.occlusion = OcclusionOf(cls.occluded_joints.size());
    cls.too_short = minimum > 0.0 && tube.length() < minimum;
    result.tubes[t].occlusion = cls.occlusion;
    result.tubes[t].occluded_joint_count = static_cast<std::uint32_t>(cls.occluded_joints.size());
  }
  return result;
}

}  // namespace tubepick
