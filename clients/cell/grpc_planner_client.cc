#include <fmt/core.h>
#include <grpcpp/grpcpp.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <set>
#include <thread>

#include "clients/cell/client_credentials.h"
#include "clients/cell/planner_client.h"
#include "core/common/errors.h"
#include "tubepick/v1/service.grpc.pb.h"

namespace tubepick::cell {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

const char* StateName(grpc_connectivity_state state) {
  switch (state) {
    case GRPC_CHANNEL_IDLE:
      return "IDLE";
    case GRPC_CHANNEL_CONNECTING:
      return "CONNECTING";
    case GRPC_CHANNEL_READY:
      return "READY";
    case GRPC_CHANNEL_TRANSIENT_FAILURE:
      return "TRANSIENT_FAILURE";
    case GRPC_CHANNEL_SHUTDOWN:
      return "SHUTDOWN";
  }
  return "UNKNOWN";
}

bool Retryable(grpc::StatusCode code) {
  return code == grpc::StatusCode::UNAVAILABLE || code == grpc::StatusCode::RESOURCE_EXHAUSTED;
}

}  // namespace

PlannerError::PlannerError(std::string rpc, grpc::StatusCode code, std::string message, std::uint32_t tries)
    : std::runtime_error(fmt::format("{} failed after {} {}: {}: {}", rpc, tries,
                                     tries == 1 ? "try" : "tries", StatusCodeName(code), message)),
      rpc_(std::move(rpc)),
      code_(code),
      message_(std::move(message)),
      tries_(tries) {}

struct GrpcPlannerClient::Impl {
  std::string address;
  GrpcPlannerClientOptions options;
  std::shared_ptr<grpc::Channel> channel;
  std::unique_ptr<v1::PickPlannerService::Stub> stub;

  // Cancellation (CancelCalls): the contexts of the RPCs in flight, and a count of the cancels so
  // far; a call started before the last cancel ends with CANCELLED.
  std::mutex mutex;
  std::condition_variable cancelled;
  std::set<grpc::ClientContext*> in_flight;
  std::uint64_t cancels = 0;

  std::uint64_t Cancels() {
    std::lock_guard lock(mutex);
    return cancels;
  }

  [[noreturn]] static void ThrowCancelled(const char* rpc, std::uint32_t attempt) {
    throw PlannerError(rpc, grpc::StatusCode::CANCELLED, "cancelled: the run is stopping", attempt);
  }

  /// Runs one try with `context` registered for CancelCalls; false when a cancel came first.
  template <typename Response, typename Call>
  bool TryCall(std::uint64_t generation, grpc::ClientContext& context, Call& call, Response& response,
               grpc::Status& status) {
    {
      std::lock_guard lock(mutex);
      if (cancels != generation) return false;
      in_flight.insert(&context);
    }
    status = call(&context, &response);
    std::lock_guard lock(mutex);
    in_flight.erase(&context);
    return cancels == generation || status.ok();
  }

  /// Waits for the channel to connect within `left`, in short slices so that a cancel ends it.
  bool WaitForConnection(std::uint64_t generation, Clock::duration left) {
    const Clock::time_point end = Clock::now() + left;
    for (;;) {
      if (Cancels() != generation) return false;
      const Clock::duration slice =
          std::min<Clock::duration>(end - Clock::now(), std::chrono::milliseconds(100));
      if (slice <= Clock::duration::zero()) return false;
      if (channel->WaitForConnected(std::chrono::system_clock::now() +
                                    std::chrono::duration_cast<std::chrono::system_clock::duration>(slice)))
        return true;
    }
  }

  /// Sleeps `backoff`; false when a cancel ended it.
  bool Backoff(std::uint64_t generation, std::chrono::milliseconds backoff) {
    std::unique_lock lock(mutex);
    return !cancelled.wait_for(lock, backoff, [&] { return cancels != generation; });
  }

