#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/common/cell_config.h"
#include "core/common/stop_token.h"
#include "core/common/types.h"
#include "core/planning/trajectory.h"
#include "physics/tube_bodies.h"

namespace tubepick::physics {

/// How trajectories are simulated (thesis §5.2.3.2, with Bullet instead of Gazebo/ODE).
///
/// The tubes become Bullet bodies (MakeTubeSegments, MakeTubeShape), settle once under gravity in
/// the bin, and that settled snapshot is the start of every trajectory: a fresh world per
/// trajectory, every tube at its settled pose, at rest and asleep. The grasped tube is a kinematic
/// body (infinite mass) driven along the waypoints at `gripper_speed`: Bullet derives its velocity
/// from its poses, so contacts see its motion and it pushes and lifts the other tubes (no
/// clipping), and no contact can push it off its path (no deflection): the two failures of §5.4.1.
/// After the motion it is held at the last waypoint for `post_motion_time`, so tubes it dragged up
/// and dropped are measured where they land. The cost is the sum of the other tubes'
/// centre-of-mass displacements from the snapshot.
///
/// Noise floor: a tube wakes when something touches it, and Bullet then wakes every tube whose
/// bounding box overlaps an awake one, i.e. usually the whole pile. A woken pile creeps (see
/// solver_iterations): lifting a 10-tube pile's top tube costs 1–5 cm in total where the true
/// answer is 0. Tubes nothing reaches stay asleep and add exactly 0.
///
/// Contact parameters combine as in DropParams: friction and restitution multiply, rolling friction
/// is r₀·μ₁ + r₁·μ₀; the bin has no rolling friction.
struct TrajectorySimParams {
  /// Speed of the grasped tube along the waypoints, m/s (a cobot's careful lift).
  double gripper_speed = 0.1;
  /// Fixed simulation step, seconds. At 0.1 m/s the grasped tube moves 0.8 mm per step, well
  /// under a tube radius; a falling tube is caught by continuous collision. 1/240 s halves the
  /// speed for no measurable gain in the tests' properties.
  double time_step = 1.0 / 120.0;
  /// Sequential-impulse solver iterations per step. A woken pile creeps by a few mm/s in total
  /// (the solver's unconverged friction); 20 iterations about halve that creep for about 25 % more
  /// time, 100 remove it for 3× the time.
  int solver_iterations = 10;
  /// Longest settling under gravity before the snapshot, seconds.
  double settle_time = 2.0;
  /// Settling ends early once every tube has stayed below the rest velocities this long, seconds.
  double rest_time = 0.1;
  /// A tube is at rest when |v| < linear and |ω| < angular rest velocity (m/s, rad/s). A pile of
  /// tubes never stops creeping at a few mm/s in Bullet (unconverged friction), so a rest velocity
  /// of 5 mm/s would make every settle last settle_time; a falling or sliding tube exceeds 1 cm/s
  /// within a step.
  double linear_rest_velocity = 0.01;
  double angular_rest_velocity = 0.1;
  /// Seconds the grasped tube is held still at the last waypoint before the cost is measured.
  double post_motion_time = 0.5;
  /// Stop a trajectory early once the displacement sum exceeds this, metres (thesis disp_max).
  double disp_max = 1.0;
  /// Mass of one tube, kg (CellConfig tube.mass).
  double tube_mass = 0.055;
  /// Friction coefficients of tubes and of the bin.
  double tube_friction = 0.7;
  double bin_friction = 0.7;
  /// Rolling friction of tubes, metres (see above).
  double tube_rolling_friction = 0.001;
  /// Restitution of tubes and of the bin.
  double tube_restitution = 0.2;
  double bin_restitution = 0.5;
  /// Velocity damping of tubes (fraction lost per second).
  double linear_damping = 0.05;
  double angular_damping = 0.2;
  /// Collision margin of flat tube ends and bin walls, metres (Bullet's default 4 cm exceeds a tube
  /// radius; a capsule's margin is its radius).
  double collision_margin = 0.001;
  /// A joint cylinder links two consecutive cylinders when their endpoints are farther apart, m.
  double joint_min_length = 0.001;
  /// Bullet deactivation thresholds of a tube woken during a trajectory (m/s, rad/s); 0 disables.
  double sleep_linear_velocity = 0.02;
  double sleep_angular_velocity = 0.2;
  /// Bin wall thickness, metres (see BinSolids; the inner faces do not depend on it). Thicker than
  /// the real 1 cm so that a tube end modeled slightly into a wall is pushed back out rather than
  /// through it (or down through the floor).
  double wall_thickness = 0.05;
  /// Worker threads that simulate trajectories in parallel; 0 = the cores the process may use
  /// (CoresAvailable).
  int threads = 0;
  /// The bin the tubes lie in (its floor and walls are bodies of every world).
  BinConfig bin;

