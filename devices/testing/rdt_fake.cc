#include "devices/testing/rdt_fake.h"

#include <cstring>
#include <string>

namespace tubepick::devices {

RdtFake::RdtFake() : server_("RdtFake", [this](std::span<const std::uint8_t> d) { return Handle(d); }) {}

void RdtFake::SetReply(const std::array<std::int32_t, 6>& counts, std::uint32_t status) {
  std::lock_guard lock(mutex_);
  counts_ = counts;
  status_ = status;
}

void RdtFake::SetSilent(bool silent) {
  std::lock_guard lock(mutex_);
  silent_ = silent;
}

int RdtFake::bias_count() const {
  std::lock_guard lock(mutex_);
  return bias_count_;
}

std::vector<rdt::RequestBytes> RdtFake::requests() const {
  std::lock_guard lock(mutex_);
  return requests_;
}

std::vector<LoopbackUdpServer::Datagram> RdtFake::Handle(std::span<const std::uint8_t> datagram) {
  std::vector<LoopbackUdpServer::Datagram> replies;
  if (datagram.size() != rdt::kRequestSize) {
    return replies;  // not an RDT request: a real Net F/T ignores it too
  }
  rdt::RequestBytes bytes{};
  std::memcpy(bytes.data(), datagram.data(), bytes.size());
  const rdt::Request request = rdt::DecodeRequest(bytes);
  std::lock_guard lock(mutex_);
  requests_.push_back(bytes);
  if (request.header != rdt::kHeader) {
    return replies;
  }
  const auto command = static_cast<rdt::Command>(request.command);
  if (command == rdt::Command::kSetSoftwareBias) {
    ++bias_count_;
  } else if ((command == rdt::Command::kStartRealtime || command == rdt::Command::kStartBuffered) &&
             !silent_) {
    const std::uint32_t n = request.sample_count == 0 ? 1 : request.sample_count;
    for (std::uint32_t i = 0; i < n; ++i) {
      rdt::Record record;
      record.rdt_sequence = i + 1;
      record.ft_sequence = ++ft_sequence_;
      record.status = status_;
      record.counts = counts_;
      const rdt::RecordBytes encoded = rdt::EncodeRecord(record);
      replies.emplace_back(encoded.begin(), encoded.end());
    }
  }
  return replies;
}

}  // namespace tubepick::devices
