#include "util/mesh_factory.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>

namespace geodex {
namespace {

constexpr double kPi = std::numbers::pi;

Vec3 Sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 Add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec3 Scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double Dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double Norm(const Vec3& a) { return std::sqrt(Dot(a, a)); }
Vec3 Normalize(const Vec3& a) { return Scale(a, 1.0 / Norm(a)); }
double Angle(const Vec3& a, const Vec3& b) { return std::atan2(Norm(Cross(a, b)), Dot(a, b)); }

Vec2 Sub2(const Vec2& a, const Vec2& b) { return {a[0] - b[0], a[1] - b[1]}; }
double Cross2(const Vec2& a, const Vec2& b) { return a[0] * b[1] - a[1] * b[0]; }

// splitmix64: a deterministic, platform-independent hash for the jitter.
uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}
// Uniform in [-1, 1], from (seed, index, axis).
double HashUnit(uint64_t seed, uint64_t index, int axis) {
  const uint64_t h = SplitMix64(SplitMix64(seed * 0x100000001b3ull + index) + axis);
  return static_cast<double>(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

void AddVertex(MeshData* m, double x, double y, double z) {
  m->positions.push_back(x);
  m->positions.push_back(y);
  m->positions.push_back(z);
}
void AddFace(MeshData* m, uint32_t a, uint32_t b, uint32_t c) {
  m->faces.push_back(a);
  m->faces.push_back(b);
  m->faces.push_back(c);
}
// Quad a b c d in counter-clockwise order (seen from the front), split along a-c or b-d.
void AddQuad(MeshData* m, uint32_t a, uint32_t b, uint32_t c, uint32_t d, bool diagonal_bd) {
  if (diagonal_bd) {
    AddFace(m, a, b, d);
    AddFace(m, b, c, d);
  } else {
    AddFace(m, a, b, c);
    AddFace(m, a, c, d);
  }
}

// --- cube unfolding ---------------------------------------------------------------------------

struct BigFace {
  std::array<Vec3, 4> corner;  // counter-clockwise seen from outside
  Vec3 normal;
  Vec3 centroid;
};

std::vector<BigFace> CubeFaces(double side) {
  std::vector<BigFace> faces;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // e_u x e_v = e_axis
    for (int high = 0; high < 2; ++high) {
      auto point = [&](double a, double b) {
        Vec3 p{};
        p[axis] = high ? side : 0;
        p[u] = a;
        p[v] = b;
        return p;
      };
      BigFace f;
      if (high) {
        f.corner = {point(0, 0), point(side, 0), point(side, side), point(0, side)};
      } else {
        f.corner = {point(0, 0), point(0, side), point(side, side), point(side, 0)};
      }
      f.normal = {0, 0, 0};
      f.normal[axis] = high ? 1 : -1;
      f.centroid = point(0.5 * side, 0.5 * side);
      faces.push_back(f);
    }
  }
  return faces;
}

bool OnBigFace(const BigFace& f, const Vec3& p, double tol) {
  if (std::abs(Dot(Sub(p, f.corner[0]), f.normal)) > tol) return false;
  for (int i = 0; i < 4; ++i) {
    const Vec3 e = Sub(f.corner[(i + 1) % 4], f.corner[i]);
    if (Dot(Cross(e, Sub(p, f.corner[i])), f.normal) < -tol * Norm(e)) return false;
  }
  return true;
}

// An isometry from a big face's plane to the unfolding plane.
struct Frame {
  Vec3 o3, e1, e2;
  Vec2 o2, f1, f2;
  Vec2 Map(const Vec3& p) const {
    const Vec3 d = Sub(p, o3);
    const double a = Dot(d, e1), b = Dot(d, e2);
    return {o2[0] + a * f1[0] + b * f2[0], o2[1] + a * f1[1] + b * f2[1]};
  }
};

struct Hinge {
  Vec2 a, b;
};

class CubeUnfolder {
 public:
  CubeUnfolder(double side, const Vec3& s, const Vec3& t)
      : faces_(CubeFaces(side)), s_(s), t_(t), tol_(1e-9 * side) {}

  double Run() {
    for (int f = 0; f < 6; ++f) {
      if (!OnBigFace(faces_[f], s_, tol_)) continue;
      Frame frame;
      frame.o3 = faces_[f].corner[0];
      frame.e1 = Normalize(Sub(faces_[f].corner[1], faces_[f].corner[0]));
      frame.e2 = Cross(faces_[f].normal, frame.e1);
      frame.o2 = {0, 0};
      frame.f1 = {1, 0};
      frame.f2 = {0, 1};
      s2_ = frame.Map(s_);
      std::vector<Hinge> hinges;
      Visit(f, frame, 1u << f, &hinges);
    }
    return best_;
  }

 private:
  void Visit(int f, const Frame& frame, unsigned visited, std::vector<Hinge>* hinges) {
    if (OnBigFace(faces_[f], t_, tol_)) {
      const Vec2 t2 = frame.Map(t_);
      if (SegmentCrossesHinges(s2_, t2, *hinges)) best_ = std::min(best_, Distance2(s2_, t2));
    }
    for (int e = 0; e < 4; ++e) {
      const Vec3& a = faces_[f].corner[e];
      const Vec3& b = faces_[f].corner[(e + 1) % 4];
      for (int g = 0; g < 6; ++g) {
        if (visited & (1u << g)) continue;
        if (!OnBigFace(faces_[g], a, tol_) || !OnBigFace(faces_[g], b, tol_)) continue;
        // Unfold g about the hinge a-b: a and b keep their images, g's interior goes to the side
        // of the hinge opposite to f's interior.
        Frame next;
        next.o3 = a;
        next.e1 = Normalize(Sub(b, a));
        const Vec3 into_g = Sub(faces_[g].centroid, a);
        next.e2 = Normalize(Sub(into_g, Scale(next.e1, Dot(into_g, next.e1))));
        const Vec2 a2 = frame.Map(a), b2 = frame.Map(b), c2 = frame.Map(faces_[f].centroid);
        const double len = Distance2(a2, b2);
        next.o2 = a2;
        next.f1 = {(b2[0] - a2[0]) / len, (b2[1] - a2[1]) / len};
        next.f2 = {-next.f1[1], next.f1[0]};
        const Vec2 to_f = Sub2(c2, a2);
        if (next.f2[0] * to_f[0] + next.f2[1] * to_f[1] > 0) {
          next.f2 = {-next.f2[0], -next.f2[1]};
        }
        hinges->push_back({a2, b2});
        Visit(g, next, visited | (1u << g), hinges);
        hinges->pop_back();
      }
    }
  }

  // The straight segment s->t must cross every hinge, inside the hinge, in the hinges' order.
  static bool SegmentCrossesHinges(const Vec2& s, const Vec2& t, const std::vector<Hinge>& hinges) {
    constexpr double kEps = 1e-12;
    const Vec2 d = Sub2(t, s);
    double previous = -kEps;
    for (const Hinge& h : hinges) {
      const Vec2 e = Sub2(h.b, h.a);
      const double denom = Cross2(d, e);
      // Parallel: the path runs along the hinge; then a path inside one face is as short.
      if (std::abs(denom) <=
          1e-14 * (std::abs(d[0]) + std::abs(d[1])) * (std::abs(e[0]) + std::abs(e[1]))) {
        return false;
      }
      const Vec2 as = Sub2(h.a, s);
      const double u = Cross2(as, e) / denom;  // along s->t
      const double w = Cross2(as, d) / denom;  // along the hinge
      if (u < -kEps || u > 1 + kEps || w < -kEps || w > 1 + kEps || u < previous - kEps) {
        return false;
      }
      previous = u;
    }
    return true;
  }

  std::vector<BigFace> faces_;
  Vec3 s_, t_;
  Vec2 s2_{};
  double tol_;
  double best_ = std::numeric_limits<double>::infinity();
};

}  // namespace

Vec3 VertexPosition(const MeshData& mesh, uint32_t v) {
  return {mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]};
}
Vec3 FaceCentroid(const MeshData& mesh, uint32_t f) {
  Vec3 c{0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const Vec3 p = VertexPosition(mesh, mesh.faces[3 * f + k]);
    for (int j = 0; j < 3; ++j) c[j] += p[j] / 3;
  }
  return c;
}
double Distance3(const Vec3& a, const Vec3& b) { return Norm(Sub(a, b)); }
double Distance2(const Vec2& a, const Vec2& b) { return std::hypot(a[0] - b[0], a[1] - b[1]); }

