#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/geodesic_solver.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"

namespace geodex {

// Exact distances between N sources and M targets (any surface points), row-major
// (values[i * cols + j] = d(sources[i], targets[j]); +inf where unreachable). One solve per
// distinct source, each stopping as soon as every target's distance is final, instead of N*M
// point-to-point queries.
struct DistanceMatrix {
  size_t rows = 0, cols = 0;
  std::vector<double> values;
  SolveStats stats;  // summed over the solves (solve_ms: total)
};

absl::StatusOr<DistanceMatrix> ComputeDistanceMatrix(const TriangleMesh& mesh,
                                                     const std::vector<SurfacePoint>& sources,
                                                     const std::vector<SurfacePoint>& targets,
                                                     const GeodesicOptions& options = {});

// Exact distances from the nearest of `sources` to each of `points`, with the nearest source's
// index: one multi-source solve that stops once every point's distance is final. `stats`, when
// given, receives the solve's counters.
absl::StatusOr<std::vector<std::pair<double, uint32_t>>> ComputeExactDistancesAt(
    const TriangleMesh& mesh, const std::vector<SurfacePoint>& sources,
    const std::vector<SurfacePoint>& points, const GeodesicOptions& options = {},
    SolveStats* stats = nullptr);

}  // namespace geodex
