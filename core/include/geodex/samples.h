#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/mesh_data.h"

namespace geodex {

// Built-in sample meshes, generated in code so every binary has them without data files:
//   "terrain": a 65 x 65 height field (8192 faces) with hills and passes (saddle vertices), open;
//   "torus":   a 48 x 24 torus (2304 faces), closed, genus 1 (saddles on the inner side);
//   "sphere":  an icosphere subdivided 3 times (1280 faces), closed and convex.
// Names may be written with a "sample:" prefix wherever a mesh path is accepted.
absl::StatusOr<MeshData> MakeSampleMesh(const std::string& name);
std::vector<std::string> SampleMeshNames();

}  // namespace geodex
