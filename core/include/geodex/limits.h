#pragma once

// Errors for crossing a limit the caller set (ReadLimits, GeodesicOptions::max_windows). The
// status is ResourceExhausted and carries which limit as a payload, so that a server can name its
// own flag for it without reading the message.

#include <cstdint>
#include <optional>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace geodex {

enum class Limit {
  kVertices,       // ReadLimits::max_vertices
  kFaces,          // ReadLimits::max_faces
  kInputBytes,     // ReadLimits::max_decompressed_bytes (file size, gzip expansion)
  kWindows,        // GeodesicOptions::max_windows
  kDemCells,       // terrain::DemOptions::max_cells (a raster's width x height)
  kSteinerPoints,  // WeightedOptions::max_steiner_points (weighted_field.h)
};

// The default Steiner-point limit of a travel solve, the CLI's (--max-steiner-points) and
// geodexd's (--max_steiner_points) alike: about 1 GiB of the engine's per-point state (25 to 33
// bytes a point), refused up front before it is allocated, never an out-of-memory kill.
inline constexpr uint64_t kDefaultMaxSteinerPoints = 32'000'000;

// The default work budget of one solve (GeodesicOptions::max_windows): the CLI's (--max-windows),
// about 5 to 10 minutes of one core, and geodexd's (--max_windows), 1 to 3 minutes of one worker.
// Core's own default stays 0 (unlimited): the budget is the caller's.
inline constexpr uint64_t kDefaultMaxWindows = 4'000'000'000;
inline constexpr uint64_t kServerDefaultMaxWindows = 1'000'000'000;

// A travel graph's search (a slope-dependent speed) makes no windows: it spends the same
// budget in links relaxed, this many to a window, about their ratio in time (a window costs
// 100-200 ns to make and propagate, a link 3-6 ns to relax; docs/travel.md, "Limits and memory").
inline constexpr uint64_t kGraphLinksPerWindow = 32;

absl::Status LimitExceededError(Limit limit, absl::string_view message);

// The limit a status reports, if it came from LimitExceededError.
std::optional<Limit> ExceededLimit(const absl::Status& status);

}  // namespace geodex
