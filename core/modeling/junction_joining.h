#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/common/cell_config.h"
#include "core/common/stop_token.h"
#include "core/common/types.h"
#include "core/modeling/end_room.h"

namespace tubepick {

/// Completion: after the Y-pieces, T-pieces and links, the free ends still unused are tried again
/// within wider limits, but only where the tree they make stays within the cell's tube length
/// (tube.length; 0 = unknown: no completion). A branch whose end lies 6–11 cm from its node (the
/// saddle unfitted, the fitting under another tube) or whose extended axis misses the other's by
/// up to 2 cm (a bent branch fitted straight) then still joins its tree, while a tree that is
/// already whole cannot take a stranger's fragment. On generated set-C bins, 60.5 → 65.0 %
/// correct (docs/ACCURACY.md). A pair of ends of which one is already at a node (a Y-piece, a link
/// or a T-node) joins the other end to that node as one more branch, within
/// max_branches_per_node: the third branch of a Y whose two others were linked, a branch whose
/// end the Y-piece's reach just missed. On generated set-C bins 69.0 → 74.0 % correct (one pure
/// ≥ 80 %: 151 → 160 of 200; docs/ACCURACY.md).
struct JunctionCompletionParams {
  bool enabled = true;
  /// As JunctionParams::max_gap and side_max_gap, for completion, metres. 0.10 rather than 0.08
  /// (with facing_offset_mean) bridges a trunk hidden for 9-11 cm under another tube; on generated
  /// set-C bins, one pure virtual tree ≥ 80 % of 200: seed 0 192 → 192, seed 500 172 → 177, seed
  /// 2000 176 → 177, seed 3000 174 → 174; set CY 174 → 176 (docs/ACCURACY.md).
  double max_gap = 0.10;
  /// As JunctionParams::max_axis_offset and side_max_axis_offset, for completion, metres.
  double max_axis_offset = 0.02;
  /// Two free ends facing each other across a gap: their offset is the mean of each end's
  /// distance from the other's axis (a bend in the hidden part shared between the two ends, and
  /// the same whichever chain comes first) rather than the second end's distance from the first
  /// one's axis (the nodes and links before the completion).
  bool facing_offset_mean = true;
  /// A completion makes no tree longer than this share of the cell's tube length.
  double max_length_share = 1.0;

