// PLY reader: ascii, binary_little_endian and binary_big_endian, any element/property layout. Only
// vertex x/y/z and the face index list are kept; everything else is walked over (lists included)
// so that the positions of later data stay right. Counts are checked against the bytes present.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"
#include "geodex/limits.h"
#include "geodex/mesh_data.h"
#include "geodex/mesh_io.h"
#include "io/io_util.h"

namespace geodex::io_internal {
namespace {

enum class Type : uint8_t { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };
enum class Encoding { kAscii, kLittle, kBig };

bool ParseType(absl::string_view s, Type* type) {
  struct Name {
    const char* name;
    Type type;
  };
  static constexpr Name kNames[] = {
      {"char", Type::kInt8},      {"int8", Type::kInt8},       {"uchar", Type::kUint8},
      {"uint8", Type::kUint8},    {"short", Type::kInt16},     {"int16", Type::kInt16},
      {"ushort", Type::kUint16},  {"uint16", Type::kUint16},   {"int", Type::kInt32},
      {"int32", Type::kInt32},    {"uint", Type::kUint32},     {"uint32", Type::kUint32},
      {"float", Type::kFloat32},  {"float32", Type::kFloat32}, {"double", Type::kFloat64},
      {"float64", Type::kFloat64}};
  for (const Name& n : kNames) {
    if (s == n.name) {
      *type = n.type;
      return true;
    }
  }
  return false;
}

size_t SizeOf(Type t) {
  switch (t) {
    case Type::kInt8:
    case Type::kUint8:
      return 1;
    case Type::kInt16:
    case Type::kUint16:
      return 2;
    case Type::kInt32:
    case Type::kUint32:
    case Type::kFloat32:
      return 4;
    case Type::kFloat64:
      return 8;
  }
  return 1;
}

bool IsInteger(Type t) { return t != Type::kFloat32 && t != Type::kFloat64; }

struct Property {
  std::string name;
  bool is_list = false;
  Type count_type = Type::kUint8;  // lists only
  Type type = Type::kFloat32;      // scalar type, or list item type
};

struct Element {
  std::string name;
  uint64_t count = 0;
  uint64_t line = 0;  // header line, for messages
  std::vector<Property> properties;
};

struct Header {
  Encoding encoding = Encoding::kAscii;
  std::vector<Element> elements;
  size_t body_offset = 0;
  uint64_t body_line = 0;  // first line of an ascii body
};

absl::StatusOr<Header> ParseHeader(absl::string_view bytes, const std::string& name) {
  Header header;
  LineReader lines(bytes, /*hash_comments=*/false);
  absl::string_view line;
  if (!lines.Next(&line) || line != "ply") {
    return LineError(name, 1, "missing the 'ply' magic line");
  }
  bool have_format = false;
  while (lines.Next(&line)) {
    const std::vector<absl::string_view> words =
        absl::StrSplit(line, absl::ByAnyChar(" \t\r\v\f"), absl::SkipEmpty());
    const uint64_t at = lines.line_number();
    if (words.empty() || words[0] == "comment" || words[0] == "obj_info") continue;
    if (words[0] == "format") {
      if (words.size() != 3) return LineError(name, at, "expected 'format <encoding> 1.0'");
      if (words[1] == "ascii") {
        header.encoding = Encoding::kAscii;
      } else if (words[1] == "binary_little_endian") {
        header.encoding = Encoding::kLittle;
      } else if (words[1] == "binary_big_endian") {
        header.encoding = Encoding::kBig;
      } else {
        return LineError(name, at, absl::StrCat("unknown PLY format ", Quote(words[1])));
      }
      have_format = true;
    } else if (words[0] == "element") {
      int64_t count;
      if (words.size() != 3 || !ParseInt(words[2], &count) || count < 0) {
        return LineError(name, at, "expected 'element <name> <count>'");
      }
      header.elements.push_back({std::string(words[1]), static_cast<uint64_t>(count), at, {}});
    } else if (words[0] == "property") {
      if (header.elements.empty()) return LineError(name, at, "property before any element");
      Property property;
      bool ok;
      if (words.size() >= 2 && words[1] == "list") {
        property.is_list = true;
        ok = words.size() == 5 && ParseType(words[2], &property.count_type) &&
             ParseType(words[3], &property.type);
        if (ok && !IsInteger(property.count_type)) {
          return LineError(name, at, "list count type must be an integer type");
        }
        if (ok) property.name = std::string(words[4]);
      } else {
        ok = words.size() == 3 && ParseType(words[1], &property.type);
        if (ok) property.name = std::string(words[2]);
      }
      if (!ok) {
        return LineError(name, at, absl::StrCat("invalid property declaration ", Quote(line)));
      }
      header.elements.back().properties.push_back(std::move(property));
    } else if (words[0] == "end_header") {
      if (!have_format) return LineError(name, at, "missing 'format' line");
      header.body_offset = lines.offset();
      header.body_line = at + 1;
      return header;
    } else {
      return LineError(name, at, absl::StrCat("unknown header keyword ", Quote(words[0])));
    }
  }
  return LineError(name, lines.line_number(), "unexpected end of file: missing end_header");
}

// Reads a scalar of type t at p, byte-swapping when the file's byte order is not the host's.
template <typename T>
T Load(const char* p, bool swap) {
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, p, sizeof(T));
  if (swap) {
    for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
  }
  T value;
  std::memcpy(&value, raw, sizeof(T));
  return value;
}

double LoadDouble(Type t, const char* p, bool swap) {
  switch (t) {
    case Type::kInt8:
      return Load<int8_t>(p, swap);
    case Type::kUint8:
      return Load<uint8_t>(p, swap);
    case Type::kInt16:
      return Load<int16_t>(p, swap);
    case Type::kUint16:
      return Load<uint16_t>(p, swap);
    case Type::kInt32:
      return Load<int32_t>(p, swap);
    case Type::kUint32:
      return Load<uint32_t>(p, swap);
    case Type::kFloat32:
      return Load<float>(p, swap);
    case Type::kFloat64:
      return Load<double>(p, swap);
  }
  return 0;
}

int64_t LoadInt(Type t, const char* p, bool swap) {
  switch (t) {
    case Type::kInt8:
      return Load<int8_t>(p, swap);
    case Type::kUint8:
      return Load<uint8_t>(p, swap);
    case Type::kInt16:
      return Load<int16_t>(p, swap);
    case Type::kUint16:
      return Load<uint16_t>(p, swap);
    case Type::kInt32:
      return Load<int32_t>(p, swap);
    case Type::kUint32:
      return Load<uint32_t>(p, swap);
    default:
      return -1;  // float types are refused where integers are needed
  }
}

// What the reader does with each property of an element.
enum class Role { kSkip, kX, kY, kZ, kFaceIndices };

// Reads the body, one element after the other, filling `mesh`.
class BodyReader {
 public:
  BodyReader(absl::string_view bytes, const Header& header, const std::string& name,
             const ReadLimits& limits, MeshData* mesh)
      : bytes_(bytes),
        header_(header),
        name_(name),
        limits_(limits),
        mesh_(mesh),
        swap_((header.encoding == Encoding::kBig) != (std::endian::native == std::endian::big)),
        tokens_(bytes.substr(header.body_offset), header.body_line) {}

