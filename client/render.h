#pragma once

// A small software renderer for `geodex render`: the mesh shaded and coloured by distance (a
// perceptual colour map), with isolines, Voronoi boundaries, Delaunay edges, paths and sources
// drawn over it, seen from a named direction and framed automatically; written as PNG (libpng).
// Also coloured PLY and glTF 2.0 exports of the same colours for 3D viewers.
//
// Orthographic projection, a z-buffer, Lambert shading (two-sided) plus an ambient term; lines are
// depth-tested against the surface with a small bias so they show on it but not through it.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "geodex/mesh_data.h"

namespace geodex::render {

using Point3 = std::array<double, 3>;
using Rgb = std::array<uint8_t, 3>;

// Viridis-like perceptual map of t in [0, 1] (dark blue-violet -> green -> yellow).
Rgb ColorMap(double t);
// Per-vertex colours of a field: distance / (largest finite distance) through the colour map;
// unreachable (+inf) vertices grey.
std::vector<Rgb> FieldColors(const std::vector<double>& distances);

struct Polyline {
  std::vector<Point3> points;
  bool closed = false;
  Rgb color{0, 0, 0};
  double width = 1.5;  // pixels
  std::string label;   // drawn on the line (an isoline's level); "" for none
};

struct Scene {
  const MeshData* mesh = nullptr;
  std::vector<Rgb> vertex_colors;  // one per mesh vertex
  std::vector<Polyline> lines;
  std::vector<Point3> markers;  // sources: black dots with a white ring
  // The colour bar at the right (when max_distance > 0 and the image is at least kColorBarMinWidth
  // wide): the colour map from 0 (bottom) to max_distance (top), labelled, with `units`.
  double max_distance = 0;
  std::string units = "mesh units";  // "m" on a DEM; "s" on a travel-time map (min from 10 min)
  std::string caption = "distance";  // above the colour bar ("travel time")
  bool scale_bar = false;            // a round length at the bottom left (a DEM: metres)
};

// Round values for a colour bar or a scale: ticks at 0, s, 2s, ... <= max_value with s 1, 2 or 5
// times a power of ten and at most `most` ticks above 0; on "m" from 2 km on, in km; on "s" from
// 10 minutes on, in min. Labels have
// no exponent (but for values beyond 1e9) and as many decimals as the step needs.
struct NiceScale {
  std::string units;
  double divisor = 1;  // the labels are value / divisor in `units`
  double step = 0;     // in the caller's units
  struct Tick {
    double value;       // in the caller's units
    std::string label;  // in `units`
  };
  std::vector<Tick> ticks;
};
NiceScale NiceTicks(double max_value, const std::string& units, int most);
// One value in the same terms ("350 m", "2.5 km").
std::string NiceLabel(double value, const std::string& units);
// The colour bar's strip: the rightmost kColorBarWidth pixels; the bar itself is the 16 pixels
// from width - kColorBarWidth + 8, from 15% to 85% of the height (tests sample it there).
inline constexpr int kColorBarWidth = 112;
inline constexpr int kColorBarMinWidth = 320;

enum class View { kAuto, kIso, kTop, kBottom, kFront, kBack, kLeft, kRight };
// "auto" (the default), "iso", "top", "bottom", "front", "back", "left", "right" (z is up: top
// looks down -z, front looks along +y).
absl::StatusOr<View> ParseView(const std::string& name);
// The view `auto` picks: of iso and the six axis views, the first (in that order) from which the
// most markers, then the most points of the lines, are visible (not hidden by the surface).
View ChooseView(const Scene& scene);

struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // row-major, 3 bytes per pixel
};

// Renders the scene into a width x height image (white background).
Image Render(const Scene& scene, View view, int width, int height);

// PNG, 8-bit RGB, rows written unfiltered (simple to read back in tests).
absl::Status WritePng(const std::string& path, const Image& image);
// Binary PLY with per-vertex colours (and the distance as a scalar).
absl::Status WriteColoredPly(const std::string& path, const MeshData& mesh,
                             const std::vector<Rgb>& colors, const std::vector<double>& distances);
// glTF 2.0 (one .gltf JSON file with the buffer embedded as a base64 data URI): positions,
// COLOR_0 and indices.
absl::Status WriteGltf(const std::string& path, const MeshData& mesh,
                       const std::vector<Rgb>& colors);

}  // namespace geodex::render
