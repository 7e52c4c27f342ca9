#pragma once

// The committed test meshes in tests/data, loaded through the project's own reader.

#include <cctype>
#include <cstddef>  // geodex/mesh_data.h uses size_t without including it
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/mesh_data.h"
#include "geodex/triangle_mesh.h"

namespace geodex {

// Absolute path of a file in tests/data.
std::string TestDataPath(const std::string& name);

// The six committed meshes, in a fixed order: knight, three-peaks, bunny-npm, kitten, fertility,
// bump-domain (file names with the .off extension).
const std::vector<std::string>& CommittedMeshNames();

// Reads tests/data/`name` with geodex::ReadMeshFile.
absl::StatusOr<MeshData> LoadTestMeshData(const std::string& name);

// Reads and builds (default MeshBuildOptions).
absl::StatusOr<TriangleMesh> LoadTestMesh(const std::string& name);

// A test name for a mesh file parameter ("bump-domain.off" -> "bump_domain_off"), for
// INSTANTIATE_TEST_SUITE_P.
struct MeshFileParamName {
  template <typename Info>
  std::string operator()(const Info& info) const {
    std::string name = info.param;
    for (char& c : name) {
      if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    }
    return name;
  }
};

}  // namespace geodex
