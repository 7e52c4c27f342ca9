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
// geodexd's (--max_steiner_points) alike: about 1.6 GiB of the engine's per-point state (25 to 33
// bytes a point), refused up front before it is allocated, never an out-of-memory kill.
inline constexpr uint64_t kDefaultMaxSteinerPoints = 50'000'000;

absl::Status LimitExceededError(Limit limit, absl::string_view message);

// The limit a status reports, if it came from LimitExceededError.
std::optional<Limit> ExceededLimit(const absl::Status& status);

}  // namespace geodex
