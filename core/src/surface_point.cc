#include "geodex/surface_point.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "geodex/triangle_mesh.h"

namespace geodex {
namespace {

constexpr double kBarycentricSumTolerance = 1e-9;

bool ParseUint(absl::string_view s, uint32_t* out) {
  if (s.empty()) return false;
  const char* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, *out);
  return ec == std::errc() && p == end;
}

bool ParseDouble(absl::string_view s, double* out) {
  if (s.empty()) return false;
  const char* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, *out);
  return ec == std::errc() && p == end && std::isfinite(*out);
}

}  // namespace

absl::StatusOr<std::vector<SurfacePoint>> ParseSurfacePoints(absl::string_view spec) {
  std::vector<SurfacePoint> points;
  if (spec.empty()) return absl::InvalidArgumentError("empty point list");
  for (absl::string_view item : absl::StrSplit(spec, ',')) {
    auto bad = [&](const char* what) {
      return absl::InvalidArgumentError(
          absl::StrFormat("bad point '%s': %s", std::string(item), what));
    };
    if (item.empty()) return bad("empty item");
    std::vector<absl::string_view> parts = absl::StrSplit(item, ':');
    if (parts.size() == 1) {
      uint32_t v;
      if (!ParseUint(parts[0], &v))
        return bad("expected a vertex id, e:V1:V2:T or f:FACE:B0:B1:B2");
      points.push_back(SurfacePoint::AtVertex(v));
    } else if (parts[0] == "e") {
      uint32_t a, b;
      double t;
      if (parts.size() != 4 || !ParseUint(parts[1], &a) || !ParseUint(parts[2], &b) ||
          !ParseDouble(parts[3], &t)) {
        return bad("expected e:V1:V2:T");
      }
      points.push_back(SurfacePoint::OnEdge(a, b, t));
    } else if (parts[0] == "f") {
      uint32_t f;
      double b[3];
      if (parts.size() != 5 || !ParseUint(parts[1], &f) || !ParseDouble(parts[2], &b[0]) ||
          !ParseDouble(parts[3], &b[1]) || !ParseDouble(parts[4], &b[2])) {
        return bad("expected f:FACE:B0:B1:B2");
      }
      points.push_back(SurfacePoint::InFace(f, b[0], b[1], b[2]));
    } else if (parts[0] == "p") {
      double x[3];
      if (parts.size() != 4 || !ParseDouble(parts[1], &x[0]) || !ParseDouble(parts[2], &x[1]) ||
          !ParseDouble(parts[3], &x[2])) {
        return bad("expected p:X:Y:Z");
      }
      points.push_back(SurfacePoint::AtPosition(x[0], x[1], x[2]));
    } else {
      return bad("unknown kind (use a vertex id, e:V1:V2:T, f:FACE:B0:B1:B2 or p:X:Y:Z)");
    }
  }
  return points;
}

absl::Status VertexOutOfRange(const SurfacePoint& p, uint32_t vertex, uint32_t vertex_count) {
  return absl::InvalidArgumentError(
      absl::StrFormat("point %s: vertex %d does not exist (the mesh has %d vertices)",
                      SurfacePointToString(p), vertex, vertex_count));
}

absl::Status ValidateSurfacePoint(const TriangleMesh& mesh, const SurfacePoint& p) {
  const std::string name = SurfacePointToString(p);
  const uint32_t nv = mesh.file_vertex_count();
  switch (p.kind) {
    case SurfacePoint::Kind::kVertex:
      if (p.vertex >= nv) return VertexOutOfRange(p, p.vertex, nv);
      return absl::OkStatus();
    case SurfacePoint::Kind::kEdge: {
      if (p.edge_from >= nv || p.edge_to >= nv) {
        return VertexOutOfRange(p, p.edge_from >= nv ? p.edge_from : p.edge_to, nv);
      }
      if (!(p.t >= 0 && p.t <= 1)) {
        return absl::InvalidArgumentError(
            absl::StrFormat("point %s: T = %g is outside [0, 1]", name, p.t));
      }
      return absl::OkStatus();  // existence of the edge is checked when the point is resolved
    }
    case SurfacePoint::Kind::kFace: {
      if (p.face >= mesh.face_count()) {
        return absl::InvalidArgumentError(
            absl::StrFormat("point %s: face %d does not exist (the mesh has %d faces)", name,
                            p.face, mesh.face_count()));
      }
      double sum = 0;
      for (double b : p.bary) {
        if (!(b >= -kBarycentricSumTolerance)) {
          return absl::InvalidArgumentError(
              absl::StrFormat("point %s: barycentric coordinate %g is negative", name, b));
        }
        sum += b;
      }
      if (std::abs(sum - 1) > kBarycentricSumTolerance) {
        return absl::InvalidArgumentError(
            absl::StrFormat("point %s: barycentric coordinates sum to %.17g, not 1", name, sum));
      }
      return absl::OkStatus();
    }
    case SurfacePoint::Kind::kPosition:
      return absl::InvalidArgumentError(absl::StrFormat(
          "point %s: a position must be located on the surface first (SurfaceLocator)", name));
  }
  return absl::InvalidArgumentError("unknown point kind");
}

