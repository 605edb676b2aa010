#include "server/planner_service.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <optional>
#include <random>
#include <utility>

#include "core/common/errors.h"
#include "server/planning_jobs.h"
#include "server/request_log.h"
#include "server/request_validation.h"
#include "wire/cloud_stream.h"
#include "wire/status_names.h"

namespace tubepick::server {
namespace {

using Clock = std::chrono::steady_clock;

double Ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

// A config's seconds as a steady-clock duration.
Clock::duration Seconds(double seconds) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

// The codes of a modeling's warnings, for the call's log line and metrics.
std::vector<std::string> WarningCodes(const v1::ModelTubesResponse& modeling) {
  std::vector<std::string> codes;
  for (const v1::ModelingWarning& w : modeling.warnings()) codes.push_back(w.code());
  return codes;
}

// A caller mistake's status: RESOURCE_EXHAUSTED for one over a size limit (TooLarge, the code gRPC
// gives a message over max_message_bytes), INVALID_ARGUMENT for the rest. Every path maps it here.
grpc::Status CallerMistake(const InvalidArgument& e) {
  const bool too_large = dynamic_cast<const TooLarge*>(&e) != nullptr;
  return {too_large ? grpc::StatusCode::RESOURCE_EXHAUSTED : grpc::StatusCode::INVALID_ARGUMENT, e.what()};
}

// A client's x-request-id is kept when it is 1..128 printable ASCII characters without spaces
// (it goes into log lines and metadata verbatim); anything else gets a fresh id.
bool SaneRequestId(std::string_view id) {
  if (id.empty() || id.size() > 128) return false;
  return std::all_of(id.begin(), id.end(),
                     [](char c) { return c > 0x20 && c < 0x7f && c != '"' && c != '\\'; });
}

// 16 random hex digits. Request ids need uniqueness, not reproducibility.
std::string NewRequestId() {
  thread_local std::mt19937_64 rng{std::random_device{}() ^
                                   static_cast<std::uint64_t>(Clock::now().time_since_epoch().count())};
  return fmt::format("{:016x}", rng());
}

std::string RequestIdOf(const grpc::CallbackServerContext& context) {
  const auto& metadata = context.client_metadata();
  const auto it = metadata.find("x-request-id");
  if (it != metadata.end()) {
    const std::string_view id(it->second.data(), it->second.size());
    if (SaneRequestId(id)) return std::string(id);
  }
  return NewRequestId();
}

// A cancel this close before a client's deadline is taken for that deadline (CallState::DeadlineReached).
constexpr auto kClientDeadlineSkew = std::chrono::milliseconds(100);

// The call's deadline on the steady clock; nullopt for none (gRPC reports "infinite" as max()).
std::optional<Clock::time_point> SteadyDeadline(const grpc::CallbackServerContext& context) {
  const auto deadline = context.deadline();
  if (deadline >= std::chrono::system_clock::time_point::max() - std::chrono::hours(24 * 365))
    return std::nullopt;
  return Clock::now() +
         std::chrono::duration_cast<Clock::duration>(deadline - std::chrono::system_clock::now());
}

}  // namespace

/// Bookkeeping shared by the unary and the stream reactors.
struct PlannerService::CallState {
  CallState(grpc::CallbackServerContext* context, const char* rpc, double max_call_time)
      : arrived(Clock::now()) {
    record.rpc = rpc;
    record.request_id = RequestIdOf(*context);
    record.peer = context->peer();
    deadline = SteadyDeadline(*context);
    if (!deadline) {  // no call runs forever: server.max_call_time is the deadline of one that sets none
      deadline = arrived + Seconds(max_call_time);
      max_call_time_s = max_call_time;
    }
    token.set_deadline(*deadline);
    context->AddInitialMetadata("x-request-id", record.request_id);
  }

  void MarkCancelled() {
    std::int64_t expected = 0;
    cancelled_at.compare_exchange_strong(expected, Clock::now().time_since_epoch().count());
    token.RequestStop();
  }

  /// When the call was asked to stop: the cancel, or the deadline if that came first.
  std::optional<Clock::time_point> StopTime() const {
    std::optional<Clock::time_point> t;
    if (const std::int64_t ns = cancelled_at.load(); ns != 0) t = Clock::time_point(Clock::duration(ns));
    if (deadline && Clock::now() >= *deadline && (!t || *deadline < *t)) t = deadline;
    return t;
  }

