// OFF reader (and the COFF/NOFF/CNOFF/STOFF variants). Line based and allocation-checked; it is
// the format of the large benchmark meshes, so it scans the buffer directly with from_chars.
#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "absl/strings/strip.h"
#include "geodex/limits.h"
#include "geodex/mesh_data.h"
#include "geodex/mesh_io.h"
#include "io/io_util.h"

namespace geodex::io_internal {
namespace {

// Smallest text a vertex ("0 0 0\n") and a face ("3 0 0 0\n") can take: bounds the header counts
// by the bytes present before anything is reserved.
constexpr uint64_t kMinVertexBytes = 6;
constexpr uint64_t kMinFaceBytes = 8;

// Accepts [ST][C][N]OFF; the 4D and n-dimensional variants are reported as unsupported.
enum class Keyword { kOff, kUnsupported, kNone };
Keyword ClassifyKeyword(absl::string_view token) {
  if (!absl::EndsWith(token, "OFF")) return Keyword::kNone;
  absl::string_view prefix = token.substr(0, token.size() - 3);
  (void)absl::ConsumePrefix(&prefix, "ST");
  (void)absl::ConsumePrefix(&prefix, "C");
  (void)absl::ConsumePrefix(&prefix, "N");
  return prefix.empty() ? Keyword::kOff : Keyword::kUnsupported;
}

}  // namespace

absl::StatusOr<MeshData> ReadOff(absl::string_view bytes, const std::string& name,
                                 const ReadLimits& limits) {
  LineReader lines(bytes, /*hash_comments=*/true);
  absl::string_view line;
  if (!lines.NextNonBlank(&line)) {
    return LineError(name, lines.line_number(), "empty file: expected an OFF header");
  }
  const char* p = line.data();
  const char* end = line.data() + line.size();
  const absl::string_view keyword = TokenAt(p, end);
  switch (ClassifyKeyword(keyword)) {
    case Keyword::kOff:
      p += keyword.size();
      break;
    case Keyword::kUnsupported:
      return LineError(name, lines.line_number(),
                       absl::StrCat("unsupported OFF variant ", Quote(keyword)));
    case Keyword::kNone: {
      int64_t ignored;
      const char* q = p;
      // Some writers omit the keyword and start with the counts.
      if (ScanInt(&q, end, &ignored) != Scan::kOk) {
        return LineError(name, lines.line_number(),
                         absl::StrCat("expected an OFF header, found ", Quote(keyword)));
      }
      break;
    }
  }
  if (absl::StrContains(absl::string_view(p, static_cast<size_t>(end - p)), "BINARY")) {
    return LineError(name, lines.line_number(), "binary OFF is not supported");
  }

  // Vertex and face counts, possibly on the keyword's line; the edge count is optional.
  int64_t counts[2];
  for (int64_t& count : counts) {
    Scan scan = ScanInt(&p, end, &count);
    while (scan == Scan::kMissing) {
      if (!lines.NextNonBlank(&line)) {
        return LineError(name, lines.line_number(),
                         "unexpected end of file: expected vertex and face counts");
      }
      p = line.data();
      end = line.data() + line.size();
      scan = ScanInt(&p, end, &count);
    }
    if (scan == Scan::kBad || count < 0) {
      return LineError(name, lines.line_number(),
                       absl::StrCat("invalid count ", Quote(TokenAt(p, end))));
    }
  }
  const uint64_t nv = static_cast<uint64_t>(counts[0]);
  const uint64_t nf = static_cast<uint64_t>(counts[1]);
  const uint64_t header_line = lines.line_number();
  int64_t edges;
  if (ScanInt(&p, end, &edges) == Scan::kBad) {
    return LineError(name, header_line,
                     absl::StrCat("invalid edge count ", Quote(TokenAt(p, end))));
  }
  const uint64_t left = lines.remaining();
  if (nv > left / kMinVertexBytes || nf > left / kMinFaceBytes ||
      nv * kMinVertexBytes + nf * kMinFaceBytes > left + 1) {
    return LineError(name, header_line,
                     absl::StrCat("header declares ", nv, " vertices and ", nf, " faces but only ",
                                  left, " bytes follow"));
  }
  if (nv > MaxVertices(limits) || nf > limits.max_faces) {
    return LimitExceededError(
        nv > MaxVertices(limits) ? Limit::kVertices : Limit::kFaces,
        nv > MaxVertices(limits)
            ? absl::StrCat(name, ": line ", header_line, ": ", nv, " vertices exceed the limit of ",
                           MaxVertices(limits))
            : absl::StrCat(name, ": line ", header_line, ": ", nf, " faces exceed the limit of ",
                           limits.max_faces));
  }

  MeshData mesh;
  mesh.positions.resize(3 * nv);
  double* xyz = mesh.positions.data();
  for (uint64_t v = 0; v < nv; ++v, xyz += 3) {
    if (!lines.NextNonBlank(&line)) {
      return LineError(name, lines.line_number(),
                       absl::StrCat("unexpected end of file: truncated vertex data (vertex ", v,
                                    " of ", nv, ")"));
    }
    p = line.data();
    end = line.data() + line.size();
    for (int k = 0; k < 3; ++k) {
      const Scan scan = ScanDouble(&p, end, &xyz[k]);
      if (scan == Scan::kMissing) {
        return LineError(name, lines.line_number(),
                         absl::StrCat("expected 3 coordinates for vertex ", v, ", found ", k));
      }
      if (scan == Scan::kBad) {
        return LineError(
            name, lines.line_number(),
            absl::StrCat("invalid coordinate ", Quote(TokenAt(p, end)), " for vertex ", v));
      }
    }
    // Anything after x y z on the line (normals, colours, texture coordinates) is ignored.
  }

  mesh.faces.reserve(3 * nf);
  uint64_t triangles = 0;
  for (uint64_t f = 0; f < nf; ++f) {
    if (!lines.NextNonBlank(&line)) {
      return LineError(
          name, lines.line_number(),
          absl::StrCat("unexpected end of file: truncated face data (face ", f, " of ", nf, ")"));
    }
    p = line.data();
    end = line.data() + line.size();
    int64_t n;
    if (ScanInt(&p, end, &n) != Scan::kOk) {
      return LineError(
          name, lines.line_number(),
          absl::StrCat("invalid vertex count ", Quote(TokenAt(p, end)), " for face ", f));
    }
    if (n < 3) {
      return LineError(name, lines.line_number(),
                       absl::StrCat("face ", f, " has ", n, " vertices (at least 3 needed)"));
    }
    // Fan triangulation (v0, v1, v2), (v0, v2, v3), ... read index by index, so a huge
    // declared corner count costs nothing until the indices are actually there.
    uint32_t first = 0, previous = 0;
    for (int64_t k = 0; k < n; ++k) {
      int64_t index;
      const Scan scan = ScanInt(&p, end, &index);
      if (scan == Scan::kMissing) {
        return LineError(name, lines.line_number(),
                         absl::StrCat("face ", f, " declares ", n, " vertices but lists ", k));
      }
      if (scan == Scan::kBad) {
        return LineError(
            name, lines.line_number(),
            absl::StrCat("invalid vertex index ", Quote(TokenAt(p, end)), " in face ", f));
      }
      if (index < 0 || static_cast<uint64_t>(index) >= nv) {
        return LineError(name, lines.line_number(),
                         absl::StrCat("vertex index ", index, " out of range in face ", f, " (", nv,
                                      " vertices)"));
      }
      const uint32_t vertex = static_cast<uint32_t>(index);
      if (k == 0) {
        first = vertex;
      } else if (k >= 2) {
        mesh.faces.insert(mesh.faces.end(), {first, previous, vertex});
      }
      previous = vertex;
    }
    triangles += static_cast<uint64_t>(n - 2);
    if (triangles > limits.max_faces) {
      return LimitExceededError(
          Limit::kFaces, absl::StrCat(name, ": line ", lines.line_number(), ": more than ",
                                      limits.max_faces, " triangles after splitting polygons"));
    }
    // A colour after the indices is ignored.
  }
  if (lines.NextNonBlank(&line)) {
    return LineError(name, lines.line_number(),
                     absl::StrCat("unexpected data after the last face (the header declares ", nv,
                                  " vertices and ", nf, " faces)"));
  }
  return mesh;
}

}  // namespace geodex::io_internal
