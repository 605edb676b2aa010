#include "clients/cell/nudge.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "wire/proto_convert.h"

namespace tubepick::cell {
namespace {

struct Sample {
  Eigen::Vector3d p_Bin;  // on the tube's axis
  double radius = 0.0;
  double fraction = 0.0;  // along the tube's cylinders
};

/// Distance of xy point p_Bin to each wall (+x, −x, +y, −y) and that wall's inward normal.
struct Walls {
  std::array<double, 4> distance{};
  static Eigen::Vector3d Inward(int w) {
    switch (w) {
      case 0:
        return -Eigen::Vector3d::UnitX();
      case 1:
        return Eigen::Vector3d::UnitX();
      case 2:
        return -Eigen::Vector3d::UnitY();
      default:
        return Eigen::Vector3d::UnitY();
    }
  }
};

Walls WallDistances(const Eigen::Vector3d& p_Bin, const CellConfig& cell) {
  const Eigen::Vector3d half = 0.5 * cell.bin.inner_size;
  Walls w;
  w.distance = {half.x() - p_Bin.x(), half.x() + p_Bin.x(), half.y() - p_Bin.y(), half.y() + p_Bin.y()};
  return w;
}

std::vector<Sample> SampleTube(const v1::Tube& tube, double spacing, double default_radius) {
  double total = 0.0;
  for (const v1::Cylinder& c : tube.cylinders()) total += (FromProto(c.end()) - FromProto(c.start())).norm();
  std::vector<Sample> samples;
  if (!(total > 0.0)) return samples;
  double offset = 0.0;
  for (const v1::Cylinder& c : tube.cylinders()) {
    const Eigen::Vector3d p_Bin_start = FromProto(c.start()), p_Bin_end = FromProto(c.end());
    const double length = (p_Bin_end - p_Bin_start).norm();
    const int n = std::max(1, static_cast<int>(std::ceil(length / spacing)));
    const double radius = c.radius() > 0.0 ? c.radius() : default_radius;
    for (int k = 0; k <= n; ++k) {
      const double t = static_cast<double>(k) / n;
      samples.push_back({p_Bin_start + t * (p_Bin_end - p_Bin_start), radius, (offset + t * length) / total});
    }
    offset += length;
  }
  return samples;
}

// The samples of every tube but tubes[skip].
std::vector<Sample> OtherTubes(const google::protobuf::RepeatedPtrField<v1::Tube>& tubes, int skip,
                               double spacing, double default_radius) {
  std::vector<Sample> samples;
  for (int i = 0; i < tubes.size(); ++i) {
    if (i == skip) continue;
    const std::vector<Sample> tube = SampleTube(tubes[i], spacing, default_radius);
    samples.insert(samples.end(), tube.begin(), tube.end());
  }
  return samples;
}

// What the closed tool must keep clear of: the other tubes, and the pressed one's parts above the contact.
struct Obstacles {
  const std::vector<Sample>& others;
  const std::vector<Sample>& own_above;
};

// The samples of the pressed tube itself that lie more than a diameter above `contact`: a branch or
// the far end of a steep piece, which the closed tool would pass through on its way down to the
// contact or up from the push (the pads press and drag the rest of it).
std::vector<Sample> OwnAbove(const std::vector<Sample>& own, const Sample& contact) {
  std::vector<Sample> above;
  for (const Sample& s : own)
    if (s.p_Bin.z() > contact.p_Bin.z() + 2.0 * contact.radius) above.push_back(s);
  return above;
}

// The tool's boxes at X_BinTcp moved by t · move_Bin, t in [0, 1]: the smallest t at which a box,
// grown by a sample's radius and `clearance`, holds that sample's axis point, or nullopt when none
// does. Per box and sample, the t where each TCP axis overlaps is an interval (the slab test); the
// box holds the point where the three meet. Samples are spaced closer than twice the growth, so no
// box slips between two of them.
std::optional<double> FirstContact(const std::array<ToolBox, 3>& boxes, const Eigen::Isometry3d& X_BinTcp,
                                   const Eigen::Vector3d& move_Bin, const Obstacles& obstacles,
                                   double clearance) {
  const Eigen::Isometry3d X_TcpBin = X_BinTcp.inverse();
  const Eigen::Vector3d move_Tcp = X_TcpBin.linear() * move_Bin;
  std::optional<double> first;
  for (const std::vector<Sample>* list : {&obstacles.others, &obstacles.own_above}) {
    for (const Sample& obstacle : *list) {
      const Eigen::Vector3d p_Tcp = X_TcpBin * obstacle.p_Bin;
      for (const ToolBox& box : boxes) {
        double lo = 0.0, hi = 1.0;
        for (int axis = 0; axis < 3 && lo <= hi; ++axis) {
          const double reach = box.half_size[axis] + obstacle.radius + clearance;
          const double offset =
              p_Tcp[axis] - box.centre_Tcp[axis];  // overlap while |offset − t·move| ≤ reach
          if (std::abs(move_Tcp[axis]) < 1e-12) {
            if (std::abs(offset) > reach) hi = -1.0;
            continue;
          }
          const double t0 = (offset - reach) / move_Tcp[axis], t1 = (offset + reach) / move_Tcp[axis];
          lo = std::max(lo, std::min(t0, t1));
          hi = std::min(hi, std::max(t0, t1));
        }
        if (lo <= hi && (!first || lo < *first)) first = lo;
      }
    }
  }
  return first;
}

// The push from X_BinTcpPress along `direction` that keeps the closed tool (`boxes`) `clearance` from the
// other tubes on the way down (from `rise` above), along the push and up (`rise` again): `distance`, or less
// where a tube is in the way; nullopt when that is less than `min_push` or the way down or up is blocked.
std::optional<double> ClearPush(const std::array<ToolBox, 3>& boxes, const Eigen::Isometry3d& X_BinTcpPress,
                                const Eigen::Vector3d& direction, double distance, double min_push,
                                double rise, const Obstacles& obstacles, double clearance) {
  const Eigen::Vector3d up(0.0, 0.0, rise);
  if (FirstContact(boxes, X_BinTcpPress, up, obstacles, clearance)) return std::nullopt;
  if (const std::optional<double> t =
          FirstContact(boxes, X_BinTcpPress, distance * direction, obstacles, clearance))
    distance *= *t;
  if (distance < min_push) return std::nullopt;
  Eigen::Isometry3d X_BinTcpPushed = X_BinTcpPress;
  X_BinTcpPushed.translation() += distance * direction;
  if (FirstContact(boxes, X_BinTcpPushed, up, obstacles, clearance)) return std::nullopt;
  return distance;
}

// A tube along a wall, nudged in this order: non-occluded first, then closest to a wall.
struct Candidate {
  int index;
  bool occluded;
  double wall_distance;
};

// The tubes with an axis sample closer than params.near_wall_distance to a wall, in nudge order.
std::vector<Candidate> WallTubes(const google::protobuf::RepeatedPtrField<v1::Tube>& tubes,
                                 const CellConfig& cell, const NudgeParams& params) {
  std::vector<Candidate> candidates;
  for (int i = 0; i < tubes.size(); ++i) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const Sample& s : SampleTube(tubes[i], params.sample_spacing, cell.tube.radius)) {
      const Walls w = WallDistances(s.p_Bin, cell);
      nearest = std::min(nearest, *std::min_element(w.distance.begin(), w.distance.end()));
    }
    if (nearest < params.near_wall_distance)
      candidates.push_back(
          {i, tubes[i].occlusion() == v1::OCCLUSION_WEAK || tubes[i].occlusion() == v1::OCCLUSION_STRONG,
           nearest});
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    if (a.occluded != b.occluded) return !a.occluded;
    return a.wall_distance < b.wall_distance;
  });
  return candidates;
}

