// Junction joining: linear chains (JoinTubes) into trees.
//
// A branch of a hose assembly leaves its run at a T- or Y-piece. Region growing splits the
// surface there (the normals turn), so the cylinders near the node end a centimetre or more from
// it, pointing at it; the blob at the node itself is often a short fragment of its own.
// Three kinds of node, accepted in this order:
// 1. Y-pieces (every branch ends at the node): free ends whose axes, each extended by its
//    radius plus max_gap, meet within max_axis_offset, at an angle of at least min_angle or
//    facing each other along one line (a run broken at the node), are clustered cheapest first;
//    a cluster of min_meeting_ends (3) or more ends within node_spacing of its centre is a node
//    (with shape `any`, at most max_meeting_ends: a cluster of more is ambiguous, none of it a node).
// 2. T-pieces (the run goes on through the node): a free end whose axis, extended by the other
//    tube's radius plus side_max_gap, passes within side_max_axis_offset of another chain's axis
//    (a cylinder or a joint of it), at least min_angle off it and not within node_spacing of
//    that chain's free ends. A tube lying across another is not one: its axis passes about two
//    radii above the other's. The chain is cut there (the cylinder under the node is split at
//    the foot; T-nodes closer than node_spacing on one chain, or with no cylinder between them,
//    share a node).
// 3. Links: two ends that met alone in step 1 and lie within link_max_distance and link_max_angle
//    (α + β, as the linear joining) are joined end to end (the node is then dropped again,
//    WithoutPassThroughNodes).
// 4. Completion: the free ends still unused, as T-pieces and links within the wider limits of
//    JunctionCompletionParams, cheapest first, where the tree stays within the cell's tube length.
// Each is accepted only while every tube stays a tree (union-find over chains), each free end is
// used once, no node exceeds max_branches_per_node and no tube max_tube_length (Acceptance).

#include "core/modeling/junction_joining.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <tuple>

#include "core/common/errors.h"
#include "core/common/require.h"
#include "core/common/segment_geometry.h"
#include "core/common/tube_graph.h"
#include "core/modeling/tube_joining.h"

