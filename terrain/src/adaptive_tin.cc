#include "geodex/adaptive_tin.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "delaunay_2d.h"
#include "geodex/limits.h"

namespace geodex::terrain {
namespace {

constexpr uint64_t kNoCell = std::numeric_limits<uint64_t>::max();
// Cells scanned between two looks at the cancel token (a few milliseconds of work).
constexpr uint64_t kPollEvery = uint64_t{1} << 22;
// Triangle ids are 32-bit: 2n - 2 - h triangles for n vertices must stay below 2^32.
constexpr uint32_t kMostVertices = (uint32_t{1} << 31) - 1;

// Integer division rounding down / up (den > 0).
int64_t FloorDiv(int64_t num, int64_t den) {
  const int64_t q = num / den;
  return (num % den != 0 && num < 0) ? q - 1 : q;
}
int64_t CeilDiv(int64_t num, int64_t den) {
  const int64_t q = num / den;
  return (num % den != 0 && num > 0) ? q + 1 : q;
}

using Corner = std::array<int64_t, 2>;  // x = column, y = row

// Calls visit(row, first_column, last_column) for each row the closed triangle meets, in
// increasing row order, with the columns of the integer points (cell centres) in it on that row.
// Exact: where the row crosses an edge is a rational number, rounded inwards by integer division,
// so a cell on an edge belongs to both triangles and no cell outside belongs to any. The caller
// clips nothing: every corner is a cell of the raster.
template <typename Visit>
void ForEachRowSpan(const Corner (&p)[3], Visit&& visit) {
  const int64_t y_min = std::min({p[0][1], p[1][1], p[2][1]});
  const int64_t y_max = std::max({p[0][1], p[1][1], p[2][1]});
  for (int64_t y = y_min; y <= y_max; ++y) {
    int64_t first = std::numeric_limits<int64_t>::max(), last = std::numeric_limits<int64_t>::min();
    for (int e = 0; e < 3; ++e) {
      const Corner &s = p[e], &t = p[e == 2 ? 0 : e + 1];
      if (y < std::min(s[1], t[1]) || y > std::max(s[1], t[1])) continue;
      if (s[1] == t[1]) {  // a horizontal edge on this row
        first = std::min({first, s[0], t[0]});
        last = std::max({last, s[0], t[0]});
        continue;
      }
      // x = s.x + (y - s.y) (t.x - s.x) / (t.y - s.y); |numerator| <= rows x cols: no overflow.
      int64_t num = (y - s[1]) * (t[0] - s[0]), den = t[1] - s[1];
      if (den < 0) num = -num, den = -den;
      first = std::min(first, s[0] + CeilDiv(num, den));
      last = std::max(last, s[0] + FloorDiv(num, den));
    }
    if (first <= last) visit(y, first, last);
  }
}

// A triangle's plane through its corners' heights: z(x, y) = z0 + gx (x - x0) + gy (y - y0),
// relative to corner 0 so that the interpolation is accurate near it and exact at it.
struct Plane {
  double x0, y0, z0, gx, gy;

  Plane(const std::array<double, 3>& a, const std::array<double, 3>& b,
        const std::array<double, 3>& c) {
    const double bx = b[0] - a[0], by = b[1] - a[1], bz = b[2] - a[2];
    const double cx = c[0] - a[0], cy = c[1] - a[1], cz = c[2] - a[2];
    const double det = bx * cy - cx * by;  // > 0: a proper counter-clockwise triangle
    x0 = a[0], y0 = a[1], z0 = a[2];
    gx = (bz * cy - cz * by) / det;
    gy = (bx * cz - cx * bz) / det;
  }
};

// A triangle's worst cell, and what the heap holds of it.
struct Candidate {
  double error = -1;
  uint64_t cell = kNoCell;
};
struct HeapEntry {
  double error;
  uint64_t cell;
  uint32_t triangle;
  uint32_t version;
};
// Heap order: the largest error on top; among equal errors the first cell in row-major order,
// then the lowest triangle id (a cell on a shared edge can be two triangles' worst).
// (A function object rather than a function, so that the heap operations inline it.)
struct Below {
  bool operator()(const HeapEntry& a, const HeapEntry& b) const {
    if (a.error != b.error) return a.error < b.error;
    if (a.cell != b.cell) return a.cell > b.cell;
    return a.triangle > b.triangle;
  }
};

class TinBuilder {
 public:
  TinBuilder(const double* heights, uint32_t rows, uint32_t cols, const uint8_t* valid,
             const AdaptiveTinOptions& options)
      : heights_(heights),
        rows_(rows),
        cols_(cols),
        valid_(valid),
        options_(options),
        dt_(0, 0, cols - 1.0, rows - 1.0) {}

