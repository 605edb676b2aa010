// `tubepick cell` as a user runs it: the CLI starts tubepick-server itself (--server auto), runs a
// simulated round and prints the thesis' tables.
#include <signal.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

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
  // The simulated bin held --tubes: both placed, none unaccounted for.
  EXPECT_EQ(j["rounds"][0]["tubes_expected"], 2);
  EXPECT_EQ(j["rounds"][0]["tubes_unaccounted"], 0);
  EXPECT_EQ(j["statistics"]["tubes_unaccounted"], 0);
  EXPECT_NE(run.output.find("bin empty, tubes unaccounted for        0 (1 of 1 rounds counted)"),
            std::string::npos)
      << run.output;
  const std::string records = testing::ReadText(records_path);
  EXPECT_NE(records.find("\"result\":\"picked\""), std::string::npos);
  EXPECT_NE(records.find("\"type\":\"end\""), std::string::npos);
}

// A full disk under --records (/dev/full: every write fails with ENOSPC) does not stop the cell:
// the bin is emptied, the run says how many records were lost and why, and exits 6.
TEST(CellCliTest, RecordsThatCannotBeWrittenDoNotStopTheCellButExit6) {
  const testing::CliRun run = RunCli("cell --sim --rounds 1 --tubes 1 --seed 3 --records /dev/full");
  EXPECT_EQ(run.exit_code, 6) << run.output;
  EXPECT_NE(run.output.find("round  0 (seed 3): bin empty: 1 tube picked"), std::string::npos) << run.output;
  EXPECT_TRUE(
      std::regex_search(run.output, std::regex("records: /dev/full: ([2-9]|\\d\\d+) of \\1 records could "
                                               "not be written \\(No space left on device\\)")))
      << run.output;
  EXPECT_EQ(run.output.find("SAFE STOP"), std::string::npos) << run.output;
}

// --json on a full disk is an error, not "wrote /dev/full".
TEST(CellCliTest, AJsonReportThatCannotBeWrittenIsAnError) {
  const testing::CliRun run = RunCli("cell --sim --rounds 1 --tubes 1 --seed 3 --json /dev/full");
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("--json /dev/full: error writing (disk full?)"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("wrote /dev/full"), std::string::npos) << run.output;
}

// The records of a run, each without its durations (wall and device times).
std::vector<nlohmann::json> RecordsWithoutTimes(const std::filesystem::path& path) {
  std::vector<nlohmann::json> records;
  std::istringstream lines(testing::ReadText(path));
  for (std::string line; std::getline(lines, line);) {
    nlohmann::json record = nlohmann::json::parse(line);
    record.erase("durations");
    records.push_back(std::move(record));
  }
  return records;
}

// Same seed, same round: the simulated cell (rubber hoses, their lifts simulated by the planner
// too), the planner and the controller draw only seeded randomness, so a round run alone twice,
// or after another round, writes the same records field by field, times aside.
TEST(CellCliTest, ARoundIsTheSameWhetherRunAgainOrAfterAnotherRound) {
  const auto dir = testing::TempDir("cell-repeat");
  const std::string round = "cell --sim --tubes 2 --material rubber --shapes C --records ";
  const testing::CliRun first = RunCli(round + (dir / "a.jsonl").string() + " --seed 4 --rounds 1");
  const testing::CliRun again = RunCli(round + (dir / "b.jsonl").string() + " --seed 4 --rounds 1");
  const testing::CliRun after = RunCli(round + (dir / "c.jsonl").string() + " --seed 3 --rounds 2");
  ASSERT_EQ(first.exit_code, 0) << first.output;
  ASSERT_EQ(again.exit_code, 0) << again.output;
  ASSERT_EQ(after.exit_code, 0) << after.output;
  const std::vector<nlohmann::json> a = RecordsWithoutTimes(dir / "a.jsonl");
  const std::vector<nlohmann::json> b = RecordsWithoutTimes(dir / "b.jsonl");
  std::vector<nlohmann::json> c;
  for (nlohmann::json record : RecordsWithoutTimes(dir / "c.jsonl")) {
    if (record["round"] != 1) continue;
    record["round"] = 0;
    c.push_back(std::move(record));
  }
  ASSERT_GE(a.size(), 3u);  // two picks at least, and the end
  const auto simulated = std::count_if(
      a.begin(), a.end(), [](const nlohmann::json& r) { return r.value("used_simulation", false); });
  EXPECT_GE(simulated, 1) << "no lift of this round was simulated: pick a round that simulates";
  EXPECT_EQ(a, b);
  EXPECT_EQ(a, c);
  std::filesystem::remove_all(dir);
}