namespace tubepick {
namespace {

constexpr double kPi = 3.14159265358979323846;
// A cylinder is split only when both halves are at least this long, metres; otherwise the cut
// moves to its nearer end.
constexpr double kMinPiece = 0.002;

// Arc length along a chain's axis pieces at a position (piece index + fraction).
double ArcAt(const std::vector<AxisPiece>& pieces, double position) {
  const auto k = static_cast<std::size_t>(position);
  double arc = 0.0;
  for (std::size_t i = 0; i < k && i < pieces.size(); ++i) arc += (pieces[i].b - pieces[i].a).norm();
  if (k < pieces.size()) arc += (position - static_cast<double>(k)) * (pieces[k].b - pieces[k].a).norm();
  return arc;
}

double ArcLength(const std::vector<AxisPiece>& pieces) {
  return ArcAt(pieces, static_cast<double>(pieces.size()));
}

// The point on a chain's axis pieces at an arc length (clamped to the chain).
Eigen::Vector3d PointAtArc(const std::vector<AxisPiece>& pieces, double arc) {
  for (const AxisPiece& piece : pieces) {
    const double length = (piece.b - piece.a).norm();
    if (arc <= length) return length > 0.0 ? piece.a + (arc / length) * (piece.b - piece.a) : piece.a;
    arc -= length;
  }
  return pieces.back().b;
}

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

// Where the arms of a T-junction's run are measured: this far from the node along the run.
constexpr double kRunArmProbe = 0.03;

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

// How far a junction's arms (directions away from its node) are from the shape: the largest
// difference between their angles and the shape's, both ascending; 0 for kAny, infinite for a
// node with another number of arms.
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

// The reach of a chain's free end (ReachOf), nominal without rooms.
double RoomReach(const EndRooms& rooms, std::uint32_t chain, bool at_end, double nominal) {
  return chain < rooms.size() ? ReachOf(rooms[chain][at_end ? 1 : 0], nominal) : nominal;
}

// Pairs of free ends of different chains whose axes, each extended by at most its radius plus
// max_gap, pass within max_axis_offset of each other at an angle of at least min_angle, or that
// face each other along one line within that reach (a run broken at a T-piece's node; alone,
// such a pair is the linear joining's business, so only a third end makes it a node). Ends
// pointing the same way side by side never meet. Cheapest first.
std::vector<EndMeeting> FindEndMeetings(const std::vector<Tube>& chains, const JunctionParams& params,
                                        const EndRooms& rooms) {
  const double cos_min = std::cos(params.min_angle);
  struct End {
    std::pair<std::uint32_t, bool> id;
    FreeEnd end;
    double reach;
  };
  std::vector<End> ends;
  for (std::uint32_t c = 0; c < chains.size(); ++c) {
    if (chains[c].cylinders.empty() || chains[c].branched()) continue;
    for (const bool at_end : {false, true}) {
      const FreeEnd end = FreeEndOf(chains[c], at_end);
      ends.push_back({{c, at_end}, end, RoomReach(rooms, c, at_end, end.radius + params.max_gap)});
    }
  }
  std::vector<EndMeeting> out;
  // As the linear joining measures a pair (α + β, no angle below the mean radius: touching ends).
  auto linkable = [&](const End& x, const End& y) {
    const double mean_radius = 0.5 * (x.end.radius + y.end.radius);
    const JoinDistance d =
        EndpointDistance(x.end.p, x.end.out, y.end.p, y.end.out, mean_radius, JoiningParams{});
    return d.euclidean <= params.link_max_distance && d.angular <= params.link_max_angle;
  };
  for (std::size_t i = 0; i < ends.size(); ++i) {
    for (std::size_t k = i + 1; k < ends.size(); ++k) {
      const End& x = ends[i];
      const End& y = ends[k];
      if (x.id.first == y.id.first) continue;
      if ((x.end.p - y.end.p).norm() > x.reach + y.reach + params.max_axis_offset) continue;
      const double alignment = x.end.out.dot(y.end.out);
      if (alignment > cos_min) continue;  // side by side, pointing the same way
      if (alignment < -cos_min) {
        // Facing each other along one line: a run broken at a T-piece's node (or a plain gap,
        // which only a third end meeting them turns into a node). They meet halfway.
        const Eigen::Vector3d gap = y.end.p - x.end.p;
        const double along = gap.dot(x.end.out);
        const double offset = (gap - along * x.end.out).norm();
        if (along <= 0.0 || along > x.reach + y.reach || offset > params.max_axis_offset) continue;
        out.push_back({x.id, y.id, 0.5 * (x.end.p + y.end.p), along + offset, linkable(x, y)});
        continue;
      }
      const SegmentClosestPoints cp = ClosestPointsOfSegments(x.end.p, x.end.p + x.reach * x.end.out, y.end.p,
                                                              y.end.p + y.reach * y.end.out);
      if (cp.distance > params.max_axis_offset) continue;
      const Eigen::Vector3d px = x.end.p + cp.s * x.reach * x.end.out;
      const Eigen::Vector3d py = y.end.p + cp.t * y.reach * y.end.out;
      out.push_back(
          {x.id, y.id, 0.5 * (px + py), cp.s * x.reach + cp.t * y.reach + cp.distance, linkable(x, y)});
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const EndMeeting& u, const EndMeeting& v) {
    return std::tie(u.cost, u.a, u.b) < std::tie(v.cost, v.a, v.b);
  });
  return out;
}

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
  // Of them, accepted by the completion (the last T-pieces and links).
  std::uint32_t completed_sides = 0;
  std::uint32_t completed_links = 0;
  std::vector<JoinDecision> decisions;
};

// Groups end meetings, cheapest first, into nodes of free ends whose meeting points lie within
// node_spacing of the node's centre (one end per chain, at most max_branches_per_node); only
// nodes of three or more ends are junctions.
std::vector<MeetingNode> ClusterMeetings(const std::vector<EndMeeting>& meetings,
                                         const JunctionParams& params) {
  std::vector<MeetingNode> nodes;
  std::map<std::pair<std::uint32_t, bool>, std::size_t> node_of_end;
  auto has_chain = [](const MeetingNode& n, std::uint32_t chain) {
    return std::any_of(n.ends.begin(), n.ends.end(), [&](const auto& e) { return e.first == chain; });
  };
  auto join = [&](std::size_t k, const std::pair<std::uint32_t, bool>& end, const Eigen::Vector3d& p) {
    MeetingNode& n = nodes[k];
    if (has_chain(n, end.first) || n.ends.size() >= params.max_branches_per_node) return;
    if ((p - n.Centre()).norm() > params.node_spacing) return;
    n.ends.push_back(end);
    n.sum += p;
    ++n.points;
    node_of_end[end] = k;
  };
  for (const EndMeeting& m : meetings) {
    const auto a = node_of_end.find(m.a), b = node_of_end.find(m.b);
    if (a == node_of_end.end() && b == node_of_end.end()) {
      nodes.push_back(MeetingNode{{m.a, m.b}, m.p, 1, m.linkable});
      node_of_end[m.a] = node_of_end[m.b] = nodes.size() - 1;
    } else if (b == node_of_end.end()) {
      join(a->second, m.b, m.p);
    } else if (a == node_of_end.end()) {
      join(b->second, m.a, m.p);
    }
  }
  std::vector<MeetingNode> junctions;
  for (MeetingNode& n : nodes) {
    if (n.ends.size() >= params.min_meeting_ends || (n.ends.size() == 2 && n.linkable)) {
      junctions.push_back(std::move(n));
    }
  }
  return junctions;
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
        std::vector<Eigen::Vector3d> arms;
        for (const auto& [chain, at_end] : ends) arms.push_back(-FreeEndOf(chains[chain], at_end).out);
        const double deviation = ShapeDeviation(arms, shape);
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
    ++near->degree;
    Use(j.branch, j.at_end);
    state_.forest.Unite(j.branch, j.host, link);
    state_.out.junctions.push_back(j);
    state_.out.node_of_junction.push_back(static_cast<std::size_t>(near - nodes.begin()));
    return true;
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

// What the completion may still accept: T-pieces and pairs of ends within its wider limits.
struct CompletionCandidates {
  std::vector<Junction> sides;
  std::vector<EndMeeting> pairs;
};

// Y-pieces first (their ends are spoken for), then T-pieces, then end-to-end links, each cheapest
// first and within `max_length` (0 = no limit); then, within `max_completed_length` (0 = none), the
// completion's candidates, cheapest first across both kinds.
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
  std::uint32_t completed_sides = 0, completed_links = 0;
  if (max_completed_length > 0.0) {
    std::size_t s = 0, m = 0;
    const auto& sides = completion.sides;
    const auto& pairs = completion.pairs;
    while (s < sides.size() || m < pairs.size()) {
      ThrowIfStopped(stop, "joining");
      if (m >= pairs.size() || (s < sides.size() && sides[s].reach + sides[s].offset <= pairs[m].cost)) {
        completed_sides +=
            acceptance.Side(sides[s++], max_completed_length, JoinDecision::Kind::kCompletionT) ? 1 : 0;
      } else {
        const EndMeeting& pair = pairs[m++];
        completed_links += acceptance.Meeting(MeetingNode{{pair.a, pair.b}, pair.p, 1, true},
                                              max_completed_length, JoinDecision::Kind::kCompletionLink)
                               ? 1
                               : 0;
      }
    }
  }
  Accepted out = std::move(acceptance).Take();
  out.completed_sides = completed_sides;
  out.completed_links = completed_links;
  return out;
}

// The longest tree joining may build (0 = no limit): max_tube_length, and with the cell's tube
// length known, max_length_share of it.
double MaxTreeLength(const JunctionParams& params, double tube_length) {
  if (!(tube_length > 0.0)) return params.max_tube_length;
  const double share = params.max_length_share * tube_length;
  return params.max_tube_length > 0.0 ? std::min(params.max_tube_length, share) : share;
}

// Sorts longest first and numbers the tubes 0..n−1; rank[t] is the new index of tubes[t].
std::vector<Tube> LongestFirst(std::vector<Tube> tubes, std::vector<std::uint32_t>* rank) {
  std::vector<double> length(tubes.size());
  for (std::size_t t = 0; t < tubes.size(); ++t) length[t] = tubes[t].length();
  std::vector<std::size_t> order(tubes.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return length[a] > length[b]; });
  std::vector<Tube> sorted;
  sorted.reserve(tubes.size());
  rank->assign(tubes.size(), 0);
  for (const std::size_t t : order) {
    (*rank)[t] = static_cast<std::uint32_t>(sorted.size());
    sorted.push_back(std::move(tubes[t]));
    sorted.back().id = static_cast<std::uint32_t>(sorted.size() - 1);
  }
  return sorted;
}

}  // namespace

