#include "render.h"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <tuple>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "geodex/mesh_io.h"
#include "output_file.h"

namespace geodex::render {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Point3 Sub(const Point3& a, const Point3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Point3 Cross(const Point3& a, const Point3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double Dot(const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Point3 Normalize(const Point3& a) {
  const double n = std::sqrt(Dot(a, a));
  return n > 0 ? Point3{a[0] / n, a[1] / n, a[2] / n} : Point3{0, 0, 1};
}

// The camera: screen right, screen up and the direction towards the viewer.
struct Camera {
  Point3 right, up, toward;
};

Camera CameraFor(View view) {
  switch (view) {
    case View::kTop:
      return {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    case View::kBottom:
      return {{1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
    case View::kFront:
      return {{1, 0, 0}, {0, 0, 1}, {0, -1, 0}};
    case View::kBack:
      return {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}};
    case View::kLeft:
      return {{0, -1, 0}, {0, 0, 1}, {-1, 0, 0}};
    case View::kRight:
      return {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}};
    case View::kIso:
    case View::kAuto:
      break;
  }
  const Point3 toward = Normalize({1, -1, 1.2});
  const Point3 right = Normalize(Cross({0, 0, 1}, toward));
  return {right, Cross(toward, right), toward};
}

// Projection of the scene into pixels: x right, y down, depth towards the viewer (larger = nearer).
struct Projector {
  Camera camera;
  double scale = 1, offset_x = 0, offset_y = 0;
  std::array<double, 3> operator()(const Point3& p) const {
    return {Dot(p, camera.right) * scale + offset_x, -Dot(p, camera.up) * scale + offset_y,
            Dot(p, camera.toward) * scale};
  }
};

Point3 VertexOf(const MeshData& m, uint32_t v) {
  return {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
}

class Canvas {
 public:
  Canvas(int width, int height)
      : width_(width),
        height_(height),
        depth_(size_t(width) * height, -kInf),
        image_{width, height, std::vector<uint8_t>(size_t(width) * height * 3, 255)} {}

  // A triangle with per-vertex colours, shaded by `light` (0..1).
  void Triangle(const std::array<double, 3> p[3], const Rgb c[3], double light) {
    const double min_x = std::max(0.0, std::floor(std::min({p[0][0], p[1][0], p[2][0]})));
    const double max_x = std::min(width_ - 1.0, std::ceil(std::max({p[0][0], p[1][0], p[2][0]})));
    const double min_y = std::max(0.0, std::floor(std::min({p[0][1], p[1][1], p[2][1]})));
    const double max_y = std::min(height_ - 1.0, std::ceil(std::max({p[0][1], p[1][1], p[2][1]})));
    const double area =
        (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
    if (std::abs(area) < 1e-12) return;
    for (int y = static_cast<int>(min_y); y <= max_y; ++y) {
      for (int x = static_cast<int>(min_x); x <= max_x; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        double w[3];
        for (int k = 0; k < 3; ++k) {
          const auto& a = p[(k + 1) % 3];
          const auto& b = p[(k + 2) % 3];
          w[k] = ((b[0] - a[0]) * (py - a[1]) - (px - a[0]) * (b[1] - a[1])) / area;
        }
        if (w[0] < -1e-9 || w[1] < -1e-9 || w[2] < -1e-9) continue;
        const double z = w[0] * p[0][2] + w[1] * p[1][2] + w[2] * p[2][2];
        const size_t i = size_t(y) * width_ + x;
        if (z <= depth_[i]) continue;
        depth_[i] = z;
        for (int ch = 0; ch < 3; ++ch) {
          const double v = (w[0] * c[0][ch] + w[1] * c[1][ch] + w[2] * c[2][ch]) * light;
          image_.rgb[3 * i + ch] = static_cast<uint8_t>(std::clamp(v, 0.0, 255.0));
        }
      }
    }
  }

  // A disc of radius r at (x, y) when its centre is not hidden (depth with a bias).
  void Dot(double x, double y, double z, double r, Rgb color, double bias) {
    for (int py = static_cast<int>(y - r - 1); py <= y + r + 1; ++py) {
      for (int px = static_cast<int>(x - r - 1); px <= x + r + 1; ++px) {
        if (px < 0 || py < 0 || px >= width_ || py >= height_) continue;
        const double dx = px + 0.5 - x, dy = py + 0.5 - y;
        if (dx * dx + dy * dy > r * r) continue;
        const size_t i = size_t(py) * width_ + px;
        if (z + bias < depth_[i]) continue;
        for (int ch = 0; ch < 3; ++ch) image_.rgb[3 * i + ch] = color[ch];
      }
    }
  }

  // A segment of the given width, depth-tested per sample.
  void Segment(const std::array<double, 3>& a, const std::array<double, 3>& b, double width,
               Rgb color, double bias) {
    const double length = std::hypot(b[0] - a[0], b[1] - a[1]);
    const int steps = std::max(1, static_cast<int>(std::ceil(length * 2)));
    for (int s = 0; s <= steps; ++s) {
      const double t = double(s) / steps;
      Dot(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2]), width / 2,
          color, bias);
    }
  }

  // True when a point at (x, y, z) lies inside the picture and is not behind the surface.
  bool Visible(double x, double y, double z, double bias) const {
    if (!(x >= 0 && y >= 0 && x < width_ && y < height_)) return false;
    return z + bias >= depth_[size_t(y) * width_ + static_cast<int>(x)];
  }

  Image Take() { return std::move(image_); }

 private:
  int width_, height_;
  std::vector<double> depth_;
  Image image_;
};

}  // namespace

Rgb ColorMap(double t) {
  // Ten evenly spaced samples of the viridis colour map, interpolated linearly.
  static constexpr uint8_t kStops[10][3] = {
      {68, 1, 84},    {72, 40, 120},  {62, 73, 137},  {49, 104, 142}, {38, 130, 142},
      {31, 158, 137}, {53, 183, 121}, {110, 206, 88}, {181, 222, 43}, {253, 231, 37}};
  t = std::clamp(std::isnan(t) ? 0.0 : t, 0.0, 1.0) * 9;
  const int i = std::min(8, static_cast<int>(t));
  const double f = t - i;
  Rgb out;
  for (int ch = 0; ch < 3; ++ch) {
    out[ch] =
        static_cast<uint8_t>(std::lround(kStops[i][ch] + f * (kStops[i + 1][ch] - kStops[i][ch])));
  }
  return out;
}

std::vector<Rgb> FieldColors(const std::vector<double>& distances) {
  double top = 0;
  for (double d : distances) {
    if (std::isfinite(d)) top = std::max(top, d);
  }
  std::vector<Rgb> out;
  out.reserve(distances.size());
  for (double d : distances) {
    out.push_back(std::isfinite(d) ? ColorMap(top > 0 ? d / top : 0) : Rgb{170, 170, 170});
  }
  return out;
}

absl::StatusOr<View> ParseView(const std::string& name) {
  if (name == "auto") return View::kAuto;
  if (name == "iso") return View::kIso;
  if (name == "top") return View::kTop;
  if (name == "bottom") return View::kBottom;
  if (name == "front") return View::kFront;
  if (name == "back") return View::kBack;
  if (name == "left") return View::kLeft;
  if (name == "right") return View::kRight;
  return absl::InvalidArgumentError(absl::StrFormat(
      "--view: '%s' is not one of auto, iso, top, bottom, front, back, left, right", name));
}

namespace {

// The projector that frames the mesh (the projected bounding box of the vertices used by faces,
// with a 5% margin) in a width x height picture.
Projector Frame(const MeshData& m, View view, int width, int height) {
  Projector project;
  project.camera = CameraFor(view);
  double lo[2] = {kInf, kInf}, hi[2] = {-kInf, -kInf};
  for (uint32_t v : m.faces) {
    const Point3 p = VertexOf(m, v);
    const double sx = Dot(p, project.camera.right), sy = -Dot(p, project.camera.up);
    lo[0] = std::min(lo[0], sx), hi[0] = std::max(hi[0], sx);
    lo[1] = std::min(lo[1], sy), hi[1] = std::max(hi[1], sy);
  }
  if (!(lo[0] <= hi[0])) lo[0] = lo[1] = 0, hi[0] = hi[1] = 1;
  const double extent_x = std::max(hi[0] - lo[0], 1e-300),
               extent_y = std::max(hi[1] - lo[1], 1e-300);
  project.scale = 0.9 * std::min(width / extent_x, height / extent_y);
  project.offset_x = width / 2.0 - (lo[0] + hi[0]) / 2 * project.scale;
  project.offset_y = height / 2.0 - (lo[1] + hi[1]) / 2 * project.scale;
  return project;
}

// Rasterises the mesh's faces (shaded, or flat grey when only the depth matters).
void DrawMesh(const Scene& scene, const Projector& project, Canvas* canvas) {
  const MeshData& m = *scene.mesh;
  const Point3 light_dir = Normalize({project.camera.toward[0] + 0.3 * project.camera.up[0],
                                      project.camera.toward[1] + 0.3 * project.camera.up[1],
                                      project.camera.toward[2] + 0.3 * project.camera.up[2]});
  const Rgb grey{128, 128, 128};
  for (size_t f = 0; f < m.face_count(); ++f) {
    const uint32_t v[3] = {m.faces[3 * f], m.faces[3 * f + 1], m.faces[3 * f + 2]};
    const Point3 a = VertexOf(m, v[0]), b = VertexOf(m, v[1]), c = VertexOf(m, v[2]);
    const Point3 normal = Normalize(Cross(Sub(b, a), Sub(c, a)));
    const double light = 0.35 + 0.65 * std::abs(Dot(normal, light_dir));  // two-sided
    const std::array<double, 3> p[3] = {project(a), project(b), project(c)};
    const bool colored = scene.vertex_colors.size() == m.vertex_count();
    const Rgb colors[3] = {colored ? scene.vertex_colors[v[0]] : grey,
                           colored ? scene.vertex_colors[v[1]] : grey,
                           colored ? scene.vertex_colors[v[2]] : grey};
    canvas->Triangle(p, colors, light);
  }
}

// Lines and markers lie on the surface: a depth bias of ~2 pixels keeps them visible on it.
constexpr double kSurfaceBias = 2.0;

// A 5x7 bitmap font for the colour bar's labels: digits, the characters of %g numbers and the
// few letters of its caption. Each glyph: 7 rows of 5 bits (bit 4 = leftmost pixel).
const uint8_t* Glyph(char c) {
  static const std::pair<char, std::array<uint8_t, 7>> kFont[] = {
      {'0', {14, 17, 19, 21, 25, 17, 14}}, {'1', {4, 12, 4, 4, 4, 4, 14}},
      {'2', {14, 17, 1, 2, 4, 8, 31}},     {'3', {31, 2, 4, 2, 1, 17, 14}},
      {'4', {2, 6, 10, 18, 31, 2, 2}},     {'5', {31, 16, 30, 1, 1, 17, 14}},
      {'6', {6, 8, 16, 30, 17, 17, 14}},   {'7', {31, 1, 2, 4, 8, 8, 8}},
      {'8', {14, 17, 17, 14, 17, 17, 14}}, {'9', {14, 17, 17, 15, 1, 2, 12}},
      {'.', {0, 0, 0, 0, 0, 12, 12}},      {'-', {0, 0, 0, 31, 0, 0, 0}},
      {'+', {0, 4, 4, 31, 4, 4, 0}},       {'e', {0, 0, 14, 17, 31, 16, 14}},
      {'a', {0, 0, 14, 1, 15, 17, 15}},    {'c', {0, 0, 14, 16, 16, 17, 14}},
      {'d', {1, 1, 13, 19, 17, 17, 15}},   {'h', {16, 16, 22, 25, 17, 17, 17}},
      {'i', {4, 0, 12, 4, 4, 4, 14}},      {'m', {0, 0, 26, 21, 21, 17, 17}},
      {'n', {0, 0, 22, 25, 17, 17, 17}},   {'s', {0, 0, 14, 16, 14, 1, 30}},
      {'t', {8, 8, 28, 8, 8, 9, 6}},       {'u', {0, 0, 17, 17, 17, 19, 13}},
      {'(', {2, 4, 8, 8, 8, 4, 2}},        {')', {8, 4, 2, 2, 2, 4, 8}},
      {'k', {16, 16, 18, 20, 24, 20, 18}}, {'r', {0, 0, 22, 25, 16, 16, 16}},
      {'v', {0, 0, 17, 17, 17, 10, 4}},    {'l', {12, 4, 4, 4, 4, 4, 14}},
  };
  for (const auto& [ch, rows] : kFont) {
    if (ch == c) return rows.data();
  }
  return nullptr;  // a space, or a character the bar never needs
}

void Text(Image* image, int x, int y, const std::string& text, int scale) {
  for (char c : text) {
    if (const uint8_t* rows = Glyph(c)) {
      for (int r = 0; r < 7; ++r) {
        for (int col = 0; col < 5; ++col) {
          if (!(rows[r] & (16 >> col))) continue;
          for (int dy = 0; dy < scale; ++dy) {
            for (int dx = 0; dx < scale; ++dx) {
              const int px = x + col * scale + dx, py = y + r * scale + dy;
              if (px < 0 || py < 0 || px >= image->width || py >= image->height) continue;
              const size_t i = 3 * (size_t(py) * image->width + px);
              image->rgb[i] = image->rgb[i + 1] = image->rgb[i + 2] = 30;
            }
          }
        }
      }
    }
    x += 6 * scale;
  }
}

// The width in pixels of `text` at `scale`.
int TextWidth(const std::string& text, int scale) {
  return static_cast<int>(text.size()) * 6 * scale - scale;
}

// White under `text` (a label over the picture stays readable).
void TextBackground(Image* image, int x, int y, const std::string& text, int scale) {
  for (int py = y - 1; py < y + 7 * scale + 1; ++py) {
    for (int px = x - 2; px < x + TextWidth(text, scale) + 2; ++px) {
      if (px < 0 || py < 0 || px >= image->width || py >= image->height) continue;
      const size_t i = 3 * (size_t(py) * image->width + px);
      image->rgb[i] = image->rgb[i + 1] = image->rgb[i + 2] = 255;
    }
  }
}

}  // namespace

NiceScale NiceTicks(double max_value, const std::string& units, int most) {
  NiceScale out;
  out.units = units;
  out.divisor = 1;
  if (units == "m" && max_value >= 2000) {  // kilometres read better from 2 km on
    out.units = "km";
    out.divisor = 1000;
  }
  if (units == "s" && max_value >= 600) {  // and minutes from 10 minutes on
    out.units = "min";
    out.divisor = 60;
  }
  const double top = max_value / out.divisor;
  if (!(top > 0) || !std::isfinite(top)) return out;
  // The smallest step of 1, 2 or 5 times a power of ten that puts at most `most` ticks above 0.
  double step = std::pow(10.0, std::floor(std::log10(top / most)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (top / (m * step) <= most) {
      step *= m;
      break;
    }
  }
  out.step = step * out.divisor;
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  for (int k = 0; k * step <= top * (1 + 1e-12); ++k) {
    const double value = k * step;
    std::string label = decimals > 6 || value >= 1e9 ? absl::StrFormat("%.3g", value)
                                                     : absl::StrFormat("%.*f", decimals, value);
    out.ticks.push_back({value * out.divisor, label});
  }
  return out;
}

std::string NiceLabel(double value, const std::string& units) {
  // Mesh units go unnamed on the picture.
  std::string unit = units == "m" || units == "s" ? units : "";
  if (units == "m" && std::abs(value) >= 2000) {
    unit = "km";
    value /= 1000;
  }
  if (units == "s" && std::abs(value) >= 600) {
    unit = "min";
    value /= 60;
  }
  // Three significant digits, no exponent.
  const int digits = std::clamp(
      2 - static_cast<int>(std::floor(std::log10(std::max(std::abs(value), 1e-300)))), 0, 6);
  std::string text = absl::StrFormat("%.*f", digits, value);
  if (text.find('.') != std::string::npos) {  // 12.50 -> 12.5, 3.00 -> 3
    while (text.back() == '0') text.pop_back();
    if (text.back() == '.') text.pop_back();
  }
  return unit.empty() ? text : text + " " + unit;
}

namespace {

// The colour bar in the right strip: the map from 0 (bottom) to max (top), ticks at round values
// (1, 2 or 5 times a power of ten; km from 2 km on a DEM) whose labels always fit in the strip
// (drawn smaller when needed), the caption ("distance", "travel time") and the units.
void DrawColorBar(Image* image, double max_distance, const std::string& units,
                  const std::string& caption) {
  const int x0 = image->width - kColorBarWidth + 8, bar = 16;
  const int top = static_cast<int>(0.15 * image->height),
            bottom = static_cast<int>(0.85 * image->height);
  for (int y = top; y < bottom; ++y) {
    const Rgb c = ColorMap(double(bottom - 1 - y) / std::max(1, bottom - 1 - top));
    for (int x = x0; x < x0 + bar; ++x) {
      const size_t i = 3 * (size_t(y) * image->width + x);
      for (int ch = 0; ch < 3; ++ch) image->rgb[i + ch] = c[ch];
    }
  }
  const NiceScale scale = NiceTicks(max_distance, units, 5);
  const int room = image->width - (x0 + bar + 9) - 2;  // to the image's edge, less a margin
  int text_scale = 2;
  for (const auto& tick : scale.ticks) {
    if (TextWidth(tick.label, 2) > room) text_scale = 1;
  }
  for (const auto& tick : scale.ticks) {
    const int y = bottom - 1 -
                  static_cast<int>(std::lround((bottom - 1 - top) * (tick.value / max_distance)));
    for (int x = x0 + bar; x < x0 + bar + 4; ++x) {  // a tick
      const size_t i = 3 * (size_t(y) * image->width + x);
      image->rgb[i] = image->rgb[i + 1] = image->rgb[i + 2] = 30;
    }
    std::string label = tick.label;
    while (TextWidth(label, text_scale) > room && !label.empty())
      label.pop_back();  // never past the edge
    Text(image, x0 + bar + 9, y - 7 * text_scale / 2, label, text_scale);
  }
  Text(image, x0 - 4, top - 40, caption, TextWidth(caption, 2) <= kColorBarWidth - 4 ? 2 : 1);
  Text(image, x0 - 4, top - 22, "(" + scale.units + ")", 1);
}

// A scale bar at the bottom left: a round length (1, 2 or 5 times a power of ten, m or km) about a
// fifth of the picture wide, in the view's own scale (lengths across the line of sight).
void DrawScaleBar(Image* image, const Projector& project, int mesh_width) {
  const double target = mesh_width * 0.25 / project.scale;  // metres
  if (!(target > 0) || !std::isfinite(target)) return;
  const double power = std::pow(10.0, std::floor(std::log10(target)));
  double length = power;
  for (double m : {2.0, 5.0}) {
    if (m * power <= target) length = m * power;
  }
  const int pixels = static_cast<int>(std::lround(length * project.scale));
  const int x = 12, y = image->height - 14;
  const std::string label = NiceLabel(length, "m");
  TextBackground(image, x, y - 12, label, 1);
  for (int px = x - 2; px < x + pixels + 2; ++px) {
    for (int py = y - 2; py < y + 5; ++py) {
      if (px < 0 || py < 0 || px >= image->width || py >= image->height) continue;
      const size_t i = 3 * (size_t(py) * image->width + px);
      image->rgb[i] = image->rgb[i + 1] = image->rgb[i + 2] = 255;
    }
  }
  for (int px = x; px < x + pixels; ++px) {
    for (int py = y; py < y + 3; ++py) {
      if (px < 0 || py < 0 || px >= image->width || py >= image->height) continue;
      const size_t i = 3 * (size_t(py) * image->width + px);
      image->rgb[i] = image->rgb[i + 1] = image->rgb[i + 2] = 30;
    }
  }
  Text(image, x, y - 12, label, 1);
}

}  // namespace

View ChooseView(const Scene& scene) {
  constexpr int kWidth = 200, kHeight = 150;  // a depth-only preview per candidate
  View best = View::kIso;
  std::pair<size_t, size_t> best_seen{0, 0};
  for (View view : {View::kIso, View::kTop, View::kFront, View::kRight, View::kBack, View::kLeft,
                    View::kBottom}) {
    const Projector project = Frame(*scene.mesh, view, kWidth, kHeight);
    Canvas canvas(kWidth, kHeight);
    DrawMesh(Scene{scene.mesh, {}, {}, {}}, project, &canvas);
    std::pair<size_t, size_t> seen{0, 0};
    for (const Point3& marker : scene.markers) {
      const auto p = project(marker);
      seen.first += canvas.Visible(p[0], p[1], p[2], kSurfaceBias * 3);
    }
    for (const Polyline& line : scene.lines) {
      for (const Point3& point : line.points) {
        const auto p = project(point);
        seen.second += canvas.Visible(p[0], p[1], p[2], kSurfaceBias);
      }
    }
    if (seen > best_seen) {
      best_seen = seen;
      best = view;
    }
  }
  return best;
}

Image Render(const Scene& scene, View view, int width, int height) {
  if (view == View::kAuto) view = ChooseView(scene);
  const bool bar = scene.max_distance > 0 && width >= kColorBarMinWidth;
  const int mesh_width = bar ? width - kColorBarWidth : width;
  const Projector project = Frame(*scene.mesh, view, mesh_width, height);
  Canvas canvas(width, height);
  DrawMesh(scene, project, &canvas);
  for (const Polyline& line : scene.lines) {
    for (size_t i = 0; i + 1 < line.points.size() + (line.closed ? 1 : 0); ++i) {
      const Point3& a = line.points[i];
      const Point3& b = line.points[(i + 1) % line.points.size()];
      canvas.Segment(project(a), project(b), line.width, line.color, kSurfaceBias);
    }
  }
  for (const Point3& marker : scene.markers) {
    const auto p = project(marker);
    canvas.Dot(p[0], p[1], p[2], 6, {255, 255, 255}, kSurfaceBias * 3);
    canvas.Dot(p[0], p[1], p[2], 4, {0, 0, 0}, kSurfaceBias * 3);
  }
  // Which lines' labels show: a label sits at its line's visible point nearest the middle of the
  // picture, on white, and is left out where it would cover another label.
  std::vector<std::array<int, 4>> placed;  // x0 y0 x1 y1
  std::vector<std::tuple<int, int, std::string>> labels;
  for (const Polyline& line : scene.lines) {
    if (line.label.empty()) continue;
    double best = kInf;
    std::array<double, 3> at{};
    for (const Point3& point : line.points) {
      const auto p = project(point);
      if (!canvas.Visible(p[0], p[1], p[2], kSurfaceBias)) continue;
      const double d = std::hypot(p[0] - mesh_width / 2.0, p[1] - height / 2.0);
      if (d < best) {
        best = d;
        at = p;
      }
    }
    if (!std::isfinite(best)) continue;
    const int w = TextWidth(line.label, 1);
    const int x = std::clamp(static_cast<int>(at[0]) - w / 2, 2, std::max(2, mesh_width - w - 2));
    const int y = std::clamp(static_cast<int>(at[1]) - 3, 2, std::max(2, height - 10));
    const std::array<int, 4> box = {x - 2, y - 1, x + w + 2, y + 8};
    bool overlaps = false;
    for (const auto& b : placed)
      overlaps |= box[0] < b[2] && b[0] < box[2] && box[1] < b[3] && b[1] < box[3];
    if (overlaps) continue;
    placed.push_back(box);
    labels.push_back({x, y, line.label});
  }
  Image image = canvas.Take();
  for (const auto& [x, y, text] : labels) {
    TextBackground(&image, x, y, text, 1);
    Text(&image, x, y, text, 1);
  }
  if (bar) DrawColorBar(&image, scene.max_distance, scene.units, scene.caption);
  if (scene.scale_bar) DrawScaleBar(&image, project, mesh_width);
  return image;
}

absl::Status WritePng(const std::string& path, const Image& image) {
  absl::Status opened;
  std::FILE* file = cli::OpenOutputFile(path, &opened);
  if (file == nullptr) return opened;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(file);
    return absl::InternalError(absl::StrCat("libpng failed writing ", path));
  }
  png_init_io(png, file);
  png_set_IHDR(png, info, image.width, image.height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_filter(png, 0, PNG_FILTER_NONE);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y) {
    png_write_row(png, const_cast<png_bytep>(image.rgb.data() + size_t(y) * image.width * 3));
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return cli::CloseOutputFile(path, file);
}

absl::Status WriteColoredPly(const std::string& path, const MeshData& mesh,
                             const std::vector<Rgb>& colors, const std::vector<double>& distances) {
  VertexAttributes attributes;
  attributes.scalar = distances;
  for (const Rgb& c : colors) attributes.colors.insert(attributes.colors.end(), c.begin(), c.end());
  return WriteMeshPly(path, mesh, attributes);
}

absl::Status WriteGltf(const std::string& path, const MeshData& mesh,
                       const std::vector<Rgb>& colors) {
  // Buffer: float32 positions, normalized uint8 RGBA colours, uint32 indices (4-byte aligned).
  std::string buffer;
  auto put = [&](const void* p, size_t n) { buffer.append(static_cast<const char*>(p), n); };
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    for (int k = 0; k < 3; ++k) {
      const float x = static_cast<float>(mesh.positions[3 * v + k]);
      lo[k] = std::min(lo[k], x), hi[k] = std::max(hi[k], x);
      put(&x, 4);
    }
  }
  const size_t colors_offset = buffer.size();
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    const uint8_t rgba[4] = {colors[v][0], colors[v][1], colors[v][2], 255};
    put(rgba, 4);
  }
  const size_t indices_offset = buffer.size();
  put(mesh.faces.data(), mesh.faces.size() * 4);
  if (mesh.vertex_count() == 0) {
    for (int k = 0; k < 3; ++k) lo[k] = hi[k] = 0;
  }
  const std::string json = absl::StrFormat(
      R"({"asset": {"version": "2.0", "generator": "geodex render"},
"scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
"meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}, "indices": 2}]}],
"buffers": [{"byteLength": %d, "uri": "data:application/octet-stream;base64,%s"}],
"bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": %d, "target": 34962},
                {"buffer": 0, "byteOffset": %d, "byteLength": %d, "target": 34962},
                {"buffer": 0, "byteOffset": %d, "byteLength": %d, "target": 34963}],
"accessors": [{"bufferView": 0, "componentType": 5126, "count": %d, "type": "VEC3", "min": [%.9g, %.9g, %.9g], "max": [%.9g, %.9g, %.9g]},
              {"bufferView": 1, "componentType": 5121, "normalized": true, "count": %d, "type": "VEC4"},
              {"bufferView": 2, "componentType": 5125, "count": %d, "type": "SCALAR"}]}
)",
      buffer.size(), absl::Base64Escape(buffer), colors_offset, colors_offset,
      indices_offset - colors_offset, indices_offset, buffer.size() - indices_offset,
      mesh.vertex_count(), lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], mesh.vertex_count(),
      mesh.faces.size());
  return cli::WriteOutputFile(path, json);
}

}  // namespace geodex::render