TEST(CellCliTest, UnreachableServerEndsInASafeStopAndExitStatus3) {
  const testing::CliRun run = RunCli("cell --sim --rounds 2 --tubes 1 --server 127.0.0.1:1");
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_NE(run.output.find("SAFE STOP: planner server_unavailable during plan"), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("the remaining rounds are skipped"), std::string::npos) << run.output;
}

// A small fault campaign: faults at random moments of the state machine, place included; what
// must never happen is a tube at rest outside the bin and the place zone.
TEST(CellCliTest, FaultCampaignNeverReleasesATubeOutsideTheBinOrThePlaceZone) {
  const auto dir = testing::TempDir("cell-faults");
  const auto json_path = dir / "campaign.json";
  // Seed 2 at this rate brings (deterministically: faults follow the controller's steps) a slip in
  // transit, safe stops holding a tube and a planner outage while one is held.
  const testing::CliRun run = RunCli(
      "cell --sim --rounds 4 --tubes 7 --inject-faults 0.1 --fault-seed 2 --json " + json_path.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::smatch m;
  const std::string output = run.output;
  ASSERT_TRUE(
      std::regex_search(output, m,
                        std::regex("faults: injected=(\\d+) safe_stops=(\\d+) released_outside=(\\d+) "
                                   "lost_in_transit=(\\d+) bins_emptied=(\\d+)/4\n")))
      << run.output;
  EXPECT_GT(std::stoi(m[1]), 0);
  EXPECT_EQ(m[3], "0");
  const nlohmann::json j = testing::ReadJson(json_path);
  const nlohmann::json& faults = j["faults"];
  EXPECT_EQ(faults["rounds"], 4);
  EXPECT_EQ(faults["released_outside"], 0);
  EXPECT_EQ(faults["injected"], std::stoi(m[1]));
  int by_kind = 0;
  for (const auto& [kind, count] : faults["by_kind"].items()) by_kind += count.get<int>();
  EXPECT_EQ(by_kind, faults["injected"].get<int>());
  EXPECT_EQ(faults["by_kind"].value("slip", 0), 1);
  EXPECT_EQ(faults["lost_in_transit"], 1);
  EXPECT_GE(faults["safe_stops_holding"].get<int>(), 1);
  EXPECT_GE(faults["local_analyses"].get<int>(), 1);
  int elsewhere = 0;
  for (const nlohmann::json& round : j["rounds"]) elsewhere += round["released_outside"].get<int>();
  EXPECT_EQ(elsewhere, 0);
}

TEST(CellCliTest, TubesHeavierThanTheCellSaysAreNamedInTheRoundLine) {
  // The simulated PVC tubes weigh 0.080 kg where the cell says 0.055 kg: each lift weighs about 1.45
  // tubes, and the round's line and JSON say the lifts doubt tube.mass.
  const auto dir = testing::TempDir("cell_mass");
  const auto json_path = dir / "cell.json";
  const testing::CliRun run =
      RunCli("cell --sim --rounds 1 --tubes 3 --seed 1 --sim-tube-mass 0.08 --json " + json_path.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("the lifts doubt tube.mass after"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("times tube.mass (0.055 kg)"), std::string::npos) << run.output;
  const nlohmann::json j = testing::ReadJson(json_path);
  EXPECT_GE(j["rounds"][0]["tube_mass_doubts"].get<int>(), 1);
  EXPECT_NE(j["rounds"][0]["tube_mass_doubt"].get<std::string>().find("is tube.mass right?"),
            std::string::npos);
}

TEST(CellCliTest, TubesTenTimesLighterThanTheCellSaysAreNamedThoughEveryLiftReadsNone) {
  // The simulated PVC tubes weigh 0.0055 kg where the cell says 0.055 kg (grams taken for a tenth):
  // every lift reads about a tenth of a tube, Algorithm 3's "none", while the gripper holds a tube. The
  // round stops at its attempt limit, and its line says why.
  const testing::CliRun run = RunCli("cell --sim --rounds 1 --tubes 3 --seed 1 --sim-tube-mass 0.0055");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("attempt limit reached"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("the lifts doubt tube.mass after"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("though the gripper held something each time: is tube.mass right?"),
            std::string::npos)
      << run.output;
}

TEST(CellCliTest, AResolutionVariantThatIsNotOneIsRefusedWithTheNames) {
  const testing::CliRun run = RunCli("cell --sim --rounds 1 --resolution sideways");
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("--resolution: unknown variant 'sideways' (unspecified, torque_axis, "),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("torque_axis_then_perpendicular)"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("round "), std::string::npos) << run.output;  // refused before any round
}

TEST(CellCliTest, ASimulatedTubeMassOnlyWithSimAndPositive) {
  const testing::CliRun without_sim = RunCli("cell --rounds 1 --sim-tube-mass 0.08");
  EXPECT_NE(without_sim.exit_code, 0) << without_sim.output;
  EXPECT_NE(without_sim.output.find("--sim-tube-mass requires --sim"), std::string::npos)
      << without_sim.output;
  const testing::CliRun zero = RunCli("cell --sim --rounds 1 --sim-tube-mass 0");
  EXPECT_NE(zero.exit_code, 0) << zero.output;
  EXPECT_NE(zero.output.find("--sim-tube-mass: Value 0 not in range"), std::string::npos) << zero.output;
}

TEST(CellCliTest, LoadRefusesANegativeSettlingTime) {
  // `tubepick load`'s new option, checked before any connection is tried.
  const testing::CliRun run = RunCli("load --target 127.0.0.1:1 --clouds . --duration 1 --rss-settle -1");
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("--rss-settle: Value -1 not in range"), std::string::npos) << run.output;
}

TEST(CellCliTest, InjectedFaultRateOutsideZeroToOneIsRefused) {
  const testing::CliRun run = RunCli("cell --sim --rounds 1 --inject-faults 5");
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("--inject-faults: a probability per state in [0, 1], got 5"), std::string::npos)
      << run.output;
}

TEST(CellCliTest, WithoutSimOrDevicesItSaysWhichCellIsMissing) {
  const testing::CliRun run = RunCli("cell --rounds 1");
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("which cell? --devices FILE for a real cell"), std::string::npos) << run.output;
}

