#pragma once

// A DEM as an adaptive TIN (triangulated irregular network): a Delaunay triangulation of a few of
// the raster's cells, chosen so that the surface it spans is within a vertical tolerance Z of every
// cell's height. A grid mesh spends two triangles on every cell; on smooth terrain the TIN needs a
// small fraction of them for the same accuracy, and the geodesic engine's cost follows the
// number of faces.
//
// The method is Garland and Heckbert's greedy insertion ("Fast Polygonal Approximation of Terrains
// and Height Fields", 1995, algorithm III): start from the rectangle's 4 corner cells, then
// repeatedly insert the cell farthest (vertically) from the current surface, until none is farther
// than Z. Each triangle knows its worst cell (the largest |height - the triangle's plane| among the
// cells whose centres lie in it, ties going to the first cell in row-major order); a max-heap holds
// the triangles by that error, stale entries skipped by a per-triangle version number. An insertion
// changes a few triangles (the split and Lawson's flips, terrain/src/delaunay_2d.h); only their
// cells are rescanned, row by row over exactly the cell centres each closed triangle contains
// (integer arithmetic: vertices are cell centres). The result depends only on the input.
//
// Cost: O((m + n) log m) expected for m cells and n vertices in practice (each cell is rescanned
// about log n times as the triangles around it shrink). Memory: no state per cell while inserting
// (heights and the valid mask are the caller's, read in place), 1 bit per cell for the final
// measurement. Per vertex: 32 bytes (its point, height and cell) and ~58 for its ~2 triangles
// (corners and neighbours 24, version and heap flag 5, each); the heap's 24-byte entries, fewer
// than 4 per vertex even before stale ones are swept out (~1 per vertex measured on 1000 x 1000
// rasters); the result's 56 (vertex, cell, ~2 faces). About 170 MB for a 1000 x 1000 raster
// every cell of which becomes a vertex (the process's peak, heights included); a few MB when Z
// keeps 1% of them.
//
// Nodata: cells with valid[i] == 0 do not matter. They never drive an insertion and are not
// measured; only the rectangle's 4 corners may be such cells (every TIN starts from them), and a
// corner without data takes the height of the nearest cell with data (Euclidean distance in
// cells, ties to the first in row-major order; 0 when no cell has data). Holes are for the caller
// to cut out afterwards (they are wherever the valid mask says, not in the TIN).

#include <array>
#include <atomic>
#include <cstdint>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/cancel.h"

namespace geodex::terrain {

struct AdaptiveTinOptions {
  // Z: the largest vertical distance (the heights' unit) allowed between a cell's height and the
  // TIN's surface above or below its centre. Finite and > 0.
  double z_tolerance = 0;
  // The most vertices the TIN may have: a LimitExceededError (geodex/limits.h kVertices) when Z
  // needs more. 0: no bound (at most every cell becomes a vertex).
  uint64_t max_vertices = 0;
  // Polled every few million cells scanned; once cancelled the build returns Cancelled (the
  // solves' CancelToken: geodexd cancels an upload's TIN build with its call).
  const CancelToken* cancel = nullptr;
};

struct AdaptiveTin {
  // x = column, y = row (cell units: cell centres at integer coordinates, (0, 0) the first cell
  // of the first row), z = the cell's height (a corner without data: see above). The first 4 are
  // the corners (0, 0), (cols - 1, 0), (cols - 1, rows - 1), (0, rows - 1).
  std::vector<std::array<double, 3>> vertices;
  // Counter-clockwise seen from +z with x and y as above (with rows running south, as in a north-up
  // raster, that is clockwise on the map: the caller flips when it maps y to northing).
  std::vector<std::array<uint32_t, 3>> faces;
  // (row, col) of each vertex's cell.
  std::vector<std::pair<uint32_t, uint32_t>> source_cell;
  // Over every valid cell: the largest and the root-mean-square |height - TIN|.
  double max_vertical_deviation = 0;
  double rms_vertical_deviation = 0;
};

// `heights`: rows x cols values, row by row. `valid`: the same shape, non-zero where a cell has
// data; null: every cell has. Errors: InvalidArgument naming `z_tolerance` (not finite or <= 0),
// `rows`/`cols` (fewer than 2, or more cells than memory can hold), `heights` (null, or not
// finite at a valid cell, which it names); LimitExceededError (kVertices) past max_vertices;
// Cancelled.
absl::StatusOr<AdaptiveTin> BuildAdaptiveTin(const double* heights, uint32_t rows, uint32_t cols,
                                             const uint8_t* valid,
                                             const AdaptiveTinOptions& options);

}  // namespace geodex::terrain
