#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tubepick/v1/requests.pb.h"

namespace tubepick {

/// CRC-32C (Castagnoli, reflected polynomial 0x82F63B78), as in iSCSI / gRPC / RFC 3720; `crc` is the
/// running value of the bytes before (0 to start). Crc32c("123456789") == 0xE3069283.
std::uint32_t Crc32c(std::string_view data, std::uint32_t crc = 0);

/// The messages of one PlanPickStream for `request` and the cloud bytes `xyz` (packed float32 x, y,
/// z; `request.cloud().xyz()` is ignored and sent empty): the header (the request, total_bytes,
/// chunk_count, the CRC-32C of `xyz`), then the chunks of at most `chunk_bytes` in index order.
/// The bytes are passed as they are, so a test may split a cloud the server must reject.
/// @pre chunk_bytes > 0.
std::vector<v1::PlanPickStreamRequest> SplitCloudStream(const v1::PlanPickRequest& request,
                                                        std::string_view xyz, std::size_t chunk_bytes);

/// Reassembles one PlanPickStream: header first, then chunks in any order, each index once.
/// Every mistake throws tubepick::InvalidArgument naming what is wrong ("chunk 3: duplicate",
/// "header.total_bytes: 12345 is not a multiple of 12", "stream ended after 3 of 5 chunks
/// (missing 1, 4)", "crc32c mismatch: header 0x..., data 0x...").
class CloudStreamAssembler {
 public:
  /// `max_total_bytes`: largest total_bytes a header may announce (ServerConfig::max_stream_bytes).
  explicit CloudStreamAssembler(std::uint64_t max_total_bytes);

  /// Feeds one stream message. The header reserves no memory: the cloud's buffer is reserved with the
  /// first chunk, so a server can admit (or refuse) the call between the two. @throws InvalidArgument (a
  /// second header, a chunk before the header, a chunk index ≥ chunk_count, a duplicate, more bytes than
  /// announced, an empty message).
  void Add(const v1::PlanPickStreamRequest& message);
  bool has_header() const { return header_.has_value(); }
  /// The header's request (valid after the header arrived).
  const v1::PlanPickRequest& request() const;
  std::uint64_t received_bytes() const { return received_bytes_; }

  /// After the client half-closed: checks every chunk arrived, the byte count and the checksum,
  /// and returns the cloud bytes in index order (moving them out).
  /// @throws InvalidArgument (no header, missing chunks, size or CRC mismatch).
  std::string Finish();

 private:
  std::uint64_t max_total_bytes_;
  std::optional<v1::PlanPickStreamHeader> header_;
  /// Chunks that arrived ahead of `next_index_`, by index.
  std::map<std::uint32_t, std::string> chunks_;
  std::uint64_t received_bytes_ = 0;
  /// Chunks 0 .. next_index_ - 1 joined in order (in-order streams never copy twice), and their CRC.
  std::string joined_;
  std::uint32_t next_index_ = 0;
  std::uint32_t crc_ = 0;
};

}  // namespace tubepick
