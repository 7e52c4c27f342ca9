#pragma once

// grpc.health.v1.Health, served by geodexd itself rather than by gRPC's default service, whose
// Watch streams stay open at shutdown and hold SIGTERM for the whole grace period. Here Shutdown()
// sends NOT_SERVING to every watcher and ends its stream at once.

#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "grpc/health/v1/health.grpc.pb.h"

namespace geodex::server {

class HealthService final : public grpc::health::v1::Health::CallbackService {
 public:
  using Status = grpc::health::v1::HealthCheckResponse::ServingStatus;

  // Sets a service's status ("" is the server as a whole) and tells its watchers.
  void SetServing(const std::string& service, bool serving);
  // NOT_SERVING everywhere, for good; every Watch stream gets it and ends.
  void Shutdown();

  grpc::ServerUnaryReactor* Check(grpc::CallbackServerContext* context,
                                  const grpc::health::v1::HealthCheckRequest* request,
                                  grpc::health::v1::HealthCheckResponse* response) override;
  grpc::ServerWriteReactor<grpc::health::v1::HealthCheckResponse>* Watch(
      grpc::CallbackServerContext* context,
      const grpc::health::v1::HealthCheckRequest* request) override;

 private:
  class Watcher;
  Status StatusOfLocked(const std::string& service) const;
  void PumpAndUnpin(const std::vector<Watcher*>& pinned);
  void Done(Watcher* watcher);  // its OnDone

  std::mutex mu_;
  std::map<std::string, Status> statuses_;  // guarded by mu_
  std::set<Watcher*> watchers_;             // guarded by mu_
  bool shut_down_ = false;                  // guarded by mu_
};

}  // namespace geodex::server
