#include "geodex/point_distance.h"

#include <cmath>
#include <vector>

#include "absl/strings/str_format.h"
#include "mesh_lookup.h"

namespace geodex {
namespace {

constexpr double kSnap = 1e-12;

struct FacePlacement {
  uint32_t face;
  double px, py;  // in the frame of half-edge 3 * face
};

// Faces containing the point, with its 2D position in each (an edge point lies in two faces).
absl::Status PlacePoint(const TriangleMesh& mesh, const SurfacePoint& p,
                        std::vector<FacePlacement>* out) {
  if (absl::Status s = ValidateSurfacePoint(mesh, p); !s.ok()) return s;
  if (p.kind == SurfacePoint::Kind::kFace) {
    double b[3] = {p.bary[0], p.bary[1], p.bary[2]};
    const double sum = b[0] + b[1] + b[2];
    for (double& x : b) x = std::max(0.0, x / sum);
    if (mesh.FaceFlipped(p.face)) std::swap(b[1], b[2]);
    double x1, y1, x2, y2;
    CornerInFaceFrame(mesh, p.face, 1, &x1, &y1);
    CornerInFaceFrame(mesh, p.face, 2, &x2, &y2);
    out->push_back({p.face, b[1] * x1 + b[2] * x2, b[1] * y1 + b[2] * y2});
    return absl::OkStatus();
  }
  // Edge points: every face with that edge.
  std::vector<uint32_t> half_edges;
  HalfEdgesOfFileEdge(mesh, p.edge_from, p.edge_to, &half_edges);
  for (const uint32_t h : half_edges) {
    const double x =
        (mesh.FileVertex(mesh.From(h)) == p.edge_from ? p.t : 1 - p.t) * mesh.Length(h);
    const uint32_t f = TriangleMesh::FaceOf(h);
    if (mesh.FaceDegenerate(f)) continue;
    const int k = static_cast<int>(h % 3);
    double x0, y0, x1, y1;
    CornerInFaceFrame(mesh, f, k, &x0, &y0);
    CornerInFaceFrame(mesh, f, (k + 1) % 3, &x1, &y1);
    const double len = mesh.Length(h);
    out->push_back({f, x0 + (x1 - x0) * x / len, y0 + (y1 - y0) * x / len});
  }
  if (out->empty()) {
    return absl::InvalidArgumentError(
        absl::StrFormat("point %s: no non-degenerate face has the edge %d-%d",
                        SurfacePointToString(p), p.edge_from, p.edge_to));
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<PointEstimate> EstimateDistanceAt(const TriangleMesh& mesh,
                                                 const DistanceField& field,
                                                 const SurfacePoint& point) {
  if (field.internal_distance.size() != mesh.vertex_count()) {
    return absl::InvalidArgumentError("the distance field was not computed on this mesh");
  }
  if (point.kind == SurfacePoint::Kind::kVertex) {
    if (absl::Status s = ValidateSurfacePoint(mesh, point); !s.ok()) return s;
    return PointEstimate{field.distance[point.vertex], field.source[point.vertex]};
  }
  if (point.kind == SurfacePoint::Kind::kEdge && (point.t <= kSnap || point.t >= 1 - kSnap)) {
    if (absl::Status s = ValidateSurfacePoint(mesh, point); !s.ok()) return s;
    const uint32_t v = point.t <= kSnap ? point.edge_from : point.edge_to;
    return PointEstimate{field.distance[v], field.source[v]};
  }
  std::vector<FacePlacement> places;
  if (absl::Status s = PlacePoint(mesh, point, &places); !s.ok()) return s;
  PointEstimate best;
  auto offer = [&](double d, uint32_t label) {
    if (d < best.distance) best = {d, label};
  };
  for (const FacePlacement& fp : places) {
    const uint32_t f = fp.face;
    double cx[3], cy[3], d[3];
    uint32_t label[3];
    for (int k = 0; k < 3; ++k) {
      CornerInFaceFrame(mesh, f, k, &cx[k], &cy[k]);
      const uint32_t v = mesh.FaceVertex(f, k);
      d[k] = field.internal_distance[v];
      label[k] = field.internal_source[v];
      // The vertex route: a real path, always a candidate.
      offer(d[k] + std::hypot(fp.px - cx[k], fp.py - cy[k]), label[k]);
    }
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3;
      if (!std::isfinite(d[i]) || !std::isfinite(d[j]) || label[i] != label[j]) continue;
      // Edge frame: vi at the origin, vj at (len, 0), the face (and vk) on +y.
      const double len = std::hypot(cx[j] - cx[i], cy[j] - cy[i]);
      if (!(len > 0)) continue;
      const double ux = (cx[j] - cx[i]) / len, uy = (cy[j] - cy[i]) / len;
      const double qx = (fp.px - cx[i]) * ux + (fp.py - cy[i]) * uy;
      const double qy = ux * (fp.py - cy[i]) - uy * (fp.px - cx[i]);
      // The unfolded source s' below the edge: |s' vi| = di, |s' vj| = dj.
      const double sx = (d[i] * d[i] - d[j] * d[j] + len * len) / (2 * len);
      const double sy = -std::sqrt(std::max(0.0, d[i] * d[i] - sx * sx));
      const double cross_x = qy - sy > 0 ? qx + (sx - qx) * qy / (qy - sy) : sx;
      double e;
      if (cross_x < 0) {
        e = std::hypot(qx, qy) + d[i];
      } else if (cross_x > len) {
        e = std::hypot(qx - len, qy) + d[j];
      } else {
        e = std::hypot(qx - sx, qy - sy);
      }
      offer(e, label[i]);
    }
  }
  // A source point in the point's own face is reached in a straight line: exact. (Vertex sources
  // at a corner are covered above, where d = 0.)
  for (uint32_t label = 0; label < field.sources.size(); ++label) {
    const SurfacePoint& s = field.sources[label];
    if (s.kind == SurfacePoint::Kind::kVertex) continue;
    std::vector<FacePlacement> source_places;
    if (!PlacePoint(mesh, s, &source_places).ok()) continue;
    for (const FacePlacement& sp : source_places) {
      for (const FacePlacement& fp : places) {
        if (sp.face == fp.face) offer(std::hypot(sp.px - fp.px, sp.py - fp.py), label);
      }
    }
  }
  return best;
}

}  // namespace geodex
