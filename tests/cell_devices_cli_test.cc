// `tubepick cell --devices` and `tubepick devices check` as an integrator runs them, against
// `tubepick virtual-cell`: the simulated cell behind the real protocols (HSES and RDT on UDP,
// Modbus RTU on a pseudo-terminal, an exec scanner), driven by the real drivers. And the operator's
// Ctrl-C: the round ends in the safe stop, the private server goes with the command.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <thread>
#include <vector>

#include "tests/cli_test_support.h"

namespace tubepick {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::RunCli;

/// `tubepick ARGS` (or another binary) in the background, stdout and stderr into a file.
class BackgroundCli {
 public:
  BackgroundCli(const std::vector<std::string>& args, const fs::path& log,
                const std::string& binary = TUBEPICK_CLI)
      : log_(log) {
    std::vector<std::string> argv_strings{binary};
    argv_strings.insert(argv_strings.end(), args.begin(), args.end());
    pid_ = ::fork();
    if (pid_ == 0) {
      const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, STDOUT_FILENO);
      ::dup2(fd, STDERR_FILENO);
      std::vector<char*> argv;
      for (std::string& a : argv_strings) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
  }
  ~BackgroundCli() {
    if (pid_ > 0 && !exited_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  pid_t pid() const { return pid_; }
  std::string Output() const { return testing::ReadText(log_); }
  /// Waits until the output matches `pattern`; the match, or "" after `timeout`.
  std::string WaitFor(const std::string& pattern, std::chrono::seconds timeout) const {
    const std::regex re(pattern);
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      std::smatch m;
      const std::string out = Output();
      if (std::regex_search(out, m, re)) return m.str(m.size() > 1 ? 1 : 0);
      std::this_thread::sleep_for(50ms);
    }
    return "";
  }
  void Signal(int signo) const { ::kill(pid_, signo); }
  /// The exit status, or -1 after `timeout`.
  int Wait(std::chrono::seconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(20ms);
    }
    return -1;
  }

