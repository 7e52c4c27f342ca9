#pragma once

// Travel time instead of length (docs/travel.md): a query whose GeodesicOptions carry a TravelCost
// is answered by the weighted engine (weighted_field.h) in SECONDS: a straight piece inside face f
// takes its 3D length x w(f) / v. Every product built on a distance field (values at vertices and
// points, paths, matrices, isolines, Voronoi regions) then speaks seconds, and max_distance is a
// time too. Approximate with a stated bound: every time is at least the true least time and at
// most (1 + epsilon) times it. Direction-independent (part 1 of the travel-cost work): times from
// the sources outward equal times towards them.
//
// Not available with a travel cost (InvalidArgument naming "travel"): the exact-only products
// read off the exact engine's per-vertex origins (geodesic directions, the geodesic Delaunay
// triangulation), lambda > 0 and the Dijkstra method.

#include <cstdint>
#include <memory>
#include <vector>

#include "absl/status/status.h"

namespace geodex {

class TriangleMesh;

struct TravelCost {
  // v, the speed on a face of weight 1 (km/h). > 0 and finite.
  double speed_kmh = 0;
  // The stated bound, in (0, 1): the answer is within (1 + epsilon) of the least time.
  double epsilon = 0.01;
  // Faces steeper than this (degrees from the horizontal x-y plane, z up) are impassable: a cliff
  // is not climbed. 0: no limit; else in (0, 90].
  double max_slope_deg = 0;
  // One multiplicative weight (friction) per face, as ArcGIS's cost rasters: > 0, +inf impassable.
  // Null: every face weighs 1. Shared, so copying options does not copy the weights.
  std::shared_ptr<const std::vector<double>> face_weight;
  // 0 = unlimited; else a solve needing more Steiner points fails with ResourceExhausted
  // (Limit::kSteinerPoints) before allocating them.
  uint64_t max_steiner_points = 0;
};

// The one check of a travel cost's own values (speed, epsilon, slope); the weights are checked
// against the mesh by the engine. Errors name "travel.speed_kmh", "travel.epsilon",
// "travel.max_slope_deg" (InvalidOptionOf).
absl::Status ValidateTravelCost(const TravelCost& travel);

// Seconds per metre on a face of weight 1.
inline double SecondsPerMetre(const TravelCost& travel) { return 3.6 / travel.speed_kmh; }

// The slope of each face in degrees from the x-y plane (0 flat, 90 vertical; 0 for a degenerate
// face): what max_slope_deg compares.
std::vector<double> FaceSlopesDeg(const TriangleMesh& mesh);

}  // namespace geodex