  /// @throws InvalidArgument naming the first bad field and its value.
  void Validate() const;
};

/// What one simulated trajectory did to every tube (for tests and tools; Evaluate keeps only the
/// outcome).
struct TrajectoryRun {
  TrajectoryOutcome outcome;
  /// Centre of mass of every tube (the grasped one included) when the run ended, Bin frame.
  std::vector<Eigen::Vector3d> p_BinCo_final;
  /// Highest centre-of-mass height of every tube during the run, metres.
  std::vector<double> max_com_z;
  /// Simulation steps taken.
  int steps = 0;
};

/// The tubes as Bullet bodies, settled once under gravity in the bin: the snapshot ("stable state")
/// every trajectory starts from. Immutable after construction; Run() is thread-safe.
class SettledTubes {
 public:
  /// Builds the tubes and the bin and steps gravity until every tube is at rest (see
  /// TrajectorySimParams::rest_time) or settle_time passes.
  /// @throws InvalidArgument for invalid params or tubes; Cancelled when `stop` fires.
  SettledTubes(const std::vector<Tube>& tubes, const TrajectorySimParams& params, const StopToken* stop);

  /// Simulates `trajectory` from the snapshot in a fresh world of its own: every tube at its settled
  /// pose, at rest and asleep (a tube wakes when something touches it), the grasped tube kinematic.
  /// Deterministic: the result depends only on the snapshot, the params and the trajectory.
  /// @throws InvalidArgument for an invalid trajectory; Cancelled when `stop` fires (polled every
  /// step).
  TrajectoryRun Run(const Trajectory& trajectory, const StopToken* stop) const;

  /// Settled pose of each tube's body frame C (centre of mass, principal axes), Bin frame.
  const std::vector<Eigen::Isometry3d>& X_BinC() const { return X_BinC_; }
  /// Settled centre of mass of tube `i`, Bin frame.
  Eigen::Vector3d p_BinCo(std::size_t i) const { return X_BinC_.at(i).translation(); }
  /// Every tube came to rest before settle_time.
  bool at_rest() const { return at_rest_; }
  /// Simulated seconds of settling.
  double settle_seconds() const { return settle_seconds_; }
  std::size_t size() const { return segments_.size(); }

  /// Checks `trajectory` against these tubes.
  /// @throws InvalidArgument naming what is wrong (tube index, empty, non-finite or non-zero first
  /// waypoint).
  void CheckTrajectory(const Trajectory& trajectory) const;

 private:
  /// Internal: as Run, also polling `abort` (set when another worker failed).
  friend class BulletTrajectoryEvaluator;
  TrajectoryRun RunImpl(const Trajectory& trajectory, const StopToken* stop, const StopToken* abort) const;

  TrajectorySimParams params_;
  std::vector<std::vector<TubeSegment>> segments_;
  std::vector<Eigen::Isometry3d> X_BinC_;
  bool at_rest_ = false;
  double settle_seconds_ = 0.0;
};

/// `base` set up for one cell and parameter profile: the cell's bin and tube mass, the profile's
/// disp_max (planning.cost.max_displacement) and `threads` workers (0 = all cores).
TrajectorySimParams SimParamsForCell(TrajectorySimParams base, const CellConfig& cell, double disp_max,
                                     int threads);

/// The Bullet physics backend of trajectory evaluation: settles the tubes once, then simulates the
/// trajectories on a pool of `threads` workers, each in a fresh world of its own (clone per
/// thread). Outcomes are bitwise the same whatever the thread count. Bullet's solver draws no
/// random numbers here, so the seed does not change the result.
class BulletTrajectoryEvaluator final : public TrajectoryEvaluator {
 public:
  /// @throws InvalidArgument for invalid params.
  explicit BulletTrajectoryEvaluator(TrajectorySimParams params = {});

  /// @throws InvalidArgument for an invalid tube or trajectory (before any simulation);
  /// Cancelled when `stop` fires (within one step of every worker).
  std::vector<TrajectoryOutcome> Evaluate(const std::vector<Tube>& tubes,
                                          const std::vector<Trajectory>& trajectories, std::uint64_t seed,
                                          const StopToken* stop) override;

  const TrajectorySimParams& params() const { return params_; }

 private:
  TrajectorySimParams params_;
};

}  // namespace tubepick::physics
