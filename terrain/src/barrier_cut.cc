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
#include "geodex/limits.h"
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
    return Own(GEOSGeom_createPolygon_r(h_, Ring(rings[0]), holes.data(),
                                        static_cast<unsigned>(holes.size())));
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
    for (int i = 0; i < GEOSGetNumInteriorRings_r(h_, g); ++i)
      read(GEOSGetInteriorRingN_r(h_, g, i));
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

using Pieces = std::vector<std::vector<std::vector<RingVertex>>>;  // polygons, rings, vertices
enum class Fate : uint8_t { kKeep, kRemove, kPieces };

// One surgery on a mesh: faces kept, removed, or replaced by pieces (polygons in the face, their
// vertices the face's corners, points on its edges, or points inside it), then the pieces
// triangulated with every point their neighbours put on shared edges.
class Surgery {
 public:
  Surgery(const MeshData& mesh, const Geos& geos, const double origin[2], double reach,
          uint64_t max_vertices, CutStats* stats)
      : mesh_(mesh),
        geos_(geos),
        h_(geos.h()),
        reach_(reach),
        max_vertices_(max_vertices),
        stats_(stats),
        fate_(mesh.face_count(), Fate::kKeep) {
    origin_[0] = origin[0];
    origin_[1] = origin[1];
    out_.positions = mesh.positions;
    local_.resize(mesh.vertex_count());
    for (size_t v = 0; v < local_.size(); ++v) local_[v] = LocalOf(static_cast<uint32_t>(v));
  }