  /// The deadline has passed, or the cancel came so close before the client's deadline that it is
  /// the client's own: its RST_STREAM at the deadline can beat the server's timer, which started
  /// when the headers arrived (seen on a loaded machine: CANCELLED 150 ms into a 300 ms call).
  bool DeadlineReached() const {
    if (token.deadline_passed()) return true;
    const std::int64_t ns = cancelled_at.load();
    return ns != 0 && deadline && !max_call_time_s &&
           Clock::time_point(Clock::duration(ns)) + kClientDeadlineSkew >= *deadline;
  }

  /// CANCELLED, or DEADLINE_EXCEEDED when the deadline has passed (gRPC also cancels a call at its
  /// deadline, so the token may say "cancelled" for an expired call).
  grpc::Status CancelledStatus(const std::string& what) const {
    if (!DeadlineReached()) return {grpc::StatusCode::CANCELLED, what};
    const std::string_view cancelled = "cancelled ";
    std::string message =
        what.rfind(cancelled, 0) == 0 ? "deadline exceeded " + what.substr(cancelled.size()) : what;
    if (max_call_time_s) {
      message += fmt::format(" (the call set no deadline; server.max_call_time is {:g} s)", *max_call_time_s);
    }
    return {grpc::StatusCode::DEADLINE_EXCEEDED, message};
  }

  const Clock::time_point arrived;
  std::optional<Clock::time_point> deadline;
  /// Set when the deadline is server.max_call_time's, not the client's.
  std::optional<double> max_call_time_s;
  StopToken token;
  std::atomic<std::int64_t> cancelled_at{0};  // steady ns of OnCancel; 0 = not cancelled
  bool ran = false;                           // reached a worker and started
  CallRecord record;
  /// The call's cloud, cell and response for /debug/calls (debug.keep_last > 0, once valid).
  std::optional<DebugCapture> debug;
};

class PlannerService::UnaryCall final : public grpc::ServerUnaryReactor {
 public:
  UnaryCall(PlannerService* service, grpc::CallbackServerContext* context, const char* rpc)
      : service_(service), state_(context, rpc, service->config_.max_call_time) {
    service_->Register(&state_.token);
  }
  CallState& state() { return state_; }
  /// Logs, counts and finishes the call. `this` may be deleted as soon as it returns.
  void Answer(grpc::Status status) { Finish(service_->Conclude(state_, std::move(status))); }

  void OnCancel() override { state_.MarkCancelled(); }
  void OnDone() override {
    service_->Unregister(&state_.token);
    delete this;
  }

 private:
  PlannerService* service_;
  CallState state_;
};

/// One PlanPickStream: the upload (admitted by UploadSlots, watched for silence by the
/// UploadWatchdog), then the planning job on the WorkerPool. Who finishes the call is settled by its
/// UploadWatch: the reactor, or the watchdog when the upload went quiet (then the reactor neither
/// reads on nor finishes).
class PlannerService::StreamCall final : public grpc::ServerReadReactor<v1::PlanPickStreamRequest> {
 public:
  StreamCall(PlannerService* service, grpc::CallbackServerContext* context,
             v1::PlanPickStreamResponse* response)
      : service_(service),
        context_(context),
        state_(context, "PlanPickStream", service->config_.max_call_time),
        response_(response),
        assembler_(service->config_.max_stream_bytes),
        watch_(service->upload_watchdog_.Watch([this] { FinishIdle(); })) {
    service_->Register(&state_.token);
    StartRead(&message_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) {
      UploadEnded();
      return;
    }
    if (!watch_->Touch()) return;  // the watchdog ended the upload
    try {
      const bool had_header = assembler_.has_header();
      const std::uint64_t announced = message_.has_header() ? message_.header().total_bytes() : 0;
      assembler_.Add(message_);
      if (!had_header) {  // Add accepts nothing but a header first
        state_.record.points = announced / 12;
        RequireAnnouncedPointsWithinLimit(announced);
        if (std::optional<grpc::Status> refused = AdmitUpload()) {
          Answer(*refused);
          return;
        }
      }
    } catch (const InvalidArgument& e) {
      Answer(CallerMistake(e));
      return;
    }
    message_.Clear();
    StartRead(&message_);
  }

  void OnCancel() override { state_.MarkCancelled(); }
  void OnDone() override {
    service_->Unregister(&state_.token);
    delete this;
  }

