#include "core/evaluation/join_audit.h"

#include <gtest/gtest.h>

#include "core/common/errors.h"

namespace tubepick {
namespace {

Tube ChainOfSegments(std::initializer_list<std::uint32_t> segments) {
  Tube t;
  double x = 0.0;
  for (const std::uint32_t s : segments) {
    Cylinder c;
    c.start = Eigen::Vector3d(x, 0, 0);
    c.end = Eigen::Vector3d(x + 0.05, 0, 0);
    c.radius = 0.0125;
    c.segment_id = s;
    t.cylinders.push_back(c);
    x += 0.06;
  }
  return t;
}

// Segments 0-4: 0 and 1 on real tube 0, 2 and 3 on real tube 1 (3 with a few of tube 0's points),
// 4 background only. Ten points each.
ModelingResult ResultWithSegments(std::vector<std::int32_t>* truth) {
  ModelingResult r;
  const std::int32_t tube_of_segment[5] = {0, 0, 1, 1, -1};
  for (std::int32_t s = 0; s < 5; ++s) {
    for (int i = 0; i < 10; ++i) {
      r.segment_of_point.push_back(s);
      truth->push_back(s == 3 && i < 3 ? 0 : tube_of_segment[s]);
    }
  }
  r.segment_of_point.push_back(-1);  // a point in no segment
  truth->push_back(1);
  return r;
}

TEST(JoinAudit, ADecisionIsRightWhenAllItsChainsAreMostlyOneRealTube) {
  std::vector<std::int32_t> truth;
  ModelingResult r = ResultWithSegments(&truth);
  r.chains = {ChainOfSegments({0}), ChainOfSegments({1}), ChainOfSegments({2}),
              ChainOfSegments({3}), ChainOfSegments({4}), ChainOfSegments({1, 2})};
  using K = JoinDecision::Kind;
  r.join_decisions = {{K::kYPiece, true, {0, 1, 5}},  // tube 0, tube 0, mostly tube 0 (a tie: the lower)
                      {K::kTPiece, true, {2, 3}},     // tube 1 twice: right
                      {K::kTPiece, true, {0, 2}},     // tubes 0 and 1: wrong
                      {K::kLink, false, {2, 3}},      // right, taken back
                      {K::kCompletionLink, false, {1, 4}},  // the background is no tube: wrong
                      {K::kCompletionT, true, {4, 4}}};     // background twice: wrong
  const JoinAudit audit = AuditJoins(r, truth);
  const auto& y = audit.kinds[static_cast<std::size_t>(K::kYPiece)];
  EXPECT_EQ(y.accepted.right, 1u);
  EXPECT_EQ(y.accepted.wrong, 0u);
  const auto& t = audit.kinds[static_cast<std::size_t>(K::kTPiece)];
  EXPECT_EQ(t.accepted.right, 1u);
  EXPECT_EQ(t.accepted.wrong, 1u);
  const auto& link = audit.kinds[static_cast<std::size_t>(K::kLink)];
  EXPECT_EQ(link.refused.right, 1u);
  EXPECT_EQ(link.accepted.right + link.accepted.wrong + link.refused.wrong, 0u);
  EXPECT_EQ(audit.kinds[static_cast<std::size_t>(K::kCompletionLink)].refused.wrong, 1u);
  EXPECT_EQ(audit.kinds[static_cast<std::size_t>(K::kCompletionT)].accepted.wrong, 1u);
  // Chain 5 joins a segment of tube 0 to one of tube 1.
  EXPECT_EQ(audit.chains, 6u);
  EXPECT_EQ(audit.mixed_chains, 1u);

  const std::vector<ChainTruth> chains = TruthOfChains(r, truth);
  EXPECT_EQ(chains[3].tube, 1);  // 7 of its 10 points
  EXPECT_FALSE(chains[3].mixed);
  EXPECT_EQ(chains[4].tube, -1);
  EXPECT_TRUE(chains[5].mixed);

  JoinAudit sum = audit;
  sum += audit;
  EXPECT_EQ(sum.kinds[static_cast<std::size_t>(K::kTPiece)].accepted.wrong, 2u);
  EXPECT_EQ(sum.mixed_chains, 2u);
  EXPECT_FALSE(sum.empty());
}

TEST(JoinAudit, IsEmptyWithoutJunctionJoiningAndRefusesInconsistentInput) {
  std::vector<std::int32_t> truth;
  ModelingResult r = ResultWithSegments(&truth);
  EXPECT_TRUE(AuditJoins(r, {}).empty());  // no decisions: the truth is not looked at
  r.chains = {ChainOfSegments({0}), ChainOfSegments({1})};
  r.join_decisions = {{JoinDecision::Kind::kLink, true, {0, 2}}};
  EXPECT_THROW(AuditJoins(r, truth), InvalidArgument);  // chain 2 does not exist
  r.join_decisions = {{JoinDecision::Kind::kLink, true, {0, 1}}};
  truth.pop_back();
  EXPECT_THROW(AuditJoins(r, truth), InvalidArgument);  // one label short
}

}  // namespace
}  // namespace tubepick