  const MeshData& mesh() const { return mesh_; }
  const Point2& local(uint32_t v) const { return local_[v]; }
  bool Valid(const uint32_t* c) const {
    const size_t n = mesh_.vertex_count();
    return c[0] < n && c[1] < n && c[2] < n;
  }
  static double SizeSquared(const Point2& A, const Point2& B, const Point2& C) {
    double size2 = 0;
    for (const auto& [p, q] : {std::pair{A, B}, std::pair{B, C}, std::pair{C, A}}) {
      size2 = std::max(size2, (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]));
    }
    return size2;
  }
  void Remove(size_t f) {
    fate_[f] = Fate::kRemove;
    ++stats_->faces_removed;
  }

  // The rings of `polygons` (what is left of face f, or its parts) as ring vertices: a corner
  // (within 2e-6 of the face's size: a DEM's stored mesh tells its cells' vertices from a cut's by
  // that margin, see Dem::FromMesh), a point on one of the face's edges (within 1e-9 of its size:
  // GEOS's rounding), or a point inside. Points snapped onto one another are one; a ring snapped
  // to fewer than 3 points goes (a sliver below rounding). Empty when nothing is left.
  Pieces Classify(size_t f, const std::vector<std::vector<std::vector<Point2>>>& polygons) {
    const uint32_t* c = &mesh_.faces[3 * f];
    const double size = std::sqrt(SizeSquared(local_[c[0]], local_[c[1]], local_[c[2]]));
    const double ulps = 64 * std::numeric_limits<double>::epsilon() * reach_;
    const double corner_tolerance = 2e-6 * size + ulps;
    const double tolerance = 1e-9 * size + ulps;
    Pieces pieces;
    for (const auto& rings : polygons) {
      std::vector<std::vector<RingVertex>> piece;
      for (const auto& ring : rings) {
        std::vector<RingVertex> vertices;
        for (const Point2& q : ring) {
          RingVertex rv{kInterior, q};
          for (int k = 0; k < 3 && rv.id == kInterior; ++k) {
            const Point2& corner = local_[c[k]];
            if (std::hypot(q[0] - corner[0], q[1] - corner[1]) <= corner_tolerance) rv.id = c[k];
          }
          for (int k = 0; k < 3 && rv.id == kInterior; ++k) {
            const uint32_t a = c[k], b = c[(k + 1) % 3];
            const Point2 &pl = local_[std::min(a, b)], &ph = local_[std::max(a, b)];
            const double dx = ph[0] - pl[0], dy = ph[1] - pl[1], length2 = dx * dx + dy * dy;
            const double t = ((q[0] - pl[0]) * dx + (q[1] - pl[1]) * dy) / length2;
            const double off =
                std::abs((q[0] - pl[0]) * dy - (q[1] - pl[1]) * dx) / std::sqrt(length2);
            if (off <= tolerance && t > 0 && t < 1) rv.id = EdgePoint(a, b, t);
          }
          if (rv.id != kInterior) rv.p = LocalOf(rv.id);
          if (vertices.empty() || rv.id == kInterior || vertices.back().id != rv.id)
            vertices.push_back(rv);
        }
        while (vertices.size() > 1 && vertices.back().id != kInterior &&
               vertices.back().id == vertices.front().id) {
          vertices.pop_back();
        }
        if (vertices.size() >= 3) {
          piece.push_back(std::move(vertices));
        } else if (piece.empty()) {
          break;  // the outer ring snapped away
        }
      }
      if (!piece.empty()) pieces.push_back(std::move(piece));
    }
    return pieces;
  }
  // True when `pieces` are face f itself, untouched (its three corners and nothing else).
  bool Untouched(size_t f, const Pieces& pieces) const {
    const uint32_t* c = &mesh_.faces[3 * f];
    if (pieces.size() != 1 || pieces[0].size() != 1 || pieces[0][0].size() != 3) return false;
    for (const RingVertex& v : pieces[0][0]) {
      if (v.id != c[0] && v.id != c[1] && v.id != c[2]) return false;
    }
    return true;
  }
  void SetPieces(size_t f, Pieces pieces) {
    fate_[f] = Fate::kPieces;
    pieces_of_[f] = std::move(pieces);
  }

  // Pass 2: the faces out, pieces (and whole faces with points on their edges) triangulated by
  // GEOS's constrained Delaunay triangulation with every edge point in their boundary, so that
  // neighbours share their edges piece for piece. `*pieces_made` lists the faces made from pieces.
  // More vertices than the budget (or than 32-bit ids hold): ResourceExhausted naming
  // --max_vertices.
  absl::Status CheckBudget() const {
    const uint64_t n = out_.positions.size() / 3;
    if ((max_vertices_ != 0 && n > max_vertices_) || n >= kInterior) {
      return LimitExceededError(
          Limit::kVertices,
          absl::StrCat("the barrier's cut makes more than ",
                       max_vertices_ != 0 ? max_vertices_ : uint64_t{kInterior}, " vertices"));
    }
    return absl::OkStatus();
  }

  absl::StatusOr<MeshData> Emit(std::vector<uint32_t>* pieces_made) {
    if (absl::Status budget = CheckBudget(); !budget.ok()) return budget;
    for (size_t f = 0; f < mesh_.face_count(); ++f) {
      const uint32_t* c = &mesh_.faces[3 * f];
      if (fate_[f] == Fate::kRemove) continue;
      if ((f & 1023) == 0) {
        if (absl::Status budget = CheckBudget(); !budget.ok()) return budget;
      }
      if (fate_[f] == Fate::kKeep) {
        bool has_points = false;
        if (Valid(c)) {
          for (int k = 0; k < 3; ++k)
            has_points |= edge_points_.contains(EdgeKey(c[k], c[(k + 1) % 3]));
        }
        if (!has_points) {
          out_.faces.insert(out_.faces.end(), c, c + 3);
          continue;
        }
        ++stats_->faces_split;
        const double area2 = Cross(local_[c[0]], local_[c[1]], local_[c[2]]);
        if (!(std::abs(area2) > 1e-12 * SizeSquared(local_[c[0]], local_[c[1]], local_[c[2]]))) {
          FanFromCentre(f, pieces_made);  // edge-on from above: no triangulation in x-y
          continue;
        }
        Pieces whole = {{{RingVertex{c[0], local_[c[0]]}, RingVertex{c[1], local_[c[1]]},
                          RingVertex{c[2], local_[c[2]]}}}};
        if (absl::Status s = Triangulate(f, whole, pieces_made); !s.ok()) return s;
        continue;
      }
      if (absl::Status s = Triangulate(f, pieces_of_[f], pieces_made); !s.ok()) return s;
    }
    return std::move(out_);
  }

 private:
  Point2 LocalOf(uint32_t id) const {  // any mesh vertex, new ones too
    return {out_.positions[3 * size_t{id}] - origin_[0],
            out_.positions[3 * size_t{id} + 1] - origin_[1]};
  }
  // A point on edge (a, b) at `t` from its lower id: the one already there within 1e-9, or new.
  uint32_t EdgePoint(uint32_t a, uint32_t b, double t) {
    const uint32_t low = std::min(a, b), high = std::max(a, b);
    std::vector<struct EdgePoint>& points = edge_points_[EdgeKey(a, b)];
    for (const struct EdgePoint& e : points) {
      if (std::abs(e.t - t) <= 1e-9) return e.vertex;
    }
    const uint32_t id = static_cast<uint32_t>(out_.positions.size() / 3);
    for (int k = 0; k < 3; ++k) {
      const double pl = mesh_.positions[3 * size_t{low} + k],
                   ph = mesh_.positions[3 * size_t{high} + k];
      out_.positions.push_back(pl + t * (ph - pl));
    }
    points.push_back({t, id});
    ++stats_->vertices_added;
    return id;
  }
  // Is ring vertex `v` on edge (a, b)? Its parameter from the lower id in *t.
  bool OnEdge(const RingVertex& v, uint32_t a, uint32_t b, double* t) const {
    if (v.id == a || v.id == b) {
      *t = v.id == std::min(a, b) ? 0.0 : 1.0;
      return true;
    }
    auto it = edge_points_.find(EdgeKey(a, b));
    if (it == edge_points_.end() || v.id == kInterior) return false;
    for (const struct EdgePoint& e : it->second) {
      if (e.vertex == v.id) {
        *t = e.t;
        return true;
      }
    }
    return false;
  }

  // A face seen edge-on from above (a vertical wall) that its neighbours put points on: a fan
  // from a new vertex at its centre through its corners and those points, in its own winding.
  void FanFromCentre(size_t f, std::vector<uint32_t>* pieces_made) {
    const uint32_t* c = &mesh_.faces[3 * f];
    std::vector<uint32_t> ring;
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = c[k], b = c[(k + 1) % 3];
      ring.push_back(a);
      auto it = edge_points_.find(EdgeKey(a, b));
      if (it == edge_points_.end()) continue;
      std::vector<struct EdgePoint> along = it->second;
      const bool forward = a < b;  // t runs from the lower id
      std::sort(along.begin(), along.end(),
                [&](const struct EdgePoint& x, const struct EdgePoint& y) {
                  return forward ? x.t < y.t : x.t > y.t;
                });
      for (const struct EdgePoint& e : along) ring.push_back(e.vertex);
    }
    const uint32_t centre = static_cast<uint32_t>(out_.positions.size() / 3);
    for (int d = 0; d < 3; ++d) {
      out_.positions.push_back((mesh_.positions[3 * size_t{c[0]} + d] +
                                mesh_.positions[3 * size_t{c[1]} + d] +
                                mesh_.positions[3 * size_t{c[2]} + d]) /
                               3);
    }
    ++stats_->vertices_added;
    for (size_t i = 0; i < ring.size(); ++i) {
      if (pieces_made != nullptr) pieces_made->push_back(static_cast<uint32_t>(out_.face_count()));
      out_.faces.insert(out_.faces.end(), {centre, ring[i], ring[(i + 1) % ring.size()]});
    }
  }

  absl::Status Triangulate(size_t f, const Pieces& pieces, std::vector<uint32_t>* pieces_made) {
    const uint32_t* c = &mesh_.faces[3 * f];
    const double area2 = Cross(local_[c[0]], local_[c[1]], local_[c[2]]);
    // The ids of the face's points by their exact coordinates (what the triangulation returns);
    // pieces touching at a point inside the face share it.
    absl::flat_hash_map<std::pair<uint64_t, uint64_t>, uint32_t> id_of;
    auto key = [](const Point2& p) {
      uint64_t x, y;
      std::memcpy(&x, &p[0], 8);
      std::memcpy(&y, &p[1], 8);
      return std::make_pair(x, y);
    };
    for (const auto& piece : pieces) {
      // Each ring with the edge points that lie between two of its vertices on one mesh edge.
      std::vector<std::vector<Point2>> coordinates;
      for (const auto& ring : piece) {
        std::vector<RingVertex> grown;
        for (size_t i = 0; i < ring.size(); ++i) {
          const RingVertex &p = ring[i], &q = ring[(i + 1) % ring.size()];
          if (grown.empty() || grown.back().id != p.id || p.id == kInterior) grown.push_back(p);
          for (int k = 0; k < 3; ++k) {
            const uint32_t a = c[k], b = c[(k + 1) % 3];
            double tp, tq;
            if (!OnEdge(p, a, b, &tp) || !OnEdge(q, a, b, &tq)) continue;
            auto it = edge_points_.find(EdgeKey(a, b));
            if (it == edge_points_.end()) break;
            std::vector<struct EdgePoint> between;
            for (const struct EdgePoint& e : it->second) {
              if (e.t > std::min(tp, tq) && e.t < std::max(tp, tq)) between.push_back(e);
            }
            std::sort(between.begin(), between.end(),
                      [&](const struct EdgePoint& x, const struct EdgePoint& y) {
                        return tp < tq ? x.t < y.t : x.t > y.t;
                      });
            for (const struct EdgePoint& e : between)
              grown.push_back({e.vertex, LocalOf(e.vertex)});
            break;
          }
        }
        while (grown.size() > 1 && grown.back().id != kInterior &&
               grown.back().id == grown.front().id)
          grown.pop_back();
        if (grown.size() < 3) continue;
        std::vector<Point2> points;
        for (const RingVertex& v : grown) {
          id_of.emplace(key(v.p), v.id);
          points.push_back(v.p);
        }
        coordinates.push_back(std::move(points));
      }
      if (coordinates.empty()) continue;
      Geos::Ptr polygon = geos_.Polygon(coordinates);
      Geos::Ptr triangles = geos_.Own(
          polygon != nullptr ? GEOSConstrainedDelaunayTriangulation_r(h_, polygon.get()) : nullptr);
      if (triangles == nullptr)
        return absl::InternalError(
            absl::StrCat("GEOS cannot triangulate what is left of face ", f));
      for (const auto& t : geos_.Polygons(triangles.get())) {
        if (t.empty() || t[0].size() != 3) continue;
        std::array<uint32_t, 3> ids{};
        for (int k = 0; k < 3; ++k) {
          const Point2& q = t[0][k];
          auto it = id_of.find(key(q));
          uint32_t id = it != id_of.end() ? it->second : kInterior;
          if (id == kInterior) {  // a point inside the face: on its plane, made once
            const Point2 &A = local_[c[0]], &B = local_[c[1]], &C = local_[c[2]];
            const double s = Cross(A, q, C) / Cross(A, B, C), u = Cross(A, B, q) / Cross(A, B, C);
            id = static_cast<uint32_t>(out_.positions.size() / 3);
            for (int d = 0; d < 3; ++d) {
              const double pa = mesh_.positions[3 * size_t{c[0]} + d];
              out_.positions.push_back(pa + s * (mesh_.positions[3 * size_t{c[1]} + d] - pa) +
                                       u * (mesh_.positions[3 * size_t{c[2]} + d] - pa));
            }
            ++stats_->vertices_added;
            id_of[key(q)] = id;
          }
          ids[k] = id;
        }
        const double turn = Cross(LocalOf(ids[0]), LocalOf(ids[1]), LocalOf(ids[2]));
        if (turn == 0) continue;
        if ((turn > 0) != (area2 > 0)) std::swap(ids[1], ids[2]);  // the face's own winding
        if (pieces_made != nullptr)
          pieces_made->push_back(static_cast<uint32_t>(out_.face_count()));
        out_.faces.insert(out_.faces.end(), ids.begin(), ids.end());
      }
    }
    return absl::OkStatus();
  }

  const MeshData& mesh_;
  const Geos& geos_;
  GEOSContextHandle_t h_;
  double origin_[2];
  double reach_;
  uint64_t max_vertices_;
  CutStats* stats_;
  std::vector<Point2> local_;
  MeshData out_;
  std::vector<Fate> fate_;
  absl::flat_hash_map<size_t, Pieces> pieces_of_;
  absl::flat_hash_map<uint64_t, std::vector<struct EdgePoint>> edge_points_;
};