  absl::Status Read(const std::vector<std::vector<Role>>& roles, uint64_t vertex_count);

 private:
  std::string Where(const Element& e, uint64_t i) const {
    return absl::StrCat(e.name, " ", i, " of ", e.count);
  }
  absl::Status Truncated(const Element& e, uint64_t i) const;
  // Scalar and list items; `value` is set for kept scalars, `index` for face indices.
  absl::Status NextScalar(const Element& e, uint64_t i, Type type, double* value);
  absl::Status NextCount(const Element& e, uint64_t i, Type type, int64_t* count);
  absl::Status AddFace(const Element& e, uint64_t i, const Property& p, uint64_t vertex_count);

  absl::string_view bytes_;
  const Header& header_;
  const std::string& name_;
  const ReadLimits& limits_;
  MeshData* mesh_;
  bool swap_;
  size_t pos_ = 0;  // binary: absolute offset
  TokenReader tokens_;
  std::vector<uint32_t> polygon_;
};

absl::Status BodyReader::Truncated(const Element& e, uint64_t i) const {
  if (header_.encoding == Encoding::kAscii) {
    return LineError(
        name_, tokens_.line(),
        absl::StrCat("unexpected end of file: truncated ", e.name, " data (", Where(e, i), ")"));
  }
  return ByteError(name_, pos_, absl::StrCat("truncated ", e.name, " data (", Where(e, i), ")"));
}

absl::Status BodyReader::NextScalar(const Element& e, uint64_t i, Type type, double* value) {
  if (header_.encoding != Encoding::kAscii) {
    if (bytes_.size() - pos_ < SizeOf(type)) return Truncated(e, i);
    *value = LoadDouble(type, bytes_.data() + pos_, swap_);
    pos_ += SizeOf(type);
    return absl::OkStatus();
  }
  absl::string_view token;
  if (!tokens_.Next(&token)) return Truncated(e, i);
  if (!ParseDouble(token, value)) {
    return LineError(name_, tokens_.line(),
                     absl::StrCat("invalid number ", Quote(token), " in ", Where(e, i)));
  }
  return absl::OkStatus();
}

absl::Status BodyReader::NextCount(const Element& e, uint64_t i, Type type, int64_t* count) {
  if (header_.encoding != Encoding::kAscii) {
    if (bytes_.size() - pos_ < SizeOf(type)) return Truncated(e, i);
    *count = LoadInt(type, bytes_.data() + pos_, swap_);
    if (*count < 0)
      return ByteError(name_, pos_, absl::StrCat("negative integer in ", Where(e, i)));
    pos_ += SizeOf(type);
    return absl::OkStatus();
  }
  absl::string_view token;
  if (!tokens_.Next(&token)) return Truncated(e, i);
  if (!ParseInt(token, count) || *count < 0) {
    return LineError(name_, tokens_.line(),
                     absl::StrCat("invalid integer ", Quote(token), " in ", Where(e, i)));
  }
  return absl::OkStatus();
}

absl::Status BodyReader::AddFace(const Element& e, uint64_t i, const Property& p,
                                 uint64_t vertex_count) {
  const size_t count_pos = pos_;
  int64_t n;
  if (absl::Status s = NextCount(e, i, p.count_type, &n); !s.ok()) return s;
  auto error = [&](absl::string_view message) {
    return header_.encoding == Encoding::kAscii ? LineError(name_, tokens_.line(), message)
                                                : ByteError(name_, count_pos, message);
  };
  if (n < 3) {
    return error(absl::StrCat("face ", i, " has ", n, " vertices (at least 3 needed)"));
  }
  if (header_.encoding != Encoding::kAscii &&
      static_cast<uint64_t>(n) > (bytes_.size() - pos_) / SizeOf(p.type)) {
    return Truncated(e, i);
  }
  polygon_.clear();
  for (int64_t k = 0; k < n; ++k) {
    int64_t index;
    if (header_.encoding != Encoding::kAscii) {
      index = LoadInt(p.type, bytes_.data() + pos_, swap_);
      pos_ += SizeOf(p.type);
    } else {
      absl::string_view token;
      if (!tokens_.Next(&token)) return Truncated(e, i);
      if (!ParseInt(token, &index)) {
        return LineError(name_, tokens_.line(),
                         absl::StrCat("invalid vertex index ", Quote(token), " in ", Where(e, i)));
      }
    }
    if (index < 0 || static_cast<uint64_t>(index) >= vertex_count) {
      return error(absl::StrCat("vertex index ", index, " out of range in face ", i, " (",
                                vertex_count, " vertices)"));
    }
    polygon_.push_back(static_cast<uint32_t>(index));
  }
  if (mesh_->faces.size() / 3 + static_cast<uint64_t>(n - 2) > limits_.max_faces) {
    return LimitExceededError(Limit::kFaces, absl::StrCat(name_, ": ", Where(e, i), ": more than ",
                                                          limits_.max_faces, " triangles"));
  }
  for (size_t k = 2; k < polygon_.size(); ++k) {  // fan triangulation, in order
    mesh_->faces.insert(mesh_->faces.end(), {polygon_[0], polygon_[k - 1], polygon_[k]});
  }
  return absl::OkStatus();
}

absl::Status BodyReader::Read(const std::vector<std::vector<Role>>& roles, uint64_t vertex_count) {
  pos_ = header_.body_offset;
  double* xyz = mesh_->positions.data();
  for (size_t ei = 0; ei < header_.elements.size(); ++ei) {
    const Element& e = header_.elements[ei];
    if (e.properties.empty()) continue;  // holds no data whatever its count
    for (uint64_t i = 0; i < e.count; ++i) {
      for (size_t pi = 0; pi < e.properties.size(); ++pi) {
        const Property& p = e.properties[pi];
        const Role role = roles[ei][pi];
        if (role == Role::kFaceIndices) {
          if (absl::Status s = AddFace(e, i, p, vertex_count); !s.ok()) return s;
        } else if (p.is_list) {
          int64_t n;
          if (absl::Status s = NextCount(e, i, p.count_type, &n); !s.ok()) return s;
          if (header_.encoding != Encoding::kAscii) {
            if (static_cast<uint64_t>(n) > (bytes_.size() - pos_) / SizeOf(p.type)) {
              return Truncated(e, i);
            }
            pos_ += static_cast<size_t>(n) * SizeOf(p.type);
          } else {
            double ignored;
            for (int64_t k = 0; k < n; ++k) {
              if (absl::Status s = NextScalar(e, i, p.type, &ignored); !s.ok()) return s;
            }
          }
        } else {
          double value;
          if (absl::Status s = NextScalar(e, i, p.type, &value); !s.ok()) return s;
          if (role != Role::kSkip) xyz[3 * i + static_cast<int>(role) - 1] = value;
        }
      }
    }
  }
  if (header_.encoding == Encoding::kAscii) {
    absl::string_view token;
    if (tokens_.Next(&token)) {
      return LineError(name_, tokens_.line(),
                       absl::StrCat("unexpected data ", Quote(token), " after the last element"));
    }
  } else if (pos_ != bytes_.size()) {
    return ByteError(
        name_, pos_,
        absl::StrCat(bytes_.size() - pos_, " unexpected bytes after the last element"));
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<MeshData> ReadPly(absl::string_view bytes, const std::string& name,
                                 const ReadLimits& limits) {
  absl::StatusOr<Header> parsed = ParseHeader(bytes, name);
  if (!parsed.ok()) return parsed.status();
  const Header& header = *parsed;
  const bool ascii = header.encoding == Encoding::kAscii;

  // Assign roles, and check every count against the smallest body that could hold it. Each
  // element on its own: that bounds every allocation, and a merely truncated file then gets the
  // exact position of the first missing item while reading.
  const Element* vertex = nullptr;
  const Element* face = nullptr;
  std::vector<std::vector<Role>> roles(header.elements.size());
  const uint64_t body = bytes.size() - header.body_offset;
  for (size_t ei = 0; ei < header.elements.size(); ++ei) {
    const Element& e = header.elements[ei];
    roles[ei].assign(e.properties.size(), Role::kSkip);
    const bool is_vertex = vertex == nullptr && e.name == "vertex";
    const bool is_face = face == nullptr && e.name == "face";
    uint64_t min_bytes = 0;  // of one item
    bool have_face_list = false;
    for (size_t pi = 0; pi < e.properties.size(); ++pi) {
      const Property& p = e.properties[pi];
      min_bytes += ascii ? 2 : SizeOf(p.is_list ? p.count_type : p.type);
      if (is_vertex && !p.is_list) {
        if (p.name == "x") roles[ei][pi] = Role::kX;
        if (p.name == "y") roles[ei][pi] = Role::kY;
        if (p.name == "z") roles[ei][pi] = Role::kZ;
      }
      if (is_face && !have_face_list && p.is_list &&
          (p.name == "vertex_indices" || p.name == "vertex_index")) {
        if (!IsInteger(p.type)) return LineError(name, e.line, "face indices must be integers");
        roles[ei][pi] = Role::kFaceIndices;
        have_face_list = true;
      }
    }
    if (is_vertex) {
      vertex = &e;
      for (Role r : {Role::kX, Role::kY, Role::kZ}) {
        if (std::find(roles[ei].begin(), roles[ei].end(), r) == roles[ei].end()) {
          return LineError(name, e.line, "vertex element lacks an x, y or z property");
        }
      }
    }
    if (is_face) {
      face = &e;
      if (e.count > 0 && !have_face_list) {
        return LineError(name, e.line, "face element lacks a vertex_indices list");
      }
    }
    if (min_bytes > 0 && e.count > (body + 1) / min_bytes) {
      return LineError(name, e.line,
                       absl::StrCat("header declares ", e.count, " ", e.name, " elements but only ",
                                    body, " bytes of data follow"));
    }
  }
  if (vertex == nullptr) return LineError(name, header.body_line - 1, "no vertex element");
  const uint64_t nv = vertex->count;
  const uint64_t nf = face ? face->count : 0;
  if (nv > MaxVertices(limits) || nf > limits.max_faces) {
    return LimitExceededError(
        nv > MaxVertices(limits) ? Limit::kVertices : Limit::kFaces,
        nv > MaxVertices(limits)
            ? absl::StrCat(name, ": ", nv, " vertices exceed the limit of ", MaxVertices(limits))
            : absl::StrCat(name, ": ", nf, " faces exceed the limit of ", limits.max_faces));
  }
  MeshData mesh;
  mesh.positions.resize(3 * nv);
  mesh.faces.reserve(3 * nf);
  BodyReader reader(bytes, header, name, limits, &mesh);
  if (absl::Status s = reader.Read(roles, nv); !s.ok()) return s;
  return mesh;
}

}  // namespace geodex::io_internal
