#include "geodex/shortest_path.h"

#include <array>
#include <cmath>
#include <limits>

#include "absl/strings/str_format.h"
#include "path_trace.h"

namespace geodex {
namespace {

struct Vec2 {
  double x, y;
};

// The 3D frame of half-edge h: origin at its start, x along it, y into its face.
struct Frame3 {
  double o[3], u[3], n[3];
};

Frame3 FrameOf(const TriangleMesh& mesh, uint32_t h) {
  Frame3 f;
  const double* p = mesh.positions();
  const double* a = p + 3 * mesh.From(h);
  const double* b = p + 3 * mesh.To(h);
  const double* c = p + 3 * mesh.Opposite(h);
  const double len = mesh.Length(h);
  for (int k = 0; k < 3; ++k) {
    f.o[k] = a[k];
    f.u[k] = len > 0 ? (b[k] - a[k]) / len : 0;
  }
  double w[3], dot = 0;
  for (int k = 0; k < 3; ++k) dot += (c[k] - a[k]) * f.u[k];
  double norm = 0;
  for (int k = 0; k < 3; ++k) {
    w[k] = c[k] - a[k] - dot * f.u[k];
    norm += w[k] * w[k];
  }
  norm = std::sqrt(norm);
  for (int k = 0; k < 3; ++k) f.n[k] = norm > 0 ? w[k] / norm : 0;
  return f;
}

// Re-expresses q, given in the frame of half-edge `from`, in the frame of half-edge `to` of the
// same face (both frames put the face on +y).
Vec2 ToSiblingFrame(const TriangleMesh& mesh, uint32_t from, uint32_t to, Vec2 q) {
  if (from == to) return q;
  const uint32_t f = TriangleMesh::FaceOf(from);
  // Corners of the face in `from`'s frame, indexed by local corner number.
  Vec2 corner[3];
  const int k = static_cast<int>(from % 3);
  corner[k] = {0, 0};
  corner[(k + 1) % 3] = {mesh.Length(from), 0};
  corner[(k + 2) % 3] = {mesh.OppX(from), mesh.OppY(from)};
  const int j = static_cast<int>(to % 3);
  const Vec2 o = corner[j], e = corner[(j + 1) % 3];
  const double len = std::hypot(e.x - o.x, e.y - o.y);
  const double ux = (e.x - o.x) / len, uy = (e.y - o.y) / len;
  const double dx = q.x - o.x, dy = q.y - o.y;
  (void)f;
  return {dx * ux + dy * uy, ux * dy - uy * dx};
}

class Tracer {
 public:
  Tracer(const TriangleMesh& mesh, const VertexPaths& field) : mesh_(mesh), field_(field) {}

  absl::Status FromVertex(uint32_t v, GeodesicPath* path) {
    path_ = path;
    AddVertex(v);
    return Chain(v);
  }

  // A target point answered by the solver: the start point, then straight to the image of its
  // origin (or to a vertex), then on along the per-vertex origins.
  absl::Status FromTarget(const ich::TargetResult& r, const SurfacePoint& where,
                          GeodesicPath* path) {
    path_ = path;
    const Frame3 f = FrameOf(mesh_, 3 * r.face);
    double q[3];
    for (int k = 0; k < 3; ++k) q[k] = f.o[k] + r.px * f.u[k] + r.py * f.n[k];
    Append(q, where);
    if (r.origin.half_edge == kNoIndex) {
      AddVertex(r.origin.pseudo_source);
      return Chain(r.origin.pseudo_source);
    }
    absl::StatusOr<uint32_t> next = LegFrom({r.tx, r.ty}, r.origin);
    if (!next.ok()) return next.status();
    if (*next == kNoIndex) return absl::OkStatus();
    return Chain(*next);
  }

