#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
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
  /// The server's (or gRPC's) status message of the last try, with what ended the tries (the
  /// unavailable_budget spent, max_retries, no connection and the likely cause).
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
  /// Ends the calls under way at once (from any thread; an operator stop): they throw
  /// PlannerError(CANCELLED). Calls started afterwards run normally. Default: nothing to cancel.
  virtual void CancelCalls() {}
};

/// How GrpcPlannerClient connects, waits and retries.
///
/// A planner restart must not end a run: every call waits for a connection (gRPC wait_for_ready)
/// and is tried again after an UNAVAILABLE or RESOURCE_EXHAUSTED answer, for as long as the time
/// the call has spent unable to reach the planner (waiting for a connection, backing off between
/// tries) stays within unavailable_budget. The channel reconnects at most max_backoff apart, so a
/// restarted planner is found within about a second. With the defaults a planner that is away for
/// up to 15 s (a restart takes 1-10 s) costs the run that time and nothing else; one away longer
/// ends the call with PlannerError(UNAVAILABLE) naming the address and gRPC's own connection error.
/// The time a try spends on the planner (its per-call deadline) is not part of the budget; a call
/// whose deadline is shorter than the budget waits at most its deadline (AnalyzeWrench, 10 s by
/// default, then falls back to the controller's local analysis).
struct GrpcPlannerClientOptions {
  /// Longest time one call spends unable to reach the planner: waiting for a connection plus the
  /// backoffs between tries that failed with UNAVAILABLE (server down or shutting down) or
  /// RESOURCE_EXHAUSTED (its worker queue is full). Other codes are never retried: they would fail
  /// the same way again. Must be positive.
  std::chrono::milliseconds unavailable_budget{15'000};
  /// Optional cap on the tries after an UNAVAILABLE / RESOURCE_EXHAUSTED answer (nullopt: the
  /// budget alone decides). Waiting for a connection is not a try.
  std::optional<std::uint32_t> max_retries;
  /// Wait before the first retry, doubled each retry up to max_backoff; the channel's reconnection
  /// attempts follow the same schedule (gRPC's default grows to 120 s between attempts).
  std::chrono::milliseconds initial_backoff{200};
  std::chrono::milliseconds max_backoff{1'000};
  /// Largest message sent or received, bytes (the server's default limit is 64 MiB; a cloud of
  /// 2.3 M points is 28 MB).
  std::uint32_t max_message_bytes = 64u << 20;

  /// TLS (the same PEM files the server's `tls` section takes; see client_credentials.h). All empty:
  /// plaintext (loopback or a trusted cell network). tls_ca_file: the CA bundle the planner's
  /// certificate must chain to; tls_cert_file + tls_key_file: the client certificate for a planner
  /// that requires mutual TLS (tls.require_client_cert); tls_server_name: the name checked against
  /// the planner's certificate instead of the address's host (needs tls_ca_file).
  std::string tls_ca_file;
  std::string tls_cert_file;
  std::string tls_key_file;
  std::string tls_server_name;
};

/// PlannerClient over a gRPC channel, plaintext or TLS (GrpcPlannerClientOptions). Each try gets
/// the whole per-call deadline once connected; a call takes at most the tries' deadlines plus
/// min(unavailable_budget, deadline). Thread-safe (the channel is).
class GrpcPlannerClient final : public PlannerClient {
 public:
  /// @param address HOST:PORT or any gRPC target ("dns:///planner:50051"). Connects lazily.
  /// @throws InvalidArgument for an empty address, bad backoffs or budget, inconsistent TLS options
  ///   or an unreadable TLS file (naming it).
  explicit GrpcPlannerClient(const std::string& address, GrpcPlannerClientOptions options = {});
  ~GrpcPlannerClient() override;

  v1::PlanPickResponse PlanPick(const v1::PlanPickRequest& request,
                                std::chrono::milliseconds deadline) override;
  v1::AnalyzeWrenchResponse AnalyzeWrench(const v1::AnalyzeWrenchRequest& request,
                                          std::chrono::milliseconds deadline) override;
  /// Cancels the RPCs in flight (ClientContext::TryCancel) and ends the waits for a connection and
  /// the backoffs of the calls under way.
  void CancelCalls() override;

  const std::string& address() const { return address_; }
  /// Whether the channel uses TLS.
  bool tls() const;

 private:
  struct Impl;
  std::string address_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tubepick::cell
