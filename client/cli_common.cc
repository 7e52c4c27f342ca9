#include "cli_common.h"

#include "output_file.h"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <thread>
#include <fstream>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "absl/strings/str_join.h"
#include "geodex/mesh_io.h"
#include "geodex/samples.h"

namespace geodex::cli {
namespace {
Progress* g_active_progress = nullptr;  // the one main shows, for Fail()
// A JSON string literal (RFC 8259 escapes).
std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20) {
      out += absl::StrFormat("\\u%04x", c);
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

}  // namespace

double MsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

int Fail(int code, const std::string& message) {
  if (g_active_progress != nullptr) g_active_progress->Stop();
  std::fprintf(stderr, "geodex: %s\n", message.c_str());
  return code;
}

absl::StatusOr<std::string> ReadBarrierText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return absl::InvalidArgumentError(
        absl::StrCat("--barrier ", path, ": cannot open: ", std::strerror(errno)));
  }
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Reads a mesh file, or a built-in sample ("sample:terrain").
absl::StatusOr<MeshData> LoadMeshData(const std::string& path,
                                      const terrain::DemOptions& dem_options,
                                      std::shared_ptr<const terrain::Dem>* dem) {
  if (terrain::IsDemPath(path) && path.rfind("sample:", 0) != 0) {
    absl::StatusOr<terrain::Dem> read = terrain::Dem::Read(path, dem_options);
    if (!read.ok()) return read.status();
    auto shared = std::make_shared<const terrain::Dem>(*std::move(read));
    MeshData data = shared->mesh();
    if (dem != nullptr) *dem = std::move(shared);
    return data;
  }
  absl::StatusOr<MeshData> data =
      path.rfind("sample:", 0) == 0 ? MakeSampleMesh(path) : ReadMeshFile(path);
  if (!data.ok()) return data.status();
  if (std::isfinite(dem_options.barrier_below)) {
    data = terrain::RemoveFacesBelow(*data, dem_options.barrier_below);
  }
  if (!dem_options.barrier_file.empty()) {  // polygons in the mesh's own x y
    absl::StatusOr<std::string> text = ReadBarrierText(dem_options.barrier_file);
    if (!text.ok()) return text.status();
    uint64_t removed = 0;
    data = terrain::RemoveFacesInPolygons(*data, *text, nullptr,
                                          "--barrier " + dem_options.barrier_file, &removed);
  }
  return data;
}

absl::StatusOr<LoadedMesh> LoadMesh(const std::string& path, const MeshBuildOptions& options,
                                    const terrain::DemOptions& dem_options) {
  const auto t0 = std::chrono::steady_clock::now();
  std::shared_ptr<const terrain::Dem> dem;
  absl::StatusOr<MeshData> data = LoadMeshData(path, dem_options, &dem);
  if (!data.ok()) return data.status();
  const double load_ms = MsSince(t0);
  const auto t1 = std::chrono::steady_clock::now();
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data, options);
  if (!mesh.ok()) {
    return absl::Status(mesh.status().code(), path + ": " + std::string(mesh.status().message()));
  }
  return LoadedMesh{std::move(*data), std::move(*mesh), load_ms, MsSince(t1), std::move(dem)};
}

bool GetDouble(const Args& args, const std::string& key, double* out, std::string* error) {
  auto it = args.options.find(key);
  if (it == args.options.end()) return true;
  if (!absl::SimpleAtod(it->second, out) || std::isnan(*out)) {
    *error = absl::StrFormat("--%s: '%s' is not a number", key, it->second);
    return false;
  }
  return true;
}

bool GetUint(const Args& args, const std::string& key, uint64_t* out, std::string* error) {
  auto it = args.options.find(key);
  if (it == args.options.end()) return true;
  if (!absl::SimpleAtoi(it->second, out)) {
    *error = absl::StrFormat("--%s: '%s' is not a non-negative integer", key, it->second);
    return false;
  }
  return true;
}

bool CheckKnown(const Args& args, const std::set<std::string>& known, std::string* error) {
  for (const auto& [key, value] : args.options) {
    if (!known.count(key) && !kMeshReadingFlags.count(key)) {
      *error = absl::StrFormat("unknown option --%s (see geodex --help)", key);
      return false;
    }
  }
  return true;
}

struct Progress::State {
  std::mutex mu;
  std::condition_variable done_cv;
  bool done = false;
  bool shown = false;
  std::thread thread;
};

