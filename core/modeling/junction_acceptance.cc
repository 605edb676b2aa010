// Acceptance of junction joining's candidates: Y-pieces, T-pieces, links and the completion, one
// by one while every tube stays a tree; and the trees they make (BuildTree).
#include "core/modeling/junction_acceptance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>

#include "core/common/tube_graph.h"
#include "core/modeling/end_room.h"

namespace tubepick::junction_internal {
namespace {

constexpr double kPi = 3.14159265358979323846;
// A cylinder is split only when both halves are at least this long, metres; otherwise the cut
// moves to its nearer end.
constexpr double kMinPiece = 0.002;

// Where a cut at `position` on a chain's axis pieces falls between two of its cylinders (on a
// joint, or within kMinPiece of a cylinder's start or end, where TreeBuilder moves the cut): the
// number of cylinders before it; nullopt inside a cylinder. Two T-nodes at one boundary have no
// cylinder between them for a branch, so they are one node.
std::optional<std::size_t> CylinderBoundaryAt(const std::vector<AxisPiece>& pieces, double position) {
  const auto k = std::min(static_cast<std::size_t>(position), pieces.size() - 1);
  std::size_t before = 0;
  for (std::size_t i = 0; i < k; ++i) before += pieces[i].cylinder >= 0 ? 1 : 0;
  const AxisPiece& piece = pieces[k];
  if (piece.cylinder < 0) return before;
  const double length = (piece.b - piece.a).norm();
  const double t = position - static_cast<double>(k);
  if (t * length < kMinPiece) return before;
  if ((1.0 - t) * length < kMinPiece) return before + 1;
  return std::nullopt;
}

// The angles between the three arms of a junction shape, ascending; empty for kAny.
std::vector<double> ArmAngles(JunctionShape shape) {
  switch (shape) {
    case JunctionShape::kAny:
      return {};
    case JunctionShape::kWye:
      return {2.0 * kPi / 3.0, 2.0 * kPi / 3.0, 2.0 * kPi / 3.0};
    case JunctionShape::kTee:
      return {kPi / 2.0, kPi / 2.0, kPi};
  }
  return {};
}

class Forest {
 public:
  explicit Forest(const std::vector<Tube>& chains) : parent_(chains.size()), length_(chains.size()) {
    std::iota(parent_.begin(), parent_.end(), 0);
    for (std::size_t i = 0; i < chains.size(); ++i) length_[i] = chains[i].length();
  }
  std::uint32_t Find(std::uint32_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  double Length(std::uint32_t i) { return length_[Find(i)]; }
  void AddLength(std::uint32_t i, double length) { length_[Find(i)] += length; }
  void Unite(std::uint32_t a, std::uint32_t b, double link) {
    a = Find(a);
    b = Find(b);
    if (a > b) std::swap(a, b);
    parent_[b] = a;
    length_[a] += length_[b] + link;
  }

 private:
  std::vector<std::uint32_t> parent_;
  std::vector<double> length_;
};

// The arms of free ends meeting at a node: the directions from the node along their chains.
std::vector<Eigen::Vector3d> ArmsOf(const std::vector<std::pair<std::uint32_t, bool>>& ends,
                                    const std::vector<Tube>& chains) {
  std::vector<Eigen::Vector3d> arms;
  for (const auto& [chain, at_end] : ends) arms.push_back(-FreeEndOf(chains[chain], at_end).out);
  return arms;
}

// A Y-piece's node with a junction shape: the three of its ends whose arms fit the shape best,
// or nullopt when none fit within shape_tolerance (a chance end among them, or no Y at all).
std::optional<MeetingNode> FittingEnds(const MeetingNode& n, const std::vector<Tube>& chains,
                                       JunctionShape shape, double tolerance) {
  if (shape == JunctionShape::kAny) return n;
  std::optional<MeetingNode> best;
  double best_deviation = tolerance;
  const std::size_t k = n.ends.size();
  for (std::size_t a = 0; a < k; ++a) {
    for (std::size_t b = a + 1; b < k; ++b) {
      for (std::size_t c = b + 1; c < k; ++c) {
        const std::vector<std::pair<std::uint32_t, bool>> ends = {n.ends[a], n.ends[b], n.ends[c]};
        const double deviation = ShapeDeviation(ArmsOf(ends, chains), shape);
        if (deviation > best_deviation) continue;
        best_deviation = deviation;
        best = n;
        best->ends = ends;
      }
    }
  }
  return best;
}

// Builds one tree from the chains of a component and the junctions among them.
class TreeBuilder {
 public:
  TreeBuilder(const std::vector<Tube>& chains, const Accepted& accepted)
      : chains_(chains), accepted_(accepted) {}

