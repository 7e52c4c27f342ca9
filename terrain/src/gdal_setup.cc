#include <mutex>

#include "cpl_conv.h"
#include "cpl_http.h"
#include "cpl_string.h"
#include "gdal_quiet.h"
#include "ogr_srs_api.h"

namespace geodex::terrain {
namespace {

// Every HTTP request GDAL would make through CPLHTTPFetch ends here, unsent. (Returning null would
// hand the request on to GDAL's own fetcher, so a failed result is returned instead.)
CPLHTTPResult* RefuseFetch(const char* url, CSLConstList, GDALProgressFunc, void*,
                           CPLHTTPFetchWriteFunc, void*, void*) {
  auto* result = static_cast<CPLHTTPResult*>(CPLCalloc(1, sizeof(CPLHTTPResult)));
  result->nStatus = 1;
  result->pszErrBuf = CPLStrdup("geodex fetches no URL");
  CPLError(CE_Failure, CPLE_AppDefined, "geodex fetches no URL (%s)", url != nullptr ? url : "");
  return result;
}

}  // namespace

void PrepareGdal() {
  static std::once_flag once;
  std::call_once(once, [] {
    CPLSetConfigOption("GDAL_DISABLE_READDIR_ON_OPEN", "EMPTY_DIR");
    // /vsicurl/, /vsis3/, /vsigs/, ... open only the file named here, which cannot exist.
    CPLSetConfigOption("CPL_VSIL_CURL_ALLOWED_FILENAME", "/geodex/network-access-is-disabled");
    // The *_streaming file systems check only the extensions: none is allowed.
    CPLSetConfigOption("CPL_VSIL_CURL_ALLOWED_EXTENSIONS", ".geodex-network-access-is-disabled");
    CPLSetConfigOption("GDAL_VRT_ENABLE_PYTHON", "NO");
    CPLSetConfigOption("GDAL_HTTP_TIMEOUT", "1");  // belt and braces, should anything still fetch
    // exportToProj4 (the upload check for PROJ text naming files) would otherwise ask PROJ for a
    // bound CRS to WGS 84 first, and PROJ 9.1 dereferences null there on some malformed GeoTIFF
    // CRSs (found by dem_fuzzer; tests/data/bad_bound_crs.tif). geodex wants the CRS's own PROJ
    // text, not an added +towgs84, so the step is skipped for every export.
    CPLSetConfigOption("OSR_ADD_TOWGS84_ON_EXPORT_TO_PROJ4", "NO");
    CPLHTTPSetFetchCallback(RefuseFetch, nullptr);
    OSRSetPROJEnableNetwork(FALSE);
    GDALAllRegister();
  });
}

}  // namespace geodex::terrain
