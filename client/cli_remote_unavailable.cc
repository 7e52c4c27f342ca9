// Remote mode when the binary is built without the gRPC API (GEODEX_BUILD_SERVER=OFF).

#include "cli_backend.h"
#include "cli_common.h"
#include "cli_remote.h"

namespace geodex::cli {

bool RemoteAvailable() { return false; }

void SetRemoteOptions(const RemoteOptions&) {}

int RunServerCommand(const std::string&, const std::string&, const Args&) {
  return Fail(kExitUsage, "this geodex was built without gRPC: --server is not available");
}

std::unique_ptr<Backend> MakeRemoteBackend(const std::string&) { return nullptr; }

}  // namespace geodex::cli
