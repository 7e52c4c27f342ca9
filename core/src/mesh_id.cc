#include "geodex/mesh_id.h"

#include <openssl/evp.h>

#include <bit>
#include <cstdlib>
#include <cstring>

namespace geodex {
namespace {

void PutLe32(uint32_t v, uint8_t* out) {
  for (int i = 0; i < 4; ++i) out[i] = static_cast<uint8_t>(v >> (8 * i));
}
void PutLe64(uint64_t v, uint8_t* out) {
  for (int i = 0; i < 8; ++i) out[i] = static_cast<uint8_t>(v >> (8 * i));
}
uint64_t GetLe(const char* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= uint64_t{static_cast<uint8_t>(p[i])} << (8 * i);
  return v;
}

// Feeds the canonical encoding to `sink(const uint8_t*, size_t)` in pieces.
template <typename Sink>
void EncodeCanonical(const MeshData& mesh, Sink&& sink) {
  uint8_t header[12] = {'G', 'D', 'X', 'M'};
  PutLe32(static_cast<uint32_t>(mesh.vertex_count()), header + 4);
  PutLe32(static_cast<uint32_t>(mesh.face_count()), header + 8);
  sink(header, sizeof header);
  uint8_t buf[4096];
  size_t n = 0;
  auto flush = [&] {
    sink(buf, n);
    n = 0;
  };
  for (double d : mesh.positions) {
    if (n + 8 > sizeof buf) flush();
    PutLe64(std::bit_cast<uint64_t>(d), buf + n);
    n += 8;
  }
  for (uint32_t f : mesh.faces) {
    if (n + 4 > sizeof buf) flush();
    PutLe32(f, buf + n);
    n += 4;
  }
  flush();
}

}  // namespace

void Sha256::Free::operator()(evp_md_ctx_st* ctx) const { EVP_MD_CTX_free(ctx); }

// Only allocation failure can make OpenSSL's SHA-256 fail; that ends the process like a failed
// new would.
Sha256::Sha256() : ctx_(EVP_MD_CTX_new()) {
  if (ctx_ == nullptr || EVP_DigestInit_ex(ctx_.get(), EVP_sha256(), nullptr) != 1) std::abort();
}
Sha256::~Sha256() = default;
Sha256::Sha256(Sha256&&) noexcept = default;
Sha256& Sha256::operator=(Sha256&&) noexcept = default;

void Sha256::Update(const void* data, size_t size) {
  if (size > 0 && EVP_DigestUpdate(ctx_.get(), data, size) != 1) std::abort();
}

std::array<uint8_t, 32> Sha256::Finish() {
  std::array<uint8_t, 32> out{};
  unsigned int length = 0;
  if (EVP_DigestFinal_ex(ctx_.get(), out.data(), &length) != 1 || length != out.size()) {
    std::abort();
  }
  return out;
}

std::string HexDigest(const std::array<uint8_t, 32>& digest) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string out(64, '0');
  for (size_t i = 0; i < 32; ++i) {
    out[2 * i] = kDigits[digest[i] >> 4];
    out[2 * i + 1] = kDigits[digest[i] & 15];
  }
  return out;
}

std::string Sha256Hex(absl::string_view bytes) {
  Sha256 sha;
  sha.Update(bytes.data(), bytes.size());
  return HexDigest(sha.Finish());
}

std::string CanonicalMeshEncoding(const MeshData& mesh) {
  std::string out;
  out.reserve(12 + 8 * mesh.positions.size() + 4 * mesh.faces.size());
  EncodeCanonical(
      mesh, [&](const uint8_t* p, size_t n) { out.append(reinterpret_cast<const char*>(p), n); });
  return out;
}

absl::StatusOr<MeshData> DecodeCanonicalMesh(absl::string_view bytes) {
  if (bytes.size() < 12 || std::memcmp(bytes.data(), "GDXM", 4) != 0) {
    return absl::InvalidArgumentError("not a canonical mesh encoding");
  }
  const uint64_t vertices = GetLe(bytes.data() + 4, 4), faces = GetLe(bytes.data() + 8, 4);
  if (bytes.size() != 12 + 24 * vertices + 12 * faces) {
    return absl::InvalidArgumentError("canonical mesh encoding has the wrong length");
  }
  MeshData mesh;
  mesh.positions.resize(3 * vertices);
  mesh.faces.resize(3 * faces);
  const char* p = bytes.data() + 12;
  for (double& x : mesh.positions) {
    x = std::bit_cast<double>(GetLe(p, 8));
    p += 8;
  }
  for (uint32_t& v : mesh.faces) {
    v = static_cast<uint32_t>(GetLe(p, 4));
    p += 4;
  }
  return mesh;
}

std::string ComputeMeshId(const MeshData& mesh) {
  Sha256 sha;
  EncodeCanonical(mesh, [&](const uint8_t* p, size_t n) { sha.Update(p, n); });
  return HexDigest(sha.Finish());
}

bool IsMeshId(absl::string_view s) {
  if (s.size() != 64) return false;
  for (char c : s) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

}  // namespace geodex
