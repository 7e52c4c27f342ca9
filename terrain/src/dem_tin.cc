// A DEM as an adaptive TIN (DemOptions::z_tolerance > 0): the TIN built from the grid's cells
// (its holes cut out exactly as the grid's), its faces' neighbours and the face over each cell
// centre mapped, points in the grid's plane dropped onto it, and a cell's surface point.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "dem_internal.h"
#include "geodex/adaptive_tin.h"
#include "geodex/geodesic_solver.h"
#include "geodex/limits.h"
#include "geodex/terrain.h"
#include "ogr_geometry.h"

namespace geodex::terrain {

using dem_internal::CutBarrier;

absl::StatusOr<MeshData> Dem::BuildTin(const Dem& grid, const DemOptions& options, bool flip,
                                       const OGRSpatialReference& file_crs, const std::string& name,
                                       DemInfo* info) {
  const uint32_t W = grid.info_.grid_width, H = grid.info_.grid_height;
  // Heights in metres, row by row (the tolerance is in metres too); cells without data (or below
  // the barrier) are holes: they do not shape the TIN, and are cut out of it below.
  std::vector<double> heights(size_t{W} * H, 0.0);
  std::vector<uint8_t> valid(size_t{W} * H, 0);
  bool holes = false;
  for (size_t cell = 0; cell < heights.size(); ++cell) {
    const uint32_t v = grid.vertex_of_cell_[cell];
    holes |= v == kNoVertex;
    if (v == kNoVertex) continue;
    heights[cell] = grid.mesh_.positions[3 * size_t{v} + 2];
    valid[cell] = 1;
  }
  AdaptiveTinOptions tin_options;
  tin_options.z_tolerance = options.z_tolerance * grid.info_.vertical_scale;
  tin_options.max_vertices = options.max_vertices;
  tin_options.cancel = options.cancel;
  absl::StatusOr<AdaptiveTin> tin =
      BuildAdaptiveTin(heights.data(), H, W, holes ? valid.data() : nullptr, tin_options);
  if (!tin.ok()) {
    if (absl::IsInvalidArgument(tin.status())) {
      return OptionError("z_tolerance", absl::StrCat(name, ": ", tin.status().message()));
    }
    return tin.status();
  }
  if (options.max_faces != 0 && tin->faces.size() > options.max_faces) {
    return LimitExceededError(
        Limit::kFaces, absl::StrFormat("%s: the TIN has %d faces, more than the %d a mesh may "
                                       "have here (a larger --z-tolerance makes fewer)",
                                       name, tin->faces.size(), options.max_faces));
  }
  // Vertices in row order (what FromMesh reads a DEM's cells by), faces wound like the grid's. A
  // corner in a hole keeps the height the TIN gave it (it is cut away with the hole).
  const size_t n = tin->vertices.size();
  std::vector<uint32_t> order(n), new_index(n);
  for (uint32_t v = 0; v < n; ++v) order[v] = v;
  auto cell_of = [&](uint32_t v) {
    return size_t{tin->source_cell[v].first} * W + tin->source_cell[v].second;
  };
  std::sort(order.begin(), order.end(),
            [&](uint32_t a, uint32_t b) { return cell_of(a) < cell_of(b); });
  MeshData out;
  out.positions.reserve(3 * n);
  for (uint32_t k = 0; k < n; ++k) {
    new_index[order[k]] = k;
    const uint32_t v = grid.vertex_of_cell_[cell_of(order[k])];
    if (v != kNoVertex) {
      const double* p = &grid.mesh_.positions[3 * size_t{v}];
      out.positions.insert(out.positions.end(), p, p + 3);
    } else {  // a corner in a hole: its map position, the TIN's height
      absl::StatusOr<std::array<double, 2>> xy = grid.CellCentreInMesh(
          tin->source_cell[order[k]].second, tin->source_cell[order[k]].first);
      if (!xy.ok()) return xy.status();
      out.positions.insert(out.positions.end(), {(*xy)[0], (*xy)[1], tin->vertices[order[k]][2]});
    }
  }
  out.faces.reserve(3 * tin->faces.size());
  for (const std::array<uint32_t, 3>& f : tin->faces) {
    // The TIN's faces turn counter-clockwise in (column, row); the grid's (a, c, d) clockwise
    // there (rows run south), mirrored when they run north.
    std::array<uint32_t, 3> t = {new_index[f[0]], new_index[f[1]], new_index[f[2]]};
    if (!flip) std::swap(t[1], t[2]);
    out.faces.insert(out.faces.end(), t.begin(), t.end());
  }
  info->max_vertical_deviation = tin->max_vertical_deviation;
  info->rms_vertical_deviation = tin->rms_vertical_deviation;
  if (!holes) return out;
  // The grid's holes, exactly: a grid triangle goes when a corner has no data, so a hole cell
  // takes the six triangles around it, a hexagon of cell centres; a row's run of hole cells
  // i0..i1 takes their union, (i0-1, j-1) (i1, j-1) (i1+1, j) (i1+1, j+1) (i0, j+1) (i0-1, j).
  const std::array<double, 6>& gt = grid.info_.geotransform;
  auto at = [&](double i, double j) {
    return std::pair{gt[0] + (i + 0.5) * gt[1], gt[3] + (j + 0.5) * gt[5]};
  };
  OGRMultiPolygon runs;
  for (uint32_t j = 0; j < H; ++j) {
    for (uint32_t i = 0; i < W;) {
      if (valid[size_t{j} * W + i]) {
        ++i;
        continue;
      }
      uint32_t end = i;
      while (end + 1 < W && !valid[size_t{j} * W + end + 1]) ++end;
      const double i0 = i, i1 = end, jj = j;
      OGRLinearRing ring;
      for (auto [u, v] : {std::pair{i0 - 1, jj - 1}, std::pair{i1, jj - 1}, std::pair{i1 + 1, jj},
                          std::pair{i1 + 1, jj + 1}, std::pair{i0, jj + 1}, std::pair{i0 - 1, jj},
                          std::pair{i0 - 1, jj - 1}}) {
        const auto [x, y] = at(u, v);
        ring.addPoint(x, y);
      }
      OGRPolygon hexagon;
      hexagon.addRing(&ring);
      runs.addGeometry(&hexagon);
      i = end + 1;
    }
  }
  std::unique_ptr<OGRGeometry> cut_out(runs.UnionCascaded());
  if (cut_out == nullptr) {
    return absl::InternalError(absl::StrCat(name, ": cannot join the DEM's holes (GEOS)"));
  }
  CutStats stats;
  return CutBarrier(out, *cut_out, &grid.info_, &file_crs, 0, options.max_vertices,
                    absl::StrCat(name, " (its cells without data)"), &stats);
}

namespace {

// Barycentrics of (u, v) in the triangle p0 p1 p2 of the plane; false when it is degenerate.
bool Barycentrics(const std::array<double, 2>& p0, const std::array<double, 2>& p1,
                  const std::array<double, 2>& p2, double u, double v, std::array<double, 3>* b) {
  const double det = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (p1[1] - p0[1]);
  if (det == 0) return false;
  const double b1 = ((u - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (v - p0[1])) / det;
  const double b2 = ((p1[0] - p0[0]) * (v - p0[1]) - (u - p0[0]) * (p1[1] - p0[1])) / det;
  *b = {1 - b1 - b2, b1, b2};
  return true;
}

// A face point from barycentrics a hair outside the face: clamped and normalised.
SurfacePoint ClampedFacePoint(uint32_t face, std::array<double, 3> b) {
  double sum = 0;
  for (double& x : b) sum += (x = x > 0 ? x : 0.0);  // also turns -0 into 0
  return SurfacePoint::InFace(face, b[0] / sum, b[1] / sum, b[2] / sum);
}

}  // namespace

absl::Status Dem::MapTin() {
  const uint32_t W = info_.grid_width, H = info_.grid_height;
  const size_t faces = mesh_.face_count(), n = mesh_.vertex_count();
  for (uint32_t v : mesh_.faces) {
    if (v >= n) return absl::InvalidArgumentError(absl::StrCat("a face has no vertex ", v));
  }
  // Neighbours across each edge (the edge opposite corner k), from the edges sorted by their ends.
  std::vector<std::pair<uint64_t, uint32_t>> edges;
  edges.reserve(3 * faces);
  for (size_t f = 0; f < faces; ++f) {
    for (int k = 0; k < 3; ++k) {
      const uint64_t a = mesh_.faces[3 * f + (k + 1) % 3], b = mesh_.faces[3 * f + (k + 2) % 3];
      edges.push_back({std::min(a, b) << 32 | std::max(a, b), static_cast<uint32_t>(3 * f + k)});
    }
  }
  std::sort(edges.begin(), edges.end());
  neighbours_.assign(3 * faces, kNoVertex);
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    if (j - i == 2) {  // an inner edge (a non-manifold one stays a boundary for the walk)
      neighbours_[edges[i].second] = edges[i + 1].second / 3;
      neighbours_[edges[i + 1].second] = edges[i].second / 3;
    }
    i = j;
  }
  // The face holding each cell centre: each face's cells, over its bounding box (TIN faces are
  // Delaunay triangles of the grid's cells: their boxes hold about twice their cells).
  face_of_cell_.assign(size_t{W} * H, kNoVertex);
  constexpr double kOn = 1e-9;  // a centre on an edge belongs to the first face that finds it
  for (size_t f = 0; f < faces; ++f) {
    const std::array<double, 2>& p0 = cell_uv_[mesh_.faces[3 * f]];
    const std::array<double, 2>& p1 = cell_uv_[mesh_.faces[3 * f + 1]];
    const std::array<double, 2>& p2 = cell_uv_[mesh_.faces[3 * f + 2]];
    const double lo_u = std::max(0.0, std::ceil(std::min({p0[0], p1[0], p2[0]}) - kOn));
    const double hi_u = std::min(W - 1.0, std::floor(std::max({p0[0], p1[0], p2[0]}) + kOn));
    const double lo_v = std::max(0.0, std::ceil(std::min({p0[1], p1[1], p2[1]}) - kOn));
    const double hi_v = std::min(H - 1.0, std::floor(std::max({p0[1], p1[1], p2[1]}) + kOn));
    for (double v = lo_v; v <= hi_v; ++v) {
      for (double u = lo_u; u <= hi_u; ++u) {
        std::array<double, 3> b;
        if (!Barycentrics(p0, p1, p2, u, v, &b) || std::min({b[0], b[1], b[2]}) < -kOn) continue;
        uint32_t& slot = face_of_cell_[static_cast<size_t>(v) * W + static_cast<size_t>(u)];
        if (slot == kNoVertex) slot = static_cast<uint32_t>(f);
      }
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<SurfacePoint> Dem::DropOnTin(double /*mx*/, double /*my*/, double u, double v,
                                            const std::string& name) const {
  // Faces and cells share the grid's plane (the TIN was made there): walk from the face of a cell
  // near the point towards it, across the edge it lies beyond, until a face holds it.
  const int W = static_cast<int>(info_.grid_width), H = static_cast<int>(info_.grid_height);
  const int ci = std::clamp(static_cast<int>(std::lround(u)), 0, W - 1);
  const int cj = std::clamp(static_cast<int>(std::lround(v)), 0, H - 1);
  std::vector<uint32_t> starts;
  for (int r = 0; r <= 2 && starts.empty(); ++r) {
    for (int j = std::max(0, cj - r); j <= std::min(H - 1, cj + r); ++j) {
      for (int i = std::max(0, ci - r); i <= std::min(W - 1, ci + r); ++i) {
        const uint32_t f = face_of_cell_[size_t(j) * W + i];
        if (f != kNoVertex && std::find(starts.begin(), starts.end(), f) == starts.end()) {
          starts.push_back(f);
        }
      }
    }
  }
  const size_t faces = mesh_.face_count();
  for (uint32_t f : starts) {
    for (size_t step = 0; step <= faces; ++step) {
      std::array<double, 3> b;
      if (!Barycentrics(cell_uv_[mesh_.faces[3 * size_t{f}]],
                        cell_uv_[mesh_.faces[3 * size_t{f} + 1]],
                        cell_uv_[mesh_.faces[3 * size_t{f} + 2]], u, v, &b)) {
        break;
      }
      const int k = static_cast<int>(std::min_element(b.begin(), b.end()) - b.begin());
      if (b[k] >= -1e-12) return ClampedFacePoint(f, b);
      const uint32_t next = neighbours_[3 * size_t{f} + k];
      if (next == kNoVertex) {
        if (b[k] >= -1e-7) return ClampedFacePoint(f, b);  // on the boundary, to round-off
        break;  // beyond a boundary here: another start may go round
      }
      f = next;
    }
  }
  return absl::InvalidArgumentError(
      absl::StrCat(name, ": in a hole of the DEM (nodata or a barrier)"));
}

absl::StatusOr<SurfacePoint> Dem::CellPoint(uint32_t col, uint32_t row) const {
  if (col >= info_.grid_width || row >= info_.grid_height) {
    return absl::InvalidArgumentError(absl::StrCat("cell (", col, ", ", row, ") is off the grid"));
  }
  const size_t cell = size_t{row} * info_.grid_width + col;
  if (!is_tin()) {
    if (vertex_of_cell_[cell] == kNoVertex) return absl::NotFoundError("a cell without surface");
    return SurfacePoint::AtVertex(vertex_of_cell_[cell]);
  }
  const uint32_t f = face_of_cell_[cell];
  if (f == kNoVertex) return absl::NotFoundError("a cell without surface");
  if (vertex_of_cell_[cell] != kNoVertex) return SurfacePoint::AtVertex(vertex_of_cell_[cell]);
  std::array<double, 3> b;
  if (!Barycentrics(cell_uv_[mesh_.faces[3 * size_t{f}]], cell_uv_[mesh_.faces[3 * size_t{f} + 1]],
                    cell_uv_[mesh_.faces[3 * size_t{f} + 2]], col, row, &b)) {
    return absl::NotFoundError("a cell on a degenerate face");
  }
  return ClampedFacePoint(f, b);
}

}  // namespace geodex::terrain
