#include "queries.h"

#include "geometry_convert.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/cord.h"
#include "absl/strings/str_cat.h"
#include "geodex/delaunay.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/isolines.h"
#include "geodex/point_distance.h"
#include "geodex/shortest_path.h"
#include "geodex/voronoi.h"
#include "field_cache.h"
#include "mesh_id.h"
#include "proto_convert.h"
#include "service_limits.h"
#include "status_convert.h"

namespace geodex::server {
namespace {

using PointList = google::protobuf::RepeatedPtrField<v1::SurfacePoint>;

// Resolves a list of request points (sources or targets) after checking its size against a limit.
absl::StatusOr<std::vector<SurfacePoint>> ResolvePoints(const StoredMesh& mesh,
                                                        const PointList& points,
                                                        const std::string& field, uint64_t limit,
                                                        const char* flag) {
  if (points.empty()) {
    return FieldError(field, "at least one point is required");
  }
  if (static_cast<uint64_t>(points.size()) > limit) {
    return ServerLimitError(
        flag, absl::StrCat(field, ": ", points.size(), " points, over --", flag, "=", limit));
  }
  std::vector<SurfacePoint> out;
  out.reserve(points.size());
  for (int i = 0; i < points.size(); ++i) {
    absl::StatusOr<SurfacePoint> p =
        ResolvePoint(mesh, points[i], absl::StrCat(field, "[", i, "]"));
    if (!p.ok()) return p.status();
    out.push_back(*p);
  }
  return out;
}

absl::StatusOr<std::vector<SurfacePoint>> ResolveSources(const QueryEnv& env,
                                                         const StoredMesh& mesh,
                                                         const PointList& sources) {
  return ResolvePoints(mesh, sources, "sources", env.limits->max_sources, "max_sources");
}

absl::StatusOr<GeodesicOptions> Options(const QueryEnv& env, const v1::SolverOptions& options) {
  absl::StatusOr<GeodesicOptions> out =
      SolverOptionsFromProto(options, env.limits->max_windows, "options");
  if (out.ok()) out->cancel = env.cancel;
  return out;
}

// Core's InvalidArgument from a solve concerns the points (e.g. two sources on one vertex of
// different components is fine, but a point on a degenerate face is not): name the field.
absl::Status NameSolveError(const absl::Status& status, const char* field) {
  if (status.code() == absl::StatusCode::kInvalidArgument) {
    return FieldError(field, status.message());
  }
  return status;
}

absl::Status CheckFieldSize(const QueryEnv& env, const StoredMesh& mesh) {
  if (mesh.vertex_count > env.limits->max_output_values) {
    return ServerLimitError("max_output_values", absl::StrCat("the field has ", mesh.vertex_count,
                     " values, over --max_output_values=", env.limits->max_output_values));
  }
  return absl::OkStatus();
}

absl::Status CheckUnaryResponseSize(const QueryEnv& env, const google::protobuf::Message& response,
                                    const char* what) {
  const size_t bytes = response.ByteSizeLong();
  if (bytes > env.limits->max_unary_response_bytes) {
    return ServerLimitError("max_unary_response_bytes", absl::StrCat("the response would be ", bytes, " bytes, over --max_unary_response_bytes=",
                     env.limits->max_unary_response_bytes, "; send fewer ", what, " per call"));
  }
  return absl::OkStatus();
}

// A distance field from the result cache, or solved (and then cached). `cached` tells which.
absl::StatusOr<std::shared_ptr<const DistanceField>> CachedField(
    const QueryEnv& env, const StoredMesh& mesh, const std::vector<SurfacePoint>& sources,
    const GeodesicOptions& options, bool* cached) {
  const std::string key = FieldCacheKey(mesh.id, sources, options);
  if (std::shared_ptr<const DistanceField> hit = env.cache->Find(key)) {
    *cached = true;
    return hit;
  }
  *cached = false;
  if (env.quick) return SolveLaneNeeded();
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh.mesh, sources, options);
  if (!field.ok()) return NameSolveError(field.status(), "sources");
  env.counters->solves.fetch_add(1, std::memory_order_relaxed);
  env.counters->windows_processed.fetch_add(field->stats.windows_processed,
                                            std::memory_order_relaxed);
  auto shared = std::make_shared<const DistanceField>(*std::move(field));
  env.cache->Insert(key, shared);
  return shared;
}

void FieldStatsToProto(const DistanceField& field, bool cached, v1::SolveStats* out) {
  StatsToProto(field.stats, out);
  out->set_cached(cached);
}

// The field behind distance fields, isolines, Voronoi and Delaunay.
struct SolvedField {
  std::shared_ptr<const StoredMesh> mesh;  // keeps the mesh alive while the result is built
  std::vector<SurfacePoint> sources;
  std::shared_ptr<const DistanceField> field;
  bool cached = false;
};

absl::StatusOr<SolvedField> SolveField(const QueryEnv& env, const std::string& mesh_name,
                                       const PointList& sources,
                                       const v1::SolverOptions& options) {
  SolvedField out;
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh =
      LookupMesh(env, mesh_name, "mesh");
  if (!mesh.ok()) return mesh.status();
  out.mesh = *std::move(mesh);
  if (absl::Status s = CheckFieldSize(env, *out.mesh); !s.ok()) return s;
  absl::StatusOr<std::vector<SurfacePoint>> resolved = ResolveSources(env, *out.mesh, sources);
  if (!resolved.ok()) return resolved.status();
  out.sources = *std::move(resolved);
  absl::StatusOr<GeodesicOptions> solver = Options(env, options);
  if (!solver.ok()) return solver.status();
  absl::StatusOr<std::shared_ptr<const DistanceField>> field =
      CachedField(env, *out.mesh, out.sources, *solver, &out.cached);
  if (!field.ok()) return field.status();
  out.field = *std::move(field);
  return out;
}

}  // namespace

