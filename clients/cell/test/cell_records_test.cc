#include "clients/cell/cell_records.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/common/errors.h"

namespace tubepick::cell {
namespace {

std::filesystem::path TempFile(const std::string& name) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("tubepick-records-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir / name;
}

std::string ReadAll(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

nlohmann::json Attempt(int n, std::size_t padding = 0) {
  return {{"type", "attempt"}, {"attempt", n}, {"note", std::string(padding, 'x')}};
}

TEST(JsonLinesFileSink, WritesOneLinePerRecordThatReadsBack) {
  const auto path = TempFile("whole.jsonl");
  {
    JsonLinesFileSink sink(path.string());
    sink.Write(Attempt(1));
    sink.Write(Attempt(2));
    EXPECT_EQ(sink.written(), 2u);
    EXPECT_EQ(sink.lost(), 0u);
    EXPECT_EQ(DescribeRecordsFile(sink), "records: " + path.string());
  }
  const std::vector<nlohmann::json> back = ReadJsonLines(path.string());
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1]["attempt"], 2);
}

// /dev/full: every write fails with ENOSPC, as on a full disk. The sink must not throw into the
// controller (a pick under way would end in a safe stop); it counts and says so.
TEST(JsonLinesFileSink, AFullDiskLosesRecordsWithoutThrowingAndSaysHowMany) {
  JsonLinesFileSink sink("/dev/full");
  EXPECT_NO_THROW(sink.Write(Attempt(1)));
  EXPECT_NO_THROW(sink.Write({{"type", "end"}}));
  EXPECT_EQ(sink.written(), 0u);
  EXPECT_EQ(sink.lost(), 2u);
  EXPECT_EQ(sink.last_error(), "No space left on device");
  EXPECT_EQ(
      DescribeRecordsFile(sink),
      "records: /dev/full: 2 of 2 records could not be written (No space left on device); the file holds "
      "the other 0");
}

TEST(JsonLinesFileSink, AFileThatCannotBeOpenedIsRefusedWithTheReason) {
  try {
    JsonLinesFileSink sink("/nonexistent-dir/records.jsonl");
    FAIL() << "opened";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(
        std::string(e.what()).find("/nonexistent-dir/records.jsonl: cannot open for writing (No such file"),
        std::string::npos)
        << e.what();
  }
}

// A record cut off half-way (the file size limit reached mid-line, as a disk filling up) is cut
// back off, so the file stays whole lines; when space comes back the next record is written.
TEST(JsonLinesFileSink, APartialLineIsCutBackOffAndWritingResumesWhenSpaceReturns) {
  const auto path = TempFile("partial.jsonl");
  JsonLinesFileSink sink(path.string());
  sink.Write(Attempt(1));
  const auto first_size = static_cast<rlim_t>(std::filesystem::file_size(path));

  rlimit saved{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit tight = saved;
  tight.rlim_cur = first_size + 20;  // room for 20 bytes of the next 200-byte line
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &tight), 0);
  sink.Write(Attempt(2, 200));
  const auto size_while_full = std::filesystem::file_size(path);
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &saved), 0);
  std::signal(SIGXFSZ, old_handler);

  EXPECT_EQ(size_while_full, first_size);
  EXPECT_EQ(sink.lost(), 1u);
  EXPECT_EQ(sink.last_error(), "File too large");
  sink.Write(Attempt(3));
  EXPECT_EQ(sink.written(), 2u);
  const std::vector<nlohmann::json> back = ReadJsonLines(path.string());
  ASSERT_EQ(back.size(), 2u) << ReadAll(path);
  EXPECT_EQ(back[0]["attempt"], 1);
  EXPECT_EQ(back[1]["attempt"], 3);
  EXPECT_EQ(DescribeRecordsFile(sink), "records: " + path.string() +
                                           ": 1 of 3 records could not be written (File too large); the file "
                                           "holds the other 2");
}

TEST(JsonLinesFileSink, AppendKeepsWhatTheFileHeld) {
  const auto path = TempFile("append.jsonl");
  { JsonLinesFileSink(path.string()).Write(Attempt(1)); }
  { JsonLinesFileSink(path.string(), /*append=*/true).Write(Attempt(2)); }
  EXPECT_EQ(ReadJsonLines(path.string()).size(), 2u);
}

}  // namespace
}  // namespace tubepick::cell
