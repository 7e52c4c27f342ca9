#include "geodex/solve_key.h"

#include <array>
#include <cstdint>
#include <memory>

#include "geodex/mesh_id.h"
#include "geodex/travel_cost.h"

namespace geodex {
namespace {

template <typename T>
void Append(std::string* out, const T& value) {
  out->append(reinterpret_cast<const char*>(&value), sizeof value);
}

using Weights = std::shared_ptr<const std::vector<double>>;

// The SHA-256 of a travel cost's face weights. One request keys many fields with the same weights
// (a matrix's rows, a batch's sources), and friction from a cache is one vector for many
// requests, so each thread remembers the last weights it hashed: the same vector (the same
// address under the same control block, still alive: immutable) has the same digest.
std::array<uint8_t, 32> WeightsDigest(const Weights& weights) {
  thread_local std::weak_ptr<const std::vector<double>> last;
  thread_local const std::vector<double>* last_address = nullptr;
  thread_local std::array<uint8_t, 32> last_digest{};
  if (!last.expired() && last_address == weights.get() && !last.owner_before(weights) &&
      !weights.owner_before(last)) {
    return last_digest;
  }
  Sha256 sha;
  sha.Update(weights->data(), weights->size() * sizeof(double));
  last_digest = sha.Finish();
  last = weights;
  last_address = weights.get();
  return last_digest;
}

// A travel answer is never another answer: a marker byte, then its speed model, speed, table
// (row count, then the rows), direction (inbound, for a slope speed), bound, slope limit and
// weights (by their SHA-256; friction polygons count by the weights they made).
void AppendTravel(std::string* out, const GeodesicOptions& options) {
  std::string& key = *out;
  Append(&key, static_cast<uint8_t>(options.travel.has_value()));
  if (options.travel) {
    const TravelCost& travel = *options.travel;
    Append(&key, static_cast<uint8_t>(travel.speed_model));
    Append(&key, travel.speed_kmh);
    const size_t rows = travel.speed_table == nullptr ? 0 : travel.speed_table->size();
    Append(&key, rows);
    for (size_t i = 0; i < rows; ++i) Append(&key, (*travel.speed_table)[i]);
    Append(&key, static_cast<uint8_t>(TimesInbound(travel)));  // (one entry at a constant speed)
    Append(&key, TravelEpsilon(travel));  // (unset and its default are one entry)
    Append(&key, travel.max_slope_deg);
    const bool weighted = travel.face_weight != nullptr;
    Append(&key, static_cast<uint8_t>(weighted));
    if (weighted) {
      Append(&key, travel.face_weight->size());
      Append(&key, WeightsDigest(travel.face_weight));
    }
  }
}

}  // namespace

std::string TravelCostKey(const GeodesicOptions& options) {
  std::string key;
  AppendTravel(&key, options);
  return key;
}

std::string SolveKey(const std::vector<SurfacePoint>& sources, const GeodesicOptions& options) {
  std::string key;
  Append(&key, static_cast<uint8_t>(options.method));
  Append(&key, options.lambda);
  Append(&key, static_cast<int>(options.lambda_scale));
  Append(&key, options.max_distance);
  Append(&key, static_cast<uint8_t>(options.use_filter));
  Append(&key, static_cast<uint8_t>(options.use_one_angle_one_split));
  AppendTravel(&key, options);
  Append(&key, sources.size());
  for (const SurfacePoint& p : sources) {
    Append(&key, static_cast<uint8_t>(p.kind));
    switch (p.kind) {
      case SurfacePoint::Kind::kVertex:
        Append(&key, p.vertex);
        break;
      case SurfacePoint::Kind::kEdge:
        Append(&key, p.edge_from);
        Append(&key, p.edge_to);
        Append(&key, p.t);
        break;
      case SurfacePoint::Kind::kFace:
        Append(&key, p.face);
        Append(&key, p.bary);
        break;
      case SurfacePoint::Kind::kPosition:
        Append(&key, p.position);
        break;
    }
  }
  return key;
}

}  // namespace geodex
