// Mesh writers: ascii OFF and binary little-endian PLY. Coordinates keep full double precision so
// that reading a written file gives back bit-identical positions.
#include <bit>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "geodex/mesh_data.h"
#include "geodex/mesh_io.h"

namespace geodex {
namespace {

// Buffered file output that remembers the first error.
class Output {
 public:
  explicit Output(const std::string& path) : path_(path), file_(std::fopen(path.c_str(), "wb")) {
    if (file_ == nullptr) error_ = errno;
  }
  ~Output() {
    if (file_ != nullptr) std::fclose(file_);
  }
  Output(const Output&) = delete;
  Output& operator=(const Output&) = delete;

  std::string& buffer() { return buffer_; }
  void MaybeFlush() {
    if (buffer_.size() >= (1u << 20)) Flush();
  }

  absl::Status Close() {
    if (file_ != nullptr) {
      Flush();
      if (std::fclose(file_) != 0 && error_ == 0) error_ = errno;
      file_ = nullptr;
    }
    if (error_ != 0) {
      return absl::UnavailableError(absl::StrCat(path_, ": cannot write: ", std::strerror(error_)));
    }
    return absl::OkStatus();
  }

 private:
  void Flush() {
    if (file_ != nullptr && error_ == 0 && !buffer_.empty() &&
        std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) {
      error_ = errno != 0 ? errno : EIO;
    }
    buffer_.clear();
  }

  std::string path_;
  std::FILE* file_;
  int error_ = 0;
  std::string buffer_;
};

absl::Status CheckInput(const std::string& path, const MeshData& mesh,
                        const VertexAttributes& attributes) {
  const size_t nv = mesh.vertex_count();
  if (!attributes.scalar.empty() && attributes.scalar.size() != nv) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": ", attributes.scalar.size(), " scalar values for ", nv, " vertices"));
  }
  if (!attributes.colors.empty() && attributes.colors.size() != 3 * nv) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": ", attributes.colors.size(), " colour bytes for ", nv, " vertices"));
  }
  for (size_t i = 0; i < 3 * mesh.face_count(); ++i) {
    if (mesh.faces[i] >= nv) {
      return absl::InvalidArgumentError(
          absl::StrCat(path, ": face ", i / 3, " has vertex ", mesh.faces[i], " of ", nv));
    }
  }
  return absl::OkStatus();
}

// Same digits as printf("%.17g") (enough to round-trip any double), independent of the locale.
void AppendDouble(std::string* out, double value) {
  char text[32];
  const auto result =
      std::to_chars(text, text + sizeof(text), value, std::chars_format::general, 17);
  out->append(text, result.ptr);
}

template <typename T>
void AppendLittleEndian(std::string* out, T value) {
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) {
    for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
  }
  out->append(reinterpret_cast<const char*>(raw), sizeof(T));
}

}  // namespace

absl::Status WriteMeshOff(const std::string& path, const MeshData& mesh,
                          const VertexAttributes& attributes) {
  if (absl::Status s = CheckInput(path, mesh, attributes); !s.ok()) return s;
  const bool colors = !attributes.colors.empty();
  Output out(path);
  std::string& b = out.buffer();
  absl::StrAppend(&b, colors ? "COFF\n" : "OFF\n", mesh.vertex_count(), " ", mesh.face_count(),
                  " 0\n");
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    for (int k = 0; k < 3; ++k) {
      if (k > 0) b.push_back(' ');
      AppendDouble(&b, mesh.positions[3 * v + k]);
    }
    if (colors) {
      absl::StrAppend(&b, " ", int{attributes.colors[3 * v]}, " ",
                      int{attributes.colors[3 * v + 1]}, " ", int{attributes.colors[3 * v + 2]},
                      " 255");
    }
    b.push_back('\n');
    out.MaybeFlush();
  }
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    absl::StrAppend(&b, "3 ", mesh.faces[3 * f], " ", mesh.faces[3 * f + 1], " ",
                    mesh.faces[3 * f + 2], "\n");
    out.MaybeFlush();
  }
  return out.Close();
}

absl::Status WriteMeshPly(const std::string& path, const MeshData& mesh,
                          const VertexAttributes& attributes) {
  if (absl::Status s = CheckInput(path, mesh, attributes); !s.ok()) return s;
  const bool scalar = !attributes.scalar.empty();
  const bool colors = !attributes.colors.empty();
  Output out(path);
  std::string& b = out.buffer();
  absl::StrAppend(&b, "ply\nformat binary_little_endian 1.0\ncomment written by geodex\n",
                  "element vertex ", mesh.vertex_count(),
                  "\nproperty double x\nproperty double y\nproperty double z\n");
  if (scalar) b.append("property double distance\n");
  if (colors) b.append("property uchar red\nproperty uchar green\nproperty uchar blue\n");
  absl::StrAppend(&b, "element face ", mesh.face_count(),
                  "\nproperty list uchar uint vertex_indices\nend_header\n");
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    for (int k = 0; k < 3; ++k) AppendLittleEndian(&b, mesh.positions[3 * v + k]);
    if (scalar) AppendLittleEndian(&b, attributes.scalar[v]);
    if (colors) b.append(reinterpret_cast<const char*>(&attributes.colors[3 * v]), 3);
    out.MaybeFlush();
  }
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    b.push_back(3);
    for (int k = 0; k < 3; ++k) AppendLittleEndian(&b, mesh.faces[3 * f + k]);
    out.MaybeFlush();
  }
  return out.Close();
}

}  // namespace geodex