  /// @throws InvalidArgument naming "<prefix>.<key>" and the value.
  void Validate(const char* prefix) const;
};

/// Junction joining: where free ends of chains meet each other (a Y-piece: every branch ends at
/// the node) or another chain's side (a T-piece: the run goes on through the node).
struct JunctionParams {
  /// Y-pieces: how far each free end's axis is extended to meet the others: its radius plus this,
  /// metres.
  double max_gap = 0.05;
  /// Y-pieces: largest distance between two extended axes where they meet, metres.
  double max_axis_offset = 0.016;
  /// T-pieces: longest gap from a chain's free end, along its axis, to the surface of the tube
  /// it meets, metres (the other tube's radius is added to reach its axis).
  double side_max_gap = 0.04;
  /// T-pieces: largest distance between the end's extended axis and the other tube's axis, metres:
  /// a branch points at the axis it leaves; a tube lying across another does not (its axis
  /// passes two radii above).
  double side_max_axis_offset = 0.016;
  /// Smallest angle between the branch's axis and the other tube's axis, radians: nearly
  /// parallel ends are the linear joining's business.
  double min_angle = 25.0 * 3.14159265358979323846 / 180.0;
  /// Fewest free ends meeting at one point that make a node there (a Y-piece has 3; 2 also
  /// accepts a Y-piece whose third branch is hidden, as a kinked link).
  std::uint32_t min_meeting_ends = 3;
  /// Most branches meeting at one node (3 = T- and Y-pieces only). A junction shape other than
  /// `any` allows three.
  std::uint32_t max_branches_per_node = 4;
  /// Junction shape `any`: most free ends one Y-node may take. Where more meet (up to
  /// max_branches_per_node are gathered), which of them belong together cannot be told, so none
  /// makes a node: the ends are left to the T-pieces, links and the completion. On generated
  /// set-C bins every 4-end node was wrong (5 of 5); 3 took them from 65.0 to 65.5 % correct
  /// (other seeds 56.5 → 57.5 %, set CY with `any` 59.0 → 60.5 %, docs/ACCURACY.md). 4 accepts
  /// X-pieces. A shape other than `any` keeps the three ends that fit it best instead.
  std::uint32_t max_meeting_ends = 3;
  /// A junction shape other than `any` (tube.junction_shape): largest difference between an
  /// angle between two of the junction's arms and the shape's, radians. The arms are the
  /// branches' axes at the node; a run cut at a T-junction gives two, each from the node to the
  /// run's axis 3 cm away (a run fitted straight through a Y-piece's bend still shows the bend).
  /// On generated set-CY bins (Y-pieces), with the shape-blind joining, the arms of 95 % of the
  /// right junctions were within 40° of 120° and those of 31 of 32 chance ones (a tube's end
  /// against another's side) 40° or more off; 55° gave the most correct tubes (docs/ACCURACY.md).
  double shape_tolerance = 55.0 * 3.14159265358979323846 / 180.0;
  /// A junction closer than this to the other chain's free end is not one (that would be an end
  /// to end join), and junctions closer than this on one chain become one node, metres (as do
  /// junctions with no cylinder between them: both on one joint of the chain).
  double node_spacing = 0.02;
  /// Where junctions are looked for, the linear joining before them is held to these limits
  /// (modeling.joining's own when smaller): joining arms end to end across a Y-piece (a 60°
  /// kink) or across a junction blob would take the ends the junction needs. Metres, radians.
  double chain_max_distance = 0.06;
  double chain_max_angle = 1.0;
  /// Two free ends that meet with no third end (kinked past chain_max_angle, or across a gap the
  /// linear joining found visible: at a junction the gap holds the junction's own surface) are
  /// linked end to end, after the junctions, within these limits (α + β as the linear joining).
  /// Their axes must meet (max_axis_offset), so the angle may be wide: a Y-piece whose third
  /// branch is hidden kinks its two visible arms by anything up to 180° less the angle between
  /// them (set C: branches leave at random). 150° rather than 90° took generated set-C bins from
  /// 54.0 % to 60.5 % correct: the links accepted rose from 34 to 64, the wrong ones stayed at 3
  /// (docs/ACCURACY.md).
  double link_max_distance = 0.08;
  double link_max_angle = 150.0 * 3.14159265358979323846 / 180.0;
  /// Longest tube (cylinders, joints and junction links) joining may build, metres; 0 = no limit.
  double max_tube_length = 0.80;
  /// With the cell's tube length known (tube.length > 0), no tree longer than this share of it
  /// either: a tree a few centimetres longer than one part holds a stranger's fragment, and the
  /// fitted axes of a whole tree come out within about 3 % of its curve length. On generated
  /// set-C bins (0.75 m trees) 1.04 took correct tubes from 65.5 to 67.0 % (one pure ≥ 80 %:
  /// 70.5 → 72.5 %), other seeds and 14 trees a little, set CY with `any` 60.5 → 63.0 %
  /// (docs/ACCURACY.md); 1.07 (the 0.80 m of max_tube_length) is where it was.
  double max_length_share = 1.04;
  /// With the part's junction layout known (tube.junctions, junction_spacing, branch_length):
  /// how far a run may differ from the drawing's, metres (FitsJunctionLayout). On generated set-C
  /// bins the runs between the two junctions of the pure trees measured 0.27–0.34 m against the
  /// drawing's 0.30, those of trees mixing two parts 0.09–0.42 m; the layout took correct trees
  /// from 67.0 to 69.0 % (other seeds 58.0 → 61.5 %), and 0.03–0.08 gave the same within a tree
  /// or two (docs/ACCURACY.md).
  double layout_tolerance = 0.04;
  /// `auto` topology: a scene counts as branched when at least this many junctions are found ...
  std::uint32_t auto_min_junctions = 3;
  /// ... and at least this many per tube they leave: a bin of linear tubes shows a few chance
  /// junctions (about 0–0.35 per tube on generated 10-tube bins of sets A and B, more in dense
  /// 20-tube bins of set B, where 0.45 took bins for branched), a bin of set C tubes (two junctions
  /// each) 0.5–1.1 (docs/ACCURACY.md).
  double auto_min_per_tube = 0.7;
  /// ... or when at least this many of the junctions are Y-pieces (three free ends meeting at a
  /// point: 0–2 in those linear bins, 2–12 in the branched ones, 4–6 with 20 tubes).
  std::uint32_t auto_min_y_pieces = 3;
  /// The room past each free end (MeasureEndRooms), for Y-pieces and T-pieces alike: unfitted
  /// surface past it (the junction's own saddle, a branch's last centimetres) lengthens its reach
  /// by as much; free space (the scanner saw past where the branch would go on) shortens it.
  EndRoomParams end_room;
  JunctionCompletionParams completion;

