// Friction (geodex/friction.h), beside the barrier reader whose file and GeoJSON rules it shares:
// friction polygons read and checked, their outlines brought to the mesh's frame, snapped onto
// vertices and cut into it, each face's friction under its centre (from polygons or a raster), and
// --friction-snap's rules.

#include "geodex/friction.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/container/flat_hash_set.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "barrier_cut.h"
#include "dem_internal.h"
#include "gdal_priv.h"
#include "gdal_quiet.h"
#include "geodex/gis_formats.h"
#include "geodex/terrain.h"
#include "ogr_geometry.h"
#include "ogr_spatialref.h"
#include "ogrsf_frmts.h"

namespace geodex::terrain {

using dem_internal::CutOutlines;
using dem_internal::FaceFrictionOf;
using dem_internal::FileMeshTransform;
using dem_internal::FlagFilesName;
using dem_internal::FrictionRegion;
using dem_internal::InconsistentCrsId;
using dem_internal::LongitudesToGrid;
using dem_internal::OpenBarrierFile;
using dem_internal::OpenUserRaster;
using dem_internal::OutlinesOf;
using dem_internal::ParseFileCrs;
using dem_internal::ReadFrictionRegions;
using dem_internal::TransformPtr;
using dem_internal::WithGeoJsonText;

namespace {

// Coordinates beyond this (in any unit a file may use) are a mistake, not a map: refused rather
// than left to GEOS, where they overflow (a friction polygon at 1e308 once vanished in silence).
constexpr double kMaxMapCoordinate = 1e12;

// Why a friction polygon cannot be used as drawn ("" when it can): a coordinate not finite or
// absurd, a ring with fewer than 3 distinct points; an invalid polygon is repaired as the cut
// repairs it (areas kept, collapsed parts dropped) and refused when no area is left.
std::string UnusableFrictionShape(std::unique_ptr<OGRGeometry>* shape) {
  std::string why;
  std::function<void(const OGRGeometry&)> check = [&](const OGRGeometry& g) {
    if (!why.empty()) return;
    if (const auto* collection = dynamic_cast<const OGRGeometryCollection*>(&g)) {
      for (const OGRGeometry* part : *collection) check(*part);
      return;
    }
    const auto* polygon = dynamic_cast<const OGRPolygon*>(&g);
    if (polygon == nullptr) return;
    for (const OGRLinearRing* ring : *polygon) {
      std::set<std::pair<double, double>> distinct;
      for (const OGRPoint& p : *ring) {
        const double x = p.getX(), y = p.getY();
        if (!std::isfinite(x) || !std::isfinite(y)) {
          why = "a coordinate is not a finite number";
          return;
        }
        if (std::abs(x) > kMaxMapCoordinate || std::abs(y) > kMaxMapCoordinate) {
          why = absl::StrFormat("a coordinate (%g, %g) is beyond %g in size", x, y,
                                kMaxMapCoordinate);
          return;
        }
        distinct.insert({x, y});
      }
      if (distinct.size() < 3) {
        why = absl::StrFormat("a ring has %d distinct points; a polygon's ring needs 3 or more",
                              distinct.size());
        return;
      }
    }
  };
  check(**shape);
  if (!why.empty() || (*shape)->IsValid()) return why;
  std::unique_ptr<OGRGeometry> valid((*shape)->MakeValid());
  auto polygons = std::make_unique<OGRMultiPolygon>();
  std::function<void(const OGRGeometry&)> keep = [&](const OGRGeometry& g) {
    if (const auto* collection = dynamic_cast<const OGRGeometryCollection*>(&g)) {
      for (const OGRGeometry* part : *collection) keep(*part);
    } else if (dynamic_cast<const OGRPolygon*>(&g) != nullptr) {
      polygons->addGeometry(&g);
    }
  };
  if (valid != nullptr) keep(*valid);
  if (polygons->IsEmpty() || polygons->get_Area() <= 0) {
    return "the polygon is invalid and encloses no area once repaired";
  }
  *shape = std::move(polygons);
  return "";
}

}  // namespace

namespace dem_internal {

// The friction polygons of a vector dataset, checked (polygons only, each with a numeric
// "friction" > 0) and projected to `crs` (null: as they are). Both uses start here: the faces'
// values (FaceFrictionOf) and the outlines cut into a mesh (OutlinesOf).
absl::StatusOr<std::vector<FrictionRegion>> ReadFrictionRegions(GDALDataset& ds,
                                                                const OGRSpatialReference* crs,
                                                                const std::string& name) {
  auto bad = [&](const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": ", why));
  };
  std::vector<FrictionRegion> regions;
  for (OGRLayer* layer : ds.GetLayers()) {
    absl::StatusOr<TransformPtr> to_dem = LayerToCrs(*layer, crs, name);
    if (!to_dem.ok()) return to_dem.status();
    const int field = layer->GetLayerDefn()->GetFieldIndex("friction");
    const OGRFieldType type =
        field >= 0 ? layer->GetLayerDefn()->GetFieldDefn(field)->GetType() : OFTString;
    for (const auto& feature : *layer) {
      const std::string which = absl::StrCat("feature ", feature->GetFID());
      if (field < 0 || !feature->IsFieldSetAndNotNull(field) ||
          (type != OFTReal && type != OFTInteger && type != OFTInteger64)) {
        return bad(absl::StrCat(which, " has no numeric \"friction\" property"));
      }
      const double friction = feature->GetFieldAsDouble(field);
      if (!(friction > 0)) {
        return bad(absl::StrCat(which, ": friction must be > 0, got ", friction));
      }
      const OGRGeometry* g = feature->GetGeometryRef();
      if (g == nullptr) return bad(absl::StrCat(which, " has no geometry"));
      const OGRwkbGeometryType kind = wkbFlatten(g->getGeometryType());
      if (kind != wkbPolygon && kind != wkbMultiPolygon) {
        return bad(
            absl::StrCat(which, " is a ", g->getGeometryName(), "; friction regions are polygons"));
      }
      std::unique_ptr<OGRGeometry> copy(g->clone());
      if (std::string why = UnusableFrictionShape(&copy); !why.empty()) {
        return bad(absl::StrCat(which, ": ", why));
      }
      if (*to_dem != nullptr && copy->transform(to_dem->get()) != OGRERR_NONE) {
        return bad(absl::StrCat("cannot project ", which, " to the DEM's CRS (",
                                QuietGdal::LastMessage(), ")"));
      }
      regions.push_back({std::move(copy), friction});
    }
  }
  if (regions.empty()) return bad("no friction polygon");
  return regions;
}

