#include "geodex/travel_cost.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "absl/strings/str_format.h"
#include "geodex/geodesic_solver.h"
#include "geodex/shortest_path.h"
#include "geodex/triangle_mesh.h"
#include "geodex/weighted_field.h"
#include "travel_queries.h"
#include "weighted_regions.h"

namespace geodex {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

SolveStats StatsOf(const WeightedStats& w) {
  SolveStats s;
  s.edge_relaxations = w.edge_relaxations;
  s.peak_bytes = w.peak_bytes;
  s.solve_ms = w.solve_ms;
  return s;
}

// Seconds per engine cost unit: a constant speed runs the engine in weighted metres; a
// slope-dependent one in seconds already (its SlopeCost is seconds per metre).
double SecondsPerUnit(const TravelCost& travel) {
  return IsDirectional(travel) ? 1.0 : 3.6 / travel.speed_kmh;
}

// Engine cost to seconds; +inf stays.
double Seconds(const TravelCost& travel, double cost) {
  return cost == kInf ? kInf : cost * SecondsPerUnit(travel);
}

// The speed (km/h) of a table at a slope in degrees; 0 beyond its slopes (cannot be walked).
double TableKmh(const std::vector<std::array<double, 2>>& table, double slope_deg) {
  if (slope_deg < table.front()[0] || slope_deg > table.back()[0]) return 0;
  auto hi = std::lower_bound(table.begin(), table.end(), slope_deg,
                             [](const std::array<double, 2>& row, double s) { return row[0] < s; });
  if (hi == table.begin()) return hi->at(1);
  const auto lo = hi - 1;
  const double t = (slope_deg - (*lo)[0]) / ((*hi)[0] - (*lo)[0]);
  return (*lo)[1] + t * ((*hi)[1] - (*lo)[1]);
}

// The engine's slope cost for a slope-dependent speed: seconds per 3D metre, sampled on the slope
// sine (weighted_field.h). 8193 samples: a step of 0.014 degrees at the level.
std::shared_ptr<const SlopeCost> SlopeCostOf(const TravelCost& travel) {
  constexpr int kSamples = 8193;
  auto cost = std::make_shared<SlopeCost>();
  cost->per_metre.resize(kSamples);
  for (int i = 0; i < kSamples; ++i) {
    cost->per_metre[i] = SecondsPerMetre(travel, -1 + 2.0 * i / (kSamples - 1), 1.0);
  }
  return cost;
}

}  // namespace

double ToblerKmh(double rise_over_run) {
  return 6 * std::exp(-3.5 * std::abs(rise_over_run + 0.05));
}

double SecondsPerMetre(const TravelCost& travel, double rise, double length) {
  if (travel.speed_model == SpeedModel::kConstant) return 3.6 / travel.speed_kmh;
  const double sine = length > 0 ? std::clamp(rise / length, -1.0, 1.0) : 0.0;
  double kmh = 0;
  if (travel.speed_model == SpeedModel::kTobler) {
    const double cosine = std::sqrt(std::max(0.0, 1 - sine * sine));
    kmh = cosine == 0 ? 0 : ToblerKmh(sine / cosine);
  } else if (travel.speed_table != nullptr) {
    kmh = TableKmh(*travel.speed_table, std::asin(sine) * 180 / M_PI);
  }
  return kmh > 0 ? 3.6 / kmh : kInf;
}