struct PreparedGeometry {
  GEOSContextHandle_t h;
  const GEOSPreparedGeometry* p;
  PreparedGeometry(GEOSContextHandle_t context, const GEOSGeometry* g)
      : h(context), p(GEOSPrepare_r(context, g)) {}
  ~PreparedGeometry() {
    if (p != nullptr) GEOSPreparedGeom_destroy_r(h, p);
  }
  PreparedGeometry(const PreparedGeometry&) = delete;
  PreparedGeometry& operator=(const PreparedGeometry&) = delete;
};

bool BoxesMiss(const Point2& A, const Point2& B, const Point2& C, const double box[4]) {
  return std::max({A[0], B[0], C[0]}) < box[0] || std::min({A[0], B[0], C[0]}) > box[2] ||
         std::max({A[1], B[1], C[1]}) < box[1] || std::min({A[1], B[1], C[1]}) > box[3];
}

// The polygons (valid, unioned) cut out of `mesh`.
absl::StatusOr<MeshData> CutPolygons(const MeshData& mesh, const Geos& geos,
                                     const GEOSGeometry* barrier, const double origin[2],
                                     double reach, uint64_t max_vertices, CutStats* stats) {
  GEOSContextHandle_t h = geos.h();
  double box[4];  // xmin ymin xmax ymax
  if (GEOSisEmpty_r(h, barrier) == 1 ||
      GEOSGeom_getExtent_r(h, barrier, &box[0], &box[1], &box[2], &box[3]) == 0) {
    return mesh;
  }
  PreparedGeometry prepared(h, barrier);
  if (prepared.p == nullptr) return absl::InternalError("GEOS cannot prepare the barrier polygons");
  Surgery surgery(mesh, geos, origin, reach, max_vertices, stats);
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    const uint32_t* c = &mesh.faces[3 * f];
    if (!surgery.Valid(c)) continue;  // left for TriangleMesh::Build to report
    const Point2 A = surgery.local(c[0]), B = surgery.local(c[1]), C = surgery.local(c[2]);
    if (BoxesMiss(A, B, C, box)) continue;
    const double area2 = Cross(A, B, C);
    if (!(std::abs(area2) >
          1e-12 * Surgery::SizeSquared(A, B, C))) {  // edge-on from above: by its centre
      Geos::Ptr centre = geos.Own(
          GEOSGeom_createPointFromXY_r(h, (A[0] + B[0] + C[0]) / 3, (A[1] + B[1] + C[1]) / 3));
      if (GEOSPreparedIntersects_r(h, prepared.p, centre.get()) == 1) surgery.Remove(f);
      continue;
    }
    Geos::Ptr triangle = geos.Polygon({{A, B, C}});
    if (GEOSPreparedIntersects_r(h, prepared.p, triangle.get()) != 1) continue;
    if (GEOSPreparedCovers_r(h, prepared.p, triangle.get()) == 1) {
      surgery.Remove(f);
      continue;
    }
    Geos::Ptr rest = geos.Own(GEOSDifference_r(h, triangle.get(), barrier));
    if (rest == nullptr) return absl::InternalError(absl::StrCat("GEOS cannot cut face ", f));
    Pieces pieces = surgery.Classify(f, geos.Polygons(rest.get()));
    if (pieces.empty()) {
      surgery.Remove(f);
      continue;
    }
    if (surgery.Untouched(f, pieces))
      continue;  // the barrier only touches it (or takes a sliver below rounding)
    // Counted as cut when it loses area beyond rounding; a barrier along its edge only splits it.
    double left = 0;
    GEOSArea_r(h, rest.get(), &left);
    ++(left < (1 - 1e-9) * std::abs(area2) / 2 ? stats->faces_cut : stats->faces_split);
    surgery.SetPieces(f, std::move(pieces));
  }
  return surgery.Emit(nullptr);
}