absl::Status SolveLaneNeeded() {
  absl::Status status = absl::UnavailableError("internal: needs the compute pool");
  status.SetPayload("geodex/lane", absl::Cord("solve"));
  return status;
}

bool IsSolveLaneNeeded(const absl::Status& status) {
  return status.GetPayload("geodex/lane").has_value();
}

absl::StatusOr<std::shared_ptr<const StoredMesh>> LookupMesh(const QueryEnv& env,
                                                             const std::string& name,
                                                             const std::string& field) {
  absl::StatusOr<std::string> key = ParseMeshName(name, field);
  if (!key.ok()) return key.status();
  if (env.quick) {
    absl::StatusOr<std::shared_ptr<const StoredMesh>> record = env.store->GetRecord(*key);
    if (record.ok() && (*record)->mesh == nullptr) return SolveLaneNeeded();  // on disk only
  }
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh = env.store->Get(*key);
  if (absl::IsNotFound(mesh.status())) {
    return MeshNotFoundError(field, absl::StrCat("mesh ", QuoteInput(name), " not found"));
  }
  return mesh;  // or DataLoss (a corrupt file), ResourceExhausted (cannot be loaded back)
}

// ------------------------------------------------------------------------------------------
// Mesh resources

absl::Status RunGetMesh(const QueryEnv& env, const v1::GetMeshRequest& request,
                        v1::Mesh* response) {
  absl::StatusOr<std::string> key = ParseMeshName(request.name(), "name");
  if (!key.ok()) return key.status();
  // The record: a mesh that is only on disk is described without loading it.
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh = env.store->GetRecord(*key);
  if (!mesh.ok()) {
    return MeshNotFoundError("name", absl::StrCat("mesh ", QuoteInput(request.name()), " not found"));
  }
  MeshToProto(**mesh, response);
  return absl::OkStatus();
}

absl::Status RunListMeshes(const QueryEnv& env, const v1::ListMeshesRequest& request,
                           v1::ListMeshesResponse* response) {
  constexpr int kDefaultPageSize = 50;
  constexpr int kMaxPageSize = 1000;
  if (request.page_size() < 0) {
    return FieldError("page_size", absl::StrCat("must be >= 0, got ", request.page_size()));
  }
  if (!request.page_token().empty() && !IsMeshId(request.page_token())) {
    return FieldError("page_token", "not a token returned by ListMeshes");
  }
  const int page_size =
      request.page_size() == 0 ? kDefaultPageSize : std::min(request.page_size(), kMaxPageSize);
  bool more = false;
  std::vector<std::shared_ptr<const StoredMesh>> page =
      env.store->List(request.page_token(), static_cast<size_t>(page_size), &more);
  for (const auto& mesh : page) MeshToProto(*mesh, response->add_meshes());
  if (more && !page.empty()) response->set_next_page_token(page.back()->id);
  return absl::OkStatus();
}

absl::Status RunDeleteMesh(const QueryEnv& env, const v1::DeleteMeshRequest& request,
                           v1::DeleteMeshResponse* /*response*/) {
  absl::StatusOr<std::string> key = ParseMeshName(request.name(), "name");
  if (!key.ok()) return key.status();
  absl::Status status = env.store->Delete(*key);
  if (absl::IsNotFound(status)) {
    return MeshNotFoundError("name", absl::StrCat("mesh ", QuoteInput(request.name()), " not found"));
  }
  return status;
}

// ------------------------------------------------------------------------------------------
// Unary queries