 private:
  // The point limit of planning.max_cloud_points, checked at the header (as CheckCloudBytes checks a
  // unary request's cloud), before anything is admitted or reserved.
  void RequireAnnouncedPointsWithinLimit(std::uint64_t announced_bytes) const {
    const std::uint64_t limit = service_->config_.planning.max_cloud_points;
    if (announced_bytes / 12 > limit) {
      throw TooLarge(
          fmt::format("header.total_bytes: {} bytes announce {} points, more than the limit of {} "
                      "(planning.max_cloud_points)",
                      announced_bytes, announced_bytes / 12, limit));
    }
  }

  // At the header: refused at once when planning is full (the cloud could not run when complete)
  // or when server.max_uploads uploads are in progress; else the upload takes its slot.
  std::optional<grpc::Status> AdmitUpload() {
    if (!service_->pool_->HasRoom()) return service_->Rejected(state_);
    std::optional<UploadSlots::Slot> slot = service_->uploads_.TryAcquire();
    if (!slot) {
      service_->metrics_->RecordRejected();
      return grpc::Status(
          grpc::StatusCode::RESOURCE_EXHAUSTED,
          fmt::format("uploads full: {} PlanPickStream uploads in progress (server.max_uploads); "
                      "retry later",
                      service_->uploads_.capacity()));
    }
    upload_slot_ = std::move(*slot);
    return std::nullopt;
  }

  // The client half-closed, or the call broke: a complete upload asks the pool for a worker; a
  // broken one (the client cancelled, its deadline passed, the connection dropped) is CANCELLED or
  // DEADLINE_EXCEEDED, and a half-closed incomplete one is INVALID_ARGUMENT, without a worker.
  void UploadEnded() {
    if (!watch_->StopWatching()) return;  // the watchdog ended the upload
    upload_slot_.Release();
    if (state_.token.should_stop() || context_->IsCancelled()) {
      state_.MarkCancelled();
      Answer(state_.CancelledStatus(fmt::format("stopped while the cloud was uploading ({} bytes received)",
                                                assembler_.received_bytes())));
      return;
    }
    if (!assembler_.has_header()) {
      Answer(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                          "PlanPickStream ended before its header: the first message must be a header"));
      return;
    }
    try {
      cloud_ = assembler_.Finish();  // cheap: checks chunks, size and CRC, moves the joined bytes
    } catch (const InvalidArgument& e) {
      Answer(CallerMistake(e));
      return;
    }
    const Clock::time_point enqueued = Clock::now();
    const WorkerPool::Admission admission = service_->pool_->TrySubmit([this, enqueued] {
      const grpc::Status status = service_->RunOnWorker(state_, enqueued, [this] {
        const PlanningJob job = ValidatePlanPick(assembler_.request(), cloud_, service_->config_.planning);
        state_.record.points = job.xyz_Sensor.size() / 12;
        service_->CaptureForDebug(state_, job);
        *response_->mutable_response() =
            RunPlanPick(job, service_->config_.planning, service_->threads_per_call_, &state_.token);
        if (state_.debug) state_.debug->frame.plan = response_->response();
        std::string().swap(cloud_);  // modeling read the bytes in place
        state_.record.tubes = static_cast<std::uint32_t>(response_->response().tubes_size());
        state_.record.plans = static_cast<std::uint32_t>(response_->response().plans_size());
        state_.record.warnings = WarningCodes(response_->response().modeling());
      });
      Answer(status);
    });
    if (admission == WorkerPool::Admission::kFull) {
      Answer(service_->Rejected(state_));
    } else if (admission == WorkerPool::Admission::kStopped) {
      Answer(grpc::Status(grpc::StatusCode::UNAVAILABLE, "the server is shutting down"));
    }
  }

  // On the watchdog's thread, which took the call over: nothing arrived for stream_idle_timeout.
  void FinishIdle() {
    upload_slot_.Release();
    const double timeout = service_->config_.stream_idle_timeout;
    const std::string progress =
        assembler_.has_header()
            ? fmt::format("{} of {} bytes received", assembler_.received_bytes(), state_.record.points * 12)
            : std::string("before its header");
    Finish(service_->Conclude(
        state_,
        grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED,
                     fmt::format("upload idle: no message for {:g} s (server.stream_idle_timeout), {}; "
                                 "the upload is ended",
                                 timeout, progress))));
  }

  void Answer(grpc::Status status) {
    if (!watch_->ClaimFinish()) return;  // the watchdog finishes this call
    upload_slot_.Release();
    Finish(service_->Conclude(state_, std::move(status)));
  }

  PlannerService* service_;
  grpc::CallbackServerContext* context_;
  CallState state_;
  v1::PlanPickStreamResponse* response_;
  v1::PlanPickStreamRequest message_;
  CloudStreamAssembler assembler_;
  /// The joined cloud bytes of a complete upload, until the job has modeled them.
  std::string cloud_;
  UploadSlots::Slot upload_slot_;
  std::shared_ptr<UploadWatch> watch_;
};

