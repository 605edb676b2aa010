#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/common/types.h"
#include "core/modeling/range_image.h"

namespace tubepick {

/// What the cloud says about the room past a chain's free end, for junction joining.
///
/// At a junction of a hose assembly the surface turns (a saddle), so region growing and the
/// cylinder fit often leave the last centimetres of a branch before its node unfitted: the
/// points are there, the cylinders stop short. And a branch that is hidden under another tube
/// may go on under it, but not where the scanner saw through the place it would take.
struct EndRoomParams {
  /// Longest unfitted surface counted past an end, metres; 0 = not measured.
  double max_unfitted = 0.08;
  /// An unfitted point within this of the free end's centre starts that surface, metres.
  double attach_distance = 0.02;
  /// Unfitted points are binned into cells of this size; touching cells are one surface, metres.
  double link_distance = 0.012;
  /// The surface is followed within the tube's radius plus this of the end's extended axis,
  /// metres (a bend of 20° over 8 cm moves the surface about 3 cm off the line).
  double corridor = 0.015;
  /// Free space: a free end reaches no further along its axis than the scanner could have missed
  /// the tube there (false: no limit).
  bool free_space_check = true;
  /// Free space: the axis is probed every this many metres ...
  double free_space_step = 0.005;
  /// ... and is free where no surface within free_space_window pixels of the range image lies
  /// closer to the sensor than the axis point plus this, metres (the tube's own top surface is a
  /// radius closer; what hides it is closer still).
  double free_space_tolerance = 0.005;
  std::uint32_t free_space_window = 2;

  /// @throws InvalidArgument naming "<prefix>.<key>" and the value.
  void Validate(const char* prefix) const;
};

/// A linear chain's free end: its centre, the outward direction of its axis and its radius.
struct FreeEnd {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

/// `at_end`: the last cylinder's end, else the first cylinder's start. @pre non-empty chain.
FreeEnd FreeEndOf(const Tube& chain, bool at_end);

/// The room past one free end, metres along its outward axis.
struct EndRoom {
  /// Unfitted surface connected to the end goes on this far.
  double unfitted = 0.0;
  /// The scanner saw nothing in front of the axis (free space) this far out; infinite when not
  /// checked.
  double free = std::numeric_limits<double>::infinity();
};

/// Per chain, per end ([0]: its first cylinder's start, [1]: its last cylinder's end).
using EndRooms = std::vector<std::array<EndRoom, 2>>;

/// The room past every free end of linear `chains` (branched chains get the defaults):
/// `unfitted` points (cloud points no cylinder took) reached from the end over touching cells of
/// link_distance within the corridor, at most max_unfitted; and, with `seen` (the range image of
/// the filtered cloud) and free_space_check, the first probe along the axis where the scanner
/// saw through (up to 0.2 m, beyond any reach). Deterministic.
/// @throws InvalidArgument for invalid parameters.
EndRooms MeasureEndRooms(const Points& unfitted, const std::vector<Tube>& chains, const EndRoomParams& params,
                         const RangeImage* seen);

}  // namespace tubepick
