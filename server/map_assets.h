#pragma once

// The map page's files (server/map/, and Leaflet from Debian's libjs-leaflet, BSD-2-Clause), built
// into geodexd (cmake/EmbedFiles.cmake) so the page works without internet and without files next
// to the binary. The HTTP port serves them under their URL paths (http_edge.cc).

#include <string>
#include <string_view>
#include <vector>

namespace geodex::server {

struct MapAsset {
  const char* path;        // "/", "/map.js", "/leaflet/leaflet.js", ...
  std::string_view bytes;  // the file
};

const std::vector<MapAsset>& MapAssets();

// The media type of a served file, by its extension.
inline std::string MapAssetMediaType(const std::string& path) {
  auto ends = [&](const char* suffix) {
    const std::string s(suffix);
    return path.size() >= s.size() && path.compare(path.size() - s.size(), s.size(), s) == 0;
  };
  if (path == "/" || ends(".html")) return "text/html; charset=utf-8";
  if (ends(".js")) return "text/javascript; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  if (ends(".png")) return "image/png";
  return "application/octet-stream";
}

}  // namespace geodex::server