std::array<double, 3> PositionOf(const MeshData& m, const SurfacePoint& p) {
  using Point3 = std::array<double, 3>;
  auto vertex = [&](uint32_t v) {
    return Point3{m.positions[3 * size_t{v}], m.positions[3 * size_t{v} + 1],
                  m.positions[3 * size_t{v} + 2]};
  };
  Point3 out{0, 0, 0};
  switch (p.kind) {
    case SurfacePoint::Kind::kVertex:
      return vertex(p.vertex);
    case SurfacePoint::Kind::kEdge: {
      const Point3 a = vertex(p.edge_from), b = vertex(p.edge_to);
      for (int k = 0; k < 3; ++k) out[k] = a[k] + p.t * (b[k] - a[k]);
      break;
    }
    case SurfacePoint::Kind::kFace:
      for (int c = 0; c < 3; ++c) {
        const Point3 v = vertex(m.faces[3 * size_t{p.face} + c]);
        for (int k = 0; k < 3; ++k) out[k] += p.bary[c] * v[k];
      }
      break;
    case SurfacePoint::Kind::kPosition:
      return p.position;
  }
  return out;
}

SurfacePoint CanonicalEdgePoint(uint32_t from, uint32_t to, double t) {
  if (t <= kSurfaceSnap) return SurfacePoint::AtVertex(from);
  if (t >= 1 - kSurfaceSnap) return SurfacePoint::AtVertex(to);
  return SurfacePoint::OnEdge(from, to, t);
}

SurfacePoint CanonicalFacePoint(uint32_t face, const std::array<uint32_t, 3>& file_corners,
                                std::array<double, 3> bary) {
  for (double& b : bary) b = std::max(0.0, b);
  double sum = bary[0] + bary[1] + bary[2];
  int zeros = 0;
  for (double& b : bary) {
    b /= sum;
    if (b <= kSurfaceSnap) b = 0, ++zeros;
  }
  if (zeros == 0) return SurfacePoint::InFace(face, bary[0], bary[1], bary[2]);
  if (zeros >= 2) {
    const int k = bary[0] > 0 ? 0 : (bary[1] > 0 ? 1 : 2);
    return SurfacePoint::AtVertex(file_corners[k]);
  }
  const int z = bary[0] == 0 ? 0 : (bary[1] == 0 ? 1 : 2);
  const int i = (z + 1) % 3, j = (z + 2) % 3;
  return SurfacePoint::OnEdge(file_corners[i], file_corners[j], bary[j] / (bary[i] + bary[j]));
}

SurfacePoint CanonicalPoint(const TriangleMesh& mesh, const SurfacePoint& p) {
  switch (p.kind) {
    case SurfacePoint::Kind::kEdge:
      return CanonicalEdgePoint(p.edge_from, p.edge_to, p.t);
    case SurfacePoint::Kind::kFace:
      return CanonicalFacePoint(p.face, mesh.FileCorners(p.face), p.bary);
    case SurfacePoint::Kind::kVertex:
    case SurfacePoint::Kind::kPosition:
      break;
  }
  return p;
}

std::string SurfacePointToString(const SurfacePoint& p) {
  switch (p.kind) {
    case SurfacePoint::Kind::kVertex:
      return absl::StrFormat("%d", p.vertex);
    case SurfacePoint::Kind::kEdge:
      return absl::StrFormat("e:%d:%d:%.17g", p.edge_from, p.edge_to, p.t);
    case SurfacePoint::Kind::kFace:
      return absl::StrFormat("f:%d:%.17g:%.17g:%.17g", p.face, p.bary[0], p.bary[1], p.bary[2]);
    case SurfacePoint::Kind::kPosition:
      return absl::StrFormat("p:%.17g:%.17g:%.17g", p.position[0], p.position[1], p.position[2]);
  }
  return "?";
}

}  // namespace geodex