  Tube Build(const std::vector<std::uint32_t>& members) {
    tube_ = Tube{};
    node_id_.clear();
    // Nodes of the junctions first (Y-pieces, then in host order), so that branch ends can name
    // them.
    for (std::size_t k = 0; k < accepted_.meetings.size(); ++k) {
      const MeetingNode& n = accepted_.meetings[k];
      if (std::find(members.begin(), members.end(), n.ends.front().first) == members.end()) continue;
      node_id_[{kMeeting, k}] = static_cast<std::uint32_t>(tube_.nodes.size());
      tube_.nodes.push_back(TubeNode{n.Centre()});
    }
    for (const std::uint32_t c : members) {
      const auto it = accepted_.nodes_of_host.find(c);
      if (it == accepted_.nodes_of_host.end()) continue;
      for (std::size_t k = 0; k < it->second.size(); ++k) {
        node_id_[{c, k}] = static_cast<std::uint32_t>(tube_.nodes.size());
        tube_.nodes.push_back(TubeNode{it->second[k].p_Bin});
      }
    }
    for (const std::uint32_t c : members) AddChain(c);
    return WithoutPassThroughNodes(tube_);
  }

 private:
  // The node a chain's free end is linked to, or a new end node.
  std::uint32_t EndNode(std::uint32_t chain, bool at_end) {
    for (std::size_t k = 0; k < accepted_.meetings.size(); ++k) {
      const auto& ends = accepted_.meetings[k].ends;
      if (std::find(ends.begin(), ends.end(), std::make_pair(chain, at_end)) != ends.end()) {
        return node_id_.at({kMeeting, k});
      }
    }
    for (std::size_t i = 0; i < accepted_.junctions.size(); ++i) {
      const Junction& j = accepted_.junctions[i];
      if (j.branch == chain && j.at_end == at_end)
        return node_id_.at({j.host, accepted_.node_of_junction[i]});
    }
    tube_.nodes.push_back(TubeNode{FreeEndOf(chains_[chain], at_end).p});
    return static_cast<std::uint32_t>(tube_.nodes.size() - 1);
  }

  void CloseBranch(std::uint32_t to_node) {
    const auto count = static_cast<std::uint32_t>(tube_.cylinders.size()) - first_;
    if (count > 0) tube_.branches.push_back(TubeBranch{from_, to_node, first_, count});
    from_ = to_node;
    first_ = static_cast<std::uint32_t>(tube_.cylinders.size());
  }

  void AddChain(std::uint32_t c) {
    const Tube& chain = chains_[c];
    const std::vector<AxisPiece> pieces = TubeAxisPieces(chain);
    // Cuts: (position on the pieces, node id), ascending.
    std::vector<std::pair<double, std::uint32_t>> cuts;
    if (const auto it = accepted_.nodes_of_host.find(c); it != accepted_.nodes_of_host.end()) {
      for (std::size_t k = 0; k < it->second.size(); ++k)
        cuts.emplace_back(it->second[k].position, node_id_.at({c, k}));
    }
    std::sort(cuts.begin(), cuts.end());
    from_ = EndNode(c, /*at_end=*/false);
    first_ = static_cast<std::uint32_t>(tube_.cylinders.size());
    std::size_t next_cut = 0;
    for (std::size_t k = 0; k < pieces.size(); ++k) {
      const AxisPiece& piece = pieces[k];
      if (piece.cylinder < 0) {  // a joint: cuts on it fall between its two cylinders
        while (next_cut < cuts.size() && cuts[next_cut].first < static_cast<double>(k + 1)) {
          CloseBranch(cuts[next_cut++].second);
        }
        continue;
      }
      Cylinder cylinder = chain.cylinders[static_cast<std::size_t>(piece.cylinder)];
      const double length = cylinder.length();
      double done = 0.0;  // fraction of this cylinder already emitted
      while (next_cut < cuts.size() && cuts[next_cut].first < static_cast<double>(k + 1)) {
        const double t = cuts[next_cut].first - static_cast<double>(k);
        const std::uint32_t node = cuts[next_cut++].second;
        if ((t - done) * length < kMinPiece) {  // at the start of what is left: cut before it
          CloseBranch(node);
        } else if ((1.0 - t) * length < kMinPiece) {  // at its end: cut after it
          tube_.cylinders.push_back(cylinder);
          done = 1.0;
          CloseBranch(node);
        } else {
          const Eigen::Vector3d foot = chain.cylinders[static_cast<std::size_t>(piece.cylinder)].start +
                                       t * (chain.cylinders[static_cast<std::size_t>(piece.cylinder)].end -
                                            chain.cylinders[static_cast<std::size_t>(piece.cylinder)].start);
          Cylinder first = cylinder;
          first.end = foot;
          tube_.cylinders.push_back(first);
          cylinder.start = foot;
          done = t;
          CloseBranch(node);
        }
      }
      if (done < 1.0) tube_.cylinders.push_back(cylinder);
    }
    CloseBranch(EndNode(c, /*at_end=*/true));
  }

