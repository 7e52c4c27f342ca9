#include "util/test_meshes.h"

#include "geodex/mesh_io.h"

namespace geodex {

std::string TestDataPath(const std::string& name) {
  return std::string(GEODEX_TEST_DATA_DIR) + "/" + name;
}

const std::vector<std::string>& CommittedMeshNames() {
  static const std::vector<std::string>* const kNames =
      new std::vector<std::string>{"knight.off", "three-peaks.off", "bunny-npm.off",
                                   "kitten.off", "fertility.off",   "bump-domain.off"};
  return *kNames;
}

absl::StatusOr<MeshData> LoadTestMeshData(const std::string& name) {
  return ReadMeshFile(TestDataPath(name));
}

absl::StatusOr<TriangleMesh> LoadTestMesh(const std::string& name) {
  absl::StatusOr<MeshData> data = LoadTestMeshData(name);
  if (!data.ok()) return data.status();
  return TriangleMesh::Build(*data);
}

}  // namespace geodex