void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

TEST(CellCliTest, TheShippedControllerExampleIsWhatTheCommandPrints) {
  const testing::CliRun run = RunCli("cell --print-controller-config");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.output, testing::ReadText(std::filesystem::path(TUBEPICK_SOURCE_DIR) / "deploy" /
                                          "cell-controller.example.yaml"))
      << "regenerate deploy/cell-controller.example.yaml with `tubepick cell --print-controller-config`";
}

TEST(CellCliTest, PrintedControllerConfigIsAcceptedBackByController) {
  const auto dir = testing::TempDir("cell_controller");
  const testing::CliRun defaults = RunCli("cell --print-controller-config");
  ASSERT_EQ(defaults.exit_code, 0) << defaults.output;
  // Durations in seconds; the command's own --plan-deadline default (300 s) is part of it.
  EXPECT_NE(defaults.output.find("robot_timeout: 60"), std::string::npos) << defaults.output;
  EXPECT_NE(defaults.output.find("plan_deadline: 300"), std::string::npos) << defaults.output;

  const auto path = dir / "controller.yaml";
  WriteText(path, defaults.output);
  const testing::CliRun back = RunCli("cell --controller " + path.string() + " --print-controller-config");
  ASSERT_EQ(back.exit_code, 0) << back.output;
  EXPECT_EQ(back.output, defaults.output);

  // A changed value is used; an option given on the command line overrides the file.
  std::string text = defaults.output;
  const std::string lift = "lift_speed: 0.1";
  ASSERT_NE(text.find(lift), std::string::npos);
  text.replace(text.find(lift), lift.size(), "lift_speed: 0.2");
  WriteText(path, text);
  const testing::CliRun changed =
      RunCli("cell --controller " + path.string() + " --plan-deadline 42 --print-controller-config");
  ASSERT_EQ(changed.exit_code, 0) << changed.output;
  EXPECT_NE(changed.output.find("lift_speed: 0.2"), std::string::npos) << changed.output;
  EXPECT_NE(changed.output.find("plan_deadline: 42"), std::string::npos) << changed.output;
}