void JunctionParams::Validate() const {
  RequireNonNegative(max_gap, "modeling.junctions.max_gap");
  RequireNonNegative(max_axis_offset, "modeling.junctions.max_axis_offset");
  RequireNonNegative(side_max_gap, "modeling.junctions.side_max_gap");
  RequireNonNegative(side_max_axis_offset, "modeling.junctions.side_max_axis_offset");
  RequireInRange(min_angle, 0.0, kPi / 2.0, "modeling.junctions.min_angle");
  if (max_branches_per_node < 3) {
    throw InvalidArgument(
        "modeling.junctions.max_branches_per_node: " + std::to_string(max_branches_per_node) +
        " is below 3 (a junction joins at least three branches)");
  }
  if (max_meeting_ends < 3 || max_meeting_ends > max_branches_per_node) {
    throw InvalidArgument(
        "modeling.junctions.max_meeting_ends: " + std::to_string(max_meeting_ends) +
        " is out of range [3, max_branches_per_node = " + std::to_string(max_branches_per_node) + "]");
  }
  if (min_meeting_ends < 2 || min_meeting_ends > max_branches_per_node) {
    throw InvalidArgument(
        "modeling.junctions.min_meeting_ends: " + std::to_string(min_meeting_ends) +
        " is out of range [2, max_branches_per_node = " + std::to_string(max_branches_per_node) + "]");
  }
  RequireInRange(shape_tolerance, 0.0, kPi, "modeling.junctions.shape_tolerance");
  RequireNonNegative(node_spacing, "modeling.junctions.node_spacing");
  RequireNonNegative(max_tube_length, "modeling.junctions.max_tube_length");
  RequirePositive(max_length_share, "modeling.junctions.max_length_share");
  RequireNonNegative(layout_tolerance, "modeling.junctions.layout_tolerance");
  RequireNonNegative(chain_max_distance, "modeling.junctions.chain_max_distance");
  RequireNonNegative(link_max_distance, "modeling.junctions.link_max_distance");
  RequireInRange(link_max_angle, 0.0, kPi, "modeling.junctions.link_max_angle");
  RequireInRange(chain_max_angle, 0.0, kPi, "modeling.junctions.chain_max_angle");
  RequireNonNegative(auto_min_per_tube, "modeling.junctions.auto_min_per_tube");
  end_room.Validate("modeling.junctions.end_room");
  completion.Validate("modeling.junctions.completion");
}

