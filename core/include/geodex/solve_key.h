#pragma once

// The key of a solve's answer: one rule for every cache of answers (geodexd's result cache, the
// CLI's field reuse). It holds every source bit for bit and every option that changes the answer:
// the method, lambda and its scale, max_distance, the engine switches, and the travel cost (speed
// model, speed, table rows, direction, epsilon, slope limit, and the face weights by their
// SHA-256). Limits (max_windows, max_steiner_points) and the cancel token are left out: they
// decide whether a solve finishes, never what it answers. Binary, not for display.

#include <string>
#include <vector>

#include "geodex/geodesic_solver.h"
#include "geodex/surface_point.h"

namespace geodex {

std::string SolveKey(const std::vector<SurfacePoint>& sources, const GeodesicOptions& options);

// The travel cost's part of SolveKey alone (no travel: one marker byte): what a travel graph,
// built for a cost and no sources, is keyed by.
std::string TravelCostKey(const GeodesicOptions& options);

}  // namespace geodex
