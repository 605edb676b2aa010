#include "core/modeling/end_room.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/cell_config.h"
#include "core/common/errors.h"

namespace tubepick {
namespace {

using ::testing::HasSubstr;
constexpr double kR = 0.0125;
constexpr double kPi = 3.14159265358979323846;

// A chain of one cylinder along x from the origin to x = 0.10, on the floor.
std::vector<Tube> ChainAlongX() {
  Tube t;
  Cylinder c;
  c.start = {0.0, 0.0, kR};
  c.end = {0.10, 0.0, kR};
  c.radius = kR;
  t.cylinders = {c};
  return {t};
}

// Points of the upper half of a tube's surface along x over [x0, x1], 4 mm apart along it.
Points UpperSurface(double x0, double x1, double y = 0.0) {
  Points out;
  for (double x = x0; x <= x1 + 1e-9; x += 0.004) {
    for (int k = 0; k <= 6; ++k) {
      const double a = kPi * k / 6.0;
      out.emplace_back(static_cast<float>(x), static_cast<float>(y + kR * std::cos(a)),
                       static_cast<float>(kR + kR * std::sin(a)));
    }
  }
  return out;
}

// A horizontal patch at height z over [x0, x1] × [−0.03, 0.03], 2 mm apart.
Points Patch(double x0, double x1, double z) {
  Points out;
  for (double x = x0; x <= x1 + 1e-9; x += 0.002) {
    for (double y = -0.03; y <= 0.03 + 1e-9; y += 0.002)
      out.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
  }
  return out;
}

EndRoomParams UnfittedOnly() {
  EndRoomParams p;
  p.free_space_check = false;
  return p;
}

TEST(EndRooms, UnfittedSurfacePastAnEndIsItsRoom) {
  // The tube goes on, unfitted, 5 cm past the cylinder's end at x = 0.10.
  const EndRooms rooms = MeasureEndRooms(UpperSurface(0.10, 0.15), ChainAlongX(), UnfittedOnly(), nullptr);
  ASSERT_EQ(rooms.size(), 1u);
  // Measured at the mean of each 12 mm cell's points: within a cell of the truth.
  EXPECT_NEAR(rooms[0][1].unfitted, 0.05, 0.008);
  EXPECT_EQ(rooms[0][0].unfitted, 0.0);       // nothing past the start at x = 0
  EXPECT_TRUE(std::isinf(rooms[0][1].free));  // free space not checked
}

TEST(EndRooms, TheWalkStopsAtAGapAtTheCapAndOutsideTheCorridor) {
  // A 3 cm gap (wider than two cells) ends the surface at x = 0.13.
  Points broken = UpperSurface(0.10, 0.13);
  const Points far_side = UpperSurface(0.16, 0.20);
  broken.insert(broken.end(), far_side.begin(), far_side.end());
  EXPECT_NEAR(MeasureEndRooms(broken, ChainAlongX(), UnfittedOnly(), nullptr)[0][1].unfitted, 0.03, 0.008);
  // A long surface counts up to max_unfitted.
  EXPECT_NEAR(
      MeasureEndRooms(UpperSurface(0.10, 0.30), ChainAlongX(), UnfittedOnly(), nullptr)[0][1].unfitted, 0.08,
      0.008);
  // A tube lying beside the end, 5 cm off the axis (outside radius + corridor), is not its room.
  EXPECT_EQ(
      MeasureEndRooms(UpperSurface(0.08, 0.20, 0.05), ChainAlongX(), UnfittedOnly(), nullptr)[0][1].unfitted,
      0.0);
}

TEST(EndRooms, FreeSpaceEndsWhereTheScannerSawPastTheAxis) {
  // Seen from the default mount (1.1 m above, looking down): a tube on top covers x in
  // [0.10, 0.16] at 5 cm; beyond it the scanner sees the floor, below the branch's axis.
  Points cloud = Patch(0.10, 0.16, 0.05);
  const Points floor = Patch(0.0, 0.30, 0.0);
  cloud.insert(cloud.end(), floor.begin(), floor.end());
  const RangeImage seen(cloud, SensorConfig::DefaultX_BinSensor(), 0.002);
  EndRoomParams params;
  params.max_unfitted = 0.0;
  const EndRooms rooms = MeasureEndRooms({}, ChainAlongX(), params, &seen);
  // The first free probe lies past the cover by up to the pixel window (about 4.4 mm) and a step.
  EXPECT_GT(rooms[0][1].free, 0.06);
  EXPECT_LE(rooms[0][1].free, 0.075 + 1e-9);
  // Past the start (x < 0) the floor alone: the first probe is free.
  EXPECT_LE(rooms[0][0].free, params.free_space_step + 1e-9);
  // The tube's own visible top surface (a radius above its axis) does not end the room.
  Points own = Patch(0.10, 0.20, 2 * kR);
  own.insert(own.end(), floor.begin(), floor.end());
  const RangeImage seen_own(own, SensorConfig::DefaultX_BinSensor(), 0.002);
  EXPECT_GT(MeasureEndRooms({}, ChainAlongX(), params, &seen_own)[0][1].free, 0.10);
}

TEST(EndRooms, ParametersAreValidatedWithTheirKeys) {
  EndRoomParams params;
  params.link_distance = 0.0;
  EXPECT_THAT(
      [&] { MeasureEndRooms({}, ChainAlongX(), params, nullptr); },
      ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("modeling.junctions.end_room.link_distance")));
  params = EndRoomParams{};
  params.free_space_window = 500;
  EXPECT_THAT([&] { params.Validate("x"); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("x.free_space_window: 500")));
}

}  // namespace
}  // namespace tubepick
