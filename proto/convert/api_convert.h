#pragma once

// Plain conversions between geodex.v1 messages and core types, used by both sides of the API (the
// server's validating conversions are in server/proto_convert.h). No validation here: a proto
// point with nothing set (or a map point, which only a DEM can place) becomes a vertex 0.

#include <array>

#include "geodex/distance_field.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "geodex/terrain.h"
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

// A DEM mesh's map (Mesh.terrain), both directions. A Terrain without 6 geotransform values
// gives zeros (FromMesh then refuses it).
void TerrainToProto(const terrain::DemInfo& info, v1::Terrain* out);
terrain::DemInfo TerrainFromProto(const v1::Terrain& terrain);

// The request's solver options: lambda, its scale and max_distance (the server's conversion back,
// with validation and its window limit, is server/proto_convert.h's SolverOptionsFromProto).
void SolverOptionsToProto(const GeodesicOptions& options, v1::SolverOptions* out);

// EstimateDistances' exact part, carried whole: the query into the request (its sources, points
// and options; the mode is the caller's), and the answer into the response and back. The server
// places the request's points itself (map points, limits), so no PointQueryFromProto.
void PointQueryToProto(const PointQuery& query, v1::EstimateDistancesRequest* out);
void PointValuesToProto(const PointValues& values, v1::EstimateDistancesResponse* out);
PointValues PointValuesFromProto(const v1::EstimateDistancesResponse& response);

}  // namespace geodex::api
