#include "core/common/require.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/common/errors.h"

namespace tubepick {
namespace {

// Largest ‖RᵀR − I‖ accepted for a rotation matrix.
constexpr double kOrthonormalTol = 1e-6;

}  // namespace

void RequireFinite(double value, const std::string& key) {
  if (!std::isfinite(value))
    throw InvalidArgument(key + ": value must be finite, got " + std::to_string(value));
}

std::string FormatNumber(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.9g", value);
  return buffer;
}

void RequireFiniteField(double value, const std::string& field) {
  if (!std::isfinite(value)) throw InvalidArgument(field + ": must be finite, got " + FormatNumber(value));
}

void RequirePositive(double value, const std::string& key) {
  RequireFinite(value, key);
  if (!(value > 0.0)) throw InvalidArgument(key + ": must be > 0, got " + std::to_string(value));
}

void RequireNonNegative(double value, const std::string& key) {
  RequireFinite(value, key);
  if (value < 0.0) throw InvalidArgument(key + ": must be >= 0, got " + std::to_string(value));
}

void RequireInRange(double value, double lo, double hi, const std::string& key) {
  RequireFinite(value, key);
  if (value < lo || value > hi) {
    std::ostringstream s;
    s << key << ": " << value << " is out of range [" << lo << ", " << hi << "]";
    throw InvalidArgument(s.str());
  }
}

void RequireFiniteVector(const Eigen::Vector3d& v, const std::string& key) {
  if (!v.allFinite()) {
    std::ostringstream s;
    s << key << ": must be finite, got [" << v.x() << ", " << v.y() << ", " << v.z() << "]";
    throw InvalidArgument(s.str());
  }
}

void RequireFiniteComponents(const Eigen::Vector3d& v, const std::string& key) {
  for (int k = 0; k < 3; ++k) RequireFinite(v[k], key + "[" + std::to_string(k) + "]");
}

void RequireRigid(const Eigen::Isometry3d& X, const std::string& name) {
  if (!X.matrix().allFinite()) throw InvalidArgument(name + ": pose must be finite");
  const Eigen::Matrix3d R = X.linear();
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  if (error > kOrthonormalTol || R.determinant() < 0.0) {
    std::ostringstream s;
    s << name << ": rotation is not proper orthonormal (|R^T R - I| = " << error
      << ", det = " << R.determinant() << ")";
    throw InvalidArgument(s.str());
  }
}

}  // namespace tubepick
