#include "wire/cloud_stream.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "core/common/errors.h"
#include "core/testing/error_of.h"

namespace tubepick {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using tubepick::testing::ErrorOf;

constexpr std::uint64_t kMax = 1 << 20;

// `points` float32 xyz triples of deterministic pseudo-random bytes.
std::string CloudBytes(std::size_t points, std::uint32_t seed = 5) {
  std::mt19937 rng(seed);
  std::string bytes(points * 12, '\0');
  for (char& b : bytes) b = static_cast<char>(rng() & 0xFF);
  return bytes;
}

v1::PlanPickStreamRequest Header(std::uint64_t total_bytes, std::uint32_t chunk_count, std::uint32_t crc) {
  v1::PlanPickStreamRequest m;
  m.mutable_header()->set_total_bytes(total_bytes);
  m.mutable_header()->set_chunk_count(chunk_count);
  m.mutable_header()->set_crc32c(crc);
  m.mutable_header()->mutable_request()->mutable_options()->set_profile("thesis");
  return m;
}

v1::PlanPickStreamRequest Chunk(std::uint32_t index, std::string data) {
  v1::PlanPickStreamRequest m;
  m.mutable_chunk()->set_index(index);
  m.mutable_chunk()->set_data(std::move(data));
  return m;
}

// Splits `bytes` into `n` chunks of (nearly) equal size.
std::vector<std::string> Split(const std::string& bytes, std::uint32_t n) {
  std::vector<std::string> chunks;
  const std::size_t size = (bytes.size() + n - 1) / n;
  for (std::uint32_t i = 0; i < n; ++i)
    chunks.push_back(bytes.substr(std::min(bytes.size(), i * size), size));
  return chunks;
}

TEST(Crc32c, KnownVectors) {
  EXPECT_EQ(Crc32c("123456789"), 0xE3069283u);
  EXPECT_EQ(Crc32c(""), 0u);
  // RFC 3720 B.4: 32 bytes of zeros and of 0xFF.
  EXPECT_EQ(Crc32c(std::string(32, '\0')), 0x8A9136AAu);
  EXPECT_EQ(Crc32c(std::string(32, '\xFF')), 0x62A8AB43u);
}

TEST(Crc32c, RunningValueEqualsWhole) {
  const std::string data = CloudBytes(1000);
  EXPECT_EQ(Crc32c(data.substr(700), Crc32c(data.substr(0, 700))), Crc32c(data));
}

TEST(CloudStreamAssembler, InOrderChunksGiveTheBytes) {
  const std::string bytes = CloudBytes(1000);
  const auto chunks = Split(bytes, 5);
  CloudStreamAssembler a(kMax);
  EXPECT_FALSE(a.has_header());
  a.Add(Header(bytes.size(), 5, Crc32c(bytes)));
  EXPECT_TRUE(a.has_header());
  EXPECT_EQ(a.request().options().profile(), "thesis");
  for (std::uint32_t i = 0; i < 5; ++i) a.Add(Chunk(i, chunks[i]));
  EXPECT_EQ(a.received_bytes(), bytes.size());
  EXPECT_EQ(a.Finish(), bytes);
}

TEST(CloudStreamAssembler, AnyOrderGivesTheSameBytes) {
  const std::string bytes = CloudBytes(1001);
  const auto chunks = Split(bytes, 7);
  std::vector<std::uint32_t> order = {6, 2, 0, 5, 1, 4, 3};
  for (int round = 0; round < 3; ++round) {
    CloudStreamAssembler a(kMax);
    a.Add(Header(bytes.size(), 7, Crc32c(bytes)));
    for (std::uint32_t i : order) a.Add(Chunk(i, chunks[i]));
    EXPECT_EQ(a.Finish(), bytes) << "round " << round;
    std::reverse(order.begin(), order.end());
    if (round == 1) std::rotate(order.begin(), order.begin() + 3, order.end());
  }
}

TEST(CloudStreamAssembler, SingleChunk) {
  const std::string bytes = CloudBytes(1);
  CloudStreamAssembler a(kMax);
  a.Add(Header(12, 1, Crc32c(bytes)));
  a.Add(Chunk(0, bytes));
  EXPECT_EQ(a.Finish(), bytes);
}

TEST(CloudStreamAssembler, RejectsBadHeaders) {
  const auto header_error = [](std::uint64_t total, std::uint32_t count, std::uint64_t max = kMax) {
    return ErrorOf([&] {
      CloudStreamAssembler a(max);
      a.Add(Header(total, count, 0));
    });
  };
  EXPECT_THAT(header_error(12345, 3),
              AllOf(HasSubstr("header.total_bytes"), HasSubstr("12345"), HasSubstr("not a multiple of 12")));
  EXPECT_THAT(header_error(0, 1), AllOf(HasSubstr("header.total_bytes"), HasSubstr("0")));
  EXPECT_THAT(header_error(1200, 1, 1188),
              AllOf(HasSubstr("header.total_bytes"), HasSubstr("1200"), HasSubstr("1188")));
  EXPECT_THAT(header_error(120, 0), AllOf(HasSubstr("header.chunk_count"), HasSubstr("0")));
  EXPECT_THAT(header_error(120, 121), AllOf(HasSubstr("header.chunk_count"), HasSubstr("121")));
  EXPECT_NO_THROW({
    CloudStreamAssembler a(1188);
    a.Add(Header(1188, 1188, 0));
  });

  v1::PlanPickStreamRequest with_bytes = Header(12, 1, 0);
  with_bytes.mutable_header()->mutable_request()->mutable_cloud()->set_xyz(CloudBytes(2));
  EXPECT_THAT(ErrorOf([&] { CloudStreamAssembler(kMax).Add(with_bytes); }),
              AllOf(HasSubstr("header.request.cloud.xyz"), HasSubstr("24 bytes")));
}

TEST(CloudStreamAssembler, RejectsSecondHeaderEarlyChunkAndEmptyMessage) {
  CloudStreamAssembler a(kMax);
  EXPECT_THAT(ErrorOf([&] { a.Add(Chunk(0, "abc")); }), HasSubstr("chunk 0: arrived before the header"));
  EXPECT_THAT(ErrorOf([&] { a.Add(v1::PlanPickStreamRequest()); }), HasSubstr("empty"));
  EXPECT_THAT(ErrorOf([&] { a.Finish(); }), HasSubstr("without a header"));
  a.Add(Header(24, 2, 0));
  EXPECT_THAT(ErrorOf([&] { a.Add(Header(24, 2, 0)); }), HasSubstr("second header"));
}

TEST(CloudStreamAssembler, RejectsBadChunks) {
  const std::string bytes = CloudBytes(10);  // 120 bytes
  const auto chunks = Split(bytes, 4);       // 30 each
  CloudStreamAssembler a(kMax);
  a.Add(Header(120, 4, Crc32c(bytes)));
  a.Add(Chunk(2, chunks[2]));
  EXPECT_THAT(ErrorOf([&] { a.Add(Chunk(2, chunks[2])); }), HasSubstr("chunk 2: duplicate"));
  a.Add(Chunk(0, chunks[0]));
  EXPECT_THAT(ErrorOf([&] { a.Add(Chunk(0, chunks[0])); }), HasSubstr("chunk 0: duplicate"));
  EXPECT_THAT(ErrorOf([&] { a.Add(Chunk(4, "x")); }),
              AllOf(HasSubstr("chunk 4"), HasSubstr("out of range"), HasSubstr("chunk_count = 4")));
  EXPECT_THAT(ErrorOf([&] { a.Add(Chunk(1, "")); }), HasSubstr("chunk 1: no data"));
  // 60 received; chunk 1 with 61 bytes would exceed 120.
  EXPECT_THAT(ErrorOf([&] { a.Add(Chunk(1, std::string(61, 'x'))); }),
              AllOf(HasSubstr("chunk 1"), HasSubstr("61 bytes"), HasSubstr("120")));
  EXPECT_EQ(a.received_bytes(), 60u);  // a rejected chunk is not counted
}

TEST(CloudStreamAssembler, TruncatedStreamNamesMissingChunks) {
  const std::string bytes = CloudBytes(100);
  const auto chunks = Split(bytes, 5);
  CloudStreamAssembler a(kMax);
  a.Add(Header(bytes.size(), 5, Crc32c(bytes)));
  a.Add(Chunk(0, chunks[0]));
  a.Add(Chunk(2, chunks[2]));
  a.Add(Chunk(3, chunks[3]));
  EXPECT_EQ(ErrorOf([&] { a.Finish(); }), "stream ended after 3 of 5 chunks (missing 1, 4)");
}

TEST(CloudStreamAssembler, ShortChunksAreASizeMismatch) {
  const std::string bytes = CloudBytes(10);
  CloudStreamAssembler a(kMax);
  a.Add(Header(120, 2, Crc32c(bytes)));
  a.Add(Chunk(0, bytes.substr(0, 60)));
  a.Add(Chunk(1, bytes.substr(60, 48)));
  EXPECT_THAT(ErrorOf([&] { a.Finish(); }), AllOf(HasSubstr("108"), HasSubstr("total_bytes is 120")));
}

TEST(CloudStreamAssembler, CorruptedByteIsACrcMismatch) {
  const std::string bytes = CloudBytes(100);
  std::string corrupted = bytes;
  corrupted[517] = static_cast<char>(corrupted[517] ^ 0x10);
  const auto chunks = Split(corrupted, 3);
  CloudStreamAssembler a(kMax);
  a.Add(Header(bytes.size(), 3, Crc32c(bytes)));
  for (std::uint32_t i : {1u, 0u, 2u}) a.Add(Chunk(i, chunks[i]));
  const std::string message = ErrorOf([&] { a.Finish(); });
  EXPECT_THAT(message, HasSubstr("crc32c mismatch: header 0x"));
  char expected[64];
  std::snprintf(expected, sizeof(expected), "header 0x%08X, data 0x%08X", Crc32c(bytes), Crc32c(corrupted));
  EXPECT_THAT(message, HasSubstr(expected));
}

}  // namespace
}  // namespace tubepick