// The push at axis sample `s`: away from every wall closer than params.near_wall_distance, by the push
// gain's distance; nullopt when no wall is that close. The press pose is PlacePress's.
std::optional<NudgePlan> PushAt(const Sample& s, int tube_id, const CellConfig& cell,
                                const NudgeParams& params) {
  const Walls w = WallDistances(s.p_Bin, cell);
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  double nearest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 4; ++k) {
    if (w.distance[k] < params.near_wall_distance) direction += Walls::Inward(k);
    nearest = std::min(nearest, w.distance[k]);
  }
  if (direction.norm() < 1e-9) return std::nullopt;
  NudgePlan plan;
  plan.tube_id = tube_id;
  plan.p_Bin_contact = s.p_Bin;
  plan.wall_distance = nearest;
  plan.direction = direction.normalized();
  plan.distance = std::clamp(params.push_gain * (params.target_wall_distance - nearest), params.min_push,
                             params.max_push);
  return plan;
}

// What PlacePress needs besides the contact: the cell, the tool and its closed boxes, the rise after the
// push and the transit height the tool comes down from.
struct NudgeTools {
  const CellConfig& cell;
  const ToolGeometry& tool;
  const NudgeParams& params;
  std::array<ToolBox, 3> closed_tool;
  double lift;
  double transit_z;
};

