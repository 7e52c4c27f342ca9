// libFuzzer target: the data-directory reader (server/mesh_disk.h), the one reader that parses
// files geodexd did not just receive. Byte 0 picks what the rest is:
//   0: a canonical mesh encoding, decoded (DecodeCanonicalMesh) and, if it decodes, built;
//   1: a whole .gdxs file, stored under a valid id and read back through MeshDisk::Open (the
//      index at start) and MeshDisk::Read (the load on first use);
//   2: like 1, but the fuzzer appends the correct trailing SHA-256 first, so the input reaches the
//      framing and header parsing past the checksum instead of stopping at it.
// Every outcome must be a status or a mesh, never a crash or an allocation beyond the file's size.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "geodex/mesh_id.h"
#include "geodex/triangle_mesh.h"
#include "mesh_disk.h"

namespace {

using namespace geodex;
using namespace geodex::server;

// One scratch data directory per fuzzing process, under $TMPDIR.
const std::string& ScratchDir() {
  static const std::string* dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp ? tmp : "/tmp") + "/geodex-fuzz-XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) std::abort();
    return new std::string(pattern);
  }();
  return *dir;
}

void StoreAndRead(const std::string& file_bytes) {
  // The id of the seed corpus's mesh (tests/data/io/tetra.off), so the seeds read back whole and
  // mutations start from a file that passes every check.
  const std::string id = "e8300f98367943b605bd4624f2440bc88227cf9ccf9a983ca8701db7b1105bc6";
  MeshDisk::Index index;
  absl::StatusOr<MeshDisk> disk = MeshDisk::Open(ScratchDir(), &index);
  if (!disk.ok()) std::abort();  // the scratch directory itself must work
  const std::string path = disk->PathOf(id);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(file_bytes.data(), static_cast<std::streamsize>(file_bytes.size()));
  }
  MeshDisk::Index reopened;
  (void)MeshDisk::Open(ScratchDir(), &reopened);
  MeshRecord header;
  std::string canonical;
  (void)disk->Read(id, &header, &canonical);
  std::remove(path.c_str());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::string body(reinterpret_cast<const char*>(data) + 1, size - 1);
  switch (data[0] % 3) {
    case 0: {
      absl::StatusOr<MeshData> mesh = DecodeCanonicalMesh(body);
      if (mesh.ok()) (void)TriangleMesh::Build(*mesh);
      break;
    }
    case 1:
      StoreAndRead(body);
      break;
    case 2: {
      Sha256 sha;
      sha.Update(body.data(), body.size());
      const std::array<uint8_t, 32> sum = sha.Finish();
      StoreAndRead(body + std::string(reinterpret_cast<const char*>(sum.data()), sum.size()));
      break;
    }
  }
  return 0;
}