PlannerService::PlannerService(ServerConfig config, WorkerPool* pool, Metrics* metrics,
                               DebugCallStore* debug_calls)
    : config_(std::move(config)),
      debug_calls_(debug_calls),
      threads_per_call_(ThreadsPerCall(config_)),
      pool_(pool),
      metrics_(metrics),
      uploads_(config_.max_uploads),
      upload_watchdog_(Seconds(config_.stream_idle_timeout)) {}

void PlannerService::Register(StopToken* token) {
  std::lock_guard lock(calls_mu_);
  active_.insert(token);
}

void PlannerService::Unregister(StopToken* token) {
  std::lock_guard lock(calls_mu_);
  active_.erase(token);
}

void PlannerService::CancelAll() {
  std::lock_guard lock(calls_mu_);
  for (StopToken* token : active_) token->RequestStop();
}

std::size_t PlannerService::calls_in_flight() const {
  std::lock_guard lock(calls_mu_);
  return active_.size();
}

grpc::Status PlannerService::Rejected(const CallState&) {
  metrics_->RecordRejected();
  const PoolLoad load = pool_->load();
  return {grpc::StatusCode::RESOURCE_EXHAUSTED,
          fmt::format("planning queue full: {} running, {} queued; retry later", load.busy, load.queued)};
}

grpc::Status PlannerService::Conclude(CallState& call, grpc::Status status) {
  const Clock::time_point now = Clock::now();
  CallRecord& r = call.record;
  r.code = StatusCodeName(status.error_code());
  r.message = status.error_message();
  r.total_ms = Ms(now - call.arrived);
  if (call.ran && !status.ok()) {
    if (const std::optional<Clock::time_point> stop = call.StopTime())
      r.stop_ms = std::max(0.0, Ms(now - *stop));
  }
  if (!status.ok()) {
    r.tubes = 0;
    r.plans = 0;
  }
  if (!status.ok()) r.warnings.clear();
  metrics_->RecordCall(r.rpc, r.code, r.total_ms / 1000.0);
  for (const std::string& code : r.warnings) metrics_->RecordModelingWarning(code);
  LogCall(r);
  if (debug_calls_ != nullptr && r.rpc != "AnalyzeWrench") debug_calls_->Add(r, std::move(call.debug));
  served_.fetch_add(1);
  return status;
}

void PlannerService::CaptureForDebug(CallState& call, const PlanningJob& job) const {
  if (debug_calls_ == nullptr) return;
  DebugCapture capture;
  capture.cell = job.cell;
  capture.tool = job.params.planning.tool;
  capture.frame.cloud = viewer::ThinToBin(PackedXyz{job.xyz_Sensor}, job.unit, job.cell.sensor.X_BinSensor,
                                          debug_calls_->max_points());
  call.debug = std::move(capture);
}

grpc::Status PlannerService::RunOnWorker(CallState& call, Clock::time_point enqueued,
                                         const std::function<void()>& body) {
  const Clock::time_point started = Clock::now();
  call.record.queue_ms = Ms(started - enqueued);
  if (call.token.should_stop()) {
    metrics_->RecordExpiredInQueue();
    return call.CancelledStatus("stopped while queued for a planning worker; not run");
  }
  call.ran = true;
  grpc::Status status;
  try {
    body();
  } catch (const Cancelled& e) {
    status = call.CancelledStatus(e.what());
  } catch (const InvalidArgument& e) {
    status = CallerMistake(e);
  } catch (const FailedPrecondition& e) {
    status = grpc::Status(grpc::StatusCode::FAILED_PRECONDITION, e.what());
  } catch (const std::exception& e) {
    spdlog::error("{} {}: internal error: {}", call.record.rpc, call.record.request_id, e.what());
    status = grpc::Status(grpc::StatusCode::INTERNAL,
                          fmt::format("internal error (request id {})", call.record.request_id));
  } catch (...) {
    spdlog::error("{} {}: internal error: unknown exception", call.record.rpc, call.record.request_id);
    status = grpc::Status(grpc::StatusCode::INTERNAL,
                          fmt::format("internal error (request id {})", call.record.request_id));
  }
  call.record.run_ms = Ms(Clock::now() - started);
  return status;
}

