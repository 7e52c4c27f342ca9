// Map points on a DEM (geodex/terrain.h): map coordinates in the DEM's CRS, WGS 84 longitudes and
// latitudes, and mesh coordinates dropped onto its surface (with where the DEM is when they miss
// it, and whether x and y were swapped), the grid test and the DEM's extent in WGS 84.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "dem_internal.h"
#include "gdal_quiet.h"
#include "geodex/terrain.h"
#include "ogr_spatialref.h"

namespace geodex::terrain {

using dem_internal::FileMeshTransform;
using dem_internal::LongitudesToGrid;
using dem_internal::MakeTransform;
using dem_internal::Shortest;
using dem_internal::TransformPtr;

namespace {

// WGS 84 longitude/latitude to the DEM file's CRS (from_wgs84), or back.
TransformPtr Wgs84Transform(const DemInfo& info, bool from_wgs84) {
  OGRSpatialReference wgs84, file_crs;
  wgs84.SetWellKnownGeogCS("WGS84");
  wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  file_crs.importFromWkt(info.file_crs_wkt.c_str());
  file_crs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return from_wgs84 ? MakeTransform(wgs84, file_crs) : MakeTransform(file_crs, wgs84);
}

bool OutsideTheDem(const absl::Status& status) {
  return absl::IsInvalidArgument(status) && absl::EndsWith(status.message(), ": outside the DEM");
}
}  // namespace

bool Dem::InGrid(double x, double y) const {
  const std::array<double, 6>& gt = info_.geotransform;
  const double u = (x - gt[0]) / gt[1] - 0.5, v = (y - gt[3]) / gt[5] - 0.5;
  return u >= 0 && v >= 0 && u <= info_.grid_width - 1.0 && v <= info_.grid_height - 1.0;
}

absl::StatusOr<std::array<double, 4>> Dem::LonLatExtent() const {
  QuietGdal quiet;
  TransformPtr t = Wgs84Transform(info_, /*from_wgs84=*/false);
  if (t == nullptr) return absl::InternalError("the DEM's CRS does not project to WGS 84");
  // The used cells' centres around the grid's edge (a projection bends straight lines).
  const std::array<double, 6>& gt = info_.geotransform;
  std::array<double, 4> box = {
      std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
      -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  const uint32_t W = info_.grid_width, H = info_.grid_height;
  for (int k = 0; k <= 64; ++k) {
    const double f = k / 64.0;
    for (auto [u, v] : {std::pair{f * (W - 1), 0.0}, std::pair{f * (W - 1), H - 1.0},
                        std::pair{0.0, f * (H - 1)}, std::pair{W - 1.0, f * (H - 1)}}) {
      double x = gt[0] + (u + 0.5) * gt[1], y = gt[3] + (v + 0.5) * gt[5];
      if (!t->Transform(1, &x, &y)) continue;
      box = {std::min(box[0], x), std::min(box[1], y), std::max(box[2], x), std::max(box[3], y)};
    }
  }
  return box;
}

absl::StatusOr<SurfacePoint> Dem::DropMapPoint(double x, double y) const {
  absl::StatusOr<SurfacePoint> p =
      DropNamed(x, y, absl::StrCat("g:", Shortest(x), ":", Shortest(y)));
  if (!OutsideTheDem(p.status())) return p;
  // Where the DEM is, in the same coordinates, and whether x and y were given the other way round.
  const std::array<double, 6>& gt = info_.geotransform;
  const double x0 = gt[0] + 0.5 * gt[1], x1 = gt[0] + (info_.grid_width - 0.5) * gt[1];
  const double y0 = gt[3] + 0.5 * gt[5], y1 = gt[3] + (info_.grid_height - 0.5) * gt[5];
  std::string message = absl::StrFormat("%s (it covers x %.10g to %.10g, y %.10g to %.10g in %s)",
                                        p.status().message(), std::min(x0, x1), std::max(x0, x1),
                                        std::min(y0, y1), std::max(y0, y1), info_.file_crs_name);
  if (InGrid(y, x))
    absl::StrAppend(&message, "; g:", Shortest(y), ":", Shortest(x),
                    " would be inside (x and y swapped?)");
  return absl::InvalidArgumentError(message);
}

absl::StatusOr<SurfacePoint> Dem::DropNamed(double x, double y, const std::string& name) const {
  const std::array<double, 6>& gt = info_.geotransform;
  const double u = (x - gt[0]) / gt[1] - 0.5, v = (y - gt[3]) / gt[5] - 0.5;
  double mx = x * info_.horizontal_scale, my = y * info_.horizontal_scale;
  if (info_.reprojected) {
    QuietGdal quiet;
    TransformPtr t = FileMeshTransform(info_, /*to_mesh=*/true);
    if (t == nullptr || !t->Transform(1, &mx, &my)) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": cannot project it (", QuietGdal::LastMessage(), ")"));
    }
  }
  return DropMeshPoint(mx, my, u, v, name);
}

