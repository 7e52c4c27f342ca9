#include "query_support.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/cord.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/strip.h"
#include "field_cache.h"
#include "geodex/delaunay.h"
#include "geodex/distance_matrix.h"
#include "geodex/friction.h"
#include "geodex/geodesic_solver.h"
#include "geodex/geometry_queries.h"
#include "geodex/isolines.h"
#include "geodex/mesh_id.h"
#include "geodex/point_distance.h"
#include "geodex/shortest_path.h"
#include "geodex/travel_cost.h"
#include "geodex/voronoi.h"
#include "geodex/weighted_field.h"
#include "geometry_convert.h"
#include "proto_convert.h"
#include "service_limits.h"
#include "status_convert.h"

namespace geodex::server {

// Resolves a list of request points (sources or targets) after checking its size against a limit.
absl::StatusOr<std::vector<SurfacePoint>> ResolvePoints(const StoredMesh& mesh,
                                                        const PointList& points,
                                                        const std::string& field, uint64_t limit,
                                                        const char* flag, PointSnaps* snaps) {
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
        ResolvePoint(mesh, points[i], absl::StrCat(field, "[", i, "]"), snaps);
    if (!p.ok()) return p.status();
    out.push_back(*p);
  }
  return out;
}

absl::StatusOr<std::vector<SurfacePoint>> ResolveSources(const QueryEnv& env,
                                                         const StoredMesh& mesh,
                                                         const PointList& sources,
                                                         PointSnaps* snaps) {
  return ResolvePoints(mesh, sources, "sources", env.limits->max_sources, "max_sources", snaps);
}

namespace {

// What reading GeoJSON on a mesh depends on beyond the mesh itself: its map (the CRS it projects
// polygons into, the grid's geotransform and units), or none.
std::string MapContextKey(const std::optional<terrain::DemInfo>& map) {
  if (!map.has_value()) return "no map";
  std::string key = absl::StrCat(map->file_crs_wkt, "|", map->mesh_crs_wkt, "|", map->reprojected,
                                 "|", map->step, "|", map->grid_width, "x", map->grid_height);
  for (double g : map->geotransform) absl::StrAppend(&key, absl::StrFormat("|%.17g", g));
  absl::StrAppend(&key,
                  absl::StrFormat("|%.17g|%.17g", map->horizontal_scale, map->vertical_scale));
  return Sha256Hex(key);
}

// The weights of a travel cost's friction_geojson on `mesh` (its face_weights came with the
// options: api::SolverOptionsFromProto).
absl::StatusOr<std::shared_ptr<const std::vector<double>>> FrictionWeights(
    const QueryEnv& env, const StoredMesh& mesh, const v1::TravelCost& travel) {
  // Friction read before from the same text on this mesh in the same map is in the result cache
  // (as a field's `distance`, like a matrix's values): a repeated request, and its cached field,
  // need no reading. Otherwise every face's centroid goes against the polygons: solve-lane work.
  // The map is part of the key: a mesh uploaded as a file gains one when its GeoTIFF is uploaded
  // (the same id), and the same GeoJSON then lands elsewhere (projected from its CRS).
  const std::string key = absl::StrCat(mesh.id, "|friction|", MapContextKey(mesh.terrain), "|",
                                       Sha256Hex(travel.friction_geojson()));
  if (std::shared_ptr<const DistanceField> hit = env.cache->Find(key, !env.quick)) {
    return std::shared_ptr<const std::vector<double>>(hit, &hit->distance);
  }
  if (env.quick) return SolveLaneNeeded();
  const std::string field = "options.travel.friction_geojson";
  // A DEM's mesh: its grid's exact file positions and its map; any other: its own x y.
  MeshData own;
  if (mesh.dem == nullptr) own = mesh.mesh->ToMeshData();
  const MeshData& data = mesh.dem != nullptr ? mesh.dem->mesh() : own;
  absl::StatusOr<std::vector<double>> friction = terrain::FrictionFromGeoJson(
      data, travel.friction_geojson(), mesh.terrain ? &*mesh.terrain : nullptr, field);
  if (!friction.ok()) {
    absl::string_view message = friction.status().message();
    absl::ConsumePrefix(&message, absl::StrCat(field, ": "));  // FieldError names it
    if (friction.status().code() != absl::StatusCode::kInvalidArgument) {
      return absl::Status(friction.status().code(), absl::StrCat(field, ": ", message));
    }
    return FieldError(field, message);
  }
  auto entry = std::make_shared<DistanceField>();
  entry->distance = *std::move(friction);
  std::shared_ptr<const DistanceField> weights = std::move(entry);
  env.cache->Insert(key, weights);
  return std::shared_ptr<const std::vector<double>>(weights, &weights->distance);
}

}  // namespace

absl::StatusOr<GeodesicOptions> Options(const QueryEnv& env, const StoredMesh& mesh,
                                        const v1::SolverOptions& options) {
  absl::StatusOr<GeodesicOptions> out = SolverOptionsFromProto(
      options, env.limits->max_windows, env.limits->max_steiner_points, "options");
  if (!out.ok()) return out;
  out->cancel = env.cancel;
  if (out->travel && !options.travel().friction_geojson().empty()) {
    absl::StatusOr<std::shared_ptr<const std::vector<double>>> weights =
        FrictionWeights(env, mesh, options.travel());
    if (!weights.ok()) return weights.status();
    out->travel->face_weight = *std::move(weights);
  }
  return out;
}