// Places the closed pads on `s` for `plan`'s push: housing's narrow side to the wall, tilted by params.tilt,
// shifted up to half a pad along the push until the tool clears the bin (ToolClearanceProblem) and the
// tubes (ClearPush) on its whole way; fills plan.X_BinTcpPress, shift and the clear distance. False when
// no shift does.
bool PlacePress(const Sample& s, const NudgeTools& t, const Obstacles& obstacles, NudgePlan& plan) {
  const NudgeParams& params = t.params;
  const Eigen::Vector3d& direction = plan.direction;
  // z_Tcp down, x_Tcp along the push: the housing's narrow side faces the wall.
  Eigen::Matrix3d R_BinTcp;
  R_BinTcp.col(0) = direction;
  R_BinTcp.col(2) = -Eigen::Vector3d::UnitZ();
  R_BinTcp.col(1) = R_BinTcp.col(2).cross(R_BinTcp.col(0));
  R_BinTcp = R_BinTcp * Eigen::AngleAxisd(-params.tilt, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const double pad_bottom = s.p_Bin.z() + s.radius - params.press_depth;
  // The pads (tool.finger_size.x along the push) must still cover the tube's top.
  const double max_shift = 0.5 * t.tool.finger_size.x() + 0.5 * s.radius;
  const std::vector<Eigen::Vector3d> path = {Eigen::Vector3d::Zero(), plan.distance * direction,
                                             plan.distance * direction + Eigen::Vector3d(0, 0, t.lift)};
  for (double shift = 0.0; shift <= max_shift + 1e-9; shift += 0.002) {
    Eigen::Isometry3d X_BinTcpPress = Eigen::Isometry3d::Identity();
    X_BinTcpPress.linear() = R_BinTcp;
    // The pads' bottom centre (tool.finger_tip_depth along z_Tcp) on the contact point.
    Eigen::Vector3d p_Bin_tip = s.p_Bin + shift * direction;
    p_Bin_tip.z() = pad_bottom;
    X_BinTcpPress.translation() = p_Bin_tip - t.tool.finger_tip_depth * R_BinTcp.col(2);
    if (ToolClearanceProblem(t.cell, t.tool, X_BinTcpPress, 0.0, path)) continue;
    // The closed tool comes down from the transit height and goes back up to it.
    const double rise = std::max(t.lift, t.transit_z - X_BinTcpPress.translation().z());
    const std::optional<double> push = ClearPush(t.closed_tool, X_BinTcpPress, direction, plan.distance,
                                                 params.min_push, rise, obstacles, params.tube_clearance);
    if (!push) continue;
    plan.distance = *push;
    plan.shift = shift;
    plan.X_BinTcpPress = X_BinTcpPress;
    return true;
  }
  return false;
}

}  // namespace

std::vector<Eigen::Vector3d> NudgePushWaypoints(const NudgePlan& plan) {
  const Eigen::Vector3d push = plan.distance * plan.direction;
  return {Eigen::Vector3d::Zero(), push};
}

std::optional<NudgePlan> PlanNudge(const google::protobuf::RepeatedPtrField<v1::Tube>& tubes,
                                   const CellConfig& cell, const ToolGeometry& tool,
                                   const NudgeParams& params, double lift, double transit_z,
                                   std::uint32_t try_index) {
  static constexpr std::array<double, 3> kFractions = {0.5, 0.3, 0.7};
  const double fraction = kFractions[try_index % kFractions.size()];
  const NudgeTools tools{cell, tool, params, ToolBoxes(tool, 0.0), lift, transit_z};
  // Obstacle samples spaced at most one growth of the slab test apart (FirstContact).
  const double obstacle_spacing =
      std::min(params.sample_spacing, params.tube_clearance + 0.5 * cell.tube.radius);
  for (const Candidate& candidate : WallTubes(tubes, cell, params)) {
    const v1::Tube& tube = tubes[candidate.index];
    const std::vector<Sample> others = OtherTubes(tubes, candidate.index, obstacle_spacing, cell.tube.radius);
    const std::vector<Sample> own = SampleTube(tube, obstacle_spacing, cell.tube.radius);
    std::vector<Sample> samples = SampleTube(tube, params.sample_spacing, cell.tube.radius);
    // Contact points along a wall, closest to the wanted fraction first.
    std::stable_sort(samples.begin(), samples.end(), [&](const Sample& a, const Sample& b) {
      return std::abs(a.fraction - fraction) < std::abs(b.fraction - fraction);
    });
    for (const Sample& s : samples) {
      std::optional<NudgePlan> plan = PushAt(s, tube.id(), cell, params);
      if (!plan) continue;
      const std::vector<Sample> own_above = OwnAbove(own, s);
      if (PlacePress(s, tools, Obstacles{others, own_above}, *plan)) return plan;
    }
  }
  return std::nullopt;
}

}  // namespace tubepick::cell
