#include "health_service.h"

#include <utility>
#include <vector>

namespace geodex::server {

using grpc::health::v1::HealthCheckRequest;
using grpc::health::v1::HealthCheckResponse;

// One Watch stream: at most one write in flight; a newer status replaces one not yet sent. gRPC is
// never called with a lock held (a reaction may run inline, on the calling thread). The service
// pins a watcher while it pumps it outside the service's lock; the last of OnDone and the unpin
// deletes it.
class HealthService::Watcher final : public grpc::ServerWriteReactor<HealthCheckResponse> {
 public:
  Watcher(HealthService* service, std::string name) : service_(service), name_(std::move(name)) {}

  // The next status to send; `last` ends the stream after it. Pump() sends it.
  void Update(Status status, bool last) {
    std::lock_guard<std::mutex> lock(mu_);
    pending_ = status;
    has_pending_ = true;
    last_ = last_ || last;
  }

  void OnWriteDone(bool ok) override {
    {
      std::lock_guard<std::mutex> lock(mu_);
      writing_ = false;
      if (!ok) broken_ = true;
    }
    Pump();
  }
  void OnCancel() override {
    {
      std::lock_guard<std::mutex> lock(mu_);
      broken_ = true;
    }
    Pump();
  }
  void OnDone() override { service_->Done(this); }

  // Starts the next write, or finishes the stream when nothing is left to send.
  void Pump() {
    enum { kNothing, kWrite, kFinishOk, kFinishCancelled } action = kNothing;
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (writing_ || finished_) return;
      if (broken_) {
        action = kFinishCancelled;
      } else if (has_pending_) {
        response_.set_status(pending_);
        has_pending_ = false;
        writing_ = true;
        action = kWrite;
      } else if (last_) {
        action = kFinishOk;
      }
      if (action == kFinishOk || action == kFinishCancelled) finished_ = true;
    }
    switch (action) {
      case kWrite:
        StartWrite(&response_);
        break;
      case kFinishOk:
        Finish(grpc::Status::OK);
        break;
      case kFinishCancelled:
        Finish(grpc::Status(grpc::StatusCode::CANCELLED, "watch cancelled"));
        break;
      case kNothing:
        break;
    }
  }

  HealthService* service_;
  const std::string name_;
  std::mutex mu_;
  HealthCheckResponse response_;  // the write in flight
  Status pending_ = HealthCheckResponse::UNKNOWN;
  bool has_pending_ = false, writing_ = false, last_ = false, broken_ = false, finished_ = false;
  int pins_ = 0;       // guarded by the service's mu_
  bool done_ = false;  // guarded by the service's mu_

  friend class HealthService;
};

HealthService::Status HealthService::StatusOfLocked(const std::string& service) const {
  auto it = statuses_.find(service);
  return it == statuses_.end() ? HealthCheckResponse::SERVICE_UNKNOWN : it->second;
}

void HealthService::SetServing(const std::string& service, bool serving) {
  std::vector<Watcher*> pinned;
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (shut_down_) return;
    const Status status = serving ? HealthCheckResponse::SERVING : HealthCheckResponse::NOT_SERVING;
    statuses_[service] = status;
    for (Watcher* w : watchers_) {
      if (w->name_ != service) continue;
      w->Update(status, /*last=*/false);
      ++w->pins_;
      pinned.push_back(w);
    }
  }
  PumpAndUnpin(pinned);
}

void HealthService::Shutdown() {
  std::vector<Watcher*> pinned;
  {
    std::lock_guard<std::mutex> lock(mu_);
    shut_down_ = true;
    for (auto& [name, status] : statuses_) status = HealthCheckResponse::NOT_SERVING;
    for (Watcher* w : watchers_) {
      w->Update(HealthCheckResponse::NOT_SERVING, /*last=*/true);
      ++w->pins_;
      pinned.push_back(w);
    }
  }
  PumpAndUnpin(pinned);
}

void HealthService::PumpAndUnpin(const std::vector<Watcher*>& pinned) {
  for (Watcher* w : pinned) w->Pump();
  std::lock_guard<std::mutex> lock(mu_);
  for (Watcher* w : pinned) {
    if (--w->pins_ == 0 && w->done_) delete w;
  }
}

void HealthService::Done(Watcher* watcher) {
  std::lock_guard<std::mutex> lock(mu_);
  watchers_.erase(watcher);
  watcher->done_ = true;
  if (watcher->pins_ == 0) delete watcher;
}

grpc::ServerUnaryReactor* HealthService::Check(grpc::CallbackServerContext* context,
                                               const HealthCheckRequest* request,
                                               HealthCheckResponse* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  Status status;
  {
    std::lock_guard<std::mutex> lock(mu_);
    status = StatusOfLocked(request->service());
  }
  if (status == HealthCheckResponse::SERVICE_UNKNOWN) {
    reactor->Finish(grpc::Status(grpc::StatusCode::NOT_FOUND, "unknown service"));
  } else {
    response->set_status(status);
    reactor->Finish(grpc::Status::OK);
  }
  return reactor;
}

grpc::ServerWriteReactor<HealthCheckResponse>* HealthService::Watch(
    grpc::CallbackServerContext* /*context*/, const HealthCheckRequest* request) {
  auto* watcher = new Watcher(this, request->service());
  {
    std::lock_guard<std::mutex> lock(mu_);
    watchers_.insert(watcher);
    watcher->Update(StatusOfLocked(request->service()), /*last=*/shut_down_);
    ++watcher->pins_;
  }
  PumpAndUnpin({watcher});
  return watcher;
}

}  // namespace geodex::server
