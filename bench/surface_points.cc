#include "surface_points.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace geodex::bench {

std::array<double, 3> FilePosition(const MeshData& data, uint32_t v) {
  return {data.positions[3 * v], data.positions[3 * v + 1], data.positions[3 * v + 2]};
}

double Distance3(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

std::array<double, 3> PointPosition(const MeshData& data, const SurfacePoint& p) {
  if (p.kind == SurfacePoint::Kind::kVertex) return FilePosition(data, p.vertex);
  std::array<double, 3> q = {0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const std::array<double, 3> c = FilePosition(data, data.faces[3 * p.face + k]);
    for (int i = 0; i < 3; ++i) q[i] += p.bary[k] * c[i];
  }
  return q;
}

PointSampler::PointSampler(const MeshData& data, const TriangleMesh& mesh, uint32_t anchor,
                           double vertex_share, uint64_t seed)
    : rng_(seed), vertex_share_(vertex_share) {
  const uint32_t component = mesh.Component(anchor);
  for (uint32_t v = 0; v < mesh.file_vertex_count(); ++v) {
    if (mesh.Component(v) == component && !mesh.IsIsolated(v)) vertices_.push_back(v);
  }
  double total = 0;
  for (uint32_t f = 0; f < data.face_count() && f < mesh.face_count(); ++f) {
    if (mesh.FaceDegenerate(f) || mesh.Component(mesh.FaceVertex(f, 0)) != component) continue;
    const std::array<double, 3> a = FilePosition(data, data.faces[3 * f]);
    const std::array<double, 3> b = FilePosition(data, data.faces[3 * f + 1]);
    const std::array<double, 3> c = FilePosition(data, data.faces[3 * f + 2]);
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                         u[0] * w[1] - u[1] * w[0]};
    const double area = 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(area > 0)) continue;
    total += area;
    faces_.push_back(f);
    cumulative_area_.push_back(total);
  }
}

SurfacePoint PointSampler::Next() {
  if (vertex_share_ > 0 && rng_.Uniform() < vertex_share_) {
    return SurfacePoint::AtVertex(vertices_[rng_.Below(vertices_.size())]);
  }
  const double x = rng_.Uniform() * cumulative_area_.back();
  const size_t i =
      std::min<size_t>(std::upper_bound(cumulative_area_.begin(), cumulative_area_.end(), x) -
                           cumulative_area_.begin(),
                       faces_.size() - 1);
  const double r1 = std::sqrt(rng_.Uniform()), r2 = rng_.Uniform();
  return SurfacePoint::InFace(faces_[i], 1 - r1, r1 * (1 - r2), r1 * r2);
}

void PackPoint(const SurfacePoint& p, std::vector<double>* out) {
  if (p.kind == SurfacePoint::Kind::kVertex) {
    out->insert(out->end(), {0.0, static_cast<double>(p.vertex), 0.0, 0.0, 0.0});
  } else {
    out->insert(out->end(), {1.0, static_cast<double>(p.face), p.bary[0], p.bary[1], p.bary[2]});
  }
}

std::vector<SurfacePoint> UnpackPoints(const std::vector<double>& values) {
  std::vector<SurfacePoint> points;
  for (size_t i = 0; i + kPackedPoint <= values.size(); i += kPackedPoint) {
    const double* x = values.data() + i;
    const uint32_t id = static_cast<uint32_t>(x[1]);
    points.push_back(x[0] == 0 ? SurfacePoint::AtVertex(id)
                               : SurfacePoint::InFace(id, x[2], x[3], x[4]));
  }
  return points;
}

std::string ShortPoint(const SurfacePoint& p) {
  return p.kind == SurfacePoint::Kind::kVertex ? absl::StrCat("v ", p.vertex)
                                               : absl::StrCat("f ", p.face);
}

}  // namespace geodex::bench
