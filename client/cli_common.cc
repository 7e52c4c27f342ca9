#include "cli_common.h"

#include <cstdio>

#include "absl/strings/numbers.h"
#include "absl/strings/str_format.h"
#include "geodex/mesh_io.h"
#include "geodex/samples.h"

namespace geodex::cli {

double MsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

int Fail(int code, const std::string& message) {
  std::fprintf(stderr, "geodex: %s\n", message.c_str());
  return code;
}

// Reads a mesh file, or a built-in sample ("sample:terrain").
absl::StatusOr<MeshData> LoadMeshData(const std::string& path) {
  if (path.rfind("sample:", 0) == 0) return MakeSampleMesh(path);
  absl::StatusOr<MeshData> data = ReadMeshFile(path);
  if (!data.ok()) return data.status();
  return data;
}

absl::StatusOr<LoadedMesh> LoadMesh(const std::string& path, const MeshBuildOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  absl::StatusOr<MeshData> data = LoadMeshData(path);
  if (!data.ok()) return data.status();
  const double load_ms = MsSince(t0);
  const auto t1 = std::chrono::steady_clock::now();
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data, options);
  if (!mesh.ok()) {
    return absl::Status(mesh.status().code(), path + ": " + std::string(mesh.status().message()));
  }
  return LoadedMesh{std::move(*data), std::move(*mesh), load_ms, MsSince(t1)};
}

bool GetDouble(const Args& args, const std::string& key, double* out, std::string* error) {
  auto it = args.options.find(key);
  if (it == args.options.end()) return true;
  if (!absl::SimpleAtod(it->second, out) || std::isnan(*out)) {
    *error = absl::StrFormat("--%s: '%s' is not a number", key, it->second);
    return false;
  }
  return true;
}

bool GetUint(const Args& args, const std::string& key, uint64_t* out, std::string* error) {
  auto it = args.options.find(key);
  if (it == args.options.end()) return true;
  if (!absl::SimpleAtoi(it->second, out)) {
    *error = absl::StrFormat("--%s: '%s' is not a non-negative integer", key, it->second);
    return false;
  }
  return true;
}

bool CheckKnown(const Args& args, const std::set<std::string>& known, std::string* error) {
  for (const auto& [key, value] : args.options) {
    if (!known.count(key)) {
      *error = absl::StrFormat("unknown option --%s (see geodex --help)", key);
      return false;
    }
  }
  return true;
}

bool ResolvePoints(const TriangleMesh& mesh, const std::string& option,
                   std::vector<SurfacePoint>* points, std::unique_ptr<SurfaceLocator>* locator,
                   std::string* error) {
  for (SurfacePoint& p : *points) {
    if (p.kind == SurfacePoint::Kind::kPosition) {
      if (*locator == nullptr) *locator = std::make_unique<SurfaceLocator>(mesh);
      absl::StatusOr<LocatedPoint> located = (*locator)->Locate(p.position);
      if (!located.ok()) {
        *error = absl::StrFormat("--%s: %s: %s", option, SurfacePointToString(p),
                                 located.status().message());
        return false;
      }
      p = located->point;
    }
    if (absl::Status s = ValidateSurfacePoint(mesh, p); !s.ok()) {
      *error = absl::StrFormat("--%s: %s", option, s.message());
      return false;
    }
  }
  return true;
}


}  // namespace geodex::cli