 private:
  // On along the origins from `node` (a vertex, or a boundary point tagged kBoundaryPointTag) to
  // the source.
  absl::Status Chain(uint32_t node) {
    // Every leg ends at a pseudo-source or a boundary point: a chain is at most as long as those.
    const uint64_t most = uint64_t{mesh_.vertex_count()} +
                          (field_.links != nullptr ? field_.links->point_count() : 0) + 1;
    for (uint64_t legs = 0; legs <= most; ++legs) {
      if (ich::IsBoundaryPoint(node)) {
        absl::StatusOr<uint32_t> next = FromPoint(node & ~ich::kBoundaryPointTag);
        if (!next.ok()) return next.status();
        if (*next == kNoIndex) return absl::OkStatus();
        node = *next;
        continue;
      }
      const uint32_t v = node;
      const VertexOrigin& o = field_.origin[v];
      if (field_.distance[v] == 0 && o.half_edge == kNoIndex) return absl::OkStatus();
      if (o.half_edge == kNoIndex) {
        // Along an edge from a neighbour (edge relaxation), or v is a source vertex.
        if (o.pseudo_source == kNoIndex || o.pseudo_source == v) return absl::OkStatus();
        node = o.pseudo_source;
        AddVertex(node);
        continue;
      }
      absl::StatusOr<uint32_t> next = Leg(v, o);
      if (!next.ok()) return next.status();
      if (*next == kNoIndex) return absl::OkStatus();  // reached the source point itself
      node = *next;
    }
    return absl::InternalError("path backtrace did not terminate");
  }

  // One step back from boundary point p: straight across the face its window ran in to that
  // window's image, or along its chain to the vertex or point whose cost it took. Returns the
  // vertex or (tagged) point reached, kNoIndex at a source point.
  absl::StatusOr<uint32_t> FromPoint(uint32_t p) {
    if (field_.links == nullptr || field_.point_origin == nullptr) {
      return absl::InternalError("path backtrace reached a boundary point without the links");
    }
    const VertexOrigin& o = field_.point_origin[p];
    if (o.half_edge == kNoIndex) {
      const uint32_t from = o.pseudo_source;
      if (from == kNoIndex) return absl::InternalError("path backtrace: a boundary point unset");
      if (ich::IsBoundaryPoint(from)) {
        AddBoundaryPoint(from & ~ich::kBoundaryPointTag);
      } else {
        AddVertex(from);
      }
      return from;
    }
    // Across the face of boundary half-edge e, from p on e towards the image.
    const uint32_t e = o.half_edge;
    const double len = mesh_.Length(e);
    const Vec2 xp{PointOnHalfEdge(p, e), 0};
    const Vec2 ip{o.ix, o.iy};
    const Vec2 c{mesh_.OppX(e), mesh_.OppY(e)};
    if (InsideTriangle(ip, len, c)) return Arrive(e, ip, o.pseudo_source);
    const double side = (ip.x - xp.x) * (c.y - xp.y) - (ip.y - xp.y) * (c.x - xp.x);
    const uint32_t exit = side > 0 ? TriangleMesh::Next(e) : TriangleMesh::Prev(e);
    return Walk(exit, ToSiblingFrame(mesh_, e, exit, xp), ToSiblingFrame(mesh_, e, exit, ip),
                o.pseudo_source);
  }

  // Where boundary point p lies along half-edge e (one of its chain's), from e's start.
  double PointOnHalfEdge(uint32_t p, uint32_t e) const {
    const double t = field_.links->point_param[p];
    return mesh_.Length(e) * (field_.links->chain_reversed[e] ? 1 - t : t);
  }

  void AddBoundaryPoint(uint32_t p) {
    const std::array<uint32_t, 2>& halves =
        field_.links->chain_halves[field_.links->point_chain[p]];
    const uint32_t e = halves[0] != kNoIndex ? halves[0] : halves[1];
    AddEdgePoint(e, PointOnHalfEdge(p, e));
  }

  // Walks from vertex v straight towards the image in o's frame, face by face, until the image
  // lies in the current face; returns the pseudo-source vertex reached (kNoIndex for a point
  // source).
  absl::StatusOr<uint32_t> Leg(uint32_t v, const VertexOrigin& o) {
    const uint32_t g = o.half_edge;
    if (mesh_.From(g) == v) return LegFrom({0, 0}, o);
    if (mesh_.To(g) == v) return LegFrom({mesh_.Length(g), 0}, o);
    return LegFrom({mesh_.OppX(g), mesh_.OppY(g)}, o);
  }

  // The same from a point p given in the frame of o.half_edge (inside its face or on its border).
  absl::StatusOr<uint32_t> LegFrom(Vec2 p, const VertexOrigin& o) {
    return Walk(o.half_edge, p, {o.ix, o.iy}, o.pseudo_source);
  }