MeshData MakeGrid(const GridSpec& spec) {
  assert(spec.jitter >= 0 && spec.jitter <= 0.2);
  MeshData m;
  const int nx = spec.cells_x, ny = spec.cells_y;
  const double hx = spec.width / nx, hy = spec.height / ny;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      double x = i * hx, y = j * hy;
      if (spec.jitter > 0 && i > 0 && j > 0 && i < nx && j < ny) {
        const uint64_t id = static_cast<uint64_t>(j) * (nx + 1) + i;
        x += spec.jitter * hx * HashUnit(spec.seed, id, 0);
        y += spec.jitter * hy * HashUnit(spec.seed, id, 1);
      }
      AddVertex(&m, x, y, 0);
    }
  }
  auto id = [&](int i, int j) { return static_cast<uint32_t>(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      AddQuad(&m, id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1),
              spec.alternate_diagonals && (i + j) % 2 == 1);
    }
  }
  return m;
}

MeshData MakeLShape(int n, double size, double jitter, uint64_t seed) {
  assert(jitter >= 0 && jitter <= 0.2);
  const int cells = 2 * n;
  const double h = size / cells;
  MeshData m;
  std::vector<uint32_t> ids((cells + 1) * (cells + 1), 0xffffffffu);
  auto in_domain = [&](int i, int j) { return !(i > n && j > n); };
  auto on_boundary = [&](int i, int j) {
    return i == 0 || j == 0 || i == cells || j == cells || (i >= n && j == n) || (i == n && j >= n);
  };
  for (int j = 0; j <= cells; ++j) {
    for (int i = 0; i <= cells; ++i) {
      if (!in_domain(i, j)) continue;
      double x = i * h, y = j * h;
      if (jitter > 0 && !on_boundary(i, j)) {
        const uint64_t key = static_cast<uint64_t>(j) * (cells + 1) + i;
        x += jitter * h * HashUnit(seed, key, 0);
        y += jitter * h * HashUnit(seed, key, 1);
      }
      ids[j * (cells + 1) + i] = static_cast<uint32_t>(m.vertex_count());
      AddVertex(&m, x, y, 0);
    }
  }
  auto id = [&](int i, int j) { return ids[j * (cells + 1) + i]; };
  for (int j = 0; j < cells; ++j) {
    for (int i = 0; i < cells; ++i) {
      if (i >= n && j >= n) continue;  // the removed quadrant's cells
      AddQuad(&m, id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1), (i + j) % 2 == 1);
    }
  }
  return m;
}