// The regions' shapes as one collection: what CutOutlines splits the mesh along.
std::unique_ptr<OGRGeometry> OutlinesOf(const std::vector<FrictionRegion>& regions) {
  auto all = std::make_unique<OGRGeometryCollection>();
  for (const FrictionRegion& r : regions) all->addGeometry(r.shape.get());
  return all;
}

// Friction regions' outlines cut into the mesh (SplitAlongOutlines), polygons as CutBarrier's.
absl::StatusOr<MeshData> CutOutlines(const MeshData& mesh, OGRGeometry& polygons,
                                     const DemInfo* dem, const OGRSpatialReference* file_crs,
                                     uint64_t max_vertices, const std::string& name,
                                     CutStats* stats) {
  double scale = 1;
  if (absl::Status s = PolygonsToMeshFrame(polygons, dem, file_crs, name, &scale); !s.ok())
    return s;
  absl::StatusOr<MeshData> cut = SplitAlongOutlines(mesh, polygons, scale, max_vertices, stats);
  if (absl::IsInvalidArgument(cut.status())) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": ", cut.status().message()));
  }
  return cut;
}

}  // namespace dem_internal

namespace {

// Every ring of the polygons in `g` (a polygon, a multipolygon or a collection of them).
void ForEachRing(OGRGeometry& g, const std::function<void(OGRLinearRing&)>& visit) {
  if (auto* polygon = dynamic_cast<OGRPolygon*>(&g)) {
    for (OGRLinearRing* ring : *polygon) visit(*ring);
  } else if (auto* collection = dynamic_cast<OGRGeometryCollection*>(&g)) {
    for (OGRGeometry* part : *collection) ForEachRing(*part, visit);
  }
}

}  // namespace