  // From p (in the frame of g, in face(g) or on its border) straight to `image`, face by face.
  absl::StatusOr<uint32_t> Walk(uint32_t g, Vec2 p, Vec2 image, uint32_t pseudo_source) {
    const uint32_t max_steps = 2 * mesh_.face_count() + 8;
    for (uint32_t step = 0; step < max_steps; ++step) {
      const double len = mesh_.Length(g);
      const double tol = 1e-12 * (len + std::abs(image.y));
      if (image.y >= -tol) {
        // The image is in this face (or on its border): the leg ends at it.
        return Arrive(g, image, pseudo_source);
      }
      // Cross edge g where the segment p -> image meets it.
      const double s = p.y / (p.y - image.y);
      double x = p.x + (image.x - p.x) * s;
      x = std::min(len, std::max(0.0, x));
      AddEdgePoint(g, x);
      const uint32_t t = mesh_.Twin(g);
      if (t == kNoIndex) return absl::InternalError("path backtrace left the surface");
      // Into the previous face: twin frame.
      const Vec2 xp{len - x, 0};
      const Vec2 ip{len - image.x, -image.y};
      // Where does the ray xp -> ip leave face(t)? Through the edge on the side of the opposite
      // corner it passes.
      const Vec2 c{mesh_.OppX(t), mesh_.OppY(t)};
      const double side = (ip.x - xp.x) * (c.y - xp.y) - (ip.y - xp.y) * (c.x - xp.x);
      // If the image is inside face(t), the leg ends here.
      if (InsideTriangle(ip, len, c)) {
        return Arrive(t, ip, pseudo_source);
      }
      const uint32_t exit = side > 0 ? TriangleMesh::Next(t) : TriangleMesh::Prev(t);
      p = ToSiblingFrame(mesh_, t, exit, xp);
      image = ToSiblingFrame(mesh_, t, exit, ip);
      g = exit;
    }
    return absl::InternalError("path backtrace did not reach its pseudo-source");
  }

  static bool InsideTriangle(Vec2 q, double len, Vec2 c) {
    // Triangle (0,0), (len,0), c with c.y > 0; a small tolerance relative to the edge.
    const double tol = 1e-12 * len;
    if (q.y < -tol) return false;
    const double right = (c.x - len) * (q.y) - (c.y) * (q.x - len);         // edge (len,0) -> c
    const double left = (0 - c.x) * (q.y - c.y) - (0 - c.y) * (q.x - c.x);  // edge c -> (0,0)
    return right >= -tol * len && left >= -tol * len;
  }

  absl::StatusOr<uint32_t> Arrive(uint32_t g, Vec2 image, uint32_t pseudo_source) {
    if (ich::IsBoundaryPoint(pseudo_source)) {
      // A boundary point on this face's border: the path goes on from it (Chain).
      AddBoundaryPoint(pseudo_source & ~ich::kBoundaryPointTag);
      return pseudo_source;
    }
    if (pseudo_source != kNoIndex) {
      AddVertex(pseudo_source);
      return pseudo_source;
    }
    // A point source inside (or on the border of) this face.
    AddFacePoint(g, image);
    return kNoIndex;
  }

  void Append(const double* local3, const SurfacePoint& where) {
    PathPoint pt;
    const auto& c = mesh_.Center();
    for (int k = 0; k < 3; ++k) pt.position[k] = local3[k] + c[k];
    pt.where = where;
    if (!path_->points.empty()) {
      const auto& q = path_->points.back().position;
      path_->length += std::sqrt((q[0] - pt.position[0]) * (q[0] - pt.position[0]) +
                                 (q[1] - pt.position[1]) * (q[1] - pt.position[1]) +
                                 (q[2] - pt.position[2]) * (q[2] - pt.position[2]));
    }
    path_->points.push_back(pt);
  }

  void AddVertex(uint32_t v) {
    Append(mesh_.positions() + 3 * v, SurfacePoint::AtVertex(mesh_.FileVertex(v)));
  }

  void AddEdgePoint(uint32_t g, double x) {
    const Frame3 f = FrameOf(mesh_, g);
    double q[3];
    for (int k = 0; k < 3; ++k) q[k] = f.o[k] + x * f.u[k];
    const double len = mesh_.Length(g);
    Append(q, SurfacePoint::OnEdge(mesh_.FileVertex(mesh_.From(g)), mesh_.FileVertex(mesh_.To(g)),
                                   len > 0 ? x / len : 0));
  }

