#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <btBulletDynamicsCommon.h>
#include <Eigen/Geometry>

#include "core/wrench/wrench.h"
#include "devices/sim/sim_cell.h"
#include "devices/sim/sim_tubes.h"
#include "physics/tube_bodies.h"

namespace tubepick::devices::sim {

/// A tube link, by tube index and link index.
using LinkId = std::pair<std::size_t, std::size_t>;

/// What the pads touch after a step.
struct PadContacts {
  /// Per pad (0: +y_Tcp, 1: −y_Tcp): something touches its inner face.
  bool touching[2] = {false, false};
  /// Per pad: normal contact force on the inner face, N.
  double force[2] = {0.0, 0.0};
  /// Every tube link touching an inner face, sorted, unique.
  std::vector<LinkId> links;
};

/// Where the gripper hits the bin or the ground.
struct GripperCollision {
  /// Deepest penetration, metres (0 when none).
  double depth = 0.0;
  /// "a finger" / "the housing" and "the bin wall" / "the floor or ground".
  std::string what;
};

/// The cell's Bullet world: bin and ground, tubes, and the kinematic gripper (a hand body at the
/// TCP carrying the housing, and two pad bodies). Device adapters command the gripper's pose and
/// opening and step it; the world measures the payload wrench after every Bullet step.
class SimWorld {
 public:
  /// Builds the world with the tubes where `tubes_Bin` puts them and the gripper at the robot's
  /// start pose, fully open.
  SimWorld(const SimCellParams& params, const std::vector<physics::TubeGeometry>& tubes_Bin);
  ~SimWorld();
  SimWorld(const SimWorld&) = delete;
  SimWorld& operator=(const SimWorld&) = delete;

  /// Steps until every tube has been at rest for 0.2 s or `max_seconds` pass; true when at rest.
  bool Settle(double max_seconds);

  /// Commands the gripper for the following steps.
  void SetGripper(const Eigen::Isometry3d& X_BinTcp, double opening);
  /// One Bullet step of substep() seconds with the commanded gripper; measures the wrench.
  void Step();
  /// One control step (substeps Bullet steps).
  void ControlStep();
  double substep() const { return substep_; }
  int substeps() const { return substeps_; }
  double time() const { return time_; }

  const Eigen::Isometry3d& X_BinTcp() const { return X_BinTcp_; }
  double opening() const { return opening_; }

  /// Payload wrench on the sensor after the last Bullet step: forces and torques about the TCP in
  /// the TCP axes (core/wrench/wrench.h), noise-free and without offsets.
  const Wrench& last_wrench() const { return last_wrench_; }
  /// Starts averaging the wrench over the following steps; WindowMean ends nothing.
  void BeginWindow();
  /// Mean wrench since BeginWindow (the last wrench when no step was taken).
  Wrench WindowMean() const;

  /// Pad contacts after the last step.
  PadContacts QueryPads() const;
  /// Deepest penetration of the pads (when `pads`) and the housing (when `housing`) into the bin
  /// or the ground now.
  GripperCollision QueryCollision(bool pads, bool housing) const;

  /// Holds `links` by fixed constraints to the hand (they stop colliding with the gripper).
  void Attach(const std::vector<LinkId>& links);
  /// Removes every grasp constraint.
  void ReleaseAll();
  /// Tubes with a held link, ascending.
  std::vector<std::size_t> HeldTubes() const;
  bool holding() const { return !grasps_.empty(); }
  /// Bodies of the tubes still in the world that Bullet steps (not asleep).
  std::uint32_t AwakeTubeBodies() const;

  std::size_t tube_count() const { return tubes_.size(); }
  /// Every tube where it is (a carried-off tube where it was carried off), by index.
  std::vector<physics::TubeGeometry> TubesBin() const;
  /// The tubes still in the world (what a scanner can see), in index order.
  std::vector<physics::TubeGeometry> TubesInWorldBin() const;

  /// Takes out of the world every tube that is neither held nor carried off already, lies at
  /// rest and whose centre of mass satisfies `where` (a conveyor carrying placed parts away): its
  /// bodies and joints leave the Bullet world, its pose and index stay. Returns how many.
  std::uint32_t CarryOff(const std::function<bool(const Eigen::Vector3d&)>& where);
  bool carried_off(std::size_t i) const { return carried_off_.at(i); }
  /// Tubes that ran away so far (SimRunaway, with `seconds` the world's time()).
  const std::vector<SimRunaway>& runaways() const { return runaways_; }
  const SimPeakSpeeds& peak_speeds() const { return peak_speeds_; }
  Eigen::Vector3d TubeCentreOfMass(std::size_t i) const { return CentreOfMass(tubes_.at(i)); }

 private:
  struct Grasp {
    LinkId link;
    std::unique_ptr<btFixedConstraint> constraint;
    std::unique_ptr<btJointFeedback> feedback;
  };

  void PlaceGripperBodies();
  Wrench MeasureWrench() const;
  /// Updates peak_speeds_ and records each tube's first runaway step.
  void WatchSpeeds();
  btRigidBody& LinkBody(const LinkId& id) const { return *tubes_.at(id.first).links.at(id.second).body; }
  /// 0 / 1 for a pad, 2 for the hand, −1 otherwise.
  int GripperPart(const btCollisionObject* object) const;

  SimCellParams params_;
  double substep_ = 0.0;
  int substeps_ = 1;
  std::unique_ptr<physics::BulletWorld> world_;
  std::vector<btRigidBody*> static_bodies_;
  std::vector<SimTube> tubes_;
  std::vector<bool> carried_off_;
  btRigidBody* hand_ = nullptr;
  btRigidBody* pads_[2] = {nullptr, nullptr};
  std::vector<std::unique_ptr<Grasp>> grasps_;

  Eigen::Isometry3d X_BinTcp_ = Eigen::Isometry3d::Identity();
  double opening_ = 0.0;
  double time_ = 0.0;
  Wrench last_wrench_;
  Wrench window_sum_;
  int window_steps_ = 0;
  SimPeakSpeeds peak_speeds_;
  std::vector<SimRunaway> runaways_;
  std::vector<bool> ran_away_;
};

}  // namespace tubepick::devices::sim