Vec2 LShapeReflexCorner(double size) { return {0.5 * size, 0.5 * size}; }

double LShapeDistance(double size, const Vec2& s, const Vec2& t) {
  // The segment s + u (t - s), u in [0, 1], leaves the closed L iff it meets the open removed
  // square (c, size]^2 with c = size / 2, i.e. iff {u : x(u) > c} and {u : y(u) > c} (open
  // intervals) overlap. Both points lie in [0, size]^2, so the outer sides never matter.
  const double c = 0.5 * size;
  double lo = 0, hi = 1;
  for (int axis = 0; axis < 2; ++axis) {
    const double p = s[axis], d = t[axis] - s[axis];
    if (d == 0) {
      if (p <= c) hi = -1;  // never strictly above c
      continue;
    }
    const double u = (c - p) / d;  // where the coordinate crosses c
    if (d > 0) {
      lo = std::max(lo, u);
    } else {
      hi = std::min(hi, u);
    }
  }
  const bool leaves = lo < hi;
  const Vec2 corner = LShapeReflexCorner(size);
  return leaves ? Distance2(s, corner) + Distance2(corner, t) : Distance2(s, t);
}

MeshData MakeCube(int k, double side) {
  MeshData m;
  const int n = k + 1;
  std::vector<uint32_t> ids(n * n * n, 0xffffffffu);
  const double h = side / k;
  for (int z = 0; z < n; ++z) {
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const bool surface = x == 0 || y == 0 || z == 0 || x == k || y == k || z == k;
        if (!surface) continue;
        ids[(z * n + y) * n + x] = static_cast<uint32_t>(m.vertex_count());
        // Exact multiples at the far side so opposite faces are exactly planar.
        AddVertex(&m, x == k ? side : x * h, y == k ? side : y * h, z == k ? side : z * h);
      }
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int high = 0; high < 2; ++high) {
      auto id = [&](int a, int b) {
        int c[3];
        c[axis] = high ? k : 0;
        c[u] = a;
        c[v] = b;
        return ids[(c[2] * n + c[1]) * n + c[0]];
      };
      for (int b = 0; b < k; ++b) {
        for (int a = 0; a < k; ++a) {
          const bool alt = (a + b) % 2 == 1;
          if (high) {
            AddQuad(&m, id(a, b), id(a + 1, b), id(a + 1, b + 1), id(a, b + 1), alt);
          } else {
            AddQuad(&m, id(a, b), id(a, b + 1), id(a + 1, b + 1), id(a + 1, b), alt);
          }
        }
      }
    }
  }
  return m;
}

double CubeDistance(double side, const Vec3& s, const Vec3& t) {
  return CubeUnfolder(side, s, t).Run();
}

