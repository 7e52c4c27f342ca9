#pragma once

// The reactors behind every geodex.v1 method. The service registers each method raw (request and
// response as bytes, geodex_service.cc): a reactor first checks the bearer token, then parses the
// request itself, so that
//   - no byte of an unauthenticated request is ever parsed, and
//   - a request that does not parse gets INVALID_ARGUMENT saying so (gRPC's typed callback API
//     answers UNIMPLEMENTED with an empty message, telling the client the method does not exist).
// Work never runs on gRPC's threads except plain map look-ups (Lane::kInline). Calls that may be
// served without a solve (cached fields, traces from them, locate) run first on the quick pool, so
// that they never wait behind full solves; one that turns out to need a solve moves to the compute
// pool. A full queue answers RESOURCE_EXHAUSTED at once; client cancellation and deadlines cancel
// the engine's CancelToken; every reactor finishes.

#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "auth.h"
#include "compute_pool.h"
#include "geodex/cancel.h"
#include "grpcpp/support/byte_buffer.h"
#include "grpcpp/support/proto_buffer_reader.h"
#include "grpcpp/support/server_callback.h"
#include "queries.h"
#include "status_convert.h"

namespace geodex::server {

inline absl::Status PoolFullError(const ComputePool& pool, const char* flags) {
  return QueueFullError(absl::StrCat("compute queue full (", pool.threads(), " workers busy, ",
                                     pool.queue_capacity(), " queued; ", flags, "); retry later"));
}

inline grpc::Status PoolFullStatus(const ComputePool& pool, const char* flags) {
  return ToGrpcStatus(PoolFullError(pool, flags));
}

inline grpc::Status CancelledStatus() {
  return grpc::Status(grpc::StatusCode::CANCELLED, "call cancelled or deadline exceeded");
}

// Parses one request message from its wire bytes; InvalidArgument naming the message type when
// the bytes are not a valid encoding (bad wire format, invalid UTF-8 in a string, nesting deeper
// than protobuf's recursion limit).
template <typename Message>
absl::Status ParseRequest(const grpc::ByteBuffer& bytes, Message* message, const char* what) {
  grpc::ByteBuffer copy(bytes);  // shares the slices; the reader needs a mutable buffer
  grpc::ProtoBufferReader reader(&copy);
  if (!reader.status().ok() || !message->ParseFromZeroCopyStream(&reader)) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": the request could not be parsed as ",
                     Message::descriptor()->full_name(), " (", bytes.Length(),
                     " bytes: invalid wire format, invalid UTF-8 in a string field, or nesting "
                     "too deep)"));
  }
  return absl::OkStatus();
}

template <typename Message>
void SerializeResponse(const Message& message, grpc::ByteBuffer* out) {
  bool own = false;
  grpc::SerializationTraits<Message>::Serialize(message, out, &own);
}

// What the reactors need from the service.
struct ReactorEnv {
  MeshStore* store;
  const ServiceLimits* limits;
  ComputePool* pool;        // solves
  ComputePool* quick_pool;  // calls that need no solve (see Lane); null = none (all on `pool`)
  FieldCache* cache;
  ServiceCounters* counters;
  const TokenAuthenticator* auth;
  CallDescriptions* descriptions;     // may be null
  FieldPromoter* promoter = nullptr;  // background fields of hot path sources; may be null
};

// Where a method's work runs.
enum class Lane {
  kInline,  // on gRPC's thread: only map look-ups (GetMesh, ListMeshes, DeleteMesh)
  kQuick,   // the quick pool first; moves to the compute pool if it needs a solve
  kSolve,   // the compute pool
};

// The token, then the parse: OK, or the status to finish the call with. On OK the call is
// described for its log line.
template <typename Request>
grpc::Status AdmitCall(const ReactorEnv& env, grpc::CallbackServerContext* context,
                       const grpc::ByteBuffer& bytes, Request* request) {
  if (!env.auth->Allows(*context)) return UnauthenticatedStatus();
  if (absl::Status parsed = ParseRequest(bytes, request, "request"); !parsed.ok()) {
    return ToGrpcStatus(parsed);
  }
  if (env.descriptions != nullptr) env.descriptions->Describe(context, *request);
  return grpc::Status::OK;
}

