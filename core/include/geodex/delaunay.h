#pragma once

// The approximate geodesic Delaunay triangulation of a finished multi-source distance field, paper
// sections 6.3 and 6.4, in O(faces + total length of the traced paths).
//
// APPROXIMATE BY DESIGN. Candidate edges (Definition 6): every mesh edge vi vj whose endpoints have
// different labels s1 != s2 gives the candidate "exact geodesic s1 -> vi, the mesh edge vi vj,
// exact geodesic vj -> s2" of length d(vi) + |vi vj| + d(vj); per site pair the shortest candidate
// is the Delaunay edge. It is a polyline on the surface, not a geodesic between the sites: its
// middle section follows a mesh edge.
//
// XL edges (Definition 4: a mesh edge whose endpoints belong to s1 and s2, possibly equal, but some
// point of which belongs to a third site s) make the approximation fail (Theorems 5 and 7 assume
// there are none). They are detected conservatively, as in the paper's section 6.4 patch: the
// geodesic sections of the Delaunay edges are exact shortest paths from a site to a vertex it owns,
// so every point on them belongs to that site; where the section of site s crosses a mesh edge
// at an interior point and neither endpoint of that edge is labelled s, the edge is an XL edge with
// witness s. XL edges that no Delaunay edge's geodesic section crosses are not found (no false
// positives, possible misses; ties between sites at the crossing point count as owned by s).
// Every Delaunay edge whose mesh-edge section is a detected XL edge runs through the witness's
// cell and is removed (D-v1v2-F in the paper's Fig. 13). A geodesic section that crosses an XL
// edge is that edge's witness: it lies in its own site's cell and is kept (C-v3v4-E in Fig. 13).

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/shortest_path.h"
#include "geodex/triangle_mesh.h"

namespace geodex {

struct DelaunayEdge {
  uint32_t site_a = 0, site_b = 0;      // site_a < site_b, indices into field.sources
  uint32_t vertex_a = 0, vertex_b = 0;  // the mesh edge (file vertex ids), labelled a and b
  double length = 0;                    // d(vertex_a) + |vertex_a vertex_b| + d(vertex_b)
  // From site a to site b: the geodesic a -> vertex_a (the reverse of TracePathFromVertex), then
  // the geodesic vertex_b -> b; the segment between the two vertices is the mesh-edge section.
  std::vector<PathPoint> points;
  uint32_t edge_start = 0;  // index of vertex_a in `points` (vertex_b follows it)
};

struct XlEdge {
  uint32_t vertex_a = 0, vertex_b = 0;  // file vertex ids
  uint32_t site_a = 0, site_b = 0;      // their labels (may be equal)
  uint32_t witness = 0;                 // the third site owning `point`
  PathPoint point;  // where the witness's geodesic section crosses the edge (kEdge)
};

struct DelaunayTriangulation {
  std::vector<DelaunayEdge> edges;          // kept, sorted by (site_a, site_b)
  std::vector<DelaunayEdge> removed_edges;  // mesh-edge section on a detected XL edge
  // Site triples (ascending) of the faces whose three vertices have three labels, deduplicated,
  // whose three sides are kept Delaunay edges.
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<XlEdge> xl_edges;  // one per detected XL edge (the first witness found)
};

// Errors: InvalidArgument when the field does not belong to the mesh; Internal if a path cannot be
// traced.
absl::StatusOr<DelaunayTriangulation> BuildDelaunay(const TriangleMesh& mesh,
                                                    const DistanceField& field);

}  // namespace geodex
