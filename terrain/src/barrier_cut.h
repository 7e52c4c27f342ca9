#pragma once

// Barrier polygons cut exactly into a triangle mesh (issue 32): the surface that remains is the
// mesh minus the vertical prism over the polygons, whatever its shape or width.
//
// Each face is clipped against the polygons in the mesh's own x-y plane by GEOS (its difference),
// and what remains is triangulated by GEOS's constrained Delaunay triangulation; new vertices lie
// on the original face's plane, so heights follow the terrain. Neighbouring faces meet exactly: a
// point where a barrier crosses a mesh edge is made once per edge (from its lower vertex id) and
// shared by both faces, and a face that keeps an edge whole gains the points its neighbour put on
// it, so the result is conforming (no T-junctions) and each face's pieces add up to what is left.
//
// Vertices keep their ids (new ones follow them, a vertex inside a barrier stays, unused); faces
// keep their order, a cut face replaced in place by its pieces. A face seen edge-on from above (its
// x-y area below 1e-12 of its squared size, a vertical wall) is not cut: it goes when its centre
// lies inside a barrier.

#include <cstdint>

#include "absl/status/statusor.h"
#include "geodex/mesh_data.h"
#include "geodex/terrain.h"

class OGRGeometry;

namespace geodex::terrain {

// `barrier`: polygons, lines and points whose coordinates times `scale` are the mesh's x y. With
// width > 0, lines and points are buffered into polygons that wide (round ends); the union of the
// polygons is cut out. With width 0, lines are slits: the surface is split along them and every
// vertex on a line (but its ends) gets one copy per side. InvalidArgument for points without a
// width, or coordinates that are not finite; Internal only when GEOS fails.
// `max_vertices` (0: none) bounds the mesh made: ResourceExhausted (geodex/limits.h kVertices)
// beyond it, checked as the cut goes.
absl::StatusOr<MeshData> CutOutPolygons(const MeshData& mesh, const OGRGeometry& barrier,
                                        double scale, double width, uint64_t max_vertices,
                                        CutStats* stats);

// Friction regions (geodex/friction.h): every face that an outline of `polygons` crosses is split
// along it (the outlines of each polygon as given, overlaps included), and nothing is removed, so
// that each face of the result lies inside or outside every polygon. Frame, rules and limits as
// CutOutPolygons; lines and points are refused (InvalidArgument: regions are polygons).
absl::StatusOr<MeshData> SplitAlongOutlines(const MeshData& mesh, const OGRGeometry& polygons,
                                            double scale, uint64_t max_vertices, CutStats* stats);

}  // namespace geodex::terrain
