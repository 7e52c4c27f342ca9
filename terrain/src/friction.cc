#include "geodex/friction.h"

#include "absl/status/status.h"

namespace geodex::terrain {

absl::StatusOr<std::vector<double>> FrictionFromGeoJson(const MeshData&, const std::string&,
                                                        const DemInfo*, const std::string& name) {
  return absl::UnimplementedError(name + ": friction polygons are not read yet");
}

absl::StatusOr<std::vector<double>> ReadFrictionFile(const MeshData&, const std::string&,
                                                     const DemInfo&, const std::string& name) {
  return absl::UnimplementedError(name + ": friction files are not read yet");
}

}  // namespace geodex::terrain