inline QueryEnv MakeQueryEnv(const ReactorEnv& env, const CancelToken* cancel, bool quick) {
  QueryEnv q{env.store, env.limits, cancel, env.cache, env.counters, env.pool};
  q.promoter = env.promoter;
  q.quick = quick;
  return q;
}

template <typename Request, typename Response>
class UnaryQueryReactor final : public grpc::ServerUnaryReactor {
 public:
  using Run = absl::Status (*)(const QueryEnv&, const Request&, Response*);

  // Starts the reactor: the caller returns it to gRPC.
  static grpc::ServerUnaryReactor* Start(const ReactorEnv& env, Run run, Lane lane,
                                         grpc::CallbackServerContext* context,
                                         const grpc::ByteBuffer* request, grpc::ByteBuffer* out) {
    auto* reactor = new UnaryQueryReactor(env, run, out);
    if (grpc::Status admitted = AdmitCall(env, context, *request, &reactor->request_);
        !admitted.ok()) {
      reactor->Finish(admitted);
      return reactor;
    }
    switch (lane) {
      case Lane::kInline:
        reactor->Compute(/*quick=*/false);
        break;
      case Lane::kQuick:
        if (env.quick_pool != nullptr) {
          reactor->Submit(env.quick_pool, /*quick=*/true);
          break;
        }
        [[fallthrough]];  // no quick lane (--quick_threads=0): everything on the compute pool
      case Lane::kSolve:
        reactor->Submit(env.pool, /*quick=*/false);
        break;
    }
    return reactor;
  }

  void OnCancel() override { cancel_.Cancel(); }
  void OnDone() override { delete this; }

 private:
  UnaryQueryReactor(const ReactorEnv& env, Run run, grpc::ByteBuffer* out)
      : env_(env), run_(run), out_(out) {}

  void Submit(ComputePool* pool, bool quick) {
    if (!pool->TrySubmit([this, pool, quick] { Compute(quick, pool); })) {
      Finish(PoolFullStatus(
          *pool, quick ? "--quick_threads/--queue_capacity" : "--pool_threads/--queue_capacity"));
    }
  }

  void Compute(bool quick, ComputePool* pool = nullptr) {
    if (cancel_.IsCancelled()) {
      if (pool != nullptr) pool->ReleaseWorker();
      Finish(CancelledStatus());
      return;
    }
    absl::Status status = run_(MakeQueryEnv(env_, &cancel_, quick), request_, &response_);
    if (quick && IsSolveLaneNeeded(status)) {
      response_.Clear();
      pool->ReleaseWorker();
      Submit(env_.pool, /*quick=*/false);
      return;
    }
    if (status.ok()) {
      SerializeResponse(response_, out_);
    }
    response_.Clear();
    if (pool != nullptr) pool->ReleaseWorker();  // before Finish: the next call may come at once
    Finish(ToGrpcStatus(status));
  }

  ReactorEnv env_;
  Run run_;
  Request request_;
  Response response_;
  grpc::ByteBuffer* out_;
  CancelToken cancel_;
};

template <typename Request, typename Response>
class StreamQueryReactor final : public grpc::ServerWriteReactor<grpc::ByteBuffer> {
 public:
  using Run = absl::StatusOr<MessageStream<Response>> (*)(const QueryEnv&, const Request&);

  static grpc::ServerWriteReactor<grpc::ByteBuffer>* Start(const ReactorEnv& env, Run run,
                                                           Lane lane,
                                                           grpc::CallbackServerContext* context,
                                                           const grpc::ByteBuffer* request) {
    auto* reactor = new StreamQueryReactor(env, run);
    if (grpc::Status admitted = AdmitCall(env, context, *request, &reactor->request_);
        !admitted.ok()) {
      reactor->Finish(admitted);
      return reactor;
    }
    if (lane == Lane::kQuick && env.quick_pool != nullptr) {
      reactor->Submit(env.quick_pool, /*quick=*/true);
    } else {
      reactor->Submit(env.pool, /*quick=*/false);
    }
    return reactor;
  }

