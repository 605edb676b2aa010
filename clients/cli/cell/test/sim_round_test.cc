// What a simulated round says about tubes the simulation threw (devices::sim::SimRunaway).
#include "clients/cli/cell/sim_round.h"

#include <gtest/gtest.h>

namespace tubepick::cli {
namespace {

TEST(SimRound, ARoundWithoutRunawaysSaysNothingOfThem) { EXPECT_EQ(DescribeRunaways({}), ""); }

TEST(SimRound, ThrownTubesAreNamedByGroundTruthIdWithTheirTimeAndSpeeds) {
  // Seed 14 of the 20-pvc-tree bins: two trees thrown just after a resolution rotation had freed them.
  const std::vector<devices::sim::SimRunaway> thrown = {
      {.tube = 16, .seconds = 315.79, .speed = 6.04, .angular_speed = 41.1},
      {.tube = 13, .seconds = 315.87, .speed = 6.9, .angular_speed = 40.5}};
  EXPECT_EQ(DescribeRunaways(thrown),
            "; the simulation threw 2 tubes (a blow-up: where they went is the simulator's doing, not the "
            "controller's): tube 17 at 6.0 m/s, 41 rad/s, 315.8 s, tube 14 at 6.9 m/s, 40 rad/s, 315.9 s");
  EXPECT_EQ(DescribeRunaways({thrown.front()}),
            "; the simulation threw 1 tube (a blow-up: where it went is the simulator's doing, not the "
            "controller's): tube 17 at 6.0 m/s, 41 rad/s, 315.8 s");
}

}  // namespace
}  // namespace tubepick::cli
