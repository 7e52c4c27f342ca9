#pragma once

// Reference distances from CGAL's Surface_mesh_shortest_path (Xin & Wang / Chen & Han style exact
// algorithm, independent implementation). Declared here without any CGAL header; the definition
// lives in testkit/cgal_reference.cc, built as the library geodex_cgal_reference
// (testkit/CMakeLists.txt) that cgal_tests and bench/geodex_bench link.

#include <array>
#include <cstddef>  // geodex/mesh_data.h uses size_t without including it
#include <cstdint>
#include <vector>

#include "geodex/mesh_data.h"
#include "geodex/surface_point.h"

namespace geodex {

// Geodesic distance from every FILE vertex to the nearest of `sources` (file vertex ids, file face
// ids, file corner order, as for ComputeDistanceField), in file vertex order. +inf for vertices
// that no source reaches (other components) and for vertices referenced by no face.
//
// The mesh must be a consistently oriented 2-manifold (with or without boundary) that CGAL's
// Surface_mesh accepts face by face; returns an empty vector otherwise, or if a source names a
// vertex/face/edge that does not exist (or an isolated vertex). Vertex and face sources go to CGAL
// as they are; an edge source is first made a vertex by splitting its edge (CGAL 5.5 mishandles
// edge sources, see the .cc), so a face source in a face that an edge source splits is not
// supported (empty result).
//
// `timing`, when given, receives the wall-clock split of the call (for the benchmark).
struct CgalTiming {
  double setup_ms = 0;  // working copy, CGAL Surface_mesh, source points
  double solve_ms = 0;  // build_sequence_tree(): the propagation itself
  double query_ms = 0;  // the distance of every vertex
};
std::vector<double> CgalDistances(const MeshData& mesh, const std::vector<SurfacePoint>& sources,
                                  CgalTiming* timing = nullptr);

// CGAL's Delaunay triangulation (Delaunay_triangulation_2, exact predicates) of `points`: its
// finite triangles as counter-clockwise triples of indices into `points`, each rotated to start
// at its smallest index, sorted. Duplicate points are one vertex (the first index).
std::vector<std::array<uint32_t, 3>> CgalDelaunayTriangles(
    const std::vector<std::array<double, 2>>& points);

}  // namespace geodex
