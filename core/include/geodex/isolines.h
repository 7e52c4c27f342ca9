#pragma once

// Approximate geodesic offsets (isolines) of a finished distance field, paper section 6.1.
//
// APPROXIMATE BY DESIGN: the distance is taken to vary linearly along every edge between its two
// vertex values (which are exact), so an isoline crosses each face as one straight segment between
// two edge points. On a fine, evenly triangulated mesh the error is a small fraction of the edge
// length (about h^2 / (8 r) at distance r on a flat mesh with edges of length h); it is not an
// exact level set of the geodesic distance. One pass over the faces for all levels: O(faces +
// points produced).

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/shortest_path.h"
#include "geodex/triangle_mesh.h"

namespace geodex {

struct IsolineOptions {
  // Explicit levels (any order; sorted and deduplicated). Levels at or below the smallest vertex
  // distance, or at or above the largest finite one, give no polyline.
  std::vector<double> levels;
  // Used when `levels` is empty: the K - 1 levels D * j / K, j = 1..K-1, with D the largest finite
  // vertex distance (the paper's family without j = K, which would be the single farthest
  // point). Must be >= 2 then.
  int count = 0;
};

// One approximate isoline. Every point lies on a mesh edge: `where` is SurfacePoint::kEdge with
// file vertex ids, edge_from the endpoint below the level (d < level), edge_to the endpoint at or
// above it (d >= level), and the point is (1 - t) * from + t * to; `position` is in file
// coordinates. Levels equal to vertex values: the comparison d >= level counts such a vertex as
// above (a consistent perturbation), so the isoline passes through the vertex itself (t = 1);
// parameters within 1e-12 of 0 or 1 snap to the vertex (t = 0 or 1 exactly), and consecutive
// points at the same vertex are merged into one, so a level at (or within round-off of) vertex
// values gives no duplicate points. A loop that collapses onto a single vertex (a local maximum
// exactly at the level) gives no polyline. Polylines are oriented with the lower distances (the
// sources) on their left, seen from the side the faces' normals point to.
struct IsolinePolyline {
  double level = 0;
  bool closed = false;  // a loop; the first point is not repeated at the end
  std::vector<PathPoint> points;
};

struct Isolines {
  std::vector<double> levels;              // the levels used, ascending
  std::vector<IsolinePolyline> polylines;  // grouped by ascending level
};

// The one check of isoline options, made by ExtractIsolines and, before any work, by the CLI and
// geodexd: levels finite, or else a count >= 2; at most `max_levels` levels either way (count - 1
// levels for a count). Errors name the option for InvalidOptionOf (geodesic_solver.h): "levels[I]"
// or "count", InvalidArgument for a bad value, ResourceExhausted over `max_levels` ("levels" or
// "count"), each front end spelling it its own way (--levels, --count, levels[3]).
absl::Status ValidateIsolineOptions(const IsolineOptions& options,
                                    uint64_t max_levels = UINT64_MAX);

// Extracts the isolines of `field` (computed on `mesh`). Faces with an unreachable vertex are
// skipped, so an isoline that meets unreachable territory is an open polyline; on a closed mesh
// every polyline is closed (paper, Theorem 3). Errors: InvalidArgument when the field does not
// belong to the mesh, a level is NaN or infinite, or neither levels nor a count >= 2 are given.
absl::StatusOr<Isolines> ExtractIsolines(const TriangleMesh& mesh, const DistanceField& field,
                                         const IsolineOptions& options);

}  // namespace geodex
