#pragma once

// GDAL reports errors through a global handler that prints; geodex reports them itself. While a
// QuietGdal lives, GDAL is quiet (drivers registered once) and LastMessage() reads back the last
// error since it was made.

#include <mutex>
#include <string>

#include "cpl_error.h"
#include "gdal_priv.h"

namespace geodex::terrain {

class QuietGdal {
 public:
  QuietGdal() {
    static std::once_flag once;
    std::call_once(once, [] { GDALAllRegister(); });
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
  }
  ~QuietGdal() { CPLPopErrorHandler(); }
  QuietGdal(const QuietGdal&) = delete;
  QuietGdal& operator=(const QuietGdal&) = delete;
  static std::string LastMessage() {
    const char* m = CPLGetLastErrorMsg();
    return m != nullptr && *m != '\0' ? std::string(m) : std::string("unknown GDAL error");
  }
};

}  // namespace geodex::terrain
