#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include <grpcpp/support/status.h>

#include "tubepick/v1/planning.pb.h"
#include "tubepick/v1/requests.pb.h"
#include "tubepick/v1/wrench.pb.h"
#include "wire/status_names.h"

namespace tubepick::cell {

/// A planner call that did not produce an answer: the gRPC status of the last try, how many tries
/// were made and the RPC's name. what() reads like
/// "PlanPick failed after 4 tries: UNAVAILABLE: failed to connect to all addresses".
class PlannerError : public std::runtime_error {
 public:
  PlannerError(std::string rpc, grpc::StatusCode code, std::string message, std::uint32_t tries);
  const std::string& rpc() const { return rpc_; }
  grpc::StatusCode code() const { return code_; }
  /// The server's (or gRPC's) status message of the last try.
  const std::string& message() const { return message_; }
  std::uint32_t tries() const { return tries_; }

 private:
  std::string rpc_;
  grpc::StatusCode code_;
  std::string message_;
  std::uint32_t tries_;
};

/// The planning service as the cell controller sees it (PickPlannerService, proto/tubepick/v1).
/// Both calls block until the answer, the deadline or the last retry.
class PlannerClient {
 public:
  virtual ~PlannerClient() = default;
  /// @param deadline time allowed for one try. @throws PlannerError.
  virtual v1::PlanPickResponse PlanPick(const v1::PlanPickRequest& request,
                                        std::chrono::milliseconds deadline) = 0;
  /// @param deadline time allowed for one try. @throws PlannerError.
  virtual v1::AnalyzeWrenchResponse AnalyzeWrench(const v1::AnalyzeWrenchRequest& request,
                                                  std::chrono::milliseconds deadline) = 0;
};

/// How GrpcPlannerClient connects and retries.
struct GrpcPlannerClientOptions {
  /// Further tries after a try that failed with UNAVAILABLE (server down or shutting down) or
  /// RESOURCE_EXHAUSTED (its worker queue is full). Other codes are never retried: they would
  /// fail the same way again.
  /// Five tries after the first ride out a planner restart of up to ~5 s (backoffs 0.2 + 0.4 +
  /// 0.8 + 1.6 + 2 s); the channel reconnects on the same schedule.
  std::uint32_t max_retries = 5;
  /// Wait before the first retry, doubled each retry up to max_backoff.
  std::chrono::milliseconds initial_backoff{200};
  std::chrono::milliseconds max_backoff{2000};
  /// Largest message sent or received, bytes (the server's default limit is 64 MiB; a cloud of
  /// 2.3 M points is 28 MB).
  std::uint32_t max_message_bytes = 64u << 20;
};

/// PlannerClient over a gRPC channel (insecure credentials: loopback or a trusted cell network).
/// Each try gets the whole per-call deadline; the call takes at most
/// (max_retries + 1) · deadline plus the backoffs. Thread-safe (the channel is).
class GrpcPlannerClient final : public PlannerClient {
 public:
  /// @param address HOST:PORT or any gRPC target ("dns:///planner:50051"). Connects lazily.
  explicit GrpcPlannerClient(const std::string& address, GrpcPlannerClientOptions options = {});
  ~GrpcPlannerClient() override;

  v1::PlanPickResponse PlanPick(const v1::PlanPickRequest& request,
                                std::chrono::milliseconds deadline) override;
  v1::AnalyzeWrenchResponse AnalyzeWrench(const v1::AnalyzeWrenchRequest& request,
                                          std::chrono::milliseconds deadline) override;

  const std::string& address() const { return address_; }

 private:
  struct Impl;
  std::string address_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tubepick::cell