  // The "host" of a Y-piece's node in node_id_'s keys.
  static constexpr std::uint32_t kMeeting = ~std::uint32_t{0};
  const std::vector<Tube>& chains_;
  const Accepted& accepted_;
  Tube tube_;
  std::map<std::pair<std::uint32_t, std::size_t>, std::uint32_t> node_id_;
  std::uint32_t from_ = 0;
  std::uint32_t first_ = 0;
};

// Accepts nodes one by one while every tube stays a tree (union-find over chains), each free
// end is used once, no node exceeds its branches, no tube the given length and, with the part's
// junction layout known, every tree fits it (FitsJunctionLayout).
class Acceptance {
 public:
  Acceptance(const std::vector<Tube>& chains, const JunctionParams& params, JunctionShape shape,
             const JunctionLayout& layout)
      : chains_(chains),
        params_(params),
        shape_(shape),
        layout_(layout),
        state_{Forest(chains), std::vector<std::array<bool, 2>>(chains.size()), {}} {}

  // A Y-piece (three or more ends) or a link (two), decided as `kind`.
  bool Meeting(const MeetingNode& meeting, double max_length, JoinDecision::Kind kind) {
    // With a junction shape, the node may keep three ends of the meeting that leave out its first.
    return Fitting(
        kind, [&] { return AcceptMeeting(meeting, max_length); },
        [&] {
          std::vector<std::uint32_t> chains;
          for (const auto& end : state_.out.meetings.back().ends) chains.push_back(end.first);
          return chains;
        });
  }

  bool Side(const Junction& j, double max_length, JoinDecision::Kind kind) {
    return Fitting(
        kind, [&] { return AcceptSide(j, max_length); },
        [&] {
          return std::vector<std::uint32_t>{j.branch, j.host};
        });
  }

  // A completion pair one of whose ends is already at a node: the other end joins that node as one
  // more branch.
  bool AtNode(const EndMeeting& pair, double max_length) {
    if (Used(pair.a.first, pair.a.second) == Used(pair.b.first, pair.b.second)) return false;
    const bool a_at_node = Used(pair.a.first, pair.a.second);
    const auto& at_node = a_at_node ? pair.a : pair.b;
    const auto& free = a_at_node ? pair.b : pair.a;
    return Fitting(
        JoinDecision::Kind::kCompletionNode, [&] { return AcceptAtNode(at_node, free, max_length); },
        [&] {
          return std::vector<std::uint32_t>{free.first, at_node.first};
        });
  }

  Accepted Take() && {
    state_.out.decisions = std::move(decisions_);
    return std::move(state_.out);
  }

 private:
  struct State {
    Forest forest;
    std::vector<std::array<bool, 2>> end_used;
    Accepted out;
  };

  // Accepts with `accept`, then takes it back unless the tree now holding `joined()` (the chains
  // it joined) fits the layout; records the decision either way.
  template <typename Accept, typename Joined>
  bool Fitting(JoinDecision::Kind kind, Accept accept, Joined joined) {
    if (!layout_.known()) {
      if (!accept()) return false;
      decisions_.push_back({kind, true, joined()});
      return true;
    }
    State before = state_;
    if (!accept()) return false;
    JoinDecision decision{kind, true, joined()};
    const std::uint32_t root = state_.forest.Find(decision.chains.front());
    std::vector<std::uint32_t> members;
    for (std::uint32_t c = 0; c < chains_.size(); ++c) {
      if (state_.forest.Find(c) == root) members.push_back(c);
    }
    decision.accepted = FitsJunctionLayout(TreeBuilder(chains_, state_.out).Build(members), layout_,
                                           params_.layout_tolerance);
    if (!decision.accepted) state_ = std::move(before);
    decisions_.push_back(std::move(decision));
    return decisions_.back().accepted;
  }