  /// @throws InvalidArgument naming "modeling.junctions.<key>" and the value.
  void Validate() const;
};

/// One junction found: chain `branch`'s free end (`at_end`: its last cylinder's end, else its
/// first cylinder's start) meets chain `host`'s axis at `p_Bin`.
struct Junction {
  std::uint32_t branch = 0;
  bool at_end = false;
  std::uint32_t host = 0;
  /// Position along the host chain's axis pieces (TubeAxisPieces): piece index + fraction.
  double host_position = 0.0;
  /// The same as arc length along the host's axis from its first end, metres.
  double host_arc = 0.0;
  Eigen::Vector3d p_Bin = Eigen::Vector3d::Zero();
  /// Distance along the branch's axis from its end to p_Bin, metres.
  double reach = 0.0;
  /// Distance between the extended branch axis and the host axis, metres.
  double offset = 0.0;
};

/// Candidate junctions of linear `chains` (JoinTubes' output), cheapest first (reach + offset),
/// each within the limits of `params` on its own, each end's reach set by `rooms` (empty: the
/// nominal reach; see ReachOf). With a junction shape other than `any`, only junctions whose arms
/// fit it (shape_tolerance).
std::vector<Junction> FindJunctions(const std::vector<Tube>& chains, const JunctionParams& params,
                                    JunctionShape shape = JunctionShape::kAny, const EndRooms& rooms = {});

/// Whether a tree can be one part of `layout` (JunctionLayout; an unknown field checks nothing):
/// every branch between two junctions (nodes of three or more branches) is junction_spacing long
/// within `tolerance`, and the junctions it shows plus one hidden past each branch from a junction
/// to a free end longer than branch_length + `tolerance` (its run goes on through a junction the
/// scan does not show) are no more than the part's. A linear tube always fits.
bool FitsJunctionLayout(const Tube& tree, const JunctionLayout& layout, double tolerance);

/// A free end's reach given its nominal reach (its radius plus max_gap or side_max_gap): longer
/// by the unfitted surface past it, never past the free space ahead of it.
double ReachOf(const EndRoom& room, double nominal);

/// What junction joining made of a scene's chains.
/// One decision of junction joining: which input chains a node or link joined, and whether it
/// stayed. For auditing the joining against ground truth (tubepick eval, AuditJoins): the
/// candidates a limit turned away before they made a tree are not decisions.
struct JoinDecision {
  /// kCompletionNode: a free end joined to the node where a completion pair's other end already
  /// is (a Y-piece's or link's meeting, or a T-node), as one more branch.
  enum class Kind { kYPiece, kTPiece, kLink, kCompletionT, kCompletionLink, kCompletionNode };
  /// How many kinds there are (Kind's values are 0 .. kKinds − 1).
  static constexpr std::size_t kKinds = 6;
  Kind kind = Kind::kYPiece;
  /// False: taken back because the tree it made does not fit the part's junction layout.
  bool accepted = true;
  /// The chains it joins (indices into JoinJunctions' `chains`); a T-piece's branch, then its host.
  std::vector<std::uint32_t> chains;
};

/// "y_piece", "t_piece", "link", "completion_t", "completion_link", "completion_node".
std::string ToString(JoinDecision::Kind kind);

struct JunctionJoining {
  /// Tube ids 0..n−1, longest tube first.
  std::vector<Tube> tubes;
  /// Per input chain: the index of the output tube that holds it.
  std::vector<std::uint32_t> tube_of_chain;
  /// Junctions accepted (Y-pieces and T-pieces).
  std::uint32_t junctions = 0;
  /// Of them, Y-pieces (three or more free ends meeting).
  std::uint32_t y_pieces = 0;
  /// Chains that take part in a junction.
  std::uint32_t chains_in_junctions = 0;
  /// Junctions and links accepted by the completion (JunctionCompletionParams); not counted in
  /// `junctions` nor `y_pieces`, so they never make a scene look branched.
  std::uint32_t completions = 0;
  /// Every node and link accepted, and every one the layout took back, in the order decided.
  std::vector<JoinDecision> decisions;
};

/// Joins linear chains (JoinTubes' output) into trees: nodes where three or more free ends meet
/// (Y-pieces, ClusterMeetings) first, then free ends meeting another chain's side (T-pieces),
/// cheapest first, while each keeps every tube a tree (no cycle), uses each free end once, gives
/// no node more than max_branches_per_node branches and keeps the tube within max_tube_length
/// and max_length_share of `tube_length`.
/// A host chain is cut at each T-junction on it (the cylinder under it is split at the
/// junction's foot); every branch end is linked to its node by a joint (TubeJoints). Tubes
/// without a junction are returned as they came (linear, implicit graph). With a junction shape
/// other than `any`, every node has three arms whose angles fit the shape. Deterministic.
/// @throws InvalidArgument for invalid parameters. @throws Cancelled when `stop` fires.
/// `rooms` (MeasureEndRooms of `chains`; empty = none) sets each free end's reach (ReachOf).
/// `tube_length` (the cell's tube.length, metres; 0 = unknown) bounds every tree
/// (max_length_share) and the completion (JunctionCompletionParams::max_length_share); every tree
/// fits `layout` (FitsJunctionLayout within layout_tolerance).
JunctionJoining JoinJunctions(const std::vector<Tube>& chains, const JunctionParams& params,
                              JunctionShape shape = JunctionShape::kAny, const StopToken* stop = nullptr,
                              const EndRooms& rooms = {}, double tube_length = 0.0,
                              const JunctionLayout& layout = {});

/// JoinJunctions for a cell whose tubes are `tube_length` long (0 = unknown), unless the trees
/// the scan shows about whole (joined within max_tube_length alone, WholeTubeLength) are longer
/// than the tree bound of that length: then as if the tubes were that long, and `scan_length`
/// (optional) receives that length (else nullopt) for the caller to say so.
JunctionJoining JoinJunctionsOfLength(const std::vector<Tube>& chains, const JunctionParams& params,
                                      JunctionShape shape, const StopToken* stop, const EndRooms& rooms,
                                      double tube_length, std::optional<double>* scan_length = nullptr,
                                      const JunctionLayout& layout = {});

/// Topology `auto`: whether a scene shows branched tubes (at least auto_min_junctions junctions
/// and auto_min_per_tube per tube joining left, or at least auto_min_y_pieces Y-pieces).
bool LooksBranched(const JunctionJoining& joined, const JunctionParams& params);

}  // namespace tubepick