absl::Status RunFindShortestPath(const QueryEnv& env, const v1::FindShortestPathRequest& request,
                                 v1::FindShortestPathResponse* response) {
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh =
      LookupMesh(env, request.mesh(), "mesh");
  if (!mesh.ok()) return mesh.status();
  absl::StatusOr<SurfacePoint> from = ResolvePoint(**mesh, request.from(), "from");
  if (!from.ok()) return from.status();
  absl::StatusOr<SurfacePoint> to = ResolvePoint(**mesh, request.to(), "to");
  if (!to.ok()) return to.status();
  absl::StatusOr<GeodesicOptions> solver = Options(env, request.options());
  if (!solver.ok()) return solver.status();
  // From a cached field of `from` a path to a vertex is a trace, not a solve; the second query
  // from the same point solves (and caches) the full field so that the following ones reuse it.
  if (to->kind == SurfacePoint::Kind::kVertex && env.cache->enabled()) {
    const std::string key = FieldCacheKey((*mesh)->id, {*from}, *solver);
    std::shared_ptr<const DistanceField> field = env.cache->Find(key);
    bool cached = field != nullptr;
    if (field == nullptr && env.quick) return SolveLaneNeeded();
    if (field == nullptr && env.cache->NotePathSource(key)) {
      absl::StatusOr<std::shared_ptr<const DistanceField>> solved =
          CachedField(env, **mesh, {*from}, *solver, &cached);
      if (!solved.ok()) return NameSolveError(solved.status(), "from");
      field = *std::move(solved);
    }
    if (field != nullptr) {
      absl::StatusOr<GeodesicPath> path = TracePathFromVertex(*(*mesh)->mesh, *field, to->vertex);
      if (absl::IsNotFound(path.status())) {
        return UnreachableError("to: unreachable from `from`");
      }
      if (!path.ok()) return path.status();
      response->set_distance(field->distance[to->vertex]);
      for (auto it = path->points.rbegin(); it != path->points.rend(); ++it) {
        PathPointToProto(*it, response->add_points());
      }
      if (request.want_stats()) FieldStatsToProto(*field, cached, response->mutable_stats());
      return CheckUnaryResponseSize(env, *response, "paths");
    }
  }
  if (env.quick) return SolveLaneNeeded();
  PathQueryOptions options;
  options.solver = *solver;
  absl::StatusOr<PathQueryResult> result = ComputeShortestPath(*(*mesh)->mesh, *from, *to, options);
  if (result.ok()) {
    env.counters->solves.fetch_add(1, std::memory_order_relaxed);
    env.counters->windows_processed.fetch_add(result->stats.windows_processed,
                                              std::memory_order_relaxed);
  }
  if (!result.ok()) {
    if (result.status().code() == absl::StatusCode::kNotFound) {
      return UnreachableError(
          absl::StrCat("to: unreachable from `from` (", result.status().message(), ")"));
    }
    return NameSolveError(result.status(), "from/to");
  }
  response->set_distance(result->distance);
  for (const PathPoint& p : result->path.points) PathPointToProto(p, response->add_points());
  if (request.want_stats()) StatsToProto(result->stats, response->mutable_stats());
  return CheckUnaryResponseSize(env, *response, "paths");
}

absl::Status RunFindShortestPaths(const QueryEnv& env, const v1::FindShortestPathsRequest& request,
                                  v1::FindShortestPathsResponse* response) {
  if (env.quick) return SolveLaneNeeded();
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh = LookupMesh(env, request.mesh(), "mesh");
  if (!mesh.ok()) return mesh.status();
  if (request.pairs().empty()) {
    return FieldError("pairs", "at least one pair is required");
  }
  if (static_cast<uint64_t>(request.pairs_size()) > env.limits->max_targets) {
    return ServerLimitError("max_targets", absl::StrCat(
        "pairs: ", request.pairs_size(), " pairs, over --max_targets=", env.limits->max_targets));
  }
  absl::StatusOr<GeodesicOptions> solver = Options(env, request.options());
  if (!solver.ok()) return solver.status();
  // Group the pairs by their source point (bit for bit), in order of first appearance.
  std::vector<SurfacePoint> froms, tos;
  std::map<std::string, size_t> group_of;
  std::vector<std::vector<size_t>> groups;
  for (int i = 0; i < request.pairs_size(); ++i) {
    const std::string field = absl::StrCat("pairs[", i, "]");
    absl::StatusOr<SurfacePoint> from = ResolvePoint(**mesh, request.pairs(i).from(), field + ".from");
    if (!from.ok()) return from.status();
    absl::StatusOr<SurfacePoint> to = ResolvePoint(**mesh, request.pairs(i).to(), field + ".to");
    if (!to.ok()) return to.status();
    const std::string key = FieldCacheKey("", {*from}, *solver);
    auto [it, fresh] = group_of.emplace(key, groups.size());
    if (fresh) {
      groups.emplace_back();
      froms.push_back(*from);
    }
    groups[it->second].push_back(static_cast<size_t>(i));
    tos.push_back(*to);
    response->add_paths();
  }
  PathQueryOptions options;
  options.solver = *solver;
  SolveStats total;
  for (size_t g = 0; g < groups.size(); ++g) {
    std::vector<SurfacePoint> targets;
    for (size_t i : groups[g]) targets.push_back(tos[i]);
    absl::StatusOr<PathsQueryResult> result =
        ComputeShortestPaths(*(*mesh)->mesh, froms[g], targets, options);
    if (!result.ok()) return NameSolveError(result.status(), "pairs");
    env.counters->solves.fetch_add(1, std::memory_order_relaxed);
    env.counters->windows_processed.fetch_add(result->stats.windows_processed,
                                              std::memory_order_relaxed);
    AddSolveStats(result->stats, &total);
    for (size_t k = 0; k < groups[g].size(); ++k) {
      v1::FindShortestPathResponse* out = response->mutable_paths(static_cast<int>(groups[g][k]));
      out->set_distance(result->distance[k]);
      for (const PathPoint& p : result->paths[k].points) PathPointToProto(p, out->add_points());
    }
  }
  response->set_solves(static_cast<uint32_t>(groups.size()));
  if (request.want_stats()) StatsToProto(total, response->mutable_stats());
  return CheckUnaryResponseSize(env, *response, "pairs");
}

