#pragma once

// The geodex command line: argument parsing (cli_args.cc) and the query commands (info,
// distances, path, matrix, locate in cli_commands.cc; isolines, voronoi, delaunay, render in
// cli_geometry.cc and cli_render.cc), each written once against a Backend (local or remote), with
// its help and formats beside it.

#include <map>
#include <string>
#include <vector>

#include "absl/status/status.h"

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
  // Flags without a value map to "". A flag of kRepeatableFlags given several times maps to its
  // first value here, and to all of them, in order, in `lists`.
  std::map<std::string, std::string> options;
  std::map<std::string, std::vector<std::string>> lists;
  // "geodex COMMAND ARGS..." as given (from the command on: no global option, no token), recorded
  // in the GIS files the command writes (terrain::Provenance).
  std::string command_line;
  // Every value of `key`: lists' when repeatable, else the one value (none when absent).
  std::vector<std::string> All(const std::string& key) const;
};

// The flags that add up when given again: each --barrier file cuts, each --friction polygon file
// counts, each --sources / --targets list (joined) and --sources-file / --targets-file adds its
// points. Any other flag given twice is refused, naming it (a second --speed or --output must not
// silently win).
inline const char* const kRepeatableFlags[] = {"barrier", "friction",     "sources",
                                               "targets", "sources-file", "targets-file"};

// Parses argv[first..]; `boolean_flags` take no value. Returns false with *error set on failure.
bool ParseArgs(int argc, char** argv, int first, const std::vector<std::string>& boolean_flags,
               Args* out, std::string* error);

// --sources-file F / --targets-file F: the file's points (terrain::ReadPointsFile) appended to
// --sources / --targets as map points, named in messages as the file's features.
absl::Status ExpandPointFiles(Args* args);

class Backend;  // cli_backend.h: where the command runs (this process or a geodexd)

// A query command, described next to its code: main dispatches on `name`, parses knowing its
// value-less `flags` (every command's, so that another's flag is refused as unknown), and prints
// `help` (its entry of `geodex --help`, from "  NAME MESH ..." to
// the end of its description) for `geodex NAME --help`.
struct Command {
  const char* name;
  const char* help;
  std::vector<std::string> flags;  // options that take no value (--stats, --directions, ...)
  int (*run)(Backend& backend, const Args& args);
};
// Every query command, in the order `geodex --help` lists them (cli_commands.cc).
const std::vector<Command>& QueryCommands();
// The commands of the other files, listed by QueryCommands.
const Command& IsolinesCommand();  // cli_geometry.cc
const Command& VoronoiCommand();   // cli_geometry.cc
const Command& DelaunayCommand();  // cli_geometry.cc
const Command& RenderCommand();    // cli_render.cc

}  // namespace geodex::cli
