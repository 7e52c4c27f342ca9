#pragma once

// Dijkstra on the edge graph: the baseline for tests and benchmarks, and what lambda = 1
// reproduces.

#include <vector>

#include "absl/status/status.h"
#include "geodex/distance_field.h"
#include "geodex/geodesic_solver.h"
#include "geodex/triangle_mesh.h"

namespace geodex {

struct VertexSeed {
  uint32_t vertex;  // internal id
  double distance;  // initial distance (0 for a vertex source; straight-line for a point source)
  uint32_t label;
};

// Fills out->internal_* and stats. Honors options.max_distance and options.cancel.
absl::Status RunDijkstra(const TriangleMesh& mesh, const std::vector<VertexSeed>& seeds,
                         const GeodesicOptions& options, DistanceField* out);

}  // namespace geodex
