#include "core/placement/placement.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

#include "core/common/errors.h"
#include "core/common/require.h"
#include "core/common/tube_graph.h"

namespace tubepick {
namespace {

// Points spreading less than this (standard deviation along the principal axis) coincide, metres.
constexpr double kMinSpread = 1e-6;
// Below this |component| the next bin axis decides the sign (kAlongBinX).
constexpr double kSignTol = 1e-6;
// Rotation angles closer than this count as equal (PlanPlacement keeps the unflipped frame).
constexpr double kAngleTieTol = 1e-9;

std::string FormatVector(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return s.str();
}

// First and second moments of what is being analysed, plus the points bounding its extent
// along any direction (for the sign rule).
struct Distribution {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  std::vector<Eigen::Vector3d> extremes;
};

Distribution FromPoints(const Points& points_Bin) {
  if (points_Bin.size() < 2) {
    throw InvalidArgument("points_Bin: the tube frame needs at least 2 points, got " +
                          std::to_string(points_Bin.size()));
  }
  Distribution d;
  d.extremes.reserve(points_Bin.size());
  for (std::size_t i = 0; i < points_Bin.size(); ++i) {
    const Eigen::Vector3d p = points_Bin[i].cast<double>();
    if (!p.allFinite()) {
      throw InvalidArgument("points_Bin[" + std::to_string(i) + "]: must be finite, got " + FormatVector(p));
    }
    d.extremes.push_back(p);
    d.centroid += p;
  }
  const double n = static_cast<double>(points_Bin.size());
  d.centroid /= n;
  for (const Eigen::Vector3d& p : d.extremes) {
    const Eigen::Vector3d q = p - d.centroid;
    d.covariance += q * q.transpose();
  }
  d.covariance /= n;
  return d;
}

// The axis polyline (TubeAxisPieces: cylinders, joints, junction links), uniformly dense.
Distribution FromTube(const Tube& tube_Bin) {
  if (tube_Bin.cylinders.empty()) {
    throw InvalidArgument("tube " + std::to_string(tube_Bin.id) +
                          ": the tube frame needs at least one cylinder");
  }
  for (std::size_t i = 0; i < tube_Bin.cylinders.size(); ++i) {
    const Cylinder& c = tube_Bin.cylinders[i];
    if (!c.start.allFinite() || !c.end.allFinite()) {
      throw InvalidArgument("tube " + std::to_string(tube_Bin.id) + ": cylinders[" + std::to_string(i) +
                            "] has a non-finite endpoint");
    }
  }
  ValidateTubeGraph(tube_Bin, "tube " + std::to_string(tube_Bin.id));
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> segments;
  for (const AxisPiece& piece : TubeAxisPieces(tube_Bin)) segments.emplace_back(piece.a, piece.b);
  Distribution d;
  double total = 0.0;
  for (const auto& [a, b] : segments) {
    const double length = (b - a).norm();
    total += length;
    d.centroid += length * 0.5 * (a + b);
    d.extremes.push_back(a);
    d.extremes.push_back(b);
  }
  if (!(total > 0.0)) {
    throw InvalidArgument("tube " + std::to_string(tube_Bin.id) + ": the axis has zero length");
  }
  d.centroid /= total;
  // ∫₀¹ (a' + t(b' − a'))(…)ᵀ dt = (a'a'ᵀ + b'b'ᵀ)/3 + (a'b'ᵀ + b'a'ᵀ)/6, weighted by length.
  for (const auto& [a, b] : segments) {
    const double length = (b - a).norm();
    const Eigen::Vector3d p = a - d.centroid;
    const Eigen::Vector3d q = b - d.centroid;
    d.covariance += length * ((p * p.transpose() + q * q.transpose()) / 3.0 +
                              (p * q.transpose() + q * p.transpose()) / 6.0);
  }
  d.covariance /= total;
  return d;
}

// Sign rule kAlongBinX: the first bin axis (x, y, z) with a clear component decides.
Eigen::Vector3d AlongBinX(const Eigen::Vector3d& direction) {
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(direction[axis]) > kSignTol) return direction[axis] > 0.0 ? direction : -direction;
  }
  return direction;  // unreachable for a unit vector
}