namespace dem_internal {

// Friction regions in the mesh's own x y (projected to its CRS, or scaled to metres): there a
// snapped outline point is a vertex's very coordinates, and the cut (scale 1) and the faces'
// values (centres in mesh x y) read the same shapes.
absl::Status RegionsToMeshFrame(std::vector<FrictionRegion>& regions, const DemInfo& dem,
                                const OGRSpatialReference& file_crs, const std::string& name) {
  for (FrictionRegion& region : regions) {
    double scale = 1;
    if (absl::Status s = PolygonsToMeshFrame(*region.shape, &dem, &file_crs, name, &scale);
        !s.ok()) {
      return s;
    }
    if (scale == 1) continue;
    ForEachRing(*region.shape, [scale](OGRLinearRing& ring) {
      for (int i = 0; i < ring.getNumPoints(); ++i) {
        ring.setPoint(i, ring.getX(i) * scale, ring.getY(i) * scale);
      }
    });
  }
  return absl::OkStatus();
}

// DemOptions::friction_snap: outlines (in the mesh's x y) moved onto the vertices they pass
// within `fraction` x the vertex's shortest x-y edge of. Why: an outline crossing an edge that
// close to its end leaves pieces with a tiny angle (the crossing is shared with the neighbouring
// face, which must take it as a corner), and the bounded engine's Steiner points per edge grow as
// 1 / sin(smallest angle), its links per face as their square. Through the vertex, the outline
// leaves no such piece there. A region whose snapped outline is no longer a valid polygon (two
// of its stretches closer than the discs) keeps its drawn shape.
void SnapOutlinesToVertices(std::vector<FrictionRegion>& regions, const MeshData& mesh,
                            double fraction) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const size_t n = mesh.vertex_count();
  auto xy = [&](uint32_t v) {
    return std::array<double, 2>{mesh.positions[3 * size_t{v}], mesh.positions[3 * size_t{v} + 1]};
  };
  std::vector<double> radius(n, kInf);  // (kInf until an edge is seen; 0 below: no face uses it)
  std::vector<double> lengths;
  lengths.reserve(mesh.faces.size());
  for (size_t c = 0; c < mesh.faces.size(); ++c) {
    const uint32_t a = mesh.faces[c], b = mesh.faces[c - c % 3 + (c + 1) % 3];
    const double length = std::hypot(xy(a)[0] - xy(b)[0], xy(a)[1] - xy(b)[1]);
    radius[a] = std::min(radius[a], fraction * length);
    radius[b] = std::min(radius[b], fraction * length);
    lengths.push_back(length);
  }
  if (lengths.empty()) return;
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  const double cell = lengths[lengths.size() / 2];
  if (!(cell > 0)) return;
  // A disc reaches at most 4 buckets away: a vertex with only long edges (an adaptive TIN's flat
  // expanse) snaps less rather than fill thousands of buckets.
  for (double& r : radius) r = r == kInf ? 0 : std::min(r, 4 * cell);  // 0: never a target
  // The discs' box: only the part of a segment inside it is walked (a polygon may reach far
  // beyond the mesh, and its walk must not grow with that).
  double box[4] = {kInf, kInf, -kInf, -kInf};  // min x, min y, max x, max y
  for (uint32_t v = 0; v < n; ++v) {
    if (!(radius[v] > 0)) continue;
    box[0] = std::min(box[0], xy(v)[0] - radius[v]);
    box[1] = std::min(box[1], xy(v)[1] - radius[v]);
    box[2] = std::max(box[2], xy(v)[0] + radius[v]);
    box[3] = std::max(box[3], xy(v)[1] + radius[v]);
  }
  // Each vertex in every bucket (a square of the median edge length) its disc touches.
  auto key = [](int64_t i, int64_t j) { return (static_cast<uint64_t>(i) << 32) ^ uint32_t(j); };
  auto index = [cell](double x) { return static_cast<int64_t>(std::floor(x / cell)); };
  absl::flat_hash_map<uint64_t, std::vector<uint32_t>> buckets;
  for (uint32_t v = 0; v < n; ++v) {
    if (!(radius[v] > 0)) continue;
    const auto [x, y] = xy(v);
    for (int64_t i = index(x - radius[v]); i <= index(x + radius[v]); ++i) {
      for (int64_t j = index(y - radius[v]); j <= index(y + radius[v]); ++j) {
        buckets[key(i, j)].push_back(v);
      }
    }
  }
  const std::vector<uint32_t> none;
  auto in_box = [&](double x, double y) {  // (false for NaN)
    return x >= box[0] && x <= box[2] && y >= box[1] && y <= box[3];
  };
  auto near = [&](double x, double y) -> const std::vector<uint32_t>& {
    if (!in_box(x, y)) return none;
    auto it = buckets.find(key(index(x), index(y)));
    return it == buckets.end() ? none : it->second;
  };
  // The walk's budget in buckets visited, for all outlines together: a polygon of millions of
  // edges across a large DEM stops being snapped (what is left stays as drawn) rather than stall.
  uint64_t budget = 64 * uint64_t{mesh.face_count()} + (uint64_t{1} << 20);
  auto snap_ring = [&](OGRLinearRing& ring, uint64_t* count) {
    std::vector<std::array<double, 2>> in(ring.getNumPoints());
    if (in.empty()) return;
    for (size_t i = 0; i < in.size(); ++i) in[i] = {ring.getX(i), ring.getY(i)};
    for (auto& p : in) {  // corners onto the nearest vertex whose disc holds them
      double best = kInf;
      std::array<double, 2> to = p;
      for (uint32_t v : near(p[0], p[1])) {
        const double d = std::hypot(xy(v)[0] - p[0], xy(v)[1] - p[1]);
        if (d < radius[v] && d < best) best = d, to = xy(v);
      }
      *count += to != p;
      p = to;
    }
    std::vector<std::array<double, 2>> out;
    std::vector<std::pair<double, uint32_t>> on_segment;
    absl::flat_hash_set<uint64_t> seen;
    for (size_t s = 0; s + 1 < in.size(); ++s) {
      const auto p = in[s], q = in[s + 1];
      out.push_back(p);
      const double dx = q[0] - p[0], dy = q[1] - p[1], length = std::hypot(dx, dy);
      if (!(length > 0)) continue;
      // The buckets the segment passes through (sampled every half bucket, with their
      // neighbours): a disc the segment enters lists its vertex in the bucket where it does.
      on_segment.clear();
      seen.clear();
      double t0 = 0, t1 = 1;  // the segment's part inside the box (Liang and Barsky's clip)
      for (int axis = 0; axis < 2; ++axis) {
        const double d = axis == 0 ? dx : dy, from = p[axis];
        if (d == 0) {
          if (from < box[axis] || from > box[axis + 2]) t1 = -1;
          continue;
        }
        const double a = (box[axis] - from) / d, b = (box[axis + 2] - from) / d;
        t0 = std::max(t0, std::min(a, b));
        t1 = std::min(t1, std::max(a, b));
      }
      if (!(t1 >= t0)) continue;  // (also NaN: the cutter names coordinates that are not finite)
      // The clipped ends, clamped into the box (rounding of a huge segment's t stays bounded).
      auto clamped = [&](double t) {
        return std::array<double, 2>{std::clamp(p[0] + dx * t, box[0], box[2]),
                                     std::clamp(p[1] + dy * t, box[1], box[3])};
      };
      const auto a = clamped(t0), b = clamped(t1);
      const int64_t steps =
          static_cast<int64_t>(std::ceil(2 * std::hypot(b[0] - a[0], b[1] - a[1]) / cell)) + 1;
      if (budget < uint64_t(steps)) continue;
      budget -= steps;
      for (int64_t k = 0; k <= steps; ++k) {
        const int64_t i0 = index(a[0] + (b[0] - a[0]) * k / steps);
        const int64_t j0 = index(a[1] + (b[1] - a[1]) * k / steps);
        for (int64_t i = i0 - 1; i <= i0 + 1; ++i) {
          for (int64_t j = j0 - 1; j <= j0 + 1; ++j) {
            if (!seen.insert(key(i, j)).second) continue;
            auto it = buckets.find(key(i, j));
            if (it == buckets.end()) continue;
            for (uint32_t v : it->second) {
              const double vx = xy(v)[0] - p[0], vy = xy(v)[1] - p[1];
              const double t = (vx * dx + vy * dy) / length / length;
              if (!(t > 0 && t < 1)) continue;
              if (std::abs(vx * dy - vy * dx) / length < radius[v]) on_segment.push_back({t, v});
            }
          }
        }
      }
      std::sort(on_segment.begin(), on_segment.end());
      for (const auto& [t, v] : on_segment) {
        if (xy(v) == out.back() || xy(v) == q) continue;  // (listed twice, or an end already)
        out.push_back(xy(v));
        ++*count;
      }
    }
    out.push_back(in.back());
    ring.setNumPoints(0);
    for (const auto& [x, y] : out) ring.addPoint(x, y);
  };
  for (FrictionRegion& region : regions) {
    std::unique_ptr<OGRGeometry> drawn(region.shape->clone());
    uint64_t count = 0;
    ForEachRing(*region.shape, [&](OGRLinearRing& ring) { snap_ring(ring, &count); });
    if (count > 0 && !region.shape->IsValid()) {
      region.shape = std::move(drawn);
    }
  }
}

}  // namespace dem_internal