// A line barrier's end and the direction it arrives in.
struct LineEnd {
  Point2 at, direction;
};

// The lines cut into `mesh` as slits: each face a line crosses is split along it (a line that
// ends inside a face is joined to one of the face's corners there, by an ordinary edge), and
// then every vertex on a line (but its ends) is split into one copy per side, so that the two
// sides of a line share no vertex and no edge: paths go around the line's ends.
// With `slit` false it stops once the faces are split (friction outlines: both sides stay joined).
absl::StatusOr<MeshData> SlitLines(const MeshData& mesh, const Geos& geos,
                                   const GEOSGeometry* lines, const std::vector<LineEnd>& ends,
                                   const double origin[2], double reach, uint64_t max_vertices,
                                   CutStats* stats, bool slit = true) {
  GEOSContextHandle_t h = geos.h();
  double box[4];
  if (GEOSisEmpty_r(h, lines) == 1 ||
      GEOSGeom_getExtent_r(h, lines, &box[0], &box[1], &box[2], &box[3]) == 0) {
    return mesh;
  }
  PreparedGeometry prepared(h, lines);
  if (prepared.p == nullptr) return absl::InternalError("GEOS cannot prepare the barrier lines");
  Surgery surgery(mesh, geos, origin, reach, max_vertices, stats);
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    const uint32_t* c = &mesh.faces[3 * f];
    if (!surgery.Valid(c)) continue;
    const Point2 A = surgery.local(c[0]), B = surgery.local(c[1]), C = surgery.local(c[2]);
    if (BoxesMiss(A, B, C, box)) continue;
    const double area2 = Cross(A, B, C);
    if (!(std::abs(area2) > 1e-12 * Surgery::SizeSquared(A, B, C))) continue;  // edge-on: not slit
    Geos::Ptr triangle = geos.Polygon({{A, B, C}});
    if (GEOSPreparedIntersects_r(h, prepared.p, triangle.get()) != 1) continue;
    Geos::Ptr inside = geos.Own(GEOSIntersection_r(h, lines, triangle.get()));
    if (inside == nullptr)
      return absl::InternalError(absl::StrCat("GEOS cannot clip the lines to face ", f));
    double length = 0;
    GEOSLength_r(h, inside.get(), &length);
    if (!(length > 0)) continue;  // touches at a point only
    // The lines' pieces in the face, their ends on its edges put exactly on them (GEOS's
    // intersections are off by rounding, and would then not split the face), and the triangle's
    // boundary with those points in it.
    const double size = std::sqrt(Surgery::SizeSquared(A, B, C));
    const double tolerance = 1e-9 * size + 64 * std::numeric_limits<double>::epsilon() * reach;
    const Point2 corners[3] = {A, B, C};
    std::vector<std::pair<double, Point2>> on_edge[3];  // (t, point) per edge
    std::vector<GEOSGeometry*> linework;
    auto snap = [&](Point2 q) {
      for (const Point2& corner : corners) {
        if (std::hypot(q[0] - corner[0], q[1] - corner[1]) <= tolerance) return corner;
      }
      for (int k = 0; k < 3; ++k) {
        const Point2 &a = corners[k], &b = corners[(k + 1) % 3];
        const double dx = b[0] - a[0], dy = b[1] - a[1], length2 = dx * dx + dy * dy;
        const double t = ((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / length2;
        const double off = std::abs((q[0] - a[0]) * dy - (q[1] - a[1]) * dx) / std::sqrt(length2);
        if (off <= tolerance && t > 0 && t < 1) {
          q = {a[0] + t * dx, a[1] + t * dy};
          on_edge[k].push_back({t, q});
          return q;
        }
      }
      return q;
    };
    std::function<void(const GEOSGeometry*)> add_pieces = [&](const GEOSGeometry* g) {
      const int type = GEOSGeomTypeId_r(h, g);
      if (type == GEOS_MULTILINESTRING || type == GEOS_GEOMETRYCOLLECTION) {
        for (int i = 0; i < GEOSGetNumGeometries_r(h, g); ++i)
          add_pieces(GEOSGetGeometryN_r(h, g, i));
        return;
      }
      if (type != GEOS_LINESTRING) return;
      const GEOSCoordSequence* seq = GEOSGeom_getCoordSeq_r(h, g);
      unsigned size = 0;
      GEOSCoordSeq_getSize_r(h, seq, &size);
      if (size < 2) return;
      GEOSCoordSequence* copy = GEOSCoordSeq_create_r(h, size, 2);
      for (unsigned i = 0; i < size; ++i) {
        Point2 q;
        GEOSCoordSeq_getXY_r(h, seq, i, &q[0], &q[1]);
        if (i == 0 || i + 1 == size) q = snap(q);
        GEOSCoordSeq_setXY_r(h, copy, i, q[0], q[1]);
      }
      linework.push_back(GEOSGeom_createLineString_r(h, copy));
    };
    add_pieces(inside.get());
    std::vector<Point2> ring;
    for (int k = 0; k < 3; ++k) {
      ring.push_back(corners[k]);
      std::sort(on_edge[k].begin(), on_edge[k].end(),
                [](const auto& x, const auto& y) { return x.first < y.first; });
      for (const auto& [t, q] : on_edge[k]) ring.push_back(q);
    }
    ring.push_back(corners[0]);
    GEOSCoordSequence* boundary = GEOSCoordSeq_create_r(h, static_cast<unsigned>(ring.size()), 2);
    for (size_t i = 0; i < ring.size(); ++i)
      GEOSCoordSeq_setXY_r(h, boundary, static_cast<unsigned>(i), ring[i][0], ring[i][1]);
    linework.push_back(GEOSGeom_createLineString_r(h, boundary));
    // A line ending inside the face is joined to the face's corner most across it by an ordinary
    // edge, so that the face splits there and its end is a vertex (a straight continuation would
    // leave the end a flat point of a longer edge, which GEOS drops).
    const double sign = area2 > 0 ? 1 : -1;
    for (const LineEnd& e : ends) {
      const double inner =
          std::min({Cross(A, B, e.at) * sign, Cross(B, C, e.at) * sign, Cross(C, A, e.at) * sign});
      if (!(inner > 1e-9 * std::abs(area2))) continue;  // not strictly inside this face
      const Point2* corner = nullptr;
      double across = -1;
      for (const Point2* q : {&A, &B, &C}) {
        const double dx = (*q)[0] - e.at[0], dy = (*q)[1] - e.at[1];
        const double sine =
            std::abs(e.direction[0] * dy - e.direction[1] * dx) / std::hypot(dx, dy);
        if (sine > across) {
          across = sine;
          corner = q;
        }
      }
      GEOSCoordSequence* seq = GEOSCoordSeq_create_r(h, 2, 2);
      GEOSCoordSeq_setXY_r(h, seq, 0, e.at[0], e.at[1]);
      GEOSCoordSeq_setXY_r(h, seq, 1, (*corner)[0], (*corner)[1]);
      linework.push_back(GEOSGeom_createLineString_r(h, seq));
    }
    Geos::Ptr all = geos.Own(GEOSGeom_createCollection_r(
        h, GEOS_GEOMETRYCOLLECTION, linework.data(), static_cast<unsigned>(linework.size())));
    Geos::Ptr noded = geos.Own(all != nullptr ? GEOSUnaryUnion_r(h, all.get()) : nullptr);
    const GEOSGeometry* noded_ptr = noded.get();
    Geos::Ptr parts = geos.Own(noded != nullptr ? GEOSPolygonize_r(h, &noded_ptr, 1) : nullptr);
    if (parts == nullptr)
      return absl::InternalError(absl::StrCat("GEOS cannot split face ", f, " along the lines"));
    Pieces pieces = surgery.Classify(f, geos.Polygons(parts.get()));
    if (pieces.empty() || surgery.Untouched(f, pieces))
      continue;  // along an edge: the slit is found below
    ++stats->faces_cut;
    surgery.SetPieces(f, std::move(pieces));
  }
  absl::StatusOr<MeshData> split = surgery.Emit(nullptr);
  if (!split.ok() || !slit) return split;
  MeshData& out = *split;

  // The mesh's edges along a line: both ends and the middle within 1e-9 of the edge's length.
  auto local_of = [&](uint32_t v) -> Point2 {
    return {out.positions[3 * size_t{v}] - origin[0], out.positions[3 * size_t{v} + 1] - origin[1]};
  };
  auto near_line = [&](const Point2& p, double tolerance) {
    Geos::Ptr point = geos.Own(GEOSGeom_createPointFromXY_r(h, p[0], p[1]));
    return GEOSPreparedDistanceWithin_r(h, prepared.p, point.get(), tolerance) == 1;
  };
  const double ulps = 64 * std::numeric_limits<double>::epsilon() * reach;
  absl::flat_hash_map<uint32_t, std::vector<uint32_t>> slit_neighbours;
  absl::flat_hash_map<uint64_t, bool> seen;
  const size_t n_out = out.vertex_count();
  for (size_t f = 0; f < out.face_count(); ++f) {
    const uint32_t* c = &out.faces[3 * f];
    if (c[0] >= n_out || c[1] >= n_out || c[2] >= n_out) continue;
    if (BoxesMiss(local_of(c[0]), local_of(c[1]), local_of(c[2]), box)) continue;
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = c[k], b = c[(k + 1) % 3];
      auto [it, fresh] = seen.emplace(EdgeKey(a, b), false);
      if (!fresh) continue;
      const Point2 pa = local_of(a), pb = local_of(b);
      const double tolerance = 1e-9 * std::hypot(pb[0] - pa[0], pb[1] - pa[1]) + ulps;
      if (near_line(pa, tolerance) && near_line(pb, tolerance) &&
          near_line({(pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2}, tolerance)) {
        slit_neighbours[a].push_back(b);
        slit_neighbours[b].push_back(a);
      }
    }
  }
  // Around each vertex on a line, its faces fall into groups joined across edges that are not
  // slits: one group where the line ends (it stays whole), two where a line passes (or leaves the
  // mesh), more where lines cross. Each group past the first gets its own copy of the vertex.
  absl::flat_hash_map<uint32_t, std::vector<std::pair<uint32_t, int>>>
      faces_at;  // vertex -> (face, corner)
  for (size_t f = 0; f < out.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (slit_neighbours.contains(out.faces[3 * f + k]))
        faces_at[out.faces[3 * f + k]].push_back({static_cast<uint32_t>(f), k});
    }
  }
  // In vertex order, so that the copies' ids (and the mesh's id) are the same in every process.
  std::vector<uint32_t> on_lines;
  for (const auto& entry : faces_at) on_lines.push_back(entry.first);
  std::sort(on_lines.begin(), on_lines.end());
  for (const uint32_t v : on_lines) {
    const std::vector<std::pair<uint32_t, int>>& around = faces_at[v];
    const std::vector<uint32_t>& slits = slit_neighbours[v];
    std::vector<size_t> parent(around.size());
    for (size_t i = 0; i < parent.size(); ++i) parent[i] = i;
    std::function<size_t(size_t)> root = [&](size_t i) {
      return parent[i] == i ? i : parent[i] = root(parent[i]);
    };
    absl::flat_hash_map<uint32_t, size_t>
        first_across;  // other end of an edge at v -> a face on it
    for (size_t i = 0; i < around.size(); ++i) {
      const uint32_t* c = &out.faces[3 * size_t{around[i].first}];
      for (uint32_t other : {c[(around[i].second + 1) % 3], c[(around[i].second + 2) % 3]}) {
        if (std::find(slits.begin(), slits.end(), other) != slits.end())
          continue;  // a slit parts them
        auto [it, fresh] = first_across.emplace(other, i);
        if (!fresh) parent[root(i)] = root(it->second);
      }
    }
    absl::flat_hash_map<size_t, uint32_t> copy_of_group;
    const size_t keeper = root(0);
    for (size_t i = 0; i < around.size(); ++i) {
      const size_t group = root(i);
      if (group == keeper) continue;
      auto [copy, fresh] = copy_of_group.emplace(group, 0);
      if (fresh) {
        copy->second = static_cast<uint32_t>(out.vertex_count());
        const double* p = &out.positions[3 * size_t{v}];
        const double position[3] = {p[0], p[1], p[2]};
        out.positions.insert(out.positions.end(), position, position + 3);
        ++stats->vertices_added;
      }
      out.faces[3 * size_t{around[i].first} + around[i].second] = copy->second;
    }
  }
  if ((max_vertices != 0 && out.vertex_count() > max_vertices) || out.vertex_count() >= kInterior) {
    return LimitExceededError(Limit::kVertices,
                              absl::StrCat("the barrier's cut makes ", out.vertex_count(),
                                           " vertices, more than the ", max_vertices, " allowed"));
  }
  return split;
}

