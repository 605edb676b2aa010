#pragma once

#include <cstdint>
#include <string>

#include "core/wrench/wrench.h"
#include "core/wrench/wrench_params.h"

namespace tubepick {

/// Outcome of entanglement detection (thesis Algorithm 3).
enum class HeldOutcome { kNone, kSingle, kMultiple };

/// "none", "single", "multiple".
std::string ToString(HeldOutcome outcome);

/// Result of CountHeldTubes. Forces are upward components (see wrench.h), newtons.
struct HeldCount {
  /// Algorithm 3's decision; authoritative.
  HeldOutcome outcome = HeldOutcome::kNone;
  /// Weight of one tube, mass · gravity.
  double tube_weight = 0.0;
  /// Half-width of the single band used, N (EffectiveForceTolerance).
  double force_tolerance = 0.0;
  /// Expected upward force with exactly one tube held: F_z_ref − tube_weight.
  double expected_force = 0.0;
  /// Weight gained since the reference, F_z_ref − F_z (negative when the gripper got lighter).
  double held_weight = 0.0;
  /// held_weight / tube_weight, unrounded: how many tubes the force suggests.
  double tube_ratio = 0.0;
  /// Extra information: round(tube_ratio), clamped into the outcome's range so the two never
  /// disagree (kNone → 0, kSingle → 1, kMultiple → at least 2).
  std::uint32_t estimated_count = 0;
};

/// Algorithm 3 (§5.2.5): expected = F_z_ref − mass·g; F_z < expected − F_tol ⇒ kMultiple;
/// F_z > expected + F_tol ⇒ kNone; otherwise kSingle. Both comparisons are strict, so F_z equal to
/// expected ± F_tol is kSingle. F_tol is EffectiveForceTolerance: the thesis' exactly when
/// params.force_tolerance_share is 0.
/// @param fz_ref upward force with the gripper empty (before picking), N.
/// @param fz upward force after grasping and lifting, N.
/// @param tube_mass mass of one tube (cell `tube.mass`), kg.
/// @throws InvalidArgument when a force is not finite, tube_mass ≤ 0 (naming `tube.mass`),
/// `params` is invalid, or params.force_tolerance is not below one tube's weight.
HeldCount CountHeldTubes(double fz_ref, double fz, double tube_mass, const WrenchParams& params);

/// The same on full readings in the sensor frame (wrench.h): F_z = force · params.up_Tcp
/// (normalised).
HeldCount CountHeldTubes(const Wrench& reference, const Wrench& current, double tube_mass,
                         const WrenchParams& params);

}  // namespace tubepick
