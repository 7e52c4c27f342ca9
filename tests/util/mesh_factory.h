#pragma once

// Analytic test meshes and their exact geodesic distances.
//
// Every generator returns a plain geodex::MeshData (file order = generation order), so the meshes
// go through TriangleMesh::Build like any file would. Every "...Distance" helper computes the exact
// geodesic distance of the *discrete* surface (not of a smooth surface it approximates) by an
// argument independent of the engine: the surfaces below are flat except at a few known vertices,
// so the distance is a planar distance in an unfolding.

#include <array>
#include <cstddef>  // geodex/mesh_data.h uses size_t without including it
#include <cstdint>
#include <vector>

#include "geodex/mesh_data.h"

namespace geodex {

using Vec2 = std::array<double, 2>;
using Vec3 = std::array<double, 3>;

Vec3 VertexPosition(const MeshData& mesh, uint32_t v);
Vec3 FaceCentroid(const MeshData& mesh, uint32_t f);
double Distance3(const Vec3& a, const Vec3& b);
double Distance2(const Vec2& a, const Vec2& b);

// Where a unimodal f is least on [lo, hi], by golden-section search (200 steps): the analytic
// optima of the refraction tests (Snell's law).
template <typename F>
double GoldenSectionArgMin(F f, double lo, double hi) {
  const double g = 0.6180339887498949;  // (sqrt(5) - 1) / 2
  double a = lo, b = hi;
  for (int i = 0; i < 200; ++i) {
    const double c = b - g * (b - a), d = a + g * (b - a);
    if (f(c) < f(d)) {
      b = d;
    } else {
      a = c;
    }
  }
  return (a + b) / 2;
}

// ---------------------------------------------------------------------------------------------
// Flat grid: cells_x x cells_y cells over [0, width] x [0, height] in the plane z = 0, vertex
// (i, j) has id j * (cells_x + 1) + i. Each cell is split into two triangles along the diagonal
// (i, j)-(i+1, j+1), or, with alternate_diagonals, along (i+1, j)-(i, j+1) in cells with i + j
// odd. With jitter > 0 every vertex off the rectangle's boundary moves in the plane by a
// deterministic pseudo-random offset of at most jitter * cell size per axis (jitter <= 0.2 keeps
// every triangle positively oriented). The domain stays the convex rectangle, so geodesic
// distance = Euclidean distance for any jitter.
struct GridSpec {
  int cells_x = 10, cells_y = 10;
  double width = 1, height = 1;
  bool alternate_diagonals = false;
  double jitter = 0;
  uint64_t seed = 1;
};
MeshData MakeGrid(const GridSpec& spec);

// ---------------------------------------------------------------------------------------------
// L-shaped planar domain: [0, size]^2 minus the open quadrant (size/2, size]^2, meshed as a
// (2n x 2n)-cell grid without the cells of that quadrant (alternating diagonals). The reflex
// corner is the boundary vertex at (size/2, size/2). jitter as for MakeGrid (boundary vertices,
// including the reflex corner and the inner edges, stay put).
MeshData MakeLShape(int n, double size, double jitter = 0, uint64_t seed = 1);
// Exact geodesic distance in that L between two points of it (z ignored): the straight segment if
// it stays inside the closed L, otherwise the path bending once at the reflex corner c:
// |s c| + |c t| (the L is a simple polygon with a single reflex vertex).
double LShapeDistance(double size, const Vec2& s, const Vec2& t);
Vec2 LShapeReflexCorner(double size);

// ---------------------------------------------------------------------------------------------
// Surface of the cube [0, side]^3, each face subdivided into k x k squares (2 triangles each),
// shared vertices welded, every triangle oriented outward. Vertex ids: lattice order (x fastest,
// then y, then z) of the (k+1)^3 lattice points that lie on the surface.
MeshData MakeCube(int k, double side);
// Exact geodesic distance on the surface of the cube [0, side]^3 between two surface points:
// the minimum, over the sequences of distinct cube faces from a face holding s to a face holding
// t, of the straight segment in the unfolding, counting only unfoldings where the segment crosses
// every hinge edge inside that edge in order. (A shortest path on a convex polyhedron visits each
// face at most once, is straight in every unfolding of the faces it crosses and never passes
// through a vertex of angle sum < 2 pi; all cube corners have 3 pi / 2.)
double CubeDistance(double side, const Vec3& s, const Vec3& t);

// ---------------------------------------------------------------------------------------------
// A pyramid "cone": apex at the origin, `segments` straight generators with unit directions g_k =
// normalise(cos 2 pi k / segments, sin 2 pi k / segments, z_k), each cut into `rings` equal parts
// up to slant length `slant` (ring j at distance j * slant / rings from the apex). The quads
// between two generators are planar (both generators are lines through the apex), so the surface
// is the polyhedral cone made of `segments` flat isosceles triangles: intrinsically flat
// everywhere except at the apex, whose angle sum is Theta = sum_k angle(g_k, g_{k+1}); the rim is
// a boundary.
//  * convex: z_k = -height_ratio for all k: Theta < 2 pi.
//  * saddle: z_k = +height_ratio / -height_ratio alternating (segments even), a wavy disk:
//    Theta > 2 pi, the apex is a saddle vertex.
// Vertex 0 is the apex; vertex 1 + (j - 1) * segments + k is ring j (1..rings), generator k.
struct Cone {
  MeshData data;
  std::vector<double> rho;  // per vertex: intrinsic distance from the apex
  std::vector<double> phi;  // per vertex: polar angle in the unfolding, in [0, total_angle)
  double total_angle = 0;   // Theta, the apex angle sum
};
Cone MakeCone(int segments, int rings, double slant, double height_ratio, bool saddle);
// Exact distance between two vertices of the cone. Unfold around the apex: a point is (rho, phi).
// With Delta = the angular separation the shorter way round, min(|phi_a - phi_b|, Theta - ...):
//  * Delta < pi: the straight segment in the unfolded wedge (which is convex: a wedge of angle
//    < pi under a convex rim chain) is a geodesic and the shortest one, length^2 = rho_a^2 +
//    rho_b^2 - 2 rho_a rho_b cos(Delta);
//  * Delta >= pi (possible only when Theta > 2 pi): no straight segment joins them, the shortest
//    path bends at the apex: rho_a + rho_b.
double ConeDistance(const Cone& cone, uint32_t a, uint32_t b);

// ---------------------------------------------------------------------------------------------
// Open cylinder discretised as a prism: `segments` vertices per ring on the circle of `radius`,
// `rings` + 1 rings at heights i * height / rings, no caps (two boundary loops). Vertex id:
// i * segments + k. The prism's side faces are planar rectangles, so the surface unrolls
// isometrically onto the strip R x [0, height] with period perimeter = segments * side.
struct Cylinder {
  MeshData data;
  std::vector<double> u;  // per vertex: arc length along the prism's perimeter
  std::vector<double> z;
  double perimeter = 0;
};
Cylinder MakeOpenCylinder(int segments, int rings, double radius, double height,
                          bool alternate_diagonals = false);
// min over shifts m in {-1, 0, 1} of |(u_a - u_b + m * perimeter, z_a - z_b)|: the strip is convex,
// so every straight segment between images is a path on the surface, and |u_a - u_b| < perimeter
// means farther shifts are longer.
double CylinderDistance(const Cylinder& cylinder, uint32_t a, uint32_t b);

// ---------------------------------------------------------------------------------------------
// Applies x -> R x + t with R the rotation by `angle` about `axis` (normalised here). Geodesic
// distances are invariant, so analytic answers computed before the motion stay valid; used to
// move planar meshes off the z = 0 plane and away from the origin.
void ApplyRigidMotion(MeshData* mesh, const Vec3& axis, double angle, const Vec3& translation);

// A mesh from explicit points and faces (vertex ids into `points`), as a file would give them.
MeshData Soup(const std::vector<std::array<double, 3>>& points,
              const std::vector<std::array<uint32_t, 3>>& faces);

}  // namespace geodex