// The mesh's local frame and `polygons` in it (times `scale`, less the origin), checked finite.
struct LocalFrame {
  double origin[2];
  double reach;
  Geos::Ptr shape;
};

absl::StatusOr<LocalFrame> InLocalFrame(const MeshData& mesh, const OGRGeometry& polygons,
                                        double scale, const Geos& geos) {
  const size_t n = mesh.vertex_count();
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
  LocalFrame frame{{n > 0 ? (lo[0] + hi[0]) / 2 : 0, n > 0 ? (lo[1] + hi[1]) / 2 : 0},
                   n > 0 ? std::max({hi[0] - lo[0], hi[1] - lo[1], 1e-300}) : 1,
                   geos.Own(nullptr)};
  const double* origin = frame.origin;

  Geos::Ptr barrier = geos.Own(polygons.exportToGEOS(h));
  if (barrier == nullptr) return absl::InternalError("GEOS cannot take the barrier polygons");
  auto shift = [](double* x, double* y, void* data) {
    const double* o = static_cast<const double*>(data);  // scale, origin x, origin y
    if (!std::isfinite(*x) || !std::isfinite(*y))
      return 0;  // every coordinate, not only the extent's
    *x = *x * o[0] - o[1];
    *y = *y * o[0] - o[2];
    return 1;
  };
  double transform[3] = {scale, origin[0], origin[1]};
  barrier = geos.Own(GEOSGeom_transformXY_r(h, barrier.get(), shift, transform));
  if (barrier == nullptr)
    return absl::InvalidArgumentError("the polygons' coordinates are not finite numbers here");
  double extent[4];
  if (GEOSisEmpty_r(h, barrier.get()) != 1 &&
      (GEOSGeom_getExtent_r(h, barrier.get(), &extent[0], &extent[1], &extent[2], &extent[3]) ==
           0 ||
       !std::all_of(extent, extent + 4, [](double v) { return std::isfinite(v); }))) {
    return absl::InvalidArgumentError("the polygons' coordinates are not finite numbers here");
  }
  frame.shape = std::move(barrier);
  return frame;
}

