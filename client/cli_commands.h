#pragma once

// The geodex command line: argument parsing and the query commands (info, distances, path,
// matrix), each written once against a Backend (local or remote).

#include <map>
#include <string>
#include <vector>

namespace geodex::cli {

// Exit codes, documented in `geodex --help`.
enum ExitCode : int {
  kExitOk = 0,
  kExitSolveFailed = 1,  // the computation failed (cancelled, budget exceeded, ...)
  kExitUsage = 2,        // bad command line or argument (including a bad point SPEC)
  kExitInput = 3,        // the mesh could not be read or is invalid
};

// `--key value` / `--key=value` / `--flag` arguments after the command and its positionals.
struct Args {
  std::vector<std::string> positional;
  std::map<std::string, std::string> options;  // flags without a value map to ""
};

// Parses argv[first..]; `boolean_flags` take no value. Returns false with *error set on failure.
bool ParseArgs(int argc, char** argv, int first, const std::vector<std::string>& boolean_flags,
               Args* out, std::string* error);

class Backend;  // cli_backend.h: where the command runs (this process or a geodexd)

int RunInfo(Backend& backend, const Args& args);
int RunDistances(Backend& backend, const Args& args);
int RunPath(Backend& backend, const Args& args);
int RunMatrix(Backend& backend, const Args& args);
int RunLocate(Backend& backend, const Args& args);

}  // namespace geodex::cli
