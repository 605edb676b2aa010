#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/stop_token.h"
#include "core/common/types.h"

namespace tubepick {

/// How a post-grasp trajectory moves the tube (thesis §5.2.3.1).
enum class TrajectoryKind {
  /// Straight up.
  kUpward,
  /// Small lift, lateral move along the escape line of the single occluded joint, then lift.
  kEscape,
  /// Beyond the thesis: for strongly occluded tubes, an escape derived from one occlusion.
  kOcclusionEscape,
};

std::string ToString(TrajectoryKind kind);

/// A candidate post-grasp trajectory of one tube (thesis Def. 5.2.5): translations of the tube
/// relative to its pose at grasp time, bin frame axes; waypoints.front() is (0, 0, 0).
struct Trajectory {
  /// Index of the moved tube in the tube list given to the evaluator (== Tube::id in plans).
  std::uint32_t tube_index = 0;
  TrajectoryKind kind = TrajectoryKind::kUpward;
  std::vector<Eigen::Vector3d> waypoints;
  /// For escape kinds: unit xy direction of the lateral move, and which section of the tube
  /// (cylinder indices [section_begin, section_end)) must hold the grasp (§5.2.4.1).
  Eigen::Vector3d escape_direction = Eigen::Vector3d::Zero();
  std::uint32_t section_begin = 0;
  std::uint32_t section_end = 0;
  /// Escapes of a branched tube, whose sections are subtrees rather than index ranges: when not
  /// empty, cylinder i may hold the grasp iff section_mask[i] (instead of the range above).
  std::vector<std::uint8_t> section_mask;
};

/// What simulating one trajectory measured (thesis §5.2.3.2).
struct TrajectoryOutcome {
  /// Sum over the other tubes of their centre-of-mass displacement, metres (the cost `disp`).
  double displacement = 0.0;
  /// Simulation stopped once the displacement exceeded disp_max.
  bool stopped_early = false;
  /// Largest distance between the grasped tube and its commanded pose during the motion, metres.
  double max_tracking_error = 0.0;
  /// Simulated seconds.
  double simulated_time = 0.0;
};

/// Evaluates candidate trajectories of a set of modeled tubes (a physics backend; core/planning
/// only sees this interface). Implementations must be deterministic: the same tubes, trajectories
/// and seed give the same outcomes whatever their thread count.
class TrajectoryEvaluator {
 public:
  virtual ~TrajectoryEvaluator() = default;

  /// One outcome per trajectory, in order. `tubes` are the modeled tubes, bin frame.
  /// @throws Cancelled when `stop` fires.
  virtual std::vector<TrajectoryOutcome> Evaluate(const std::vector<Tube>& tubes,
                                                  const std::vector<Trajectory>& trajectories,
                                                  std::uint64_t seed, const StopToken* stop) = 0;
};

}  // namespace tubepick