absl::Status RunEstimateDistances(const QueryEnv& env, const v1::EstimateDistancesRequest& request,
                                  v1::EstimateDistancesResponse* response) {
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh =
      LookupMesh(env, request.mesh(), "mesh");
  if (!mesh.ok()) return mesh.status();
  const TriangleMesh& tm = *(*mesh)->mesh;
  absl::StatusOr<std::vector<SurfacePoint>> sources =
      ResolveSources(env, **mesh, request.sources());
  if (!sources.ok()) return sources.status();
  absl::StatusOr<std::vector<SurfacePoint>> points =
      ResolvePoints(**mesh, request.points(), "points", env.limits->max_targets, "max_targets");
  if (!points.ok()) return points.status();
  if (!v1::PointDistanceMode_IsValid(request.mode())) {
    return FieldError("mode", absl::StrCat("unknown value ", request.mode()));
  }
  const bool estimate = request.mode() != v1::POINT_DISTANCE_MODE_EXACT;
  const bool exact = request.mode() == v1::POINT_DISTANCE_MODE_EXACT ||
                     request.mode() == v1::POINT_DISTANCE_MODE_BOTH;
  if (exact && env.quick) return SolveLaneNeeded();
  absl::StatusOr<GeodesicOptions> solver = Options(env, request.options());
  if (!solver.ok()) return solver.status();
  if (estimate) {
    bool cached = false;
    absl::StatusOr<std::shared_ptr<const DistanceField>> field =
        CachedField(env, **mesh, *sources, *solver, &cached);
    if (!field.ok()) return field.status();
    for (size_t i = 0; i < points->size(); ++i) {
      absl::StatusOr<PointEstimate> e = EstimateDistanceAt(tm, **field, (*points)[i]);
      if (!e.ok()) return NameSolveError(e.status(), "points");
      response->add_estimates(e->distance);
      response->add_estimate_labels(e->source);
    }
    if (request.want_stats()) {
      FieldStatsToProto(**field, cached, response->mutable_estimate_stats());
    }
  }
  if (exact) {
    SolveStats stats;
    absl::StatusOr<std::vector<std::pair<double, uint32_t>>> values =
        ComputeExactDistancesAt(tm, *sources, *points, *solver, &stats);
    if (!values.ok()) return NameSolveError(values.status(), "points");
    env.counters->solves.fetch_add(1, std::memory_order_relaxed);
    env.counters->windows_processed.fetch_add(stats.windows_processed, std::memory_order_relaxed);
    for (const auto& [distance, label] : *values) {
      response->add_exact(distance);
      response->add_exact_labels(label);
    }
    if (request.want_stats()) StatsToProto(stats, response->mutable_exact_stats());
  }
  return CheckUnaryResponseSize(env, *response, "points");
}

