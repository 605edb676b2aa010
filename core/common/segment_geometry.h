#pragma once

#include <Eigen/Core>

namespace tubepick {

/// The closest points of two segments: p0 + s (p1 − p0) and q0 + t (q1 − q0), s, t in [0, 1].
struct SegmentClosestPoints {
  double s = 0.0;
  double t = 0.0;
  double distance = 0.0;
};

/// Closest points of segments [p0, p1] and [q0, q1] (Ericson, Real-Time Collision Detection
/// §5.1.9); degenerate segments are points.
SegmentClosestPoints ClosestPointsOfSegments(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                             const Eigen::Vector3d& q0, const Eigen::Vector3d& q1);

}  // namespace tubepick