  /// Why a connection to the planner may fail, for the error message: the likely cause the
  /// configuration suggests.
  std::string ConnectionHint(const std::string& grpc_message) const {
    const bool refused = grpc_message.find("refused") != std::string::npos;
    if (refused) return fmt::format("; is the planner running and listening at {}?", address);
    if (options.tls_ca_file.empty() && options.tls_cert_file.empty())
      return "; plaintext channel: a planner that serves TLS closes it (set tls_ca_file)";
    if (options.tls_cert_file.empty())
      return "; TLS without a client certificate: a planner that requires mutual TLS "
             "(tls.require_client_cert) refuses it (set tls_cert_file and tls_key_file)";
    return "; TLS: check that tls_ca_file signed the planner's certificate, that the planner's "
           "client CA signed tls_cert_file, and the name checked (tls_server_name)";
  }

  /// The status message, with the channel's state when the try ran out of time without a
  /// connection (the planner was unreachable, not slow).
  std::string Describe(const grpc::Status& status) const {
    std::string message = status.error_message();
    if (status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED) {
      const grpc_connectivity_state state = channel->GetState(false);
      if (state != GRPC_CHANNEL_READY)
        message += fmt::format(" (the channel to {} is {}: the planner became unreachable during the call)",
                               address, StateName(state));
    }
    return message;
  }

  /// Runs `call(context, response)`: waits for a connection and retries UNAVAILABLE /
  /// RESOURCE_EXHAUSTED while the time spent unable to reach the planner stays within
  /// options.unavailable_budget (GrpcPlannerClientOptions).
  template <typename Response, typename Call>
  Response Invoke(const char* rpc, std::chrono::milliseconds deadline, Call call) {
    // A call never waits for the planner longer than its own deadline either.
    const Clock::duration budget = std::min<Clock::duration>(options.unavailable_budget, deadline);
    const char* budget_name =
        deadline < options.unavailable_budget ? "the call's deadline" : "unavailable_budget";
    Clock::duration unavailable{0};
    std::chrono::milliseconds backoff = options.initial_backoff;
    std::uint32_t retries = 0;
    const std::uint64_t generation = Cancels();
    for (std::uint32_t attempt = 1;; ++attempt) {
      if (channel->GetState(true) != GRPC_CHANNEL_READY) {
        const Clock::time_point wait_start = Clock::now();
        const Clock::duration left = budget - unavailable;
        const bool connected = left > Clock::duration::zero() && WaitForConnection(generation, left);
        unavailable += Clock::now() - wait_start;
        if (Cancels() != generation) ThrowCancelled(rpc, attempt);
        if (!connected)
          return LastTry<Response>(rpc, deadline, call, attempt, unavailable, budget_name, generation);
      }
      grpc::ClientContext context;
      // Fail fast: a connection lost just now (a planner killed between calls, the channel still
      // READY) gives UNAVAILABLE at once, which the loop retries within the budget; waiting for
      // ready would wait out the call's deadline (minutes for a PlanPick) instead.
      context.set_wait_for_ready(false);
      context.set_deadline(std::chrono::system_clock::now() + deadline);
      Response response;
      grpc::Status status;
      if (!TryCall(generation, context, call, response, status)) ThrowCancelled(rpc, attempt);
      if (status.ok()) return response;
      if (!Retryable(status.error_code()))
        throw PlannerError(rpc, status.error_code(), Describe(status), attempt);
      if (options.max_retries && retries >= *options.max_retries)
        throw PlannerError(rpc, status.error_code(),
                           fmt::format("{} (max_retries = {})", status.error_message(), *options.max_retries),
                           attempt);
      if (unavailable + backoff > budget)
        throw PlannerError(rpc, status.error_code(),
                           fmt::format("{} ({} of {:.1f} s spent unable to reach the planner)",
                                       status.error_message(), budget_name, Seconds(budget)),
                           attempt);
      ++retries;
      spdlog::warn("{}: {} ({}), retry {} in {} ms ({:.1f} of {:.1f} s of {} spent)", rpc,
                   StatusCodeName(status.error_code()), status.error_message(), retries, backoff.count(),
                   Seconds(unavailable), Seconds(budget), budget_name);
      if (!Backoff(generation, backoff)) ThrowCancelled(rpc, attempt);
      unavailable += backoff;
      backoff = std::min(backoff * 2, options.max_backoff);
    }
  }

