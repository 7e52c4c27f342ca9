#pragma once

// Every file the CLI writes (--output of any command, render's pictures) fails the same way:
// InvalidArgument "cannot write PATH: <the OS's reason>", which the CLI reports with exit code 2
// (a bad argument: the path), never as an unreadable mesh.

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace geodex::cli {

inline absl::Status OutputFileError(const std::string& path, int err) {
  return absl::InvalidArgumentError(absl::StrCat("cannot write ", path, ": ", std::strerror(err)));
}

// Opens `path` for writing (binary); null with *status set when it cannot.
inline std::FILE* OpenOutputFile(const std::string& path, absl::Status* status) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) *status = OutputFileError(path, errno);
  return f;
}

// Closes a file from OpenOutputFile, reporting a failed write or close (a full disk).
inline absl::Status CloseOutputFile(const std::string& path, std::FILE* f) {
  const bool write_error = std::ferror(f) != 0;
  const int err = errno;
  if (std::fclose(f) != 0) return OutputFileError(path, errno);
  if (write_error) return OutputFileError(path, err != 0 ? err : EIO);
  return absl::OkStatus();
}

inline absl::Status WriteOutputFile(const std::string& path, std::string_view bytes) {
  absl::Status status;
  std::FILE* f = OpenOutputFile(path, &status);
  if (f == nullptr) return status;
  std::fwrite(bytes.data(), 1, bytes.size(), f);
  return CloseOutputFile(path, f);
}

}  // namespace geodex::cli
