#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/common/types.h"

namespace tubepick {

/// Where the tube frame's origin is.
enum class TubeFrameOrigin {
  /// The centroid of the points (or of the model's axis): the tube's centre lands on X_BinPlace.
  kCentroid,
  /// The grasp point (the TCP position at grasp): the grasp lands on X_BinPlace.
  kGraspPoint,
};

/// How the sign of the principal axis (two-fold ambiguous in PCA) is chosen.
enum class AxisSign {
  /// x has a positive bin-x component; when that is ~0, a positive bin-y component, then bin-z.
  kAlongBinX,
  /// x points from the grasp point towards the tube's farther end (the longer arm).
  kAwayFromGrasp,
};

/// Parameters of the tube placement frame (thesis §5.2.7).
struct PlacementParams {
  /// true: x is the principal direction projected on the bin's xOy plane and z = bin +z, so the
  /// alignment is a pure yaw (the thesis's safe option); false: x is the full 3-D principal
  /// direction and z the bin's +z made perpendicular to it.
  bool yaw_only = true;
  /// Origin of the tube frame.
  TubeFrameOrigin origin = TubeFrameOrigin::kCentroid;
  /// Sign rule of the principal axis.
  AxisSign sign = AxisSign::kAlongBinX;
  /// Smallest horizontal part |(d_x, d_y)| of the unit principal direction d, in (0, 1); below
  /// it the tube is nearly vertical, has no defined yaw and no frame is returned (0.05 ≈ 87°).
  double min_horizontal = 0.05;
  /// PlanPlacement: tubes are symmetric end to end, so the tube frame may be turned 180° about
  /// its z when that makes the TCP's rotation from grasp to place smaller (joint-friendly);
  /// false places exactly as the sign rule says.
  bool allow_flip = false;

  /// @throws InvalidArgument naming the first bad field ("placement.min_horizontal: ...").
  void Validate() const;
};

/// The tube's orientation frame (Fig. 5.7), in the bin frame.
struct TubeFrame {
  /// x along the tube, z up (yaw_only) or as close to up as x allows, y = z × x.
  Eigen::Isometry3d X_BinTube = Eigen::Isometry3d::Identity();
  /// The unit principal direction (largest eigenvalue), full 3-D, sign per params.sign.
  Eigen::Vector3d principal_direction_Bin = Eigen::Vector3d::UnitX();
  /// Eigenvalues of the normalised covariance, largest first, m².
  Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();
  /// Centroid of the points (or of the axis), bin frame.
  Eigen::Vector3d p_Bin_centroid = Eigen::Vector3d::Zero();
};

/// PCA of the grasped tube's points (§5.2.7): eigen decomposition of the normalised covariance
/// (1/N)·Σ(p − c)(p − c)ᵀ; the eigenvector of the largest eigenvalue is the tube's direction.
/// @param points_Bin the tube's points, bin frame.
/// @param p_Bin_grasp the grasp point; required by TubeFrameOrigin::kGraspPoint and
///   AxisSign::kAwayFromGrasp, ignored otherwise.
/// @return std::nullopt when the principal direction is nearly vertical (horizontal part below
///   params.min_horizontal): the yaw is undefined.
/// @throws InvalidArgument for fewer than 2 points, a non-finite point, points that all coincide
///   (spread below 1 µm), a missing or non-finite grasp point, or invalid params.
std::optional<TubeFrame> EstimateTubeFrame(const Points& points_Bin, const PlacementParams& params,
                                           const std::optional<Eigen::Vector3d>& p_Bin_grasp = std::nullopt);

/// The same for a tube model: its axis polyline (cylinder axes and the joints between them) is
/// treated as uniformly dense, and the covariance integrated exactly (the limit of sampling the
/// axes finely). The cylinders' radii do not change the principal direction.
/// @throws InvalidArgument for a tube without cylinders, a non-finite endpoint, a zero-length
///   axis, or as above.
std::optional<TubeFrame> EstimateTubeFrame(const Tube& tube_Bin, const PlacementParams& params,
                                           const std::optional<Eigen::Vector3d>& p_Bin_grasp = std::nullopt);

/// X_BinTcpPlace = X_BinPlace · X_TubeTcp with X_TubeTcp = X_BinTube⁻¹ · X_BinTcp: the TCP pose
/// that carries the tube frame (rigidly held since the grasp) onto X_BinPlace.
/// @throws InvalidArgument naming the pose that is not a finite rigid transform.
Eigen::Isometry3d PlacementTcpPose(const Eigen::Isometry3d& X_BinTcp, const Eigen::Isometry3d& X_BinTube,
                                   const Eigen::Isometry3d& X_BinPlace);

/// The placement for one grasp.
struct Placement {
  /// TCP pose at the destination, bin frame.
  Eigen::Isometry3d X_BinTcpPlace = Eigen::Isometry3d::Identity();
  /// The grasp relative to the tube frame actually used (after a flip, if any).
  Eigen::Isometry3d X_TubeTcp = Eigen::Isometry3d::Identity();
  /// The tube frame was turned 180° about its z (params.allow_flip).
  bool flipped = false;
  /// Angle of the TCP's rotation from grasp to place, radians, in [0, π].
  double tcp_rotation_angle = 0.0;
};

/// PlacementTcpPose, plus the optional 180° flip of the tube frame (params.allow_flip) when it
/// gives a smaller TCP rotation angle (ties keep the unflipped frame).
/// @throws InvalidArgument as PlacementTcpPose, or for invalid params.
Placement PlanPlacement(const Eigen::Isometry3d& X_BinTcp, const TubeFrame& tube,
                        const Eigen::Isometry3d& X_BinPlace, const PlacementParams& params);

/// "centroid", "grasp_point".
std::string ToString(TubeFrameOrigin origin);
/// @throws InvalidArgument naming `field` for an unknown name.
TubeFrameOrigin ParseTubeFrameOrigin(const std::string& text, const std::string& field);
/// "along_bin_x", "away_from_grasp".
std::string ToString(AxisSign sign);
/// @throws InvalidArgument naming `field` for an unknown name.
AxisSign ParseAxisSign(const std::string& text, const std::string& field);

}  // namespace tubepick