absl::Status ValidateTravelCost(const TravelCost& travel) {
  if (travel.speed_model == SpeedModel::kConstant) {
    if (!(travel.speed_kmh > 0) || !std::isfinite(travel.speed_kmh)) {
      return OptionError(
          "travel.speed_kmh",
          absl::StrFormat("must be > 0 and finite (km/h), got %g", travel.speed_kmh));
    }
  } else if (travel.speed_kmh != 0) {
    return OptionError("travel.speed_kmh",
                       absl::StrFormat("must be 0 with a slope-dependent speed (it sets the "
                                       "speed), got %g",
                                       travel.speed_kmh));
  }
  if (travel.speed_model == SpeedModel::kTable) {
    const auto* table = travel.speed_table.get();
    if (table == nullptr || table->size() < 2) {
      return OptionError("travel.speed_table",
                         absl::StrFormat("needs >= 2 rows (slope in degrees, km/h), got %d",
                                         table == nullptr ? 0 : table->size()));
    }
    for (size_t i = 0; i < table->size(); ++i) {
      const double slope = (*table)[i][0], kmh = (*table)[i][1];
      std::string problem;
      if (!(slope >= -90 && slope <= 90)) {
        problem = absl::StrFormat("slope %g is not in [-90, 90] degrees", slope);
      } else if (i > 0 && !(slope > (*table)[i - 1][0])) {
        problem =
            absl::StrFormat("slope %g does not increase (after %g)", slope, (*table)[i - 1][0]);
      } else if (!(kmh > 0) || !std::isfinite(kmh)) {
        problem = absl::StrFormat("speed %g km/h is not > 0 and finite", kmh);
      }
      if (!problem.empty())
        return OptionError(absl::StrFormat("travel.speed_table[%d]", i), problem);
    }
    if (!(table->front()[0] <= 0 && table->back()[0] >= 0)) {
      return OptionError(
          "travel.speed_table",
          absl::StrFormat("must cover slope 0 (the level; it covers %g to %g degrees)",
                          table->front()[0], table->back()[0]));
    }
  } else if (travel.speed_table != nullptr) {
    return OptionError("travel.speed_table", "is only read with the table speed model");
  }

  if (travel.epsilon.has_value() && !(*travel.epsilon > 0 && *travel.epsilon < 1)) {
    return OptionError("travel.epsilon",
                       absl::StrFormat("must be in (0, 1), got %g", *travel.epsilon));
  }
  if (!(travel.max_slope_deg >= 0 && travel.max_slope_deg <= 90)) {
    return OptionError(
        "travel.max_slope_deg",
        absl::StrFormat("must be in (0, 90] degrees (0: no limit), got %g", travel.max_slope_deg));
  }
  return absl::OkStatus();
}

std::vector<double> FaceSlopesDeg(const TriangleMesh& mesh) {
  std::vector<double> slope(mesh.face_count(), 0);
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    const std::array<double, 3> a = mesh.Position(mesh.FaceVertex(f, 0)),
                                b = mesh.Position(mesh.FaceVertex(f, 1)),
                                c = mesh.Position(mesh.FaceVertex(f, 2));
    const double ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
    const double vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
    const double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    const double horizontal = std::hypot(nx, ny);
    if (horizontal == 0 && nz == 0) continue;  // degenerate: no slope
    // The angle between the face and the x-y plane is the normal's angle from the z axis.
    slope[f] = std::atan2(horizontal, std::abs(nz)) * 180 / M_PI;
  }
  return slope;
}

absl::StatusOr<WeightedOptions> WeightedOptionsFor(const TriangleMesh& mesh,
                                                   const GeodesicOptions& options) {
  if (absl::Status s = ValidateGeodesicOptions(options); !s.ok()) return s;
  if (!options.travel.has_value()) {
    return absl::InvalidArgumentError("WeightedOptionsFor needs options with a travel cost");
  }
  const TravelCost& travel = *options.travel;
  WeightedOptions out;
  out.epsilon = TravelEpsilon(travel);
  out.max_steiner_points = travel.max_steiner_points;
  out.max_windows = options.max_windows;
  out.cancel = options.cancel;
  out.max_distance = options.max_distance / SecondsPerUnit(travel);
  if (IsDirectional(travel)) {
    out.slope_cost = SlopeCostOf(travel);
    out.inbound = travel.inbound;
  }
  if (travel.face_weight != nullptr) out.face_weight = *travel.face_weight;
  if (travel.max_slope_deg > 0 && travel.max_slope_deg < 90) {
    if (out.face_weight.empty()) out.face_weight.assign(mesh.face_count(), 1.0);
    if (out.face_weight.size() == mesh.face_count()) {  // else the engine names the count
      const std::vector<double> slope = FaceSlopesDeg(mesh);
      for (uint32_t f = 0; f < mesh.face_count(); ++f) {
        if (slope[f] > travel.max_slope_deg) out.face_weight[f] = kInf;
      }
    }
  }
  return out;
}