Progress::Progress(std::string what) {
  if (!::isatty(2)) return;
  state_ = std::make_unique<State>();
  State* s = state_.get();
  g_active_progress = this;
  s->thread = std::thread([s, what = std::move(what)] {
    const auto start = std::chrono::steady_clock::now();
    std::unique_lock<std::mutex> lock(s->mu);
    if (s->done_cv.wait_for(lock, std::chrono::seconds(1), [s] { return s->done; })) return;
    while (!s->done) {
      std::fprintf(stderr, "\rgeodex: %s... %.1f s ", what.c_str(), MsSince(start) / 1e3);
      std::fflush(stderr);
      s->shown = true;
      s->done_cv.wait_for(lock, std::chrono::milliseconds(200), [s] { return s->done; });
    }
  });
}

Progress::~Progress() { Stop(); }

void Progress::Stop() {
  if (g_active_progress == this) g_active_progress = nullptr;
  if (state_ == nullptr || !state_->thread.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(state_->mu);
    state_->done = true;
  }
  state_->done_cv.notify_all();
  state_->thread.join();
  if (state_->shown) std::fputs("\r\033[K", stderr);  // clear the line
}

RowProgress::RowProgress() : enabled_(::isatty(2) != 0), start_(Clock::now()) {}

void RowProgress::Finish() {
  if (shown_) std::fputs("\r\033[K", stderr);
  shown_ = false;
  enabled_ = false;
}

void RowProgress::Update(size_t done, size_t total) {
  if (!enabled_) return;
  const auto now = Clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (elapsed < 1 || (shown_ && now - last_ < std::chrono::milliseconds(100) && done < total)) {
    return;
  }
  if (!shown_ && g_active_progress != nullptr) g_active_progress->Stop();  // one line at a time
  last_ = now;
  shown_ = true;
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(kWidth * done / std::max<size_t>(total, 1));
  const double left = done > 0 ? elapsed * (total - done) / done : 0;
  std::fprintf(stderr, "\r[%s%s] %zu/%zu rows, %.1f s, ~%.0f s left\033[K",
               std::string(filled, '#').c_str(), std::string(kWidth - filled, '.').c_str(), done,
               total, elapsed, left);
  std::fflush(stderr);
}

