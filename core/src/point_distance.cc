#include "geodex/point_distance.h"

#include <array>
#include <cmath>
#include <vector>

#include "absl/strings/str_format.h"
#include "geodex/geodesic_solver.h"
#include "mesh_lookup.h"

namespace geodex {
namespace {

struct FacePlacement {
  uint32_t face;
  double px, py;  // in the frame of half-edge 3 * face
};

// Faces containing the canonical point `p` (surface_point.h), with its 2D position in each (an
// edge point lies in every face on its edge). Not for vertices.
absl::Status PlacePoint(const TriangleMesh& mesh, const SurfacePoint& p,
                        std::vector<FacePlacement>* out) {
  if (p.kind == SurfacePoint::Kind::kFace) {
    std::array<double, 3> b = p.bary;
    mesh.SwapCornerOrder(p.face, &b);
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
  if (field.travel_epsilon > 0) {  // seconds, not lengths: an unfolding means nothing there
    return OptionError("travel",
                       "the unfolding estimate is geometry; a travel cost's times have none (ask "
                       "for the times at the points)");
  }
  if (field.internal_distance.size() != mesh.vertex_count()) {
    return absl::InvalidArgumentError("the distance field was not computed on this mesh");
  }
  if (absl::Status s = ValidateSurfacePoint(mesh, point); !s.ok()) return s;
  const SurfacePoint canonical = CanonicalPoint(mesh, point);
  if (canonical.kind == SurfacePoint::Kind::kVertex) {
    return PointEstimate{field.distance[canonical.vertex], field.source[canonical.vertex]};
  }
  std::vector<FacePlacement> places;
  if (absl::Status s = PlacePoint(mesh, canonical, &places); !s.ok()) return s;
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
    const SurfacePoint cs = CanonicalPoint(mesh, s);
    if (cs.kind == SurfacePoint::Kind::kVertex || cs.kind == SurfacePoint::Kind::kPosition)
      continue;
    std::vector<FacePlacement> source_places;
    if (!PlacePoint(mesh, cs, &source_places).ok()) continue;
    for (const FacePlacement& sp : source_places) {
      for (const FacePlacement& fp : places) {
        if (sp.face == fp.face) offer(std::hypot(sp.px - fp.px, sp.py - fp.py), label);
      }
    }
  }
  return best;
}

}  // namespace geodex