absl::StatusOr<DistanceField> ComputeTravelField(const TriangleMesh& mesh,
                                                 const std::vector<SurfacePoint>& sources,
                                                 const GeodesicOptions& options) {
  absl::StatusOr<WeightedOptions> weighted = WeightedOptionsFor(mesh, options);
  if (!weighted.ok()) return weighted.status();
  absl::StatusOr<WeightedField> w;
  if (RegionsServeFields(*weighted)) {
    absl::StatusOr<std::shared_ptr<const RegionSurface>> regions =
        RegionSurface::Build(mesh, *weighted, sources);
    if (!regions.ok()) return regions.status();
    w = (*regions)->Field(sources, {weighted->max_distance, weighted->cancel});
  } else {
    w = ComputeWeightedField(mesh, sources, *weighted);
  }
  if (!w.ok()) return w.status();
  DistanceField field;
  field.sources = sources;
  field.distance.resize(w->cost.size());
  for (size_t v = 0; v < w->cost.size(); ++v) {
    field.distance[v] = Seconds(*options.travel, w->cost[v]);
  }
  field.source = std::move(w->source);
  // Every internal copy of a split vertex takes its file vertex's time (the weighted engine
  // answers per file vertex): what isolines and Voronoi read.
  field.internal_distance.resize(mesh.vertex_count());
  field.internal_source.resize(mesh.vertex_count());
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    field.internal_distance[v] = field.distance[mesh.FileVertex(v)];
    field.internal_source[v] = field.source[mesh.FileVertex(v)];
  }
  field.stats = StatsOf(w->stats);
  field.travel_epsilon = TravelEpsilon(*options.travel);
  field.travel_exact = TravelIsExact(*options.travel);
  return field;
}

namespace {

// The caller's graph (TravelCost::graph) when it is the one `weighted` would build, else null.
std::shared_ptr<const WeightedSurface> SharedGraph(const TriangleMesh& mesh,
                                                   const GeodesicOptions& options,
                                                   const WeightedOptions& weighted) {
  const std::shared_ptr<const WeightedSurface>& graph = options.travel->graph;
  return graph != nullptr && graph->Serves(mesh, weighted) ? graph : nullptr;
}

}  // namespace

absl::StatusOr<std::shared_ptr<const WeightedSurface>> BuildTravelSurface(
    const TriangleMesh& mesh, const GeodesicOptions& options) {
  absl::StatusOr<WeightedOptions> weighted = WeightedOptionsFor(mesh, options);
  if (!weighted.ok()) return weighted.status();
  // Several weights: regions per query (built around its points); a slope speed: a graph per
  // query. Neither is shared.
  if (!RegionsServe(*weighted)) return nullptr;
  weighted->cancel = nullptr;  // the surface outlives the call that builds it
  absl::StatusOr<std::shared_ptr<const RegionSurface>> regions =
      RegionSurface::Build(mesh, *weighted);
  if (!regions.ok()) return regions.status();
  return std::make_shared<const WeightedSurface>(
      WeightedSurface::OnRegions(mesh, *std::move(weighted), *std::move(regions)));
}

bool TravelIsExact(const TravelCost& travel) {
  return !IsDirectional(travel) &&
         (travel.face_weight == nullptr || OneFiniteWeight(*travel.face_weight));
}

// The exact engine's surface is what is shared: the same condition as exactness.
bool SharesTravelSurface(const TravelCost& travel) { return TravelIsExact(travel); }

absl::StatusOr<TravelPointSolver> TravelPointSolver::Create(
    const TriangleMesh& mesh, const GeodesicOptions& options,
    const std::vector<SurfacePoint>& sources, const std::vector<SurfacePoint>& points) {
  absl::StatusOr<WeightedOptions> weighted = WeightedOptionsFor(mesh, options);
  if (!weighted.ok()) return weighted.status();
  const WeightedSurface::Limits limits{weighted->max_distance, weighted->cancel};
  // Several weights: regions built for these points, not a shared graph (the exact engine inside
  // each region answers a matrix in a fraction of the graph's search; SharesTravelSurface).
  const bool several = RegionsServeSeveralWeights(*weighted);
  if (!several) {
    if (std::shared_ptr<const WeightedSurface> shared = SharedGraph(mesh, options, *weighted)) {
      return TravelPointSolver(*options.travel, std::move(shared), nullptr, limits);
    }
  }
  if (RegionsServeFields(*weighted)) {
    std::vector<SurfacePoint> anchors = sources;
    anchors.insert(anchors.end(), points.begin(), points.end());
    absl::StatusOr<std::shared_ptr<const RegionSurface>> regions =
        RegionSurface::Build(mesh, *weighted, anchors);
    if (!regions.ok()) return regions.status();
    return TravelPointSolver(*options.travel, nullptr, *std::move(regions), limits);
  }
  absl::StatusOr<WeightedSurface> surface =
      WeightedSurface::Build(mesh, *weighted, sources, points);
  if (!surface.ok()) return surface.status();
  return TravelPointSolver(*options.travel,
                           std::make_shared<const WeightedSurface>(*std::move(surface)), nullptr,
                           limits);
}