 private:
  fs::path log_;
  pid_t pid_ = -1;
  bool exited_ = false;
};

/// A process that is gone or a zombie nobody reaped yet (it no longer runs).
bool Gone(pid_t pid) {
  if (::kill(pid, 0) != 0) return true;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  std::getline(stat, text);
  const auto close = text.rfind(')');
  return close != std::string::npos && close + 2 < text.size() && text[close + 2] == 'Z';
}

struct VirtualCell {
  explicit VirtualCell(const fs::path& dir, int tubes, int seed)
      : devices(dir / "devices.yaml"),
        cli({"virtual-cell", "--tubes", std::to_string(tubes), "--material", "pvc", "--seed",
             std::to_string(seed), "--devices-out", devices.string()},
            dir / "virtual-cell.log") {}
  bool Ready() const { return !cli.WaitFor("virtual-cell: ready", 60s).empty(); }
  /// SIGTERM, then the last line's counts.
  std::string Stop() {
    cli.Signal(SIGTERM);
    exit_code = cli.Wait(60s);
    return cli.WaitFor("(virtual-cell: tubes_in_bin=\\d+ placed=\\d+ outside=\\d+)", 1s);
  }
  fs::path devices;
  BackgroundCli cli;
  int exit_code = -1;
};

TEST(VirtualCellTest, CheckThenOneRoundThroughTheRealDriversEmptiesTheBin) {
  const auto dir = testing::TempDir("virtual_cell_round");
  VirtualCell cell(dir, 4, 3);
  ASSERT_TRUE(cell.Ready()) << cell.cli.Output();

  const testing::CliRun check = RunCli("devices check --devices " + cell.devices.string());
  ASSERT_EQ(check.exit_code, 0) << check.output;
  EXPECT_NE(check.output.find("robot      yaskawa-hses      PASS"), std::string::npos) << check.output;
  EXPECT_NE(check.output.find("gripper    robotiq-2f85-rtu  PASS"), std::string::npos) << check.output;
  EXPECT_NE(check.output.find("ft_sensor  ati-netft-rdt     PASS"), std::string::npos) << check.output;
  EXPECT_NE(check.output.find("scanner    exec              PASS"), std::string::npos) << check.output;
  // The counts per unit came from the virtual box's web server (torque configured in N-mm).
  EXPECT_NE(check.output.find("1000000 counts/N, 1000 counts/N-mm from the box"), std::string::npos)
      << check.output;

  const auto json_path = dir / "round.json";
  const auto records_path = dir / "records.jsonl";
  // Told the bin held 5 where the virtual cell dropped 4: the bin found empty says one is missing.
  const testing::CliRun run =
      RunCli("cell --devices " + cell.devices.string() + " --rounds 1 --tubes 5 --json " +
             json_path.string() + " --records " + records_path.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("; 1 of the bin's 5 tubes unaccounted for (tubes_per_bin)"), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find(
                "devices: robot yaskawa-hses, gripper robotiq-2f85-rtu, F/T ati-netft-rdt, scanner exec"),
            std::string::npos)
      << run.output;
  const nlohmann::json j = testing::ReadJson(json_path);
  EXPECT_EQ(j["statistics"]["picks"], 4) << j.dump(2);
  EXPECT_EQ(j["rounds"][0]["reason"], "bin_empty");
  EXPECT_EQ(j["rounds"][0]["tubes_unaccounted"], 1);
  EXPECT_EQ(j["statistics"]["tubes_unaccounted"], 1);
  EXPECT_NE(testing::ReadText(records_path).find("\"type\":\"end\""), std::string::npos);

  EXPECT_EQ(cell.Stop(), "virtual-cell: tubes_in_bin=0 placed=4 outside=0") << cell.cli.Output();
  EXPECT_EQ(cell.exit_code, 0);
}

TEST(VirtualCellTest, DryRunPlansAndPrintsTheMotionsWithoutMovingAnything) {
  const auto dir = testing::TempDir("virtual_cell_dry");
  VirtualCell cell(dir, 3, 4);
  ASSERT_TRUE(cell.Ready()) << cell.cli.Output();
  const auto before = dir / "before.json";
  ASSERT_EQ(
      RunCli("devices check --devices " + cell.devices.string() + " --json " + before.string()).exit_code, 0);

  const auto json_path = dir / "dry.json";
  const testing::CliRun run =
      RunCli("cell --devices " + cell.devices.string() + " --dry-run --json " + json_path.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json dry = testing::ReadJson(json_path);
  ASSERT_GE(dry["motions"].size(), 5u) << dry.dump(2);

  const auto after = dir / "after.json";
  ASSERT_EQ(
      RunCli("devices check --devices " + cell.devices.string() + " --json " + after.string()).exit_code, 0);
  const nlohmann::json b = testing::ReadJson(before)["rows"][0]["values"];
  const nlohmann::json a = testing::ReadJson(after)["rows"][0]["values"];
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(a["p_Bin_tcp"][i].get<double>(), b["p_Bin_tcp"][i].get<double>(), 1e-6);
  EXPECT_EQ(testing::ReadJson(after)["rows"][1]["values"]["activated"], false)
      << "the gripper was not touched";
  EXPECT_EQ(cell.Stop(), "virtual-cell: tubes_in_bin=3 placed=0 outside=0") << cell.cli.Output();
}

TEST(DevicesConfigCliTest, TheShippedExampleIsWhatTheCommandPrints) {
  const testing::CliRun run = RunCli("cell --print-devices-config");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.output, testing::ReadText(fs::path(TUBEPICK_SOURCE_DIR) / "deploy" / "devices.example.yaml"))
      << "regenerate deploy/devices.example.yaml with `tubepick cell --print-devices-config`";
}

TEST(DevicesConfigCliTest, ARealCellWithoutACellDescriptionIsRefused) {
  const auto dir = testing::TempDir("devices_no_cell");
  std::string text = testing::ReadText(fs::path(TUBEPICK_SOURCE_DIR) / "deploy" / "devices.example.yaml");
  text.replace(text.find("cell: cell.example.yaml"), 23, "cell: \"\"");
  std::ofstream(dir / "devices.yaml") << text;
  const testing::CliRun run = RunCli("cell --devices " + (dir / "devices.yaml").string() + " --rounds 1");
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("no cell description"), std::string::npos) << run.output;
}

