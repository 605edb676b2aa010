#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tubepick {

/// Whether a cell's lifts weigh what its tube.mass says.
///
/// Algorithm 3 (CountHeldTubes) reads every lift against tube.mass. With it wrong, single picks read as
/// none or several once the error passes the single band (EffectiveForceTolerance: the fast
/// profile's 0.2 of a tube's weight, the thesis' 0.25 N: 0.46 of the 0.055 kg PVC tube's weight), and the
/// cell releases or shakes tubes it holds alone, again and again, with nothing naming the cause. With the
/// right mass the lifts weigh about a whole number of tubes: in the simulated cell, 144 lifts of pvc and
/// rubber bins of sets A, B and C weighed 0.93–1.04 tubes when single and 1.98–3.00 when several, but for two
/// entangled rubber lifts of 5.32 and 5.42. A lift the gripper holds through weighs at least one tube: one
/// that reads about none (a mass ten times too high, kilograms for a tenth) fits nothing, nor does one of
/// more tubes than a grasp lifts (a mass ten times too low). A mass off by a small whole factor (half the
/// real one) is not seen this way: every lift then weighs two tubes.
struct TubeMassCheckParams {
  /// The most recent lifts looked at ...
  std::uint32_t window = 5;
  /// ... of which at least this many are needed to judge.
  std::uint32_t min_lifts = 3;
  /// The most tubes one lift is believed to hold (the grasped one and those hanging on it).
  std::uint32_t max_tubes_per_lift = 6;
  /// A lift fits tube.mass when its tube_ratio lies within this of a whole number of tubes from 1
  /// to max_tubes_per_lift.
  double max_off_whole = 0.2;

  /// @throws InvalidArgument naming the field and value.
  void Validate() const;
};

/// Lifts that do not fit tube.mass.
struct TubeMassDoubt {
  /// The lifts judged (the most recent) and their tube ratios' range and median.
  std::uint32_t lifts = 0;
  double min_ratio = 0.0;
  double max_ratio = 0.0;
  double median_ratio = 0.0;
  /// tube.mass as stated, kg, and the mass one tube would have if each lift held one, kg.
  double tube_mass = 0.0;
  double mass_if_single = 0.0;
  /// One sentence naming both masses and the likely cause.
  std::string message;
};

/// The doubt when each of the last `params.window` lifts (at least min_lifts of them) lies more than
/// max_off_whole from every whole number of tubes from 1 to max_tubes_per_lift; std::nullopt
/// otherwise (too few lifts, or one fits).
/// @param tube_ratios held weight / (tube.mass · g) of the cell's lifts that held something (the
///        gripper closed on an object and still held it after the lift), oldest first.
/// @throws InvalidArgument when params are invalid, tube_mass ≤ 0 or a ratio is not finite.
std::optional<TubeMassDoubt> CheckTubeMass(const std::vector<double>& tube_ratios, double tube_mass,
                                           const TubeMassCheckParams& params = {});

}  // namespace tubepick