grpc::ServerUnaryReactor* PlannerService::StartPlanning(grpc::CallbackServerContext* context, const char* rpc,
                                                        std::uint64_t points,
                                                        std::function<void(CallState&)> body) {
  auto* call = new UnaryCall(this, context, rpc);
  call->state().record.points = points;
  const Clock::time_point enqueued = Clock::now();
  const WorkerPool::Admission admission = pool_->TrySubmit([this, call, enqueued, body = std::move(body)] {
    CallState& state = call->state();
    call->Answer(RunOnWorker(state, enqueued, [&] { body(state); }));
  });
  // On admission the worker may already have answered; the reactor lives until gRPC has bound it.
  if (admission == WorkerPool::Admission::kFull) {
    call->Answer(Rejected(call->state()));
  } else if (admission == WorkerPool::Admission::kStopped) {
    call->Answer(grpc::Status(grpc::StatusCode::UNAVAILABLE, "the server is shutting down"));
  }
  return call;
}

grpc::ServerUnaryReactor* PlannerService::ModelTubes(grpc::CallbackServerContext* context,
                                                     const v1::ModelTubesRequest* request,
                                                     v1::ModelTubesResponse* response) {
  return StartPlanning(context, "ModelTubes", request->cloud().xyz().size() / 12,
                       [this, request, response](CallState& call) {
                         const PlanningJob job = ValidateModelTubes(*request, config_.planning);
                         CaptureForDebug(call, job);
                         *response = RunModelTubes(job, threads_per_call_, &call.token);
                         if (call.debug) call.debug->frame.modeling = *response;
                         call.record.tubes = static_cast<std::uint32_t>(response->tubes_size());
                         call.record.warnings = WarningCodes(*response);
                       });
}

grpc::ServerUnaryReactor* PlannerService::PlanPick(grpc::CallbackServerContext* context,
                                                   const v1::PlanPickRequest* request,
                                                   v1::PlanPickResponse* response) {
  return StartPlanning(context, "PlanPick", request->cloud().xyz().size() / 12,
                       [this, request, response](CallState& call) {
                         const PlanningJob job = ValidatePlanPick(*request, config_.planning);
                         CaptureForDebug(call, job);
                         *response = RunPlanPick(job, config_.planning, threads_per_call_, &call.token);
                         if (call.debug) call.debug->frame.plan = *response;
                         call.record.tubes = static_cast<std::uint32_t>(response->tubes_size());
                         call.record.plans = static_cast<std::uint32_t>(response->plans_size());
                         call.record.warnings = WarningCodes(response->modeling());
                       });
}

grpc::ServerReadReactor<v1::PlanPickStreamRequest>* PlannerService::PlanPickStream(
    grpc::CallbackServerContext* context, v1::PlanPickStreamResponse* response) {
  return new StreamCall(this, context, response);
}

grpc::ServerUnaryReactor* PlannerService::AnalyzeWrench(grpc::CallbackServerContext* context,
                                                        const v1::AnalyzeWrenchRequest* request,
                                                        v1::AnalyzeWrenchResponse* response) {
  // Microseconds of arithmetic: answered inline, never queued behind plans.
  auto* call = new UnaryCall(this, context, "AnalyzeWrench");
  call->state().ran = true;
  const Clock::time_point started = Clock::now();
  grpc::Status status;
  try {
    const WrenchJob job = ValidateAnalyzeWrench(*request, config_.planning);
    *response = RunAnalyzeWrench(job);
  } catch (const InvalidArgument& e) {
    status = CallerMistake(e);
  } catch (const std::exception& e) {
    spdlog::error("AnalyzeWrench {}: internal error: {}", call->state().record.request_id, e.what());
    status = grpc::Status(grpc::StatusCode::INTERNAL,
                          fmt::format("internal error (request id {})", call->state().record.request_id));
  }
  call->state().record.run_ms = Ms(Clock::now() - started);
  call->Answer(std::move(status));
  return call;
}

}  // namespace tubepick::server
