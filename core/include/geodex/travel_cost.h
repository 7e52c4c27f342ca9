#pragma once

// Travel time instead of length (docs/travel.md): a query whose GeodesicOptions carry a TravelCost
// is answered in SECONDS: a straight piece inside face f takes its 3D length x w(f) / v. At a
// constant speed, by the exact engine inside regions of one weight (weighted_regions.h: every
// product with one weight; fields with several, joined at the graph's boundary points), else by
// the weighted engine's graph (weighted_field.h). Every product built on a distance field (values
// at vertices and points, paths, matrices, isolines, Voronoi regions) then speaks seconds, and
// max_distance is a time too. Approximate with a stated bound: every time is at least the true
// least time and at most (1 + epsilon) times it.
//
// The speed is constant (times are direction-independent: from the sources equals towards them)
// or depends on the slope along the direction of travel (Tobler's hiking function or a table): a
// walker zigzags up and down steep faces where that is quicker (switchbacks), times from the
// sources differ from times towards them (`inbound`), and no bound is proved: epsilon then only
// sets the density of the engine's Steiner points (docs/travel.md states the measured error).
//
// Not available with a travel cost (InvalidArgument naming "travel"): the exact-only products
// read off the exact engine's per-vertex origins (geodesic directions, the geodesic Delaunay
// triangulation), lambda > 0 and the Dijkstra method.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace geodex {

class TriangleMesh;
class WeightedSurface;
struct GeodesicOptions;

enum class SpeedModel {
  kConstant,  // speed_kmh everywhere
  kTobler,    // Tobler (1993): 6 exp(-3.5 |s + 0.05|) km/h, s = rise / run along the travel
  kTable,     // speed_table, linear between its slopes; steeper slopes cannot be walked
};

struct TravelCost {
  SpeedModel speed_model = SpeedModel::kConstant;
  // kConstant: v, the speed on a face of weight 1 (km/h), > 0 and finite. Otherwise 0.
  double speed_kmh = 0;
  // kTable: rows (slope in degrees, speed in km/h on weight 1): >= 2 rows, slopes in [-90, 90],
  // strictly increasing, the first <= 0 <= the last; speeds > 0 and finite. Shared.
  std::shared_ptr<const std::vector<std::array<double, 2>>> speed_table;
  // With a slope-dependent speed: times to REACH the sources (a walker ends there) instead of
  // times from them. Paths are always walked from their start.
  bool inbound = false;
  // In (0, 1). A constant speed: the stated bound, every time within (1 + epsilon) of the least
  // time. A slope-dependent speed: the Steiner points' spacing (no bound; docs/travel.md). Unset:
  // the speed model's default, TravelEpsilon.
  std::optional<double> epsilon;
  // Faces steeper than this (degrees from the horizontal x-y plane, z up) are impassable: a cliff
  // is not climbed. 0: no limit; else in (0, 90].
  double max_slope_deg = 0;
  // One multiplicative weight (friction) per face, as ArcGIS's cost rasters: > 0, +inf impassable.
  // Null: every face weighs 1. Shared, so copying options does not copy the weights.
  std::shared_ptr<const std::vector<double>> face_weight;
  // 0 = unlimited; else a solve needing more Steiner points fails with ResourceExhausted
  // (Limit::kSteinerPoints) before allocating them.
  uint64_t max_steiner_points = 0;
  // The weighted engine's graph for this mesh and these options, built once (BuildTravelSurface)
  // and shared by many queries: paths, times at points and matrices then skip building their own.
  // It is used only where it is the graph they would build (WeightedSurface::Serves: the same mesh
  // object, epsilon and weights), so a stale one costs a build, never a wrong answer. Not part of
  // the cost: caches key on the fields above.
  std::shared_ptr<const WeightedSurface> graph;
};

// The one check of a travel cost's own values (speed model, speed, table, epsilon, slope); the
// weights are checked against the mesh by the engine. Errors name "travel.speed_kmh",
// "travel.speed_table", "travel.speed_table[3]", "travel.epsilon", "travel.max_slope_deg"
// (InvalidOptionOf).
absl::Status ValidateTravelCost(const TravelCost& travel);