TEST(DevicesCheckTest, DevicesThatDoNotAnswerFailOneRowEachNamingWhy) {
  const auto dir = testing::TempDir("devices_check_fail");
  const auto devices = dir / "devices.yaml";
  std::ofstream(dir / "cell.yaml") << "bin: {inner_size: [0.6, 0.4, 0.2]}\n";
  std::ofstream(devices) << R"(cell: cell.yaml
robot:
  driver: yaskawa-hses
  yaskawa_hses: {host: 127.0.0.1, port: 9}
gripper:
  driver: robotiq-2f85-rtu
  robotiq_2f85_rtu: {device: /dev/tubepick-no-such-adapter}
ft_sensor: {driver: sim}
scanner:
  driver: exec
  exec: {command: "echo 'no camera on 192.168.1.20' >&2; exit 2 # {out}"}
)";
  const testing::CliRun run = RunCli("devices check --timeout 0.5 --devices " + devices.string());
  EXPECT_EQ(run.exit_code, 5) << run.output;
  EXPECT_NE(run.output.find("robot      yaskawa-hses      FAIL"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("gripper    robotiq-2f85-rtu  FAIL  cannot open"), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("/dev/tubepick-no-such-adapter"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("ft_sensor  sim               PASS"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("no camera on 192.168.1.20"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("some devices FAIL"), std::string::npos) << run.output;
}

TEST(DevicesCheckTest, ACloudInTheWrongUnitFailsTheScannerRowNamingTheUnit) {
  const auto dir = testing::TempDir("devices_check_unit");
  VirtualCell cell(dir, 2, 5);
  ASSERT_TRUE(cell.Ready()) << cell.cli.Output();
  // The cell file says the scanner gives millimetres; the virtual scanner gives metres.
  std::string cell_yaml = testing::ReadText(dir / "devices.cell.yaml");
  const auto at = cell_yaml.find("unit: m");
  ASSERT_NE(at, std::string::npos) << cell_yaml;
  cell_yaml.replace(at, 7, "unit: mm");
  std::ofstream(dir / "mm.cell.yaml") << cell_yaml;
  const testing::CliRun run = RunCli("devices check --devices " + cell.devices.string() + " --cell " +
                                     (dir / "mm.cell.yaml").string());
  EXPECT_EQ(run.exit_code, 5) << run.output;
  EXPECT_NE(run.output.find("scanner    exec              FAIL"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("unit"), std::string::npos) << run.output;
  cell.Stop();
}

// The planner behind mutual TLS, as on a plant network: the cell connects with the same PEM files
// the server takes, and without its client certificate it is refused with the likely cause.
TEST(CellTlsTest, ARoundAgainstAPlannerThatRequiresMutualTls) {
  const auto dir = testing::TempDir("cell_tls");
  ASSERT_EQ(
      std::system(
          ("sh " TUBEPICK_SOURCE_DIR "/tests/test_certs.sh " + dir.string() + " >/dev/null 2>&1").c_str()),
      0);
  std::ofstream(dir / "server.yaml")
      << "server:\n  tls:\n    cert_file: server.pem\n    key_file: server.key\n"
         "    client_ca_file: ca.pem\n    require_client_cert: true\n";
  BackgroundCli server(
      {"--config", (dir / "server.yaml").string(), "--address", "127.0.0.1:0", "--metrics-address", ""},
      dir / "server.log", TUBEPICK_SERVER);
  const std::string port = server.WaitFor("listening on 127\\.0\\.0\\.1:(\\d+)", 60s);
  ASSERT_FALSE(port.empty()) << server.Output();
  const std::string planner = " --server 127.0.0.1:" + port + " --tls-ca " + (dir / "ca.pem").string();

  const testing::CliRun run =
      RunCli("cell --sim --rounds 1 --tubes 2 --seed 4" + planner + " --tls-cert " +
             (dir / "client.pem").string() + " --tls-key " + (dir / "client.key").string());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("bin empty: 2 tubes picked"), std::string::npos) << run.output;

  // No client certificate: the planner refuses the handshake; the round safe-stops, saying why.
  const testing::CliRun refused = RunCli("cell --sim --rounds 1 --tubes 1" + planner);
  EXPECT_EQ(refused.exit_code, 3) << refused.output;
  EXPECT_NE(refused.output.find("requires mutual TLS"), std::string::npos) << refused.output;
  server.Signal(SIGTERM);
  EXPECT_EQ(server.Wait(30s), 0) << server.Output();

  // TLS options with the private plaintext planner are a mistake, said at once.
  const testing::CliRun mixed = RunCli("cell --sim --tls-ca " + (dir / "ca.pem").string());
  EXPECT_EQ(mixed.exit_code, 2) << mixed.output;
  EXPECT_NE(mixed.output.find("--server auto starts is plaintext"), std::string::npos) << mixed.output;
}

TEST(CellOperatorStopTest, SigintDuringARoundEndsInTheSafeStopAndExit130) {
  const auto dir = testing::TempDir("cell_sigint");
  const auto records = dir / "records.jsonl";
  BackgroundCli cli(
      {"cell", "--sim", "--rounds", "5", "--tubes", "7", "--seed", "2", "--records", records.string()},
      dir / "cell.log");
  const std::string server_pid = cli.WaitFor("started tubepick-server \\(pid (\\d+)\\)", 60s);
  ASSERT_FALSE(server_pid.empty()) << cli.Output();
  // A round of 7 tubes takes a few seconds: 2 s after the server is up one is under way (were it
  // not yet, the stop would come at its first state, with the same outcome).
  std::this_thread::sleep_for(2s);
  cli.Signal(SIGINT);
  EXPECT_EQ(cli.Wait(60s), 130) << cli.Output();
  const std::string out = cli.Output();
  EXPECT_NE(out.find("stopped by SIGINT"), std::string::npos) << out;
  EXPECT_NE(out.find("0 fault, 1 operator"), std::string::npos) << "the tables count the stop:\n" << out;
  // The stopped round is the last one: the remaining rounds are skipped.
  const std::regex round_line("round +\\d+ \\(seed \\d+\\): ([^|]*)");
  std::vector<std::string> rounds;
  for (auto it = std::sregex_iterator(out.begin(), out.end(), round_line); it != std::sregex_iterator(); ++it)
    rounds.push_back((*it)[1]);
  ASSERT_FALSE(rounds.empty()) << out;
  EXPECT_LT(rounds.size(), 5u) << out;
  EXPECT_NE(rounds.back().find("STOPPED: operator stop (SIGINT)"), std::string::npos) << out;
  const std::string text = testing::ReadText(records);
  EXPECT_NE(text.find("\"type\":\"safe_stop\""), std::string::npos) << text;
  EXPECT_NE(text.find("operator stop (SIGINT)"), std::string::npos) << text;
  EXPECT_TRUE(Gone(std::stoi(server_pid))) << "the private server was stopped";
}

TEST(CellOperatorStopTest, ThePrivateServerDiesWithItsParent) {
  const auto dir = testing::TempDir("cell_parent_killed");
  BackgroundCli cli({"cell", "--sim", "--rounds", "5", "--tubes", "7"}, dir / "cell.log");
  const std::string server_pid = cli.WaitFor("started tubepick-server \\(pid (\\d+)\\)", 60s);
  ASSERT_FALSE(server_pid.empty()) << cli.Output();
  cli.Signal(SIGKILL);  // no chance to clean up
  cli.Wait(10s);
  const auto end = std::chrono::steady_clock::now() + 20s;
  while (!Gone(std::stoi(server_pid)) && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(50ms);
  EXPECT_TRUE(Gone(std::stoi(server_pid)));
}

}  // namespace
}  // namespace tubepick