  void AddFacePoint(uint32_t g, Vec2 q2) {
    const Frame3 f = FrameOf(mesh_, g);
    double q[3];
    for (int k = 0; k < 3; ++k) q[k] = f.o[k] + q2.x * f.u[k] + q2.y * f.n[k];
    // Barycentrics in the file's corner order.
    const uint32_t face = TriangleMesh::FaceOf(g);
    const double len = mesh_.Length(g), cx = mesh_.OppX(g), cy = mesh_.OppY(g);
    double w_opp = cy > 0 ? q2.y / cy : 0;
    double w_to = len > 0 ? (q2.x - w_opp * cx) / len : 0;
    double w_from = 1 - w_opp - w_to;
    std::array<double, 3> bary;
    const int k = static_cast<int>(g % 3);
    bary[k] = w_from;
    bary[(k + 1) % 3] = w_to;
    bary[(k + 2) % 3] = w_opp;
    mesh_.SwapCornerOrder(face, &bary);
    Append(q, SurfacePoint::InFace(face, bary[0], bary[1], bary[2]));
  }

  const TriangleMesh& mesh_;
  const VertexPaths field_;  // two pointers: held by value
  GeodesicPath* path_ = nullptr;
};

}  // namespace

absl::StatusOr<GeodesicPath> TraceFromTarget(const TriangleMesh& mesh, const VertexPaths& field,
                                             const ich::TargetResult& result,
                                             const SurfacePoint& where) {
  if (!std::isfinite(result.distance)) {
    return absl::NotFoundError("the target is unreachable from every source");
  }
  GeodesicPath path;
  path.source = result.label;
  Tracer tracer(mesh, field);
  if (result.vertex != kNoIndex) {
    if (absl::Status s = tracer.FromVertex(result.vertex, &path); !s.ok()) return s;
  } else if (absl::Status s = tracer.FromTarget(result, where, &path); !s.ok()) {
    return s;
  }
  return path;
}

absl::StatusOr<GeodesicPath> TracePathFromVertex(const TriangleMesh& mesh,
                                                 const DistanceField& field, uint32_t vertex) {
  if (vertex >= mesh.file_vertex_count()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "vertex %d does not exist (the mesh has %d vertices)", vertex, mesh.file_vertex_count()));
  }
  if (field.travel_epsilon > 0) {
    return OptionError("travel",
                       "a travel field has no geodesic origins to trace; ask for the least-time "
                       "path (ComputeShortestPath with the travel cost)");
  }
  if (field.internal_origin.size() != mesh.vertex_count()) {
    return absl::InvalidArgumentError("the distance field was not computed on this mesh");
  }
  // A split vertex: start from its best copy.
  uint32_t start = vertex;
  for (uint32_t v = mesh.file_vertex_count(); v < mesh.vertex_count(); ++v) {
    if (mesh.FileVertex(v) == vertex &&
        field.internal_distance[v] < field.internal_distance[start]) {
      start = v;
    }
  }
  if (!std::isfinite(field.internal_distance[start])) {
    return absl::NotFoundError(
        absl::StrFormat("vertex %d is unreachable from every source", vertex));
  }
  GeodesicPath path;
  path.source = field.internal_source[start];
  Tracer tracer(mesh, VertexPaths{field.internal_distance.data(), field.internal_origin.data()});
  if (absl::Status s = tracer.FromVertex(start, &path); !s.ok()) return s;
  return path;
}

namespace {

std::array<double, 3> Unit(const double d[3]) {
  const double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(norm > 0)) return {0, 0, 0};
  return {d[0] / norm, d[1] / norm, d[2] / norm};
}

// The step from the point at (px, py) in the frame of half-edge g (on g when `on_g`) straight
// towards (ix, iy): inside face(g), or, from a point on g with the image below it, in the twin's
// face, which the frame of g shows unfolded below the edge.
void StepInFrame(const TriangleMesh& mesh, uint32_t g, double px, double py, double ix, double iy,
                 bool on_g, double d[3]) {
  const double dx = ix - px, dy = iy - py;
  const Frame3 f = FrameOf(mesh, g);
  const uint32_t twin = mesh.Twin(g);
  if (!on_g || dy >= 0 || twin == kNoIndex) {
    for (int k = 0; k < 3; ++k) d[k] = dx * f.u[k] + dy * f.n[k];
  } else {
    const Frame3 t = FrameOf(mesh, twin);
    for (int k = 0; k < 3; ++k) d[k] = dx * f.u[k] - dy * t.n[k];
  }
}