  absl::StatusOr<AdaptiveTin> Build();

 private:
  bool Valid(uint64_t cell) const { return valid_ == nullptr || valid_[cell] != 0; }
  // Counts `work` cells towards the next look at the cancel token; true when cancelled.
  bool Cancelled(uint64_t work) {
    work_ += work;
    if (work_ < next_poll_) return false;
    next_poll_ = work_ + kPollEvery;
    return options_.cancel != nullptr && options_.cancel->IsCancelled();
  }
  double CornerHeight(uint32_t row, uint32_t col) const;
  void AddVertex(uint64_t cell, double height);
  void Corners(uint32_t t, Corner (&p)[3]) const;
  Candidate Scan(uint32_t t);
  void Rescan(uint32_t t);
  absl::Status Measure(AdaptiveTin& tin);

  const double* heights_;
  const uint32_t rows_, cols_;
  const uint8_t* valid_;
  const AdaptiveTinOptions& options_;

  Delaunay2d dt_;
  std::vector<double> vertex_height_;  // per vertex (a corner without data: its stand-in)
  std::vector<uint64_t> vertex_cell_;  // per vertex: row * cols + col
  std::vector<uint32_t> version_;      // per triangle: bumped when it changes
  std::vector<uint8_t> queued_;        // per triangle: its current version is in the heap
  std::vector<HeapEntry> heap_;        // std::push_heap order by Below
  uint64_t live_ = 0;                  // heap entries of current versions
  uint64_t work_ = 0, next_poll_ = 0;
};

// The height of the nearest cell with data to (row, col), searched in square rings of growing
// radius until no closer cell can remain; 0 when no cell has data.
double TinBuilder::CornerHeight(uint32_t row, uint32_t col) const {
  const uint64_t cell = uint64_t{row} * cols_ + col;
  if (Valid(cell)) return heights_[cell];
  uint64_t best = kNoCell, best_d2 = std::numeric_limits<uint64_t>::max();
  const int64_t r0 = row, c0 = col;
  auto consider = [&](int64_t r, int64_t c) {
    if (r < 0 || r >= rows_ || c < 0 || c >= cols_) return;
    const uint64_t candidate = uint64_t(r) * cols_ + uint64_t(c);
    if (!Valid(candidate)) return;
    const uint64_t d2 = uint64_t((r - r0) * (r - r0) + (c - c0) * (c - c0));
    if (d2 < best_d2 || (d2 == best_d2 && candidate < best)) best = candidate, best_d2 = d2;
  };
  // Ring `radius`: the cells at Chebyshev distance radius, so at Euclidean distance >= radius.
  for (int64_t radius = 1; radius < std::max<int64_t>(rows_, cols_); ++radius) {
    if (best != kNoCell && uint64_t(radius * radius) > best_d2) break;
    for (int64_t c = c0 - radius; c <= c0 + radius; ++c) {
      consider(r0 - radius, c);
      consider(r0 + radius, c);
    }
    for (int64_t r = r0 - radius + 1; r < r0 + radius; ++r) {
      consider(r, c0 - radius);
      consider(r, c0 + radius);
    }
  }
  return best == kNoCell ? 0.0 : heights_[best];
}

void TinBuilder::AddVertex(uint64_t cell, double height) {
  vertex_cell_.push_back(cell);
  vertex_height_.push_back(height);
}

void TinBuilder::Corners(uint32_t t, Corner (&p)[3]) const {
  for (int k = 0; k < 3; ++k) {
    const uint64_t cell = vertex_cell_[dt_.corners(t)[k]];
    p[k] = {int64_t(cell % cols_), int64_t(cell / cols_)};
  }
}

Candidate TinBuilder::Scan(uint32_t t) {
  const auto& v = dt_.corners(t);
  std::array<double, 3> corner[3];
  for (int k = 0; k < 3; ++k) {
    const auto& p = dt_.point(v[k]);
    corner[k] = {p[0], p[1], vertex_height_[v[k]]};
  }
  const Plane plane(corner[0], corner[1], corner[2]);
  const uint64_t skip[3] = {vertex_cell_[v[0]], vertex_cell_[v[1]], vertex_cell_[v[2]]};
  Corner p[3];
  Corners(t, p);
  Candidate worst;
  uint64_t scanned = 0;
  ForEachRowSpan(p, [&](int64_t y, int64_t first, int64_t last) {
    const uint64_t row_start = uint64_t(y) * cols_;
    const double row_base = plane.z0 + plane.gy * (double(y) - plane.y0);
    scanned += uint64_t(last - first + 1);
    for (int64_t x = first; x <= last; ++x) {
      const uint64_t cell = row_start + uint64_t(x);
      if (!Valid(cell)) continue;
      const double error =
          std::abs(heights_[cell] - (row_base + plane.gx * (double(x) - plane.x0)));
      // Strictly larger: ties keep the first cell in row-major order. A corner is exact by
      // construction (its own height), and must never be chosen again.
      if (error > worst.error && cell != skip[0] && cell != skip[1] && cell != skip[2]) {
        worst = {error, cell};
      }
    }
  });
  work_ += scanned;
  return worst;
}

// Triangle t changed (or is new): its old heap entry goes stale and its new worst cell is queued
// when it is above Z.
void TinBuilder::Rescan(uint32_t t) {
  if (t >= version_.size()) {
    version_.resize(t + 1, 0);
    queued_.resize(t + 1, 0);
  }
  ++version_[t];
  if (queued_[t]) {
    queued_[t] = 0;
    --live_;
  }
  const Candidate worst = Scan(t);
  if (worst.error > options_.z_tolerance) {
    heap_.push_back({worst.error, worst.cell, t, version_[t]});
    std::push_heap(heap_.begin(), heap_.end(), Below{});
    queued_[t] = 1;
    ++live_;
  }
  // Stale entries are dropped as they surface; when they outnumber the live ones, all at once.
  if (heap_.size() > 2 * live_ + 1024) {
    std::erase_if(heap_, [&](const HeapEntry& e) { return e.version != version_[e.triangle]; });
    std::make_heap(heap_.begin(), heap_.end(), Below{});
  }
}

absl::StatusOr<AdaptiveTin> TinBuilder::Build() {
  const uint32_t corner_rows[4] = {0, 0, rows_ - 1, rows_ - 1};
  const uint32_t corner_cols[4] = {0, cols_ - 1, cols_ - 1, 0};
  for (int k = 0; k < 4; ++k) {  // Delaunay2d's vertices 0 to 3, in its order
    AddVertex(uint64_t{corner_rows[k]} * cols_ + corner_cols[k],
              CornerHeight(corner_rows[k], corner_cols[k]));
  }
  if (options_.max_vertices != 0 && options_.max_vertices < 4) {
    return LimitExceededError(Limit::kVertices,
                              absl::StrCat("an adaptive TIN has at least 4 vertices; max_vertices "
                                           "is ",
                                           options_.max_vertices));
  }
  for (uint32_t t = 0; t < dt_.triangle_count(); ++t) Rescan(t);

  std::vector<uint32_t> changed;
  while (!heap_.empty()) {
    if (Cancelled(1)) return absl::CancelledError("adaptive TIN: cancelled");
    std::pop_heap(heap_.begin(), heap_.end(), Below{});
    const HeapEntry top = heap_.back();
    heap_.pop_back();
    if (top.version != version_[top.triangle]) continue;  // stale
    queued_[top.triangle] = 0;
    --live_;

    const uint32_t n = dt_.vertex_count();
    if (options_.max_vertices != 0 && n >= options_.max_vertices) {
      return LimitExceededError(
          Limit::kVertices,
          absl::StrCat("the adaptive TIN needs more than max_vertices = ", options_.max_vertices,
                       " vertices for z_tolerance ", options_.z_tolerance, " (a cell is still ",
                       top.error, " off)"));
    }
    if (n >= kMostVertices) {
      return LimitExceededError(Limit::kVertices,
                                absl::StrCat("the adaptive TIN needs more than ", kMostVertices,
                                             " vertices for z_tolerance ", options_.z_tolerance));
    }
    const uint64_t row = top.cell / cols_, col = top.cell % cols_;
    changed.clear();
    const uint32_t v = dt_.Insert({double(col), double(row)}, top.triangle, &changed);
    if (v != n) {
      // The scan never offers a vertex's own cell, and every cell lies in the rectangle.
      return absl::InternalError(
          absl::StrCat("adaptive TIN: cell (", row, ", ", col, ") could not be inserted"));
    }
    AddVertex(top.cell, heights_[top.cell]);
    std::sort(changed.begin(), changed.end());
    changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
    for (uint32_t t : changed) Rescan(t);
  }

  AdaptiveTin tin;
  const uint32_t n = dt_.vertex_count();
  tin.vertices.reserve(n);
  tin.source_cell.reserve(n);
  for (uint32_t v = 0; v < n; ++v) {
    const auto& p = dt_.point(v);
    tin.vertices.push_back({p[0], p[1], vertex_height_[v]});
    tin.source_cell.push_back(
        {uint32_t(vertex_cell_[v] / cols_), uint32_t(vertex_cell_[v] % cols_)});
  }
  tin.faces.reserve(dt_.triangle_count());
  for (uint32_t t = 0; t < dt_.triangle_count(); ++t) tin.faces.push_back(dt_.corners(t));
  if (absl::Status status = Measure(tin); !status.ok()) return status;
  return tin;
}

// Every valid cell once (the first triangle to reach it, in triangle order), against the TIN.
absl::Status TinBuilder::Measure(AdaptiveTin& tin) {
  std::vector<bool> measured(uint64_t{rows_} * cols_, false);
  double max_error = 0, sum_squares = 0;
  uint64_t count = 0;
  for (uint32_t t = 0; t < dt_.triangle_count(); ++t) {
    const auto& v = dt_.corners(t);
    const Plane plane(tin.vertices[v[0]], tin.vertices[v[1]], tin.vertices[v[2]]);
    Corner p[3];
    Corners(t, p);
    uint64_t scanned = 0;
    ForEachRowSpan(p, [&](int64_t y, int64_t first, int64_t last) {
      const uint64_t row_start = uint64_t(y) * cols_;
      const double row_base = plane.z0 + plane.gy * (double(y) - plane.y0);
      scanned += uint64_t(last - first + 1);
      for (int64_t x = first; x <= last; ++x) {
        const uint64_t cell = row_start + uint64_t(x);
        if (measured[cell] || !Valid(cell)) continue;
        measured[cell] = true;
        // At a vertex the surface is the vertex's height, not the plane's rounding of it.
        const double surface = cell == vertex_cell_[v[0]]   ? tin.vertices[v[0]][2]
                               : cell == vertex_cell_[v[1]] ? tin.vertices[v[1]][2]
                               : cell == vertex_cell_[v[2]]
                                   ? tin.vertices[v[2]][2]
                                   : row_base + plane.gx * (double(x) - plane.x0);
        const double error = std::abs(heights_[cell] - surface);
        max_error = std::max(max_error, error);
        sum_squares += error * error;
        ++count;
      }
    });
    if (Cancelled(scanned)) return absl::CancelledError("adaptive TIN: cancelled");
  }
  tin.max_vertical_deviation = max_error;
  tin.rms_vertical_deviation = count == 0 ? 0.0 : std::sqrt(sum_squares / double(count));
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<AdaptiveTin> BuildAdaptiveTin(const double* heights, uint32_t rows, uint32_t cols,
                                             const uint8_t* valid,
                                             const AdaptiveTinOptions& options) {
  if (!std::isfinite(options.z_tolerance) || options.z_tolerance <= 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "z_tolerance must be a finite number > 0 (the largest vertical error allowed), not ",
        options.z_tolerance));
  }
  if (rows < 2 || cols < 2) {
    return absl::InvalidArgumentError(absl::StrCat(
        "rows and cols must be at least 2 for an adaptive TIN, not ", rows, " x ", cols));
  }
  // Cells are counted in 64 bits, and the scans' integer arithmetic needs rows x cols < 2^62.
  if (uint64_t{rows} * cols >= (uint64_t{1} << 59)) {
    return absl::InvalidArgumentError(
        absl::StrCat("rows x cols is too large for an adaptive TIN: ", rows, " x ", cols));
  }
  if (heights == nullptr) return absl::InvalidArgumentError("heights is null");
  if (options.cancel != nullptr && options.cancel->IsCancelled()) {
    return absl::CancelledError("adaptive TIN: cancelled");
  }
  for (uint64_t cell = 0; cell < uint64_t{rows} * cols; ++cell) {
    if (!std::isfinite(heights[cell]) && (valid == nullptr || valid[cell] != 0)) {
      return absl::InvalidArgumentError(absl::StrCat("heights: cell (row ", cell / cols, ", col ",
                                                     cell % cols, ") is not finite (",
                                                     heights[cell], "); mark it invalid"));
    }
  }
  TinBuilder builder(heights, rows, cols, valid, options);
  return builder.Build();
}

}  // namespace geodex::terrain
