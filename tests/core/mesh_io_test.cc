// Tests of the mesh readers and writers: every format and variant on good input (files under
// tests/data/io, binary files built here), gzip, format detection, malformed and hostile input
// (the error must name the file and the position), and write/read round trips.
#include "geodex/mesh_io.h"

#include <stdlib.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "geodex/limits.h"
#include "gtest/gtest.h"
#include "util/gzip.h"

namespace geodex {
namespace {

namespace fs = std::filesystem;
using Code = absl::StatusCode;

// tests/data/io, from the build's definition or else found next to this file.
std::string DataPath(const std::string& file) {
#ifdef GEODEX_TEST_DATA_DIR
  const fs::path data = GEODEX_TEST_DATA_DIR;
#else
  const fs::path data = fs::path(__FILE__).parent_path().parent_path() / "data";
#endif
  return (data / "io" / file).string();
}

const std::vector<double> kTetraPositions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
const std::vector<uint32_t> kTetraFaces = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
const std::vector<double> kCubePositions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                                            0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
// The six quads (0 3 2 1) (4 5 6 7) (0 1 5 4) (1 2 6 5) (2 3 7 6) (3 0 4 7), fan-triangulated.
const std::vector<uint32_t> kCubeFaces = {0, 3, 2, 0, 2, 1, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                          1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};

// The STL tetrahedron, corners welded in order of first appearance: (0,0,0) (0,1,0) (1,0,0) (0,0,1)
const std::vector<double> kStlPositions = {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1};
const std::vector<uint32_t> kStlFaces = {0, 1, 2, 0, 2, 3, 0, 3, 1, 2, 1, 3};

const char kTetraOff[] =
    "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
    "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

absl::StatusOr<MeshData> Parse(const std::string& bytes, const std::string& name,
                               const ReadLimits& limits = {}) {
  return ReadMeshFromBuffer(bytes, MeshFormat::kAuto, name, limits);
}

void ExpectMesh(const absl::StatusOr<MeshData>& mesh, const std::vector<double>& positions,
                const std::vector<uint32_t>& faces) {
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->positions, positions);
  EXPECT_EQ(mesh->faces, faces);
}

// The error must have `code` and mention every fragment (the file name, the position, ...).
void ExpectError(const absl::StatusOr<MeshData>& mesh, Code code,
                 std::initializer_list<std::string> fragments) {
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().code(), code) << mesh.status();
  const std::string message(mesh.status().message());
  for (const std::string& f : fragments) {
    EXPECT_TRUE(absl::StrContains(message, f)) << "'" << f << "' not in: " << message;
  }
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

// Little- or big-endian binary output for building PLY and STL files.
struct Bytes {
  bool big_endian = false;
  std::string data;
  template <typename T>
  void Put(T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    for (size_t i = 0; i < sizeof(T); ++i) data.push_back(raw[big_endian ? sizeof(T) - 1 - i : i]);
  }
  // Writes `value` as the PLY type `type`.
  void PutAs(const std::string& type, double value) {
    if (type == "char" || type == "int8") return Put(static_cast<int8_t>(value));
    if (type == "uchar" || type == "uint8") return Put(static_cast<uint8_t>(value));
    if (type == "short" || type == "int16") return Put(static_cast<int16_t>(value));
    if (type == "ushort" || type == "uint16") return Put(static_cast<uint16_t>(value));
    if (type == "int" || type == "int32") return Put(static_cast<int32_t>(value));
    if (type == "uint" || type == "uint32") return Put(static_cast<uint32_t>(value));
    if (type == "float" || type == "float32") return Put(static_cast<float>(value));
    ASSERT_TRUE(type == "double" || type == "float64") << type;
    Put(value);
  }
};

const char* const kPlyTypes[] = {"char",   "int8",    "uchar",  "uint8",  "short", "int16",
                                 "ushort", "uint16",  "int",    "int32",  "uint",  "uint32",
                                 "float",  "float32", "double", "float64"};

// A binary PLY of the tetrahedron with coordinates of `coord` type, out of order and among extra
// properties, an extra element with lists between vertices and faces, and a chosen face list.
std::string TetraPly(bool big_endian, const std::string& coord = "float",
                     const std::string& count = "uchar", const std::string& index = "int",
                     const std::string& list_name = "vertex_indices") {
  Bytes b{big_endian, ""};
  b.data = absl::StrCat(
      "ply\nformat ", big_endian ? "binary_big_endian" : "binary_little_endian", " 1.0\n",
      "comment built by mesh_io_test\nelement vertex 4\nproperty uchar red\n", "property ", coord,
      " z\nproperty ", coord, " x\nproperty list uchar ushort extra\n", "property ", coord,
      " y\nelement edge 2\nproperty list uint uchar stuff\nproperty int a\n",
      "element face 4\nproperty list ", count, " ", index, " ", list_name,
      "\nproperty float quality\nend_header\n");
  for (int v = 0; v < 4; ++v) {
    b.Put<uint8_t>(200);
    b.PutAs(coord, kTetraPositions[3 * v + 2]);
    b.PutAs(coord, kTetraPositions[3 * v]);
    b.Put<uint8_t>(static_cast<uint8_t>(v));  // v extra ushorts
    for (int k = 0; k < v; ++k) b.Put<uint16_t>(0xabcd);
    b.PutAs(coord, kTetraPositions[3 * v + 1]);
  }
  for (uint32_t e = 0; e < 2; ++e) {
    b.Put<uint32_t>(e + 1);
    for (uint32_t k = 0; k <= e; ++k) b.Put<uint8_t>(1);
    b.Put<int32_t>(-5);
  }
  for (int f = 0; f < 4; ++f) {
    b.PutAs(count, 3);
    for (int k = 0; k < 3; ++k) b.PutAs(index, kTetraFaces[3 * f + k]);
    b.Put<float>(0.5f);
  }
  return b.data;
}

// A binary STL of the tetrahedron; the corners repeat, so reading must weld them.
std::string TetraStl(const std::string& header_text = "binary tetra") {
  Bytes b;
  b.data = header_text;
  b.data.resize(80, '\0');
  b.Put<uint32_t>(4);
  for (int f = 0; f < 4; ++f) {
    for (int k = 0; k < 3; ++k) b.Put<float>(0.0f);  // normal
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < 3; ++k) {
        b.Put<float>(static_cast<float>(kTetraPositions[3 * kTetraFaces[3 * f + c] + k]));
      }
    }
    b.Put<uint16_t>(0);
  }
  return b.data;
}

