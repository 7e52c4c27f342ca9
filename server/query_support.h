#pragma once

// What the query families (queries_*.cc) share: resolving request points and options, the result
// cache in front of full fields, and response-size checks. Internal to the server.

#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/geodesic_solver.h"
#include "geodex/isolines.h"
#include "geodex/surface_point.h"
#include "geodex/v1/geodex.pb.h"
#include "mesh_store.h"
#include "proto_convert.h"
#include "queries.h"

namespace geodex::server {

using PointList = google::protobuf::RepeatedPtrField<v1::SurfacePoint>;

// Resolves a list of request points (sources or targets) after checking its size against a limit;
// the points' snap distances are appended to `snaps` (see ResolvePoint).
absl::StatusOr<std::vector<SurfacePoint>> ResolvePoints(const StoredMesh& mesh,
                                                        const PointList& points,
                                                        const std::string& field, uint64_t limit,
                                                        const char* flag, PointSnaps* snaps);
absl::StatusOr<std::vector<SurfacePoint>> ResolveSources(const QueryEnv& env,
                                                         const StoredMesh& mesh,
                                                         const PointList& sources,
                                                         PointSnaps* snaps);
// The snap distances as the response field `snap_distances` of any response that has it.
template <typename Response>
void SnapsToProto(const PointSnaps& snaps, Response* out) {
  out->mutable_snap_distances()->Add(snaps.distances.begin(), snaps.distances.end());
}
// The request's solver options on `mesh`, the one place every query gets them: validated
// (SolverOptionsFromProto), with the server's window and Steiner-point budgets, the call's cancel
// token, and a travel cost's face weights resolved against the mesh: face_weights (exactly one
// per face; their values the engine checks, NameSolveError naming them) or friction_geojson
// (terrain's FrictionFromGeoJson: in the DEM's map on a DEM's mesh, else in the mesh's x y).
absl::StatusOr<GeodesicOptions> Options(const QueryEnv& env, const StoredMesh& mesh,
                                        const v1::SolverOptions& options);
// A constant-speed, one-weight travel cost's surface (the exact engine's on the passable faces,
// core's BuildTravelSurface) from the result cache (TravelSurfaceKey), or built and cached, set in
// options->travel->graph: the travel paths, times at points and matrices on one mesh with one
// cost layer then share it; it takes any point. Nothing without a travel cost, with the cache off,
// or where core shares nothing (SharesTravelSurface): several weights run on regions built around
// each query's points, a slope-dependent speed on its own graph. A surface that cannot be built is
// left to the query, whose solve names the error. Solve-lane work (it may build).
void ShareTravelSurface(const QueryEnv& env, const StoredMesh& mesh, GeodesicOptions* options);
// What an answer's travel_epsilon says: 0 for exact metres, else the epsilon the solve uses
// (set, or the speed model's default).
inline double TravelEpsilon(const GeodesicOptions& options) {
  return options.travel ? TravelEpsilon(*options.travel) : 0;
}
// The response field travel_exact: the times are exact (TravelIsExact).
inline bool TravelExact(const GeodesicOptions& options) {
  return options.travel && TravelIsExact(*options.travel);
}
// INVALID_ARGUMENT naming options.travel for a product a travel cost cannot give, before any
// solve (`why`: what the product needs, "the geodesic Delaunay triangulation is traced through the
// exact engine's origins"); OK without a travel cost.
absl::Status RefuseTravel(const v1::SolverOptions& options, absl::string_view why);
inline constexpr absl::string_view kDelaunayNeedsOrigins =
    "the geodesic Delaunay triangulation is traced through the exact engine's origins";
// Core's InvalidArgument from a solve: an option's (InvalidOptionOf) names that option's request
// field (OptionFieldName: "options.travel.face_weights[7]"); any other concerns the points: name
// `field`.
absl::Status NameSolveError(const absl::Status& status, const char* field);
absl::Status CheckFieldSize(const QueryEnv& env, const StoredMesh& mesh);
absl::Status CheckUnaryResponseSize(const QueryEnv& env, const google::protobuf::Message& response,
                                    const char* what);
// A distance field from the result cache, or solved (and then cached). `cached` tells which.
absl::StatusOr<std::shared_ptr<const DistanceField>> CachedField(
    const QueryEnv& env, const StoredMesh& mesh, const std::vector<SurfacePoint>& sources,
    const GeodesicOptions& options, bool* cached);
void FieldStatsToProto(const DistanceField& field, bool cached, v1::SolveStats* out);

// Isoline options read from a request (api::IsolineLevelsFromProto), checked by core's
// ValidateIsolineOptions against --max_levels. Errors name the field or the flag.
absl::StatusOr<IsolineOptions> IsolineLevels(const QueryEnv& env, IsolineOptions options);

// The field behind distance fields, isolines, Voronoi and Delaunay.
struct SolvedField {
  std::shared_ptr<const StoredMesh> mesh;  // keeps the mesh alive while the result is built
  std::vector<SurfacePoint> sources;
  std::shared_ptr<const DistanceField> field;
  bool cached = false;
  PointSnaps snaps;         // the sources' snap distances
  GeodesicOptions options;  // the request's, as Options resolved them (field->travel_epsilon > 0
                            // for a travel cost)
};
// `snaps` is the request's rule (SnapsOf); the result's `snaps` carries the sources' distances.
// `isolines`: the levels the field is drawn for (isolines, isochrones): solved with core's
// IsolineFieldOptions, just past the top level.
absl::StatusOr<SolvedField> SolveField(const QueryEnv& env, const std::string& mesh_name,
                                       const PointList& sources, const v1::SolverOptions& options,
                                       absl::StatusOr<PointSnaps> snaps,
                                       const IsolineOptions* isolines = nullptr);

}  // namespace geodex::server