TEST(CellCliTest, ControllerFileWithAnUnknownKeyExits2NamingTheKeyPath) {
  const auto dir = testing::TempDir("cell_controller_bad");
  const auto path = dir / "controller.yaml";
  WriteText(path, "lift_speed: 0.2\nnudge:\n  max_psh: 0.3\n");
  const testing::CliRun run = RunCli("cell --sim --rounds 1 --controller " + path.string());
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("nudge.max_psh"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(path.string()), std::string::npos) << run.output;
  // Nothing was started.
  EXPECT_EQ(run.output.find("started tubepick-server"), std::string::npos) << run.output;

  WriteText(path, "robot_timeout: 0\n");
  const testing::CliRun zero = RunCli("cell --sim --rounds 1 --controller " + path.string());
  EXPECT_EQ(zero.exit_code, 2) << zero.output;
  EXPECT_NE(zero.output.find("robot_timeout: must be positive"), std::string::npos) << zero.output;

  // A tube count other than the simulated bins': both named.
  WriteText(path, "tubes_per_bin: 14\n");
  const testing::CliRun count = RunCli("cell --sim --rounds 1 --tubes 7 --controller " + path.string());
  EXPECT_EQ(count.exit_code, 2) << count.output;
  EXPECT_NE(count.output.find("tubes_per_bin: 14 in the controller config, but --tubes 7"), std::string::npos)
      << count.output;
}

TEST(CellCliTest, CellFileWithAnUnknownKeyExits2NamingTheKeyPath) {
  const auto dir = testing::TempDir("cell_file_bad");
  const auto path = dir / "cell.yaml";
  WriteText(path, "bin:\n  inner_sise: [0.8, 0.6, 0.2]\n");
  const testing::CliRun run = RunCli("cell --sim --rounds 1 --cell " + path.string());
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("bin.inner_sise"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("started tubepick-server"), std::string::npos) << run.output;
}

TEST(CellCliTest, OneRoundWithACellFileAndAControllerFile) {
  const auto dir = testing::TempDir("cell_files");
  const auto cell_path = dir / "cell.yaml";
  // A larger, deeper bin than the thesis cell, with the thesis' PVC tubes.
  WriteText(cell_path,
            "bin:\n  inner_size: [0.9, 0.7, 0.25]\n"
            "tube:\n  radius: 0.0125\n  length: 0.5\n  mass: 0.055\n");
  const auto controller_path = dir / "controller.yaml";
  WriteText(controller_path, "max_attempts_per_bin: 8\ntransit_clearance: 0.25\n");
  const testing::CliRun run = RunCli("cell --sim --rounds 1 --tubes 1 --seed 3 --cell " + cell_path.string() +
                                     " --controller " + controller_path.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("round  0 (seed 3): bin empty: 1 tube picked"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace tubepick