  // Each write starts only after the previous one completed (one outstanding write at a time).
  void OnWriteDone(bool ok) override {
    std::unique_lock<std::mutex> lock(mu_);
    writing_ = false;
    if (!ok) {  // the client is gone: stop the work; finish once it has returned
      cancel_.Cancel();
      client_gone_ = true;
    }
    Act(Decide(), &lock);
  }
  void OnCancel() override { cancel_.Cancel(); }
  void OnDone() override { delete this; }

 private:
  // What to do next once mu_ is released: Finish and StartWrite are called outside it, and after
  // either this thread touches nothing more (gRPC may delete the reactor from another thread).
  enum class Action { kNone, kWrite, kFinish };

  StreamQueryReactor(const ReactorEnv& env, Run run) : env_(env), run_(run) {}

  void Submit(ComputePool* pool, bool quick) {
    if (!pool->TrySubmit([this, pool, quick] { Compute(pool, quick); })) {
      this->Finish(PoolFullStatus(
          *pool, quick ? "--quick_threads/--queue_capacity" : "--pool_threads/--queue_capacity"));
    }
  }

  void Compute(ComputePool* pool, bool quick) {
    if (cancel_.IsCancelled()) {
      pool->ReleaseWorker();
      this->Finish(CancelledStatus());
      return;
    }
    absl::StatusOr<MessageStream<Response>> stream =
        run_(MakeQueryEnv(env_, &cancel_, quick), request_);
    if (quick && IsSolveLaneNeeded(stream.status())) {
      pool->ReleaseWorker();
      Submit(env_.pool, /*quick=*/false);
      return;
    }
    if (!stream.ok()) {
      pool->ReleaseWorker();  // before any Finish or write: see ComputePool::ReleaseWorker
      this->Finish(ToGrpcStatus(stream.status()));
      return;
    }
    stream_ = *std::move(stream);
    absl::Status work_status = absl::OkStatus();
    if (stream_.work) {
      // Messages go out while the work runs; the reactor cannot finish before it returns (work
      // still uses cancel_), so it stays alive for every ready() call.
      Pump();
      work_status = stream_.work([this] { Pump(); });
    }
    pool->ReleaseWorker();
    std::unique_lock<std::mutex> lock(mu_);
    work_done_ = true;
    work_status_ = work_status;
    Act(Decide(), &lock);
  }

  void Pump() {
    std::unique_lock<std::mutex> lock(mu_);
    Act(Decide(), &lock);
  }

  // With mu_ held: the next step, given what is written, produced and finished.
  Action Decide() {
    if (writing_ || finishing_) return Action::kNone;
    if (!cancel_.IsCancelled() && work_status_.ok()) {
      response_.Clear();
      const Produced produced = stream_.next(&response_);
      if (produced == Produced::kMessage) {
        buffer_.Clear();
        SerializeResponse(response_, &buffer_);
        writing_ = true;
        return Action::kWrite;
      }
      if (produced == Produced::kLater && !work_done_) return Action::kNone;
    }
    if (!work_done_) return Action::kNone;  // cancelled: wait for the work to stop
    finishing_ = true;
    if (cancel_.IsCancelled() || client_gone_) {
      final_status_ = CancelledStatus();
    } else if (!work_status_.ok()) {
      final_status_ = ToGrpcStatus(work_status_);
    }
    return Action::kFinish;
  }

  void Act(Action action, std::unique_lock<std::mutex>* lock) {
    lock->unlock();
    if (action == Action::kWrite) this->StartWrite(&buffer_);
    if (action == Action::kFinish) this->Finish(final_status_);
  }

  ReactorEnv env_;
  Run run_;
  Request request_;
  CancelToken cancel_;
  MessageStream<Response> stream_;  // set by Compute before any write, then used under mu_
  std::mutex mu_;         // orders the writer's state between the compute thread and gRPC's threads
  bool writing_ = false;  // a StartWrite is outstanding
  bool finishing_ = false;  // Finish was decided; nothing more happens
  bool work_done_ = false;  // the query (and its work, if any) returned
  bool client_gone_ = false;
  absl::Status work_status_ = absl::OkStatus();
  grpc::Status final_status_ = grpc::Status::OK;
  Response response_;
  grpc::ByteBuffer buffer_;
};

}  // namespace geodex::server