absl::Status RunLocatePoints(const QueryEnv& env, const v1::LocatePointsRequest& request,
                             v1::LocatePointsResponse* response) {
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh =
      LookupMesh(env, request.mesh(), "mesh");
  if (!mesh.ok()) return mesh.status();
  if (request.positions().empty()) {
    return FieldError("positions", "at least one position is required");
  }
  if (static_cast<uint64_t>(request.positions_size()) > env.limits->max_targets) {
    return ServerLimitError("max_targets", absl::StrCat("positions: ", request.positions_size(),
                     " points, over --max_targets=", env.limits->max_targets));
  }
  const double max_snap =
      request.has_max_snap() ? request.max_snap() : std::numeric_limits<double>::infinity();
  if (!(max_snap > 0)) {  // also NaN
    return FieldError("max_snap", absl::StrCat("must be > 0 when set, got ", request.max_snap()));
  }
  for (int i = 0; i < request.positions_size(); ++i) {
    if ((i & 1023) == 0 && env.cancel->IsCancelled()) return absl::CancelledError("cancelled");
    const v1::Position& q = request.positions(i);
    absl::StatusOr<LocatedPoint> located = (*mesh)->locator->Locate({q.x(), q.y(), q.z()});
    if (located.ok()) {
      absl::Status snap = CheckSnapDistance({q.x(), q.y(), q.z()}, *located, max_snap);
      if (!snap.ok()) located = snap;
    }
    if (!located.ok()) {
      const std::string field = absl::StrCat("positions[", i, "]");
      if (absl::IsInvalidArgument(located.status())) {
        return FieldError(field, located.status().message());
      }
      return absl::Status(located.status().code(),
                          absl::StrCat(field, ": ", located.status().message()));
    }
    v1::LocatedPoint* out = response->add_points();
    SurfacePointToProto(located->point, out->mutable_point());
    PositionToProto(located->position, out->mutable_position());
    out->set_distance(located->distance);
  }
  return CheckUnaryResponseSize(env, *response, "positions");
}

// ------------------------------------------------------------------------------------------
// Streamed queries

absl::StatusOr<MessageStream<v1::ComputeDistanceFieldResponse>> RunComputeDistanceField(
    const QueryEnv& env, const v1::ComputeDistanceFieldRequest& request) {
  if (!v1::ValueType_IsValid(request.value_type())) {
    return FieldError("value_type", absl::StrCat("unknown value ", request.value_type()));
  }
  absl::StatusOr<SolvedField> solved =
      SolveField(env, request.mesh(), request.sources(), request.options());
  if (!solved.ok()) return solved.status();

  // Produced lazily from the field: no second copy of a large result.
  struct State {
    SolvedField solved;  // the shared field: chunks are read from it, never copied whole
    size_t next = 0;
    bool started = false;
  };
  auto state = std::make_shared<State>();
  state->solved = *std::move(solved);
  const bool f32 = request.value_type() == v1::VALUE_TYPE_FLOAT32;
  const bool want_stats = request.want_stats();
  const bool labels = !request.omit_labels();
  const size_t bytes_per_value = (f32 ? 4 : 8) + (labels ? 4 : 0);
  const size_t chunk = std::max<size_t>(1, env.limits->stream_chunk_bytes / bytes_per_value);
  return MessageProducer<v1::ComputeDistanceFieldResponse>(
      [state, f32, want_stats, labels, chunk](v1::ComputeDistanceFieldResponse* out) {
        const DistanceField& field = *state->solved.field;
        const size_t n = field.distance.size();
        if (state->started && state->next >= n) return false;
        out->set_vertex_count(n);
        out->set_offset(state->next);
        if (!state->started) {
          for (const SurfacePoint& p : state->solved.sources) {
            SurfacePointToProto(p, out->add_resolved_sources());
          }
        }
        const size_t begin = state->next, end = std::min(n, begin + chunk);
        if (f32) {
          auto* values = out->mutable_distances_f32();
          values->Reserve(static_cast<int>(end - begin));
          for (size_t i = begin; i < end; ++i) {
            values->AddAlreadyReserved(static_cast<float>(field.distance[i]));
          }
        } else {
          out->mutable_distances_f64()->Add(field.distance.begin() + begin,
                                            field.distance.begin() + end);
        }
        if (labels) {
          out->mutable_labels()->Add(field.source.begin() + begin, field.source.begin() + end);
        }
        if (end == n && want_stats) {
          FieldStatsToProto(field, state->solved.cached, out->mutable_stats());
        }
        state->started = true;
        state->next = end;
        return true;
      });
}

