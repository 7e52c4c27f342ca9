// STL reader, ascii and binary. STL stores every triangle's corners by value, so corners with
// bit-identical positions are welded into one vertex, numbered in order of first appearance.
#include <cstdint>
#include <cstring>
#include <string>
#include <unordered_map>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "geodex/limits.h"
#include "geodex/mesh_data.h"
#include "geodex/mesh_io.h"
#include "io/io_util.h"

namespace geodex::io_internal {
namespace {

struct PositionKey {
  uint64_t bits[3];
  bool operator==(const PositionKey& o) const {
    return bits[0] == o.bits[0] && bits[1] == o.bits[1] && bits[2] == o.bits[2];
  }
};

struct PositionHash {
  static uint64_t Mix(uint64_t x) {  // splitmix64 finaliser
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ULL;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
  }
  size_t operator()(const PositionKey& k) const {
    return static_cast<size_t>(Mix(k.bits[0] ^ Mix(k.bits[1] ^ Mix(k.bits[2]))));
  }
};

// Maps positions to vertex indices, appending new positions to the mesh.
class Welder {
 public:
  Welder(MeshData* mesh, uint64_t max_vertices) : mesh_(mesh), max_vertices_(max_vertices) {}

  // False when a new vertex would exceed the limit.
  bool Add(const double xyz[3], uint32_t* index) {
    PositionKey key;
    std::memcpy(key.bits, xyz, sizeof(key.bits));
    const uint32_t next = static_cast<uint32_t>(mesh_->vertex_count());
    auto [it, inserted] = map_.try_emplace(key, next);
    if (inserted) {
      if (next >= max_vertices_) return false;
      mesh_->positions.insert(mesh_->positions.end(), {xyz[0], xyz[1], xyz[2]});
    }
    *index = it->second;
    return true;
  }

  void Reserve(size_t vertices) { map_.reserve(vertices); }

