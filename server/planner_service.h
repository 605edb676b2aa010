#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <set>
#include <string>

#include "core/common/stop_token.h"
#include "server/debug_calls.h"
#include "server/metrics.h"
#include "server/request_validation.h"
#include "server/server_config.h"
#include "server/upload_slots.h"
#include "server/upload_watchdog.h"
#include "server/worker_pool.h"
#include "tubepick/v1/service.grpc.pb.h"

namespace tubepick::server {

/// PickPlannerService on gRPC's callback API. Each call:
/// - gets a request id (the client's `x-request-id` metadata when it is sane, else a generated
///   one), echoed in the initial metadata and written in its log line (LogCall) and metrics;
/// - gets a StopToken carrying the call's deadline, stopped by ServerUnaryReactor::OnCancel
///   (client cancel, deadline, shutdown), which modeling and simulation poll;
/// - a call without a deadline gets server.max_call_time as its deadline;
/// - ModelTubes / PlanPick are admitted to the WorkerPool or refused at once with
///   RESOURCE_EXHAUSTED. A PlanPickStream's upload is admitted apart (UploadSlots,
///   server.max_uploads: an upload holds no planning slot), is ended by the UploadWatchdog after
///   server.stream_idle_timeout without a message, and its complete cloud then asks the WorkerPool
///   for a slot like a unary call. Validation and work run on the worker with ThreadsPerCall
///   threads; a call whose deadline passed (or that was cancelled) while queued is dropped without
///   running. AnalyzeWrench is microseconds of arithmetic and runs inline;
/// - errors map as: TooLarge (over a point or byte limit) → RESOURCE_EXHAUSTED, the code gRPC gives
///   a message over max_message_bytes; InvalidArgument → INVALID_ARGUMENT (its message);
///   FailedPrecondition (a cloud that misses the bin) → FAILED_PRECONDITION (its message);
///   Cancelled → CANCELLED or DEADLINE_EXCEEDED; anything else → INTERNAL (logged with the
///   request id).
class PlannerService final : public v1::PickPlannerService::CallbackService {
 public:
  /// `pool` and `metrics` must outlive the service; so must `debug_calls` (null = keep no calls), which
  /// gets every ModelTubes, PlanPick and PlanPickStream call as it is answered (debug.keep_last).
  PlannerService(ServerConfig config, WorkerPool* pool, Metrics* metrics,
                 DebugCallStore* debug_calls = nullptr);

  grpc::ServerUnaryReactor* ModelTubes(grpc::CallbackServerContext* context,
                                       const v1::ModelTubesRequest* request,
                                       v1::ModelTubesResponse* response) override;
  grpc::ServerUnaryReactor* PlanPick(grpc::CallbackServerContext* context, const v1::PlanPickRequest* request,
                                     v1::PlanPickResponse* response) override;
  grpc::ServerReadReactor<v1::PlanPickStreamRequest>* PlanPickStream(
      grpc::CallbackServerContext* context, v1::PlanPickStreamResponse* response) override;
  grpc::ServerUnaryReactor* AnalyzeWrench(grpc::CallbackServerContext* context,
                                          const v1::AnalyzeWrenchRequest* request,
                                          v1::AnalyzeWrenchResponse* response) override;

  /// Stops every call in progress (their workers throw Cancelled at the next poll). Shutdown uses
  /// it when the grace period is over.
  void CancelAll();
  /// Calls whose reactor has not completed yet.
  std::size_t calls_in_flight() const;
  /// Calls answered so far, any status.
  std::uint64_t calls_served() const { return served_.load(); }
  /// PlanPickStream calls still receiving their cloud.
  std::uint32_t uploads_in_progress() const { return uploads_.in_use(); }

 private:
  struct CallState;
  class UnaryCall;
  class StreamCall;

  /// Queues `body` (validation and work, filling the response and the record) for a unary call.
  grpc::ServerUnaryReactor* StartPlanning(grpc::CallbackServerContext* context, const char* rpc,
                                          std::uint64_t points, std::function<void(CallState&)> body);
  /// The worker side of every planning call: drops expired calls, runs `body`, maps exceptions.
  grpc::Status RunOnWorker(CallState& call, std::chrono::steady_clock::time_point enqueued,
                           const std::function<void()>& body);
  grpc::Status Rejected(const CallState& call);
  grpc::Status Conclude(CallState& call, grpc::Status status);
  /// With debug.keep_last: keeps the job's cloud (thinned, bin frame) and cell for the call's page.
  void CaptureForDebug(CallState& call, const PlanningJob& job) const;
  void Register(StopToken* token);
  void Unregister(StopToken* token);

  const ServerConfig config_;
  DebugCallStore* const debug_calls_;
  const std::uint32_t threads_per_call_;
  WorkerPool* pool_;
  Metrics* metrics_;
  UploadSlots uploads_;
  UploadWatchdog upload_watchdog_;
  mutable std::mutex calls_mu_;
  std::set<StopToken*> active_;
  std::atomic<std::uint64_t> served_{0};
};

}  // namespace tubepick::server
