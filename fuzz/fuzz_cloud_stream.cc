// libFuzzer target: PlanPickStream reassembly and the cloud decoding behind it.
//
// Input: a sequence of PlanPickStreamRequest messages, each preceded by its size as a varint (the
// protobuf "delimited" form; fuzz/make_corpus.py writes the seeds). They are fed to a
// CloudStreamAssembler as the server does, then Finish(); the joined bytes go through the stream
// request's validation (CheckCloudBytes included). Accepted: InvalidArgument / FailedPrecondition naming
// the mistake. Anything else, a sanitizer report or a broken invariant below, is a crash.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/stubs/common.h>

#include "core/common/errors.h"
#include "server/request_validation.h"
#include "server/server_config.h"
#include "wire/cloud_stream.h"

namespace {

using namespace tubepick;  // NOLINT(build/namespaces): a fuzz target's few names

constexpr std::uint64_t kMaxStreamBytes = 1 << 20;  // small, so no input can ask for much memory
constexpr std::uint64_t kMaxPoints = kMaxStreamBytes / 12;

const server::PlanningDefaults& Defaults() {
  static const server::PlanningDefaults defaults = [] {
    server::PlanningDefaults d;
    d.max_cloud_points = kMaxPoints;
    return d;
  }();
  return defaults;
}

void Check(bool condition) {
  if (!condition) std::abort();
}

// Properties of the CRC on the raw input: split anywhere, the running value continues the whole.
void CheckCrc(std::string_view bytes) {
  const std::size_t half = bytes.size() / 2;
  Check(Crc32c(bytes) == Crc32c(bytes.substr(half), Crc32c(bytes.substr(0, half))));
}

// CheckCloudBytes on the raw input: the bytes themselves (12 a point) or InvalidArgument.
void CheckCloudBytes(std::string_view bytes) {
  try {
    const std::string_view checked = server::CheckCloudBytes(bytes, kMaxPoints, "cloud.xyz");
    Check(checked.data() == bytes.data() && checked.size() == bytes.size() && bytes.size() % 12 == 0);
  } catch (const InvalidArgument&) {
  }
}

}  // namespace

// protobuf logs every string field with invalid UTF-8 it parses; the parse result is what counts.
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  google::protobuf::SetLogHandler(nullptr);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  CheckCrc(bytes);
  CheckCloudBytes(bytes);

  google::protobuf::io::CodedInputStream input(data, static_cast<int>(size));
  CloudStreamAssembler assembler(kMaxStreamBytes);
  v1::PlanPickStreamHeader header;  // the one the assembler accepted
  try {
    while (!input.ExpectAtEnd()) {
      std::uint32_t length = 0;
      if (!input.ReadVarint32(&length)) return 0;
      const auto limit = input.PushLimit(static_cast<int>(length));
      v1::PlanPickStreamRequest message;
      if (!message.ParseFromCodedStream(&input) || !input.ConsumedEntireMessage()) return 0;
      input.PopLimit(limit);
      const bool first_header = message.has_header() && !assembler.has_header();
      assembler.Add(message);
      if (first_header) header = message.header();
      Check(assembler.received_bytes() <= header.total_bytes());
    }
    const std::string cloud = assembler.Finish();
    // Finish returns exactly what the header announced, with the announced checksum.
    Check(cloud.size() == header.total_bytes() && Crc32c(cloud) == header.crc32c());
    const server::PlanningJob job = server::ValidatePlanPick(assembler.request(), cloud, Defaults());
    Check(job.xyz_Sensor.data() == cloud.data() && job.xyz_Sensor.size() == cloud.size());  // a view, no copy
  } catch (const InvalidArgument&) {
  } catch (const FailedPrecondition&) {
  }
  return 0;
}