absl::StatusOr<SurfacePoint> Dem::DropLonLat(double lon, double lat) const {
  const std::string name = absl::StrCat("ll:", Shortest(lon), ":", Shortest(lat));
  if (!(std::abs(lon) <= 180 && std::abs(lat) <= 90)) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": longitude must be in [-180, 180] and latitude in [-90, 90]"));
  }
  QuietGdal quiet;
  TransformPtr t = Wgs84Transform(info_, /*from_wgs84=*/true);
  double x = lon, y = lat;
  if (t == nullptr || !t->Transform(1, &x, &y)) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": cannot project it to the DEM's CRS (",
                                                   QuietGdal::LastMessage(), ")"));
  }
  LongitudesToGrid(info_, &x, 1);
  absl::StatusOr<SurfacePoint> p = DropNamed(x, y, name);
  if (!OutsideTheDem(p.status())) return p;
  std::string message(p.status().message());
  if (absl::StatusOr<std::array<double, 4>> box = LonLatExtent(); box.ok()) {
    absl::StrAppendFormat(&message, " (it covers longitude %.8g to %.8g, latitude %.8g to %.8g)",
                          (*box)[0], (*box)[2], (*box)[1], (*box)[3]);
  }
  double sx = lat, sy = lon;  // longitude and latitude the other way round
  if (std::abs(lat) <= 180 && std::abs(lon) <= 90 && t->Transform(1, &sx, &sy)) {
    LongitudesToGrid(info_, &sx, 1);
    if (InGrid(sx, sy)) {
      absl::StrAppend(&message, "; ll:", Shortest(lat), ":", Shortest(lon),
                      " would be inside (longitude first: ll:LON:LAT)");
    }
  }
  return absl::InvalidArgumentError(message);
}

absl::StatusOr<SurfacePoint> Dem::DropMeshPoint(double mx, double my, double u, double v,
                                                const std::string& name) const {
  const uint32_t W = info_.grid_width, H = info_.grid_height;
  constexpr double kEdge = 1e-9;  // grid units: a point on the outer boundary is inside
  if (!(u >= -kEdge && u <= W - 1 + kEdge && v >= -kEdge && v <= H - 1 + kEdge)) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": outside the DEM"));
  }
  if (is_tin()) return DropOnTin(mx, my, u, v, name);
  const int bi = std::clamp(static_cast<int>(std::floor(u)), 0, static_cast<int>(W) - 2);
  const int bj = std::clamp(static_cast<int>(std::floor(v)), 0, static_cast<int>(H) - 2);
  // The point's block and its neighbours: a point on a grid line belongs to two blocks (one may be
  // a hole), and a reprojected grid is not exactly affine. The face holding it best wins.
  uint32_t best_face = kNoVertex;
  std::array<double, 3> best{};
  double best_min = -std::numeric_limits<double>::infinity();
  for (int dj = 0; dj <= 2; ++dj) {
    for (int di = 0; di <= 2; ++di) {
      const int i = bi + (di == 2   ? -1
                          : di == 1 ? 1
                                    : 0),
                j = bj + (dj == 2   ? -1
                          : dj == 1 ? 1
                                    : 0);
      if (i < 0 || j < 0 || i > static_cast<int>(W) - 2 || j > static_cast<int>(H) - 2) continue;
      for (int k = 0; k < 2; ++k) {
        const uint64_t triangle = 2 * (uint64_t(j) * (W - 1) + i) + k;
        // The block triangle's face, or the pieces a barrier cut left of it.
        std::vector<uint32_t> candidates;
        if (face_of_block_[triangle] != kNoVertex) candidates.push_back(face_of_block_[triangle]);
        for (auto it = std::lower_bound(pieces_.begin(), pieces_.end(),
                                        std::make_pair(triangle, uint32_t{0}));
             it != pieces_.end() && it->first == triangle; ++it) {
          candidates.push_back(it->second);
        }
        for (const uint32_t f : candidates) {
          const double* p[3];
          for (int c = 0; c < 3; ++c)
            p[c] = &mesh_.positions[3 * size_t{mesh_.faces[3 * size_t{f} + c]}];
          // Barycentrics of (mx, my) in the face's projection onto the map plane.
          const double det =
              (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
          if (det == 0) continue;
          const double b1 =
              ((mx - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (my - p[0][1])) / det;
          const double b2 =
              ((p[1][0] - p[0][0]) * (my - p[0][1]) - (mx - p[0][0]) * (p[1][1] - p[0][1])) / det;
          const std::array<double, 3> b = {1 - b1 - b2, b1, b2};
          const double lowest = std::min({b[0], b[1], b[2]});
          if (lowest > best_min) {
            best_min = lowest;
            best = b;
            best_face = f;
          }
        }
      }
    }
  }
  if (best_face == kNoVertex || best_min < -1e-7) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": in a hole of the DEM (nodata or a barrier)"));
  }
  double sum = 0;
  for (double& b : best) sum += (b = b > 0 ? b : 0.0);  // also turns -0 into 0
  return SurfacePoint::InFace(best_face, best[0] / sum, best[1] / sum, best[2] / sum);
}

}  // namespace geodex::terrain
