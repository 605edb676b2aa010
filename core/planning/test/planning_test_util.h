#pragma once

// Hand-built tube models shared by the planning tests.

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "core/common/types.h"

namespace tubepick {
namespace testing_planning {

constexpr double kR = 0.0125;  // tube radius, metres

inline Cylinder MakeCylinder(const Eigen::Vector3d& start, const Eigen::Vector3d& end, std::uint32_t segment,
                             double radius = kR) {
  Cylinder c;
  c.start = start;
  c.end = end;
  c.radius = radius;
  c.segment_id = segment;
  return c;
}

// A cylinder lying at height z (axis height) from (x0, y0) to (x1, y1).
inline Cylinder FlatCylinder(double x0, double y0, double x1, double y1, std::uint32_t segment,
                             double z = kR) {
  return MakeCylinder({x0, y0, z}, {x1, y1, z}, segment);
}

inline Tube MakeTube(std::uint32_t id, std::vector<Cylinder> cylinders) {
  Tube t;
  t.id = id;
  t.cylinders = std::move(cylinders);
  return t;
}

// Two crossing tubes: tube 0 along y on top (z = 3r, one segment, non-occluded); tube 1 along x
// on the floor, seen as two segments split by tube 0 (one occluded joint from x = −0.02 to 0.02).
inline std::vector<Tube> CrossingTubes() {
  return {MakeTube(0, {FlatCylinder(0.0, -0.2, 0.0, 0.2, 7, 3.0 * kR)}),
          MakeTube(1, {FlatCylinder(-0.2, 0.0, -0.02, 0.0, 1), FlatCylinder(0.02, 0.0, 0.2, 0.0, 2)})};
}

}  // namespace testing_planning
}  // namespace tubepick