void ShareTravelSurface(const QueryEnv& env, const StoredMesh& mesh, GeodesicOptions* options) {
  if (!options->travel.has_value() || IsDirectional(*options->travel) || !env.cache->enabled()) {
    return;
  }
  if (!SharesTravelSurface(*options->travel)) return;
  const std::string key = TravelSurfaceKey(mesh.id, *options);
  std::shared_ptr<const WeightedSurface> graph = env.cache->FindGraph(key, *mesh.mesh);
  if (graph == nullptr) {
    absl::StatusOr<std::shared_ptr<const WeightedSurface>> built =
        BuildTravelSurface(*mesh.mesh, *options);
    if (!built.ok() || *built == nullptr) return;
    // The graph refers to the mesh: its owner keeps the mesh alive as long as the graph lives.
    struct Held {
      std::shared_ptr<const TriangleMesh> mesh;
      std::shared_ptr<const WeightedSurface> graph;
    };
    auto held = std::make_shared<const Held>(Held{mesh.mesh, *std::move(built)});
    graph = std::shared_ptr<const WeightedSurface>(held, held->graph.get());
    env.cache->InsertGraph(key, graph, mesh.memory_bytes);
  }
  options->travel->graph = std::move(graph);
}

absl::Status RefuseTravel(const v1::SolverOptions& options, absl::string_view why) {
  if (!options.has_travel()) return absl::OkStatus();
  return FieldError("options.travel",
                    absl::StrCat(why,
                                 "; a travel cost has none (fields, paths, matrices, exact "
                                 "point values, isolines and Voronoi work)"));
}

// Core's InvalidArgument from a solve: an option's names the option's field (the weighted
// engine's face weights, a travel cost with directions); any other concerns the points (e.g. a
// point on a degenerate face): name `field`.
absl::Status NameSolveError(const absl::Status& status, const char* field) {
  if (status.code() == absl::StatusCode::kInvalidArgument) {
    const std::string option = InvalidOptionOf(status);
    return FieldError(option.empty() ? std::string(field) : OptionFieldName(option),
                      status.message());
  }
  return status;
}

absl::Status CheckFieldSize(const QueryEnv& env, const StoredMesh& mesh) {
  if (mesh.vertex_count > env.limits->max_output_values) {
    return ServerLimitError("max_output_values", absl::StrCat("the field has ", mesh.vertex_count,
                                                              " values, over --max_output_values=",
                                                              env.limits->max_output_values));
  }
  return absl::OkStatus();
}

absl::Status CheckUnaryResponseSize(const QueryEnv& env, const google::protobuf::Message& response,
                                    const char* what) {
  const size_t bytes = response.ByteSizeLong();
  if (bytes > env.limits->max_unary_response_bytes) {
    return ServerLimitError(
        "max_unary_response_bytes",
        absl::StrCat("the response would be ", bytes, " bytes, over --max_unary_response_bytes=",
                     env.limits->max_unary_response_bytes, "; send fewer ", what, " per call"));
  }
  return absl::OkStatus();
}

// A distance field from the result cache, or solved (and then cached). `cached` tells which.
absl::StatusOr<std::shared_ptr<const DistanceField>> CachedField(
    const QueryEnv& env, const StoredMesh& mesh, const std::vector<SurfacePoint>& sources,
    const GeodesicOptions& options, bool* cached) {
  const std::string key = FieldCacheKey(mesh.id, sources, options);
  if (std::shared_ptr<const DistanceField> hit = env.cache->Find(key, !env.quick)) {
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

absl::StatusOr<SolvedField> SolveField(const QueryEnv& env, const std::string& mesh_name,
                                       const PointList& sources, const v1::SolverOptions& options,
                                       absl::StatusOr<PointSnaps> snaps,
                                       const IsolineOptions* isolines) {
  if (!snaps.ok()) return snaps.status();
  SolvedField out;
  out.snaps = *std::move(snaps);
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh = LookupMesh(env, mesh_name, "mesh");
  if (!mesh.ok()) return mesh.status();
  out.mesh = *std::move(mesh);
  if (absl::Status s = CheckFieldSize(env, *out.mesh); !s.ok()) return s;
  absl::StatusOr<std::vector<SurfacePoint>> resolved =
      ResolveSources(env, *out.mesh, sources, &out.snaps);
  if (!resolved.ok()) return resolved.status();
  out.sources = *std::move(resolved);
  absl::StatusOr<GeodesicOptions> solver = Options(env, *out.mesh, options);
  if (!solver.ok()) return solver.status();
  if (isolines != nullptr) *solver = IsolineFieldOptions(*out.mesh->mesh, *solver, *isolines);
  out.options = *solver;
  absl::StatusOr<std::shared_ptr<const DistanceField>> field =
      CachedField(env, *out.mesh, out.sources, *solver, &out.cached);
  if (!field.ok()) return field.status();
  out.field = *std::move(field);
  return out;
}

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

absl::StatusOr<IsolineOptions> IsolineLevels(const QueryEnv& env, IsolineOptions options) {
  // Core's one check; its errors name the option ("levels[2]", "count").
  if (absl::Status s = ValidateIsolineOptions(options, env.limits->max_levels); !s.ok()) {
    const std::string option = InvalidOptionOf(s);
    if (absl::IsResourceExhausted(s)) {
      return ServerLimitError("max_levels",
                              absl::StrCat(option, ": ", s.message(), " (--max_levels)"));
    }
    return FieldError(option, s.message());
  }
  return options;
}

}  // namespace geodex::server