 private:
  MeshData* mesh_;
  uint64_t max_vertices_;
  std::unordered_map<PositionKey, uint32_t, PositionHash> map_;
};

absl::Status TooManyVertices(const std::string& name, uint64_t limit) {
  return LimitExceededError(Limit::kVertices,
                            absl::StrCat(name, ": more than ", limit, " distinct vertices"));
}

uint32_t LoadLe32(const char* p) {
  const auto* u = reinterpret_cast<const unsigned char*>(p);
  return uint32_t{u[0]} | uint32_t{u[1]} << 8 | uint32_t{u[2]} << 16 | uint32_t{u[3]} << 24;
}

absl::StatusOr<MeshData> ReadBinaryStl(absl::string_view bytes, const std::string& name,
                                       const ReadLimits& limits) {
  if (bytes.size() < 84) {
    return ByteError(name, bytes.size(),
                     "truncated binary STL header (80-byte header and triangle count expected)");
  }
  const uint64_t n = LoadLe32(bytes.data() + 80);
  const uint64_t expected = 84 + 50 * n;
  if (bytes.size() < expected) {
    const uint64_t complete = (bytes.size() - 84) / 50;
    return ByteError(name, 84 + 50 * complete,
                     absl::StrCat("truncated triangle data (triangle ", complete, " of ", n, ")"));
  }
  if (bytes.size() > expected) {
    return ByteError(name, expected,
                     absl::StrCat(bytes.size() - expected, " unexpected bytes after the ", n,
                                  " triangles the header declares"));
  }
  if (n > limits.max_faces) {
    return LimitExceededError(
        Limit::kFaces,
        absl::StrCat(name, ": ", n, " triangles exceed the limit of ", limits.max_faces));
  }
  MeshData mesh;
  mesh.faces.reserve(3 * n);
  Welder welder(&mesh, MaxVertices(limits));
  welder.Reserve(n / 2 + 3);  // a closed mesh has about half as many vertices as triangles
  for (uint64_t t = 0; t < n; ++t) {
    const char* record = bytes.data() + 84 + 50 * t + 12;  // skip the normal
    for (int c = 0; c < 3; ++c) {
      double xyz[3];
      for (int k = 0; k < 3; ++k) {
        const uint32_t bits = LoadLe32(record + 12 * c + 4 * k);
        float value;
        std::memcpy(&value, &bits, sizeof(value));
        xyz[k] = value;
      }
      uint32_t index;
      if (!welder.Add(xyz, &index)) return TooManyVertices(name, MaxVertices(limits));
      mesh.faces.push_back(index);
    }
  }
  return mesh;
}

absl::StatusOr<MeshData> ReadAsciiStl(absl::string_view bytes, const std::string& name,
                                      const ReadLimits& limits) {
  MeshData mesh;
  Welder welder(&mesh, MaxVertices(limits));
  TokenReader tokens(bytes, 1);
  absl::string_view token;
  std::vector<uint32_t> polygon;
  auto expect = [&](absl::string_view keyword) -> absl::Status {
    if (!tokens.Next(&token)) {
      return LineError(name, tokens.line(),
                       absl::StrCat("unexpected end of file: expected '", keyword, "'"));
    }
    if (!absl::EqualsIgnoreCase(token, keyword)) {
      return LineError(name, tokens.line(),
                       absl::StrCat("expected '", keyword, "', found ", Quote(token)));
    }
    return absl::OkStatus();
  };
  auto numbers = [&](double* xyz) -> absl::Status {
    for (int k = 0; k < 3; ++k) {
      if (!tokens.Next(&token)) {
        return LineError(name, tokens.line(), "unexpected end of file: expected a number");
      }
      if (!ParseDouble(token, &xyz[k])) {
        return LineError(name, tokens.line(), absl::StrCat("invalid number ", Quote(token)));
      }
    }
    return absl::OkStatus();
  };
  if (absl::Status s = expect("solid"); !s.ok()) return s;
  tokens.SkipRestOfLine();  // the solid's name
  while (true) {
    if (!tokens.Next(&token)) {
      return LineError(name, tokens.line(), "unexpected end of file: expected 'endsolid'");
    }
    if (absl::EqualsIgnoreCase(token, "endsolid")) {
      tokens.SkipRestOfLine();
      if (tokens.AtEnd()) break;
      // Several solids may follow one another; they form one mesh.
      if (absl::Status s = expect("solid"); !s.ok()) return s;
      tokens.SkipRestOfLine();
      continue;
    }
    if (!absl::EqualsIgnoreCase(token, "facet")) {
      return LineError(name, tokens.line(),
                       absl::StrCat("expected 'facet' or 'endsolid', found ", Quote(token)));
    }
    double normal[3];
    if (absl::Status s = expect("normal"); !s.ok()) return s;
    if (absl::Status s = numbers(normal); !s.ok()) return s;
    if (absl::Status s = expect("outer"); !s.ok()) return s;
    if (absl::Status s = expect("loop"); !s.ok()) return s;
    const uint64_t facet_line = tokens.line();
    polygon.clear();
    while (true) {
      if (!tokens.Next(&token)) {
        return LineError(name, tokens.line(), "unexpected end of file: expected 'endloop'");
      }
      if (absl::EqualsIgnoreCase(token, "endloop")) break;
      if (!absl::EqualsIgnoreCase(token, "vertex")) {
        return LineError(name, tokens.line(),
                         absl::StrCat("expected 'vertex' or 'endloop', found ", Quote(token)));
      }
      double xyz[3];
      if (absl::Status s = numbers(xyz); !s.ok()) return s;
      uint32_t index;
      if (!welder.Add(xyz, &index)) return TooManyVertices(name, MaxVertices(limits));
      polygon.push_back(index);
    }
    if (polygon.size() < 3) {
      return LineError(name, facet_line,
                       absl::StrCat("facet has ", polygon.size(), " vertices (at least 3 needed)"));
    }
    if (absl::Status s = expect("endfacet"); !s.ok()) return s;
    if (mesh.face_count() + polygon.size() - 2 > limits.max_faces) {
      return LimitExceededError(Limit::kFaces,
                                absl::StrCat(name, ": line ", tokens.line(), ": more than ",
                                             limits.max_faces, " triangles"));
    }
    for (size_t k = 2; k < polygon.size(); ++k) {  // fan triangulation, in order
      mesh.faces.insert(mesh.faces.end(), {polygon[0], polygon[k - 1], polygon[k]});
    }
  }
  return mesh;
}

// Binary headers may also start with "solid" (some CAD exporters do that), so ascii also needs the
// size not to match the binary layout and no NUL byte near the start.
bool LooksAscii(absl::string_view bytes) {
  if (IsBinaryStlSize(bytes)) return false;
  absl::string_view start = bytes.substr(0, 512);
  const size_t first = start.find_first_not_of(" \t\r\n");
  if (first == absl::string_view::npos) return false;
  start.remove_prefix(first);
  return absl::StartsWithIgnoreCase(start, "solid") && start.find('\0') == absl::string_view::npos;
}

}  // namespace

absl::StatusOr<MeshData> ReadStl(absl::string_view bytes, const std::string& name,
                                 const ReadLimits& limits) {
  return LooksAscii(bytes) ? ReadAsciiStl(bytes, name, limits) : ReadBinaryStl(bytes, name, limits);
}

}  // namespace geodex::io_internal