namespace {

using FinalRowFn = std::function<void(size_t row, const double* values)>;

// The rows of a matrix: from cached full fields where possible (see RunComputeDistanceMatrix),
// the rest solved in one engine call. `*cached` is true when nothing was solved. Each row goes to
// `on_final_row` as soon as it and every row before it are final, in order.
absl::StatusOr<DistanceMatrix> SolveMatrixRows(const QueryEnv& env, const StoredMesh& mesh,
                                               const std::vector<SurfacePoint>& sources,
                                               const std::vector<SurfacePoint>& targets,
                                               const GeodesicOptions& solver, uint32_t k_nearest,
                                               bool symmetric, const FinalRowFn& on_final_row,
                                               const std::function<void(double)>& on_progress,
                                               bool* cached) {
  DistanceMatrix out;
  out.rows = sources.size();
  out.cols = targets.size();
  out.values.assign(out.rows * out.cols, std::numeric_limits<double>::infinity());
  std::vector<size_t> missing;
  std::vector<char> row_final(out.rows, 0);
  size_t next_final = 0;
  auto hand_out = [&] {  // the final prefix, in order
    for (; next_final < out.rows && row_final[next_final]; ++next_final) {
      on_final_row(next_final, &out.values[next_final * out.cols]);
    }
  };
  const bool vertex_targets =
      std::all_of(targets.begin(), targets.end(),
                  [](const SurfacePoint& p) { return p.kind == SurfacePoint::Kind::kVertex; });
  for (size_t r = 0; r < sources.size(); ++r) {
    std::shared_ptr<const DistanceField> field;
    if (vertex_targets && !symmetric && env.cache->enabled()) {
      field = env.cache->Find(FieldCacheKey(mesh.id, {sources[r]}, solver));
    }
    if (field == nullptr) {
      missing.push_back(r);
      continue;
    }
    double* row = &out.values[r * out.cols];
    for (size_t c = 0; c < targets.size(); ++c) row[c] = field->distance[targets[c].vertex];
    KeepKNearest(k_nearest, row, targets.size());  // as the engine's rows do
    row_final[r] = 1;
  }
  hand_out();
  *cached = missing.empty();
  if (missing.empty()) return out;

  std::vector<SurfacePoint> rest;
  rest.reserve(missing.size());
  for (size_t r : missing) rest.push_back(sources[r]);
  MatrixOptions matrix_options;
  matrix_options.solver = solver;
  matrix_options.k_nearest = k_nearest;
  if (env.pool != nullptr) {
    // Rows beyond the calling worker's go to the shared pool, behind work already queued; a
    // refused helper (queue full) only means fewer rows at once.
    ComputePool* pool = env.pool;
    matrix_options.threads = static_cast<unsigned>(pool->threads());
    matrix_options.spawn = [pool](std::function<void()> helper) {
      pool->TrySubmit(std::move(helper));
    };
  } else {
    matrix_options.threads = 1;
  }
  const double cached_rows = static_cast<double>(out.rows - missing.size());
  matrix_options.on_row = [&](size_t done, size_t total) {
    on_progress((cached_rows + static_cast<double>(done) / total * missing.size()) / out.rows);
  };
  // The engine hands out its rows one at a time, in order: place each, then pass on the prefix.
  matrix_options.on_final_row = [&](size_t i, const double* values) {
    std::copy_n(values, out.cols, out.values.begin() + missing[i] * out.cols);
    row_final[missing[i]] = 1;
    hand_out();
  };
  absl::StatusOr<DistanceMatrix> matrix = ComputeDistanceMatrix(*mesh.mesh, rest, targets,
                                                                matrix_options);
  if (!matrix.ok()) return NameSolveError(matrix.status(), "sources/targets");
  env.counters->solves.fetch_add(1, std::memory_order_relaxed);
  env.counters->windows_processed.fetch_add(matrix->stats.windows_processed,
                                            std::memory_order_relaxed);
  out.stats = matrix->stats;
  return out;
}

// A matrix on its way to the client: rows are added as they become final (the first
// `final_values` values), `done` once the solve has returned and `stats` are set.
struct MatrixStreamState {
  std::mutex mu;
  size_t rows = 0, cols = 0;
  std::vector<double> values;
  size_t final_values = 0;
  bool done = false;
  SolveStats stats;
  bool cached = false;
  size_t next = 0;    // the next value to send
  bool sent = false;  // a message went out (an empty matrix still gets one)
  double progress = 0, progress_sent = 0;  // fraction of the solves done; the last one sent
};

// The next message of a matrix stream: the final values not sent yet (at most `chunk`), the last
// value held back until the solve returned so that the stats ride with it.
Produced NextMatrixMessage(MatrixStreamState& state, bool f32, bool want_stats, size_t chunk,
                           v1::ComputeDistanceMatrixResponse* out) {
  std::lock_guard<std::mutex> lock(state.mu);
  const size_t n = state.values.size();
  if (state.done && state.next >= n && (n > 0 || state.sent)) return Produced::kEnd;
  const size_t ready = state.done ? n : std::min(state.final_values, n > 0 ? n - 1 : 0);
  const double progress = state.done ? 1.0 : state.progress;
  // Progress alone is worth a message in steps of 1% (rows that wait on others).
  const bool progressed = progress >= state.progress_sent + 0.01;
  if (state.next >= ready && !(state.done && !state.sent) && !progressed) return Produced::kLater;
  out->set_rows(state.rows);
  out->set_cols(state.cols);
  out->set_offset(state.next);
  out->set_progress(progress);
  state.progress_sent = progress;
  const size_t begin = state.next, end = std::min(ready, begin + chunk);
  if (f32) {
    for (size_t i = begin; i < end; ++i) out->add_values_f32(static_cast<float>(state.values[i]));
  } else {
    out->mutable_values_f64()->Add(state.values.begin() + begin, state.values.begin() + end);
  }
  if (end == n && want_stats) {
    StatsToProto(state.stats, out->mutable_stats());
    out->mutable_stats()->set_cached(state.cached);
  }
  state.next = end > begin ? end : (n == 0 ? 1 : begin);
  state.sent = true;
  return Produced::kMessage;
}

}  // namespace