using testing_support::Gzip;

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A fresh directory under the test temp dir, removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::path(::testing::TempDir()) / "mesh_io_test.XXXXXX").string();
    path_ = mkdtemp(pattern.data());
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string File(const std::string& name) const { return (fs::path(path_) / name).string(); }
  std::string Write(const std::string& name, const std::string& bytes) const {
    std::ofstream(File(name), std::ios::binary) << bytes;
    return File(name);
  }

 private:
  std::string path_;
};

// ---------------------------------------------------------------------------------------------
// OFF

TEST(OffReaderTest, ReadsTetraFileWithComments) {
  ExpectMesh(ReadMeshFile(DataPath("tetra.off")), kTetraPositions, kTetraFaces);
}

TEST(OffReaderTest, ColoursCommentsAndPolygons) {
  ExpectMesh(ReadMeshFile(DataPath("cube_polygons.off")), kCubePositions, kCubeFaces);
}

TEST(OffReaderTest, VariantsHeaderLayoutsAndNumberForms) {
  ExpectMesh(Parse("NOFF\n4 4\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n0 0 1 0 0 1\n"
                   "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
                   "n.off"),
             kTetraPositions, kTetraFaces);
  ExpectMesh(Parse("CNOFF\r\n4 4 6\r\n0 0 0 0 0 1 1 1 1 1\r\n1 0 0 0 0 1 1 1 1 1\r\n"
                   "0 1 0 0 0 1 1 1 1 1\r\n0 0 1 0 0 1 1 1 1 1\r\n3 0 2 1\r\n3 0 1 3\r\n"
                   "3 0 3 2\r\n3 1 2 3 0 0 1\r\n",
                   "cn.off"),
             kTetraPositions, kTetraFaces);
  ExpectMesh(Parse("4 4 6\n0 0 0\n+1 0 0\n0 1.0 0\n0 0 1e0\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3",
                   "no_keyword.off"),
             kTetraPositions, kTetraFaces);
  ExpectMesh(Parse("OFF 4 4 6 # all on one line\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n"
                   "3 0 1 3\n3 0 3 2\n3 1 2 3\n",
                   "st.off"),
             kTetraPositions, kTetraFaces);
}