// Every part of `g` that is not a collection.
std::vector<const GEOSGeometry*> Parts(GEOSContextHandle_t h, const GEOSGeometry* g) {
  std::vector<const GEOSGeometry*> flat;
  std::function<void(const GEOSGeometry*)> flatten = [&](const GEOSGeometry* part) {
    const int type = GEOSGeomTypeId_r(h, part);
    if (type == GEOS_GEOMETRYCOLLECTION || type == GEOS_MULTIPOLYGON ||
        type == GEOS_MULTILINESTRING || type == GEOS_MULTIPOINT) {
      for (int i = 0; i < GEOSGetNumGeometries_r(h, part); ++i)
        flatten(GEOSGetGeometryN_r(h, part, i));
    } else {
      flat.push_back(part);
    }
  };
  flatten(g);
  return flat;
}

// A polygon as given when valid; else made valid as areas (shells less holes), collapsed parts
// (spikes) dropped. Null when GEOS fails.
GEOSGeometry* ValidPolygon(GEOSContextHandle_t h, const GEOSGeometry* g) {
  if (GEOSisValid_r(h, g) == 1) return GEOSGeom_clone_r(h, g);
  GEOSMakeValidParams* params = GEOSMakeValidParams_create_r(h);
  GEOSMakeValidParams_setMethod_r(h, params, GEOS_MAKE_VALID_STRUCTURE);
  GEOSMakeValidParams_setKeepCollapsed_r(h, params, 0);
  GEOSGeometry* valid = GEOSMakeValidWithParams_r(h, g, params);
  GEOSMakeValidParams_destroy_r(h, params);
  return valid;
}

}  // namespace

