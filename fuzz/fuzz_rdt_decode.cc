// libFuzzer target: the ATI Net F/T RDT decoders on arbitrary UDP payloads.
// A 36-byte record and an 8-byte request decode and encode back to the very same bytes; decoding
// never reads past them (the sanitizers check that).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "devices/ati_netft.h"

namespace {

namespace rdt = tubepick::devices::rdt;

void Check(bool condition) {
  if (!condition) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The driver takes exactly one record per datagram; a fuzz input may carry several.
  for (std::size_t at = 0; at + rdt::kRecordSize <= size; at += rdt::kRecordSize) {
    const std::span<const std::uint8_t, rdt::kRecordSize> bytes(data + at, rdt::kRecordSize);
    const rdt::RecordBytes again = rdt::EncodeRecord(rdt::DecodeRecord(bytes));
    Check(std::equal(again.begin(), again.end(), bytes.begin()));
  }
  if (size >= rdt::kRequestSize) {
    const std::span<const std::uint8_t, rdt::kRequestSize> bytes(data, rdt::kRequestSize);
    const rdt::Request request = rdt::DecodeRequest(bytes);
    if (request.header == rdt::kHeader) {
      const rdt::RequestBytes again =
          rdt::EncodeRequest(static_cast<rdt::Command>(request.command), request.sample_count);
      Check(std::equal(again.begin(), again.end(), bytes.begin()));
    }
  }
  return 0;
}
