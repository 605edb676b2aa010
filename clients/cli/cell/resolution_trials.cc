// tubepick resolution-trials: the entanglement-resolution rotation (thesis §5.2.6) tried on many
// double picks in the simulated cell, so that its variants and angle are chosen on a measured rate
// rather than on the handful of double picks a cell round gives.

#include "clients/cli/cell/resolution_trials.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <thread>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "clients/cli/cell/sim_round.h"
#include "clients/cli/inputs/cli_inputs.h"
#include "core/common/errors.h"
#include "core/planning/grasp_synthesis.h"
#include "core/planning/plan_certainty.h"
#include "core/wrench/held_count.h"
#include "core/wrench/resolution_hold.h"
#include "core/wrench/resolution_rotation.h"
#include "devices/device_error.h"
#include "physics/random_tubes.h"
#include "wire/wrench_analysis.h"

namespace tubepick::cli {
namespace {

using devices::sim::Material;
using devices::sim::SimCell;
using devices::sim::SimCellParams;

using devices::AsWrench;

constexpr double kDegree = M_PI / 180.0;
constexpr devices::Timeout kLong{std::chrono::seconds(120)};
// The fingers' opening on the way down, metres (the grasped tube is 2.5 cm thick), and the
// gripper's speeds (m/s) and force (N) of the measured trials (the simulated cell's own tests use
// the same; the controller closes at its gripper_speed 0.1 and gripper_force 60).
constexpr double kTrialOpening = 0.045;
constexpr double kOpenSpeed = 0.1;
constexpr double kCloseSpeed = 0.05;
constexpr double kGripForce = 50.0;

Eigen::Isometry3d Above(Eigen::Isometry3d X_BinTcp, double height) {
  X_BinTcp.translation().z() += height;
  return X_BinTcp;
}

// Grasps: down from the pre-grasp pose, close (the fingers already open). False when the gripper
// closed on nothing.
bool Grasp(SimCell& cell, const Eigen::Isometry3d& X_BinTcpGrasp, const cell::CellControllerParams& c) {
  cell.robot().MoveTo(X_BinTcpGrasp, c.approach_speed, kLong);
  return cell.gripper().Close(kCloseSpeed, kGripForce, kLong).object ==
         devices::GripperObject::kStoppedClosing;
}

// Down from X_BinTcpFrom towards X_BinTcpTo (straight below it) in steps of at most `step`
// (cell::DescentSteps), reading the F/T at each, until less than `weight` newtons hang on the tool;
// ends at that step, or at X_BinTcpTo. Returns where it ended.
Eigen::Isometry3d DescendUntilLighter(SimCell& cell, const Wrench& reference,
                                      const Eigen::Isometry3d& X_BinTcpFrom,
                                      const Eigen::Isometry3d& X_BinTcpTo, double step, double speed,
                                      double weight) {
  Eigen::Isometry3d X_BinTcpEnd = X_BinTcpTo;
  for (const Eigen::Isometry3d& X_BinTcpStep : cell::DescentSteps(step, X_BinTcpFrom, X_BinTcpTo)) {
    cell.robot().MoveTo(X_BinTcpStep, speed, kLong);
    if (PayloadOnTool(reference, AsWrench(cell.ft_sensor().Read(kLong)), X_BinTcpFrom.linear()).weight <
        weight) {
      X_BinTcpEnd = X_BinTcpStep;
      break;
    }
  }
  cell.robot().MoveTo(X_BinTcpEnd, speed, kLong);
  return X_BinTcpEnd;
}

// The controller's resolution_rest_load: from the hold pose down until less than that many tube
// weights hang on the tool, not below floor_z; the offset from the hold pose.
Eigen::Vector3d LowerToRest(SimCell& cell, const Wrench& reference, const Eigen::Isometry3d& X_BinTcpHold,
                            double floor_z, const cell::CellControllerParams& c) {
  Eigen::Isometry3d X_BinTcpLow = X_BinTcpHold;
  X_BinTcpLow.translation().z() = std::min(floor_z, X_BinTcpHold.translation().z());
  const double resting = c.resolution_rest_load * cell.cell().tube.mass * WrenchParams{}.gravity;
  return DescendUntilLighter(cell, reference, X_BinTcpHold, X_BinTcpLow, c.put_back_step, c.lift_speed,
                             resting)
             .translation() -
         X_BinTcpHold.translation();
}

// Why a resolution motion turned about the TCP `shift` from where it was planned leaves the arm's
// reach or wrist limits (a tool tilted at the grasp turned further), or nullopt: the controller
// skips such a motion (CellController's ResolutionReachProblem) rather than drive into the stop.
std::optional<std::string> ReachProblem(SimCell& cell, const ResolutionMotion& motion,
                                        const Eigen::Translation3d& shift) {
  const devices::RobotLimits limits = cell.robot().Limits();
  for (std::size_t w = 0; w < motion.waypoints.size(); ++w) {
    if (std::string problem = limits.Problem(shift * motion.waypoints[w].X_BinTcpRotated); !problem.empty())
      return fmt::format("waypoint {}: {}", w, problem);
  }
  return std::nullopt;
}

// The resolution as the controller runs it: with hold_over_bin, first to the hold pose
// (PlanResolutionHold) and every waypoint shifted with it; each motion followed by the return to the
// hold pose and a reading, until the F/T says one tube (or none). With resolution_replan, each
// motion after the first is the first one planned from that reading at the hold pose, and up to
// resolution_extra_motions more follow the plan's. A motion beyond the robot's limits is skipped, and
// one beyond them only where it was let down turns at the hold pose, as the controller does.
void Resolve(SimCell& cell, const ResolutionPlan& plan, const Wrench& reference, const Wrench& lifted,
             const WrenchParams& params, const Eigen::Isometry3d& X_BinTcpLift, double floor_z,
             const TrialParams& tp, ResolutionTrial& trial, Wrench* held) {
  const cell::CellControllerParams& c = tp.controller;
  const double tube_mass = cell.cell().tube.mass;
  const Eigen::Translation3d shift(
      c.resolution_hold_over_bin ? PlanResolutionHold(reference, lifted, X_BinTcpLift,
                                                      cell.cell().bin.inner_size, c.resolution_wall_margin)
                                       .shift_Bin
                                 : Eigen::Vector3d::Zero());
  const Eigen::Isometry3d X_BinTcpHold = shift * X_BinTcpLift;
  trial.hold_shift = shift.translation().norm();
  cell.robot().MoveTo(X_BinTcpHold, c.lift_speed, kLong);
  std::optional<ResolutionPlan> replanned;  // from the reading after the last motion, at the hold pose
  for (std::size_t m = 0;; ++m) {
    const cell::ResolutionMotionSource source =
        cell::NextResolutionMotion(c, m, plan.motions.size(), replanned.has_value());
    if (source == cell::ResolutionMotionSource::kNone) break;
    const bool from_reading = source == cell::ResolutionMotionSource::kReading;
    const ResolutionMotion& motion = from_reading ? replanned->motions.front() : plan.motions[m];
    const Eigen::Translation3d motion_shift = from_reading ? Eigen::Translation3d::Identity() : shift;
    if (ReachProblem(cell, motion, motion_shift)) {
      ++trial.beyond_limits;
      if (from_reading) replanned.reset();  // that reading plans nothing else: the plan's next motion
      continue;
    }
    ++trial.motions_used;
    Eigen::Translation3d down(c.resolution_rest_load > 0.0
                                  ? LowerToRest(cell, reference, X_BinTcpHold, floor_z, c)
                                  : Eigen::Vector3d::Zero());
    if (c.resolution_rest_load > 0.0 && ReachProblem(cell, motion, down * motion_shift)) {
      ++trial.lowered_beyond_limits;
      cell.robot().MoveTo(X_BinTcpHold, c.lift_speed, kLong);
      down = Eigen::Translation3d::Identity();
    }
    trial.lowered = -down.translation().z();
    for (const ResolutionWaypoint& w : motion.waypoints)
      cell.robot().MoveTo(down * motion_shift * w.X_BinTcpRotated, c.resolution_speed, kLong);
    if (c.resolution_dwell > 0.0) cell.robot().Hold(c.resolution_dwell, kLong);
    if (c.resolution_rest_load > 0.0) cell.robot().MoveTo(down * X_BinTcpHold, c.resolution_speed, kLong);
    cell.robot().MoveTo(X_BinTcpHold, c.resolution_speed, kLong);
    *held = AsWrench(cell.ft_sensor().Read(kLong));
    const HeldCount again = CountHeldTubes(reference, *held, tube_mass, params);
    if (again.outcome != HeldOutcome::kMultiple) {
      trial.freed = again.outcome == HeldOutcome::kSingle;
      return;
    }
    if (c.resolution_replan) replanned = PlanResolutionRotation(reference, *held, X_BinTcpHold, params);
  }
}

// Tubes other than `tube` hanging clear of the floor: every node above two radii.
std::uint32_t OthersLifted(const SimCell& cell, std::size_t tube) {
  const std::vector<physics::TubeGeometry> tubes = cell.TubesBin();
  std::uint32_t lifted = 0;
  for (std::size_t t = 0; t < tubes.size(); ++t) {
    if (t == tube) continue;
    lifted += std::all_of(tubes[t].nodes.begin(), tubes[t].nodes.end(), [&](const physics::TubeNode& n) {
      return n.centre.z() > 2.0 * cell.cell().tube.radius;
    });
  }
  return lifted;
}

// Several tubes not freed, put back as the controller does (CellController::PutBack): from the lift
// pose, or from further inside when their centre of mass (`held`, the last reading) lies less than
// put_back_margin inside a wall (PlanPutBackShift; not for a reading no hanging load gives,
// HangsFromTheTool), then down in put_back_step steps until less
// than half a tube's weight hangs on the tool; opened, up, and the tool's load read there.
void PutBackSeveral(SimCell& cell, const TrialGrasp& grasp, const Wrench& reference, const Wrench& held,
                    const Eigen::Isometry3d& X_BinTcpLift, const TrialParams& tp, ResolutionTrial& trial) {
  const cell::CellControllerParams& c = tp.controller;
  const Eigen::Matrix3d R_BinTcp = X_BinTcpLift.linear();
  const Payload payload = PayloadOnTool(reference, held, R_BinTcp);
  const Eigen::Vector3d shift = HangsFromTheTool(payload, cell.cell().tube.length)
                                    ? PlanPutBackShift(X_BinTcpLift.translation(), payload.p_TcpPayload_Bin,
                                                       cell.cell().bin.inner_size, c.put_back_margin)
                                    : Eigen::Vector3d::Zero();
  trial.put_back_shift = shift.norm();
  const Eigen::Isometry3d X_BinTcpPutBack = Eigen::Translation3d(shift) * X_BinTcpLift;
  cell.robot().MoveTo(X_BinTcpPutBack, c.lift_speed, kLong);
  Eigen::Isometry3d X_BinTcpRelease = X_BinTcpPutBack;
  X_BinTcpRelease.translation().z() = grasp.X_BinTcp.translation().z() + c.release_height;
  const double resting = 0.5 * cell.cell().tube.mass * WrenchParams{}.gravity;
  X_BinTcpRelease = DescendUntilLighter(cell, reference, X_BinTcpPutBack, X_BinTcpRelease, c.put_back_step,
                                        c.lift_speed, resting);
  cell.gripper().MoveTo(kTrialOpening, kOpenSpeed, kGripForce, kLong);
  cell.robot().MoveTo(X_BinTcpPutBack, c.approach_speed, kLong);
  trial.caught = PayloadOnTool(reference, AsWrench(cell.ft_sensor().Read(kLong)), R_BinTcp).weight > resting;
}

// One lift of the trial: grasp from 10 cm above (reference reading there), lift, read. With several
// tubes, the resolution; otherwise the tube is put back (lowered to 3 cm above the grasp, opened)
// for the next lift.
void LiftAndResolve(SimCell& cell, const TrialGrasp& grasp, const WrenchParams& wrench, const TrialParams& tp,
                    ResolutionTrial& trial) {
  const cell::CellControllerParams& c = tp.controller;
  const auto open = [&] { cell.gripper().MoveTo(kTrialOpening, kOpenSpeed, kGripForce, kLong); };
  open();
  const Eigen::Isometry3d above = Above(grasp.X_BinTcp, c.approach_height);
  cell.robot().MoveTo(above, c.transit_speed, kLong);
  cell.ft_sensor().Bias(kLong);
  const Wrench reference = AsWrench(cell.ft_sensor().Read(kLong));
  if (!Grasp(cell, grasp.X_BinTcp, c)) {
    open();
    cell.robot().MoveTo(above, c.approach_speed, kLong);
    return;
  }
  cell.robot().MoveThrough({Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 0.0, tp.lift)}, c.lift_speed,
                           kLong);
  const Eigen::Isometry3d X_BinTcpLift = cell.X_BinTcp();
  const WrenchParams at_lift = WrenchParamsAtPose(wrench, X_BinTcpLift);
  const double mass = cell.cell().tube.mass;
  const Wrench lifted = AsWrench(cell.ft_sensor().Read(kLong));
  trial.multiple = CountHeldTubes(reference, lifted, mass, at_lift).outcome == HeldOutcome::kMultiple;
  if (trial.multiple) {
    trial.others_lifted = OthersLifted(cell, grasp.tube);
    Wrench held = lifted;
    if (const std::optional<ResolutionPlan> plan =
            PlanResolutionRotation(reference, lifted, X_BinTcpLift, at_lift);
        plan && tp.resolve)
      Resolve(cell, *plan, reference, lifted, at_lift, X_BinTcpLift,
              grasp.X_BinTcp.translation().z() + c.release_height, tp, trial, &held);
    if (trial.freed) return;  // held: the freed tubes fell, counted at the end
    PutBackSeveral(cell, grasp, reference, held, X_BinTcpLift, tp, trial);
    return;
  }
  // Put back, as the controller does with one tube here.
  cell.robot().MoveTo(Above(grasp.X_BinTcp, c.release_height), c.lift_speed, kLong);
  open();
  cell.robot().MoveTo(above, c.approach_speed, kLong);
}

// Ground truth at the end: 2 s of rest, then whether the tube is held and how many others lie
// outside the bin.
void RecordTruth(SimCell& cell, ResolutionTrial& trial) {
  cell.Advance(2.0);
  const std::vector<std::size_t> held = cell.HeldTubes();
  trial.tube_held = std::find(held.begin(), held.end(), trial.tube) != held.end();
  trial.others_outside = cell.TubesOutsideBin();
}

// Whether the open fingers (and the housing above them) coming down to X_BinTcp from above would
// meet a tube other than `grasped`: a point of its axis (every 5 mm) within a radius of a pad's or
// the housing's box, anywhere above the fingertips (z_Tcp points down). The planner keeps its
// grasps clear of the cloud this way (grasp_filters.h); pads pushing a tube into the pile would
// kick the kinematic gripper's neighbours apart rather than make a double pick.
bool FingersMeetAnotherTube(const SimCell& cell, const std::vector<Tube>& tubes, std::size_t grasped,
                            const Eigen::Isometry3d& X_BinTcp) {
  const devices::sim::SimGripperParams& g = cell.params().gripper;
  const double r = cell.cell().tube.radius;
  const double pad_inner = 0.5 * kTrialOpening, pad_outer = pad_inner + g.finger_thickness;
  const double housing_bottom = g.finger_tip_depth - g.finger_length - g.housing_gap;
  const Eigen::Isometry3d X_TcpBin = X_BinTcp.inverse();
  auto meets = [&](const Eigen::Vector3d& p_Bin) {
    const Eigen::Vector3d p = X_TcpBin * p_Bin;
    if (p.z() > g.finger_tip_depth + r) return false;  // below the fingertips
    const bool pad = std::abs(p.x()) < 0.5 * g.finger_width + r && std::abs(p.y()) > pad_inner - r &&
                     std::abs(p.y()) < pad_outer + r;
    const bool housing = p.z() < housing_bottom + r && std::abs(p.x()) < 0.5 * g.housing_size.x() + r &&
                         std::abs(p.y()) < 0.5 * g.housing_size.y() + r;
    return pad || housing;
  };
  for (std::size_t t = 0; t < tubes.size(); ++t) {
    if (t == grasped) continue;
    for (const Cylinder& c : tubes[t].cylinders) {
      const int steps = std::max(1, static_cast<int>(std::ceil(c.length() / 0.005)));
      for (int k = 0; k <= steps; ++k) {
        if (meets(c.start + (static_cast<double>(k) / steps) * (c.end - c.start))) return true;
      }
    }
  }
  return false;
}

// The grasp at the middle of tubes[t]'s flattest cylinder (≥ 4 cm, inclined < 17°) nearest its
// centre of mass `com` whose fingers meet no other tube.
std::optional<Eigen::Isometry3d> MiddleGrasp(const SimCell& cell, const std::vector<Tube>& tubes,
                                             std::size_t t, const Eigen::Vector3d& com) {
  Eigen::Isometry3d best = Eigen::Isometry3d::Identity();
  double nearest = std::numeric_limits<double>::infinity();
  for (const Cylinder& c : tubes[t].cylinders) {
    if (c.length() < 0.04 || std::abs(c.axis().z()) > 0.3) continue;
    const Eigen::Vector3d middle = 0.5 * (c.start + c.end);
    const double d = (middle - com).head<2>().norm();
    if (d >= nearest) continue;
    const std::optional<Eigen::Isometry3d> X = GraspFrame(middle, c.axis());
    if (!X || FingersMeetAnotherTube(cell, tubes, t, *X)) continue;
    nearest = d;
    best = *X;
  }
  if (!std::isfinite(nearest)) return std::nullopt;
  return best;
}

}  // namespace

