#pragma once

// Range checks for parameter validation and algorithm inputs. Each throws InvalidArgument with a
// message that starts with the key (a YAML key path such as "modeling.cylinders.min_radius", or an
// argument name) and states the bad value.

#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tubepick {

/// @throws InvalidArgument "<key>: value must be finite, got <value>" for NaN or ±inf.
void RequireFinite(double value, const std::string& key);

/// `value` as messages about request fields print numbers ("%.9g": 0.1, 1e+30, nan).
std::string FormatNumber(double value);

/// The check of a request field (wire/, server/): @throws InvalidArgument
/// "<field>: must be finite, got <FormatNumber(value)>" for NaN or ±inf.
void RequireFiniteField(double value, const std::string& field);

/// @throws InvalidArgument unless `value` is finite and > 0.
void RequirePositive(double value, const std::string& key);

/// @throws InvalidArgument unless `value` is finite and >= 0.
void RequireNonNegative(double value, const std::string& key);

/// @throws InvalidArgument unless `value` is finite and in [lo, hi].
void RequireInRange(double value, double lo, double hi, const std::string& key);

/// @throws InvalidArgument "<key>: must be finite, got [x, y, z]" when any component of `v` is not
/// finite.
void RequireFiniteVector(const Eigen::Vector3d& v, const std::string& key);

/// RequireFinite of each component, named "<key>[i]".
/// @throws InvalidArgument "<key>[i]: value must be finite, got <value>" for the first bad component.
void RequireFiniteComponents(const Eigen::Vector3d& v, const std::string& key);

/// Checks that `X` is a finite rigid transform: its rotation is proper orthonormal
/// (‖RᵀR − I‖ ≤ 1e-6 and det R > 0).
/// @throws InvalidArgument "<name>: pose must be finite" or "<name>: rotation is not proper
/// orthonormal (...)".
void RequireRigid(const Eigen::Isometry3d& X, const std::string& name);

}  // namespace tubepick
