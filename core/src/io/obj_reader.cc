// Wavefront OBJ reader. Hand-written rather than tinyobjloader so that every error names its line
// (tinyobjloader reports out-of-range indices without a position) and parses the buffer in place.
// Only `v` and `f` matter; texture coordinates, normals, groups, materials and curves are skipped.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "geodex/limits.h"
#include "geodex/mesh_data.h"
#include "geodex/mesh_io.h"
#include "io/io_util.h"

namespace geodex::io_internal {
namespace {

// OBJ statements are words (v, vt, usemtl, curv2, ...); vendors add their own, which are skipped.
bool IsDirective(absl::string_view token) {
  for (char c : token) {
    if (!absl::ascii_isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
  }
  return true;
}

}  // namespace

absl::StatusOr<MeshData> ReadObj(absl::string_view bytes, const std::string& name,
                                 const ReadLimits& limits) {
  MeshData mesh;
  uint64_t vertex_count = 0;
  // Positive indices may point past the vertices read so far (a forward reference); those
  // corners are checked once the whole file is read, remembering where they came from.
  std::vector<std::pair<size_t, uint64_t>> forward;  // (corner in mesh.faces, line)
  std::vector<uint32_t> polygon;
  std::vector<size_t> forward_corners;  // positions in `polygon`
  LineReader lines(bytes, /*hash_comments=*/true);
  absl::string_view line;
  while (lines.NextNonBlank(&line)) {
    const char* p = line.data();
    const char* end = line.data() + line.size();
    const absl::string_view directive = TokenAt(p, end);
    p += directive.size();
    if (directive == "v") {
      if (vertex_count >= MaxVertices(limits)) {
        return LimitExceededError(Limit::kVertices,
                                  absl::StrCat(name, ": line ", lines.line_number(), ": more than ",
                                               MaxVertices(limits), " vertices"));
      }
      double xyz[3];
      for (int k = 0; k < 3; ++k) {
        const Scan scan = ScanDouble(&p, end, &xyz[k]);
        if (scan == Scan::kMissing) {
          return LineError(name, lines.line_number(),
                           absl::StrCat("expected 3 coordinates, found ", k));
        }
        if (scan == Scan::kBad) {
          return LineError(name, lines.line_number(),
                           absl::StrCat("invalid coordinate ", Quote(TokenAt(p, end))));
        }
      }
      // A w component or a vertex colour after x y z is ignored.
      mesh.positions.insert(mesh.positions.end(), {xyz[0], xyz[1], xyz[2]});
      ++vertex_count;
    } else if (directive == "f") {
      polygon.clear();
      forward_corners.clear();
      while (true) {
        p = SkipBlanks(p, end);
        if (p == end) break;
        const absl::string_view corner = TokenAt(p, end);
        p += corner.size();
        // v, v/vt, v//vn or v/vt/vn: only the position index matters.
        const absl::string_view index_text = corner.substr(0, corner.find('/'));
        int64_t index;
        if (!ParseInt(index_text, &index)) {
          return LineError(name, lines.line_number(),
                           absl::StrCat("invalid vertex reference ", Quote(corner)));
        }
        int64_t resolved;
        if (index > 0) {
          resolved = index - 1;
          if (static_cast<uint64_t>(resolved) >= MaxVertices(limits)) {
            return LineError(name, lines.line_number(),
                             absl::StrCat("vertex index ", index, " out of range"));
          }
          if (static_cast<uint64_t>(resolved) >= vertex_count) {
            forward_corners.push_back(polygon.size());
          }
        } else if (index < 0) {
          // Relative: -1 is the last vertex defined so far.
          resolved = static_cast<int64_t>(vertex_count) + index;
          if (resolved < 0) {
            return LineError(name, lines.line_number(),
                             absl::StrCat("vertex index ", index, " out of range (", vertex_count,
                                          " vertices defined so far)"));
          }
        } else {
          return LineError(name, lines.line_number(), "vertex index 0 (OBJ indices start at 1)");
        }
        polygon.push_back(static_cast<uint32_t>(resolved));
      }
      if (polygon.size() < 3) {
        return LineError(
            name, lines.line_number(),
            absl::StrCat("face has ", polygon.size(), " vertices (at least 3 needed)"));
      }
      if (mesh.faces.size() / 3 + (polygon.size() - 2) > limits.max_faces) {
        return LimitExceededError(Limit::kFaces,
                                  absl::StrCat(name, ": line ", lines.line_number(), ": more than ",
                                               limits.max_faces, " faces"));
      }
      // Fan triangulation in order: (v0, v1, v2), (v0, v2, v3), ...
      for (size_t k = 2; k < polygon.size(); ++k) {
        mesh.faces.insert(mesh.faces.end(), {polygon[0], polygon[k - 1], polygon[k]});
      }
      for (size_t corner : forward_corners) {
        // The first triangle holding the corner is enough to find its value at the end.
        const size_t slot = corner == 0 ? 0 : (corner < 2 ? 1 : 3 * (corner - 2) + 2);
        forward.emplace_back(mesh.faces.size() - 3 * (polygon.size() - 2) + slot,
                             lines.line_number());
      }
    } else if (!IsDirective(directive)) {
      // Binary garbage or a broken line rather than a statement some other tool understands.
      return LineError(name, lines.line_number(),
                       absl::StrCat("unexpected ", Quote(directive), " (not an OBJ statement)"));
    }
    // Everything else (vt, vn, vp, g, o, s, usemtl, mtllib, l, p, ...) is not geometry we use.
  }
  for (const auto& [slot, line_number] : forward) {
    if (mesh.faces[slot] >= vertex_count) {
      return LineError(name, line_number,
                       absl::StrCat("vertex index ", uint64_t{mesh.faces[slot]} + 1,
                                    " out of range (", vertex_count, " vertices)"));
    }
  }
  return mesh;
}

}  // namespace geodex::io_internal
