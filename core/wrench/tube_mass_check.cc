#include "core/wrench/tube_mass_check.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/common/errors.h"
#include "core/common/require.h"

namespace tubepick {

void TubeMassCheckParams::Validate() const {
  if (window < 1) throw InvalidArgument("tube_mass_check.window: must be at least 1");
  if (min_lifts < 1 || min_lifts > window)
    throw InvalidArgument(
        fmt::format("tube_mass_check.min_lifts: {} is outside [1, window = {}]", min_lifts, window));
  if (max_tubes_per_lift < 1) throw InvalidArgument("tube_mass_check.max_tubes_per_lift: must be at least 1");
  if (!(max_off_whole > 0.0 && max_off_whole < 0.5))
    throw InvalidArgument(
        fmt::format("tube_mass_check.max_off_whole: {} is outside (0, 0.5)", max_off_whole));
}

std::optional<TubeMassDoubt> CheckTubeMass(const std::vector<double>& tube_ratios, double tube_mass,
                                           const TubeMassCheckParams& params) {
  params.Validate();
  RequirePositive(tube_mass, "tube.mass");
  std::vector<double> held;  // most recent first
  for (auto it = tube_ratios.rbegin(); it != tube_ratios.rend() && held.size() < params.window; ++it) {
    RequireFinite(*it, "tube_ratio");
    held.push_back(*it);
  }
  if (held.size() < params.min_lifts) return std::nullopt;
  const double most = static_cast<double>(params.max_tubes_per_lift);
  for (const double r : held) {
    const double whole = std::clamp(std::round(r), 1.0, most);
    if (std::abs(r - whole) <= params.max_off_whole) return std::nullopt;
  }
  TubeMassDoubt d;
  d.lifts = static_cast<std::uint32_t>(held.size());
  std::sort(held.begin(), held.end());
  d.min_ratio = held.front();
  d.max_ratio = held.back();
  d.median_ratio = held.size() % 2 == 1 ? held[held.size() / 2]
                                        : 0.5 * (held[held.size() / 2 - 1] + held[held.size() / 2]);
  d.tube_mass = tube_mass;
  d.mass_if_single = tube_mass * d.median_ratio;
  d.message = fmt::format(
      "the last {} lifts weighed {:.2f}-{:.2f} times tube.mass ({:.3f} kg), none a whole number of tubes "
      "from 1 to {}, though the gripper held something each time: is tube.mass right? One tube per lift "
      "would weigh {:.3f} kg. Every lift is judged against tube.mass: with it wrong, a single pick can "
      "read as none or several",
      d.lifts, d.min_ratio, d.max_ratio, tube_mass, params.max_tubes_per_lift, d.mass_if_single);
  return d;
}

}  // namespace tubepick
