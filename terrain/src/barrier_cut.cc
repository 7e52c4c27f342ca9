#include "barrier_cut.h"

#include <geos_c.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/str_cat.h"
#include "ogr_geometry.h"

namespace geodex::terrain {
namespace {

using Point2 = std::array<double, 2>;
constexpr uint32_t kInterior = 0xffffffffu;

double Cross(const Point2& o, const Point2& a, const Point2& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

// One GEOS context for the cut, and geometries owned by it.
class Geos {
 public:
  Geos() : h_(GEOS_init_r()) {}
  ~Geos() { GEOS_finish_r(h_); }
  Geos(const Geos&) = delete;
  Geos& operator=(const Geos&) = delete;
  GEOSContextHandle_t h() const { return h_; }

  struct Free {
    GEOSContextHandle_t h;
    void operator()(GEOSGeometry* g) const { GEOSGeom_destroy_r(h, g); }
  };
  using Ptr = std::unique_ptr<GEOSGeometry, Free>;
  Ptr Own(GEOSGeometry* g) const { return Ptr(g, Free{h_}); }

  // A closed ring from `points` (not closed).
  GEOSGeometry* Ring(const std::vector<Point2>& points) const {
    GEOSCoordSequence* seq = GEOSCoordSeq_create_r(h_, static_cast<unsigned>(points.size() + 1), 2);
    for (size_t i = 0; i <= points.size(); ++i) {
      const Point2& p = points[i % points.size()];
      GEOSCoordSeq_setXY_r(h_, seq, static_cast<unsigned>(i), p[0], p[1]);
    }
    return GEOSGeom_createLinearRing_r(h_, seq);
  }
  Ptr Polygon(const std::vector<std::vector<Point2>>& rings) const {
    std::vector<GEOSGeometry*> holes;
    for (size_t r = 1; r < rings.size(); ++r) holes.push_back(Ring(rings[r]));
    return Own(GEOSGeom_createPolygon_r(h_, Ring(rings[0]), holes.data(), static_cast<unsigned>(holes.size())));
  }
  // The rings of every polygon in `g` (a Polygon, MultiPolygon or collection), each without its
  // closing point.
  std::vector<std::vector<std::vector<Point2>>> Polygons(const GEOSGeometry* g) const {
    std::vector<std::vector<std::vector<Point2>>> out;
    const int type = GEOSGeomTypeId_r(h_, g);
    if (type == GEOS_MULTIPOLYGON || type == GEOS_GEOMETRYCOLLECTION) {
      for (int i = 0; i < GEOSGetNumGeometries_r(h_, g); ++i) {
        auto part = Polygons(GEOSGetGeometryN_r(h_, g, i));
        out.insert(out.end(), part.begin(), part.end());
      }
      return out;
    }
    if (type != GEOS_POLYGON || GEOSisEmpty_r(h_, g) == 1) return out;
    std::vector<std::vector<Point2>> rings;
    auto read = [&](const GEOSGeometry* ring) {
      const GEOSCoordSequence* seq = GEOSGeom_getCoordSeq_r(h_, ring);
      unsigned size = 0;
      GEOSCoordSeq_getSize_r(h_, seq, &size);
      std::vector<Point2> points;
      for (unsigned i = 0; i + 1 < size; ++i) {
        Point2 p;
        GEOSCoordSeq_getXY_r(h_, seq, i, &p[0], &p[1]);
        points.push_back(p);
      }
      rings.push_back(std::move(points));
    };
    read(GEOSGetExteriorRing_r(h_, g));
    for (int i = 0; i < GEOSGetNumInteriorRings_r(h_, g); ++i) read(GEOSGetInteriorRingN_r(h_, g, i));
    out.push_back(std::move(rings));
    return out;
  }

 private:
  GEOSContextHandle_t h_;
};

// A vertex of a piece's ring: a mesh vertex (an original corner or a shared edge point), or a
// point inside the face (kInterior) at `p`.
struct RingVertex {
  uint32_t id = kInterior;
  Point2 p{};
};

struct EdgePoint {
  double t;  // along the edge from its lower vertex id
  uint32_t vertex;
};

uint64_t EdgeKey(uint32_t a, uint32_t b) {
  return (uint64_t{std::min(a, b)} << 32) | std::max(a, b);
}

}  // namespace

absl::StatusOr<MeshData> CutOutPolygons(const MeshData& mesh, const OGRGeometry& polygons, double scale,
                                        double width, CutStats* stats) {
  *stats = CutStats{};
  const size_t n = mesh.vertex_count();
  const size_t faces = mesh.face_count();
  Geos geos;
  GEOSContextHandle_t h = geos.h();

  // Local x y about the middle of the mesh: GEOS's intersections then carry the bits of the
  // offsets from it, not of UTM's millions of metres.
  double lo[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  double hi[2] = {-lo[0], -lo[1]};
  for (size_t v = 0; v < n; ++v) {
    for (int k = 0; k < 2; ++k) {
      lo[k] = std::min(lo[k], mesh.positions[3 * v + k]);
      hi[k] = std::max(hi[k], mesh.positions[3 * v + k]);
    }
  }
  const double origin[2] = {n > 0 ? (lo[0] + hi[0]) / 2 : 0, n > 0 ? (lo[1] + hi[1]) / 2 : 0};
  const double reach = n > 0 ? std::max({hi[0] - lo[0], hi[1] - lo[1], 1e-300}) : 1;
  std::vector<Point2> local(n);
  for (size_t v = 0; v < n; ++v) {
    local[v] = {mesh.positions[3 * v] - origin[0], mesh.positions[3 * v + 1] - origin[1]};
  }

  Geos::Ptr barrier = geos.Own(polygons.exportToGEOS(h));
  if (barrier == nullptr) return absl::InternalError("GEOS cannot take the barrier polygons");
  auto shift = [](double* x, double* y, void* data) {
    const double* o = static_cast<const double*>(data);  // scale, origin x, origin y
    *x = *x * o[0] - o[1];
    *y = *y * o[0] - o[2];
    return 1;
  };
  double frame[3] = {scale, origin[0], origin[1]};
  barrier = geos.Own(GEOSGeom_transformXY_r(h, barrier.get(), shift, frame));
  if (barrier == nullptr) return absl::InternalError("GEOS cannot place the barrier polygons");
  // Polygons as they are (made valid); lines and points buffered into polygons `width` wide.
  std::vector<GEOSGeometry*> parts;  // owned until handed to the collection below
  std::vector<const GEOSGeometry*> flat;
  std::function<void(const GEOSGeometry*)> flatten = [&](const GEOSGeometry* g) {
    const int type = GEOSGeomTypeId_r(h, g);
    if (type == GEOS_GEOMETRYCOLLECTION || type == GEOS_MULTIPOLYGON || type == GEOS_MULTILINESTRING ||
        type == GEOS_MULTIPOINT) {
      for (int i = 0; i < GEOSGetNumGeometries_r(h, g); ++i) flatten(GEOSGetGeometryN_r(h, g, i));
    } else {
      flat.push_back(g);
    }
  };
  flatten(barrier.get());
  for (const GEOSGeometry* g : flat) {
    const int type = GEOSGeomTypeId_r(h, g);
    GEOSGeometry* part = nullptr;
    if (type == GEOS_POLYGON) {
      part = GEOSisValid_r(h, g) == 1 ? GEOSGeom_clone_r(h, g) : GEOSMakeValid_r(h, g);
    } else {
      if (!(width > 0)) {
        for (GEOSGeometry* p : parts) GEOSGeom_destroy_r(h, p);
        return absl::InvalidArgumentError(
            "lines and points are barriers with a width (metres): --barrier-width, barrier.width");
      }
      part = GEOSBuffer_r(h, g, width / 2, 8);
    }
    if (part == nullptr) {
      for (GEOSGeometry* p : parts) GEOSGeom_destroy_r(h, p);
      return absl::InternalError("GEOS cannot make the barrier's polygons");
    }
    parts.push_back(part);
  }
  Geos::Ptr collection = geos.Own(GEOSGeom_createCollection_r(h, GEOS_GEOMETRYCOLLECTION, parts.data(),
                                                              static_cast<unsigned>(parts.size())));
  barrier = geos.Own(collection != nullptr ? GEOSUnaryUnion_r(h, collection.get()) : nullptr);
  if (barrier == nullptr) return absl::InternalError("GEOS cannot merge the barrier's polygons");
  double box[4];  // xmin ymin xmax ymax
  if (GEOSisEmpty_r(h, barrier.get()) == 1 ||
      GEOSGeom_getExtent_r(h, barrier.get(), &box[0], &box[1], &box[2], &box[3]) == 0) {
    return mesh;
  }
  if (!std::all_of(box, box + 4, [](double v) { return std::isfinite(v); })) {
    return absl::InvalidArgumentError("the polygons' coordinates are not finite numbers here");
  }
  const GEOSPreparedGeometry* prepared = GEOSPrepare_r(h, barrier.get());
  if (prepared == nullptr) return absl::InternalError("GEOS cannot prepare the barrier polygons");
  struct PreparedFree {
    GEOSContextHandle_t h;
    const GEOSPreparedGeometry* p;
    ~PreparedFree() { GEOSPreparedGeom_destroy_r(h, p); }
  } prepared_free{h, prepared};

  MeshData out;
  out.positions = mesh.positions;
  absl::flat_hash_map<uint64_t, std::vector<EdgePoint>> edge_points;
  // A point on edge (a, b) at `t` from its lower id: the one already there within 1e-9, or new.
  auto edge_point = [&](uint32_t a, uint32_t b, double t) -> uint32_t {
    const uint32_t low = std::min(a, b), high = std::max(a, b);
    std::vector<EdgePoint>& points = edge_points[EdgeKey(a, b)];
    for (const EdgePoint& e : points) {
      if (std::abs(e.t - t) <= 1e-9) return e.vertex;
    }
    const uint32_t id = static_cast<uint32_t>(out.positions.size() / 3);
    for (int k = 0; k < 3; ++k) {
      const double pl = mesh.positions[3 * size_t{low} + k], ph = mesh.positions[3 * size_t{high} + k];
      out.positions.push_back(pl + t * (ph - pl));
    }
    points.push_back({t, id});
    ++stats->vertices_added;
    return id;
  };
  auto local_of = [&](uint32_t id) -> Point2 {  // any mesh vertex, new ones too
    return {out.positions[3 * size_t{id}] - origin[0], out.positions[3 * size_t{id} + 1] - origin[1]};
  };

  // Pass 1: each face kept, removed, or clipped to its pieces; edge points made once per edge.
  enum class Fate : uint8_t { kKeep, kRemove, kPieces };
  std::vector<Fate> fate(faces, Fate::kKeep);
  absl::flat_hash_map<size_t, std::vector<std::vector<std::vector<RingVertex>>>> pieces_of;
  for (size_t f = 0; f < faces; ++f) {
    const uint32_t* c = &mesh.faces[3 * f];
    if (c[0] >= n || c[1] >= n || c[2] >= n) continue;  // left for TriangleMesh::Build to report
    const Point2 A = local[c[0]], B = local[c[1]], C = local[c[2]];
    if (std::max({A[0], B[0], C[0]}) < box[0] || std::min({A[0], B[0], C[0]}) > box[2] ||
        std::max({A[1], B[1], C[1]}) < box[1] || std::min({A[1], B[1], C[1]}) > box[3]) {
      continue;
    }
    const double area2 = Cross(A, B, C);
    double size2 = 0;
    for (int e = 0; e < 3; ++e) {
      const Point2 &p = local[c[e]], &q = local[c[(e + 1) % 3]];
      size2 = std::max(size2, (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]));
    }
    if (!(std::abs(area2) > 1e-12 * size2)) {  // edge-on from above: by its centre
      Geos::Ptr centre = geos.Own(GEOSGeom_createPointFromXY_r(h, (A[0] + B[0] + C[0]) / 3, (A[1] + B[1] + C[1]) / 3));
      if (GEOSPreparedIntersects_r(h, prepared, centre.get()) == 1) {
        fate[f] = Fate::kRemove;
        ++stats->faces_removed;
      }
      continue;
    }
    Geos::Ptr triangle = geos.Polygon({{A, B, C}});
    if (GEOSPreparedIntersects_r(h, prepared, triangle.get()) != 1) continue;
    if (GEOSPreparedCovers_r(h, prepared, triangle.get()) == 1) {
      fate[f] = Fate::kRemove;
      ++stats->faces_removed;
      continue;
    }
    Geos::Ptr rest = geos.Own(GEOSDifference_r(h, triangle.get(), barrier.get()));
    if (rest == nullptr) return absl::InternalError(absl::StrCat("GEOS cannot cut face ", f));
    auto polygons_left = geos.Polygons(rest.get());
    if (polygons_left.empty()) {
      fate[f] = Fate::kRemove;
      ++stats->faces_removed;
      continue;
    }
    // Classify every ring vertex: a corner (within 2e-6 of the face's size: a DEM's stored mesh
    // tells its cells' vertices from a cut's by that margin, see Dem::FromMesh), a point on one of
    // the face's edges (within 1e-9 of its size: GEOS's rounding), or a point inside.
    const double ulps = 64 * std::numeric_limits<double>::epsilon() * reach;
    const double corner_tolerance = 2e-6 * std::sqrt(size2) + ulps;
    const double tolerance = 1e-9 * std::sqrt(size2) + ulps;
    std::vector<std::vector<std::vector<RingVertex>>> pieces;
    for (const auto& rings : polygons_left) {
      std::vector<std::vector<RingVertex>> piece;
      for (const auto& ring : rings) {
        std::vector<RingVertex> vertices;
        for (const Point2& q : ring) {
          RingVertex rv{kInterior, q};
          for (int k = 0; k < 3 && rv.id == kInterior; ++k) {
            const Point2& corner = local[c[k]];
            if (std::hypot(q[0] - corner[0], q[1] - corner[1]) <= corner_tolerance) rv.id = c[k];
          }
          for (int k = 0; k < 3 && rv.id == kInterior; ++k) {
            const uint32_t a = c[k], b = c[(k + 1) % 3];
            const uint32_t low = std::min(a, b), high = std::max(a, b);
            const Point2 &pl = local[low], &ph = local[high];
            const double dx = ph[0] - pl[0], dy = ph[1] - pl[1], length2 = dx * dx + dy * dy;
            const double t = ((q[0] - pl[0]) * dx + (q[1] - pl[1]) * dy) / length2;
            const double off = std::abs((q[0] - pl[0]) * dy - (q[1] - pl[1]) * dx) / std::sqrt(length2);
            if (off <= tolerance && t > 0 && t < 1) rv.id = edge_point(a, b, t);
          }
          if (rv.id != kInterior) rv.p = local_of(rv.id);
          // Points snapped onto one another are one.
          if (vertices.empty() || rv.id == kInterior || vertices.back().id != rv.id) vertices.push_back(rv);
        }
        while (vertices.size() > 1 && vertices.back().id != kInterior && vertices.back().id == vertices.front().id) {
          vertices.pop_back();
        }
        if (vertices.size() >= 3) {
          piece.push_back(std::move(vertices));
        } else if (piece.empty()) {
          break;  // an outer ring snapped away: a sliver, nothing left of this piece
        }
      }
      if (!piece.empty()) pieces.push_back(std::move(piece));
    }
    if (pieces.empty()) {
      fate[f] = Fate::kRemove;
      ++stats->faces_removed;
      continue;
    }
    bool untouched = pieces.size() == 1 && pieces[0].size() == 1 && pieces[0][0].size() == 3;
    for (const RingVertex& v : pieces[0][0]) untouched &= v.id == c[0] || v.id == c[1] || v.id == c[2];
    if (untouched) continue;  // the barrier only touches it (or takes a sliver below rounding)
    fate[f] = Fate::kPieces;
    // Counted as cut when it loses area beyond rounding; a barrier along its edge only splits it.
    double left = 0;
    GEOSArea_r(h, rest.get(), &left);
    ++(left < (1 - 1e-9) * std::abs(area2) / 2 ? stats->faces_cut : stats->faces_split);
    pieces_of[f] = std::move(pieces);
  }

  // Pass 2: pieces (and whole faces with points on their edges) triangulated with every edge
  // point in their boundary, so that neighbours share their edges piece for piece.
  auto on_edge = [&](const RingVertex& v, uint32_t a, uint32_t b, double* t) {
    const uint32_t low = std::min(a, b);
    if (v.id == a || v.id == b) {
      *t = v.id == low ? 0.0 : 1.0;
      return true;
    }
    auto it = edge_points.find(EdgeKey(a, b));
    if (it == edge_points.end() || v.id == kInterior) return false;
    for (const EdgePoint& e : it->second) {
      if (e.vertex == v.id) {
        *t = e.t;
        return true;
      }
    }
    return false;
  };
  for (size_t f = 0; f < faces; ++f) {
    const uint32_t* c = &mesh.faces[3 * f];
    if (fate[f] == Fate::kRemove) continue;
    bool has_points = false;
    if (fate[f] == Fate::kKeep) {
      if (c[0] < n && c[1] < n && c[2] < n) {
        for (int k = 0; k < 3; ++k) has_points |= edge_points.contains(EdgeKey(c[k], c[(k + 1) % 3]));
      }
      if (!has_points) {
        out.faces.insert(out.faces.end(), c, c + 3);
        continue;
      }
      ++stats->faces_split;
    }
    std::vector<std::vector<std::vector<RingVertex>>> whole;
    if (fate[f] == Fate::kKeep) {
      whole.push_back({{RingVertex{c[0], local[c[0]]}, RingVertex{c[1], local[c[1]]}, RingVertex{c[2], local[c[2]]}}});
    }
    const auto& pieces = fate[f] == Fate::kKeep ? whole : pieces_of[f];
    // The ids of the face's points by their exact coordinates (what the triangulation returns);
    // pieces touching at a point inside the face share it.
    absl::flat_hash_map<std::pair<uint64_t, uint64_t>, uint32_t> id_of;
    auto key = [](const Point2& p) {
      uint64_t x, y;
      std::memcpy(&x, &p[0], 8);
      std::memcpy(&y, &p[1], 8);
      return std::make_pair(x, y);
    };
    const double area2 = Cross(local[c[0]], local[c[1]], local[c[2]]);
    for (const auto& piece : pieces) {
      // Each ring with the edge points that lie between two of its vertices on one mesh edge.
      std::vector<std::vector<RingVertex>> rings;
      for (const auto& ring : piece) {
        std::vector<RingVertex> grown;
        for (size_t i = 0; i < ring.size(); ++i) {
          const RingVertex &p = ring[i], &q = ring[(i + 1) % ring.size()];
          if (grown.empty() || grown.back().id != p.id || p.id == kInterior) grown.push_back(p);
          for (int k = 0; k < 3; ++k) {
            const uint32_t a = c[k], b = c[(k + 1) % 3];
            double tp, tq;
            if (!on_edge(p, a, b, &tp) || !on_edge(q, a, b, &tq)) continue;
            auto it = edge_points.find(EdgeKey(a, b));
            if (it == edge_points.end()) break;
            std::vector<EdgePoint> between;
            for (const EdgePoint& e : it->second) {
              if (e.t > std::min(tp, tq) && e.t < std::max(tp, tq)) between.push_back(e);
            }
            std::sort(between.begin(), between.end(), [&](const EdgePoint& x, const EdgePoint& y) {
              return tp < tq ? x.t < y.t : x.t > y.t;
            });
            for (const EdgePoint& e : between) grown.push_back({e.vertex, local_of(e.vertex)});
            break;
          }
        }
        while (grown.size() > 1 && grown.back().id != kInterior && grown.back().id == grown.front().id) grown.pop_back();
        if (grown.size() >= 3) rings.push_back(std::move(grown));
      }
      if (rings.empty()) continue;
      std::vector<std::vector<Point2>> coordinates;
      for (const auto& ring : rings) {
        std::vector<Point2> points;
        for (const RingVertex& v : ring) {
          id_of.emplace(key(v.p), v.id);
          points.push_back(v.p);
        }
        coordinates.push_back(std::move(points));
      }
      Geos::Ptr polygon = geos.Polygon(coordinates);
      Geos::Ptr triangles = geos.Own(polygon != nullptr ? GEOSConstrainedDelaunayTriangulation_r(h, polygon.get()) : nullptr);
      if (triangles == nullptr) return absl::InternalError(absl::StrCat("GEOS cannot triangulate what is left of face ", f));
      for (const auto& t : geos.Polygons(triangles.get())) {
        if (t.empty() || t[0].size() != 3) continue;
        std::array<uint32_t, 3> ids{};
        for (int k = 0; k < 3; ++k) {
          const Point2& q = t[0][k];
          auto it = id_of.find(key(q));
          uint32_t id = it != id_of.end() ? it->second : kInterior;
          if (id == kInterior) {  // a point inside the face: on its plane, made once
            const Point2 &A = local[c[0]], &B = local[c[1]], &C = local[c[2]];
            const double s = Cross(A, q, C) / Cross(A, B, C), u = Cross(A, B, q) / Cross(A, B, C);
            id = static_cast<uint32_t>(out.positions.size() / 3);
            for (int d = 0; d < 3; ++d) {
              const double pa = mesh.positions[3 * size_t{c[0]} + d];
              out.positions.push_back(pa + s * (mesh.positions[3 * size_t{c[1]} + d] - pa) +
                                      u * (mesh.positions[3 * size_t{c[2]} + d] - pa));
            }
            ++stats->vertices_added;
            id_of[key(q)] = id;
          }
          ids[k] = id;
        }
        const double turn = Cross(local_of(ids[0]), local_of(ids[1]), local_of(ids[2]));
        if (turn == 0) continue;
        if ((turn > 0) != (area2 > 0)) std::swap(ids[1], ids[2]);  // the face's own winding
        out.faces.insert(out.faces.end(), ids.begin(), ids.end());
      }
    }
  }
  return out;
}

}  // namespace geodex::terrain