  bool AcceptMeeting(const MeetingNode& meeting, double max_length) {
    const std::optional<MeetingNode> fitting =
        meeting.ends.size() >= 3 ? FittingEnds(meeting, chains_, shape_, params_.shape_tolerance) : meeting;
    if (!fitting) return false;
    const MeetingNode& n = *fitting;
    std::vector<std::uint32_t> roots;
    double links = 0.0;
    for (const auto& [chain, at_end] : n.ends) {
      if (Used(chain, at_end)) return false;
      roots.push_back(state_.forest.Find(chain));
      links += (FreeEndOf(chains_[chain], at_end).p - n.Centre()).norm();
    }
    std::sort(roots.begin(), roots.end());
    if (std::adjacent_find(roots.begin(), roots.end()) != roots.end()) return false;  // a cycle
    double length = links;
    for (const std::uint32_t r : roots) length += state_.forest.Length(r);
    if (max_length > 0.0 && length > max_length) return false;
    for (std::size_t k = 1; k < n.ends.size(); ++k)
      state_.forest.Unite(n.ends[0].first, n.ends[k].first, 0.0);
    state_.forest.AddLength(n.ends[0].first, links);
    for (const auto& [chain, at_end] : n.ends) Use(chain, at_end);
    state_.out.meetings.push_back(n);
    return true;
  }

  // A T-piece: the branch's free end on the host's side.
  bool AcceptSide(const Junction& j, double max_length) {
    if (Used(j.branch, j.at_end) || state_.forest.Find(j.branch) == state_.forest.Find(j.host)) return false;
    const double link = (j.p_Bin - FreeEndOf(chains_[j.branch], j.at_end).p).norm();
    if (max_length > 0.0 && state_.forest.Length(j.branch) + state_.forest.Length(j.host) + link > max_length)
      return false;
    std::vector<HostNode>& nodes = state_.out.nodes_of_host[j.host];
    const std::vector<AxisPiece> pieces = TubeAxisPieces(chains_[j.host]);
    const std::optional<std::size_t> boundary = CylinderBoundaryAt(pieces, j.host_position);
    auto near = std::find_if(nodes.begin(), nodes.end(), [&](const HostNode& n) {
      return std::abs(n.arc - j.host_arc) < params_.node_spacing ||
             (boundary && CylinderBoundaryAt(pieces, n.position) == boundary);
    });
    const std::uint32_t max_branches = shape_ == JunctionShape::kAny ? params_.max_branches_per_node : 3;
    if (near != nodes.end() && near->degree + 1 > max_branches) return false;
    if (near == nodes.end()) {
      nodes.push_back(HostNode{j.host_arc, j.host_position, j.p_Bin, 2});
      near = nodes.end() - 1;
    }
    AddJunction(j, static_cast<std::size_t>(near - nodes.begin()), link);
    return true;
  }

  // Junction `j` at node `node` of its host (nodes_of_host[j.host]), its branch linked `link` away.
  void AddJunction(const Junction& j, std::size_t node, double link) {
    ++state_.out.nodes_of_host[j.host][node].degree;
    Use(j.branch, j.at_end);
    state_.forest.Unite(j.branch, j.host, link);
    state_.out.junctions.push_back(j);
    state_.out.node_of_junction.push_back(node);
  }

  // `free` joins the node `at_node` is at: a Y-piece or link (one more end of the meeting) or a
  // T-node (one more branch at the host's node).
  bool AcceptAtNode(const std::pair<std::uint32_t, bool>& at_node, const std::pair<std::uint32_t, bool>& free,
                    double max_length) {
    const std::uint32_t max_branches = shape_ == JunctionShape::kAny ? params_.max_branches_per_node : 3;
    const Eigen::Vector3d p_free = FreeEndOf(chains_[free.first], free.second).p;
    if (state_.forest.Find(free.first) == state_.forest.Find(at_node.first)) return false;
    auto within = [&](const Eigen::Vector3d& p_node) {
      const double link = (p_node - p_free).norm();
      return max_length <= 0.0 ||
             state_.forest.Length(free.first) + state_.forest.Length(at_node.first) + link <= max_length;
    };
    for (MeetingNode& n : state_.out.meetings) {
      if (std::find(n.ends.begin(), n.ends.end(), at_node) == n.ends.end()) continue;
      if (n.ends.size() + 1 > max_branches || !within(n.Centre())) return false;
      if (shape_ != JunctionShape::kAny && n.ends.size() + 1 == 3) {
        std::vector<std::pair<std::uint32_t, bool>> ends = n.ends;
        ends.push_back(free);
        if (ShapeDeviation(ArmsOf(ends, chains_), shape_) > params_.shape_tolerance) return false;
      }
      state_.forest.Unite(n.ends.front().first, free.first, (n.Centre() - p_free).norm());
      n.ends.push_back(free);
      Use(free.first, free.second);
      return true;
    }
    for (std::size_t i = 0; i < state_.out.junctions.size(); ++i) {
      const Junction& j = state_.out.junctions[i];
      if (j.branch != at_node.first || j.at_end != at_node.second) continue;
      const std::size_t node = state_.out.node_of_junction[i];
      const HostNode& host_node = state_.out.nodes_of_host[j.host][node];
      if (host_node.degree + 1 > max_branches || !within(host_node.p_Bin)) return false;
      Junction added = j;  // a copy: AddJunction appends to the vector j is in
      added.branch = free.first;
      added.at_end = free.second;
      AddJunction(added, node, (host_node.p_Bin - p_free).norm());
      return true;
    }
    return false;
  }

