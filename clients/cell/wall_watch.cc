#include "clients/cell/wall_watch.h"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "core/common/errors.h"
#include "core/common/require.h"
#include "wire/proto_convert.h"

namespace tubepick::cell {
namespace {

/// The wall a tube hangs over at its axis point `p` (its surface `radius` above), or nullopt.
std::optional<std::string> WallAt(const Eigen::Vector3d& p, double radius, const BinConfig& bin,
                                  const WallWatchParams& params) {
  const Eigen::Vector3d& size = bin.inner_size;
  if (p.z() + radius < size.z() - params.below_top) return std::nullopt;
  const std::array<std::pair<double, const char*>, 4> walls = {{{p.x() - 0.5 * size.x(), "+x"},
                                                                {-p.x() - 0.5 * size.x(), "-x"},
                                                                {p.y() - 0.5 * size.y(), "+y"},
                                                                {-p.y() - 0.5 * size.y(), "-y"}}};
  // Signed distance past each inner face (negative inside): the nearest wall within reach.
  const auto nearest = std::max_element(walls.begin(), walls.end(),
                                        [](const auto& a, const auto& b) { return a.first < b.first; });
  if (nearest->first < -params.from_wall) return std::nullopt;
  return std::string(nearest->second);
}

}  // namespace

void WallWatchParams::Validate() const {
  RequireNonNegative(below_top, "wall_watch.below_top");
  RequireNonNegative(from_wall, "wall_watch.from_wall");
  RequirePositive(gone_distance, "wall_watch.gone_distance");
  if (min_points == 0) throw InvalidArgument("wall_watch.min_points: must be at least 1, got 0");
}

std::vector<TubeOverWall> TubesOverWalls(const v1::PlanPickResponse& response, const BinConfig& bin,
                                         std::uint32_t scan, const WallWatchParams& params) {
  std::vector<TubeOverWall> out;
  if (!params.enabled) return out;
  for (const v1::Tube& tube : response.tubes()) {
    std::optional<TubeOverWall> highest;
    for (const v1::Cylinder& c : tube.cylinders()) {
      for (const Eigen::Vector3d& p : {FromProto(c.start()), FromProto(c.end())}) {
        const std::optional<std::string> wall = WallAt(p, std::max(0.0, c.radius()), bin, params);
        if (!wall || (highest && highest->p_Bin.z() >= p.z())) continue;
        highest = TubeOverWall{tube.id(), p, *wall, scan};
      }
    }
    if (highest) out.push_back(*highest);
  }
  return out;
}

std::size_t PointsNear(const devices::Capture& capture, const Eigen::Vector3d& p_Bin, double distance,
                       const BinConfig& bin) {
  // Compared in the capture's frame and unit: a rigid transform keeps distances.
  const double scale = capture.unit == LengthUnit::kMillimetre ? 1000.0 : 1.0;
  const Eigen::Vector3f p = (scale * (capture.X_BinSensor.inverse() * p_Bin)).cast<float>();
  const float r2 = static_cast<float>(scale * distance * scale * distance);
  constexpr double kWallBand = 0.005;
  const Eigen::Vector3d half = 0.5 * bin.inner_size;
  std::size_t n = 0;
  for (const Eigen::Vector3f& q : capture.points_Sensor) {
    if ((q - p).squaredNorm() > r2) continue;
    const Eigen::Vector3d q_Bin = capture.X_BinSensor * (q.cast<double>() / scale);
    const bool at_wall =
        q_Bin.z() <= bin.inner_size.z() + kWallBand &&
        (std::abs(q_Bin.x()) >= half.x() - kWallBand || std::abs(q_Bin.y()) >= half.y() - kWallBand);
    if (!at_wall) ++n;
  }
  return n;
}

std::vector<TubeOverWall> VanishedOverWalls(const std::vector<TubeOverWall>& before,
                                            const devices::Capture& after, const BinConfig& bin,
                                            const std::vector<std::uint32_t>& touched,
                                            const WallWatchParams& params) {
  std::vector<TubeOverWall> out;
  for (const TubeOverWall& tube : before) {
    if (std::find(touched.begin(), touched.end(), tube.tube_id) != touched.end()) continue;
    if (PointsNear(after, tube.p_Bin, params.gone_distance, bin) < params.min_points) out.push_back(tube);
  }
  return out;
}

std::string Describe(const TubeOverWall& tube) {
  return fmt::format("over the {} wall at ({:.3f}, {:.3f}, {:.3f}) m, not seen again after scan {}",
                     tube.wall, tube.p_Bin.x(), tube.p_Bin.y(), tube.p_Bin.z(), tube.scan);
}

}  // namespace tubepick::cell
