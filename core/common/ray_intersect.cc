#include "core/common/ray_intersect.h"

#include <cmath>
#include <limits>

namespace tubepick {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

double RaySphere(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& c, double r) {
  const Eigen::Vector3d oc = o - c;
  const double b = oc.dot(d);
  const double disc = b * b - (oc.squaredNorm() - r * r);
  if (disc < 0.0) return kInf;
  const double s = std::sqrt(disc);
  const double t0 = -b - s;
  if (t0 > 0.0) return t0;
  const double t1 = -b + s;
  return t1 > 0.0 ? t1 : kInf;
}

double RayCylinderSide(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b, double r) {
  const Eigen::Vector3d axis = b - a;
  const double len = axis.norm();
  if (len <= 0.0) return kInf;
  const Eigen::Vector3d u = axis / len;
  const Eigen::Vector3d oa = o - a;
  const Eigen::Vector3d d_perp = d - d.dot(u) * u;
  const Eigen::Vector3d oa_perp = oa - oa.dot(u) * u;
  const double qa = d_perp.squaredNorm();
  if (qa < 1e-14) return kInf;
  const double qb = 2.0 * d_perp.dot(oa_perp);
  const double qc = oa_perp.squaredNorm() - r * r;
  const double disc = qb * qb - 4.0 * qa * qc;
  if (disc < 0.0) return kInf;
  const double s = std::sqrt(disc);
  for (double t : {(-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa)}) {
    if (t <= 0.0) continue;
    const double along = (oa + t * d).dot(u);
    if (along >= 0.0 && along <= len) return t;
  }
  return kInf;
}

double RayPlane(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& n, double c) {
  const double nd = n.dot(d);
  if (std::abs(nd) < 1e-12) return kInf;
  const double t = (c - n.dot(o)) / nd;
  return t > 0.0 ? t : kInf;
}

}  // namespace tubepick
