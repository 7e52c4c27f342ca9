#include "geodex_server.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "geodex/mesh_id.h"
#include "geodex/mesh_io.h"
#include "geodex/samples.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/ext/proto_server_reflection_plugin.h"
#include "grpcpp/security/credentials.h"
#include "grpcpp/security/server_credentials.h"
#include "grpcpp/server_builder.h"
#include "listen_address.h"

namespace geodex::server {

absl::Status ValidateServerOptions(const ServerOptions& options) {
  auto at_least = [](const char* flag, uint64_t value, uint64_t min, const char* why) {
    return value >= min ? absl::OkStatus()
                        : absl::InvalidArgumentError(absl::StrCat("--", flag, "=", value,
                                                                  ": must be at least ", min, why));
  };
  if (options.pool_threads > kMaxPoolThreads) {
    return absl::InvalidArgumentError(absl::StrCat("--pool_threads=", options.pool_threads,
                                                   ": at most ", kMaxPoolThreads,
                                                   " (0 = one per hardware thread)"));
  }
  if (options.quick_threads > kMaxQuickThreads) {
    return absl::InvalidArgumentError(absl::StrCat("--quick_threads=", options.quick_threads,
                                                   ": at most ", kMaxQuickThreads,
                                                   " (0 = no quick lane)"));
  }
  if (absl::Status s = ValidateListenAddress(options.listen, "listen"); !s.ok()) return s;
  if (!options.metrics_listen.empty()) {
    if (absl::Status s = ValidateListenAddress(options.metrics_listen, "metrics_listen"); !s.ok()) {
      return s;
    }
  }
  if (!options.auth_token_file.empty() && options.tls_cert_file.empty() &&
      !options.allow_plaintext_tokens) {
    return absl::InvalidArgumentError(
        "--auth_token_file without --tls_cert/--tls_key would send bearer tokens in plaintext; "
        "serve TLS, or pass --allow_plaintext_tokens when a TLS-terminating proxy is in front");
  }
  if (!options.http.listen.empty() && !options.tls_cert_file.empty() &&
      !options.allow_plaintext_tokens) {
    return absl::InvalidArgumentError(
        "--http_listen with --tls_cert: the HTTP/JSON port serves plaintext only; put a "
        "TLS-terminating proxy in front of it and pass --allow_plaintext_tokens, or leave "
        "--http_listen off");
  }
  if (options.queue_capacity > kMaxQueueCapacity) {
    return absl::InvalidArgumentError(
        absl::StrCat("--queue_capacity=", options.queue_capacity, ": at most ", kMaxQueueCapacity));
  }
  const ServiceLimits& l = options.limits;
  const uint64_t stream_chunk = l.stream_chunk_bytes;
  for (absl::Status status : {
           at_least("mesh_budget_bytes", options.mesh_budget_bytes, 1, ""),
           at_least("max_receive_message_bytes",
                    options.max_receive_message_bytes < 0
                        ? 0
                        : static_cast<uint64_t>(options.max_receive_message_bytes),
                    uint64_t{1} << 16, " (uploads arrive in chunks of up to 1 MiB by default)"),
           at_least("max_upload_bytes", l.max_upload_bytes, 1, ""),
           at_least("max_vertices", l.max_vertices, 1, ""),
           at_least("max_faces", l.max_faces, 1, ""),
           at_least("max_dem_cells", l.max_dem_cells, 4, " (a DEM has at least 2x2 cells)"),
           at_least("max_sources", l.max_sources, 1, ""),
           at_least("max_names_per_mesh", l.max_names_per_mesh, 1, ""),
           at_least("max_targets", l.max_targets, 1, ""),
           at_least("max_levels", l.max_levels, 1, ""),
           at_least("max_output_values", l.max_output_values, 1, ""),
           at_least("max_unary_response_bytes", l.max_unary_response_bytes, 1, ""),
           at_least("stream_chunk_bytes", stream_chunk, 256, ""),
       }) {
    if (!status.ok()) return status;
  }
  if (absl::Status http = ValidateHttpEdgeOptions(options.http); !http.ok()) return http;
  if (stream_chunk > kMaxStreamChunkBytes) {
    return absl::InvalidArgumentError(
        absl::StrCat("--stream_chunk_bytes=", stream_chunk, ": at most ", kMaxStreamChunkBytes,
                     " (clients keep gRPC's default 4 MiB receive limit)"));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<GeodexServer>> GeodexServer::Start(const ServerOptions& options) {
  if (absl::Status valid = ValidateServerOptions(options); !valid.ok()) return valid;
  std::unique_ptr<GeodexServer> s(new GeodexServer());
  size_t threads = options.pool_threads;
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  s->store_ = std::make_unique<MeshStore>(options.mesh_budget_bytes);
  s->pool_ = std::make_unique<ComputePool>(threads, options.queue_capacity);
  if (options.quick_threads > 0) {
    s->quick_pool_ = std::make_unique<ComputePool>(options.quick_threads, options.queue_capacity);
  }
  s->cache_ = std::make_unique<FieldCache>(options.result_cache_bytes);
  std::vector<std::string> tokens;
  if (!options.auth_token_file.empty()) {
    absl::StatusOr<std::vector<std::string>> read = ReadTokenFile(options.auth_token_file);
    if (!read.ok()) return read.status();
    tokens = *std::move(read);
  }
  s->authenticated_ = !tokens.empty();
  s->service_ = std::make_unique<GeodexService>(
      s->store_.get(), s->pool_.get(), s->quick_pool_.get(), s->cache_.get(), options.limits,
      TokenAuthenticator(std::move(tokens)), &s->descriptions_);
  std::shared_ptr<grpc::ServerCredentials> credentials = grpc::InsecureServerCredentials();
  if (options.tls_cert_file.empty() != options.tls_key_file.empty()) {
    return absl::InvalidArgumentError("--tls_cert and --tls_key go together");
  }
  if (!options.tls_cert_file.empty()) {
    absl::StatusOr<std::string> cert = ReadSmallFile(options.tls_cert_file, "--tls_cert");
    if (!cert.ok()) return cert.status();
    absl::StatusOr<std::string> key = ReadSmallFile(options.tls_key_file, "--tls_key");
    if (!key.ok()) return key.status();
    grpc::SslServerCredentialsOptions ssl;
    ssl.pem_key_cert_pairs.push_back({*key, *cert});
    credentials = grpc::SslServerCredentials(ssl);
    s->tls_ = true;
  }

  // The store is complete before the port opens: health never says SERVING before the index is
  // read (and no call sees a half-read index).
  bool fresh = true;
  if (!options.data_dir.empty()) {
    MeshDisk::Index index;
    absl::StatusOr<MeshDisk> disk = MeshDisk::Open(options.data_dir, &index);
    if (!disk.ok()) return disk.status();
    fresh = index.fresh;
    s->report_.indexed = index.meshes.size();
    s->report_.skipped = index.skipped;
    s->report_.removed_temporaries = index.removed_temporaries;
    s->store_->AttachDisk(*std::move(disk), index);
  }
  if (options.samples && fresh) {
    for (const std::string& name : SampleMeshNames()) {
      absl::StatusOr<MeshData> data = MakeSampleMesh(name);
      if (!data.ok()) return data.status();
      absl::StatusOr<std::string> id = AddMesh(*s->store_, *data, name, 0);
      if (!id.ok()) return id.status();
      s->report_.samples.push_back(absl::StrCat(name, " -> meshes/", *id));
    }
  }
  if (!options.import_dir.empty()) s->ImportDirectory(options.import_dir);

  absl::StatusOr<std::unique_ptr<ServerMetrics>> metrics =
      ServerMetrics::Start(options.metrics_listen,
                           MetricSources{s->pool_.get(), s->store_.get(), s->cache_.get(),
                                         &s->service_->counters(), &s->descriptions_},
                           options.log_requests, options.replica_name);
  if (!metrics.ok()) return metrics.status();
  s->metrics_ = *std::move(metrics);

  if (options.background_solves && s->cache_->enabled()) {
    s->promoter_ = std::make_unique<FieldPromoter>(
        s->cache_.get(), &s->service_->mutable_counters(), options.limits.max_windows);
    s->service_->set_promoter(s->promoter_.get());
  }
  s->pool_->Publish();  // the service (and everything above) before any task runs
  if (s->quick_pool_) s->quick_pool_->Publish();

  grpc::EnableDefaultHealthCheckService(false);  // ours (health_service.h) ends Watch streams
  s->health_ = std::make_unique<HealthService>();
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  builder.SetMaxReceiveMessageSize(options.max_receive_message_bytes);
  builder.AddListeningPort(options.listen, credentials, &s->port_);
  builder.RegisterService(s->service_.get());
  builder.RegisterService(s->health_.get());
  std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> interceptors;
  interceptors.push_back(s->metrics_->InterceptorFactory());
  builder.experimental().SetInterceptorCreators(std::move(interceptors));
  s->server_ = builder.BuildAndStart();
  if (s->server_ == nullptr || s->port_ == 0) {
    if (AddressInUse(options.listen)) {
      return absl::UnavailableError(absl::StrCat(
          "--listen=", options.listen,
          ": address in use (another geodexd?); choose another port, or port 0 for a free one"));
    }
    return absl::UnavailableError(absl::StrCat("--listen=", options.listen, ": cannot listen"));
  }
  if (!options.http.listen.empty()) {
    HttpEdgeOptions http = options.http;
    http.max_body_bytes = static_cast<uint64_t>(options.max_receive_message_bytes);
    http.tokens = s->authenticated_;
    grpc::ChannelArguments arguments;
    arguments.SetMaxReceiveMessageSize(-1);  // answers are bounded by the server's own limits
    absl::StatusOr<std::unique_ptr<HttpEdge>> edge = HttpEdge::Start(
        http, http.grpc_target.empty()
                  ? s->server_->InProcessChannel(arguments)
                  : grpc::CreateCustomChannel(http.grpc_target, grpc::InsecureChannelCredentials(),
                                              arguments));
    if (!edge.ok()) return edge.status();
    s->http_ = *std::move(edge);
  }
  s->health_->SetServing("", true);
  s->health_->SetServing(v1::Geodex::service_full_name(), true);
  return s;
}

absl::StatusOr<std::string> ReadSmallFile(const std::string& path, const std::string& flag) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) {
    return absl::InvalidArgumentError(absl::StrCat(flag, " ", path, ": cannot read"));
  }
  if (bytes.empty())
    return absl::InvalidArgumentError(absl::StrCat(flag, " ", path, ": empty or missing"));
  return bytes;
}

absl::StatusOr<std::string> AddMesh(MeshStore& store, const MeshData& data,
                                    const std::string& alias, uint64_t file_bytes) {
  std::string id = ComputeMeshId(data);
  if (store.Contains(id)) return id;
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  if (!mesh.ok()) return mesh.status();
  std::shared_ptr<StoredMesh> stored = MakeStoredMesh(id, *std::move(mesh));
  stored->display_name = alias;
  stored->upload_bytes = file_bytes;
  const std::string canonical = store.has_disk() ? CanonicalMeshEncoding(data) : std::string();
  absl::StatusOr<std::shared_ptr<const StoredMesh>> inserted =
      store.Insert(std::move(stored), canonical);
  if (!inserted.ok()) return inserted.status();
  return id;
}

void GeodexServer::ImportDirectory(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<fs::path> files;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_regular_file()) files.push_back(it->path());
  }
  if (ec) {
    report_.import_errors.push_back(absl::StrCat(dir, ": ", ec.message()));
    return;
  }
  std::sort(files.begin(), files.end());  // deterministic alias assignment
  for (const fs::path& path : files) {
    absl::StatusOr<MeshData> data = ReadMeshFile(path.string());
    if (!data.ok()) {
      report_.import_errors.push_back(std::string(data.status().message()));
      continue;
    }
    // The alias is the file name up to its first dot, when it is a valid, unused alias.
    std::string alias = path.filename().string();
    alias = alias.substr(0, alias.find('.'));
    bool valid =
        !alias.empty() && alias.size() <= 63 && !IsMeshId(alias) && !store_->GetRecord(alias).ok();
    for (char c : alias) {
      valid = valid && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-');
    }
    absl::StatusOr<std::string> id =
        AddMesh(*store_, *data, valid ? alias : "", fs::file_size(path, ec));
    if (!id.ok()) {
      report_.import_errors.push_back(absl::StrCat(path.string(), ": ", id.status().message()));
    } else {
      report_.imported.push_back(absl::StrCat(path.string(), " -> meshes/", *id));
    }
  }
}

void GeodexServer::Shutdown(absl::Time deadline) {
  if (shut_down_) return;
  shut_down_ = true;
  health_->Shutdown();  // NOT_SERVING; Watch streams end now, not at the deadline
  server_->Shutdown(absl::ToChronoTime(deadline));
  if (http_ != nullptr) http_->Stop();          // its calls are over: the server's are
  if (promoter_ != nullptr) promoter_->Stop();  // a background solve is cancelled, not awaited
}

void GeodexServer::Wait() { server_->Wait(); }

GeodexServer::~GeodexServer() {
  if (server_ != nullptr) Shutdown(absl::Now());
  if (metrics_ != nullptr) metrics_->StopHttp();  // no scrape may read a pool being destroyed
  // Join the compute threads before the gRPC server goes: Shutdown returns once every call is
  // done, but a worker may still be returning from the StartWrite or Finish that ended its call
  // (gRPC's code there reads the server object), and only the join orders that before the
  // server's deletion (ThreadSanitizer reported it). The quick pool first: its tasks may move to
  // the solve pool.
  quick_pool_.reset();
  pool_.reset();
}

}  // namespace geodex::server
