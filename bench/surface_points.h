#pragma once

// Random points on a mesh for the targeted-query sections (--astar, --matrix, --estimate), the
// same for a seed on every platform, and how they travel between the parent and its children.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "geodex/mesh_data.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"

namespace geodex::bench {

// SplitMix64: the same sequence on every platform and standard library (std:: distributions are
// not), so a seed names the same points everywhere.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t Next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }  // [0, 1)
  uint64_t Below(uint64_t n) { return Next() % n; }  // the bias is below 1e-9 for n < 2^32

 private:
  uint64_t state_;
};

// The position of file vertex v, of two points' distance, and of a vertex or face point, in file
// coordinates.
std::array<double, 3> FilePosition(const MeshData& data, uint32_t v);
double Distance3(const std::array<double, 3>& a, const std::array<double, 3>& b);
std::array<double, 3> PointPosition(const MeshData& data, const SurfacePoint& p);

// Random points on the connected component of file vertex `anchor`: with probability
// `vertex_share` a vertex (uniform over the component's vertices), otherwise a face point
// uniform over the component's area (a face picked by area, then a uniform point inside it).
class PointSampler {
 public:
  PointSampler(const MeshData& data, const TriangleMesh& mesh, uint32_t anchor, double vertex_share,
               uint64_t seed);

  bool ok() const { return !vertices_.empty() && !faces_.empty(); }

  SurfacePoint Next();

 private:
  Rng rng_;
  double vertex_share_;
  std::vector<uint32_t> vertices_, faces_;
  std::vector<double> cumulative_area_;
};

// Vertex and face points travel between processes as 5 doubles: kind, id, barycentrics.
inline constexpr size_t kPackedPoint = 5;
void PackPoint(const SurfacePoint& p, std::vector<double>* out);
std::vector<SurfacePoint> UnpackPoints(const std::vector<double>& values);

// "v 12" for a vertex, "f 34" for a face point.
std::string ShortPoint(const SurfacePoint& p);

}  // namespace geodex::bench