std::optional<TrialGrasp> ChooseTrialGrasp(const SimCell& cell, const std::vector<std::size_t>& tried) {
  const std::vector<physics::TubeGeometry> truth = cell.TubesBin();
  const std::vector<Eigen::Vector3d> coms = cell.TubeCentresOfMass();
  std::vector<Tube> tubes;
  for (const physics::TubeGeometry& g : truth) tubes.push_back(g.ToTube());
  std::optional<TrialGrasp> best;
  double best_height = -1.0;
  for (std::size_t t = 0; t < tubes.size(); ++t) {
    const std::size_t on_it = TubesLyingOn(tubes, t, CertaintyParams{}).size();
    if (on_it == 0 || coms[t].z() <= best_height) continue;
    if (std::find(tried.begin(), tried.end(), t) != tried.end()) continue;
    const std::optional<Eigen::Isometry3d> X_BinTcp = MiddleGrasp(cell, tubes, t, coms[t]);
    if (!X_BinTcp) continue;
    best = TrialGrasp{t, on_it, *X_BinTcp};
    best_height = coms[t].z();
  }
  return best;
}

ResolutionTrial RunResolutionTrial(SimCell& cell, const WrenchParams& wrench, const TrialParams& tp) {
  ResolutionTrial trial;
  trial.seed = cell.params().seed;
  std::vector<std::size_t> tried;
  trial.outside_at_start = cell.TubesOutsideBin();
  try {
    cell.robot().ServoOn(kLong);
    cell.gripper().Activate(kLong);
    while (trial.lifts < tp.max_lifts && !trial.multiple) {
      const std::optional<TrialGrasp> grasp = ChooseTrialGrasp(cell, tried);
      if (!grasp) break;
      tried.push_back(grasp->tube);
      ++trial.lifts;
      trial.tube = grasp->tube;
      trial.tubes_on_it = grasp->tubes_on_it;
      LiftAndResolve(cell, *grasp, wrench, tp, trial);
    }
  } catch (const devices::DeviceFault& e) {
    trial.fault = e.what();
  } catch (const devices::DeviceTimeout& e) {
    trial.fault = e.what();
  }
  RecordTruth(cell, trial);
  return trial;
}

