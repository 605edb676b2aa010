#include <fmt/core.h>
#include <grpcpp/grpcpp.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <thread>

#include "clients/cell/planner_client.h"
#include "core/common/errors.h"
#include "tubepick/v1/service.grpc.pb.h"

namespace tubepick::cell {

PlannerError::PlannerError(std::string rpc, grpc::StatusCode code, std::string message, std::uint32_t tries)
    : std::runtime_error(fmt::format("{} failed after {} {}: {}: {}", rpc, tries,
                                     tries == 1 ? "try" : "tries", StatusCodeName(code), message)),
      rpc_(std::move(rpc)),
      code_(code),
      message_(std::move(message)),
      tries_(tries) {}

struct GrpcPlannerClient::Impl {
  GrpcPlannerClientOptions options;
  std::shared_ptr<grpc::Channel> channel;
  std::unique_ptr<v1::PickPlannerService::Stub> stub;

  /// Runs `call(context, response)` with retries on UNAVAILABLE / RESOURCE_EXHAUSTED.
  template <typename Response, typename Call>
  Response Invoke(const char* rpc, std::chrono::milliseconds deadline, Call call) {
    std::chrono::milliseconds backoff = options.initial_backoff;
    for (std::uint32_t attempt = 1;; ++attempt) {
      grpc::ClientContext context;
      context.set_deadline(std::chrono::system_clock::now() + deadline);
      Response response;
      const grpc::Status status = call(&context, &response);
      if (status.ok()) return response;
      const bool retryable = status.error_code() == grpc::StatusCode::UNAVAILABLE ||
                             status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED;
      if (!retryable || attempt > options.max_retries)
        throw PlannerError(rpc, status.error_code(), status.error_message(), attempt);
      spdlog::warn("{}: {} ({}), retry {}/{} in {} ms", rpc, StatusCodeName(status.error_code()),
                   status.error_message(), attempt, options.max_retries, backoff.count());
      std::this_thread::sleep_for(backoff);
      backoff = std::min(backoff * 2, options.max_backoff);
    }
  }
};

GrpcPlannerClient::GrpcPlannerClient(const std::string& address, GrpcPlannerClientOptions options)
    : address_(address), impl_(std::make_unique<Impl>()) {
  if (address.empty()) throw InvalidArgument("planner address: must not be empty");
  if (options.initial_backoff.count() < 0 || options.max_backoff < options.initial_backoff)
    throw InvalidArgument(fmt::format("planner backoff: need 0 <= initial ({} ms) <= max ({} ms)",
                                      options.initial_backoff.count(), options.max_backoff.count()));
  impl_->options = options;
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(static_cast<int>(options.max_message_bytes));
  args.SetMaxSendMessageSize(static_cast<int>(options.max_message_bytes));
  // Reconnect within the retries' backoff: gRPC's own default grows to 120 s between connection
  // attempts, so a planner back after a restart would stay unreachable for minutes.
  args.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, static_cast<int>(options.initial_backoff.count()));
  args.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, static_cast<int>(options.initial_backoff.count()));
  args.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, static_cast<int>(options.max_backoff.count()));
  impl_->channel = grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args);
  impl_->stub = v1::PickPlannerService::NewStub(impl_->channel);
}

GrpcPlannerClient::~GrpcPlannerClient() = default;

v1::PlanPickResponse GrpcPlannerClient::PlanPick(const v1::PlanPickRequest& request,
                                                 std::chrono::milliseconds deadline) {
  return impl_->Invoke<v1::PlanPickResponse>(
      "PlanPick", deadline, [&](grpc::ClientContext* context, v1::PlanPickResponse* response) {
        return impl_->stub->PlanPick(context, request, response);
      });
}

v1::AnalyzeWrenchResponse GrpcPlannerClient::AnalyzeWrench(const v1::AnalyzeWrenchRequest& request,
                                                           std::chrono::milliseconds deadline) {
  return impl_->Invoke<v1::AnalyzeWrenchResponse>(
      "AnalyzeWrench", deadline, [&](grpc::ClientContext* context, v1::AnalyzeWrenchResponse* response) {
        return impl_->stub->AnalyzeWrench(context, request, response);
      });
}

}  // namespace tubepick::cell
