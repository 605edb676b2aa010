// libFuzzer target: the Yaskawa HSES decoders on arbitrary UDP payloads.
// Whatever decodes must encode back to the same fields; decoding never throws and never reads past
// the datagram (the sanitizers check that).

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "devices/yaskawa_hses.h"

namespace {

namespace hses = tubepick::devices::hses;

void Check(bool condition) {
  if (!condition) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);

  if (const auto request = hses::DecodeRequest(bytes)) {
    Check(request->data.size() == size - hses::kHeaderSize);
    const auto again = hses::DecodeRequest(hses::EncodeRequest(*request));
    Check(again && again->request_id == request->request_id && again->command == request->command &&
          again->instance == request->instance && again->attribute == request->attribute &&
          again->service == request->service && again->data == request->data);
  }

  if (const auto answer = hses::DecodeAnswer(bytes)) {
    Check(answer->data.size() == size - hses::kHeaderSize);
    const auto again = hses::DecodeAnswer(hses::EncodeAnswer(*answer));
    Check(again && again->request_id == answer->request_id && again->service == answer->service &&
          again->status == answer->status && again->added_status_size == answer->added_status_size &&
          again->added_status == answer->added_status && again->data == answer->data);
  }

  // The payload as the driver reads it: words, and a pose from words 5..10 of a position answer.
  const std::vector<std::int32_t> words = hses::DecodeWords(bytes);
  Check(words.size() == size / 4);
  Check(hses::EncodeWords(words) == std::vector<std::uint8_t>(data, data + 4 * words.size()));
  if (words.size() >= hses::kPositionWords) {
    const Eigen::Isometry3d X = hses::PoseFromWords(std::span<const std::int32_t, 6>(words.data() + 5, 6));
    Check(X.matrix().allFinite());
    Check(std::abs(X.linear().determinant() - 1.0) < 1e-9);
  }
  return 0;
}