void JunctionCompletionParams::Validate(const char* prefix) const {
  const std::string p(prefix);
  RequirePositive(max_gap, p + ".max_gap");
  RequirePositive(max_axis_offset, p + ".max_axis_offset");
  RequirePositive(max_length_share, p + ".max_length_share");
}

std::string ToString(JoinDecision::Kind kind) {
  switch (kind) {
    case JoinDecision::Kind::kYPiece:
      return "y_piece";
    case JoinDecision::Kind::kTPiece:
      return "t_piece";
    case JoinDecision::Kind::kLink:
      return "link";
    case JoinDecision::Kind::kCompletionT:
      return "completion_t";
    case JoinDecision::Kind::kCompletionLink:
      return "completion_link";
  }
  return "?";
}

bool FitsJunctionLayout(const Tube& tree, const JunctionLayout& layout, double tolerance) {
  if (!tree.branched() || !layout.known()) return true;
  const std::vector<std::uint32_t> degree = NodeDegrees(tree);
  const std::vector<double> length = BranchLengths(tree);
  std::uint32_t junctions = 0, hidden = 0;
  for (const std::uint32_t d : degree) junctions += d >= 3 ? 1 : 0;
  for (std::size_t b = 0; b < tree.branches.size(); ++b) {
    const bool from = degree[tree.branches[b].from_node] >= 3, to = degree[tree.branches[b].to_node] >= 3;
    if (from && to) {
      if (layout.junction_spacing > 0.0 && std::abs(length[b] - layout.junction_spacing) > tolerance)
        return false;
    } else if ((from || to) && layout.branch_length > 0.0 && length[b] > layout.branch_length + tolerance) {
      ++hidden;  // the run goes on through a junction the scan does not show
    }
  }
  return layout.junctions == 0 || junctions + hidden <= layout.junctions;
}