namespace {

// Each face's centroid in the DEM file's CRS (`dem`), or in the mesh's x y (no `dem`).
absl::StatusOr<std::vector<std::array<double, 2>>> FaceCentresInMap(const MeshData& mesh,
                                                                    const DemInfo* dem,
                                                                    const std::string& name) {
  const size_t nf = mesh.faces.size() / 3;
  std::vector<double> xs(nf), ys(nf);
  for (size_t f = 0; f < nf; ++f) {
    double x = 0, y = 0;
    for (int k = 0; k < 3; ++k) {
      x += mesh.positions[3 * size_t{mesh.faces[3 * f + k]}] / 3;
      y += mesh.positions[3 * size_t{mesh.faces[3 * f + k]} + 1] / 3;
    }
    xs[f] = x;
    ys[f] = y;
  }
  if (dem != nullptr && dem->reprojected) {
    TransformPtr back = FileMeshTransform(*dem, /*to_mesh=*/false);
    std::vector<int> ok(nf);
    if (back == nullptr ||
        (nf > 0 &&
         !back->Transform(static_cast<int>(nf), xs.data(), ys.data(), nullptr, ok.data())) ||
        std::find(ok.begin(), ok.end(), 0) != ok.end()) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": the faces do not project back to the DEM's CRS"));
    }
    LongitudesToGrid(*dem, xs.data(), nf);
  } else if (dem != nullptr) {
    for (size_t f = 0; f < nf; ++f) {
      xs[f] /= dem->horizontal_scale;
      ys[f] /= dem->horizontal_scale;
    }
  }
  std::vector<std::array<double, 2>> out(nf);
  for (size_t f = 0; f < nf; ++f) out[f] = {xs[f], ys[f]};
  return out;
}

