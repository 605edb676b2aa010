#include "core/evaluation/virtual_labelling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>

#include "core/common/errors.h"
#include "core/common/tube_graph.h"

namespace tubepick {
namespace {

// A capsule of one modeled tube: a cylinder or a joint.
struct Capsule {
  Eigen::Vector3d a;
  Eigen::Vector3d b;
  double radius;
  std::int32_t tube;
  std::int8_t source;  // 1 joint, 2 cylinder
  Eigen::Vector3d lo;  // bounding box, inflated by radius + tolerance
  Eigen::Vector3d hi;
};

Capsule MakeCapsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius, std::int32_t tube,
                    std::int8_t source, double tolerance) {
  const double reach = radius + tolerance;
  return Capsule{a, b, radius, tube, source, a.cwiseMin(b).array() - reach, a.cwiseMax(b).array() + reach};
}

}  // namespace

double DistanceToSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length2 = ab.squaredNorm();
  if (length2 <= 0.0) return (p - a).norm();
  const double t = std::clamp((p - a).dot(ab) / length2, 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

VirtualLabels LabelVirtualTubes(const Points& points_Bin, const std::vector<std::int32_t>& tube_of_point,
                                const std::vector<Tube>& tubes, const VirtualLabellingParams& params) {
  if (tube_of_point.size() != points_Bin.size()) {
    throw InvalidArgument("virtual labelling: " + std::to_string(tube_of_point.size()) + " tube labels for " +
                          std::to_string(points_Bin.size()) + " points");
  }
  if (!(params.tolerance >= 0.0) || !std::isfinite(params.tolerance)) {
    throw InvalidArgument("virtual labelling: tolerance must be finite and >= 0, got " +
                          std::to_string(params.tolerance));
  }
  std::unordered_map<std::int32_t, std::int32_t> index_of_id;
  for (std::size_t t = 0; t < tubes.size(); ++t) index_of_id[static_cast<std::int32_t>(tubes[t].id)] = t;

  std::vector<Capsule> capsules;
  for (std::size_t t = 0; t < tubes.size(); ++t) {
    for (const AxisPiece& piece : TubeAxisPieces(tubes[t])) {
      const bool joint = piece.cylinder < 0;
      if (joint || params.label_inside_cylinders) {
        capsules.push_back(MakeCapsule(piece.a, piece.b, piece.radius, static_cast<std::int32_t>(t),
                                       joint ? 1 : 2, params.tolerance));
      }
    }
  }

  VirtualLabels out;
  const std::size_t n = points_Bin.size();
  out.tube.assign(n, -1);
  out.cylinder.assign(n, -1);
  out.source.assign(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d p = points_Bin[i].cast<double>();
    if (tube_of_point[i] >= 0) {
      const auto it = index_of_id.find(tube_of_point[i]);
      if (it == index_of_id.end()) {
        throw InvalidArgument("virtual labelling: point " + std::to_string(i) + " names tube id " +
                              std::to_string(tube_of_point[i]) + ", which is not among the " +
                              std::to_string(tubes.size()) + " tubes");
      }
      out.tube[i] = it->second;
      out.source[i] = 0;
      continue;
    }
    double best = std::numeric_limits<double>::infinity();
    for (const Capsule& k : capsules) {
      if ((p.array() < k.lo.array()).any() || (p.array() > k.hi.array()).any()) continue;
      const double d = DistanceToSegment(p, k.a, k.b);
      if (d > k.radius + params.tolerance) continue;
      const double off_surface = std::abs(d - k.radius);
      if (off_surface < best) {  // strict: the first capsule (lowest tube, then order) wins ties
        best = off_surface;
        out.tube[i] = k.tube;
        out.source[i] = k.source;
      }
    }
  }
  // Nearest cylinder of the point's tube (for the per-cylinder purity check).
  for (std::size_t i = 0; i < n; ++i) {
    if (out.tube[i] < 0) continue;
    const Eigen::Vector3d p = points_Bin[i].cast<double>();
    const auto& cyl = tubes[out.tube[i]].cylinders;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t c = 0; c < cyl.size(); ++c) {
      const double d = DistanceToSegment(p, cyl[c].start, cyl[c].end);
      if (d < best) {
        best = d;
        out.cylinder[i] = static_cast<std::int32_t>(c);
      }
    }
  }
  return out;
}

}  // namespace tubepick
