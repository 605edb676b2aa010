#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "core/common/cell_config.h"
#include "physics/tube_geometry.h"

namespace tubepick::physics {

/// How tubes fall into the bin (thesis §4.5.1, with Bullet instead of ODE).
///
/// Drop strategy: one tube after another, as in §4.5.1. Each tube gets a uniformly random
/// orientation, redrawn until its bounding box fits the bin's footprint (inset by
/// `spawn_margin`) and is at most `max_spawn_height` tall, so it cannot topple over a wall; a
/// uniformly random xy inside the footprint; and a height that puts its lowest point
/// `drop_clearance` above the highest point of the floor and of every tube already in the world
/// (heights are staggered, spawns never overlap, and early tubes start inside the walls). The next
/// tube is spawned `spawn_interval` later or, with `wait_for_rest` (the thesis' procedure), once
/// every tube present is at rest. After the last spawn the world runs until every tube has stayed
/// below the rest velocities for `settle_time`, or `max_time` passes.
///
/// Bullet combines the contact parameters of two bodies: friction and restitution multiply,
/// rolling friction is r₀·μ₁ + r₁·μ₀ (a lever arm, metres). The bin has no rolling friction.
struct DropParams {
  /// Bin wall and floor thickness, metres (see BinSolids).
  double wall_thickness = 0.01;
  /// Mass of one tube, kg (CellConfig tube.mass).
  double tube_mass = 0.055;
  /// Friction coefficients of tubes and of the bin/ground.
  double tube_friction = 0.7;
  double bin_friction = 0.7;
  /// Rolling friction of tubes, metres (see above); damps rolling on the floor.
  double tube_rolling_friction = 0.001;
  /// Restitution of tubes and of the bin.
  double tube_restitution = 0.2;
  double bin_restitution = 0.5;
  /// Velocity damping of tubes (fraction lost per second).
  double linear_damping = 0.05;
  double angular_damping = 0.2;
  /// Fixed simulation step, seconds; one Bullet step per call.
  double time_step = 1.0 / 240.0;
  /// Sequential-impulse solver iterations per step.
  int solver_iterations = 15;
  /// Collision margin of the tube and bin shapes, metres (Bullet's default 4 cm is larger than a
  /// tube's radius).
  double collision_margin = 0.001;
  /// Seconds between two spawns (ignored with wait_for_rest).
  double spawn_interval = 0.3;
  /// Spawn the next tube only when every tube present is at rest (capped by max_time).
  bool wait_for_rest = false;
  /// Gap between a spawned tube's lowest point and the highest floor / tube point, metres.
  double drop_clearance = 0.03;
  /// Inset of the spawn footprint from the inner walls, metres.
  double spawn_margin = 0.01;
  /// Largest vertical extent of a tube's bounding box at spawn, metres.
  double max_spawn_height = 0.10;
  /// A tube is at rest when |v| < linear and |ω| < angular rest velocity (m/s, rad/s).
  double linear_rest_velocity = 0.005;
  double angular_rest_velocity = 0.05;
  /// How long every tube must stay at rest, seconds.
  double settle_time = 0.5;
  /// Bullet deactivation: a group of touching tubes that all stay below these velocities for 2 s
  /// is put to sleep (frozen until something hits it). This stops the solver's slow creep of
  /// stacked tubes that would otherwise, seconds later, let a balanced tube slide off. 0 disables.
  double sleep_linear_velocity = 0.02;
  double sleep_angular_velocity = 0.2;
  /// Give up waiting for rest this long after the last spawn, seconds (DropResult::settled is then
  /// false). With wait_for_rest, also the longest wait before the next spawn.
  double max_time = 20.0;

  /// @throws InvalidArgument naming the first bad field and its value.
  void Validate() const;
};

struct DropResult {
  /// The tubes in their settled poses, Bin frame (same ids and order as the input).
  std::vector<TubeGeometry> tubes;
  /// Final pose of each input tube's frame in the bin frame: tubes[i] = input[i] moved by X_BinTube[i].
  std::vector<Eigen::Isometry3d> X_BinTube;
  /// Per tube: every node centre inside the inner footprint (|x| ≤ length/2, |y| ≤ width/2) and
  /// z ≥ 0 — false for a tube that leans over a wall or fell out.
  std::vector<bool> inside_bin;
  /// Every tube was at rest for settle_time before max_time.
  bool settled = false;
  /// Simulated seconds and Bullet steps taken.
  double simulated_time = 0.0;
  int steps = 0;
};

/// Drops `tubes` (each in its own frame, e.g. from GenerateRandomTubes) into the bin and lets them
/// settle. Single-threaded; the same inputs and seed give bitwise the same result.
/// @throws InvalidArgument for invalid params, an invalid bin or a tube without edges.
DropResult DropTubes(const std::vector<TubeGeometry>& tubes, const BinConfig& bin, const DropParams& params,
                     std::uint64_t seed);

}  // namespace tubepick::physics