absl::StatusOr<PointValues> TravelPointSolver::Solve(const std::vector<SurfacePoint>& sources,
                                                     const std::vector<SurfacePoint>& points,
                                                     bool covers_surface) const {
  WeightedSurface::Limits limits = limits_;
  limits.anchor_targets = !covers_surface;  // a raster's cells: refined around the sources only
  absl::StatusOr<WeightedCosts> w =
      regions_ != nullptr ? regions_->CostsAt(sources, points, covers_surface, limits)
                          : surface_->CostsAt(sources, points, covers_surface, limits);
  if (!w.ok()) return w.status();
  PointValues out;
  for (double c : w->cost) out.distance.push_back(Seconds(travel_, c));
  out.source = std::move(w->source);
  out.stats = StatsOf(w->stats);
  return out;
}

absl::StatusOr<PointValues> ComputeTravelPointValues(const TriangleMesh& mesh,
                                                     const PointQuery& query) {
  if (query.directions) {
    return OptionError("travel",
                       "geodesic directions are read off the exact engine; a travel cost has none");
  }
  absl::StatusOr<TravelPointSolver> solver =
      TravelPointSolver::Create(mesh, query.options, query.sources,
                                query.covers_surface ? std::vector<SurfacePoint>{} : query.points);
  if (!solver.ok()) return solver.status();
  return solver->Solve(query.sources, query.points, query.covers_surface);
}

absl::StatusOr<PathsQueryResult> ComputeTravelPaths(const TriangleMesh& mesh,
                                                    const SurfacePoint& from,
                                                    const std::vector<SurfacePoint>& tos,
                                                    const GeodesicOptions& options) {
  if (options.travel.has_value() && options.travel->inbound) {
    return OptionError("travel.inbound",
                       "a path is walked from its start to its end (swap them for the way back)");
  }
  absl::StatusOr<WeightedOptions> weighted = WeightedOptionsFor(mesh, options);
  if (!weighted.ok()) return weighted.status();
  const WeightedSurface::Limits limits{weighted->max_distance, weighted->cancel};
  absl::StatusOr<std::vector<WeightedPath>> paths;
  // A constant speed: the regions, as for fields, so a path's time is the field's at its end
  // (one weight: the exact engine's surface, shared when the caller has it; several: the regions
  // built around the path's ends). A slope speed: the graph.
  const bool several = RegionsServeSeveralWeights(*weighted);
  const std::shared_ptr<const WeightedSurface> shared =
      several ? nullptr : SharedGraph(mesh, options, *weighted);
  if (shared != nullptr) {
    paths = shared->Paths(from, tos, limits);
  } else if (RegionsServeFields(*weighted)) {
    std::vector<SurfacePoint> anchors = tos;
    anchors.push_back(from);
    absl::StatusOr<std::shared_ptr<const RegionSurface>> regions =
        RegionSurface::Build(mesh, *weighted, anchors);
    if (!regions.ok()) return regions.status();
    paths = (*regions)->Paths(from, tos, limits);
  } else {
    paths = ComputeWeightedPaths(mesh, from, tos, *weighted);
  }
  if (!paths.ok()) return paths.status();
  PathsQueryResult out;
  out.distance.assign(tos.size(), kUnreachable);
  out.paths.resize(tos.size());
  for (size_t i = 0; i < tos.size(); ++i) {
    WeightedPath& path = (*paths)[i];
    if (!std::isfinite(path.cost)) continue;  // unreachable: inf, no points
    out.distance[i] = Seconds(*options.travel, path.cost);
    // The path's length stays a length (metres along the polyline); its time is the distance.
    double length = 0;
    for (size_t k = 1; k < path.points.size(); ++k) {
      const auto& a = path.points[k - 1].position;
      const auto& b = path.points[k].position;
      length += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                          (a[2] - b[2]) * (a[2] - b[2]));
    }
    out.paths[i].length = length;
    out.paths[i].source = 0;
    out.paths[i].points = std::move(path.points);
  }
  if (!paths->empty()) out.stats = StatsOf((*paths)[0].stats);  // one search for every target
  return out;
}

}  // namespace geodex
