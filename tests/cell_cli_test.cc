// `tubepick cell` as a user runs it: the CLI starts tubepick-server itself (--server auto), runs a
// simulated round and prints the thesis' tables.
#include <signal.h>

#include <gtest/gtest.h>

#include <cerrno>
#include <regex>

#include "tests/cli_test_support.h"

namespace tubepick {
namespace {

using testing::RunCli;

TEST(CellCliTest, OneRoundWithAnAutoStartedServerPrintsTheTables) {
  const auto dir = testing::TempDir("cell");
  const auto json_path = dir / "cell.json";
  const auto records_path = dir / "records.jsonl";
  const testing::CliRun run = RunCli("cell --sim --rounds 1 --tubes 2 --seed 5 --json " + json_path.string() +
                                     " --records " + records_path.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("Table 5.4"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("Table 5.9"), std::string::npos);
  EXPECT_NE(run.output.find("round  0 (seed 5): bin empty: 2 tubes picked"), std::string::npos) << run.output;
  std::smatch pid;
  const std::string output = run.output;
  ASSERT_TRUE(std::regex_search(
      output, pid, std::regex("started tubepick-server \\(pid (\\d+)\\) on 127\\.0\\.0\\.1:\\d+")))
      << run.output;
  // The server was stopped (and reaped) before the CLI exited.
  EXPECT_EQ(::kill(std::stoi(pid[1]), 0), -1);
  EXPECT_EQ(errno, ESRCH);

  const nlohmann::json j = testing::ReadJson(json_path);
  EXPECT_EQ(j["statistics"]["bins_emptied"], 1);
  EXPECT_EQ(j["statistics"]["picks"], 2);
  EXPECT_EQ(j["rounds"][0]["tubes_left"], 0);
  const std::string records = testing::ReadText(records_path);
  EXPECT_NE(records.find("\"result\":\"picked\""), std::string::npos);
  EXPECT_NE(records.find("\"type\":\"end\""), std::string::npos);
}

TEST(CellCliTest, UnreachableServerEndsInASafeStopAndExitStatus3) {
  const testing::CliRun run = RunCli("cell --sim --rounds 2 --tubes 1 --server 127.0.0.1:1");
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_NE(run.output.find("SAFE STOP: planner server_unavailable during plan"), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("the remaining rounds are skipped"), std::string::npos) << run.output;
}

TEST(CellCliTest, WithoutSimItSaysWhy) {
  const testing::CliRun run = RunCli("cell --rounds 1");
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("--sim is required"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace tubepick