// `what` names the input in error messages.
std::optional<TubeFrame> FrameOf(const Distribution& d, const std::string& what,
                                 const PlacementParams& params,
                                 const std::optional<Eigen::Vector3d>& p_Bin_grasp) {
  const bool needs_grasp =
      params.origin == TubeFrameOrigin::kGraspPoint || params.sign == AxisSign::kAwayFromGrasp;
  if (needs_grasp && !p_Bin_grasp.has_value()) {
    throw InvalidArgument("p_Bin_grasp: required by placement.origin = " + ToString(params.origin) +
                          " / placement.sign = " + ToString(params.sign) + ", but not given");
  }
  if (p_Bin_grasp.has_value() && !p_Bin_grasp->allFinite()) {
    throw InvalidArgument("p_Bin_grasp: must be finite, got " + FormatVector(*p_Bin_grasp));
  }

  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(d.covariance);
  if (solver.info() != Eigen::Success)
    throw InvalidArgument(what + ": covariance eigen decomposition failed");
  // Ascending order: column 2 is the principal direction.
  TubeFrame frame;
  frame.eigenvalues = solver.eigenvalues().reverse();
  frame.p_Bin_centroid = d.centroid;
  if (!(frame.eigenvalues[0] >= kMinSpread * kMinSpread)) {
    std::ostringstream s;
    s << what << ": the points all coincide (spread " << std::sqrt(std::max(0.0, frame.eigenvalues[0]))
      << " m < " << kMinSpread << " m): no principal direction";
    throw InvalidArgument(s.str());
  }
  Eigen::Vector3d direction = solver.eigenvectors().col(2).normalized();

  direction = AlongBinX(direction);
  if (params.sign == AxisSign::kAwayFromGrasp) {
    double t_min = std::numeric_limits<double>::infinity();
    double t_max = -std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& p : d.extremes) {
      const double t = (p - *p_Bin_grasp).dot(direction);
      t_min = std::min(t_min, t);
      t_max = std::max(t_max, t);
    }
    // Equal arms (grasp at the middle) keep the kAlongBinX sign.
    if (-t_min > t_max + kSignTol) direction = -direction;
  }
  frame.principal_direction_Bin = direction;

  const double horizontal = direction.head<2>().norm();
  if (horizontal < params.min_horizontal) return std::nullopt;

  Eigen::Vector3d x;
  Eigen::Vector3d z;
  if (params.yaw_only) {
    x = Eigen::Vector3d(direction.x(), direction.y(), 0.0) / horizontal;
    z = Eigen::Vector3d::UnitZ();
  } else {
    x = direction;
    z = (Eigen::Vector3d::UnitZ() - direction.z() * direction) / horizontal;
    z.normalize();
  }
  const Eigen::Vector3d y = z.cross(x);
  frame.X_BinTube = Eigen::Isometry3d::Identity();
  frame.X_BinTube.linear().col(0) = x;
  frame.X_BinTube.linear().col(1) = y;
  frame.X_BinTube.linear().col(2) = z;
  frame.X_BinTube.translation() = params.origin == TubeFrameOrigin::kCentroid ? d.centroid : *p_Bin_grasp;
  return frame;
}

double RotationAngle(const Eigen::Isometry3d& X_A, const Eigen::Isometry3d& X_B) {
  return Eigen::AngleAxisd(X_A.linear().transpose() * X_B.linear()).angle();
}

}  // namespace

void PlacementParams::Validate() const {
  RequireFinite(min_horizontal, "placement.min_horizontal");
  if (!(min_horizontal > 0.0 && min_horizontal < 1.0)) {
    std::ostringstream s;
    s << "placement.min_horizontal: " << min_horizontal << " is out of range (0, 1)";
    throw InvalidArgument(s.str());
  }
  if (origin != TubeFrameOrigin::kCentroid && origin != TubeFrameOrigin::kGraspPoint) {
    throw InvalidArgument("placement.origin: unknown value " + std::to_string(static_cast<int>(origin)));
  }
  if (sign != AxisSign::kAlongBinX && sign != AxisSign::kAwayFromGrasp) {
    throw InvalidArgument("placement.sign: unknown value " + std::to_string(static_cast<int>(sign)));
  }
}

