#pragma once

// Internal to junction joining (junction_joining.cc, junction_acceptance.cc): which nodes and
// links are accepted, and the trees they make. Not part of core's interface.

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "core/common/cell_config.h"
#include "core/common/stop_token.h"
#include "core/common/types.h"
#include "core/modeling/junction_joining.h"

namespace tubepick::junction_internal {

// Two free ends whose extended axes meet (a pair of a Y-piece's branches).
struct EndMeeting {
  std::pair<std::uint32_t, bool> a;  // (chain, at_end)
  std::pair<std::uint32_t, bool> b;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  double cost = 0.0;
  // Close and straight enough to be linked end to end when no third end meets them.
  bool linkable = false;
};

// Free ends meeting at one node: a Y-piece, where every branch ends at the junction.
struct MeetingNode {
  std::vector<std::pair<std::uint32_t, bool>> ends;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int points = 0;
  bool linkable = false;

  Eigen::Vector3d Centre() const { return sum / points; }
};

// A node on a host chain: the junctions that share it.
struct HostNode {
  double arc = 0.0;
  double position = 0.0;  // on the host's axis pieces
  Eigen::Vector3d p_Bin = Eigen::Vector3d::Zero();
  std::uint32_t degree = 2;  // the two halves of the host
};

struct Accepted {
  std::vector<Junction> junctions;
  // Per accepted junction: its host node (index into nodes_of_host[host]).
  std::vector<std::size_t> node_of_junction;
  std::map<std::uint32_t, std::vector<HostNode>> nodes_of_host;
  std::vector<MeetingNode> meetings;
  // Every decision, in order (JunctionJoining::decisions): what counts as a junction or a completion.
  std::vector<JoinDecision> decisions;
};

// What the completion may still accept: T-pieces and pairs of ends within its wider limits.
struct CompletionCandidates {
  std::vector<Junction> sides;
  std::vector<EndMeeting> pairs;
};

// How far a junction's arms (directions away from its node) are from the shape: the largest
// difference between their angles and the shape's, both ascending; 0 for kAny, infinite for a
// node with another number of arms.
double ShapeDeviation(const std::vector<Eigen::Vector3d>& arms, JunctionShape shape);

// One tree from the chains `members` (a component) and the accepted junctions among them: each
// host chain cut at its T-nodes, every branch end linked to its node, pass-through nodes dropped.
Tube BuildTree(const std::vector<Tube>& chains, const Accepted& accepted,
               const std::vector<std::uint32_t>& members);

// Y-pieces first (their ends are spoken for), then T-pieces, then end-to-end links, each cheapest
// first and within `max_length` (0 = no limit); then, within `max_completed_length` (0 = none), the
// completion's candidates, cheapest first across both kinds: a pair of ends one of which is already
// at a node joins the other to that node.
Accepted Accept(const std::vector<Tube>& chains, const std::vector<MeetingNode>& meeting_nodes,
                const std::vector<Junction>& candidates, const CompletionCandidates& completion,
                double max_length, double max_completed_length, const JunctionParams& params,
                JunctionShape shape, const JunctionLayout& layout, const StopToken* stop);

}  // namespace tubepick::junction_internal
