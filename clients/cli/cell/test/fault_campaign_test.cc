// The totals line of a fault campaign.
#include "clients/cli/cell/fault_campaign.h"

#include <gtest/gtest.h>

namespace tubepick::cli {
namespace {

TEST(FaultCampaign, TubesTheSimulationThrewAreCountedBesideThoseOutside) {
  FaultCampaign campaign;
  SimRoundResult clean;
  clean.run.reason = cell::CellStopReason::kBinEmpty;
  campaign.Add(clean, nullptr);
  EXPECT_EQ(campaign.SummaryLine(),
            "faults: injected=0 safe_stops=0 released_outside=0 lost_in_transit=0 bins_emptied=1/1");

  // A round whose simulation threw two tubes over the walls: outside, and named as thrown.
  SimRoundResult thrown = clean;
  thrown.tubes_elsewhere = 2;
  thrown.runaways = {{.tube = 16, .seconds = 315.8, .speed = 6.0, .angular_speed = 41.0},
                     {.tube = 13, .seconds = 315.9, .speed = 6.9, .angular_speed = 41.0}};
  campaign.Add(thrown, nullptr);
  EXPECT_EQ(campaign.SummaryLine(),
            "faults: injected=0 safe_stops=0 released_outside=2 lost_in_transit=0 bins_emptied=2/2 "
            "thrown_by_simulation=2");
  EXPECT_EQ(campaign.Json(0.05, 1)["thrown_by_simulation"], 2);
}

}  // namespace
}  // namespace tubepick::cli