// Points bucketed on a uniform grid over their bounding box (counting sort: flat arrays).
class CentreGrid {
 public:
  explicit CentreGrid(const std::vector<std::array<double, 2>>& points) : points_(points) {
    if (points.empty()) return;
    min_x_ = max_x_ = points[0][0];
    min_y_ = max_y_ = points[0][1];
    for (const auto& [x, y] : points) {
      min_x_ = std::min(min_x_, x);
      max_x_ = std::max(max_x_, x);
      min_y_ = std::min(min_y_, y);
      max_y_ = std::max(max_y_, y);
    }
    side_ = std::max<size_t>(1, static_cast<size_t>(std::sqrt(points.size() / 4.0)));
    start_.assign(side_ * side_ + 1, 0);
    for (const auto& [x, y] : points) ++start_[Cell(x, y) + 1];
    for (size_t c = 0; c < side_ * side_; ++c) start_[c + 1] += start_[c];
    order_.resize(points.size());
    std::vector<uint32_t> at(start_.begin(), start_.end() - 1);
    for (uint32_t i = 0; i < points.size(); ++i) {
      order_[at[Cell(points[i][0], points[i][1])]++] = i;
    }
  }

  // The points of every cell the box [x0, x1] x [y0, y1] touches (a superset of those inside).
  std::vector<uint32_t> Near(double x0, double y0, double x1, double y1) const {
    std::vector<uint32_t> out;
    if (points_.empty() || x1 < min_x_ || x0 > max_x_ || y1 < min_y_ || y0 > max_y_) return out;
    const size_t i0 = Index(x0, min_x_, max_x_), i1 = Index(x1, min_x_, max_x_);
    const size_t j0 = Index(y0, min_y_, max_y_), j1 = Index(y1, min_y_, max_y_);
    for (size_t j = j0; j <= j1; ++j) {
      for (size_t i = i0; i <= i1; ++i) {
        const size_t c = j * side_ + i;
        out.insert(out.end(), order_.begin() + start_[c], order_.begin() + start_[c + 1]);
      }
    }
    return out;
  }

