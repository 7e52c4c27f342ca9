// Remote mode when the binary is built without the gRPC API (GEODEX_BUILD_SERVER=OFF).

#include "cli_common.h"
#include "cli_remote.h"

namespace geodex::cli {

bool RemoteAvailable() { return false; }

void SetRemoteOptions(const RemoteOptions&) {}

int RunRemote(const std::string&, const std::string&, const Args&) {
  return Fail(kExitUsage, "this geodex was built without gRPC: --server is not available");
}

std::unique_ptr<RemoteGeometry> ConnectRemoteGeometry(const std::string&) { return nullptr; }

int FailRemote(const absl::Status& status) {
  return Fail(kExitSolveFailed, std::string(status.message()));
}

}  // namespace geodex::cli
