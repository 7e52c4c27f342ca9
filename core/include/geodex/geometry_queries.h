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

// Solve the field, then derive the product from it. Errors: those of ComputeDistanceField and of
// the validation above.
absl::StatusOr<Isolines> ComputeIsolines(const TriangleMesh& mesh, const IsolineQuery& query);
absl::StatusOr<VoronoiDiagram> ComputeVoronoi(const TriangleMesh& mesh, const VoronoiQuery& query);
absl::StatusOr<DelaunayTriangulation> ComputeDelaunay(const TriangleMesh& mesh,
                                                      const DelaunayQuery& query);

}  // namespace geodex
