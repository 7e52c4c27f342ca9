#include "geodex/limits.h"

#include <iterator>
#include <string>

#include "absl/strings/cord.h"

namespace geodex {
namespace {

constexpr absl::string_view kPayloadUrl = "geodex/limit";

constexpr absl::string_view kNames[] = {"vertices", "faces",     "input_bytes",
                                        "windows",  "dem_cells", "steiner_points"};

}  // namespace

absl::Status LimitExceededError(Limit limit, absl::string_view message) {
  absl::Status status = absl::ResourceExhaustedError(message);
  status.SetPayload(kPayloadUrl, absl::Cord(kNames[static_cast<int>(limit)]));
  return status;
}

std::optional<Limit> ExceededLimit(const absl::Status& status) {
  auto payload = status.GetPayload(kPayloadUrl);
  if (!payload.has_value()) return std::nullopt;
  for (int i = 0; i < static_cast<int>(std::size(kNames)); ++i) {
    if (*payload == kNames[i]) return static_cast<Limit>(i);
  }
  return std::nullopt;
}

}  // namespace geodex