ResolutionTrial RunResolutionTrial(const SimCellParams& params, const WrenchParams& wrench,
                                   const TrialParams& tp) {
  SimCell cell(params);
  return RunResolutionTrial(cell, wrench, tp);
}

}  // namespace tubepick::cli

namespace tubepick::cli {
namespace {

// Counts over the bins of one material, variant and angle.
struct ArmSummary {
  std::uint32_t bins = 0, lifts = 0, multiple = 0, freed = 0, second_motion = 0, outside = 0, faults = 0;
  std::uint32_t put_back = 0, moved_inside = 0, caught = 0, beyond_limits = 0;
};

std::vector<ResolutionTrial> RunArm(const SimCellParams& base, const WrenchParams& wrench,
                                    const ResolutionTrialsOptions& o) {
  std::vector<ResolutionTrial> trials(o.bins);
  std::atomic<std::uint32_t> next{0};
  std::vector<std::thread> workers;
  std::exception_ptr error;
  std::mutex error_mutex;
  for (std::uint32_t w = 0; w < std::max(1u, o.jobs); ++w) {
    workers.emplace_back([&] {
      for (std::uint32_t i = next++; i < o.bins; i = next++) {
        try {
          SimCellParams params = base;
          params.seed = o.seed + i;
          trials[i] = RunResolutionTrial(params, wrench, o.trial);
        } catch (...) {
          const std::lock_guard<std::mutex> lock(error_mutex);
          error = std::current_exception();
        }
      }
    });
  }
  for (std::thread& t : workers) t.join();
  if (error) std::rethrow_exception(error);
  return trials;
}

ArmSummary Summarise(const std::vector<ResolutionTrial>& trials) {
  ArmSummary s;
  s.bins = static_cast<std::uint32_t>(trials.size());
  for (const ResolutionTrial& t : trials) {
    s.lifts += t.lifts;
    s.faults += !t.fault.empty();
    s.beyond_limits += t.beyond_limits;
    s.outside += t.others_outside;
    if (!t.multiple) continue;
    ++s.multiple;
    s.freed += t.freed;
    s.second_motion += t.freed && t.motions_used > 1;
    if (t.freed || !t.fault.empty()) continue;
    ++s.put_back;
    s.moved_inside += t.put_back_shift > 0.0;
    s.caught += t.caught;
  }
  return s;
}

nlohmann::json TrialJson(const ResolutionTrial& t) {
  return {{"seed", t.seed},
          {"lifts", t.lifts},
          {"tube", t.tube},
          {"tubes_on_it", t.tubes_on_it},
          {"multiple", t.multiple},
          {"others_lifted", t.others_lifted},
          {"motions_used", t.motions_used},
          {"hold_shift", t.hold_shift},
          {"lowered", t.lowered},
          {"beyond_limits", t.beyond_limits},
          {"lowered_beyond_limits", t.lowered_beyond_limits},
          {"freed", t.freed},
          {"tube_held", t.tube_held},
          {"outside_at_start", t.outside_at_start},
          {"others_outside", t.others_outside},
          {"put_back_shift", t.put_back_shift},
          {"caught", t.caught},
          {"fault", t.fault}};
}

std::string Percent(std::uint32_t part, std::uint32_t whole) {
  return whole == 0 ? "–" : fmt::format("{:.0f} %", 100.0 * part / whole);
}

void RunTrials(const ResolutionTrialsOptions& o) {
  ValidateResolutionTrials(o);
  nlohmann::json json = nlohmann::json::array();
  fmt::print(
      "| material | shapes | variant | angle | bins | lifts | double picks (F/T) | freed | freed by a later "
      "motion | put back: moved inside, caught on the tool | tubes outside the bin | gripper or robot faults "
      "| motions skipped, beyond the robot's limits |\n"
      "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const std::string& material_name : o.materials) {
    const Material material = devices::sim::ParseMaterial(material_name, "--materials");
    SimCellParams params = SimCellParams::Thesis(material, o.tubes, o.seed);
    if (!o.shapes.empty()) WithShapes(o.shapes, &params);
    const std::string shapes = o.shapes.empty() ? (material == Material::kRubber ? "B" : "A") : o.shapes;
    for (const std::string& variant : o.variants) {
      for (const double angle : o.angles_deg) {
        WrenchParams wrench;
        wrench.variant = ParseResolutionVariant(variant, "--variants");
        wrench.rotation_angle = angle * kDegree;
        wrench.Validate();
        const std::vector<ResolutionTrial> trials = RunArm(params, wrench, o);
        const ArmSummary s = Summarise(trials);
        fmt::print("| {} | {} | {} | {:.0f}° | {} | {} | {} | {} ({}) | {} | {}: {}, {} | {} | {} | {} |\n",
                   material_name, shapes, variant, angle, s.bins, s.lifts, s.multiple, s.freed,
                   Percent(s.freed, s.multiple), s.second_motion, s.put_back, s.moved_inside, s.caught,
                   s.outside, s.faults, s.beyond_limits);
        nlohmann::json arm = {{"material", material_name},
                              {"shapes", shapes},
                              {"variant", variant},
                              {"angle_deg", angle},
                              {"tubes", o.tubes},
                              {"lift", o.trial.lift},
                              {"dwell", o.trial.controller.resolution_dwell},
                              {"replan", o.trial.controller.resolution_replan},
                              {"extra_motions", o.trial.controller.resolution_extra_motions},
                              {"rest_load", o.trial.controller.resolution_rest_load},
                              {"trials", nlohmann::json::array()}};
        for (const ResolutionTrial& t : trials) arm["trials"].push_back(TrialJson(t));
        json.push_back(arm);
      }
    }
  }
  if (!o.json_path.empty()) WriteTextFile(o.json_path, json.dump(1) + "\n");
}

}  // namespace

void ValidateResolutionTrials(const ResolutionTrialsOptions& o) {
  if (o.bins == 0) throw InvalidArgument("--bins: 0 (at least one bin)");
  if (o.tubes < 2)
    throw InvalidArgument(fmt::format("--tubes: {} (a double pick needs at least 2)", o.tubes));
  for (const std::string& m : o.materials) devices::sim::ParseMaterial(m, "--materials");
  for (const std::string& v : o.variants) ParseResolutionVariant(v, "--variants");
  for (const double angle : o.angles_deg) {
    // A few degrees shake nothing; 0.8 is 46° in radians, the likely mistake.
    if (!(angle >= 5.0 && angle <= 90.0))
      throw InvalidArgument(fmt::format(
          "--angles: {}° is out of range [5, 90] (degrees; a value below 5 looks like radians)", angle));
  }
  if (!o.shapes.empty()) {
    try {
      physics::RandomTubeParams::Preset(o.shapes);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(std::string("--shapes: ") + e.what());
    }
  }
  if (!(o.trial.lift > 0.0))
    throw InvalidArgument(
        fmt::format("--lift: {} m (the lift before the reading must be positive)", o.trial.lift));
  if (!(o.trial.controller.resolution_dwell >= 0.0))
    throw InvalidArgument(
        fmt::format("--dwell: {} s (a wait, at least 0)", o.trial.controller.resolution_dwell));
  if (!(o.trial.controller.put_back_margin >= 0.0))
    throw InvalidArgument(fmt::format("--put-back-margin: {} m (inside the bin walls, at least 0)",
                                      o.trial.controller.put_back_margin));
  if (!(o.trial.controller.put_back_step >= 0.0))
    throw InvalidArgument(
        fmt::format("--put-back-step: {} m (a step down, at least 0)", o.trial.controller.put_back_step));
  if (!(o.trial.controller.resolution_wall_margin >= 0.0))
    throw InvalidArgument(fmt::format("--wall-margin: {} m (inside the bin walls, at least 0)",
                                      o.trial.controller.resolution_wall_margin));
  // The controller's own rule for resolution_rest_load (0, or over one tube weight).
  cell::CellControllerParams rest_load;
  rest_load.resolution_rest_load = o.trial.controller.resolution_rest_load;
  try {
    rest_load.Validate();
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("--rest-load: ") + e.what());
  }
}

