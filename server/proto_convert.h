#pragma once

// Conversions between geodex.v1 messages and core types, with input validation. Every error is
// InvalidArgument and names the request field ("sources[2].edge.t: ...").

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "api_convert.h"
#include "geodex/distance_field.h"
#include "geodex/geodesic_solver.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "geodex/v1/geodex.pb.h"
#include "mesh_store.h"

namespace geodex::server {

// "meshes/{key}" -> key (an id or an alias). `field` names the request field in errors.
absl::StatusOr<std::string> ParseMeshName(const std::string& name, const std::string& field);

// An alias given at upload or derivation: 1-63 characters of [A-Za-z0-9._-], not a 64-digit hex
// id ("" is none). InvalidArgument naming `field`.
absl::Status ValidateDisplayName(const std::string& name, const std::string& field);

// Fills a Mesh resource.
void MeshToProto(const StoredMesh& mesh, v1::Mesh* out);

// A request's snapping rule and record (the proto's "Snapping"): positions farther than
// `max_snap` from the surface are refused; ResolvePoint appends each point's snap distance, in
// the order the points are resolved (0 for points given on the surface or dropped from a map).
struct PointSnaps {
  double max_snap = std::numeric_limits<double>::infinity();
  std::vector<double> distances;
};

// The request's optional max_snap field: > 0 when set (InvalidArgument naming "max_snap").
absl::StatusOr<PointSnaps> SnapsFromRequest(bool has_max_snap, double max_snap);
template <typename Request>
absl::StatusOr<PointSnaps> SnapsOf(const Request& request) {
  return SnapsFromRequest(request.has_max_snap(), request.max_snap());
}

// A request point as a solver-ready SurfacePoint: range-checked against the mesh; positions are
// snapped to the surface with the mesh's locator, within `snaps->max_snap`, and every point's
// snap distance recorded in `snaps`.
absl::StatusOr<SurfacePoint> ResolvePoint(const StoredMesh& mesh, const v1::SurfacePoint& point,
                                          const std::string& field, PointSnaps* snaps);

// The plain conversions (shared with the client library).
using api::PathPointToProto;
using api::PositionToProto;
using api::StatsToProto;
using api::SurfacePointToProto;

// The request field of a core option error (InvalidOptionOf) under the options field `field`:
// "lambda" -> "options.lambda", "travel.speed_kmh" -> "options.travel.speed_kmh",
// "travel.speed_table[3]" -> "options.travel.speed_table[3]", "travel" -> "options.travel", and
// the weighted engine's "epsilon", "face_weight", "face_weight[7]", "slope_cost" ->
// "options.travel.epsilon", "options.travel.face_weights", "options.travel.face_weights[7]",
// "options.travel.speed_table".
std::string OptionFieldName(const std::string& option, const std::string& field = "options");

// A request's solver options as the server runs them: their wire mapping and core's check
// (api::SolverOptionsFromProto), errors naming the field ("options.travel.speed_kmh"; an unknown
// speed model is "options.travel.speed_model"), with the server's budgets (`max_windows`,
// `max_steiner_points`). Face weights given as friction_geojson need the mesh: query_support.h's
// Options reads them.
absl::StatusOr<GeodesicOptions> SolverOptionsFromProto(const v1::SolverOptions& options,
                                                       uint64_t max_windows,
                                                       uint64_t max_steiner_points,
                                                       const std::string& field);

}  // namespace geodex::server
