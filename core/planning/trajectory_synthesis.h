#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/common/cell_config.h"
#include "core/common/types.h"
#include "core/planning/classification.h"
#include "core/planning/trajectory.h"

namespace tubepick {

/// Trajectory synthesis (thesis §5.2.3.1, Table 5.3).
struct TrajectoryParams {
  /// Lift of the upward trajectory, metres (Table 5.3: 40 cm).
  double upward_distance = 0.40;
  /// First, small lift of an escape trajectory, metres (Table 5.3: 2 cm).
  double escape_first_lift = 0.02;
  /// Final lift of an escape trajectory, after the lateral move, metres (Table 5.3: 40 cm).
  double escape_second_lift = 0.40;
  /// d_const of Equation 5.1, metres; 0 = three times the tube radius (the thesis' lower bound;
  /// Table 5.3's value is not legible in the seed).
  double escape_constant = 0.0;
  /// The safety zone is the bin's inner xy rectangle shrunk by this margin on every side, metres.
  double safety_margin = 0.05;
  /// An escape shortened (by the safety zone) below this lateral distance is dropped: it would
  /// be an upward trajectory in disguise, metres.
  double min_escape_distance = 0.01;
  /// Beyond the thesis: strongly occluded tubes also get one escape per occluded joint.
  bool occlusion_escapes = true;
};

/// Axis-aligned rectangle in the bin's xy plane the tube's xy bounding box must stay in.
struct SafetyZone {
  Eigen::Vector2d min = Eigen::Vector2d::Zero();
  Eigen::Vector2d max = Eigen::Vector2d::Zero();
};

/// The bin's inner rectangle (centred on the bin origin) shrunk by `margin` on every side;
/// clamped to a degenerate rectangle at the centre when the margin exceeds the half size.
SafetyZone MakeSafetyZone(const BinConfig& bin, double margin);

/// xy bounding box of a tube: its cylinder endpoints grown by each cylinder's radius.
SafetyZone TubeBoundingBoxXy(const Tube& tube);

/// Largest distance the tube can translate along the unit xy `direction` while its xy bounding
/// box does not extend further past the safety zone on any side it moves towards: for every
/// axis k with direction_k > 0, box.max_k + d·direction_k ≤ zone.max_k (and symmetrically for
/// direction_k < 0). The trailing sides move away from their walls and never constrain.
/// Negative when the box already exceeds the zone on a side it moves towards; +∞ when the
/// direction has no xy component.
double SafetyZoneLimit(const Tube& tube, const Eigen::Vector3d& direction, const SafetyZone& zone);

/// Unit direction of the escape line of `joint` (Def. 5.2.6): the xy projection of the line from
/// cylinders[joint].end to cylinders[joint + 1].start, pointing from the first section towards
/// the second. When that projection is shorter than 1e-6 m, the xy projection of the sum of the
/// two cylinders' axes (the tube's direction at the joint) is used instead; nullopt when that is
/// degenerate too. @pre joint + 1 < tube.cylinders.size()
std::optional<Eigen::Vector3d> EscapeLineDirection(const Tube& tube, std::uint32_t joint);

/// One direction along the escape line of one occluded joint (Equations 5.1 and 5.2).
///
/// Moving the tube along +d drags the section *behind* the joint (the trailing section) under
/// the occluding tube, which sits over the joint; the tube is freed once the whole trailing
/// section has passed under it. Hence occl is the joint endpoint on the trailing section,
/// EP(occl) the endpoints of the trailing section's cylinders, d_var their farthest projection
/// from proj(occl), and the gripper must hold the leading section (§5.2.4.1; Fig. 5.3: moving
/// towards the upper left, grasps on the left section).
struct EscapeCandidate {
  std::uint32_t joint = 0;
  /// Unit xy direction of the lateral move.
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  /// True when moving towards the higher cylinder indices (the trailing section is [0, joint+1)).
  bool towards_end = true;
  /// Section that passes under the occluding tube.
  CylinderRange trailing;
  /// Section on the other side of the joint.
  CylinderRange leading;
  /// d_var (Eq. 5.2), d_const, and their sum d_escape (Eq. 5.1), metres.
  double variable_distance = 0.0;
  double constant_distance = 0.0;
  double escape_distance = 0.0;
  /// SafetyZoneLimit along `direction`.
  double zone_limit = 0.0;
  /// The lateral distance used: min(escape_distance, zone_limit), at least 0.
  double distance = 0.0;
};

/// Both directions of the escape line of `joint`: [0] towards the tube's end (higher cylinder
/// indices), [1] towards its start. nullopt when the escape line is degenerate.
/// @pre joint + 1 < tube.cylinders.size(), constant_distance ≥ 0
std::optional<std::array<EscapeCandidate, 2>> EscapeCandidates(const Tube& tube, std::uint32_t joint,
                                                               double constant_distance,
                                                               const SafetyZone& zone);

/// The two sides of joint `joint` (an index into TubeJoints(tube)) of a branched tube: per
/// cylinder, 1 when it is on the joint's `a` side (the tree without that joint falls in two).
/// @pre joint < TubeJoints(tube).size(); the tube is a tree (ValidateTubeGraph)
std::vector<std::uint8_t> SideOfJointA(const Tube& tube, std::uint32_t joint);

/// A branched tube's escape over joint `joint` (Def. 5.2.6 on a tree): the escape line is the xy
/// projection of the joint (from its `a` end to its `b` end); moving along +line drags the `a`
/// side under the occluder (it trails) and the gripper holds the `b` side (it leads), and the other
/// way round. d_var is the farthest projection of the trailing side's cylinder endpoints from the
/// joint end on that side, as on a linear tube. nullopt when the joint's xy projection is shorter
/// than 1 µm. [0] moves towards `b`, [1] towards `a`; `trailing`/`leading` are left empty (the
/// sides are the masks in `leading_mask`).
struct TreeEscapeCandidate {
  EscapeCandidate escape;
  std::vector<std::uint8_t> leading_mask;
};
std::optional<std::array<TreeEscapeCandidate, 2>> TreeEscapeCandidates(const Tube& tube, std::uint32_t joint,
                                                                       double constant_distance,
                                                                       const SafetyZone& zone);

/// Waypoints (0,0,0) → (0,0,h).
Trajectory UpwardTrajectory(std::uint32_t tube_index, const Tube& tube, const TrajectoryParams& params);

/// Waypoints (0,0,0) → (0,0,h₁) → (d·u, h₁) → (d·u, h₁ + h₂) with u = candidate.direction,
/// d = candidate.distance, h₁ = escape_first_lift, h₂ = escape_second_lift; section =
/// `grasp_section`.
Trajectory EscapeTrajectory(std::uint32_t tube_index, const EscapeCandidate& candidate, TrajectoryKind kind,
                            const CylinderRange& grasp_section, const TrajectoryParams& params);

/// Every trajectory of one tube, upward first:
/// - NONE: upward.
/// - WEAK: upward, then the escapes towards the end and towards the start of the single
///   occluded joint (§5.2.3.1), each with grasps allowed on its leading section.
/// - STRONG (when occlusion_escapes): upward, then per occluded joint (ascending) one
///   kOcclusionEscape. Beyond the thesis; rule: of the joint's two directions, the one with the
///   smaller d_var (the shorter trailing part to pull out from under that occluder; ties go
///   towards the end). Grasps are allowed only beyond the last occluded joint in the direction
///   of motion (cylinders [last joint + 1, n) when moving towards the end, [0, first joint + 1)
///   towards the start): while the tube slides, every occluder moves backwards relative to the
///   tube, so a gripper held anywhere behind an occluder would run into it.
/// A branched tube (several branches): upward; when WEAK also the two TreeEscapeCandidates of its
/// occluded joint, grasps allowed on the leading subtree (Trajectory::section_mask); a STRONG
/// tree is lifted straight up only.
/// Escapes whose distance is below min_escape_distance, or whose escape line is degenerate,
/// are dropped. `tube_radius` gives the default d_const (3·radius).
/// @pre tube classified as `cls`; params validated.
std::vector<Trajectory> SynthesizeTrajectories(std::uint32_t tube_index, const Tube& tube,
                                               const TubeClass& cls, double tube_radius,
                                               const SafetyZone& zone, const TrajectoryParams& params);

}  // namespace tubepick
