// The room past a chain's free end (EndRoom).
//
// Unfitted surface: the unfitted points binned into cells of link_distance (a cell's node is its
// points' mean); a walk from the cells next to the end over touching cells, kept to a corridor
// around the end's extended axis; the furthest node reached, measured along the axis.
// Free space: probes along the extended axis; the first one at which the range image shows no
// surface in front of it (the scanner looked past the place the tube would take) ends the room.

#include "core/modeling/end_room.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <unordered_map>

#include "core/common/errors.h"
#include "core/common/grid_cell_key.h"
#include "core/common/require.h"

namespace tubepick {
namespace {

// How far free space is probed: beyond the longest reach junction joining gives an end.
constexpr double kFreeSpaceHorizon = 0.2;

// The unfitted points on a grid of link_distance cells, each occupied cell one node at the mean
// of its points; cells touching (26-neighbourhood) are one surface.
class UnfittedWalk {
 public:
  UnfittedWalk(const Points& unfitted, const EndRoomParams& params)
      : params_(params), cell_(params.link_distance) {
    std::vector<Eigen::Vector3d> sum;
    std::vector<int> count;
    for (const Eigen::Vector3f& p : unfitted) {
      if (!p.allFinite()) continue;
      const auto [it, added] =
          id_.try_emplace(Key(CellOf(p.cast<double>())), static_cast<std::uint32_t>(sum.size()));
      if (added) {
        sum.emplace_back(Eigen::Vector3d::Zero());
        count.push_back(0);
      }
      sum[it->second] += p.cast<double>();
      ++count[it->second];
    }
    centre_.resize(sum.size());
    for (std::size_t k = 0; k < sum.size(); ++k) centre_[k] = sum[k] / count[k];
    stamp_.assign(centre_.size(), 0);
  }

  double Measure(const FreeEnd& ray) {
    ++walk_;
    const double lateral_limit = ray.radius + params_.corridor;
    double furthest = 0.0;
    std::vector<std::uint32_t> stack;
    auto visit = [&](const Eigen::Vector3i& cell) {
      const auto it = id_.find(Key(cell));
      if (it == id_.end() || stamp_[it->second] == walk_) return;
      stamp_[it->second] = walk_;
      const Eigen::Vector3d d = centre_[it->second] - ray.p;
      const double along = d.dot(ray.out);
      if (along < -ray.radius || along > params_.max_unfitted) return;
      if ((d - along * ray.out).norm() > lateral_limit) return;
      furthest = std::max(furthest, along);
      stack.push_back(it->second);
    };
    // Seeds: the occupied cells whose points' mean lies within attach_distance of the end.
    const Eigen::Vector3i c = CellOf(ray.p);
    const int r = static_cast<int>(std::ceil(params_.attach_distance / cell_));
    for (int dx = -r; dx <= r; ++dx) {
      for (int dy = -r; dy <= r; ++dy) {
        for (int dz = -r; dz <= r; ++dz) {
          const Eigen::Vector3i cell = c + Eigen::Vector3i(dx, dy, dz);
          const auto it = id_.find(Key(cell));
          if (it != id_.end() && (centre_[it->second] - ray.p).norm() <= params_.attach_distance) visit(cell);
        }
      }
    }
    while (!stack.empty()) {
      const Eigen::Vector3i cell = CellOf(centre_[stack.back()]);
      stack.pop_back();
      for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dz = -1; dz <= 1; ++dz) visit(cell + Eigen::Vector3i(dx, dy, dz));
        }
      }
    }
    return furthest;
  }

 private:
  Eigen::Vector3i CellOf(const Eigen::Vector3d& p) const {
    return (p / cell_).array().floor().cast<int>().matrix();
  }
  static std::uint64_t Key(const Eigen::Vector3i& c) { return GridCellKey(c.x(), c.y(), c.z()); }

  const EndRoomParams& params_;
  double cell_;
  std::unordered_map<std::uint64_t, std::uint32_t> id_;
  std::vector<Eigen::Vector3d> centre_;
  std::vector<std::uint32_t> stamp_;
  std::uint32_t walk_ = 0;
};

double FreeSpaceAhead(const RangeImage& seen, const FreeEnd& ray, const EndRoomParams& params) {
  double t = params.free_space_step;
  for (; t <= kFreeSpaceHorizon; t += params.free_space_step) {
    const Eigen::Vector3d q = ray.p + t * ray.out;
    if (!seen.IsPointCovered(q, static_cast<int>(params.free_space_window), -params.free_space_tolerance)) {
      return t;
    }
  }
  return t;
}

}  // namespace

FreeEnd FreeEndOf(const Tube& chain, bool at_end) {
  const Cylinder& c = at_end ? chain.cylinders.back() : chain.cylinders.front();
  return at_end ? FreeEnd{c.end, c.axis(), c.radius} : FreeEnd{c.start, -c.axis(), c.radius};
}

void EndRoomParams::Validate(const char* prefix) const {
  const std::string p = prefix;
  RequireNonNegative(max_unfitted, p + ".max_unfitted");
  RequireNonNegative(attach_distance, p + ".attach_distance");
  RequirePositive(link_distance, p + ".link_distance");
  RequireNonNegative(corridor, p + ".corridor");
  RequirePositive(free_space_step, p + ".free_space_step");
  RequireNonNegative(free_space_tolerance, p + ".free_space_tolerance");
  if (free_space_window > 100) {
    throw InvalidArgument(p + ".free_space_window: " + std::to_string(free_space_window) +
                          " pixels is out of range [0, 100]");
  }
}

EndRooms MeasureEndRooms(const Points& unfitted, const std::vector<Tube>& chains, const EndRoomParams& params,
                         const RangeImage* seen) {
  params.Validate("modeling.junctions.end_room");
  EndRooms rooms(chains.size());
  const bool walk_unfitted = params.max_unfitted > 0.0 && !unfitted.empty();
  const bool check_free = params.free_space_check && seen != nullptr;
  if (!walk_unfitted && !check_free) return rooms;
  std::optional<UnfittedWalk> walk;
  if (walk_unfitted) walk.emplace(unfitted, params);
  for (std::size_t c = 0; c < chains.size(); ++c) {
    if (chains[c].cylinders.empty() || chains[c].branched()) continue;
    for (const bool at_end : {false, true}) {
      const FreeEnd ray = FreeEndOf(chains[c], at_end);
      EndRoom& room = rooms[c][at_end ? 1 : 0];
      if (walk) room.unfitted = walk->Measure(ray);
      if (check_free) room.free = FreeSpaceAhead(*seen, ray, params);
    }
  }
  return rooms;
}

}  // namespace tubepick
