#include "harness/cli.h"

#include <cstddef>
#include <filesystem>
#include <system_error>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace geodex::bench {

bool ArgReader::Next() {
  if (++i_ >= argc_) return false;
  flag_ = argv_[i_];
  value_.clear();
  has_value_ = false;
  if (const size_t eq = flag_.find('='); absl::StartsWith(flag_, "--") && eq != std::string::npos) {
    value_ = flag_.substr(eq + 1);
    flag_ = flag_.substr(0, eq);
    has_value_ = true;
  }
  return true;
}

absl::StatusOr<std::string> ArgReader::Value() {
  if (has_value_) return value_;
  if (i_ + 1 >= argc_) return absl::InvalidArgumentError(absl::StrCat(flag_, " needs a value"));
  return std::string(argv_[++i_]);
}

absl::Status ArgReader::Bad(const std::string& value) const {
  return absl::InvalidArgumentError(absl::StrCat("bad value for ", flag_, ": '", value, "'"));
}

absl::Status ArgReader::Unknown() const {
  return absl::InvalidArgumentError(absl::StrCat("unknown argument '", flag_, "'"));
}

bool IsMeshFileName(const std::string& name) {
  std::string n = name;
  if (absl::EndsWith(n, ".gz")) n.resize(n.size() - 3);
  return absl::EndsWith(n, ".off") || absl::EndsWith(n, ".obj") || absl::EndsWith(n, ".ply") ||
         absl::EndsWith(n, ".stl");
}

std::string MeshName(const std::string& path) {
  std::string name = std::filesystem::path(path).filename().string();
  if (absl::EndsWith(name, ".gz")) name.resize(name.size() - 3);
  if (const size_t dot = name.rfind('.'); dot != std::string::npos) name.resize(dot);
  return name;
}

std::vector<std::string> MeshFilesIn(const std::string& dir) {
  std::vector<std::string> paths;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(dir, error)) {
    if (entry.is_regular_file() && IsMeshFileName(entry.path().filename().string())) {
      paths.push_back(entry.path().lexically_normal().string());
    }
  }
  return paths;
}

}  // namespace geodex::bench