  bool Used(std::uint32_t chain, bool at_end) const { return state_.end_used[chain][at_end ? 1 : 0]; }
  void Use(std::uint32_t chain, bool at_end) { state_.end_used[chain][at_end ? 1 : 0] = true; }

  const std::vector<Tube>& chains_;
  const JunctionParams& params_;
  JunctionShape shape_;
  const JunctionLayout& layout_;
  State state_;
  std::vector<JoinDecision> decisions_;
};

}  // namespace

double ShapeDeviation(const std::vector<Eigen::Vector3d>& arms, JunctionShape shape) {
  const std::vector<double> expected = ArmAngles(shape);
  if (expected.empty()) return 0.0;
  if (arms.size() != expected.size()) return std::numeric_limits<double>::infinity();
  std::vector<double> angles;
  for (std::size_t i = 0; i < arms.size(); ++i) {
    for (std::size_t k = i + 1; k < arms.size(); ++k) {
      angles.push_back(std::acos(std::clamp(arms[i].normalized().dot(arms[k].normalized()), -1.0, 1.0)));
    }
  }
  std::sort(angles.begin(), angles.end());
  double deviation = 0.0;
  for (std::size_t i = 0; i < angles.size(); ++i)
    deviation = std::max(deviation, std::abs(angles[i] - expected[i]));
  return deviation;
}

Tube BuildTree(const std::vector<Tube>& chains, const Accepted& accepted,
               const std::vector<std::uint32_t>& members) {
  return TreeBuilder(chains, accepted).Build(members);
}

// Y-pieces first (their ends are spoken for), then T-pieces, then end-to-end links, each cheapest
// first and within `max_length` (0 = no limit); then, within `max_completed_length` (0 = none), the
// completion's candidates, cheapest first across both kinds: a pair of ends one of which is already
// at a node joins the other to that node.
Accepted Accept(const std::vector<Tube>& chains, const std::vector<MeetingNode>& meeting_nodes,
                const std::vector<Junction>& candidates, const CompletionCandidates& completion,
                double max_length, double max_completed_length, const JunctionParams& params,
                JunctionShape shape, const JunctionLayout& layout, const StopToken* stop) {
  Acceptance acceptance(chains, params, shape, layout);
  for (const MeetingNode& n : meeting_nodes) {
    const bool ambiguous = shape == JunctionShape::kAny && n.ends.size() > params.max_meeting_ends;
    if (n.ends.size() >= 3 && !ambiguous) acceptance.Meeting(n, max_length, JoinDecision::Kind::kYPiece);
  }
  for (const Junction& j : candidates) {
    ThrowIfStopped(stop, "joining");
    acceptance.Side(j, max_length, JoinDecision::Kind::kTPiece);
  }
  for (const MeetingNode& n : meeting_nodes) {
    if (n.ends.size() == 2) acceptance.Meeting(n, max_length, JoinDecision::Kind::kLink);
  }
  if (max_completed_length > 0.0) {
    std::size_t s = 0, m = 0;
    const auto& sides = completion.sides;
    const auto& pairs = completion.pairs;
    while (s < sides.size() || m < pairs.size()) {
      ThrowIfStopped(stop, "joining");
      if (m >= pairs.size() || (s < sides.size() && sides[s].reach + sides[s].offset <= pairs[m].cost)) {
        acceptance.Side(sides[s++], max_completed_length, JoinDecision::Kind::kCompletionT);
      } else {
        const EndMeeting& pair = pairs[m++];
        if (!acceptance.Meeting(MeetingNode{{pair.a, pair.b}, pair.p, 1, true}, max_completed_length,
                                JoinDecision::Kind::kCompletionLink))
          acceptance.AtNode(pair, max_completed_length);
      }
    }
  }
  return std::move(acceptance).Take();
}
}  // namespace tubepick::junction_internal
