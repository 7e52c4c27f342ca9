#include "mesh_file_header.h"

#include <bit>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "api_convert.h"
#include "geodex/v1/geodex.pb.h"
#include "google/protobuf/util/time_util.h"

namespace geodex::server {
namespace {

class Writer {
 public:
  void U8(uint8_t v) { out_.push_back(static_cast<char>(v)); }
  void U32(uint32_t v) { Le(v, 4); }
  void U64(uint64_t v) { Le(v, 8); }
  void F64(double v) { Le(std::bit_cast<uint64_t>(v), 8); }
  void Str(const std::string& s) {
    U32(static_cast<uint32_t>(s.size()));
    out_ += s;
  }
  std::string Take() { return std::move(out_); }

 private:
  void Le(uint64_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) out_.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  }
  std::string out_;
};

// Reads what Writer wrote; any read past the end sets !ok() and yields zeros.
class Reader {
 public:
  explicit Reader(absl::string_view bytes) : rest_(bytes) {}
  uint8_t U8() { return static_cast<uint8_t>(Le(1)); }
  uint32_t U32() { return static_cast<uint32_t>(Le(4)); }
  uint64_t U64() { return Le(8); }
  double F64() { return std::bit_cast<double>(Le(8)); }
  std::string Str() {
    const uint32_t n = U32();
    if (n > rest_.size()) return Fail(), std::string();
    std::string s(rest_.substr(0, n));
    rest_.remove_prefix(n);
    return s;
  }
  bool ok() const { return ok_; }
  bool done() const { return rest_.empty(); }

 private:
  void Fail() {
    ok_ = false;
    rest_ = {};
  }
  uint64_t Le(int bytes) {
    if (rest_.size() < static_cast<size_t>(bytes)) return Fail(), 0;
    uint64_t v = 0;
    for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | static_cast<uint8_t>(rest_[i]);
    rest_.remove_prefix(bytes);
    return v;
  }
  absl::string_view rest_;
  bool ok_ = true;
};

// MeshReport's counts, in declaration order: the one list both directions walk.
template <typename Report, typename F>
void ForEachCount(Report& r, F&& f) {
  for (auto* p :
       {&r.file_vertices, &r.file_faces, &r.boundary_edges, &r.boundary_loops, &r.components,
        &r.vertex_connected_components, &r.isolated_vertices, &r.non_manifold_edges,
        &r.non_manifold_vertices, &r.degenerate_faces, &r.flipped_faces, &r.orientation_cuts,
        &r.saddle_vertices, &r.boundary_vertices}) {
    f(*p);
  }
}

// Version 1: a serialized geodex.v1.Mesh (the public resource) named "meshes/<id>".
absl::StatusOr<MeshRecord> DecodeVersion1(absl::string_view bytes) {
  v1::Mesh proto;
  if (!proto.ParseFromArray(bytes.data(), static_cast<int>(bytes.size())) ||
      !absl::StartsWith(proto.name(), "meshes/")) {
    return absl::DataLossError("corrupt header");
  }
  MeshRecord record;
  record.id = proto.name().substr(7);
  record.display_name = proto.display_name();
  record.aliases.assign(proto.aliases().begin(), proto.aliases().end());
  record.vertex_count = proto.vertex_count();
  record.face_count = proto.face_count();
  record.upload_bytes = proto.upload_bytes();
  record.memory_bytes = proto.memory_bytes();
  record.pinned = proto.pinned();
  record.create_time = absl::FromUnixNanos(
      google::protobuf::util::TimeUtil::TimestampToNanoseconds(proto.create_time()));
  record.summary = api::MeshSummaryFromProto(proto);
  return record;
}

}  // namespace