double ReachOf(const EndRoom& room, double nominal) { return std::min(nominal + room.unfitted, room.free); }

std::vector<Junction> FindJunctions(const std::vector<Tube>& chains, const JunctionParams& params,
                                    JunctionShape shape, const EndRooms& rooms) {
  params.Validate();
  const double cos_min = std::cos(params.min_angle);
  std::vector<Junction> out;
  std::vector<std::vector<AxisPiece>> pieces(chains.size());
  std::vector<double> arc_length(chains.size());
  for (std::size_t h = 0; h < chains.size(); ++h) {
    pieces[h] = TubeAxisPieces(chains[h]);
    arc_length[h] = ArcLength(pieces[h]);
  }
  for (std::uint32_t b = 0; b < chains.size(); ++b) {
    if (chains[b].cylinders.empty() || chains[b].branched()) continue;
    for (const bool at_end : {false, true}) {
      const FreeEnd end = FreeEndOf(chains[b], at_end);
      std::optional<Junction> best_overall;
      for (std::uint32_t h = 0; h < chains.size(); ++h) {
        if (h == b || chains[h].branched()) continue;
        std::optional<Junction> best;
        for (std::size_t k = 0; k < pieces[h].size(); ++k) {
          const AxisPiece& piece = pieces[h][k];
          const Eigen::Vector3d axis = piece.b - piece.a;
          if (!(axis.norm() > 0.0)) continue;
          if (std::abs(end.out.dot(axis.normalized())) > cos_min) continue;
          const double reach = RoomReach(rooms, b, at_end, piece.radius + params.side_max_gap);
          const SegmentClosestPoints cp =
              ClosestPointsOfSegments(end.p, end.p + reach * end.out, piece.a, piece.b);
          if (cp.distance > params.side_max_axis_offset) continue;
          const double position = static_cast<double>(k) + cp.t;
          const double arc = ArcAt(pieces[h], position);
          if (arc < params.node_spacing || arc_length[h] - arc < params.node_spacing) continue;
          Junction j{b, at_end, h, position, arc, piece.a + cp.t * axis, cp.s * reach, cp.distance};
          if (shape != JunctionShape::kAny) {
            const std::vector<Eigen::Vector3d> arms = {-end.out,
                                                       PointAtArc(pieces[h], arc - kRunArmProbe) - j.p_Bin,
                                                       PointAtArc(pieces[h], arc + kRunArmProbe) - j.p_Bin};
            if (ShapeDeviation(arms, shape) > params.shape_tolerance) continue;
          }
          if (!best || j.reach + j.offset < best->reach + best->offset) best = j;
        }
        if (best) out.push_back(*best);
      }
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const Junction& x, const Junction& y) {
    return std::make_tuple(x.reach + x.offset, x.branch, x.at_end, x.host) <
           std::make_tuple(y.reach + y.offset, y.branch, y.at_end, y.host);
  });
  return out;
}

