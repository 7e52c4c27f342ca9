// Unary queries: FindShortestPath(s), EstimateDistances, LocatePoints.

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "field_cache.h"
#include "field_promoter.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/point_distance.h"
#include "geodex/shortest_path.h"
#include "proto_convert.h"
#include "queries.h"
#include "query_support.h"
#include "service_limits.h"
#include "status_convert.h"

namespace geodex::server {

// ------------------------------------------------------------------------------------------
// Unary queries

absl::Status RunFindShortestPath(const QueryEnv& env, const v1::FindShortestPathRequest& request,
                                 v1::FindShortestPathResponse* response) {
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh = LookupMesh(env, request.mesh(), "mesh");
  if (!mesh.ok()) return mesh.status();
  absl::StatusOr<PointSnaps> snaps = SnapsOf(request);
  if (!snaps.ok()) return snaps.status();
  absl::StatusOr<SurfacePoint> from = ResolvePoint(**mesh, request.from(), "from", &*snaps);
  if (!from.ok()) return from.status();
  absl::StatusOr<SurfacePoint> to = ResolvePoint(**mesh, request.to(), "to", &*snaps);
  if (!to.ok()) return to.status();
  SnapsToProto(*snaps, response);
  absl::StatusOr<GeodesicOptions> solver = Options(env, **mesh, request.options());
  if (!solver.ok()) return solver.status();
  response->set_travel_epsilon(TravelEpsilon(*solver));
  response->set_travel_exact(TravelExact(*solver));
  // From a cached field of `from` a path to a vertex is a trace, not a solve. Otherwise the path
  // runs A* (the work it asked for); a source asked again is offered for its whole field in the
  // background (FieldPromoter), never solved on this caller's clock, so that later paths from it
  // become traces. (A travel field has no origins to trace: a travel path is always its own
  // solve.)
  if (to->kind == SurfacePoint::Kind::kVertex && env.cache->enabled() && !solver->travel) {
    const std::string key = FieldCacheKey((*mesh)->id, {*from}, *solver);
    std::shared_ptr<const DistanceField> field = env.cache->Find(key, !env.quick);
    const bool cached = field != nullptr;
    if (field == nullptr && env.quick) return SolveLaneNeeded();
    if (field == nullptr && env.cache->NotePathSource(key) && env.promoter != nullptr) {
      env.promoter->Offer(*mesh, {*from}, *solver, key);  // with its own cancel token and budget
    }
    if (field != nullptr) {
      absl::StatusOr<GeodesicPath> path = TracePathFromVertex(*(*mesh)->mesh, *field, to->vertex);
      if (absl::IsNotFound(path.status())) {
        return UnreachableError(
            absl::StrCat("to: unreachable from `from`: ",
                         UnreachableReason(*(*mesh)->mesh, *from, *to, solver->max_distance)));
      }
      if (!path.ok()) return path.status();
      std::reverse(path->points.begin(), path->points.end());  // traced from `to`
      api::PathResultToProto(field->distance[to->vertex], path->length, path->points, response);
      if (request.want_stats()) FieldStatsToProto(*field, cached, response->mutable_stats());
      return CheckUnaryResponseSize(env, *response, "paths");
    }
  }
  if (env.quick) return SolveLaneNeeded();
  PathQueryOptions options;
  options.solver = *solver;
  ShareTravelSurface(env, **mesh, &options.solver);
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
  api::PathResultToProto(result->distance, result->path.length, result->path.points, response);
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
    return ServerLimitError("max_targets",
                            absl::StrCat("pairs: ", request.pairs_size(),
                                         " pairs, over --max_targets=", env.limits->max_targets));
  }
  absl::StatusOr<GeodesicOptions> solver = Options(env, **mesh, request.options());
  if (!solver.ok()) return solver.status();
  response->set_travel_epsilon(TravelEpsilon(*solver));
  response->set_travel_exact(TravelExact(*solver));
  absl::StatusOr<PointSnaps> rule = SnapsOf(request);
  if (!rule.ok()) return rule.status();
  // Group the pairs by their source point (bit for bit), in order of first appearance.
  std::vector<SurfacePoint> froms, tos;
  std::map<std::string, size_t> group_of;
  std::vector<std::vector<size_t>> groups;
  for (int i = 0; i < request.pairs_size(); ++i) {
    const std::string field = absl::StrCat("pairs[", i, "]");
    PointSnaps snaps{rule->max_snap, {}};  // this pair's
    absl::StatusOr<SurfacePoint> from =
        ResolvePoint(**mesh, request.pairs(i).from(), field + ".from", &snaps);
    if (!from.ok()) return from.status();
    absl::StatusOr<SurfacePoint> to =
        ResolvePoint(**mesh, request.pairs(i).to(), field + ".to", &snaps);
    if (!to.ok()) return to.status();
    const std::string key = FieldCacheKey("", {*from}, *solver);
    auto [it, fresh] = group_of.emplace(key, groups.size());
    if (fresh) {
      groups.emplace_back();
      froms.push_back(*from);
    }
    groups[it->second].push_back(static_cast<size_t>(i));
    tos.push_back(*to);
    v1::FindShortestPathResponse* path = response->add_paths();
    SnapsToProto(snaps, path);
    path->set_travel_epsilon(response->travel_epsilon());
    path->set_travel_exact(response->travel_exact());
  }
  PathQueryOptions options;
  options.solver = *solver;
  ShareTravelSurface(env, **mesh, &options.solver);
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
      api::PathResultToProto(result->distance[k], result->paths[k].length, result->paths[k].points,
                             out);
    }
  }
  response->set_solves(static_cast<uint32_t>(groups.size()));
  if (request.want_stats()) StatsToProto(total, response->mutable_stats());
  return CheckUnaryResponseSize(env, *response, "pairs");
}

