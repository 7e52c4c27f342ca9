#include "geodex/geometry_queries.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "geodex/travel_cost.h"

namespace geodex {

namespace {

// IsolineFieldOptions over any mesh: `corner(f, k)` is face f's k-th corner position.
template <typename Corner>
GeodesicOptions IsolineFieldOptionsOf(size_t face_count, const Corner& corner,
                                      const GeodesicOptions& options,
                                      const IsolineOptions& levels) {
  if (levels.levels.empty()) return options;
  const double top = *std::max_element(levels.levels.begin(), levels.levels.end());
  if (!(top > 0) || !std::isfinite(top) || options.max_distance < top) return options;
  // The most a face's interior can add: its longest edge times its slowest pace (seconds per
  // metre with a travel cost: the face's weight over the slowest speed any direction in it has).
  double reach = 0;
  for (size_t f = 0; f < face_count; ++f) {
    const std::array<std::array<double, 3>, 3> p = {corner(f, 0), corner(f, 1), corner(f, 2)};
    double longest = 0;
    for (int k = 0; k < 3; ++k) {
      const std::array<double, 3>&a = p[k], &b = p[(k + 1) % 3];
      longest = std::max(longest, std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]));
    }
    double pace = 1;
    if (options.travel.has_value()) {
      const TravelCost& travel = *options.travel;
      const double weight = travel.face_weight != nullptr && f < travel.face_weight->size()
                                ? (*travel.face_weight)[f]
                                : 1.0;
      if (!std::isfinite(weight)) continue;  // impassable: no field inside
      // The face's slope (as FaceSlopesDeg: from the x-y plane), from its normal.
      const std::array<double, 3> u = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
      const std::array<double, 3> v = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
      const double nx = u[1] * v[2] - u[2] * v[1], ny = u[2] * v[0] - u[0] * v[2],
                   nz = u[0] * v[1] - u[1] * v[0];
      const double rise_over_run =
          nz != 0 ? std::hypot(nx, ny) / std::abs(nz) : std::numeric_limits<double>::infinity();
      const double slope_deg = std::atan(rise_over_run) * 180 / M_PI;
      if (travel.max_slope_deg > 0 && slope_deg > travel.max_slope_deg) continue;
      double slowest_kmh = travel.speed_kmh;
      if (travel.speed_model == SpeedModel::kTobler) {
        slowest_kmh = ToblerKmh(rise_over_run);  // straight up the steepest line
      } else if (travel.speed_model == SpeedModel::kTable && travel.speed_table != nullptr) {
        slowest_kmh = std::numeric_limits<double>::infinity();
        for (const auto& row : *travel.speed_table) slowest_kmh = std::min(slowest_kmh, row[1]);
      }
      if (!(slowest_kmh > 0)) continue;
      pace = weight * 3.6 / slowest_kmh;
    }
    reach = std::max(reach, longest * pace);
  }
  const double bound = options.travel.has_value() ? 1 + TravelEpsilon(*options.travel) : 1;
  // A little more than the bound, so that rounding never leaves a corner just past the limit.
  const double limit = (top + reach) * bound * (1 + 1e-9);
  GeodesicOptions out = options;
  // Options already made here (by a client from the same mesh, rounded differently) are kept, so
  // that the field asked twice is one field.
  if (!(std::abs(options.max_distance - limit) <= 1e-6 * limit)) out.max_distance = limit;
  return out;
}

}  // namespace

GeodesicOptions IsolineFieldOptions(const TriangleMesh& mesh, const GeodesicOptions& options,
                                    const IsolineOptions& levels) {
  return IsolineFieldOptionsOf(
      mesh.face_count(),
      [&](size_t f, int k) { return mesh.Position(mesh.FaceVertex(static_cast<uint32_t>(f), k)); },
      options, levels);
}

GeodesicOptions IsolineFieldOptions(const MeshData& mesh, const GeodesicOptions& options,
                                    const IsolineOptions& levels) {
  return IsolineFieldOptionsOf(
      mesh.face_count(),
      [&](size_t f, int k) {
        const size_t v = mesh.faces[3 * f + k];
        return std::array<double, 3>{mesh.positions[3 * v], mesh.positions[3 * v + 1],
                                     mesh.positions[3 * v + 2]};
      },
      options, levels);
}

absl::Status ValidateIsolineQuery(const IsolineQuery& query, uint64_t max_levels) {
  if (absl::Status s = ValidateGeodesicOptions(query.options); !s.ok()) return s;
  return ValidateIsolineOptions(query.levels, max_levels);
}

absl::StatusOr<Isolines> ComputeIsolines(const TriangleMesh& mesh, const IsolineQuery& query) {
  if (absl::Status s = ValidateIsolineQuery(query); !s.ok()) return s;
  absl::StatusOr<DistanceField> field = ComputeDistanceField(
      mesh, query.sources, IsolineFieldOptions(mesh, query.options, query.levels));
  if (!field.ok()) return field.status();
  return ExtractIsolines(mesh, *field, query.levels);
}

absl::StatusOr<VoronoiDiagram> ComputeVoronoi(const TriangleMesh& mesh, const VoronoiQuery& query) {
  absl::StatusOr<DistanceField> field = ComputeDistanceField(mesh, query.sites, query.options);
  if (!field.ok()) return field.status();
  return BuildVoronoi(mesh, *field,
                      query.options.travel.has_value() ? &*query.options.travel : nullptr);
}

absl::StatusOr<DelaunayTriangulation> ComputeDelaunay(const TriangleMesh& mesh,
                                                      const DelaunayQuery& query) {
  absl::StatusOr<DistanceField> field = ComputeDistanceField(mesh, query.sites, query.options);
  if (!field.ok()) return field.status();
  return BuildDelaunay(mesh, *field);
}

}  // namespace geodex
