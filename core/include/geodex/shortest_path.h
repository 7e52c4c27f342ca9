#pragma once

#include <array>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/geodesic_solver.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"

namespace geodex {

// One point of a geodesic polyline: where it is (file coordinates) and the simplex it lies on
// (a vertex, an edge point with its parameter, or a face point with barycentrics).
struct PathPoint {
  std::array<double, 3> position{};
  SurfacePoint where;
};

// A geodesic from a query point back to its nearest source: points[0] is the query point, the last
// point is on the source. The polyline is straight inside every face it crosses and bends only at
// saddle or boundary vertices (or runs along an edge where the field came from edge relaxation,
// as with lambda > 0 or Dijkstra).
struct GeodesicPath {
  double length = 0;
  uint32_t source = 0xffffffffu;  // index into the solve's source list
  std::vector<PathPoint> points;
};

// Backtraces the exact shortest path from vertex `vertex` (a file vertex id) to its nearest
// source in `field`, using the per-vertex origins the solver keeps (no windows are needed).
// Errors: InvalidArgument for an unknown vertex, NotFound when the vertex is unreachable.
absl::StatusOr<GeodesicPath> TracePathFromVertex(const TriangleMesh& mesh,
                                                 const DistanceField& field, uint32_t vertex);

// The geodesic direction field a robot controller follows (as mesh_navigation's vector-field
// planners consume it): per file vertex, the unit tangent, in file coordinates, of its shortest
// path towards its nearest source, i.e. the direction of the first step of the path
// TracePathFromVertex returns. (0, 0, 0) at a source vertex; NaN components where the direction
// is undefined (an unreachable vertex). Exact: read off the per-vertex origins, O(V).
std::vector<std::array<double, 3>> ComputeDirectionField(const TriangleMesh& mesh,
                                                         const DistanceField& field);

// A distance field asked whole: what `geodex distances` and ComputeDistanceField ask. The CLI
// hands it to either backend as it is and proto/convert carries it (api::FieldQueryToProto), so a
// new per-vertex product is a member here, its computation in ComputeFieldProducts, and its wire
// fields in proto/convert.
struct FieldQuery {
  std::vector<SurfacePoint> sources;
  GeodesicOptions options;
  bool directions = false;  // DistanceField::direction (ComputeDirectionField)
};

// The per-vertex products `query` asks for beyond distances and labels, from its solved `field`,
// written to `out`'s product members only (`out` may be `field` itself, or another DistanceField
// so that a shared, cached field stays untouched). Members already filled are kept.
// InvalidArgument naming "travel" for directions on a travel-cost field (it has no origins).
absl::Status ComputeFieldProducts(const TriangleMesh& mesh, const DistanceField& field,
                                  const FieldQuery& query, DistanceField* out);

}  // namespace geodex

namespace geodex {

struct PathQueryOptions {
  GeodesicOptions solver;  // lambda, budget, cancel token, ... (max_distance is honoured)
  // Single source, single target (paper section 5): windows are ordered by
  // sigma + min over the interval of (|I p| + |p t|), a lower bound of any path through them, and
  // the solve stops once the smallest key reaches the target's distance. Exact either way.
  bool use_heuristic = true;
  // Solve the whole field first (no early stop), then trace: the baseline for benchmarks.
  bool full_field = false;
};

// Why `to` is unreachable from `from`, in words for an error ("it is on another part of the
// surface (...)"): a vertex no face uses, a point on another part of the surface (split off by a
// barrier or a hole, or a separate piece of the mesh), or beyond the max_distance limit.
std::string UnreachableReason(const TriangleMesh& mesh, const SurfacePoint& from,
                              const SurfacePoint& to, double max_distance);

struct PathQueryResult {
  double distance = kUnreachable;
  GeodesicPath path;  // from `from` to `to`
  SolveStats stats;
  // geodexd's answers only (the client library): how far each point given as a 3D position
  // (SurfacePoint::kPosition) moved onto the surface, `from`'s then `to`'s; 0 for a point given on
  // the surface. Core's own queries take surface points and leave it empty.
  std::vector<double> snap_distances;
};

// The exact shortest path between two surface points, with its length.
// Errors: InvalidArgument (bad point), NotFound (`to` unreachable from `from`), Cancelled,
// ResourceExhausted.
absl::StatusOr<PathQueryResult> ComputeShortestPath(const TriangleMesh& mesh,
                                                    const SurfacePoint& from,
                                                    const SurfacePoint& to,
                                                    const PathQueryOptions& options = {});

// The same, asked whole: what `geodex path` and FindShortestPath ask. The CLI hands it to either
// backend as it is and proto/convert carries it (api::PathQueryToProto).
struct PathQuery {
  SurfacePoint from, to;
  PathQueryOptions options;
};
absl::StatusOr<PathQueryResult> ComputeShortestPath(const TriangleMesh& mesh,
                                                    const PathQuery& query);

// Paths from one point to several: one targeted solve (A* towards the targets when they are close
// together, stopping once every target is final), then one trace per target.
struct PathsQueryResult {
  std::vector<double> distance;     // per target; kUnreachable when it cannot be reached
  std::vector<GeodesicPath> paths;  // per target, from `from`; empty when unreachable
  SolveStats stats;                 // of the one solve
};
absl::StatusOr<PathsQueryResult> ComputeShortestPaths(const TriangleMesh& mesh,
                                                      const SurfacePoint& from,
                                                      const std::vector<SurfacePoint>& tos,
                                                      const PathQueryOptions& options = {});

}  // namespace geodex