std::string EncodeMeshFileHeader(const MeshRecord& record) {
  Writer w;
  w.Str(record.id);
  w.Str(record.display_name);
  w.U32(static_cast<uint32_t>(record.aliases.size()));
  for (const std::string& alias : record.aliases) w.Str(alias);
  w.U64(record.vertex_count);
  w.U64(record.face_count);
  w.U64(record.upload_bytes);
  w.U64(record.memory_bytes);
  w.U8(record.pinned ? 1 : 0);
  w.U64(static_cast<uint64_t>(absl::ToUnixNanos(record.create_time)));
  const MeshSummary& s = record.summary;
  ForEachCount(s.report, [&](uint64_t v) { w.U64(v); });
  w.U64(s.internal_vertices);
  w.F64(s.mean_edge_length);
  w.F64(s.max_edge_length);
  for (double v : s.bbox_min) w.F64(v);
  for (double v : s.bbox_max) w.F64(v);
  w.U64(s.bytes);
  w.U8(record.terrain.has_value() ? 1 : 0);
  if (record.terrain) {
    const terrain::DemInfo& t = *record.terrain;
    w.Str(t.driver);
    for (uint32_t v : {t.raster_width, t.raster_height, t.step, t.grid_width, t.grid_height})
      w.U32(v);
    for (uint64_t v : {t.nodata_cells, t.barrier_cells, t.barrier_faces}) w.U64(v);
    w.Str(t.file_crs_name);
    w.Str(t.file_crs_wkt);
    w.U8(t.reprojected ? 1 : 0);
    w.Str(t.mesh_crs_name);
    w.Str(t.mesh_crs_wkt);
    w.F64(t.horizontal_scale);
    w.Str(t.vertical_unit);
    w.F64(t.vertical_scale);
    for (double v : t.geotransform) w.F64(v);
    for (double v : {t.z_tolerance, t.max_vertical_deviation, t.rms_vertical_deviation}) w.F64(v);
  }
  return w.Take();
}

absl::StatusOr<MeshRecord> DecodeMeshFileHeader(uint32_t version, absl::string_view bytes) {
  if (version == 1) return DecodeVersion1(bytes);
  if (version < 2 || version > 4) {
    return absl::DataLossError(absl::StrCat("unsupported format version ", version));
  }
  Reader r(bytes);
  MeshRecord record;
  record.id = r.Str();
  record.display_name = r.Str();
  const uint32_t aliases = r.U32();
  for (uint32_t i = 0; i < aliases && r.ok(); ++i) record.aliases.push_back(r.Str());
  record.vertex_count = r.U64();
  record.face_count = r.U64();
  record.upload_bytes = r.U64();
  record.memory_bytes = r.U64();
  record.pinned = r.U8() != 0;
  record.create_time = absl::FromUnixNanos(static_cast<int64_t>(r.U64()));
  MeshSummary& s = record.summary;
  ForEachCount(s.report, [&](uint64_t& v) { v = r.U64(); });
  s.internal_vertices = r.U64();
  s.mean_edge_length = r.F64();
  s.max_edge_length = r.F64();
  for (double& v : s.bbox_min) v = r.F64();
  for (double& v : s.bbox_max) v = r.F64();
  s.bytes = r.U64();
  if (version >= 3 && r.U8() != 0) {
    terrain::DemInfo& t = record.terrain.emplace();
    t.driver = r.Str();
    for (uint32_t* v :
         {&t.raster_width, &t.raster_height, &t.step, &t.grid_width, &t.grid_height}) {
      *v = r.U32();
    }
    for (uint64_t* v : {&t.nodata_cells, &t.barrier_cells, &t.barrier_faces}) *v = r.U64();
    t.file_crs_name = r.Str();
    t.file_crs_wkt = r.Str();
    t.reprojected = r.U8() != 0;
    t.mesh_crs_name = r.Str();
    t.mesh_crs_wkt = r.Str();
    t.horizontal_scale = r.F64();
    t.vertical_unit = r.Str();
    t.vertical_scale = r.F64();
    for (double& v : t.geotransform) v = r.F64();
    if (version >= 4) {
      for (double* v : {&t.z_tolerance, &t.max_vertical_deviation, &t.rms_vertical_deviation}) {
        *v = r.F64();
      }
    }
  }
  if (!r.ok() || !r.done()) return absl::DataLossError("corrupt header");
  return record;
}

}  // namespace geodex::server