 private:
  size_t Index(double v, double lo, double hi) const {
    if (!(hi > lo)) return 0;
    const double at = (v - lo) / (hi - lo) * side_;
    return at <= 0 ? 0 : std::min(side_ - 1, static_cast<size_t>(at));
  }
  size_t Cell(double x, double y) const {
    return Index(y, min_y_, max_y_) * side_ + Index(x, min_x_, max_x_);
  }

  const std::vector<std::array<double, 2>>& points_;
  double min_x_ = 0, max_x_ = 0, min_y_ = 0, max_y_ = 0;
  size_t side_ = 1;
  std::vector<uint32_t> start_, order_;
};

}  // namespace

namespace dem_internal {

// Each face's friction: the largest of the regions (in the DEM file's CRS, or the mesh's own x y
// without a DEM) containing its centroid, 1 elsewhere. A reprojected DEM's faces are classified
// in the mesh's CRS, the polygons projected there vertex by vertex as CutOutlines projects them,
// so that a face of a mesh cut along their outlines lies on one side.
absl::StatusOr<std::vector<double>> FaceFrictionOf(std::vector<FrictionRegion> regions,
                                                   const MeshData& mesh, const DemInfo* dem,
                                                   const std::string& name) {
  const bool in_mesh_crs = dem != nullptr && dem->reprojected;
  if (in_mesh_crs) {
    TransformPtr to_mesh = FileMeshTransform(*dem, /*to_mesh=*/true);
    if (to_mesh == nullptr) {
      return absl::InvalidArgumentError(absl::StrCat(
          name, ": cannot project it to the mesh's CRS (", QuietGdal::LastMessage(), ")"));
    }
    for (FrictionRegion& r : regions) {
      if (r.shape->transform(to_mesh.get()) != OGRERR_NONE) {
        return absl::InvalidArgumentError(absl::StrCat(
            name, ": cannot project a polygon to the mesh's CRS (", QuietGdal::LastMessage(), ")"));
      }
    }
  }
  std::vector<OGREnvelope> boxes(regions.size());
  for (size_t i = 0; i < regions.size(); ++i) regions[i].shape->getEnvelope(&boxes[i]);
  absl::StatusOr<std::vector<std::array<double, 2>>> centres =
      FaceCentresInMap(mesh, in_mesh_crs ? nullptr : dem, name);
  if (!centres.ok()) return centres.status();
  std::vector<double> weight(centres->size(), 1.0);
  std::vector<char> inside_any(centres->size(), 0);
  // The centres bucketed on a grid of about 4 per cell, so a polygon visits only the faces near
  // its box: the cost grows with faces + polygons + the faces inside boxes, not faces x polygons
  // (a land-cover layer has thousands of polygons, a DEM a million faces).
  const CentreGrid grid(*centres);
  OGRPoint point;
  for (size_t i = 0; i < regions.size(); ++i) {
    const FrictionRegion& r = regions[i];
    const OGREnvelope& box = boxes[i];
    for (const uint32_t f : grid.Near(box.MinX, box.MinY, box.MaxX, box.MaxY)) {
      const auto& [x, y] = (*centres)[f];
      if (x < box.MinX || x > box.MaxX || y < box.MinY || y > box.MaxY) continue;
      point.setX(x);
      point.setY(y);
      bool inside = false;
      if (const OGRPolygon* p = dynamic_cast<const OGRPolygon*>(r.shape.get())) {
        inside = p->IsPointOnSurface(&point);
      } else if (const auto* m = dynamic_cast<const OGRMultiPolygon*>(r.shape.get())) {
        for (const OGRPolygon* part : *m) inside = inside || part->IsPointOnSurface(&point);
      }
      if (!inside) continue;
      weight[f] = inside_any[f] ? std::max(weight[f], r.friction) : r.friction;
      inside_any[f] = 1;
    }
  }
  return weight;
}

}  // namespace dem_internal