void AddResolutionTrialsCommand(CLI::App& app) {
  auto o = std::make_shared<ResolutionTrialsOptions>();
  CLI::App* cmd = app.add_subcommand(
      "resolution-trials",
      "Double picks in generated bins of the simulated cell (a tube grasped under another): how often "
      "each resolution rotation frees the extra tubes, and where they fall");
  cmd->add_option("--materials", o->materials, "pvc, rubber")->delimiter(',')->capture_default_str();
  cmd->add_option(
         "--variants", o->variants,
         "torque_axis, torque_axis_negative, perpendicular, joint_safe, torque_axis_then_perpendicular")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--angles", o->angles_deg, "Rotation angles, degrees")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--shapes", o->shapes,
                  "A, B, C or CY (default: the material's thesis set, pvc A, rubber B)");
  cmd->add_option("--tubes", o->tubes, "Tubes per bin")->capture_default_str();
  cmd->add_option("--bins", o->bins, "Bins (seeds seed, seed + 1, ...); the same bins for every variant")
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the first bin")->capture_default_str();
  cmd->add_option("--lift", o->trial.lift, "Lift before the reading, metres")->capture_default_str();
  cmd->add_option("--hold-over-bin", o->trial.controller.resolution_hold_over_bin,
                  "Bring the payload over the bin's middle before the rotation, as the controller does")
      ->capture_default_str();
  cmd->add_option("--wall-margin", o->trial.controller.resolution_wall_margin,
                  "The hold pose's TCP inside the bin walls, metres")
      ->capture_default_str();
  cmd->add_option("--dwell", o->trial.controller.resolution_dwell,
                  "Pause at each resolution motion's tilt, seconds (the controller's resolution_dwell)")
      ->capture_default_str();
  cmd->add_option("--replan", o->trial.controller.resolution_replan,
                  "Each motion after the first planned from the reading after the one before, at the hold "
                  "pose (the controller's resolution_replan)")
      ->capture_default_str();
  cmd->add_option("--extra-motions", o->trial.controller.resolution_extra_motions,
                  "With --replan: up to this many more motions after the plan's, each from the latest "
                  "reading (the controller's resolution_extra_motions)")
      ->check(CLI::Range(0U, cell::CellControllerParams::kMaxResolutionExtraMotions))
      ->capture_default_str();
  cmd->add_option("--rest-load", o->trial.controller.resolution_rest_load,
                  "Each motion turns lower: the tangle let down from the hold pose until less than this many "
                  "tube weights hang on the tool (the others resting on the heap), turned there, lifted back "
                  "for the reading; 0 = at the hold pose (the controller's resolution_rest_load)")
      ->check(CLI::Range(0.0, cell::CellControllerParams::kMaxResolutionRestLoad))
      ->capture_default_str();
  cmd->add_option("--resolve", o->trial.resolve,
                  "Run the resolution; false: every double pick is put back at once (the put-back alone)")
      ->capture_default_str();
  cmd->add_option("--put-back-margin", o->trial.controller.put_back_margin,
                  "Tubes not freed: their centre of mass at least this inside the walls, metres")
      ->capture_default_str();
  cmd->add_option("--put-back-step", o->trial.controller.put_back_step,
                  "... and lowered in steps of this, metres (0 = one move)")
      ->capture_default_str();
  cmd->add_option("--max-lifts", o->trial.max_lifts, "Lifts per bin until one holds several tubes")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option("--jobs", o->jobs, "Trials run in parallel")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd->add_option("--json", o->json_path, "Write every trial as JSON");
  cmd->callback([o] { RunTrials(*o); });
}

}  // namespace tubepick::cli
