#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/common/types.h"

namespace tubepick {

/// How sure a plan is to lift its tube alone, before any physics (issue 14 item 6).
enum class PlanCertainty {
  /// A non-occluded tube that no other modeled tube lies on, lifted straight up: nothing is known
  /// to come along.
  kSure,
  /// Its trajectory was simulated: PickPlan::displacement says how safe it is.
  kSimulated,
  /// Needs luck: an occluded tube, or a non-occluded one another tube lies on, whose trajectory
  /// was not simulated (no evaluator).
  kUnsure,
};

/// "sure", "simulated", "unsure".
std::string ToString(PlanCertainty certainty);

/// The certainty rule of ranking (PlanningParams::certainty).
///
/// A plan is *safe* when it is kSure, or kSimulated with a displacement of at most
/// `safe_displacement`. With `safe_first`, every safe plan outranks every plan that is not, and
/// G_cost orders plans within each group; planning also goes on to the next candidate stage
/// (thesis §5.2.3: non-occluded, weakly, strongly occluded tubes) while the stages so far gave
/// plans but no safe one, and ranks the plans of all stages it tried together. Without it,
/// ranking is G_cost alone and planning stops at the first stage with a plan (the thesis).
struct CertaintyParams {
  bool safe_first = true;
  /// Metres: the summed displacement of the other tubes (thesis `disp`) that still counts as
  /// lifting the tube alone. Lifting a free tube off a pile measures 1–5 cm in the Bullet
  /// evaluator where the true answer is 0 (physics/trajectory_simulator.h, noise floor).
  double safe_displacement = 0.05;
  /// A tube lies on another when their axes come within the two radii plus this, metres, at a
  /// point where its axis is higher than the other's by at least half the two radii (the contact
  /// normal at least 30° above horizontal: tubes side by side on the floor do not count).
  double contact_margin = 0.005;
};

/// The tubes (indices into `tubes`) that lie on tubes[t] (CertaintyParams::contact_margin), in
/// ascending order. Non-occluded tubes classified by joints alone (thesis Def. 5.2.2) can still
/// have another tube across an end, which hides the end rather than splitting the tube.
std::vector<std::uint32_t> TubesLyingOn(const std::vector<Tube>& tubes, std::size_t t,
                                        const CertaintyParams& params);

}  // namespace tubepick