absl::StatusOr<MessageStream<v1::ComputeDistanceMatrixResponse>> RunComputeDistanceMatrix(
    const QueryEnv& env, const v1::ComputeDistanceMatrixRequest& request) {
  if (!v1::ValueType_IsValid(request.value_type())) {
    return FieldError("value_type", absl::StrCat("unknown value ", request.value_type()));
  }
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh =
      LookupMesh(env, request.mesh(), "mesh");
  if (!mesh.ok()) return mesh.status();
  absl::StatusOr<std::vector<SurfacePoint>> sources =
      ResolveSources(env, **mesh, request.sources());
  if (!sources.ok()) return sources.status();
  absl::StatusOr<std::vector<SurfacePoint>> targets =
      ResolvePoints(**mesh, request.targets(), "targets", env.limits->max_targets, "max_targets");
  if (!targets.ok()) return targets.status();
  const uint64_t values = uint64_t{sources->size()} * targets->size();
  if (values > env.limits->max_output_values) {
    return ServerLimitError("max_output_values", absl::StrCat("the matrix has ", sources->size(), " x ", targets->size(), " = ", values,
                     " values, over --max_output_values=", env.limits->max_output_values));
  }
  absl::StatusOr<GeodesicOptions> solver = Options(env, request.options());
  if (!solver.ok()) return solver.status();

  // Reuse (issue 19): a repeated matrix is one cache entry (values as a DistanceField); otherwise
  // rows whose source has a full field in the cache are read from it when every target is a
  // vertex (not for symmetric requests, whose pairs the engine solves once and mirrors), and only
  // the other rows are solved.
  const std::string sources_key = FieldCacheKey((*mesh)->id, *sources, *solver);
  const std::string targets_key = FieldCacheKey("", *targets, *solver);
  std::string matrix_key =
      absl::StrCat(sources_key, "|matrix|", targets_key, "|k", request.k_nearest());
  std::shared_ptr<const DistanceField> cached_matrix = env.cache->Find(matrix_key);
  if (cached_matrix == nullptr && env.quick) return SolveLaneNeeded();

  auto state = std::make_shared<MatrixStreamState>();
  state->rows = sources->size();
  state->cols = targets->size();
  const bool f32 = request.value_type() == v1::VALUE_TYPE_FLOAT32;
  const bool want_stats = request.want_stats();
  const size_t chunk = std::max<size_t>(1, env.limits->stream_chunk_bytes / (f32 ? 4 : 8));
  auto next = [state, f32, want_stats, chunk](v1::ComputeDistanceMatrixResponse* out) {
    return NextMatrixMessage(*state, f32, want_stats, chunk, out);
  };
  if (cached_matrix != nullptr) {
    state->values = cached_matrix->distance;
    state->final_values = state->values.size();
    state->stats = cached_matrix->stats;
    state->cached = state->done = true;
    return MessageStream<v1::ComputeDistanceMatrixResponse>(std::move(next), nullptr);
  }
  // Solved while streaming (issue 19): each row is sent as soon as it and the rows before it are
  // final, so a client sees progress; the whole matrix then enters the cache.
  state->values.assign(values, std::numeric_limits<double>::infinity());
  const bool symmetric = sources_key == FieldCacheKey((*mesh)->id, *targets, *solver);
  auto work = [env, mesh = *std::move(mesh), sources = *std::move(sources),
               targets = *std::move(targets), solver = *solver, k = request.k_nearest(), symmetric,
               matrix_key = std::move(matrix_key),
               state](const std::function<void()>& ready) -> absl::Status {
    auto on_final_row = [&](size_t row, const double* row_values) {
      {
        std::lock_guard<std::mutex> lock(state->mu);
        std::copy_n(row_values, state->cols, state->values.begin() + row * state->cols);
        state->final_values = (row + 1) * state->cols;
      }
      ready();
    };
    auto on_progress = [&](double progress) {
      {
        std::lock_guard<std::mutex> lock(state->mu);
        state->progress = progress;
      }
      ready();
    };
    bool cached = false;
    absl::StatusOr<DistanceMatrix> solved = SolveMatrixRows(
        env, *mesh, sources, targets, solver, k, symmetric, on_final_row, on_progress, &cached);
    if (!solved.ok()) return solved.status();
    auto entry = std::make_shared<DistanceField>();
    entry->distance = std::move(solved->values);  // the stream already holds every row
    entry->stats = solved->stats;
    env.cache->Insert(matrix_key, std::move(entry));
    std::lock_guard<std::mutex> lock(state->mu);
    state->stats = solved->stats;
    state->cached = cached;
    state->done = true;
    return absl::OkStatus();
  };
  return MessageStream<v1::ComputeDistanceMatrixResponse>(std::move(next), std::move(work));
}

