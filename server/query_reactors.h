#pragma once

// Two reactor shapes serve every query method: a unary one and a server-streaming one. Both hand
// the work to the ComputePool (never computing on gRPC's threads), answer RESOURCE_EXHAUSTED at
// once when the pool's queue is full, cancel the engine's CancelToken on client cancellation or
// deadline, and always Finish (a reactor that never finishes would hang the server's shutdown).

#include <functional>
#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "compute_pool.h"
#include "geodex/cancel.h"
#include "grpcpp/support/server_callback.h"
#include "queries.h"
#include "status_convert.h"

namespace geodex::server {

inline grpc::Status PoolFullStatus(const ComputePool& pool) {
  return ToGrpcStatus(absl::ResourceExhaustedError(
      absl::StrCat("compute queue full (", pool.threads(), " workers busy, ", pool.queue_capacity(),
                   " queued; --pool_threads/--queue_capacity); retry later")));
}

inline grpc::Status CancelledStatus() {
  return grpc::Status(grpc::StatusCode::CANCELLED, "call cancelled or deadline exceeded");
}

// What the reactors need from the service.
struct ReactorEnv {
  MeshStore* store;
  const ServiceLimits* limits;
  ComputePool* pool;
  FieldCache* cache;
  ServiceCounters* counters;
};

template <typename Request, typename Response>
class UnaryQueryReactor final : public grpc::ServerUnaryReactor {
 public:
  using Run = absl::Status (*)(const QueryEnv&, const Request&, Response*);

  // Starts the reactor: the caller returns it to gRPC.
  static grpc::ServerUnaryReactor* Start(const ReactorEnv& env, Run run, const Request* request,
                                         Response* response) {
    auto* reactor = new UnaryQueryReactor(env, run, request, response);
    if (!env.pool->TrySubmit([reactor] { reactor->Compute(); })) {
      reactor->Finish(PoolFullStatus(*env.pool));
    }
    return reactor;
  }

  void OnCancel() override { cancel_.Cancel(); }
  void OnDone() override { delete this; }

 private:
  UnaryQueryReactor(const ReactorEnv& env, Run run, const Request* request, Response* response)
      : env_(env), run_(run), request_(request), response_(response) {}

  void Compute() {
    if (cancel_.IsCancelled()) {
      env_.pool->ReleaseWorker();
      Finish(CancelledStatus());
      return;
    }
    absl::Status status = run_(QueryEnv{env_.store, env_.limits, &cancel_, env_.cache, env_.counters, env_.pool}, *request_, response_);
    if (!status.ok()) response_->Clear();
    env_.pool->ReleaseWorker();  // before Finish: the client may send its next call at once
    Finish(ToGrpcStatus(status));
  }

  ReactorEnv env_;
  Run run_;
  const Request* request_;
  Response* response_;
  CancelToken cancel_;
};

template <typename Request, typename Response>
class StreamQueryReactor final : public grpc::ServerWriteReactor<Response> {
 public:
  using Run = absl::StatusOr<MessageProducer<Response>> (*)(const QueryEnv&, const Request&);

  static grpc::ServerWriteReactor<Response>* Start(const ReactorEnv& env, Run run,
                                                   const Request* request) {
    auto* reactor = new StreamQueryReactor(env, run, request);
    if (!env.pool->TrySubmit([reactor] { reactor->Compute(); })) {
      reactor->Finish(PoolFullStatus(*env.pool));
    }
    return reactor;
  }

  // Each write starts only after the previous one completed (one outstanding write at a time).
  void OnWriteDone(bool ok) override {
    if (!ok) {
      this->Finish(CancelledStatus());
      return;
    }
    WriteNext();
  }
  void OnCancel() override { cancel_.Cancel(); }
  void OnDone() override { delete this; }

 private:
  StreamQueryReactor(const ReactorEnv& env, Run run, const Request* request)
      : env_(env), run_(run), request_(request) {}

  void Compute() {
    if (cancel_.IsCancelled()) {
      env_.pool->ReleaseWorker();
      this->Finish(CancelledStatus());
      return;
    }
    absl::StatusOr<MessageProducer<Response>> producer =
        run_(QueryEnv{env_.store, env_.limits, &cancel_, env_.cache, env_.counters, env_.pool}, *request_);
    env_.pool->ReleaseWorker();  // before any Finish or write: see ComputePool::ReleaseWorker
    if (!producer.ok()) {
      this->Finish(ToGrpcStatus(producer.status()));
      return;
    }
    producer_ = *std::move(producer);
    WriteNext();
  }

  void WriteNext() {
    response_.Clear();
    if (cancel_.IsCancelled() || !producer_(&response_)) {
      this->Finish(cancel_.IsCancelled() ? CancelledStatus() : grpc::Status::OK);
      return;
    }
    this->StartWrite(&response_);
  }

  ReactorEnv env_;
  Run run_;
  const Request* request_;
  CancelToken cancel_;
  MessageProducer<Response> producer_;
  Response response_;
};

}  // namespace geodex::server