std::string FormatInfo(const InfoValues& v, bool json) {
  const MeshReport& r = v.report;
  const std::vector<std::pair<std::string, std::string>> rows = {
      {"vertices", absl::StrFormat("%d", r.file_vertices)},
      {"faces", absl::StrFormat("%d", r.file_faces)},
      {"boundary_edges", absl::StrFormat("%d", r.boundary_edges)},
      {"boundary_loops", absl::StrFormat("%d", r.boundary_loops)},
      {"components", absl::StrFormat("%d", r.components)},
      {"vertex_connected_components", absl::StrFormat("%d", r.vertex_connected_components)},
      {"isolated_vertices", absl::StrFormat("%d", r.isolated_vertices)},
      {"non_manifold_edges", absl::StrFormat("%d", r.non_manifold_edges)},
      {"non_manifold_vertices", absl::StrFormat("%d", r.non_manifold_vertices)},
      {"degenerate_faces", absl::StrFormat("%d", r.degenerate_faces)},
      {"flipped_faces", absl::StrFormat("%d", r.flipped_faces)},
      {"orientation_cuts", absl::StrFormat("%d", r.orientation_cuts)},
      {"saddle_vertices", absl::StrFormat("%d", r.saddle_vertices)},
      {"boundary_vertices", absl::StrFormat("%d", r.boundary_vertices)},
      {"internal_vertices", absl::StrFormat("%d", v.internal_vertices)},
      {"mean_edge_length", absl::StrFormat("%.17g", v.mean_edge_length)},
      {"max_edge_length", absl::StrFormat("%.17g", v.max_edge_length)},
      {"bbox_min", absl::StrFormat("%.17g %.17g %.17g", v.bbox_min[0], v.bbox_min[1], v.bbox_min[2])},
      {"bbox_max", absl::StrFormat("%.17g %.17g %.17g", v.bbox_max[0], v.bbox_max[1], v.bbox_max[2])},
      {"bytes", absl::StrFormat("%d", v.bytes)},
      {"load_ms", absl::StrFormat("%.3f", v.load_ms)},
      {"build_ms", absl::StrFormat("%.3f", v.build_ms)},
  };
  // A DEM's map (strings are quoted in JSON).
  std::vector<std::pair<std::string, std::string>> dem_rows;
  if (v.dem != nullptr) {
    const terrain::DemInfo& d = *v.dem;
    dem_rows = {
        {"barrier_cells", absl::StrFormat("%d", d.barrier_cells)},
        {"barrier_faces", absl::StrFormat("%d", d.barrier_faces)},
        {"crs", d.file_crs_name},
        {"mesh_crs", d.mesh_crs_name},
        {"units", "m"},
        {"raster", absl::StrFormat("%d %d", d.raster_width, d.raster_height)},
        {"dem_step", absl::StrFormat("%d", d.step)},
        {"grid", absl::StrFormat("%d %d", d.grid_width, d.grid_height)},
        {"nodata_cells", absl::StrFormat("%d", d.nodata_cells)},
        {"vertical_unit", d.vertical_unit.empty() ? "m (assumed)" : d.vertical_unit},
        {"driver", d.driver},
    };
  }
  std::string out;
  if (!json) {
    for (const auto& [k, value] : rows) absl::StrAppend(&out, k, ": ", value, "\n");
    for (const auto& [k, value] : dem_rows) absl::StrAppend(&out, k, ": ", value, "\n");
    return out;
  }
  out = "{";
  for (size_t i = 0; i < rows.size(); ++i) {
    // A bounding-box corner is an array of three numbers in JSON.
    const bool triple = rows[i].first.rfind("bbox_", 0) == 0;
    out += absl::StrFormat("%s\"%s\": %s%s%s", i ? ", " : "", rows[i].first, triple ? "[" : "",
                           triple ? absl::StrJoin(absl::StrSplit(rows[i].second, ' '), ", ")
                                  : rows[i].second,
                           triple ? "]" : "");
  }
  for (const auto& [k, value] : dem_rows) {
    const bool pair = k == "raster" || k == "grid";
    const bool number =
        k == "dem_step" || k == "nodata_cells" || k == "barrier_cells" || k == "barrier_faces";
    out += absl::StrFormat(", \"%s\": %s", k,
                           pair     ? absl::StrCat("[", absl::StrJoin(absl::StrSplit(value, ' '), ", "), "]")
                           : number ? value
                                    : JsonString(value));
  }
  return out + "}\n";
}

std::string FormatDistances(const std::vector<double>& distances,
                            const std::vector<std::array<double, 3>>& directions) {
  std::string text;
  text.reserve(distances.size() * (directions.empty() ? 24 : 96));
  char buf[160];
  for (size_t i = 0; i < distances.size(); ++i) {
    const int n = directions.empty()
                      ? std::snprintf(buf, sizeof(buf), "%.17g\n", distances[i])
                      : std::snprintf(buf, sizeof(buf), "%.17g\t%.17g %.17g %.17g\n", distances[i],
                                      directions[i][0], directions[i][1], directions[i][2]);
    text.append(buf, n);
  }
  return text;
}

std::string FormatAtLine(const SurfacePoint& point, double estimate, double exact,
                         uint32_t source) {
  return absl::StrFormat("%s\testimate %.17g\texact %.17g\tsource %d\n", SurfacePointToString(point),
                         estimate, exact,
                         static_cast<int64_t>(source == kNoIndex ? -1 : int64_t{source}));
}

namespace {

std::string SimplexText(const SurfacePoint& p) {
  switch (p.kind) {
    case SurfacePoint::Kind::kVertex:
      return absl::StrFormat("v %d", p.vertex);
    case SurfacePoint::Kind::kEdge:
      return absl::StrFormat("e %d %d %.17g", p.edge_from, p.edge_to, p.t);
    case SurfacePoint::Kind::kFace:
      return absl::StrFormat("f %d %.17g %.17g %.17g", p.face, p.bary[0], p.bary[1], p.bary[2]);
    case SurfacePoint::Kind::kPosition:
      break;
  }
  return "?";
}

}  // namespace

std::string FormatPath(const PathQueryResult& result) {
  std::string text = absl::StrFormat("%.17g\n", result.distance);
  for (const PathPoint& p : result.path.points) {
    text += absl::StrFormat("%.17g %.17g %.17g %s\n", p.position[0], p.position[1], p.position[2],
                            SimplexText(p.where));
  }
  return text;
}

