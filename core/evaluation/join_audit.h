#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/modeling/junction_joining.h"
#include "core/modeling/model_tubes.h"

namespace tubepick {

/// Decisions of one kind whose chains are one real tube (right) or not (wrong).
struct JoinTally {
  std::uint32_t right = 0;
  std::uint32_t wrong = 0;
};

/// Junction joining's decisions (ModelingResult::join_decisions) against ground truth, per kind:
/// those kept and those the junction layout took back. A decision is right when every chain it
/// joins is mostly one and the same real tube. Shows where a scene's merged trees come from (the
/// kind of node or link that joined two tubes) and what the layout costs (right ones taken back).
struct JoinAudit {
  struct Kind {
    JoinTally accepted;
    JoinTally refused;
  };
  /// Indexed by JoinDecision::Kind.
  std::array<Kind, JoinDecision::kKinds> kinds{};
  /// The linear chains junction joining started from, and those of them whose segments are mostly
  /// different real tubes (the linear joining before the junctions joined two tubes).
  std::uint32_t chains = 0;
  std::uint32_t mixed_chains = 0;

  bool empty() const;
  JoinAudit& operator+=(const JoinAudit& other);
};

/// The real tube of each of result.chains: the most common ground truth among the filtered points
/// of the segments its cylinders were fitted to (−1 when none of them is a tube's); `mixed` when
/// two of those segments are mostly different tubes. `truth` has one label per filtered point
/// (real tube index, or negative for background).
struct ChainTruth {
  std::int32_t tube = -1;
  bool mixed = false;
};
/// @throws InvalidArgument when truth and result.segment_of_point differ in size.
std::vector<ChainTruth> TruthOfChains(const ModelingResult& result, const std::vector<std::int32_t>& truth);

/// Audits result.join_decisions against `truth` (as TruthOfChains). Empty without junction joining
/// (no decisions; `truth` is then not looked at).
/// @throws InvalidArgument as TruthOfChains, or for a decision naming a chain that does not exist.
JoinAudit AuditJoins(const ModelingResult& result, const std::vector<std::int32_t>& truth);

}  // namespace tubepick
