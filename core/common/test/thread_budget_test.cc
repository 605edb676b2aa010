#include "core/common/thread_budget.h"

#include <thread>

#include <gtest/gtest.h>

namespace tubepick {
namespace {

TEST(ThreadBudget, CgroupQuotaRoundsUpToWholeCores) {
  EXPECT_EQ(internal::CoresFromCpuMax("max 100000"), 0);
  EXPECT_EQ(internal::CoresFromCpuMax("200000 100000"), 2);
  EXPECT_EQ(internal::CoresFromCpuMax("150000 100000\n"), 2);
  EXPECT_EQ(internal::CoresFromCpuMax("50000 100000"), 1);
  EXPECT_EQ(internal::CoresFromCpuMax(""), 0);
  EXPECT_EQ(internal::CoresFromCpuMax("garbage 100000"), 0);
  EXPECT_EQ(internal::CoresFromCpuMax("100000 0"), 0);
}

TEST(ThreadBudget, CoresAvailableIsWithinTheMachine) {
  const int cores = CoresAvailable();
  EXPECT_GE(cores, 1);
  if (std::thread::hardware_concurrency() > 0) {
    EXPECT_LE(cores, static_cast<int>(std::thread::hardware_concurrency()));
  }
}

TEST(ThreadBudget, ZeroMeansTheAvailableCores) {
  EXPECT_EQ(ResolveThreads(0), CoresAvailable());
  EXPECT_EQ(ResolveThreads(3), 3);
}

}  // namespace
}  // namespace tubepick
