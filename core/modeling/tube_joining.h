#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "core/common/stop_token.h"
#include "core/common/types.h"
#include "core/modeling/range_image.h"

namespace tubepick {

enum class JoiningStrategy {
  /// Thesis Algorithm 1 lines 9–17: pairs in ascending combined distance, greedily.
  kGreedy,
  /// Global assignment: endpoint pairs chosen to minimise the summed distance over all joins
  /// (subject to the same constraints), avoiding the greedy order's mis-joins. Exactly: the join
  /// set maximising Σ (max_distance + angular_weight·max_angle − combined), so more useful joins
  /// win first, then a smaller total distance (branch and bound, see tube_joining.cc).
  kGlobal,
};

/// Tube joining (thesis §4.3.4, Table 4.3).
struct JoiningParams {
  /// Maximum euclidean distance between joined endpoints, metres.
  double max_distance = 0.10;
  /// Maximum angular distance α+β, radians (Table 4.3: 90°).
  double max_angle = 3.14159265358979323846 / 2.0;
  /// c_Δθ in metres per radian (Table 4.3: 0.001 m per degree = 0.0573 m/rad).
  double angular_weight = 0.001 * 180.0 / 3.14159265358979323846;
  /// Length constraint: joined tubes may not exceed this, metres; 0 disables it.
  double max_tube_length = 0.60;
  /// With the cell's tube length known, joined tubes may not exceed this share of it either
  /// (MaxJoinedLength); 0 = only max_tube_length (the thesis).
  double max_length_share = 0.0;
  /// Euclidean distance below which the angular distance counts as 0 (the radius shortcut);
  /// 0 = use the mean radius of the two cylinders, as the thesis.
  double radius_shortcut = 0.0;
  /// Visibility constraint: a gap is joined only if something in the range image lies between
  /// it and the sensor (or the gap is shorter than visibility_min_gap).
  bool visibility_check = true;
  /// Angular pixel size of the range image, radians.
  double visibility_pixel_angle = 0.002;
  /// Half-size of the pixel window searched around the gap's midpoint.
  std::uint32_t visibility_window = 2;
  /// Gaps shorter than this are joined without the visibility test, metres (touching ends).
  double visibility_min_gap = 0.0;
  JoiningStrategy strategy = JoiningStrategy::kGreedy;
};

/// The longest tube joining may build, metres (0 = no limit): max_tube_length, and with
/// `tube_length` > 0 and max_length_share > 0, at most max_length_share · tube_length.
double MaxJoinedLength(const JoiningParams& params, double tube_length);

/// The length of a scene's whole tubes: the median length of the `unbounded` tubes (joined
/// without the share bound) at least 0.8 · tube_length long, the tubes seen about whole; 0 when
/// there is none. With the cell's tube.length right it is about that length (a merge is rarely
/// the median); a cell that states its tubes shorter than they are shows it here. 0 also when
/// fewer than `min_whole` tubes are that long.
double WholeTubeLength(const std::vector<Tube>& unbounded, double tube_length, std::size_t min_whole = 1);

/// Endpoint-pair distance terms, exposed for tests.
struct JoinDistance {
  double euclidean = 0.0;
  /// α + β, radians; 0 when the radius shortcut applies.
  double angular = 0.0;
  /// euclidean + angular_weight · angular (Equation 4.2).
  double combined = 0.0;
};

/// Distance between endpoint `a` of a cylinder with outward axis `a_out` (pointing away from the
/// cylinder at that end) and endpoint `b` with outward axis `b_out` (need not be unit). α is the
/// angle between `a_out` and b − a, β between `b_out` and a − b; the angular term is 0 when the
/// euclidean distance is below `shortcut_radius` (or 0).
JoinDistance EndpointDistance(const Eigen::Vector3d& a, const Eigen::Vector3d& a_out,
                              const Eigen::Vector3d& b, const Eigen::Vector3d& b_out, double shortcut_radius,
                              const JoiningParams& params);

/// Joins cylinders into tubes. Every cylinder starts as its own tube; compatible endpoint pairs
/// of different tubes are united (different tubes, distance and angle limits, length constraint,
/// visibility constraint when `visibility` is non-null and enabled). In each output tube the
/// cylinders are ordered and oriented along the tube. Tube ids are 0..n−1, longest tube first.
/// Deterministic: the same input gives the same output.
/// @throws InvalidArgument for an invalid parameter (naming "joining.<key>" and the value) or a
///         non-finite cylinder (naming "cylinders[i]").
/// @throws Cancelled when `stop` fires.
std::vector<Tube> JoinTubes(const std::vector<Cylinder>& cylinders, const JoiningParams& params,
                            const RangeImage* visibility, const StopToken* stop = nullptr);

/// JoinTubes for a cell whose tubes are `tube_length` long (0 = unknown): no tube longer than
/// MaxJoinedLength of the longer of tube_length and the scene's WholeTubeLength. When the scene's
/// whole tubes are longer than that bound of tube_length alone, `scan_length` (optional) receives
/// their length (else nullopt): the cell's tube.length is probably shorter than its parts, and the
/// caller says so (ModelingResult::warnings).
std::vector<Tube> JoinTubesOfLength(const std::vector<Cylinder>& cylinders, const JoiningParams& params,
                                    double tube_length, const RangeImage* visibility, const StopToken* stop,
                                    std::optional<double>* scan_length = nullptr);

}  // namespace tubepick
