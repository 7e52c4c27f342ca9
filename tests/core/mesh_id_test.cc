#include "geodex/mesh_id.h"

#include <cstring>

#include "gtest/gtest.h"

namespace geodex {
namespace {

TEST(Sha256Test, KnownVectors) {
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(Sha256Hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256Test, IncrementalEqualsOneShot) {
  std::string data;
  for (int i = 0; i < 1000; ++i) data.push_back(static_cast<char>(i * 7));
  Sha256 sha;
  for (size_t i = 0; i < data.size(); i += 37)
    sha.Update(data.data() + i, std::min<size_t>(37, data.size() - i));
  std::array<uint8_t, 32> digest = sha.Finish();
  std::string hex;
  for (uint8_t b : digest) {
    static constexpr char kDigits[] = "0123456789abcdef";
    hex.push_back(kDigits[b >> 4]);
    hex.push_back(kDigits[b & 15]);
  }
  EXPECT_EQ(hex, Sha256Hex(data));
}

TEST(MeshIdTest, CanonicalEncodingLayout) {
  MeshData mesh;
  mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, -0.0};
  mesh.faces = {0, 1, 2};
  std::string bytes = CanonicalMeshEncoding(mesh);
  ASSERT_EQ(bytes.size(), 4 + 4 + 4 + 9 * 8 + 3 * 4u);
  EXPECT_EQ(bytes.substr(0, 4), "GDXM");
  EXPECT_EQ(bytes.substr(4, 8), std::string("\x03\0\0\0\x01\0\0\0", 8));
  double x1;
  std::memcpy(&x1, bytes.data() + 12 + 3 * 8, 8);
  EXPECT_EQ(x1, 1.0);
  EXPECT_EQ(static_cast<uint8_t>(bytes[12 + 8 * 8 + 7]), 0x80);  // -0.0 keeps its sign bit
  EXPECT_EQ(bytes.substr(12 + 72), std::string("\0\0\0\0\x01\0\0\0\x02\0\0\0", 12));
  EXPECT_EQ(ComputeMeshId(mesh), Sha256Hex(bytes));
  EXPECT_TRUE(IsMeshId(ComputeMeshId(mesh)));
  mesh.positions[8] = 0.0;
  EXPECT_NE(ComputeMeshId(mesh), Sha256Hex(bytes));
}

TEST(MeshIdTest, IsMeshId) {
  EXPECT_FALSE(IsMeshId(""));
  EXPECT_FALSE(IsMeshId(std::string(64, 'A')));
  EXPECT_TRUE(IsMeshId(std::string(64, 'a')));
  EXPECT_FALSE(IsMeshId(std::string(63, 'a')));
}

}  // namespace
}  // namespace geodex