// The first step from internal vertex v along its origin o (0 0 0 at a source).
std::array<double, 3> VertexStep(const TriangleMesh& mesh, uint32_t v, double distance,
                                 const VertexOrigin& o) {
  const double* pos = mesh.positions();
  double d[3] = {0, 0, 0};
  if (o.half_edge == kNoIndex) {
    // Along an edge towards a neighbour (edge relaxation); a source vertex has no direction.
    if (o.pseudo_source != kNoIndex && o.pseudo_source != v && distance > 0) {
      for (int k = 0; k < 3; ++k) d[k] = pos[3 * o.pseudo_source + k] - pos[3 * v + k];
    }
  } else {
    // Straight from v towards the image of its origin, in the frame of o.half_edge (from the
    // opposite corner the step heads for edge g, so it runs inside face(g)).
    const uint32_t g = o.half_edge;
    const double len = mesh.Length(g);
    const bool opposite = mesh.From(g) != v && mesh.To(g) != v;
    const double px = mesh.From(g) == v ? 0 : mesh.To(g) == v ? len : mesh.OppX(g);
    const double py = opposite ? mesh.OppY(g) : 0;
    StepInFrame(mesh, g, px, py, o.ix, o.iy, !opposite, d);
  }
  return Unit(d);
}

}  // namespace

std::vector<std::array<double, 3>> ComputeDirectionField(const TriangleMesh& mesh,
                                                         const DistanceField& field) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const uint32_t nv = mesh.file_vertex_count();
  std::vector<std::array<double, 3>> out(nv, {kNaN, kNaN, kNaN});
  if (field.internal_origin.size() != mesh.vertex_count()) return out;
  // Each file vertex speaks through its nearest internal copy (as TracePathFromVertex starts).
  std::vector<uint32_t> best(nv);
  for (uint32_t v = 0; v < nv; ++v) best[v] = v;
  for (uint32_t v = nv; v < mesh.vertex_count(); ++v) {
    const uint32_t f = mesh.FileVertex(v);
    if (field.internal_distance[v] < field.internal_distance[best[f]]) best[f] = v;
  }
  for (uint32_t file = 0; file < nv; ++file) {
    const uint32_t v = best[file];
    if (!std::isfinite(field.internal_distance[v])) continue;  // undefined: NaN
    out[file] = VertexStep(mesh, v, field.internal_distance[v], field.internal_origin[v]);
  }
  return out;
}

std::array<double, 3> TargetDirection(const TriangleMesh& mesh, const VertexPaths& field,
                                      const ich::TargetResult& r) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (!std::isfinite(r.distance)) return {kNaN, kNaN, kNaN};
  if (!(r.distance > 0)) return {0, 0, 0};
  if (r.vertex != kNoIndex) {
    return VertexStep(mesh, r.vertex, field.distance[r.vertex], field.origin[r.vertex]);
  }
  double d[3];
  if (r.origin.half_edge == kNoIndex) {
    // Straight to a corner of the point's face (TraceFromTarget's first leg).
    const Frame3 f = FrameOf(mesh, 3 * r.face);
    const double* c = mesh.positions() + 3 * r.origin.pseudo_source;
    for (int k = 0; k < 3; ++k) d[k] = c[k] - (f.o[k] + r.px * f.u[k] + r.py * f.n[k]);
  } else {
    // Towards the image, in the frame of its half-edge g, where the point is at (tx, ty); a point
    // on g itself (ty within the trace's tolerance of 0) steps into the twin's face when the image
    // is beyond g.
    const uint32_t g = r.origin.half_edge;
    const bool on_g = std::abs(r.ty) <= 1e-12 * mesh.Length(g);
    StepInFrame(mesh, g, r.tx, r.ty, r.origin.ix, r.origin.iy, on_g, d);
  }
  return Unit(d);
}

absl::Status ComputeFieldProducts(const TriangleMesh& mesh, const DistanceField& field,
                                  const FieldQuery& query, DistanceField* out) {
  if (query.directions && field.travel_epsilon > 0) {
    return OptionError("travel",
                       "geodesic directions are read off the exact engine; a travel cost has none");
  }
  if (query.directions && out->direction.empty()) {
    out->direction = ComputeDirectionField(mesh, field);
  }
  return absl::OkStatus();
}

}  // namespace geodex
