#pragma once

#include <Eigen/Core>

namespace tubepick {

/// Smallest t > 0 where the ray o + t·d (|d| = 1) meets the sphere (c, r); +inf when it misses.
double RaySphere(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& c, double r);

/// Smallest t > 0 where the ray o + t·d (|d| = 1) meets the side of the finite cylinder with
/// base centres a and b and radius r (no caps); +inf when it misses.
double RayCylinderSide(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b, double r);

/// Smallest t > 0 where the ray meets the plane n·p = c; +inf when parallel or behind.
double RayPlane(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& n, double c);

}  // namespace tubepick
