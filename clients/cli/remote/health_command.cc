#include "clients/cli/remote/health_command.h"

#include <fmt/core.h>
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include <future>
#include <memory>
#include <optional>

namespace tubepick::cli {
namespace {

// Why hand-encoded bytes on a GenericStub instead of compiling grpc.health.v1's health.proto:
// the two messages have one field each (HealthCheckRequest.service = 1, a string;
// HealthCheckResponse.status = 1, an enum), Debian ships no C++ stubs for them, and a second
// proto module would have to be kept out of buf lint and the tubepick.v1 contract. A dozen lines
// of protobuf wire format are simpler and exactly as correct.

constexpr const char* kCheckMethod = "/grpc.health.v1.Health/Check";

void AppendVarint(std::uint64_t value, std::string* out) {
  while (value >= 0x80) {
    out->push_back(static_cast<char>((value & 0x7F) | 0x80));
    value >>= 7;
  }
  out->push_back(static_cast<char>(value));
}

std::optional<std::uint64_t> ReadVarint(const std::string& in, std::size_t* pos) {
  std::uint64_t value = 0;
  for (int shift = 0; shift < 64 && *pos < in.size(); shift += 7) {
    const auto byte = static_cast<std::uint8_t>(in[(*pos)++]);
    value |= static_cast<std::uint64_t>(byte & 0x7F) << shift;
    if ((byte & 0x80) == 0) return value;
  }
  return std::nullopt;
}

/// HealthCheckRequest{service}: field 1, wire type 2 (length-delimited); empty fields are omitted.
std::string EncodeHealthCheckRequest(const std::string& service) {
  std::string out;
  if (service.empty()) return out;
  out.push_back(0x0A);
  AppendVarint(service.size(), &out);
  out += service;
  return out;
}

/// HealthCheckResponse.status (field 1, varint); other fields are skipped; absent = UNKNOWN.
std::optional<ServingStatus> DecodeHealthCheckResponse(const std::string& in) {
  std::size_t pos = 0;
  std::uint64_t status = 0;
  while (pos < in.size()) {
    const std::optional<std::uint64_t> key = ReadVarint(in, &pos);
    if (!key) return std::nullopt;
    const std::uint64_t field = *key >> 3;
    switch (*key & 7) {
      case 0: {
        const std::optional<std::uint64_t> v = ReadVarint(in, &pos);
        if (!v) return std::nullopt;
        if (field == 1) status = *v;
        break;
      }
      case 1:
        pos += 8;
        break;
      case 2: {
        const std::optional<std::uint64_t> len = ReadVarint(in, &pos);
        if (!len || *len > in.size() - std::min(pos, in.size())) return std::nullopt;
        pos += *len;
        break;
      }
      case 5:
        pos += 4;
        break;
      default:
        return std::nullopt;
    }
    if (pos > in.size()) return std::nullopt;
  }
  if (status > 3) return ServingStatus::kUnknown;
  return static_cast<ServingStatus>(status);
}

struct HealthOptions {
  ChannelOptions channel;
  std::string service;
  double timeout_seconds = 5.0;
};

}  // namespace

std::string ToString(ServingStatus status) {
  switch (status) {
    case ServingStatus::kUnknown:
      return "UNKNOWN";
    case ServingStatus::kServing:
      return "SERVING";
    case ServingStatus::kNotServing:
      return "NOT_SERVING";
    case ServingStatus::kServiceUnknown:
      return "SERVICE_UNKNOWN";
  }
  return "UNKNOWN";
}

HealthAnswer CheckHealth(const ChannelOptions& channel_options, const std::string& service,
                         std::chrono::milliseconds timeout) {
  HealthAnswer answer;
  std::shared_ptr<grpc::Channel> channel;
  try {
    channel = MakeChannel(channel_options);
  } catch (const std::exception& e) {
    answer.grpc_code = grpc::StatusCode::INVALID_ARGUMENT;
    answer.grpc_message = e.what();
    return answer;
  }
  grpc::GenericStub stub(channel);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + timeout);

  std::string request_bytes = EncodeHealthCheckRequest(service);
  grpc::Slice slice(std::move(request_bytes));
  const grpc::ByteBuffer request(&slice, 1);
  grpc::ByteBuffer response;
  std::promise<grpc::Status> done;
  std::future<grpc::Status> result = done.get_future();
  const std::string method = kCheckMethod;
  stub.UnaryCall(&context, method, grpc::StubOptions(), &request, &response,
                 [&done](grpc::Status status) { done.set_value(std::move(status)); });
  const grpc::Status status = result.get();
  answer.grpc_code = status.error_code();
  answer.grpc_message = status.error_message();
  if (!status.ok()) return answer;

  std::vector<grpc::Slice> slices;
  std::string bytes;
  if (response.Dump(&slices).ok())
    for (const grpc::Slice& s : slices) bytes.append(reinterpret_cast<const char*>(s.begin()), s.size());
  const std::optional<ServingStatus> serving = DecodeHealthCheckResponse(bytes);
  if (!serving) {
    answer.grpc_code = grpc::StatusCode::INTERNAL;
    answer.grpc_message = "malformed HealthCheckResponse";
    return answer;
  }
  answer.status = *serving;
  return answer;
}

void AddHealthCommand(CLI::App& app) {
  auto o = std::make_shared<HealthOptions>();
  CLI::App* cmd =
      app.add_subcommand("health", "grpc.health.v1 Check of a server: exit 0 when SERVING, else 1");
  AddChannelOptions(cmd, o->channel);
  cmd->add_option("--service", o->service, "Service to check (default: the whole server)");
  cmd->add_option("--timeout", o->timeout_seconds, "Deadline of the check, seconds")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->callback([o] {
    const auto timeout = std::chrono::milliseconds(static_cast<long long>(o->timeout_seconds * 1000.0));
    const HealthAnswer a = CheckHealth(o->channel, o->service, timeout);
    const std::string what = o->service.empty() ? o->channel.target : o->channel.target + " " + o->service;
    if (a.grpc_code != 0) {
      fmt::print("{}: health check failed: {}: {}\n", what,
                 StatusCodeName(static_cast<grpc::StatusCode>(a.grpc_code)), a.grpc_message);
      std::fflush(stdout);
      throw CLI::RuntimeError(1);
    }
    fmt::print("{}: {}\n", what, ToString(a.status));
    std::fflush(stdout);
    if (a.status != ServingStatus::kServing) throw CLI::RuntimeError(1);
  });
}

}  // namespace tubepick::cli
