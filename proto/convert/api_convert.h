#pragma once

// Plain conversions between geodex.v1 messages and core types, used by both sides of the API (the
// server's validating conversions are in server/proto_convert.h). No validation here but the
// solver options' (core's own check): a proto point with nothing set (or a map point, which only a
// DEM can place) becomes a vertex 0.

#include <array>

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/locate.h"
#include "geodex/point_distance.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"
#include "geodex/v1/geodex.pb.h"

namespace geodex::api {

void SurfacePointToProto(const SurfacePoint& point, v1::SurfacePoint* out);
SurfacePoint SurfacePointFromProto(const v1::SurfacePoint& point);

void PositionToProto(const std::array<double, 3>& position, v1::Position* out);
std::array<double, 3> PositionFromProto(const v1::Position& position);

void PathPointToProto(const PathPoint& point, v1::PathPoint* out);
PathPoint PathPointFromProto(const v1::PathPoint& point);

void StatsToProto(const SolveStats& stats, v1::SolveStats* out);
// The counters the API carries (windows_filtered goes to windows_filtered_at_pop).
SolveStats StatsFromProto(const v1::SolveStats& stats);

// A mesh's summary as the Mesh resource carries it (counts on Mesh, the rest in Mesh.info), and
// back (file_vertices and file_faces from vertex_count and face_count).
void MeshSummaryToProto(const MeshSummary& summary, v1::Mesh* out);
MeshSummary MeshSummaryFromProto(const v1::Mesh& mesh);

// The request's solver options, both ways, the one place of their wire mapping: lambda, its
// scale, max_distance and the travel cost (speed model, speed, table, inbound, epsilon, slope
// limit, face weights as face_weights). Not on the wire: the budgets (max_windows,
// max_steiner_points: the server's flags), the cancel token, and friction_geojson's weights, which
// need the mesh (geodexd reads them: query_support.h's Options).
void SolverOptionsToProto(const GeodesicOptions& options, v1::SolverOptions* out);
// Back, checked by core's ValidateGeodesicOptions. Errors are InvalidArgument naming the option
// as core's do (InvalidOptionOf: "lambda_scale", "travel.speed_model", "travel.speed_kmh",
// "travel.friction_geojson" when face weights are given too), for the caller to put in its words
// (geodexd: server/proto_convert.h's OptionFieldName).
absl::StatusOr<GeodesicOptions> SolverOptionsFromProto(const v1::SolverOptions& options);

// EstimateDistances' exact part, carried whole: the query into the request (its sources, points
// and options; the mode is the caller's), and the answer into the response and back. The server
// places the request's points itself (map points, limits), so no PointQueryFromProto.
void PointQueryToProto(const PointQuery& query, v1::EstimateDistancesRequest* out);
void PointValuesToProto(const PointValues& values, v1::EstimateDistancesResponse* out);
PointValues PointValuesFromProto(const v1::EstimateDistancesResponse& response);
// Its estimate part (paper section 4), one point at a time out and all of them back.
void PointEstimateToProto(const PointEstimate& estimate, v1::EstimateDistancesResponse* out);
std::vector<PointEstimate> PointEstimatesFromProto(const v1::EstimateDistancesResponse& response);

// ComputeDistanceField's stream, both directions. The query into the request: its sources,
// options and the products it asks for (value type, labels and stats are the caller's).
void FieldQueryToProto(const FieldQuery& query, v1::ComputeDistanceFieldRequest* out);
// How a field is cut into messages: float32 or float64 distances, with or without labels.
struct FieldEncoding {
  bool f32 = false;
  bool labels = true;
};
// Bytes one vertex takes in a message (to size the chunks), with `products`' members.
size_t FieldBytesPerVertex(const FieldEncoding& encoding, const DistanceField& products);
// Vertices [begin, end) of `field` into one message, with the members `products` holds
// (ComputeFieldProducts) for them; the first message (begin == 0) also carries the resolved
// sources and the field's travel_epsilon. Stats are the caller's (the last message).
void FieldChunkToProto(const DistanceField& field, const DistanceField& products, size_t begin,
                       size_t end, const FieldEncoding& encoding,
                       v1::ComputeDistanceFieldResponse* out);
// The messages, in order, back into one DistanceField (float32 distances widened; the first
// message's travel_epsilon into DistanceField::travel_epsilon).
class FieldAssembler {
 public:
  using Message = v1::ComputeDistanceFieldResponse;  // what it is fed, one stream message at a time
  void Add(const v1::ComputeDistanceFieldResponse& message);
  DistanceField& result() { return field_; }
  bool cached() const { return cached_; }  // the last stats said the server's cache answered

 private:
  DistanceField field_;
  bool cached_ = false;
};

// The path and matrix requests asked whole: points, solver options and (matrix) k_nearest.
void PathQueryToProto(const PathQuery& query, v1::FindShortestPathRequest* out);
void MatrixQueryToProto(const MatrixQuery& query, v1::ComputeDistanceMatrixRequest* out);

// FindShortestPath's answer (and each of FindShortestPaths'), both directions: the length and the
// points from `from` to `to` (none when unreachable in FindShortestPaths). Stats are the
// caller's; FromProto reads them when present.
// `distance`: the path's cost (metres, or seconds with a travel cost); `length_m`: metres.
void PathResultToProto(double distance, double length_m, const std::vector<PathPoint>& points,
                       v1::FindShortestPathResponse* out);
PathQueryResult PathResultFromProto(const v1::FindShortestPathResponse& response);

// One answer of LocatePoints, both directions.
void LocatedPointToProto(const LocatedPoint& point, v1::LocatedPoint* out);
LocatedPoint LocatedPointFromProto(const v1::LocatedPoint& point);

// ComputeDistanceMatrix's stream, both directions: values [begin, end) (row-major) of a rows x
// cols matrix into one message, float32 or float64 (stats and progress are the caller's); and the
// messages, in order, back into the matrix.
void MatrixChunkToProto(size_t rows, size_t cols, const std::vector<double>& values, size_t begin,
                        size_t end, bool f32, v1::ComputeDistanceMatrixResponse* out);
class MatrixAssembler {
 public:
  using Message =
      v1::ComputeDistanceMatrixResponse;  // what it is fed, one stream message at a time
  void Add(const v1::ComputeDistanceMatrixResponse& message);
  DistanceMatrix& result() { return matrix_; }
  // Rows received, or rows' worth of solves done by the server's last progress, if more.
  size_t rows_done() const;

 private:
  DistanceMatrix matrix_;
  double progress_ = 0;
};

}  // namespace geodex::api
