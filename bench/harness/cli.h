#pragma once

// Command-line helpers shared by the bench's programs: reading --flag, --flag VALUE and
// --flag=VALUE with the same error messages everywhere, and finding mesh files.

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace geodex::bench {

// Walks argv[1..]: Next() moves to the next argument, flag() is it (the part before '=' for
// --flag=VALUE), Value() its value (after '=', else the next argument, which it consumes).
class ArgReader {
 public:
  ArgReader(int argc, char** argv) : argc_(argc), argv_(argv) {}

  // False after the last argument.
  bool Next();
  const std::string& flag() const { return flag_; }
  // "--flag needs a value" when there is none.
  absl::StatusOr<std::string> Value();
  // "bad value for --flag: 'VALUE'".
  absl::Status Bad(const std::string& value) const;
  // "unknown argument '--flag'".
  absl::Status Unknown() const;

 private:
  int argc_;
  char** argv_;
  int i_ = 0;
  std::string flag_, value_;
  bool has_value_ = false;
};

// A mesh file by its name: .off .obj .ply .stl, optionally .gz.
bool IsMeshFileName(const std::string& name);
// The mesh's name: its file name without .gz and without the format's extension.
std::string MeshName(const std::string& path);
// Every mesh file in `dir` (not recursive), in directory order.
std::vector<std::string> MeshFilesIn(const std::string& dir);

}  // namespace geodex::bench
