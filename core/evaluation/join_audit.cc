#include "core/evaluation/join_audit.h"

#include <algorithm>
#include <map>
#include <set>
#include <string>

#include "core/common/errors.h"

namespace tubepick {

bool JoinAudit::empty() const {
  return chains == 0 && std::all_of(kinds.begin(), kinds.end(), [](const Kind& k) {
           return k.accepted.right + k.accepted.wrong + k.refused.right + k.refused.wrong == 0;
         });
}

JoinAudit& JoinAudit::operator+=(const JoinAudit& other) {
  chains += other.chains;
  mixed_chains += other.mixed_chains;
  for (std::size_t k = 0; k < kinds.size(); ++k) {
    kinds[k].accepted.right += other.kinds[k].accepted.right;
    kinds[k].accepted.wrong += other.kinds[k].accepted.wrong;
    kinds[k].refused.right += other.kinds[k].refused.right;
    kinds[k].refused.wrong += other.kinds[k].refused.wrong;
  }
  return *this;
}

namespace {

// The real tube holding most of `votes` (tube → points), or −1 for none.
std::int32_t Majority(const std::map<std::int32_t, std::uint64_t>& votes) {
  const auto best = std::max_element(votes.begin(), votes.end(),
                                     [](const auto& a, const auto& b) { return a.second < b.second; });
  return best == votes.end() ? -1 : best->first;
}

}  // namespace

std::vector<ChainTruth> TruthOfChains(const ModelingResult& result, const std::vector<std::int32_t>& truth) {
  if (truth.size() != result.segment_of_point.size()) {
    throw InvalidArgument("join audit: " + std::to_string(truth.size()) + " ground-truth labels for " +
                          std::to_string(result.segment_of_point.size()) + " filtered points");
  }
  // Per segment: how many of its points each real tube holds.
  std::map<std::int32_t, std::map<std::int32_t, std::uint64_t>> tally;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (result.segment_of_point[i] >= 0 && truth[i] >= 0) ++tally[result.segment_of_point[i]][truth[i]];
  }
  std::vector<ChainTruth> out;
  out.reserve(result.chains.size());
  for (const Tube& chain : result.chains) {
    std::set<std::int32_t> segments;
    for (const Cylinder& c : chain.cylinders) segments.insert(static_cast<std::int32_t>(c.segment_id));
    std::map<std::int32_t, std::uint64_t> votes;
    std::set<std::int32_t> segment_tubes;
    for (const std::int32_t s : segments) {
      const auto it = tally.find(s);
      if (it == tally.end()) continue;
      segment_tubes.insert(Majority(it->second));
      for (const auto& [tube, n] : it->second) votes[tube] += n;
    }
    out.push_back({Majority(votes), segment_tubes.size() > 1});
  }
  return out;
}

JoinAudit AuditJoins(const ModelingResult& result, const std::vector<std::int32_t>& truth) {
  JoinAudit out;
  if (result.join_decisions.empty()) return out;
  const std::vector<ChainTruth> chains = TruthOfChains(result, truth);
  out.chains = static_cast<std::uint32_t>(chains.size());
  out.mixed_chains = static_cast<std::uint32_t>(
      std::count_if(chains.begin(), chains.end(), [](const ChainTruth& c) { return c.mixed; }));
  for (const JoinDecision& d : result.join_decisions) {
    bool right = !d.chains.empty();
    for (const std::uint32_t c : d.chains) {
      if (c >= chains.size()) {
        throw InvalidArgument("join audit: a decision names chain " + std::to_string(c) + " of " +
                              std::to_string(chains.size()));
      }
      right = right && chains[c].tube >= 0 && chains[c].tube == chains[d.chains.front()].tube;
    }
    JoinAudit::Kind& kind = out.kinds[static_cast<std::size_t>(d.kind)];
    JoinTally& tally = d.accepted ? kind.accepted : kind.refused;
    ++(right ? tally.right : tally.wrong);
  }
  return out;
}

}  // namespace tubepick
