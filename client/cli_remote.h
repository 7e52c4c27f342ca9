#pragma once

// Remote mode of the geodex command line: `geodex --server HOST:PORT COMMAND ...` (or the
// GEODEX_SERVER environment variable). The query commands run through the remote Backend
// (cli_backend.h, implemented in cli_remote.cc); here are the connection settings and the
// commands that exist only against a server (mesh management, health).

#include <string>

#include "cli_commands.h"

namespace geodex::cli {

// Connection settings of remote mode: global options before the command.
struct RemoteOptions {
  std::string target;      // --server HOST:PORT, or GEODEX_SERVER
  bool tls = false;        // --tls
  std::string ca_file;     // --ca FILE (PEM roots; implies --tls)
  std::string token_file;  // --token-file FILE, or the token itself in GEODEX_TOKEN
};
// Set once by main before any command runs.
void SetRemoteOptions(const RemoteOptions& options);

// True when this binary was built with the gRPC API (remote mode available).
bool RemoteAvailable();

// `mesh ...` and `health` against `target`; kExitUsage for any other command.
int RunServerCommand(const std::string& target, const std::string& command, const Args& args);

}  // namespace geodex::cli
