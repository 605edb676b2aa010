#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/planning/grasp_synthesis.h"
#include "core/planning/plan_certainty.h"
#include "core/planning/trajectory.h"

namespace tubepick {

/// Grasp evaluation (thesis §5.2.4.2, Equations 5.3–5.6, Table 5.3). The weights sum to 1.
struct CostParams {
  /// H_cost_weight (Table 5.3: 0.2).
  double height_weight = 0.2;
  /// C_cost_weight (Table 5.3: 0.5).
  double centre_weight = 0.5;
  /// T_cost_weight (Table 5.3: 0.3).
  double trajectory_weight = 0.3;
  /// disp_max of Equation 5.6, metres (Table 5.3: 1 m).
  double max_displacement = 1.0;
};

/// The normalised cost terms of one plan and their weighted sum G_cost (Eq. 5.3), each in [0, 1].
struct PlanCosts {
  double height = 0.0;
  double centre = 0.0;
  double trajectory = 0.0;
  double total = 0.0;
};

/// One way to pick one tube: a grasp and the trajectory to follow after grasping.
struct PickPlan {
  /// Tube::id of the picked tube.
  std::uint32_t tube_id = 0;
  Grasp grasp;
  /// Relative translations of the grasped tube (and TCP), bin frame axes; first = (0, 0, 0).
  std::vector<Eigen::Vector3d> waypoints;
  TrajectoryKind kind = TrajectoryKind::kUpward;
  /// For escape kinds: unit xy direction of the lateral move; zero for upward.
  Eigen::Vector3d escape_direction = Eigen::Vector3d::Zero();
  /// Position of the trajectory among those synthesized for this request (diagnostics and
  /// deterministic tie-breaking).
  std::uint32_t trajectory_index = 0;
  PlanCosts costs;
  /// `disp` measured by the simulation, metres; nullopt when the trajectory was not simulated
  /// (non-occluded tubes, or no evaluator).
  std::optional<double> displacement;
  /// How sure the plan is to lift its tube alone (PlanCertainty); set by PlanPick.
  PlanCertainty certainty = PlanCertainty::kSure;
  /// X_BinTcp when placing the tube; attached after planning by core/placement (§5.2.7).
  std::optional<Eigen::Isometry3d> X_BinTcp_place;
};

/// H_cost = G_z / max_z (Eq. 5.4), clamped to [0, 1]; 0 when max_z ≤ 0.
double HeightCost(double grasp_z, double max_z);

/// C_cost (Eq. 5.5) with the distance measured along the tube's curve:
/// |curve_position − L/2| / (L/2), clamped to [0, 1]; 0 when L ≤ 0. (The thesis writes
/// dist(G, T_center) with T_center the point halfway along the curve length; on a bent tube the
/// straight-line distance would understate how far the grasp is from the middle, so the along-
/// curve distance is used: it is the lever arm along the tube.)
double CentreCost(double curve_position, double tube_length);

/// C_cost on a branched tube, which has no one middle along a curve: the distance from the grasp
/// point to the tube's mass centre (TubeMassCentre) over the largest distance of a cylinder
/// endpoint from it, clamped to [0, 1]: the lever arm of the whole tube's weight about the grasp.
double MassCentreCost(const Eigen::Vector3d& p_Bin_grasp, const Tube& tube);

/// C_cost of a grasp on `tube`: CentreCost along the curve on a one-branch (linear) tube,
/// MassCentreCost on a tube of several branches.
double GraspCentreCost(const Grasp& grasp, const Tube& tube);

/// T_cost = min(disp, disp_max)/disp_max (Eq. 5.6); 0 when not simulated (nullopt).
double TrajectoryCost(std::optional<double> displacement, double max_displacement);

/// All three terms and G_cost (Eq. 5.3).
PlanCosts PlanCost(double grasp_z, double max_z, double curve_position, double tube_length,
                   std::optional<double> displacement, const CostParams& params);
/// The same for a grasp on `tube` (C_cost from GraspCentreCost).
PlanCosts PlanCost(const Grasp& grasp, const Tube& tube, double max_z, std::optional<double> displacement,
                   const CostParams& params);

/// The plan is sure, or simulated with a displacement of at most params.safe_displacement.
bool PlanIsSafe(const PickPlan& plan, const CertaintyParams& params);

/// Strict weak order, best first: with params.safe_first a safe plan (PlanIsSafe) before one that
/// is not; then lower total cost, then lower tube id, then lower trajectory index, then lower curve
/// position, then lower cylinder index.
bool PlanBefore(const PickPlan& a, const PickPlan& b, const CertaintyParams& params);

/// Sorts best first with PlanBefore (deterministic for equal costs).
void RankPlans(std::vector<PickPlan>* plans, const CertaintyParams& params);

}  // namespace tubepick