absl::StatusOr<MeshData> CutOutPolygons(const MeshData& mesh, const OGRGeometry& polygons,
                                        double scale, double width, uint64_t max_vertices,
                                        CutStats* stats) {
  *stats = CutStats{};
  Geos geos;
  GEOSContextHandle_t h = geos.h();
  absl::StatusOr<LocalFrame> frame = InLocalFrame(mesh, polygons, scale, geos);
  if (!frame.ok()) return frame.status();
  const double* origin = frame->origin;
  const double reach = frame->reach;
  // Polygons as they are (made valid); with a width, lines and points buffered into polygons that
  // wide; without one, lines are slits and points are refused.
  std::vector<GEOSGeometry*> areas, lines;  // owned until handed to the collections below
  std::vector<LineEnd> ends;
  auto drop = [&] {
    for (GEOSGeometry* p : areas) GEOSGeom_destroy_r(h, p);
    for (GEOSGeometry* p : lines) GEOSGeom_destroy_r(h, p);
  };
  for (const GEOSGeometry* g : Parts(h, frame->shape.get())) {
    const int type = GEOSGeomTypeId_r(h, g);
    GEOSGeometry* part = nullptr;
    if (type == GEOS_POLYGON) {
      part = ValidPolygon(h, g);
    } else if (width > 0) {
      part = GEOSBuffer_r(h, g, width / 2, 8);
    } else if (type == GEOS_LINESTRING) {
      const GEOSCoordSequence* seq = GEOSGeom_getCoordSeq_r(h, g);
      unsigned size = 0;
      GEOSCoordSeq_getSize_r(h, seq, &size);
      std::vector<Point2> p(size);
      for (unsigned i = 0; i < size; ++i) GEOSCoordSeq_getXY_r(h, seq, i, &p[i][0], &p[i][1]);
      p.erase(std::unique(p.begin(), p.end()), p.end());  // a repeated point is no direction
      if (p.size() >= 2) {
        auto end = [&](const Point2& at, const Point2& before) {
          const double dx = at[0] - before[0], dy = at[1] - before[1], l = std::hypot(dx, dy);
          if (l > 0) ends.push_back({at, {dx / l, dy / l}});
        };
        end(p[p.size() - 1], p[p.size() - 2]);
        end(p[0], p[1]);
        lines.push_back(GEOSRemoveRepeatedPoints_r(h, g, 0));  // as the ends were read
      }
      continue;
    } else {
      drop();
      return absl::InvalidArgumentError(
          "points are barriers with a width (metres): --barrier-width, barrier.width");
    }
    if (part == nullptr) {
      drop();
      return absl::InternalError("GEOS cannot make the barrier's polygons");
    }
    areas.push_back(part);
  }
  Geos::Ptr area_collection = geos.Own(GEOSGeom_createCollection_r(
      h, GEOS_GEOMETRYCOLLECTION, areas.data(), static_cast<unsigned>(areas.size())));
  Geos::Ptr line_collection = geos.Own(GEOSGeom_createCollection_r(
      h, GEOS_GEOMETRYCOLLECTION, lines.data(), static_cast<unsigned>(lines.size())));
  Geos::Ptr area =
      geos.Own(area_collection != nullptr ? GEOSUnaryUnion_r(h, area_collection.get()) : nullptr);
  Geos::Ptr line =
      geos.Own(line_collection != nullptr ? GEOSUnaryUnion_r(h, line_collection.get()) : nullptr);
  if (area == nullptr || line == nullptr)
    return absl::InternalError("GEOS cannot merge the barrier's parts");
  absl::StatusOr<MeshData> cut =
      CutPolygons(mesh, geos, area.get(), origin, reach, max_vertices, stats);
  if (!cut.ok() || lines.empty()) return cut;
  return SlitLines(*cut, geos, line.get(), ends, origin, reach, max_vertices, stats);
}