Cone MakeCone(int segments, int rings, double slant, double height_ratio, bool saddle) {
  assert(!saddle || segments % 2 == 0);
  Cone cone;
  std::vector<Vec3> g(segments);
  for (int k = 0; k < segments; ++k) {
    const double theta = 2 * kPi * k / segments;
    const double z = saddle ? (k % 2 == 0 ? height_ratio : -height_ratio) : -height_ratio;
    g[k] = Normalize({std::cos(theta), std::sin(theta), z});
  }
  std::vector<double> phi_of(segments, 0);
  double total = 0;
  for (int k = 0; k < segments; ++k) {
    phi_of[k] = total;
    total += Angle(g[k], g[(k + 1) % segments]);
  }
  cone.total_angle = total;
  AddVertex(&cone.data, 0, 0, 0);
  cone.rho.push_back(0);
  cone.phi.push_back(0);
  for (int j = 1; j <= rings; ++j) {
    const double r = slant * j / rings;
    for (int k = 0; k < segments; ++k) {
      AddVertex(&cone.data, r * g[k][0], r * g[k][1], r * g[k][2]);
      cone.rho.push_back(r);
      cone.phi.push_back(phi_of[k]);
    }
  }
  auto id = [&](int j, int k) {
    return static_cast<uint32_t>(1 + (j - 1) * segments + k % segments);
  };
  for (int k = 0; k < segments; ++k) AddFace(&cone.data, 0, id(1, k), id(1, k + 1));
  for (int j = 1; j < rings; ++j) {
    for (int k = 0; k < segments; ++k) {
      AddQuad(&cone.data, id(j, k), id(j + 1, k), id(j + 1, k + 1), id(j, k + 1), (j + k) % 2 == 1);
    }
  }
  return cone;
}

double ConeDistance(const Cone& cone, uint32_t a, uint32_t b) {
  const double ra = cone.rho[a], rb = cone.rho[b];
  double delta = std::abs(cone.phi[a] - cone.phi[b]);
  delta = std::min(delta, cone.total_angle - delta);
  if (delta >= kPi) return ra + rb;
  // Law of cosines in a numerically benign form: |a - b|^2 = (ra - rb)^2 + 4 ra rb sin^2(delta/2).
  const double half = std::sin(0.5 * delta);
  return std::sqrt((ra - rb) * (ra - rb) + 4 * ra * rb * half * half);
}

Cylinder MakeOpenCylinder(int segments, int rings, double radius, double height,
                          bool alternate_diagonals) {
  Cylinder cyl;
  const double side = 2 * radius * std::sin(kPi / segments);
  cyl.perimeter = segments * side;
  for (int i = 0; i <= rings; ++i) {
    const double z = height * i / rings;
    for (int k = 0; k < segments; ++k) {
      const double theta = 2 * kPi * k / segments;
      AddVertex(&cyl.data, radius * std::cos(theta), radius * std::sin(theta), z);
      cyl.u.push_back(k * side);
      cyl.z.push_back(z);
    }
  }
  auto id = [&](int i, int k) { return static_cast<uint32_t>(i * segments + k % segments); };
  for (int i = 0; i < rings; ++i) {
    for (int k = 0; k < segments; ++k) {
      AddQuad(&cyl.data, id(i, k), id(i, k + 1), id(i + 1, k + 1), id(i + 1, k),
              alternate_diagonals && (i + k) % 2 == 1);
    }
  }
  return cyl;
}

double CylinderDistance(const Cylinder& cyl, uint32_t a, uint32_t b) {
  const double du = cyl.u[a] - cyl.u[b], dz = cyl.z[a] - cyl.z[b];
  double best = std::numeric_limits<double>::infinity();
  for (int shift = -1; shift <= 1; ++shift) {
    best = std::min(best, std::hypot(du + shift * cyl.perimeter, dz));
  }
  return best;
}

void ApplyRigidMotion(MeshData* mesh, const Vec3& axis, double angle, const Vec3& translation) {
  const Vec3 k = Normalize(axis);
  const double c = std::cos(angle), s = std::sin(angle);
  for (size_t v = 0; v < mesh->vertex_count(); ++v) {
    const Vec3 p = VertexPosition(*mesh, static_cast<uint32_t>(v));
    // Rodrigues: p c + (k x p) s + k (k . p)(1 - c).
    const Vec3 r = Add(Add(Scale(p, c), Scale(Cross(k, p), s)), Scale(k, Dot(k, p) * (1 - c)));
    for (int a = 0; a < 3; ++a) mesh->positions[3 * v + a] = r[a] + translation[a];
  }
}

MeshData Soup(const std::vector<std::array<double, 3>>& points,
              const std::vector<std::array<uint32_t, 3>>& faces) {
  MeshData m;
  for (const auto& p : points) m.positions.insert(m.positions.end(), p.begin(), p.end());
  for (const auto& f : faces) m.faces.insert(m.faces.end(), f.begin(), f.end());
  return m;
}

}  // namespace geodex