TEST(OffReaderTest, NanAndInfAreNotReaderErrors) {
  absl::StatusOr<MeshData> mesh =
      Parse("OFF\n2 0 0\nnan inf -inf\n1e999 -1e999 1e-999\n", "special.off");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_TRUE(std::isnan(mesh->positions[0]));
  EXPECT_EQ(mesh->positions[1], std::numeric_limits<double>::infinity());
  EXPECT_EQ(mesh->positions[2], -std::numeric_limits<double>::infinity());
  EXPECT_EQ(mesh->positions[3], std::numeric_limits<double>::infinity());
  EXPECT_EQ(mesh->positions[4], -std::numeric_limits<double>::infinity());
  EXPECT_EQ(mesh->positions[5], 0.0);
}

TEST(OffReaderTest, MalformedInputNamesFileAndLine) {
  const Code kInvalid = Code::kInvalidArgument;
  ExpectError(Parse("", "e.off"), kInvalid, {"e.off: line 0", "empty file"});
  ExpectError(Parse("OFF\n4 1 0\n0.0000 0.0000 0.0000\n1.0000 0.0000 0.0000\n", "t.off"), kInvalid,
              {"t.off: line 4", "truncated vertex data (vertex 2 of 4)"});
  // Too short for the declared counts even at the smallest possible size of each line.
  ExpectError(Parse("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "th.off"), kInvalid,
              {"th.off: line 2", "3 vertices and 2 faces but only 26 bytes follow"});
  ExpectError(Parse("OFF\n3 2 0\n0.000 0.000 0.000\n1 0 0\n0 1 0\n3 0 1 2\n", "tf.off"), kInvalid,
              {"tf.off: line 6", "truncated face data (face 1 of 2)"});
  ExpectError(Parse("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n", "more.off"), kInvalid,
              {"more.off: line 7", "after the last face"});
  ExpectError(Parse("OFF\n2 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "fewer.off"), kInvalid,
              {"fewer.off: line 5", "face 0 has 0 vertices"});
  ExpectError(Parse("OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n", "g.off"), kInvalid,
              {"g.off: line 4", "invalid coordinate 'x' for vertex 1"});
  ExpectError(Parse("OFF\n3 1 0\n0 0 0\n1.0 0.0\n0 1 0\n3 0 1 2\n", "c.off"), kInvalid,
              {"c.off: line 4", "expected 3 coordinates"});
  ExpectError(Parse("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", "r.off"), kInvalid,
              {"r.off: line 6", "vertex index 7 out of range"});
  ExpectError(Parse("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", "neg.off"), kInvalid,
              {"neg.off: line 6", "vertex index -1 out of range"});
  ExpectError(Parse("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1 \n", "two.off"), kInvalid,
              {"two.off: line 6", "face 0 has 2 vertices"});
  ExpectError(Parse("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", "short.off"), kInvalid,
              {"short.off: line 6", "declares 4 vertices but lists 3"});
  ExpectError(Parse("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n", "fi.off"), kInvalid,
              {"fi.off: line 6", "invalid vertex index '1.5'"});
  ExpectError(Parse("OFF\n999999999999 1 0\n", "absurd.off"), kInvalid,
              {"absurd.off: line 2", "999999999999 vertices"});
  ExpectError(Parse("OFF\n3 99999999999999999999 0\n", "huge.off"), kInvalid,
              {"huge.off: line 2", "invalid count"});
  ExpectError(Parse("OFF\n-3 1 0\n", "negc.off"), kInvalid, {"negc.off: line 2", "count"});
  ExpectError(Parse("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n9999999999 0 1 2\n", "big.off"), kInvalid,
              {"big.off: line 6", "lists 3"});
  ExpectError(Parse("4OFF\n1 0 0\n0 0 0 0\n", "4d.off"), kInvalid, {"4d.off: line 1"});
  ExpectError(Parse("OFF BINARY\n", "bin.off"), kInvalid, {"bin.off: line 1", "binary"});
  const char kBinary[] = "OFF\n3 1 0\n0 0 0\n\x01\xff\x00\x7f 0 0\n0 1 0\n3 0 1 2\n";
  ExpectError(Parse(std::string(kBinary, sizeof(kBinary) - 1), "bytes.off"), kInvalid,
              {"bytes.off: line 4", "\\x01"});
  ExpectError(Parse("garbage\n", "junk.off"), kInvalid, {"junk.off: line 1", "'garbage'"});
}

TEST(OffReaderTest, CountsBeyondLimitsAreResourceExhausted) {
  ReadLimits limits;
  limits.max_vertices = 3;
  ExpectError(Parse(kTetraOff, "lim.off", limits), Code::kResourceExhausted,
              {"lim.off: line 2", "4 vertices exceed the limit of 3"});
  // Which limit was crossed travels as data, for a server to name its own flag.
  EXPECT_EQ(ExceededLimit(Parse(kTetraOff, "lim.off", limits).status()), Limit::kVertices);
  limits = ReadLimits();
  limits.max_faces = 1;
  EXPECT_EQ(ExceededLimit(Parse(kTetraOff, "lim.off", limits).status()), Limit::kFaces);
  ExpectError(Parse("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n4 0 1 2 3\n", "poly.off", limits),
              Code::kResourceExhausted, {"poly.off: line 7", "triangles"});
  EXPECT_FALSE(ExceededLimit(Parse("OFF\n", "bad.off").status()).has_value());
}

// ---------------------------------------------------------------------------------------------
// OBJ

TEST(ObjReaderTest, QuadsTextureNormalAndRelativeIndices) {
  ExpectMesh(ReadMeshFile(DataPath("cube.obj")), kCubePositions, kCubeFaces);
}

TEST(ObjReaderTest, IndexFormsForwardReferencesAndExtraComponents) {
  ExpectMesh(Parse("v 0 0 0 1\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0\nf 1/1/1 2//2 3/3\n", "f.obj"),
             {0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2});
  ExpectMesh(Parse("v 0 0 0\nf 1 2 3\nv 1 0 0\nv 0 1 0\n", "fwd.obj"), {0, 0, 0, 1, 0, 0, 0, 1, 0},
             {0, 1, 2});
}

TEST(ObjReaderTest, MalformedInputNamesFileAndLine) {
  const Code kInvalid = Code::kInvalidArgument;
  const std::string v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  ExpectError(Parse(v3 + "f 1 2 4\n", "r.obj"), kInvalid,
              {"r.obj: line 4", "vertex index 4 out of range"});
  ExpectError(Parse(v3 + "f 1 2 3\n# end\nf 1 2 9/1/1\n", "fwd.obj"), kInvalid,
              {"fwd.obj: line 6", "vertex index 9 out of range (3 vertices)"});
  ExpectError(Parse(v3 + "f -1 -2 -4\n", "neg.obj"), kInvalid,
              {"neg.obj: line 4", "vertex index -4 out of range"});
  ExpectError(Parse(v3 + "f 0 1 2\n", "zero.obj"), kInvalid, {"zero.obj: line 4", "index 0"});
  ExpectError(Parse(v3 + "f 1 2\n", "two.obj"), kInvalid, {"two.obj: line 4", "2 vertices"});
  ExpectError(Parse(v3 + "f 1 a 3\n", "nan.obj"), kInvalid, {"nan.obj: line 4", "'a'"});
  ExpectError(Parse("v 0 0 0\nv 1 0\n", "c.obj"), kInvalid, {"c.obj: line 2", "3 coordinates"});
  ExpectError(Parse("v 0 0 0\nv 1 0 zz\n", "z.obj"), kInvalid, {"z.obj: line 2", "'zz'"});
  ExpectError(Parse(v3 + "f 1 2 99999999999999\n", "huge.obj"), kInvalid, {"huge.obj: line 4"});
  ExpectError(Parse(v3 + std::string("\x7f\x45\x4c\x46\x02\x01\x00\x00\n", 9), "elf.obj"), kInvalid,
              {"elf.obj: line 4", "not an OBJ statement"});
  ReadLimits limits;
  limits.max_vertices = 2;
  ExpectError(Parse(v3, "lim.obj", limits), Code::kResourceExhausted, {"lim.obj: line 3"});
}

// ---------------------------------------------------------------------------------------------
// PLY

TEST(PlyReaderTest, AsciiWithExtraPropertiesAndElements) {
  ExpectMesh(ReadMeshFile(DataPath("tetra_ascii.ply")), kTetraPositions, kTetraFaces);
}

TEST(PlyReaderTest, BinaryBothEndiansEveryCoordinateType) {
  for (bool big : {false, true}) {
    for (const char* type : kPlyTypes) {
      SCOPED_TRACE(absl::StrCat(big ? "big " : "little ", type));
      ExpectMesh(Parse(TetraPly(big, type), "t.ply"), kTetraPositions, kTetraFaces);
    }
  }
}

TEST(PlyReaderTest, FaceListCountAndIndexTypesAndName) {
  for (bool big : {false, true}) {
    for (const char* count : {"uchar", "char", "ushort", "int", "uint32"}) {
      for (const char* index : {"int8", "uchar", "short", "uint16", "int", "uint"}) {
        SCOPED_TRACE(absl::StrCat(big, " ", count, " ", index));
        ExpectMesh(Parse(TetraPly(big, "double", count, index, "vertex_index"), "t.ply"),
                   kTetraPositions, kTetraFaces);
      }
    }
  }
}

TEST(PlyReaderTest, AsciiPolygonsAreFanTriangulated) {
  std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 8\nproperty double x\n"
      "property double y\nproperty double z\nelement face 6\n"
      "property list uchar uint vertex_index\nend_header\n";
  for (int v = 0; v < 8; ++v) {
    absl::StrAppend(&ply, kCubePositions[3 * v], " ", kCubePositions[3 * v + 1], " ",
                    kCubePositions[3 * v + 2], "\n");
  }
  ply += "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
  ExpectMesh(Parse(ply, "cube.ply"), kCubePositions, kCubeFaces);
}

TEST(PlyReaderTest, MalformedBinaryNamesFileAndByte) {
  const Code kInvalid = Code::kInvalidArgument;
  const std::string good = TetraPly(false, "float", "uchar", "int");
  const size_t body = good.find("end_header\n") + 11;
  // Vertex v: red(1) z(4) x(4) count(1) 2v bytes y(4), so vertex 3 starts at body + 48 and its
  // y at body + 64. The smallest possible data (14 + 16 + 20 bytes) fits before that.
  ExpectError(Parse(good.substr(0, body + 66), "tv.ply"), kInvalid,
              {absl::StrCat("tv.ply: byte ", body + 64), "truncated vertex data (vertex 3 of 4)"});
  ExpectError(Parse(good.substr(0, body + 35), "th.ply"), kInvalid,
              {"th.ply: line 4", "4 vertex elements but only 35 bytes"});
  ExpectError(
      Parse(good.substr(0, good.size() - 3), "tf.ply"), kInvalid,
      {absl::StrCat("tf.ply: byte ", good.size() - 4), "truncated face data (face 3 of 4)"});
  ExpectError(Parse(good + "xyz", "extra.ply"), kInvalid,
              {absl::StrCat("extra.ply: byte ", good.size()), "3 unexpected bytes"});
  std::string bad_index = good;
  const size_t last_face = good.size() - 17;  // count(1) 3 ints(12) quality(4)
  bad_index[last_face + 1 + 8] = 4;           // third index of face 3 := 4
  ExpectError(Parse(bad_index, "oor.ply"), kInvalid,
              {absl::StrCat("oor.ply: byte ", last_face), "vertex index 4 out of range in face 3"});
  std::string two = good;
  two[last_face] = 2;
  ExpectError(Parse(two, "two.ply"), kInvalid, {"two.ply: byte", "face 3 has 2 vertices"});
  std::string absurd = good;
  absurd.replace(absurd.find("vertex 4"), 8, "vertex 999999999999");
  ExpectError(Parse(absurd, "absurd.ply"), kInvalid, {"absurd.ply: line 4", "999999999999"});
  std::string huge_list = good;
  huge_list[last_face] = static_cast<char>(255);
  ExpectError(Parse(huge_list, "hl.ply"), kInvalid, {"hl.ply: byte", "truncated face data"});
}

TEST(PlyReaderTest, MalformedHeaderAndAsciiNamesFileAndLine) {
  const Code kInvalid = Code::kInvalidArgument;
  const std::string ascii = ReadText(DataPath("tetra_ascii.ply"));
  ExpectError(Parse("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", "eh.ply"),
              kInvalid, {"eh.ply: line 4", "end_header"});
  ExpectError(Parse("ply\nformat utf8 1.0\nend_header\n", "f.ply"), kInvalid,
              {"f.ply: line 2", "'utf8'"});
  ExpectError(
      Parse("ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n", "t.ply"),
      kInvalid, {"t.ply: line 4", "float128"});
  ExpectError(Parse("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n",
                    "xyz.ply"),
              kInvalid, {"xyz.ply: line 3", "x, y or z"});
  std::string garbage = ascii;
  garbage.replace(garbage.find("0 7 1 0 0"), 9, "0 7 one 0");
  ExpectError(Parse(garbage, "g.ply"), kInvalid, {"g.ply: line 20", "'one'", "vertex 1 of 4"});
  ExpectError(Parse(ascii.substr(0, ascii.size() - 10), "ta.ply"), kInvalid,
              {"ta.ply: line 28", "truncated face data (face 3 of 4)"});
  std::string oor = ascii;
  oor.replace(oor.find("9 3 1 2 3"), 9, "9 3 1 2 4");
  ExpectError(Parse(oor, "oor.ply"), kInvalid, {"oor.ply: line 28", "vertex index 4 out of range"});
  ExpectError(Parse(ascii + "5\n", "more.ply"), kInvalid, {"more.ply: line 29", "'5'"});
  ReadLimits limits;
  limits.max_faces = 3;
  ExpectError(Parse(ascii, "lim.ply", limits), Code::kResourceExhausted,
              {"lim.ply", "faces exceed the limit of 3"});
}

// ---------------------------------------------------------------------------------------------
// STL

TEST(StlReaderTest, AsciiWelded) {
  ExpectMesh(ReadMeshFile(DataPath("tetra_ascii.stl")), kStlPositions, kStlFaces);
}

TEST(StlReaderTest, BinaryWeldedEvenWithSolidHeader) {
  // TetraStl lists the triangles of the ascii file, so welding numbers the corners the same way.
  ExpectMesh(Parse(TetraStl(), "t.stl"), kStlPositions, kStlFaces);
  ExpectMesh(Parse(TetraStl("solid exported by a CAD tool"), "t.stl"), kStlPositions, kStlFaces);
}

TEST(StlReaderTest, MalformedNamesFileAndPosition) {
  const Code kInvalid = Code::kInvalidArgument;
  const std::string good = TetraStl();
  ExpectError(Parse(good.substr(0, 84 + 50 * 2 + 17), "t.stl"), kInvalid,
              {"t.stl: byte 184", "truncated triangle data (triangle 2 of 4)"});
  ExpectError(Parse(good + "xx", "x.stl"), kInvalid, {"x.stl: byte 284", "2 unexpected bytes"});
  ExpectError(Parse(good.substr(0, 50), "h.stl"), kInvalid, {"h.stl: byte 50", "header"});
  std::string absurd = good;
  absurd[83] = 0x7f;  // ~2 billion triangles
  ExpectError(Parse(absurd, "a.stl"), kInvalid, {"a.stl: byte 284", "truncated triangle data"});
  const std::string ascii = ReadText(DataPath("tetra_ascii.stl"));
  ExpectError(Parse(ascii.substr(0, ascii.find("endsolid")), "e.stl"), kInvalid,
              {"e.stl: line 30", "endsolid"});
  ExpectError(Parse(ascii.substr(0, 120), "tr.stl"), kInvalid, {"tr.stl: line 6"});
  std::string bad = ascii;
  bad.replace(bad.find("vertex 1 0 0"), 12, "vertex 1 O 0");
  ExpectError(Parse(bad, "o.stl"), kInvalid, {"o.stl: line 6", "'O'"});
  bad = ascii;
  bad.replace(bad.find("endloop"), 7, "vertexx");
  ExpectError(Parse(bad, "k.stl"), kInvalid, {"k.stl: line 7", "'vertexx'"});
}

// ---------------------------------------------------------------------------------------------
// gzip, format detection, files

TEST(MeshIoTest, GzipOfEveryFormat) {
  const std::string off = ReadText(DataPath("cube_polygons.off"));
  const std::string obj = ReadText(DataPath("cube.obj"));
  ExpectMesh(Parse(Gzip(off), "c.off.gz"), kCubePositions, kCubeFaces);
  ExpectMesh(Parse(Gzip(obj), "c.obj.gz"), kCubePositions, kCubeFaces);
  ExpectMesh(Parse(Gzip(ReadText(DataPath("tetra_ascii.ply"))), "t.ply.gz"), kTetraPositions,
             kTetraFaces);
  ExpectMesh(Parse(Gzip(TetraPly(true)), "t.ply.gz"), kTetraPositions, kTetraFaces);
  ExpectMesh(Parse(Gzip(TetraStl()), "t.stl.gz"), kStlPositions, kStlFaces);
  ExpectMesh(Parse(Gzip(ReadText(DataPath("tetra_ascii.stl"))), "t.stl.gz"), kStlPositions,
             kStlFaces);
  // Concatenated members are one stream, as zcat sees it.
  const size_t half = off.size() / 2;
  ExpectMesh(Parse(Gzip(off.substr(0, half)) + Gzip(off.substr(half)), "two.off.gz"),
             kCubePositions, kCubeFaces);
}

TEST(MeshIoTest, BrokenOrOversizedGzip) {
  const std::string gz = Gzip(ReadText(DataPath("cube_polygons.off")));
  ExpectError(Parse(gz.substr(0, gz.size() / 2), "t.off.gz"), Code::kInvalidArgument,
              {"t.off.gz: byte", "truncated gzip"});
  std::string corrupt = gz;
  for (size_t i = 12; i < 40; ++i) corrupt[i] = static_cast<char>(0xff);
  ExpectError(Parse(corrupt, "c.off.gz"), Code::kInvalidArgument, {"c.off.gz: byte", "gzip"});
  ReadLimits limits;
  limits.max_decompressed_bytes = 100;
  ExpectError(Parse(gz, "big.off.gz", limits), Code::kResourceExhausted, {"big.off.gz", "100"});
  // A bomb: 64 MiB of zeros is about 64 KiB compressed; the limit stops it early.
  limits.max_decompressed_bytes = 1 << 20;
  ExpectError(Parse(Gzip(std::string(64 << 20, '\0')), "bomb.gz", limits), Code::kResourceExhausted,
              {"bomb.gz"});
}

TEST(MeshIoTest, SniffsContentWhenTheExtensionDoesNotTell) {
  ExpectMesh(Parse(kTetraOff, "upload"), kTetraPositions, kTetraFaces);
  ExpectMesh(Parse(ReadText(DataPath("cube_polygons.off")), "upload.txt"), kCubePositions,
             kCubeFaces);
  ExpectMesh(Parse(ReadText(DataPath("cube.obj")), "upload"), kCubePositions, kCubeFaces);
  ExpectMesh(Parse(TetraPly(false), "upload"), kTetraPositions, kTetraFaces);
  ExpectMesh(Parse(ReadText(DataPath("tetra_ascii.stl")), "upload"), kStlPositions, kStlFaces);
  ExpectMesh(Parse(TetraStl("solid but binary"), "upload"), kStlPositions, kStlFaces);
  ExpectMesh(Parse(Gzip(TetraStl()), "upload.gz"), kStlPositions, kStlFaces);
  ExpectError(Parse("hello world\n", "upload"), Code::kInvalidArgument,
              {"upload: unrecognised mesh format"});
}

TEST(MeshIoTest, ExtensionIsCaseInsensitiveAndExplicitFormatWins) {
  ExpectMesh(Parse(Gzip(kTetraOff), "MESH.OFF.GZ"), kTetraPositions, kTetraFaces);
  ExpectMesh(ReadMeshFromBuffer(kTetraOff, MeshFormat::kOff, "mesh.stl"), kTetraPositions,
             kTetraFaces);
  // The extension decides over the content: OFF text read as PLY is a PLY error.
  ExpectError(Parse(kTetraOff, "mesh.ply"), Code::kInvalidArgument, {"mesh.ply: line 1", "ply"});
}

TEST(MeshIoTest, ReadMeshFileFromDisk) {
  TempDir dir;
  ExpectMesh(ReadMeshFile(dir.Write("a.off", kTetraOff)), kTetraPositions, kTetraFaces);
  ExpectMesh(ReadMeshFile(dir.Write("a.off.gz", Gzip(kTetraOff))), kTetraPositions, kTetraFaces);
  ExpectMesh(ReadMeshFile(dir.Write("b.ply", TetraPly(true, "short"))), kTetraPositions,
             kTetraFaces);
  ExpectMesh(ReadMeshFile(dir.Write("c.stl", TetraStl())), kStlPositions, kStlFaces);
  ExpectMesh(ReadMeshFile(dir.Write("d", ReadText(DataPath("cube.obj")))), kCubePositions,
             kCubeFaces);
  const std::string bad = dir.Write("bad.off", "OFF\n1 0 0\n0.0 0.0\n");
  ExpectError(ReadMeshFile(bad), Code::kInvalidArgument, {bad + ": line 3"});
  const absl::StatusOr<MeshData> missing = ReadMeshFile(dir.File("missing.off"));
  EXPECT_EQ(missing.status().code(), Code::kNotFound) << missing.status();
  EXPECT_TRUE(absl::StrContains(missing.status().message(), "missing.off"));
}

// Every prefix and many random corruptions of valid files: an answer, never a crash or a hang,
// and every error names the file.
TEST(MeshIoTest, TruncatedAndCorruptedInputNeverCrashes) {
  const std::vector<std::pair<std::string, std::string>> files = {
      {"a.off", ReadText(DataPath("cube_polygons.off"))},
      {"a.obj", ReadText(DataPath("cube.obj"))},
      {"a.ply", ReadText(DataPath("tetra_ascii.ply"))},
      {"b.ply", TetraPly(false)},
      {"c.ply", TetraPly(true, "double", "int", "uint")},
      {"a.stl", ReadText(DataPath("tetra_ascii.stl"))},
      {"b.stl", TetraStl()},
      {"a.off.gz", Gzip(kTetraOff)}};
  std::mt19937 rng(12345);
  for (const auto& [name, bytes] : files) {
    SCOPED_TRACE(name);
    std::vector<std::string> inputs;
    for (size_t n = 0; n < bytes.size(); ++n) inputs.push_back(bytes.substr(0, n));
    for (int i = 0; i < 300; ++i) {
      std::string corrupt = bytes;
      for (int k = 0; k < 1 + i % 4; ++k) {
        corrupt[rng() % corrupt.size()] = static_cast<char>(rng() % 256);
      }
      inputs.push_back(corrupt);
    }
    for (const std::string& input : inputs) {
      const absl::StatusOr<MeshData> mesh = Parse(input, name);
      if (mesh.ok()) {
        for (uint32_t v : mesh->faces) ASSERT_LT(v, mesh->vertex_count());
      } else {
        ASSERT_TRUE(absl::StartsWith(mesh.status().message(), name + ": ")) << mesh.status();
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Writers

MeshData TrickyMesh() {
  MeshData mesh;
  mesh.positions = {
      0.1,     1.0 / 3.0,    -2.5e300, 5e-324, -0.0, 123456789.123456789, std::nextafter(1.0, 2.0),
      -1e-300, 6.02214076e23};
  mesh.faces = {0, 1, 2, 2, 1, 0};
  return mesh;
}

TEST(MeshWriterTest, OffRoundTripIsBitIdentical) {
  TempDir dir;
  const MeshData mesh = TrickyMesh();
  ASSERT_TRUE(WriteMeshOff(dir.File("m.off"), mesh).ok());
  const absl::StatusOr<MeshData> back = ReadMeshFile(dir.File("m.off"));
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->positions.size(), mesh.positions.size());
  EXPECT_EQ(std::memcmp(back->positions.data(), mesh.positions.data(), 8 * 9), 0);
  EXPECT_EQ(back->faces, mesh.faces);

  VertexAttributes colours;
  colours.colors = {255, 0, 0, 0, 255, 0, 0, 0, 255};
  ASSERT_TRUE(WriteMeshOff(dir.File("c.off"), mesh, colours).ok());
  EXPECT_TRUE(absl::StartsWith(ReadText(dir.File("c.off")), "COFF\n3 2 0\n"));
  ExpectMesh(ReadMeshFile(dir.File("c.off")), back->positions, mesh.faces);
}

TEST(MeshWriterTest, PlyRoundTripWithDistanceAndColours) {
  TempDir dir;
  const MeshData mesh = TrickyMesh();
  VertexAttributes attributes;
  attributes.scalar = {0.0, 0.5, std::numeric_limits<double>::infinity()};
  attributes.colors = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  ASSERT_TRUE(WriteMeshPly(dir.File("m.ply"), mesh, attributes).ok());
  const absl::StatusOr<MeshData> back = ReadMeshFile(dir.File("m.ply"));
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->positions.size(), mesh.positions.size());
  EXPECT_EQ(std::memcmp(back->positions.data(), mesh.positions.data(), 8 * 9), 0);
  EXPECT_EQ(back->faces, mesh.faces);

  const std::string text = ReadText(dir.File("m.ply"));
  EXPECT_TRUE(absl::StrContains(text, "format binary_little_endian 1.0\n"));
  EXPECT_TRUE(absl::StrContains(text, "property double distance\n"));
  EXPECT_TRUE(absl::StrContains(text, "property uchar red\nproperty uchar green\n"));
  // Vertex records are x y z distance (4 doubles) then r g b.
  const size_t body = text.find("end_header\n") + 11;
  for (int v = 0; v < 3; ++v) {
    double distance;
    std::memcpy(&distance, text.data() + body + 35 * v + 24, 8);
    EXPECT_EQ(distance, attributes.scalar[v]);
    EXPECT_EQ(text[body + 35 * v + 32], static_cast<char>(3 * v + 1));
  }
  ASSERT_TRUE(WriteMeshPly(dir.File("plain.ply"), mesh).ok());
  EXPECT_FALSE(absl::StrContains(ReadText(dir.File("plain.ply")), "distance"));
}

TEST(MeshWriterTest, RejectsMismatchedAttributesAndUnwritablePaths) {
  TempDir dir;
  VertexAttributes attributes;
  attributes.scalar = {1.0};
  EXPECT_EQ(WriteMeshPly(dir.File("x.ply"), TrickyMesh(), attributes).code(),
            Code::kInvalidArgument);
  EXPECT_FALSE(WriteMeshOff(dir.File("no/such/dir/x.off"), TrickyMesh()).ok());
}

}  // namespace
}  // namespace geodex
