// The adaptive TIN (geodex/adaptive_tin.h), checked independently of its own scans: each face's
// cells are found by brute force (its bounding box, an exact integer inside test) and interpolated
// by barycentric weights, so every valid cell's distance to the TIN is recomputed here.

#include "geodex/adaptive_tin.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "geodex/limits.h"
#include "gtest/gtest.h"

namespace geodex::terrain {
namespace {

struct Raster {
  uint32_t rows = 0, cols = 0;
  std::vector<double> heights;
  std::vector<uint8_t> valid;  // empty: all valid

  double& at(uint32_t r, uint32_t c) { return heights[size_t{r} * cols + c]; }
  const uint8_t* mask() const { return valid.empty() ? nullptr : valid.data(); }
  bool Valid(size_t cell) const { return valid.empty() || valid[cell] != 0; }
};

// A few Gaussian hills and hollows (heights in [-60, 60] or so, widths 10 to 60 cells).
Raster GaussianHills(uint32_t rows, uint32_t cols, uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> x(0, cols), y(0, rows), amplitude(-40, 40), sigma(10, 60);
  struct Hill {
    double x, y, a, s;
  };
  std::vector<Hill> hills;
  for (int i = 0; i < 6; ++i)
    hills.push_back({x(random), y(random), amplitude(random), sigma(random)});
  Raster raster{rows, cols, std::vector<double>(size_t{rows} * cols), {}};
  for (uint32_t r = 0; r < rows; ++r) {
    for (uint32_t c = 0; c < cols; ++c) {
      double z = 0;
      for (const Hill& h : hills) {
        z += h.a * std::exp(-((c - h.x) * (c - h.x) + (r - h.y) * (r - h.y)) / (2 * h.s * h.s));
      }
      raster.at(r, c) = z;
    }
  }
  return raster;
}

absl::StatusOr<AdaptiveTin> Build(const Raster& raster, double z, uint64_t max_vertices = 0) {
  AdaptiveTinOptions options;
  options.z_tolerance = z;
  options.max_vertices = max_vertices;
  return BuildAdaptiveTin(raster.heights.data(), raster.rows, raster.cols, raster.mask(), options);
}

// Twice the signed area of face f in x-y, exactly (vertices are integer points).
int64_t DoubleArea(const AdaptiveTin& tin, const std::array<uint32_t, 3>& f) {
  const auto &a = tin.vertices[f[0]], &b = tin.vertices[f[1]], &c = tin.vertices[f[2]];
  return int64_t(b[0] - a[0]) * int64_t(c[1] - a[1]) - int64_t(b[1] - a[1]) * int64_t(c[0] - a[0]);
}

struct Measured {
  double max_error = 0, rms = 0;
  size_t uncovered = 0;  // valid cells in no face
};

// Every valid cell's |height - TIN|, from the faces that contain it (the largest if several do:
// they agree up to rounding), by brute force.
Measured MeasureIndependently(const Raster& raster, const AdaptiveTin& tin) {
  const size_t cells = raster.heights.size();
  std::vector<double> error(cells, -1);
  for (const auto& f : tin.faces) {
    const auto &a = tin.vertices[f[0]], &b = tin.vertices[f[1]], &c = tin.vertices[f[2]];
    const int64_t area = DoubleArea(tin, f);
    const int64_t x0 = int64_t(std::min({a[0], b[0], c[0]})),
                  x1 = int64_t(std::max({a[0], b[0], c[0]}));
    const int64_t y0 = int64_t(std::min({a[1], b[1], c[1]})),
                  y1 = int64_t(std::max({a[1], b[1], c[1]}));
    for (int64_t y = y0; y <= y1; ++y) {
      for (int64_t x = x0; x <= x1; ++x) {
        // Barycentric weights times 2 area, exact in integers; all >= 0 inside or on the face.
        auto edge = [&](const std::array<double, 3>& p, const std::array<double, 3>& q) {
          return int64_t(q[0] - p[0]) * (y - int64_t(p[1])) -
                 int64_t(q[1] - p[1]) * (x - int64_t(p[0]));
        };
        const int64_t wa = edge(b, c), wb = edge(c, a), wc = edge(a, b);
        if (wa < 0 || wb < 0 || wc < 0) continue;
        const double z = (double(wa) * a[2] + double(wb) * b[2] + double(wc) * c[2]) / double(area);
        const size_t cell = size_t(y) * raster.cols + size_t(x);
        if (!raster.Valid(cell)) continue;
        error[cell] = std::max(error[cell], std::abs(raster.heights[cell] - z));
      }
    }
  }
  Measured m;
  double sum = 0;
  size_t count = 0;
  for (size_t cell = 0; cell < cells; ++cell) {
    if (!raster.Valid(cell)) continue;
    if (error[cell] < 0) {
      ++m.uncovered;
      continue;
    }
    m.max_error = std::max(m.max_error, error[cell]);
    sum += error[cell] * error[cell];
    ++count;
  }
  m.rms = count == 0 ? 0 : std::sqrt(sum / double(count));
  return m;
}

// The structure every TIN must have: integer vertices at their cells with their heights (but
// corners without data), counter-clockwise faces covering the rectangle, Euler's count.
void CheckTin(const Raster& raster, const AdaptiveTin& tin) {
  const size_t n = tin.vertices.size();
  ASSERT_EQ(tin.source_cell.size(), n);
  ASSERT_GE(n, 4u);
  size_t hull = 0;
  for (size_t v = 0; v < n; ++v) {
    const auto& [row, col] = tin.source_cell[v];
    ASSERT_EQ(tin.vertices[v][0], double(col));
    ASSERT_EQ(tin.vertices[v][1], double(row));
    const size_t cell = size_t{row} * raster.cols + col;
    if (v >= 4 || raster.Valid(cell)) {
      ASSERT_EQ(tin.vertices[v][2], raster.heights[cell]) << "vertex " << v;
    }
    if (v >= 4) {
      ASSERT_TRUE(raster.Valid(cell)) << "vertex " << v << " at a cell without data";
    }
    hull += row == 0 || col == 0 || row == raster.rows - 1 || col == raster.cols - 1;
  }
  EXPECT_EQ(tin.faces.size(), 2 * n - 2 - hull);
  int64_t area = 0;
  for (const auto& f : tin.faces) {
    for (uint32_t v : f) ASSERT_LT(v, n);
    const int64_t a = DoubleArea(tin, f);
    ASSERT_GT(a, 0) << "a face is not counter-clockwise";
    area += a;
  }
  EXPECT_EQ(area, 2 * int64_t(raster.rows - 1) * int64_t(raster.cols - 1));
}

TEST(AdaptiveTinTest, APlaneIsTwoTriangles) {
  Raster raster{37, 53, std::vector<double>(37 * 53), {}};
  // Dyadic slopes: every height and every interpolation is exact, so no Z is too small.
  for (uint32_t r = 0; r < raster.rows; ++r) {
    for (uint32_t c = 0; c < raster.cols; ++c) raster.at(r, c) = 0.5 * c - 0.25 * r + 3;
  }
  for (const double z : {1e-300, 1e-9, 1.0, 1e6}) {
    const auto tin = Build(raster, z);
    ASSERT_TRUE(tin.ok()) << tin.status();
    EXPECT_EQ(tin->vertices.size(), 4u);
    EXPECT_EQ(tin->faces.size(), 2u);
    EXPECT_EQ(tin->max_vertical_deviation, 0.0);
    EXPECT_EQ(tin->rms_vertical_deviation, 0.0);
    CheckTin(raster, *tin);
  }
  // Any plane, within rounding.
  for (uint32_t r = 0; r < raster.rows; ++r) {
    for (uint32_t c = 0; c < raster.cols; ++c) raster.at(r, c) = 0.3 * c - 0.7 * r + 12.1;
  }
  const auto tin = Build(raster, 1e-9);
  ASSERT_TRUE(tin.ok()) << tin.status();
  EXPECT_EQ(tin->vertices.size(), 4u);
  EXPECT_EQ(tin->faces.size(), 2u);
  EXPECT_LT(tin->max_vertical_deviation, 1e-12);
}

TEST(AdaptiveTinTest, GaussianHillsWithinZ) {
  const Raster raster = GaussianHills(200, 300, 1);
  const double z = 0.5;
  const auto tin = Build(raster, z);
  ASSERT_TRUE(tin.ok()) << tin.status();
  CheckTin(raster, *tin);
  const Measured m = MeasureIndependently(raster, *tin);
  EXPECT_EQ(m.uncovered, 0u);
  EXPECT_LE(m.max_error, z);
  EXPECT_NEAR(tin->max_vertical_deviation, m.max_error, 1e-9);
  EXPECT_NEAR(tin->rms_vertical_deviation, m.rms, 1e-9);
  EXPECT_GT(tin->rms_vertical_deviation, 0);
  EXPECT_LT(tin->vertices.size(), raster.heights.size() / 50) << "not adaptive";
  // Z is tight: one vertex less (the last one inserted) would not do.
  EXPECT_GT(tin->max_vertical_deviation, z / 4);
}

TEST(AdaptiveTinTest, Deterministic) {
  const Raster raster = GaussianHills(120, 90, 2);
  const auto a = Build(raster, 0.2), b = Build(raster, 0.2);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->vertices, b->vertices);
  EXPECT_EQ(a->faces, b->faces);
  EXPECT_EQ(a->source_cell, b->source_cell);
  EXPECT_EQ(a->max_vertical_deviation, b->max_vertical_deviation);
  EXPECT_EQ(a->rms_vertical_deviation, b->rms_vertical_deviation);
}

// Greedy insertion takes the cells in the same order whatever Z is (Z only says when to stop), so
// a smaller Z's vertices start with a larger Z's.
TEST(AdaptiveTinTest, SmallerZNeverFewerVertices) {
  const Raster raster = GaussianHills(150, 170, 3);
  std::vector<std::array<double, 3>> previous;
  for (const double z : {8.0, 4.0, 2.0, 1.0, 0.5, 0.25, 0.1, 0.05}) {
    const auto tin = Build(raster, z);
    ASSERT_TRUE(tin.ok()) << tin.status();
    ASSERT_GE(tin->vertices.size(), previous.size()) << "z " << z;
    EXPECT_TRUE(std::equal(previous.begin(), previous.end(), tin->vertices.begin())) << "z " << z;
    EXPECT_LE(MeasureIndependently(raster, *tin).max_error, z);
    previous = tin->vertices;
  }
}

// Noise at a tiny Z: every cell becomes a vertex, and the TIN is a Delaunay triangulation of the
// whole grid (every cell's 4 centres cocircular).
TEST(AdaptiveTinTest, NoiseTakesEveryCell) {
  Raster raster{23, 31, std::vector<double>(23 * 31), {}};
  std::mt19937_64 random(4);
  std::uniform_real_distribution<double> noise(0, 1);
  for (double& h : raster.heights) h = noise(random);
  const auto tin = Build(raster, 1e-12);
  ASSERT_TRUE(tin.ok()) << tin.status();
  EXPECT_EQ(tin->vertices.size(), raster.heights.size());
  CheckTin(raster, *tin);
  for (const auto& f : tin->faces) EXPECT_EQ(DoubleArea(*tin, f), 1);  // half a cell each
  EXPECT_EQ(tin->max_vertical_deviation, 0.0);
  EXPECT_EQ(MeasureIndependently(raster, *tin).max_error, 0.0);
}

TEST(AdaptiveTinTest, InvalidCellsDoNotMatter) {
  Raster raster = GaussianHills(90, 110, 5);
  raster.valid.assign(raster.heights.size(), 1);
  // A hole with spikes, and a corner without data.
  for (uint32_t r = 30; r < 50; ++r) {
    for (uint32_t c = 40; c < 75; ++c) {
      raster.valid[size_t{r} * raster.cols + c] = 0;
      raster.at(r, c) = (r + c) % 2 == 0 ? 1e9 : -1e9;
    }
  }
  raster.valid[0] = 0;
  raster.heights[0] = std::numeric_limits<double>::quiet_NaN();
  const auto tin = Build(raster, 0.3);
  ASSERT_TRUE(tin.ok()) << tin.status();
  CheckTin(raster, *tin);
  EXPECT_EQ(tin->vertices[0][2], raster.heights[1]) << "the corner takes its nearest cell's height";
  const Measured m = MeasureIndependently(raster, *tin);
  EXPECT_EQ(m.uncovered, 0u);
  EXPECT_LE(m.max_error, 0.3);
  EXPECT_NEAR(tin->max_vertical_deviation, m.max_error, 1e-9);
  EXPECT_NEAR(tin->rms_vertical_deviation, m.rms, 1e-9);

  // Other garbage in the hole (NaN, infinities): the same TIN.
  for (uint32_t r = 30; r < 50; ++r) {
    for (uint32_t c = 40; c < 75; ++c) {
      raster.at(r, c) = (r + c) % 3 == 0 ? std::numeric_limits<double>::quiet_NaN()
                                         : std::numeric_limits<double>::infinity();
    }
  }
  const auto again = Build(raster, 0.3);
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(again->vertices, tin->vertices);
  EXPECT_EQ(again->faces, tin->faces);
}

TEST(AdaptiveTinTest, CornersWithoutData) {
  // Corner (0, 0) invalid: its nearest cells with data are (0, 2) and (2, 0) at distance 2 (row
  // order takes (0, 2)); the whole raster invalid: every corner 0.
  Raster raster{5, 6, std::vector<double>(30, 1.0), std::vector<uint8_t>(30, 1)};
  for (const auto& [r, c] : {std::pair{0, 0}, std::pair{0, 1}, std::pair{1, 0}, std::pair{1, 1}})
    raster.valid[r * 6 + c] = 0;
  raster.at(0, 2) = 7;
  raster.at(2, 0) = 9;
  auto tin = Build(raster, 0.5);
  ASSERT_TRUE(tin.ok()) << tin.status();
  EXPECT_EQ(tin->vertices[0][2], 7.0);
  CheckTin(raster, *tin);
  EXPECT_LE(MeasureIndependently(raster, *tin).max_error, 0.5);

  std::fill(raster.valid.begin(), raster.valid.end(), 0);
  tin = Build(raster, 0.5);
  ASSERT_TRUE(tin.ok()) << tin.status();
  EXPECT_EQ(tin->vertices.size(), 4u);
  for (const auto& v : tin->vertices) EXPECT_EQ(v[2], 0.0);
  EXPECT_EQ(tin->max_vertical_deviation, 0.0);
  EXPECT_EQ(tin->rms_vertical_deviation, 0.0);
}

TEST(AdaptiveTinTest, RefusesBadInput) {
  const Raster raster = GaussianHills(10, 12, 6);
  for (const double z : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(),
                         std::numeric_limits<double>::infinity()}) {
    const auto tin = Build(raster, z);
    ASSERT_FALSE(tin.ok()) << z;
    EXPECT_EQ(tin.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(tin.status().message().find("z_tolerance"), std::string::npos) << tin.status();
  }
  AdaptiveTinOptions options;
  options.z_tolerance = 1;
  auto tin = BuildAdaptiveTin(raster.heights.data(), 1, 120, nullptr, options);
  EXPECT_EQ(tin.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(tin.status().message().find("rows"), std::string::npos) << tin.status();
  tin = BuildAdaptiveTin(nullptr, 10, 12, nullptr, options);
  EXPECT_EQ(tin.status().code(), absl::StatusCode::kInvalidArgument);

  Raster with_nan = raster;
  with_nan.at(3, 4) = std::numeric_limits<double>::quiet_NaN();
  tin = Build(with_nan, 1);
  EXPECT_EQ(tin.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(tin.status().message().find("row 3, col 4"), std::string::npos) << tin.status();
}

TEST(AdaptiveTinTest, MaxVertices) {
  const Raster raster = GaussianHills(80, 70, 7);
  const auto full = Build(raster, 0.5);
  ASSERT_TRUE(full.ok());
  const uint64_t n = full->vertices.size();
  ASSERT_GT(n, 10u);
  EXPECT_TRUE(Build(raster, 0.5, n).ok());
  for (const uint64_t bound : {n - 1, uint64_t{5}, uint64_t{3}}) {
    const auto tin = Build(raster, 0.5, bound);
    ASSERT_FALSE(tin.ok()) << bound;
    EXPECT_EQ(tin.status().code(), absl::StatusCode::kResourceExhausted);
    EXPECT_EQ(ExceededLimit(tin.status()), Limit::kVertices);
  }
}

TEST(AdaptiveTinTest, Cancelled) {
  const Raster raster = GaussianHills(50, 60, 8);
  CancelToken cancel;
  cancel.Cancel();
  AdaptiveTinOptions options;
  options.z_tolerance = 0.1;
  options.cancel = &cancel;
  const auto tin =
      BuildAdaptiveTin(raster.heights.data(), raster.rows, raster.cols, nullptr, options);
  EXPECT_EQ(tin.status().code(), absl::StatusCode::kCancelled);
  CancelToken fresh;
  options.cancel = &fresh;
  EXPECT_TRUE(
      BuildAdaptiveTin(raster.heights.data(), raster.rows, raster.cols, nullptr, options).ok());
}

// A cancel that lands during the insertions (noise at a tiny Z: every one of 250,000 cells
// becomes a vertex, about a second's work) stops the build.
TEST(AdaptiveTinTest, CancelledWhileInserting) {
  Raster raster{500, 500, std::vector<double>(500 * 500), {}};
  std::mt19937_64 random(9);
  std::uniform_real_distribution<double> noise(0, 1);
  for (double& h : raster.heights) h = noise(random);
  CancelToken cancel;
  AdaptiveTinOptions options;
  options.z_tolerance = 1e-12;
  options.cancel = &cancel;
  std::thread canceller([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    cancel.Cancel();
  });
  const auto start = std::chrono::steady_clock::now();
  const auto tin =
      BuildAdaptiveTin(raster.heights.data(), raster.rows, raster.cols, nullptr, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  canceller.join();
  EXPECT_EQ(tin.status().code(), absl::StatusCode::kCancelled) << seconds << " s";
}

}  // namespace
}  // namespace geodex::terrain