absl::StatusOr<MeshData> SplitAlongOutlines(const MeshData& mesh, const OGRGeometry& polygons,
                                            double scale, uint64_t max_vertices, CutStats* stats) {
  *stats = CutStats{};
  Geos geos;
  GEOSContextHandle_t h = geos.h();
  absl::StatusOr<LocalFrame> frame = InLocalFrame(mesh, polygons, scale, geos);
  if (!frame.ok()) return frame.status();
  // Each polygon's outline (valid: rings that do not cross themselves), all noded into one.
  std::vector<GEOSGeometry*> outlines;  // owned until handed to the collection below
  for (const GEOSGeometry* g : Parts(h, frame->shape.get())) {
    if (GEOSGeomTypeId_r(h, g) != GEOS_POLYGON) {
      for (GEOSGeometry* o : outlines) GEOSGeom_destroy_r(h, o);
      return absl::InvalidArgumentError("friction regions are polygons (a line or point found)");
    }
    Geos::Ptr valid = geos.Own(ValidPolygon(h, g));
    GEOSGeometry* outline = valid != nullptr ? GEOSBoundary_r(h, valid.get()) : nullptr;
    if (outline == nullptr) {
      for (GEOSGeometry* o : outlines) GEOSGeom_destroy_r(h, o);
      return absl::InternalError("GEOS cannot take a friction polygon's outline");
    }
    outlines.push_back(outline);
  }
  Geos::Ptr collection = geos.Own(GEOSGeom_createCollection_r(
      h, GEOS_GEOMETRYCOLLECTION, outlines.data(), static_cast<unsigned>(outlines.size())));
  Geos::Ptr noded =
      geos.Own(collection != nullptr ? GEOSUnaryUnion_r(h, collection.get()) : nullptr);
  if (noded == nullptr) return absl::InternalError("GEOS cannot merge the friction outlines");
  absl::StatusOr<MeshData> split = SlitLines(mesh, geos, noded.get(), {}, frame->origin,
                                             frame->reach, max_vertices, stats, /*slit=*/false);
  stats->faces_split += stats->faces_cut;  // none loses area: each is split, whole
  stats->faces_cut = 0;
  return split;
}

}  // namespace geodex::terrain
