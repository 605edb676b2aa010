#include "core/planning/plan_certainty.h"

#include <algorithm>
#include <cassert>

#include "core/common/segment_geometry.h"
#include "core/common/tube_graph.h"

namespace tubepick {
namespace {

struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300);
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-1e300);
};

Box BoundsOf(const std::vector<AxisPiece>& pieces, double pad) {
  Box box;
  for (const AxisPiece& p : pieces) {
    box.lo = box.lo.cwiseMin(p.a.cwiseMin(p.b) - Eigen::Vector3d::Constant(p.radius + pad));
    box.hi = box.hi.cwiseMax(p.a.cwiseMax(p.b) + Eigen::Vector3d::Constant(p.radius + pad));
  }
  return box;
}

bool Overlap(const Box& a, const Box& b) {
  return (a.lo.array() <= b.hi.array()).all() && (b.lo.array() <= a.hi.array()).all();
}

// `upper` lies on `lower` somewhere along their axes.
bool LiesOn(const std::vector<AxisPiece>& upper, const std::vector<AxisPiece>& lower, double margin) {
  for (const AxisPiece& u : upper) {
    for (const AxisPiece& l : lower) {
      const double contact = u.radius + l.radius;
      const SegmentClosestPoints c = ClosestPointsOfSegments(l.a, l.b, u.a, u.b);
      if (c.distance > contact + margin) continue;
      const Eigen::Vector3d p_lower = l.a + c.s * (l.b - l.a);
      const Eigen::Vector3d p_upper = u.a + c.t * (u.b - u.a);
      if (p_upper.z() - p_lower.z() >= 0.5 * contact) return true;
    }
  }
  return false;
}

}  // namespace

std::string ToString(PlanCertainty certainty) {
  switch (certainty) {
    case PlanCertainty::kSure:
      return "sure";
    case PlanCertainty::kSimulated:
      return "simulated";
    case PlanCertainty::kUnsure:
      return "unsure";
  }
  return "unknown";
}

std::vector<std::uint32_t> TubesLyingOn(const std::vector<Tube>& tubes, std::size_t t,
                                        const CertaintyParams& params) {
  assert(t < tubes.size());
  const std::vector<AxisPiece> lower = TubeAxisPieces(tubes[t]);
  const Box lower_box = BoundsOf(lower, params.contact_margin);
  std::vector<std::uint32_t> on;
  for (std::size_t u = 0; u < tubes.size(); ++u) {
    if (u == t) continue;
    const std::vector<AxisPiece> upper = TubeAxisPieces(tubes[u]);
    if (!Overlap(lower_box, BoundsOf(upper, 0.0))) continue;
    if (LiesOn(upper, lower, params.contact_margin)) on.push_back(static_cast<std::uint32_t>(u));
  }
  return on;
}

}  // namespace tubepick
