// Sources and targets resolved onto the mesh (weighted/steiner_graph.h's Located): a surface point
// to its internal vertices, half-edges or face and its position, and back from graph nodes and
// located points to a path's points.

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_format.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"
#include "mesh_lookup.h"
#include "weighted/steiner_graph.h"

namespace geodex::weighted_internal {

absl::StatusOr<Located> Locate(const TriangleMesh& mesh, const SurfacePoint& p) {
  if (absl::Status s = ValidateSurfacePoint(mesh, p); !s.ok()) return s;
  Located out;
  out.canonical = CanonicalPoint(mesh, p);
  const SurfacePoint& c = out.canonical;
  switch (c.kind) {
    case SurfacePoint::Kind::kVertex:
      InternalCopies(mesh, c.vertex, &out.vertices);
      out.pos = mesh.Position(c.vertex);
      break;
    case SurfacePoint::Kind::kEdge: {
      HalfEdgesOfFileEdge(mesh, c.edge_from, c.edge_to, &out.half_edges);
      if (out.half_edges.empty()) {
        return absl::InvalidArgumentError(
            absl::StrFormat("point %s: the mesh has no edge between vertices %d and %d",
                            SurfacePointToString(p), c.edge_from, c.edge_to));
      }
      const uint32_t h = out.half_edges[0];
      const bool forward = mesh.FileVertex(mesh.From(h)) == c.edge_from;
      const Vec a = mesh.Position(forward ? mesh.From(h) : mesh.To(h));
      const Vec b = mesh.Position(forward ? mesh.To(h) : mesh.From(h));
      out.pos = SteinerGraph::Lerp(a, b, c.t);
      break;
    }
    case SurfacePoint::Kind::kFace: {
      out.face = c.face;
      std::array<double, 3> ib = c.bary;
      mesh.SwapCornerOrder(c.face, &ib);
      out.pos = {0, 0, 0};
      for (int k = 0; k < 3; ++k) {
        const Vec q = mesh.Position(mesh.FaceVertex(c.face, k));
        for (int j = 0; j < 3; ++j) out.pos[j] += ib[k] * q[j];
      }
      break;
    }
    case SurfacePoint::Kind::kPosition:
      break;  // rejected by ValidateSurfacePoint
  }
  return out;
}

absl::Status Prepare(const TriangleMesh& mesh, const std::vector<SurfacePoint>& points,
                     std::vector<Located>* located) {
  for (const SurfacePoint& p : points) {
    absl::StatusOr<Located> l = Locate(mesh, p);
    if (!l.ok()) return l.status();
    located->push_back(*std::move(l));
  }
  return absl::OkStatus();
}

PathPoint NodePoint(const SteinerGraph& g, uint32_t n) {
  const TriangleMesh& mesh = g.mesh();
  PathPoint pp;
  const Vec p = g.Pos(n);
  for (int k = 0; k < 3; ++k) pp.position[k] = p[k] + mesh.Center()[k];
  if (n < g.nv()) {
    pp.where = SurfacePoint::AtVertex(mesh.FileVertex(n));
  } else {
    const uint32_t h = g.EdgeHalf(g.EdgeOfNode(n));
    pp.where =
        CanonicalEdgePoint(mesh.FileVertex(mesh.From(h)), mesh.FileVertex(mesh.To(h)), g.Param(n));
  }
  return pp;
}

PathPoint LocatedPoint(const TriangleMesh& mesh, const Located& l) {
  PathPoint pp;
  for (int k = 0; k < 3; ++k) pp.position[k] = l.pos[k] + mesh.Center()[k];
  pp.where = l.canonical;
  return pp;
}

}  // namespace geodex::weighted_internal