// True when times depend on the direction of travel (a slope-dependent speed).
inline bool IsDirectional(const TravelCost& travel) {
  return travel.speed_model != SpeedModel::kConstant;
}

// The epsilon a solve uses: the one set, else the speed model's default. 0.01 for a constant speed
// (a 1% bound); 0.125 (7 points per edge) for a slope-dependent speed, whose error falls as the
// spacing squared, the points graded denser near the sources (within 0.7% of the finest run on
// rough terrain, in about 5x the exact field's time, where 0.01 takes some 30 times longer;
// docs/performance.md).
inline constexpr double kConstantSpeedEpsilon = 0.01;
inline constexpr double kSlopeSpeedEpsilon = 0.125;
inline double TravelEpsilon(const TravelCost& travel) {
  if (travel.epsilon.has_value()) return *travel.epsilon;
  return IsDirectional(travel) ? kSlopeSpeedEpsilon : kConstantSpeedEpsilon;
}

// Whether times are to reach the sources: inbound, and only for a direction-dependent speed (a
// constant speed takes the same time both ways, so its inbound field is the outbound one).
inline bool TimesInbound(const TravelCost& travel) {
  return travel.inbound && IsDirectional(travel);
}

// Whether answers under `travel` are exact: a constant speed with one finite weight (any
// --max-slope) is answered by the exact engine on the passable faces, so its times are the least
// times, not within a bound. Such answers say exact, with epsilon 0 (StatedTravelEpsilon).
bool TravelIsExact(const TravelCost& travel);
// The epsilon an answer states: 0 when exact, else TravelEpsilon (a constant speed's bound, a
// slope speed's spacing).
inline double StatedTravelEpsilon(const TravelCost& travel) {
  return TravelIsExact(travel) ? 0 : TravelEpsilon(travel);
}

// The model's name in answers: "constant", "tobler" or "table".
inline const char* SpeedModelName(SpeedModel model) {
  switch (model) {
    case SpeedModel::kConstant:
      return "constant";
    case SpeedModel::kTobler:
      return "tobler";
    case SpeedModel::kTable:
      return "table";
  }
  return "constant";
}

// The surface a constant-speed travel cost with one weight (every passable face the same) answers
// paths, times at points and matrices on `mesh` from, to be shared through TravelCost::graph
// (geodexd keeps them in its result cache): the exact engine's surface of the passable faces
// (WeightedSurface::OnRegions, no Steiner points), which takes any point. `mesh` must outlive it.
// Null where nothing is shared (SharesTravelSurface): several weights run on regions built around
// each query's points, a slope-dependent speed on a graph that follows each query's sources.
// Errors: as the queries' (the options).
absl::StatusOr<std::shared_ptr<const WeightedSurface>> BuildTravelSurface(
    const TriangleMesh& mesh, const GeodesicOptions& options);

// Whether paths, times at points and matrices under `travel` read a surface shared through
// TravelCost::graph: a constant speed with one weight (the exact engine's surface, which takes any
// point). With several weights they run on regions built for their own points (docs/engine.md
// "Several weights by regions"), the fields' engine, so a path's time is the field's at its end; a
// slope-dependent speed builds its own graph per query. Reads the face weights only (a
// --max-slope leaving one weight is still counted as several: that only forgoes sharing).
bool SharesTravelSurface(const TravelCost& travel);

// Tobler's hiking function: km/h at s = rise / run along the direction of travel.
double ToblerKmh(double rise_over_run);

// Seconds per metre along a straight segment of 3D `length` rising `rise` (z up; < 0 downhill)
// on a face of weight 1, as the engine times it: 3.6 / speed_kmh, or the slope-dependent speed at
// the segment's slope; +inf where the model cannot walk it. What converts metres along an edge to
// a field's seconds (the Voronoi boundary on an edge).
double SecondsPerMetre(const TravelCost& travel, double rise, double length);

// The slope of each face in degrees from the x-y plane (0 flat, 90 vertical; 0 for a degenerate
// face): what max_slope_deg compares.
std::vector<double> FaceSlopesDeg(const TriangleMesh& mesh);

}  // namespace geodex