namespace {

// JoinJunctions with its trees bounded by `max_tree_length` (0 = no limit).
JunctionJoining JoinJunctionsWithin(const std::vector<Tube>& chains, const JunctionParams& params,
                                    JunctionShape shape, const StopToken* stop, const EndRooms& rooms,
                                    double tube_length, double max_tree_length,
                                    const JunctionLayout& layout) {
  params.Validate();
  ThrowIfStopped(stop, "joining");
  CompletionCandidates completion;
  const double max_completed_length =
      params.completion.enabled && tube_length > 0.0 ? params.completion.max_length_share * tube_length : 0.0;
  if (max_completed_length > 0.0) {
    JunctionParams wide = params;
    wide.max_gap = wide.side_max_gap = params.completion.max_gap;
    wide.max_axis_offset = wide.side_max_axis_offset = params.completion.max_axis_offset;
    completion.sides = FindJunctions(chains, wide, shape, rooms);
    completion.pairs = FindEndMeetings(chains, wide, rooms);
  }
  const Accepted accepted = Accept(chains, ClusterMeetings(FindEndMeetings(chains, params, rooms), params),
                                   FindJunctions(chains, params, shape, rooms), completion, max_tree_length,
                                   max_completed_length, params, shape, layout, stop);
  JunctionJoining out;
  out.y_pieces =
      static_cast<std::uint32_t>(std::count_if(accepted.meetings.begin(), accepted.meetings.end(),
                                               [](const MeetingNode& n) { return n.ends.size() >= 3; }));
  out.junctions =
      static_cast<std::uint32_t>(accepted.junctions.size()) - accepted.completed_sides + out.y_pieces;
  out.completions = accepted.completed_sides + accepted.completed_links;
  out.decisions = accepted.decisions;

  // Components (by the smallest chain index in them), in order of that index.
  std::vector<std::uint32_t> component(chains.size());
  std::iota(component.begin(), component.end(), 0);
  bool changed = true;
  while (changed) {  // a handful of junctions: simple relaxation is enough
    changed = false;
    auto link = [&](std::uint32_t a, std::uint32_t b) {
      const std::uint32_t m = std::min(component[a], component[b]);
      if (component[a] != m || component[b] != m) {
        component[a] = component[b] = m;
        changed = true;
      }
    };
    for (const Junction& j : accepted.junctions) link(j.branch, j.host);
    for (const MeetingNode& n : accepted.meetings) {
      for (const auto& end : n.ends) link(n.ends.front().first, end.first);
    }
  }
  std::map<std::uint32_t, std::vector<std::uint32_t>> members;
  for (std::uint32_t c = 0; c < chains.size(); ++c) members[component[c]].push_back(c);
  std::vector<Tube> tubes;
  std::vector<std::uint32_t> built_from(chains.size());
  TreeBuilder builder(chains, accepted);
  for (const auto& [root, list] : members) {
    for (const std::uint32_t c : list) built_from[c] = static_cast<std::uint32_t>(tubes.size());
    if (list.size() > 1) out.chains_in_junctions += static_cast<std::uint32_t>(list.size());
    tubes.push_back(list.size() == 1 ? chains[list.front()] : builder.Build(list));
  }
  std::vector<std::uint32_t> rank;
  out.tubes = LongestFirst(std::move(tubes), &rank);
  out.tube_of_chain.resize(chains.size());
  for (std::size_t c = 0; c < chains.size(); ++c) out.tube_of_chain[c] = rank[built_from[c]];
  return out;
}

}  // namespace

JunctionJoining JoinJunctions(const std::vector<Tube>& chains, const JunctionParams& params,
                              JunctionShape shape, const StopToken* stop, const EndRooms& rooms,
                              double tube_length, const JunctionLayout& layout) {
  return JoinJunctionsWithin(chains, params, shape, stop, rooms, tube_length,
                             MaxTreeLength(params, tube_length), layout);
}

JunctionJoining JoinJunctionsOfLength(const std::vector<Tube>& chains, const JunctionParams& params,
                                      JunctionShape shape, const StopToken* stop, const EndRooms& rooms,
                                      double tube_length, std::optional<double>* scan_length,
                                      const JunctionLayout& layout) {
  if (scan_length != nullptr) scan_length->reset();
  if (!(tube_length > 0.0)) return JoinJunctions(chains, params, shape, stop, rooms, tube_length, layout);
  // The trees within max_tube_length alone: how long are the ones seen about whole? Four of them
  // at least: in a bin of two or three trees one merge can be the median (a 3-tree bin of set C).
  constexpr std::size_t kMinWholeTrees = 4;
  const double whole = WholeTubeLength(
      JoinJunctionsWithin(chains, params, shape, stop, rooms, tube_length, params.max_tube_length, layout)
          .tubes,
      tube_length, kMinWholeTrees);
  if (whole <= MaxTreeLength(params, tube_length)) {
    return JoinJunctions(chains, params, shape, stop, rooms, tube_length, layout);
  }
  if (scan_length != nullptr) *scan_length = whole;
  return JoinJunctions(chains, params, shape, stop, rooms, whole, layout);
}

bool LooksBranched(const JunctionJoining& joined, const JunctionParams& params) {
  return joined.y_pieces >= params.auto_min_y_pieces ||
         (joined.junctions >= params.auto_min_junctions &&
          static_cast<double>(joined.junctions) >=
              params.auto_min_per_tube * static_cast<double>(joined.tubes.size()));
}

}  // namespace tubepick
