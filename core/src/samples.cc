#include "geodex/samples.h"

#include <cmath>
#include <map>
#include <utility>

#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"

namespace geodex {
namespace {

constexpr double kPi = 3.14159265358979323846;

MeshData Terrain() {
  constexpr int kN = 64;  // cells per side
  MeshData m;
  for (int i = 0; i <= kN; ++i) {
    for (int j = 0; j <= kN; ++j) {
      const double x = i / double(kN), y = j / double(kN);
      // Two hills and a ridge: passes between them are saddle vertices.
      const double z = 0.25 * std::exp(-((x - 0.3) * (x - 0.3) + (y - 0.35) * (y - 0.35)) / 0.02) +
                       0.2 * std::exp(-((x - 0.7) * (x - 0.7) + (y - 0.6) * (y - 0.6)) / 0.03) +
                       0.03 * std::sin(6 * x) * std::cos(5 * y);
      m.positions.insert(m.positions.end(), {x, y, z});
    }
  }
  auto id = [](int i, int j) { return static_cast<uint32_t>(i * (kN + 1) + j); };
  for (int i = 0; i < kN; ++i) {
    for (int j = 0; j < kN; ++j) {
      m.faces.insert(m.faces.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.faces.insert(m.faces.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return m;
}

MeshData Torus() {
  constexpr int kU = 48, kV = 24;
  constexpr double kR = 1.0, kr = 0.35;
  MeshData m;
  for (int i = 0; i < kU; ++i) {
    for (int j = 0; j < kV; ++j) {
      const double u = 2 * kPi * i / kU, v = 2 * kPi * j / kV;
      m.positions.insert(m.positions.end(),
                         {(kR + kr * std::cos(v)) * std::cos(u),
                          (kR + kr * std::cos(v)) * std::sin(u), kr * std::sin(v)});
    }
  }
  auto id = [](int i, int j) { return static_cast<uint32_t>((i % kU) * kV + (j % kV)); };
  for (int i = 0; i < kU; ++i) {
    for (int j = 0; j < kV; ++j) {
      m.faces.insert(m.faces.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.faces.insert(m.faces.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return m;
}

MeshData Sphere() {
  const double t = (1 + std::sqrt(5.0)) / 2;
  MeshData m;
  m.positions = {-1, t,  0,  1, t, 0,  -1, -t, 0,  1, -t, 0, 0,  -1, t,  0,  1, t,
                 0,  -1, -t, 0, 1, -t, t,  0,  -1, t, 0,  1, -t, 0,  -1, -t, 0, 1};
  m.faces = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
             4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
             6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
  for (int level = 0; level < 3; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoint;
    auto mid = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      const uint32_t id = static_cast<uint32_t>(m.positions.size() / 3);
      for (int k = 0; k < 3; ++k) {
        m.positions.push_back(0.5 * (m.positions[3 * a + k] + m.positions[3 * b + k]));
      }
      midpoint.emplace(key, id);
      return id;
    };
    std::vector<uint32_t> faces;
    for (size_t f = 0; f < m.faces.size(); f += 3) {
      const uint32_t a = m.faces[f], b = m.faces[f + 1], c = m.faces[f + 2];
      const uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      faces.insert(faces.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    m.faces = std::move(faces);
  }
  for (size_t v = 0; v < m.positions.size(); v += 3) {
    const double n =
        std::sqrt(m.positions[v] * m.positions[v] + m.positions[v + 1] * m.positions[v + 1] +
                  m.positions[v + 2] * m.positions[v + 2]);
    for (int k = 0; k < 3; ++k) m.positions[v + k] /= n;
  }
  return m;
}

}  // namespace

std::vector<std::string> SampleMeshNames() { return {"terrain", "torus", "sphere"}; }

absl::StatusOr<MeshData> MakeSampleMesh(const std::string& name_or_spec) {
  std::string name = name_or_spec;
  if (name.rfind("sample:", 0) == 0) name = name.substr(7);
  if (name == "terrain") return Terrain();
  if (name == "torus") return Torus();
  if (name == "sphere") return Sphere();
  return absl::NotFoundError(absl::StrFormat("no built-in sample mesh '%s' (samples: %s)", name,
                                             absl::StrJoin(SampleMeshNames(), ", ")));
}

}  // namespace geodex