absl::StatusOr<std::vector<double>> FrictionFromGeoJson(const MeshData& mesh,
                                                        const std::string& geojson,
                                                        const DemInfo* dem,
                                                        const std::string& name) {
  QuietGdal quiet;
  OGRSpatialReference file_crs;
  if (absl::Status s = ParseFileCrs(dem, name, &file_crs); !s.ok()) return s;
  return WithGeoJsonText<std::vector<double>>(
      geojson, name, [&](GDALDataset& ds) -> absl::StatusOr<std::vector<double>> {
        absl::StatusOr<std::vector<FrictionRegion>> regions =
            ReadFrictionRegions(ds, dem != nullptr ? &file_crs : nullptr, name);
        if (!regions.ok()) return regions.status();
        return FaceFrictionOf(*std::move(regions), mesh, dem, name);
      });
}

absl::StatusOr<MeshData> CutFrictionOutlines(const MeshData& mesh, const std::string& geojson,
                                             const DemInfo* dem, const std::string& name,
                                             CutStats* stats, uint64_t max_vertices) {
  QuietGdal quiet;
  OGRSpatialReference file_crs;
  if (absl::Status s = ParseFileCrs(dem, name, &file_crs); !s.ok()) return s;
  return WithGeoJsonText<MeshData>(geojson, name, [&](GDALDataset& ds) -> absl::StatusOr<MeshData> {
    // Read and checked as FrictionFromGeoJson reads them: a bad value fails here too.
    absl::StatusOr<std::vector<FrictionRegion>> regions =
        ReadFrictionRegions(ds, dem != nullptr ? &file_crs : nullptr, name);
    if (!regions.ok()) return regions.status();
    return CutOutlines(mesh, *OutlinesOf(*regions), dem, &file_crs, max_vertices, name, stats);
  });
}

absl::StatusOr<std::vector<double>> ReadFrictionFiles(const MeshData& mesh,
                                                      const std::vector<std::string>& paths,
                                                      const DemInfo& dem) {
  if (paths.size() == 1) return ReadFrictionFile(mesh, paths[0], dem, "--friction " + paths[0]);
  QuietGdal quiet;
  const std::string names = FlagFilesName("friction", paths);
  for (const std::string& path : paths) {
    const std::string name = absl::StrCat("--friction ", path);
    const GisFormat* format = GisFormatOf(path);
    if (format != nullptr && format->kind == GisFileKind::kRaster) {
      return absl::InvalidArgumentError(absl::StrCat(
          name,
          ": a friction raster is given alone (it values every face); only polygon files "
          "add up when --friction is repeated"));
    }
  }
  OGRSpatialReference file_crs;
  if (absl::Status s = ParseFileCrs(&dem, names, &file_crs); !s.ok()) return s;
  // Every file's polygons in one list: as one file holding them all (overlaps take the largest).
  std::vector<FrictionRegion> all;
  for (const std::string& path : paths) {
    const std::string name = absl::StrCat("--friction ", path);
    absl::StatusOr<GDALDatasetUniquePtr> ds = OpenBarrierFile(path, name);
    if (!ds.ok()) return ds.status();
    absl::StatusOr<std::vector<FrictionRegion>> regions =
        ReadFrictionRegions(**ds, &file_crs, name);
    if (!regions.ok()) return regions.status();
    for (FrictionRegion& r : *regions) all.push_back(std::move(r));
  }
  return FaceFrictionOf(std::move(all), mesh, &dem, names);
}

