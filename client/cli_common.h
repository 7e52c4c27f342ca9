#pragma once

// Helpers every geodex command shares: one-line failures, mesh loading, option parsing, and
// resolving point SPECs against a mesh.

#include <array>
#include <chrono>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "cli_commands.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/isolines.h"
#include "geodex/locate.h"
#include "geodex/mesh_data.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "geodex/terrain.h"
#include "geodex/triangle_mesh.h"

namespace geodex::cli {

double MsSince(std::chrono::steady_clock::time_point t);

// Prints "geodex: MESSAGE" on stderr and returns `code`.
int Fail(int code, const std::string& message);

// The text of a --barrier file (GeoJSON polygons); InvalidArgument naming it with the OS's reason.
absl::StatusOr<std::string> ReadBarrierText(const std::string& path);

// Reads a mesh file, or a built-in sample ("sample:terrain"); a DEM (terrain::IsDemPath) is read
// with GDAL and triangulated, and kept in *dem when given. A mesh file or sample takes the
// barriers too: --barrier-below (faces with a corner lower) and --barrier (GeoJSON polygons in
// its own x y), vertices keeping their ids.
absl::StatusOr<MeshData> LoadMeshData(const std::string& path,
                                      const terrain::DemOptions& dem_options = {},
                                      std::shared_ptr<const terrain::Dem>* dem = nullptr);

struct LoadedMesh {
  MeshData data;
  TriangleMesh mesh;
  double load_ms, build_ms;
  std::shared_ptr<const terrain::Dem> dem;  // when read from a DEM
};
// Reads and builds; a Build error is prefixed with the path.
absl::StatusOr<LoadedMesh> LoadMesh(const std::string& path, const MeshBuildOptions& options,
                                    const terrain::DemOptions& dem_options = {});

// --key as a number; absent leaves *out unchanged. False with *error naming the option.
bool GetDouble(const Args& args, const std::string& key, double* out, std::string* error);
bool GetUint(const Args& args, const std::string& key, uint64_t* out, std::string* error);
// With a barrier (--barrier-below, --barrier), says on stderr when the surface is in several parts
// (what lies in another part than the sources is unreachable). Local and remote mode alike.
void WarnIfBarrierSplits(const terrain::DemOptions& dem_options, uint64_t components);

// How MESH is read (--dem-step, --barrier-below, --barrier) and GeoJSON written (--crs): options
// of every command that takes a MESH, checked by MeshReadOptions (cli_backend.h).
inline const std::set<std::string> kMeshReadingFlags = {
    "dem-step", "z-tolerance", "barrier-below", "barrier", "barrier-width", "crs"};
// Travel time instead of length (geodex/travel_cost.h), taken by every command that takes --lambda:
// --speed constant:KMH turns it on; the others need it.
inline const std::set<std::string> kTravelFlags = {
    "speed",         "cost-epsilon", "max-slope",          "friction", "friction-boundaries",
    "friction-snap", "face-weights", "max-steiner-points", "inbound"};
// The flag a core option error is about (InvalidOptionOf: "lambda", "travel.epsilon",
// "face_weight[3]"; or geodexd's request field under "options.", "travel.face_weights[3]"), as the
// user typed it: "--lambda", "--cost-epsilon", "--face-weights".
std::string FlagOfOption(const std::string& option);
// The message of an option error (core's, terrain's) in the CLI's words: "--flag: message" when
// it names an option (InvalidOptionOf), the message alone otherwise.
std::string InFlagTerms(const absl::Status& status);
// False with *error naming the first option neither in `known` nor in kMeshReadingFlags (nor, for
// a command that takes --lambda, kTravelFlags).
bool CheckKnown(const Args& args, const std::set<std::string>& known, std::string* error);
// --lambda, --lambda-scale, --max-distance and --max-windows into `options`, checked by core's
// ValidateGeodesicOptions; false with *error naming the flag.
bool GetSolverFlags(const Args& args, GeodesicOptions* options, std::string* error);
// --levels L1,L2,... or --COUNT_FLAG K (isolines' --count, render's --isolines) into `options`,
// checked by core's ValidateIsolineOptions (finite levels, a count >= 2); false with *error
// naming the flag.
bool GetLevels(const Args& args, const std::string& count_flag, IsolineOptions* options,
               std::string* error);

// While alive, shows "geodex: WHAT... 3.4 s" on stderr, refreshed, once the work has taken more
// than a second, and only when stderr is a terminal (scripts and pipes see nothing). Cleared at the
// end.
class Progress {
 public:
  explicit Progress(std::string what);
  ~Progress();
  // Stops and clears the line (Fail() calls this so that an error starts on a clean line).
  void Stop();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// A progress bar on stderr for row-by-row work (matrix rows, solved locally or streamed by a
// server), shown only on a terminal and only once the call has run for a second; it replaces the
// Progress line while shown.
class RowProgress {
 public:
  RowProgress();
  ~RowProgress() { Finish(); }
  // Clears the bar (before the answer is printed).
  void Finish();
  void Update(size_t done, size_t total);

 private:
  using Clock = std::chrono::steady_clock;
  bool enabled_;
  bool shown_ = false;
  Clock::time_point start_, last_;
};

// --- Output, shared by local and remote mode (so both print the same bytes) ---

// What `geodex info` prints.
struct InfoValues : MeshSummary {
  double load_ms = 0, build_ms = 0;
  const terrain::DemInfo* dem = nullptr;  // a DEM's map: its CRS, grid, nodata and units
};
// --- JSON (--format json): %.17g numbers, null for an unreachable (infinite) distance. Each
// command's own text and JSON formats are next to the command (cli_commands.cc). ---
std::string JsonNumber(double x);
std::string JsonString(const std::string& s);  // a string literal, RFC 8259 escapes
std::string JsonXyz(const std::array<double, 3>& p);
// {"p": [x, y, z], "v": id} / "e": [from, to, t] / "f": [face, b0, b1, b2]
std::string PathPointJson(const PathPoint& p);
// --format text|json (absent: text). False with *error naming the flag.
bool GetFormat(const Args& args, bool* json, std::string* error);

// Writes `text` to --output FILE, or stdout. kExitOk, or kExitUsage naming the OS's reason.
int WriteOutput(const Args& args, const std::string& text);

}  // namespace geodex::cli
