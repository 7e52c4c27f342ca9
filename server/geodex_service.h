#pragma once

// geodex.v1.Geodex on gRPC's callback API, every method registered raw (bytes in, bytes out) from
// one table (geodex_service.cc, GeodexService::Methods): the reactors of query_reactors.h check
// the token, parse the request and run the method's function (queries.h) in its lane.

#include <cstdint>
#include <string>
#include <vector>

#include "auth.h"
#include "compute_pool.h"
#include "field_cache.h"
#include "geodex/v1/geodex.grpc.pb.h"
#include "mesh_store.h"
#include "query_reactors.h"
#include "service_limits.h"

namespace geodex::server {

class GeodexService final : public v1::Geodex::CallbackService {
 public:
  // `store`, `pool` and `quick_pool` must outlive the service and the grpc::Server's Shutdown
  // (their tasks finish the calls); so must `cache` and `descriptions` (may be null).
  GeodexService(MeshStore* store, ComputePool* pool, ComputePool* quick_pool, FieldCache* cache,
                const ServiceLimits& limits, TokenAuthenticator auth = TokenAuthenticator({}),
                CallDescriptions* descriptions = nullptr);

  // Every method of geodex.v1.Geodex with its lane ("CreateMesh" reads a stream and builds on the
  // compute pool). Tests and tools read this list rather than keeping their own.
  struct MethodInfo {
    std::string name;  // "FindShortestPath"
    Lane lane;
    // The method's query function (queries.h) on a serialized request, in this thread, without
    // gRPC: parses, runs, drains a stream, drops the answer and returns its status
    // (InvalidArgument for bytes that do not parse). What the request fuzzer drives. Null for
    // CreateMesh, a client stream (its readers have fuzzers of their own).
    absl::Status (*run_serialized)(const QueryEnv& env, absl::string_view request) = nullptr;
  };
  static const std::vector<MethodInfo>& Methods();

  MeshStore* store() const { return store_; }
  ComputePool* pool() const { return pool_; }
  const ServiceLimits& limits() const { return limits_; }
  const ServiceCounters& counters() const { return counters_; }
  ServiceCounters& mutable_counters() { return counters_; }
  const ReactorEnv& env() const { return env_; }
  // Where paths offer their hot sources for a background field (before calls arrive; it must
  // outlive the calls).
  void set_promoter(FieldPromoter* promoter) { env_.promoter = promoter; }

 private:
  MeshStore* store_;
  ComputePool* pool_;
  ServiceLimits limits_;
  TokenAuthenticator auth_;
  ServiceCounters counters_;
  ReactorEnv env_;
};

}  // namespace geodex::server