absl::StatusOr<MessageStream<v1::ComputeIsolinesResponse>> RunComputeIsolines(
    const QueryEnv& env, const v1::ComputeIsolinesRequest& request) {
  const uint32_t max_levels = env.limits->max_levels;
  if (static_cast<uint64_t>(request.levels_size()) > max_levels) {
    return ServerLimitError("max_levels", absl::StrCat("levels: ", request.levels_size(), " levels, over --max_levels=", max_levels));
  }
  IsolineOptions options;
  for (int i = 0; i < request.levels_size(); ++i) {
    if (!std::isfinite(request.levels(i))) {
      return FieldError(absl::StrCat("levels[", i, "]"),
                        absl::StrCat("must be finite, got ", request.levels(i)));
    }
    options.levels.push_back(request.levels(i));
  }
  if (options.levels.empty()) {
    if (request.count() < 2) {
      return FieldError("count", absl::StrCat("give levels, or a count >= 2 (got ", request.count(), ")"));
    }
    if (static_cast<uint64_t>(request.count()) > uint64_t{max_levels} + 1) {
      return ServerLimitError("max_levels", absl::StrCat("count: ", request.count(), " gives ",
                                                       request.count() - 1,
                                                       " levels, over --max_levels=", max_levels));
    }
    options.count = request.count();
  }
  absl::StatusOr<SolvedField> solved =
      SolveField(env, request.mesh(), request.sources(), request.options());
  if (!solved.ok()) return solved.status();
  absl::StatusOr<Isolines> isolines = ExtractIsolines(*solved->mesh->mesh, *solved->field, options);
  if (!isolines.ok()) return isolines.status();

  std::vector<v1::ComputeIsolinesResponse> messages =
      api::IsolinesToProto(*isolines, env.limits->stream_chunk_bytes);
  if (request.want_stats()) {
    FieldStatsToProto(*solved->field, solved->cached, messages.back().mutable_stats());
  }
  return ProducerOf(std::move(messages));
}

absl::StatusOr<MessageStream<v1::ComputeVoronoiResponse>> RunComputeVoronoi(
    const QueryEnv& env, const v1::ComputeVoronoiRequest& request) {
  absl::StatusOr<SolvedField> solved =
      SolveField(env, request.mesh(), request.sources(), request.options());
  if (!solved.ok()) return solved.status();
  absl::StatusOr<VoronoiDiagram> diagram = BuildVoronoi(*solved->mesh->mesh, *solved->field);
  if (!diagram.ok()) return diagram.status();

  std::vector<v1::ComputeVoronoiResponse> messages = api::VoronoiToProto(
      *diagram, solved->sources, request.omit_cell_faces(), env.limits->stream_chunk_bytes);
  if (request.want_stats()) {
    FieldStatsToProto(*solved->field, solved->cached, messages.back().mutable_stats());
  }
  return ProducerOf(std::move(messages));
}

absl::StatusOr<MessageStream<v1::ComputeDelaunayResponse>> RunComputeDelaunay(
    const QueryEnv& env, const v1::ComputeDelaunayRequest& request) {
  absl::StatusOr<SolvedField> solved =
      SolveField(env, request.mesh(), request.sources(), request.options());
  if (!solved.ok()) return solved.status();
  absl::StatusOr<DelaunayTriangulation> delaunay =
      BuildDelaunay(*solved->mesh->mesh, *solved->field);
  if (!delaunay.ok()) return delaunay.status();

  std::vector<v1::ComputeDelaunayResponse> messages =
      api::DelaunayToProto(*delaunay, solved->sources, env.limits->stream_chunk_bytes);
  if (request.want_stats()) {
    FieldStatsToProto(*solved->field, solved->cached, messages.back().mutable_stats());
  }
  return ProducerOf(std::move(messages));
}

}  // namespace geodex::server
