#pragma once

// GDAL reports errors through a global handler that prints; geodex reports them itself. While a
// QuietGdal lives, GDAL is quiet (and prepared once, see PrepareGdal) and LastMessage() reads back
// the last error since it was made.

#include <string>

#include "cpl_error.h"
#include "gdal_priv.h"

namespace geodex::terrain {

// Registers GDAL's drivers and closes every way GDAL or PROJ could reach beyond the bytes and files
// geodex hands them, once per process, for geodexd and the CLI alike (docs/reliability.md, "What
// GDAL may not follow"):
// - no network: every CPLHTTPFetch (a GeoJSON "crs" link, importFromUrl, WMS-like drivers) is
//   answered by a refusing callback; /vsicurl/ and the other network file systems open nothing
//   (CPL_VSIL_CURL_ALLOWED_FILENAME names no file, CPL_VSIL_CURL_ALLOWED_EXTENSIONS allows no
//   extension for the *_streaming ones); PROJ fetches no grid (OSRSetPROJEnableNetwork);
// - no side-car files found by listing a directory (GDAL_DISABLE_READDIR_ON_OPEN=EMPTY_DIR): a
//   caller that wants a local file's own side-cars (.prj, .hdr, .aux.xml) passes them by name;
// - no Python in VRT pixel functions (GDAL_VRT_ENABLE_PYTHON=NO).
// Safe to call from any thread, as often as wanted; every terrain entry point calls it.
void PrepareGdal();

class QuietGdal {
 public:
  QuietGdal() {
    PrepareGdal();
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
