#include "cli_common.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <mutex>
#include <thread>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "geodex/geodesic_solver.h"
#include "geodex/gis_formats.h"
#include "geodex/limits.h"
#include "geodex/mesh_io.h"
#include "geodex/samples.h"
#include "output_file.h"

namespace geodex::cli {
namespace {
Progress* g_active_progress = nullptr;  // the one main shows, for Fail()

}  // namespace

std::string JsonString(const std::string& s) { return terrain::JsonQuoted(s); }

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

// A barrier that cuts nothing is most often drawn in the wrong place or CRS: said, not an error.
void WarnBarrierMisses(const terrain::DemOptions& dem_options) {
  std::fprintf(stderr,
               "geodex: warning: %s: the barrier cuts nothing: it misses the surface (drawn in "
               "another CRS, or "
               "lon/lat swapped?)\n",
               terrain::BarrierFilesName(dem_options.barrier_files).c_str());
}

void WarnIfBarrierSplits(const terrain::DemOptions& dem_options, uint64_t components) {
  const bool barrier =
      std::isfinite(dem_options.barrier_below) || !dem_options.barrier_files.empty();
  if (!barrier || components < 2) return;
  std::fprintf(
      stderr,
      "geodex: warning: with its barriers the surface is in %llu parts: a point in another part "
      "than every source is unreachable (inf)\n",
      static_cast<unsigned long long>(components));
}

// Reads a mesh file, or a built-in sample ("sample:terrain").
absl::StatusOr<MeshData> LoadMeshData(const std::string& path,
                                      const terrain::DemOptions& dem_options,
                                      std::shared_ptr<const terrain::Dem>* dem) {
  if (terrain::IsDemPath(path) && path.rfind("sample:", 0) != 0) {
    absl::StatusOr<terrain::Dem> read = terrain::Dem::Read(path, dem_options);
    if (!read.ok()) return read.status();
    if (!dem_options.barrier_files.empty() && read->info().barrier_faces == 0)
      WarnBarrierMisses(dem_options);
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
  if (!dem_options.barrier_files.empty()) {  // polygons in the mesh's own x y
    std::vector<terrain::NamedText> texts;
    for (const std::string& path : dem_options.barrier_files) {
      absl::StatusOr<std::string> text = ReadBarrierText(path);
      if (!text.ok()) return text.status();
      texts.push_back({*std::move(text), "--barrier " + path});
    }
    terrain::CutStats cut_stats;
    data =
        terrain::CutBarrierPolygons(*data, texts, nullptr, dem_options.barrier_width, &cut_stats);
    if (data.ok() && cut_stats.faces_removed + cut_stats.faces_cut == 0)
      WarnBarrierMisses(dem_options);
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
  WarnIfBarrierSplits(dem_options, mesh->report().components);
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

std::string FlagOfOption(const std::string& option) {
  if (option == "travel" || option == "travel.speed_kmh" ||
      absl::StartsWith(option, "travel.speed_table")) {
    return "--speed";
  }
  if (option == "travel.epsilon") return "--cost-epsilon";
  if (option == "travel.inbound") return "--inbound";
  if (option == "travel.max_slope_deg") return "--max-slope";
  if (absl::StartsWith(option, "face_weight") || absl::StartsWith(option, "travel.face_weights")) {
    return "--face-weights";  // or --friction's values
  }
  if (option == "travel.friction_geojson") return "--friction";
  if (option == "step") return "--dem-step";  // terrain's DemOptions (ValidateDemOptions)
  std::string flag = option;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return "--" + flag;
}

std::string InFlagTerms(const absl::Status& status) {
  const std::string option = InvalidOptionOf(status);
  const std::string message(status.message());
  return option.empty() ? message : absl::StrCat(FlagOfOption(option), ": ", message);
}

namespace {

// A speed table file: "slope_deg,speed_kmh" rows (a header line, blank lines and # comments are
// skipped); the rows' rules are core's (ValidateTravelCost).
bool ReadSpeedTable(const std::string& path, TravelCost* travel, std::string* error) {
  std::ifstream in(path);
  if (!in) {
    *error = absl::StrCat("--speed table:", path, ": cannot open: ", std::strerror(errno));
    return false;
  }
  auto table = std::make_shared<std::vector<std::array<double, 2>>>();
  std::string line;
  for (size_t n = 1; std::getline(in, line); ++n) {
    const absl::string_view text = absl::StripAsciiWhitespace(line);
    if (text.empty() || text[0] == '#') continue;
    const std::vector<absl::string_view> cells = absl::StrSplit(text, ',');
    std::array<double, 2> row{};
    if (cells.size() != 2 || !absl::SimpleAtod(cells[0], &row[0]) ||
        !absl::SimpleAtod(cells[1], &row[1])) {
      if (table->empty() && n == 1 && cells.size() == 2) continue;  // a header
      *error = absl::StrFormat(
          "--speed table:%s: line %d: '%s' is not 'slope_deg,speed_kmh' (two numbers)", path, n,
          text);
      return false;
    }
    table->push_back(row);
  }
  travel->speed_model = SpeedModel::kTable;
  travel->speed_table = std::move(table);
  return true;
}

// --speed constant:KMH | tobler | table:FILE.csv, --inbound and the cost flags that need a
// speed (the weights, read once the mesh is open, come later: ResolveTravelWeights).
bool GetTravelFlags(const Args& args, GeodesicOptions* options, std::string* error) {
  if (!args.options.count("speed")) {
    for (const std::string& flag : kTravelFlags) {
      if (args.options.count(flag)) {
        *error = absl::StrFormat(
            "--%s: a travel cost needs --speed constant:KMH, tobler or table:FILE.csv", flag);
        return false;
      }
    }
    return true;
  }
  const std::string& speed = args.options.at("speed");
  TravelCost travel;
  if (speed == "tobler") {
    travel.speed_model = SpeedModel::kTobler;
  } else if (absl::StartsWith(speed, "table:")) {
    if (!ReadSpeedTable(speed.substr(6), &travel, error)) return false;
  } else if (!absl::StartsWith(speed, "constant:") ||
             !absl::SimpleAtod(speed.substr(9), &travel.speed_kmh)) {
    *error = absl::StrFormat(
        "--speed: '%s' is not constant:KMH (a speed in km/h on a face of friction 1), tobler "
        "(Tobler's hiking function of the slope) or table:FILE.csv (slope_deg,speed_kmh rows)",
        speed);
    return false;
  }
  travel.inbound = args.options.count("inbound") > 0;
  if (args.options.count("cost-epsilon")) {  // unset: the speed model's default (TravelEpsilon)
    double epsilon = 0;
    if (!GetDouble(args, "cost-epsilon", &epsilon, error)) return false;
    travel.epsilon = epsilon;
  }
  // A default budget, as geodexd's: a solve needing more points is refused before allocating.
  travel.max_steiner_points = kDefaultMaxSteinerPoints;
  if (!GetDouble(args, "max-slope", &travel.max_slope_deg, error) ||
      !GetUint(args, "max-steiner-points", &travel.max_steiner_points, error)) {
    return false;
  }
  if (args.options.count("friction") && args.options.count("face-weights")) {
    *error = "--friction and --face-weights: give one (both set a weight per face)";
    return false;
  }
  options->travel = travel;
  return true;
}

}  // namespace

// --lambda, --lambda-scale, --max-distance and --max-windows, shared by every command
// that solves (distances, path, matrix, isolines, voronoi, delaunay), and the travel flags.
namespace {

// One cost amount as --levels and --max-distance take it: metres (or the mesh's unit), or with a
// travel cost a time in seconds, or with a unit (10min, 1.5h, 90s). False with *error naming
// --`flag`.
bool ParseAmount(const Args& args, const std::string& flag, absl::string_view item, double* out,
                 std::string* error) {
  double unit = 1;
  absl::string_view number = item;
  for (const auto& [suffix, seconds] :
       {std::pair<absl::string_view, double>{"min", 60}, {"h", 3600}, {"s", 1}}) {
    if (absl::ConsumeSuffix(&number, suffix)) {
      unit = seconds;
      break;
    }
  }
  double value;
  if (!absl::SimpleAtod(number, &value)) {
    *error = absl::StrFormat("--%s: '%s' is not a number", flag, item);
    return false;
  }
  if (number.size() != item.size() && !args.options.count("speed")) {
    *error = absl::StrFormat("--%s: '%s' is a time; times need --speed constant:KMH", flag, item);
    return false;
  }
  *out = value * unit;
  return true;
}

}  // namespace

bool GetSolverFlags(const Args& args, GeodesicOptions* options, std::string* error) {
  if (args.options.count("max-distance") &&
      !ParseAmount(args, "max-distance", args.options.at("max-distance"), &options->max_distance,
                   error)) {
    return false;
  }
  options->max_windows = kDefaultMaxWindows;  // the work budget (geodex/limits.h); 0: none
  if (!GetDouble(args, "lambda", &options->lambda, error) ||
      !GetUint(args, "max-windows", &options->max_windows, error) ||
      !GetTravelFlags(args, options, error)) {
    return false;
  }
  if (absl::Status s = ValidateGeodesicOptions(*options); !s.ok()) {  // core's one check
    *error = InFlagTerms(s);
    return false;
  }
  if (args.options.count("lambda-scale")) {
    const std::string& s = args.options.at("lambda-scale");
    if (s == "max") {
      options->lambda_scale = LambdaScale::kMaxEdge;
    } else if (s == "mean") {
      options->lambda_scale = LambdaScale::kMeanEdge;
    } else {
      *error = "--lambda-scale must be max or mean";
      return false;
    }
  }
  return true;
}

bool GetLevels(const Args& args, const std::string& count_flag, IsolineOptions* options,
               std::string* error) {
  if (args.options.count("levels")) {
    for (absl::string_view item : absl::StrSplit(args.options.at("levels"), ',')) {
      double level;
      if (!ParseAmount(args, "levels", item, &level, error)) return false;
      options->levels.push_back(level);
    }
  } else if (args.options.count(count_flag)) {
    if (!absl::SimpleAtoi(args.options.at(count_flag), &options->count)) {
      *error =
          absl::StrFormat("--%s: '%s' is not an integer", count_flag, args.options.at(count_flag));
      return false;
    }
  } else {
    return true;  // neither: the command says whether it needs levels
  }
  if (absl::Status s = ValidateIsolineOptions(*options); !s.ok()) {  // core's one check
    const std::string option = InvalidOptionOf(s);
    *error = absl::StrFormat("--%s: %s", absl::StartsWith(option, "levels") ? "levels" : count_flag,
                             s.message());
    return false;
  }
  return true;
}

bool CheckKnown(const Args& args, const std::set<std::string>& known, std::string* error) {
  for (const auto& [key, value] : args.options) {
    // --X-file (points from a file) goes with a command that takes --X.
    const bool file_of_known =
        absl::EndsWith(key, "-file") && known.count(key.substr(0, key.size() - 5));
    const bool travel = known.count("lambda") && kTravelFlags.count(key);
    if (!known.count(key) && !kMeshReadingFlags.count(key) && !file_of_known && !travel) {
      const std::string flag = args.options.count(key + "-file") ? key + "-file" : key;
      *error = absl::StrFormat("unknown option --%s (see geodex --help)", flag);
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

std::string JsonNumber(double x) { return std::isfinite(x) ? absl::StrFormat("%.17g", x) : "null"; }

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
