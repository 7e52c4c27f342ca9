#pragma once

// The approximate geometry of paper section 6 asked whole, like FieldQuery (shortest_path.h): the
// sources (sites), the solver options of their distance field (lambda, max_distance, ...) and the
// product's own options. The CLI hands a query to either backend unchanged, proto/convert carries
// it (api::IsolineQueryToProto, ...) and geodexd reads it back, so an option added here reaches
// every front end through those three places. Approximate by design (docs/geometry.md).

#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "geodex/delaunay.h"
#include "geodex/geodesic_solver.h"
#include "geodex/isolines.h"
#include "geodex/mesh_data.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"
#include "geodex/voronoi.h"

namespace geodex {

struct IsolineQuery {
  std::vector<SurfacePoint> sources;
  GeodesicOptions options;  // of the field the isolines are drawn on
  IsolineOptions levels;
};

struct VoronoiQuery {
  std::vector<SurfacePoint> sites;
  GeodesicOptions options;
};

struct DelaunayQuery {
  std::vector<SurfacePoint> sites;
  GeodesicOptions options;
};

// The one check of a geometry query's options, before any work: the solver options
// (ValidateGeodesicOptions) and, for isolines, the levels (ValidateIsolineOptions with
// `max_levels`). Errors name the option (InvalidOptionOf).
absl::Status ValidateIsolineQuery(const IsolineQuery& query, uint64_t max_levels = UINT64_MAX);

// The options of the field an isoline query draws on. With explicit levels and no max_distance
// below the top level, the solve stops just past the top level: at (top + the most any one face
// can add across itself, from its longest edge at its slowest pace) x (1 + the travel bound), so
// every face holding a point within the top level has all its corners solved and no polygon is
// cut, however large max_distance is (isochrones used to solve the whole DEM, or be cut by a
// max_distance equal to their top). A max_distance below the top level cuts there, as asked; a
// `count` family (its top is the largest distance) keeps the options. Every front end (CLI,
// geodexd's isolines and isochrones) solves with these.
GeodesicOptions IsolineFieldOptions(const TriangleMesh& mesh, const GeodesicOptions& options,
                                    const IsolineOptions& levels);
// The same from the mesh as read (a client without the built mesh): the same limit up to
// rounding, which the TriangleMesh form then keeps as it is.
GeodesicOptions IsolineFieldOptions(const MeshData& mesh, const GeodesicOptions& options,
                                    const IsolineOptions& levels);

// Solve the field, then derive the product from it. Errors: those of ComputeDistanceField and of
// the validation above.
absl::StatusOr<Isolines> ComputeIsolines(const TriangleMesh& mesh, const IsolineQuery& query);
absl::StatusOr<VoronoiDiagram> ComputeVoronoi(const TriangleMesh& mesh, const VoronoiQuery& query);
absl::StatusOr<DelaunayTriangulation> ComputeDelaunay(const TriangleMesh& mesh,
                                                      const DelaunayQuery& query);

}  // namespace geodex