std::string FormatMatrix(const DistanceMatrix& m) {
  std::string text;
  for (size_t i = 0; i < m.rows; ++i) {
    for (size_t j = 0; j < m.cols; ++j) {
      text += absl::StrFormat(j ? "\t%.17g" : "%.17g", m.values[i * m.cols + j]);
    }
    text += "\n";
  }
  return text;
}

std::string JsonNumber(double x) {
  return std::isfinite(x) ? absl::StrFormat("%.17g", x) : "null";
}

std::string JsonXyz(const std::array<double, 3>& p) {
  return absl::StrFormat("[%.17g, %.17g, %.17g]", p[0], p[1], p[2]);
}

std::string PathPointJson(const PathPoint& p) {
  const SurfacePoint& w = p.where;
  std::string s = "{\"p\": " + JsonXyz(p.position) + ", ";
  switch (w.kind) {
    case SurfacePoint::Kind::kVertex:
      return s + absl::StrFormat("\"v\": %d}", w.vertex);
    case SurfacePoint::Kind::kEdge:
      return s + absl::StrFormat("\"e\": [%d, %d, %.17g]}", w.edge_from, w.edge_to, w.t);
    case SurfacePoint::Kind::kFace:
      return s + absl::StrFormat("\"f\": [%d, %.17g, %.17g, %.17g]}", w.face, w.bary[0], w.bary[1],
                                 w.bary[2]);
    case SurfacePoint::Kind::kPosition:
      break;
  }
  return s + "\"position\": true}";
}

std::string FormatDistancesJson(const std::vector<double>& distances,
                                const std::vector<std::array<double, 3>>& directions) {
  std::string text = "{\"distances\": [";
  text.reserve(distances.size() * (directions.empty() ? 24 : 96));
  for (size_t i = 0; i < distances.size(); ++i) {
    if (i) text += ", ";
    text += JsonNumber(distances[i]);
  }
  if (!directions.empty()) {
    text += "], \"directions\": [";
    for (size_t i = 0; i < directions.size(); ++i) {
      if (i) text += ", ";
      text += std::isnan(directions[i][0]) ? "null" : JsonXyz(directions[i]);
    }
  }
  return text + "]}\n";
}

std::string FormatAtJson(const std::vector<SurfacePoint>& points, const std::vector<double>& estimate,
                         const std::vector<double>& exact, const std::vector<int64_t>& source) {
  std::string text = "{\"points\": [";
  for (size_t i = 0; i < points.size(); ++i) {
    text += absl::StrFormat(
        "%s{\"point\": \"%s\", \"estimate\": %s, \"exact\": %s, \"source\": %s}",
        i ? ", " : "", SurfacePointToString(points[i]), JsonNumber(estimate[i]),
        JsonNumber(exact[i]), source[i] < 0 ? "null" : absl::StrCat(source[i]));
  }
  return text + "]}\n";
}

std::string FormatPathJson(const PathQueryResult& result) {
  std::string text = "{\"length\": " + JsonNumber(result.distance) + ", \"points\": [";
  for (size_t i = 0; i < result.path.points.size(); ++i) {
    text += (i ? ", " : "") + PathPointJson(result.path.points[i]);
  }
  return text + "]}\n";
}

std::string FormatMatrixJson(const DistanceMatrix& m) {
  std::string text = absl::StrFormat("{\"rows\": %d, \"cols\": %d, \"values\": [", m.rows, m.cols);
  for (size_t i = 0; i < m.rows; ++i) {
    text += i ? ", [" : "[";
    for (size_t j = 0; j < m.cols; ++j) {
      text += (j ? ", " : "") + JsonNumber(m.values[i * m.cols + j]);
    }
    text += "]";
  }
  return text + "]}\n";
}

bool GetFormat(const Args& args, bool* json, std::string* error) {
  const std::string format = args.options.count("format") ? args.options.at("format") : "text";
  if (format != "text" && format != "json") {
    *error = "--format must be text or json";
    return false;
  }
  *json = format == "json";
  return true;
}

int WriteOutput(const Args& args, const std::string& text) {
  auto it = args.options.find("output");
  if (it == args.options.end()) {
    std::fwrite(text.data(), 1, text.size(), stdout);
    return kExitOk;
  }
  absl::Status written = WriteOutputFile(it->second, text);
  if (!written.ok()) return Fail(kExitUsage, std::string(written.message()));
  return kExitOk;
}

}  // namespace geodex::cli