std::optional<TubeFrame> EstimateTubeFrame(const Points& points_Bin, const PlacementParams& params,
                                           const std::optional<Eigen::Vector3d>& p_Bin_grasp) {
  params.Validate();
  return FrameOf(FromPoints(points_Bin), "points_Bin", params, p_Bin_grasp);
}

std::optional<TubeFrame> EstimateTubeFrame(const Tube& tube_Bin, const PlacementParams& params,
                                           const std::optional<Eigen::Vector3d>& p_Bin_grasp) {
  params.Validate();
  return FrameOf(FromTube(tube_Bin), "tube " + std::to_string(tube_Bin.id), params, p_Bin_grasp);
}

Eigen::Isometry3d PlacementTcpPose(const Eigen::Isometry3d& X_BinTcp, const Eigen::Isometry3d& X_BinTube,
                                   const Eigen::Isometry3d& X_BinPlace) {
  RequireRigid(X_BinTcp, "X_BinTcp");
  RequireRigid(X_BinTube, "X_BinTube");
  RequireRigid(X_BinPlace, "X_BinPlace");
  const Eigen::Isometry3d X_TubeTcp = X_BinTube.inverse(Eigen::Isometry) * X_BinTcp;
  return X_BinPlace * X_TubeTcp;
}

Placement PlanPlacement(const Eigen::Isometry3d& X_BinTcp, const TubeFrame& tube,
                        const Eigen::Isometry3d& X_BinPlace, const PlacementParams& params) {
  params.Validate();
  Placement placement;
  placement.X_BinTcpPlace = PlacementTcpPose(X_BinTcp, tube.X_BinTube, X_BinPlace);
  placement.X_TubeTcp = tube.X_BinTube.inverse(Eigen::Isometry) * X_BinTcp;
  placement.tcp_rotation_angle = RotationAngle(X_BinTcp, placement.X_BinTcpPlace);
  if (params.allow_flip) {
    // Half a turn about the tube frame's z: same tube axis, origin and up, x and y reversed.
    const Eigen::Isometry3d X_BinTubeFlipped =
        tube.X_BinTube * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ());
    const Eigen::Isometry3d X_BinTcpPlaceFlipped = PlacementTcpPose(X_BinTcp, X_BinTubeFlipped, X_BinPlace);
    const double angle_flipped = RotationAngle(X_BinTcp, X_BinTcpPlaceFlipped);
    if (angle_flipped + kAngleTieTol < placement.tcp_rotation_angle) {
      placement.X_BinTcpPlace = X_BinTcpPlaceFlipped;
      placement.X_TubeTcp = X_BinTubeFlipped.inverse(Eigen::Isometry) * X_BinTcp;
      placement.tcp_rotation_angle = angle_flipped;
      placement.flipped = true;
    }
  }
  return placement;
}

std::string ToString(TubeFrameOrigin origin) {
  switch (origin) {
    case TubeFrameOrigin::kCentroid:
      return "centroid";
    case TubeFrameOrigin::kGraspPoint:
      return "grasp_point";
  }
  return "unknown";
}

TubeFrameOrigin ParseTubeFrameOrigin(const std::string& text, const std::string& field) {
  if (text == "centroid") return TubeFrameOrigin::kCentroid;
  if (text == "grasp_point") return TubeFrameOrigin::kGraspPoint;
  throw InvalidArgument(field + ": unknown origin '" + text + "' (expected centroid or grasp_point)");
}

std::string ToString(AxisSign sign) {
  switch (sign) {
    case AxisSign::kAlongBinX:
      return "along_bin_x";
    case AxisSign::kAwayFromGrasp:
      return "away_from_grasp";
  }
  return "unknown";
}

AxisSign ParseAxisSign(const std::string& text, const std::string& field) {
  if (text == "along_bin_x") return AxisSign::kAlongBinX;
  if (text == "away_from_grasp") return AxisSign::kAwayFromGrasp;
  throw InvalidArgument(field + ": unknown sign rule '" + text +
                        "' (expected along_bin_x or away_from_grasp)");
}

}  // namespace tubepick
