#include "wire/cloud_stream.h"

#include <array>
#include <cassert>
#include <cstdio>

#include "core/common/errors.h"

namespace tubepick {
namespace {

constexpr std::uint32_t kCastagnoli = 0x82F63B78u;  // reflected

constexpr std::array<std::uint32_t, 256> MakeTable() {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? (c >> 1) ^ kCastagnoli : c >> 1;
    table[i] = c;
  }
  return table;
}

constexpr std::array<std::uint32_t, 256> kTable = MakeTable();

std::string Hex(std::uint32_t value) {
  char buffer[16];
  std::snprintf(buffer, sizeof(buffer), "0x%08X", value);
  return buffer;
}

std::string ChunkName(std::uint32_t index) { return "chunk " + std::to_string(index); }

}  // namespace

std::uint32_t Crc32c(std::string_view data, std::uint32_t crc) {
  crc = ~crc;
  for (const char ch : data) crc = kTable[(crc ^ static_cast<unsigned char>(ch)) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}

std::vector<v1::PlanPickStreamRequest> SplitCloudStream(const v1::PlanPickRequest& request,
                                                        std::string_view xyz, std::size_t chunk_bytes) {
  assert(chunk_bytes > 0);
  const std::size_t chunks = (xyz.size() + chunk_bytes - 1) / chunk_bytes;
  std::vector<v1::PlanPickStreamRequest> messages(chunks + 1);
  v1::PlanPickStreamHeader* header = messages[0].mutable_header();
  v1::PlanPickRequest* header_request = header->mutable_request();  // all but the cloud bytes
  if (request.has_cell()) *header_request->mutable_cell() = request.cell();
  if (request.has_options()) *header_request->mutable_options() = request.options();
  header_request->mutable_cloud()->set_unit(request.cloud().unit());
  header->set_total_bytes(xyz.size());
  header->set_chunk_count(static_cast<std::uint32_t>(chunks));
  header->set_crc32c(Crc32c(xyz));
  for (std::size_t i = 0; i < chunks; ++i) {
    v1::CloudChunk* chunk = messages[i + 1].mutable_chunk();
    chunk->set_index(static_cast<std::uint32_t>(i));
    chunk->set_data(std::string(xyz.substr(i * chunk_bytes, chunk_bytes)));
  }
  return messages;
}

CloudStreamAssembler::CloudStreamAssembler(std::uint64_t max_total_bytes)
    : max_total_bytes_(max_total_bytes) {}

const v1::PlanPickRequest& CloudStreamAssembler::request() const {
  if (!header_) throw InvalidArgument("stream: no header received yet");
  return header_->request();
}

void CloudStreamAssembler::Add(const v1::PlanPickStreamRequest& message) {
  switch (message.message_case()) {
    case v1::PlanPickStreamRequest::kHeader: {
      if (header_) throw InvalidArgument("header: a second header (the header must be sent exactly once)");
      const v1::PlanPickStreamHeader& header = message.header();
      const std::uint64_t total = header.total_bytes();
      if (total == 0) throw InvalidArgument("header.total_bytes: 0, but a cloud needs at least one point");
      if (total % 12 != 0) {
        throw InvalidArgument("header.total_bytes: " + std::to_string(total) +
                              " is not a multiple of 12 (float32 x, y, z per point)");
      }
      if (total > max_total_bytes_) {
        throw TooLarge("header.total_bytes: " + std::to_string(total) + " exceeds the limit of " +
                       std::to_string(max_total_bytes_) + " bytes (server.max_stream_bytes)");
      }
      if (header.chunk_count() == 0)
        throw InvalidArgument("header.chunk_count: 0, but at least 1 chunk must follow");
      if (header.chunk_count() > total) {
        throw InvalidArgument("header.chunk_count: " + std::to_string(header.chunk_count()) + " chunks for " +
                              std::to_string(total) + " bytes (every chunk carries at least one byte)");
      }
      if (!header.request().cloud().xyz().empty()) {
        throw InvalidArgument(
            "header.request.cloud.xyz: must be empty in a stream header (the bytes follow "
            "in chunks), got " +
            std::to_string(header.request().cloud().xyz().size()) + " bytes");
      }
      header_ = header;  // the cloud's memory is reserved with the first chunk, after admission
      return;
    }
    case v1::PlanPickStreamRequest::kChunk: {
      const v1::CloudChunk& chunk = message.chunk();
      const std::uint32_t index = chunk.index();
      if (!header_) throw InvalidArgument(ChunkName(index) + ": arrived before the header");
      if (index >= header_->chunk_count()) {
        throw InvalidArgument(ChunkName(index) + ": index out of range (header.chunk_count = " +
                              std::to_string(header_->chunk_count()) + ")");
      }
      if (index < next_index_ || chunks_.count(index))
        throw InvalidArgument(ChunkName(index) + ": duplicate");
      if (chunk.data().empty()) throw InvalidArgument(ChunkName(index) + ": no data");
      const std::uint64_t size = chunk.data().size();
      if (received_bytes_ + size > header_->total_bytes()) {
        throw InvalidArgument(ChunkName(index) + ": its " + std::to_string(size) +
                              " bytes exceed header.total_bytes " + std::to_string(header_->total_bytes()) +
                              " (" + std::to_string(received_bytes_) + " bytes received before it)");
      }
      if (received_bytes_ == 0) joined_.reserve(header_->total_bytes());
      received_bytes_ += size;
      if (index != next_index_) {
        chunks_.emplace(index, chunk.data());
        return;
      }
      // In order: append, then every buffered successor.
      crc_ = Crc32c(chunk.data(), crc_);
      joined_.append(chunk.data());
      ++next_index_;
      for (auto it = chunks_.begin(); it != chunks_.end() && it->first == next_index_;
           it = chunks_.erase(it)) {
        crc_ = Crc32c(it->second, crc_);
        joined_.append(it->second);
        ++next_index_;
      }
      return;
    }
    case v1::PlanPickStreamRequest::MESSAGE_NOT_SET:
      break;
  }
  throw InvalidArgument("stream message: empty (neither header nor chunk)");
}

std::string CloudStreamAssembler::Finish() {
  if (!header_) throw InvalidArgument("stream ended without a header");
  const std::uint32_t count = header_->chunk_count();
  if (next_index_ < count) {
    const std::uint64_t received = next_index_ + chunks_.size();
    std::string missing;
    std::uint64_t listed = 0;
    for (std::uint32_t i = next_index_; i < count && listed < 10; ++i) {
      if (chunks_.count(i)) continue;
      missing += (missing.empty() ? "" : ", ") + std::to_string(i);
      ++listed;
    }
    if (count - received > listed) missing += ", ...";
    throw InvalidArgument("stream ended after " + std::to_string(received) + " of " + std::to_string(count) +
                          " chunks (missing " + missing + ")");
  }
  if (received_bytes_ != header_->total_bytes()) {
    throw InvalidArgument("stream ended with " + std::to_string(received_bytes_) +
                          " bytes, but header.total_bytes is " + std::to_string(header_->total_bytes()));
  }
  if (crc_ != header_->crc32c()) {
    throw InvalidArgument("crc32c mismatch: header " + Hex(header_->crc32c()) + ", data " + Hex(crc_));
  }
  return std::move(joined_);
}

}  // namespace tubepick
