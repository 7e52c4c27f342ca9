#pragma once

// A GDAL in-memory file (/vsimem) of its own: a unique name (calls run in parallel on a server's
// pool), removed when the MemFile goes. Over the caller's bytes (not copied: they must outlive it)
// for GDAL to read, or empty for GDAL to write and Take() to read back.

#include <atomic>
#include <cstdint>
#include <string>

#include "absl/strings/str_cat.h"
#include "cpl_conv.h"
#include "cpl_vsi.h"

namespace geodex::terrain {

class MemFile {
 public:
  // An empty name to write to; `extension` tells GDAL the format (".tif", ".geojson").
  explicit MemFile(const char* extension) {
    static std::atomic<uint64_t> serial{0};
    path_ = absl::StrCat("/vsimem/geodex-", serial.fetch_add(1), extension);
  }
  // A file over `bytes`; ok() is false when GDAL cannot make it.
  MemFile(const char* extension, const std::string& bytes) : MemFile(extension) {
    VSILFILE* file = VSIFileFromMemBuffer(path_.c_str(),
                                          reinterpret_cast<GByte*>(const_cast<char*>(bytes.data())),
                                          bytes.size(), FALSE);
    ok_ = file != nullptr;
    if (ok_) VSIFCloseL(file);
  }
  ~MemFile() { VSIUnlink(path_.c_str()); }
  MemFile(const MemFile&) = delete;
  MemFile& operator=(const MemFile&) = delete;

  const std::string& path() const { return path_; }
  bool ok() const { return ok_; }
  // What GDAL wrote, taken out of the file ("" when nothing was).
  std::string Take() {
    vsi_l_offset length = 0;
    GByte* data = VSIGetMemFileBuffer(path_.c_str(), &length, TRUE);
    std::string out =
        data != nullptr ? std::string(reinterpret_cast<const char*>(data), length) : "";
    CPLFree(data);
    return out;
  }

 private:
  std::string path_;
  bool ok_ = true;
};

}  // namespace geodex::terrain