absl::Status RunEstimateDistances(const QueryEnv& env, const v1::EstimateDistancesRequest& request,
                                  v1::EstimateDistancesResponse* response) {
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh = LookupMesh(env, request.mesh(), "mesh");
  if (!mesh.ok()) return mesh.status();
  const TriangleMesh& tm = *(*mesh)->mesh;
  absl::StatusOr<PointSnaps> snaps = SnapsOf(request);
  if (!snaps.ok()) return snaps.status();
  absl::StatusOr<std::vector<SurfacePoint>> sources =
      ResolveSources(env, **mesh, request.sources(), &*snaps);
  if (!sources.ok()) return sources.status();
  absl::StatusOr<std::vector<SurfacePoint>> points = ResolvePoints(
      **mesh, request.points(), "points", env.limits->max_targets, "max_targets", &*snaps);
  if (!points.ok()) return points.status();
  SnapsToProto(*snaps, response);
  if (!v1::PointDistanceMode_IsValid(request.mode())) {
    return FieldError("mode", absl::StrCat("unknown value ", request.mode()));
  }
  const bool estimate = request.mode() != v1::POINT_DISTANCE_MODE_EXACT;
  const bool exact = request.mode() == v1::POINT_DISTANCE_MODE_EXACT ||
                     request.mode() == v1::POINT_DISTANCE_MODE_BOTH;
  if (request.want_directions() && !exact) {
    return FieldError("want_directions",
                      "needs mode EXACT or BOTH (directions come from the exact solve)");
  }
  if (exact && env.quick) return SolveLaneNeeded();
  if (estimate) {  // the unfolding reads the exact engine's metres
    absl::Status s = RefuseTravel(request.options(),
                                  "the unfolding estimate (mode ESTIMATE, BOTH) unfolds the exact "
                                  "engine's metres (ask mode EXACT)");
    if (!s.ok()) return s;
  }
  absl::StatusOr<GeodesicOptions> solver = Options(env, **mesh, request.options());
  if (!solver.ok()) return solver.status();
  response->set_travel_epsilon(TravelEpsilon(*solver));
  response->set_travel_exact(TravelExact(*solver));
  if (estimate) {
    bool cached = false;
    absl::StatusOr<std::shared_ptr<const DistanceField>> field =
        CachedField(env, **mesh, *sources, *solver, &cached);
    if (!field.ok()) return field.status();
    for (size_t i = 0; i < points->size(); ++i) {
      absl::StatusOr<PointEstimate> e = EstimateDistanceAt(tm, **field, (*points)[i]);
      if (!e.ok()) return NameSolveError(e.status(), "points");
      api::PointEstimateToProto(*e, response);
    }
    if (request.want_stats()) {
      FieldStatsToProto(**field, cached, response->mutable_estimate_stats());
    }
  }
  if (exact) {
    if (!request.want_directions()) ShareTravelSurface(env, **mesh, &*solver);
    PointQuery query{*std::move(sources), *std::move(points), *solver, request.want_directions()};
    absl::StatusOr<PointValues> values = ComputePointValues(tm, query);
    if (!values.ok()) return NameSolveError(values.status(), "points");
    env.counters->solves.fetch_add(1, std::memory_order_relaxed);
    env.counters->windows_processed.fetch_add(values->stats.windows_processed,
                                              std::memory_order_relaxed);
    api::PointValuesToProto(*values, response);
    if (request.want_stats()) StatsToProto(values->stats, response->mutable_exact_stats());
  }
  return CheckUnaryResponseSize(env, *response, "points");
}

absl::Status RunLocatePoints(const QueryEnv& env, const v1::LocatePointsRequest& request,
                             v1::LocatePointsResponse* response) {
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh = LookupMesh(env, request.mesh(), "mesh");
  if (!mesh.ok()) return mesh.status();
  if (request.positions().empty()) {
    return FieldError("positions", "at least one position is required");
  }
  if (static_cast<uint64_t>(request.positions_size()) > env.limits->max_targets) {
    return ServerLimitError("max_targets",
                            absl::StrCat("positions: ", request.positions_size(),
                                         " points, over --max_targets=", env.limits->max_targets));
  }
  absl::StatusOr<PointSnaps> snaps = SnapsOf(request);
  if (!snaps.ok()) return snaps.status();
  const double max_snap = snaps->max_snap;
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
    api::LocatedPointToProto(*located, response->add_points());
  }
  return CheckUnaryResponseSize(env, *response, "positions");
}

}  // namespace geodex::server
