#include "geodex_server.h"

#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "grpcpp/ext/proto_server_reflection_plugin.h"
#include "grpcpp/health_check_service_interface.h"
#include "grpcpp/security/server_credentials.h"
#include "grpcpp/server_builder.h"

namespace geodex::server {

absl::StatusOr<std::unique_ptr<GeodexServer>> GeodexServer::Start(const ServerOptions& options) {
  std::unique_ptr<GeodexServer> s(new GeodexServer());
  size_t threads = options.pool_threads;
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  s->store_ = std::make_unique<MeshStore>(options.mesh_budget_bytes);
  s->pool_ = std::make_unique<ComputePool>(threads, options.queue_capacity);
  s->service_ = std::make_unique<GeodexService>(s->store_.get(), s->pool_.get(), options.limits);

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  builder.SetMaxReceiveMessageSize(options.max_receive_message_bytes);
  builder.AddListeningPort(options.listen, grpc::InsecureServerCredentials(), &s->port_);
  builder.RegisterService(s->service_.get());
  s->server_ = builder.BuildAndStart();
  if (s->server_ == nullptr || s->port_ == 0) {
    return absl::UnavailableError(absl::StrCat("cannot listen on ", options.listen));
  }
  grpc::HealthCheckServiceInterface* health = s->server_->GetHealthCheckService();
  health->SetServingStatus("", true);
  health->SetServingStatus(v1::Geodex::service_full_name(), true);
  return s;
}

void GeodexServer::Shutdown(absl::Time deadline) {
  if (shut_down_) return;
  shut_down_ = true;
  if (auto* health = server_->GetHealthCheckService()) health->Shutdown();
  server_->Shutdown(absl::ToChronoTime(deadline));
}

void GeodexServer::Wait() { server_->Wait(); }

GeodexServer::~GeodexServer() {
  if (server_ != nullptr) Shutdown(absl::Now());
}

}  // namespace geodex::server