  /// No connection within the budget: one try that fails fast (no wait_for_ready) so that the
  /// error says why gRPC could not connect (refused, TLS handshake, name resolution); it runs the
  /// call if the planner came back in the meantime.
  template <typename Response, typename Call>
  Response LastTry(const char* rpc, std::chrono::milliseconds deadline, Call call, std::uint32_t attempt,
                   Clock::duration unavailable, const char* budget_name, std::uint64_t generation) {
    grpc::ClientContext context;
    context.set_wait_for_ready(false);
    context.set_deadline(std::chrono::system_clock::now() + deadline);
    Response response;
    grpc::Status status;
    if (!TryCall(generation, context, call, response, status)) ThrowCancelled(rpc, attempt);
    if (status.ok()) return response;
    const grpc::StatusCode code =
        Retryable(status.error_code()) ? grpc::StatusCode::UNAVAILABLE : status.error_code();
    throw PlannerError(
        rpc, code,
        fmt::format("no connection to the planner at {} within {:.1f} s ({}); channel {}: {}{}", address,
                    Seconds(unavailable), budget_name, StateName(channel->GetState(false)),
                    status.error_message(), ConnectionHint(status.error_message())),
        attempt);
  }
};

GrpcPlannerClient::GrpcPlannerClient(const std::string& address, GrpcPlannerClientOptions options)
    : address_(address), impl_(std::make_unique<Impl>()) {
  if (address.empty()) throw InvalidArgument("planner address: must not be empty");
  if (options.initial_backoff.count() < 0 || options.max_backoff < options.initial_backoff)
    throw InvalidArgument(fmt::format("planner backoff: need 0 <= initial ({} ms) <= max ({} ms)",
                                      options.initial_backoff.count(), options.max_backoff.count()));
  if (options.unavailable_budget.count() <= 0)
    throw InvalidArgument(fmt::format(
        "planner unavailable_budget: must be positive (the time a call may wait for the planner), got {} ms",
        options.unavailable_budget.count()));
  if (options.max_message_bytes == 0 || options.max_message_bytes > static_cast<std::uint32_t>(INT32_MAX))
    throw InvalidArgument(fmt::format("planner max_message_bytes: must be in [1, {}], got {}", INT32_MAX,
                                      options.max_message_bytes));
  impl_->address = address;
  impl_->options = options;
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(static_cast<int>(options.max_message_bytes));
  args.SetMaxSendMessageSize(static_cast<int>(options.max_message_bytes));
  // Reconnect on the retries' schedule, at most max_backoff apart: gRPC's own default grows to
  // 120 s between connection attempts, so a planner back after a restart would stay unreachable
  // for minutes. (gRPC core also takes the "min reconnect backoff" as the least time one
  // connection attempt is given: max_backoff leaves a TLS handshake enough.)
  args.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, static_cast<int>(options.initial_backoff.count()));
  args.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, static_cast<int>(options.max_backoff.count()));
  args.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, static_cast<int>(options.max_backoff.count()));
  const ClientTlsFiles tls{options.tls_ca_file, options.tls_cert_file, options.tls_key_file,
                           options.tls_server_name};
  impl_->channel = grpc::CreateCustomChannel(address, MakeClientCredentials(tls, args), args);
  impl_->stub = v1::PickPlannerService::NewStub(impl_->channel);
}

GrpcPlannerClient::~GrpcPlannerClient() = default;

void GrpcPlannerClient::CancelCalls() {
  std::lock_guard lock(impl_->mutex);
  ++impl_->cancels;
  for (grpc::ClientContext* context : impl_->in_flight) context->TryCancel();
  impl_->cancelled.notify_all();
}

bool GrpcPlannerClient::tls() const {
  return !impl_->options.tls_ca_file.empty() || !impl_->options.tls_cert_file.empty();
}

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
