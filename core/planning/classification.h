#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/common/types.h"

namespace tubepick {

/// Tube classification (thesis §5.2.2, Table 5.3).
struct ClassificationParams {
  /// Subtracted from the expected tube length (TubeConfig::length) to get the minimum length of
  /// a complete virtual tube, metres (Table 5.3, set A: 50 cm tubes, 35 cm minimum).
  double length_tolerance = 0.15;
  /// A link between a junction node and a branch of a branched tube is an occluded joint when
  /// it is longer than the branch's radius plus this, metres: at a junction seen whole, the
  /// branch's first cylinder starts about one radius from the node (on the other branch's axis).
  double junction_gap = 0.02;
  /// Beyond the thesis: when every modeled tube is shorter than the minimum, plan them anyway, as
  /// plans that need luck (simulated where an evaluator is given, else unsure). The thesis plans
  /// nothing then, and a bin whose last tube is partly hidden (a tree propped against a wall, an end
  /// under its own branch) is never emptied.
  bool short_tubes_last_resort = true;
};

/// Cylinder indices [begin, end) of a tube: a section, or the cylinders a grasp may use.
struct CylinderRange {
  std::uint32_t begin = 0;
  std::uint32_t end = 0;

  bool contains(std::uint32_t i) const { return i >= begin && i < end; }
  std::uint32_t size() const { return end > begin ? end - begin : 0; }
  bool operator==(const CylinderRange&) const = default;
};

/// What classification found for one tube.
struct TubeClass {
  Occlusion occlusion = Occlusion::kUnspecified;
  /// Occluded joints (Def. 5.2.1), ascending indices into TubeJoints(tube); on a linear tube
  /// joint i links cylinders[i].end to cylinders[i+1].start.
  std::vector<std::uint32_t> occluded_joints;
  /// Shorter than the minimum length: an incomplete model, never a pick candidate (it still
  /// takes part in simulations as an obstacle).
  bool too_short = false;
  /// Non-occluded tubes only, filled by PlanPick: the tubes (indices into the tube list) that lie
  /// on this one (TubesLyingOn). Its plans are then not sure (PlanCertainty::kUnsure).
  std::vector<std::uint32_t> lying_on;
};

/// Occluded joints of `tube` (Def. 5.2.1): joints whose two cylinders come from different
/// segments, and links to a junction node longer than the branch's radius plus
/// params.junction_gap. Ascending indices into TubeJoints(tube).
std::vector<std::uint32_t> OccludedJoints(const Tube& tube, const ClassificationParams& params = {});

/// "none", "weak", "strong", "unspecified".
std::string ToString(Occlusion occlusion);

/// NONE for 0 occluded joints (Def. 5.2.2), WEAK for 1 (Def. 5.2.3), STRONG for 2+ (Def. 5.2.4).
Occlusion OcclusionOf(std::size_t occluded_joint_count);

/// The two sections of a tube split by `joint` (Def. 5.2.3): cylinders [0, joint + 1) and
/// [joint + 1, n). @pre joint + 1 < tube.cylinders.size()
std::pair<CylinderRange, CylinderRange> SplitAtJoint(const Tube& tube, std::uint32_t joint);

/// Minimum accepted tube length: expected_length − length_tolerance, or 0 (no filter) when the
/// expected length is 0 (unknown) or the tolerance is at least the expected length.
double MinimumTubeLength(double expected_length, const ClassificationParams& params);

struct ClassificationResult {
  /// The input tubes, same order, with Tube::occlusion and Tube::occluded_joint_count filled.
  std::vector<Tube> tubes;
  /// Parallel to `tubes`.
  std::vector<TubeClass> classes;
};

/// Classifies every tube (§5.2.2): the minimum-length filter, then occlusion counting.
/// @throws InvalidArgument naming "tubes[i]" for a tube without cylinders or with non-finite
///         endpoints, or naming "planning.classification.length_tolerance" / "tube.length" for a
///         negative or non-finite value.
ClassificationResult ClassifyTubes(const std::vector<Tube>& tubes, double expected_length,
                                   const ClassificationParams& params);

}  // namespace tubepick
