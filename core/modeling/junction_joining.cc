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
// used once, no node exceeds max_branches_per_node and no tube max_tube_length (Acceptance, with
// the trees it builds, in junction_acceptance.cc).

#include "core/modeling/junction_joining.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <tuple>

#include "core/common/errors.h"
#include "core/common/require.h"
#include "core/common/segment_geometry.h"
#include "core/common/tube_graph.h"
#include "core/modeling/junction_acceptance.h"
#include "core/modeling/tube_joining.h"

namespace tubepick {
namespace {

using junction_internal::Accept;
using junction_internal::Accepted;
using junction_internal::BuildTree;
using junction_internal::CompletionCandidates;
using junction_internal::EndMeeting;
using junction_internal::MeetingNode;
using junction_internal::ShapeDeviation;

constexpr double kPi = 3.14159265358979323846;

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

// Where the arms of a T-junction's run are measured: this far from the node along the run.
constexpr double kRunArmProbe = 0.03;

// The reach of a chain's free end (ReachOf), nominal without rooms.
double RoomReach(const EndRooms& rooms, std::uint32_t chain, bool at_end, double nominal) {
  return chain < rooms.size() ? ReachOf(rooms[chain][at_end ? 1 : 0], nominal) : nominal;
}

// Pairs of free ends of different chains whose axes, each extended by at most its radius plus
// max_gap, pass within max_axis_offset of each other at an angle of at least min_angle, or that
// face each other along one line within that reach (a run broken at a T-piece's node; alone,
// such a pair is the linear joining's business, so only a third end makes it a node). Ends
// pointing the same way side by side never meet. Cheapest first. A facing pair's offset is the
// second end's distance from the first end's axis, or with `facing_offset_mean` the mean of each
// end's distance from the other's axis (JunctionCompletionParams::facing_offset_mean).
std::vector<EndMeeting> FindEndMeetings(const std::vector<Tube>& chains, const JunctionParams& params,
                                        const EndRooms& rooms, bool facing_offset_mean = false) {
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
        const double off_x = (gap - along * x.end.out).norm();
        const double off_y = (gap + gap.dot(-y.end.out) * y.end.out).norm();
        const double offset = facing_offset_mean ? 0.5 * (off_x + off_y) : off_x;
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

static_assert(static_cast<std::size_t>(JoinDecision::Kind::kCompletionNode) + 1 == JoinDecision::kKinds);

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
    case JoinDecision::Kind::kCompletionNode:
      return "completion_node";
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
    completion.pairs = FindEndMeetings(chains, wide, rooms, params.completion.facing_offset_mean);
  }
  Accepted accepted = Accept(chains, ClusterMeetings(FindEndMeetings(chains, params, rooms), params),
                             FindJunctions(chains, params, shape, rooms), completion, max_tree_length,
                             max_completed_length, params, shape, layout, stop);
  JunctionJoining out;
  for (const JoinDecision& d : accepted.decisions) {
    if (!d.accepted) continue;
    switch (d.kind) {
      case JoinDecision::Kind::kYPiece:
        ++out.y_pieces;
        ++out.junctions;
        break;
      case JoinDecision::Kind::kTPiece:
        ++out.junctions;
        break;
      case JoinDecision::Kind::kLink:
        break;
      case JoinDecision::Kind::kCompletionT:
      case JoinDecision::Kind::kCompletionLink:
      case JoinDecision::Kind::kCompletionNode:
        ++out.completions;
        break;
    }
  }
  out.decisions = std::move(accepted.decisions);

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
  for (const auto& [root, list] : members) {
    for (const std::uint32_t c : list) built_from[c] = static_cast<std::uint32_t>(tubes.size());
    if (list.size() > 1) out.chains_in_junctions += static_cast<std::uint32_t>(list.size());
    tubes.push_back(list.size() == 1 ? chains[list.front()] : BuildTree(chains, accepted, list));
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
