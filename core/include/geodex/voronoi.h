#pragma once

// The approximate geodesic Voronoi diagram of a finished multi-source distance field, paper
// section 6.2, in O(faces).
//
// APPROXIMATE BY DESIGN. Every vertex belongs to the cell of its nearest source (its label in the
// field, which is exact). On an edge v1 v2 whose endpoints have different labels the cell boundary
// is put at the point p with d1 + |v1 p| = d2 + |p v2|, i.e. the distance is assumed to grow at
// unit rate away from each endpoint along the edge; inside a face the boundary is straight between
// those edge points, and where a face's three vertices have three labels the three boundary pieces
// meet at the barycentre of the three edge points. On a fine, evenly triangulated mesh boundaries
// lie within a fraction of an edge length of the exact ones; an edge whose interior belongs to a
// third cell (an XL edge, Definition 4; see delaunay.h) is not seen at all.

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/shortest_path.h"
#include "geodex/triangle_mesh.h"

namespace geodex {

// A maximal chain of boundary segments between the cells of two sites. Its points are edge points
// (SurfacePoint::kEdge, file vertex ids, t from edge_from) and, where it ends at a junction of
// three cells, that face's barycentre point (kFace, barycentrics in the file's corner order).
// It ends at junctions and at mesh boundaries, or is a loop (`closed`, first point not repeated).
struct VoronoiBoundary {
  uint32_t site_a = 0, site_b = 0;  // site_a < site_b, indices into field.sources
  bool closed = false;
  std::vector<PathPoint> points;
};

// The part of a cell inside one face that the boundary cuts: a convex polygon, counter-clockwise
// in the face's orientation, whose corners are the face's vertices (kVertex), edge points and the
// face's barycentre point.
struct VoronoiFragment {
  uint32_t face = 0;  // file face id
  double area = 0;
  std::vector<PathPoint> polygon;
};

struct VoronoiCell {
  uint32_t site = 0;
  std::vector<uint32_t> whole_faces;  // file face ids whose three vertices all have this label
  std::vector<VoronoiFragment> fragments;
  double area = 0;  // whole faces + fragments
};

struct VoronoiDiagram {
  // One cell per site that is the nearest source of at least one vertex, by ascending site; a site
  // that owns no vertex (another site at the same vertex, ...) has no cell in this approximation.
  std::vector<VoronoiCell> cells;
  std::vector<VoronoiBoundary> boundaries;
  std::vector<std::array<uint32_t, 2>> adjacency;  // site pairs (a < b) sharing a boundary, sorted
  uint32_t junction_faces = 0;  // faces whose three vertices have three labels (barycentre rule)
  // Sum of the cell areas: the area of the faces whose three vertices are reachable (faces with an
  // unreachable vertex belong to no cell).
  double total_area = 0;
};

// `travel`: the travel cost a travel-time field was solved with (its values are seconds): each
// boundary point on an edge is placed where the two sites' times meet, the edge walked at its
// pace, so that at a constant speed with equal weights the cells are the geodesic ones at any
// speed. Errors: InvalidArgument when the field does not belong to the mesh, or is a travel-time
// field given without its travel cost.
struct TravelCost;
absl::StatusOr<VoronoiDiagram> BuildVoronoi(const TriangleMesh& mesh, const DistanceField& field,
                                            const TravelCost* travel = nullptr);

}  // namespace geodex
