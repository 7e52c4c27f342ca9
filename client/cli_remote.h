#pragma once

// Remote mode of the geodex command line: `geodex --server HOST:PORT COMMAND ...` (or the
// GEODEX_SERVER environment variable) runs the command on a geodexd through the client library and
// prints exactly what local mode prints (timings and --stats aside).

#include <string>

#include "cli_commands.h"

namespace geodex::cli {

// True when this binary was built with the gRPC API (remote mode available).
bool RemoteAvailable();

// Runs `command` against `target`; kExitUsage for a command remote mode does not offer.
int RunRemote(const std::string& target, const std::string& command, const Args& args);

}  // namespace geodex::cli