absl::StatusOr<std::vector<double>> ReadFrictionFile(const MeshData& mesh, const std::string& path,
                                                     const DemInfo& dem, const std::string& name) {
  QuietGdal quiet;
  auto bad = [&](const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": ", why));
  };
  OGRSpatialReference file_crs;
  if (absl::Status s = ParseFileCrs(&dem, name, &file_crs); !s.ok()) return s;
  const GisFormat* format = GisFormatOf(path);
  if (format == nullptr || format->kind != GisFileKind::kRaster) {  // polygons
    absl::StatusOr<GDALDatasetUniquePtr> ds = OpenBarrierFile(path, name);
    if (!ds.ok()) return ds.status();
    absl::StatusOr<std::vector<FrictionRegion>> regions =
        ReadFrictionRegions(**ds, &file_crs, name);
    if (!regions.ok()) return regions.status();
    return FaceFrictionOf(*std::move(regions), mesh, &dem, name);
  }
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    return absl::NotFoundError(absl::StrCat(name, ": cannot open: No such file or directory"));
  }
  // A raster: the drivers and side-car rules of Dem::Read.
  GDALDatasetUniquePtr ds = OpenUserRaster(path);
  if (ds == nullptr) {
    return bad(absl::StrCat("not a raster GDAL reads (", QuietGdal::LastMessage(), ")"));
  }
  if (ds->GetRasterCount() != 1) return bad("a friction raster has one band");
  const OGRSpatialReference* crs = ds->GetSpatialRef();
  if (crs == nullptr || crs->IsEmpty()) return bad("no coordinate reference system");
  if (std::string why = InconsistentCrsId(*crs); !why.empty()) return bad(why);
  if (!crs->IsSame(&file_crs)) {
    return bad(absl::StrCat("its CRS (", crs->GetName() != nullptr ? crs->GetName() : "?",
                            ") is not the DEM's (", dem.file_crs_name,
                            "); reproject it first (gdalwarp -t_srs)"));
  }
  double gt[6];
  if (ds->GetGeoTransform(gt) != CE_None || gt[2] != 0 || gt[4] != 0 || gt[1] == 0 || gt[5] == 0 ||
      !std::all_of(gt, gt + 6, [](double v) { return std::isfinite(v); })) {
    return bad("no north-up geotransform");
  }
  const int W = ds->GetRasterXSize(), H = ds->GetRasterYSize();
  if (int64_t{W} * H > (int64_t{1} << 28)) {
    return bad(absl::StrFormat("%dx%d cells: more than a friction raster may have (2^28)", W, H));
  }
  absl::StatusOr<std::vector<std::array<double, 2>>> centres = FaceCentresInMap(mesh, &dem, name);
  if (!centres.ok()) return centres.status();
  GDALRasterBand* band = ds->GetRasterBand(1);
  std::vector<double> cells(size_t(W) * H);
  if (band->RasterIO(GF_Read, 0, 0, W, H, cells.data(), W, H, GDT_Float64, 0, 0) != CE_None) {
    return bad(absl::StrCat("cannot read its cells (", QuietGdal::LastMessage(), ")"));
  }
  int has_nodata = 0;
  const double nodata = band->GetNoDataValue(&has_nodata);
  std::vector<double> weight(centres->size());
  for (size_t f = 0; f < centres->size(); ++f) {
    const auto& [x, y] = (*centres)[f];
    const double u = std::floor((x - gt[0]) / gt[1]), v = std::floor((y - gt[3]) / gt[5]);
    if (!(u >= 0 && v >= 0 && u < W && v < H)) {
      return bad(absl::StrFormat(
          "it does not cover the DEM: face %d's centre (%.10g, %.10g) is outside it", f, x, y));
    }
    const double value = cells[static_cast<size_t>(v) * W + static_cast<size_t>(u)];
    if ((has_nodata && value == nodata) || std::isnan(value)) {
      weight[f] = std::numeric_limits<double>::infinity();  // no data: impassable
    } else if (!(value > 0)) {
      return bad(absl::StrFormat("cell (column %d, row %d) has friction %g; it must be > 0",
                                 static_cast<int>(u), static_cast<int>(v), value));
    } else {
      weight[f] = value;
    }
  }
  return weight;
}

}  // namespace geodex::terrain
