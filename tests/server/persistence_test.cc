// geodexd's data directory: restarts lose nothing, corrupt or truncated files are skipped, crashed
// writes are cleaned up, built-in samples appear on a fresh directory only, evicted meshes come
// back from disk, and a server-side import directory is read at start.

#include <filesystem>
#include <fstream>

#include "absl/strings/str_cat.h"
#include "geodex/mesh_id.h"
#include "mesh_disk.h"
#include "mesh_file_header.h"
#include "server_test_util.h"

namespace geodex::server {
namespace {

using testing::FieldRequest;
using testing::GridOff;
using testing::In;
using testing::ReadField;
using testing::Upload;

namespace fs = std::filesystem;

class PersistenceTest : public testing::ServerFixture {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) /
           absl::StrCat("geodex-persist-", ::testing::UnitTest::GetInstance()->random_seed(), "-",
                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override {
    testing::ServerFixture::TearDown();
    server_.reset();
    fs::remove_all(dir_);
  }
  void Restart(ServerOptions options = {}) {
    if (server_) server_->Shutdown(absl::Now() + absl::Seconds(10));
    server_.reset();
    options.data_dir = dir_.string();
    StartServer(options);
  }
  std::vector<v1::Mesh> List() {
    grpc::ClientContext context;
    context.set_deadline(In(30));
    v1::ListMeshesRequest request;
    v1::ListMeshesResponse response;
    EXPECT_TRUE(stub_->ListMeshes(&context, request, &response).ok());
    return {response.meshes().begin(), response.meshes().end()};
  }
  grpc::Status GetMesh(const std::string& name, v1::Mesh* out) {
    grpc::ClientContext context;
    context.set_deadline(In(30));
    v1::GetMeshRequest request;
    request.set_name(name);
    return stub_->GetMesh(&context, request, out);
  }
  std::string MeshFile(const v1::Mesh& mesh) {
    return (dir_ / "meshes" / (mesh.name().substr(7) + ".gdxs")).string();
  }

  fs::path dir_;
};

TEST_F(PersistenceTest, RestartKeepsEveryMeshWithItsIdAliasAndAnswers) {
  Restart();
  testing::UploadResult a = Upload(*stub_, GridOff(12, 9, true), "hills");
  testing::UploadResult b = Upload(*stub_, GridOff(7, 7, false), "", 1 << 20, /*pin=*/true);
  ASSERT_TRUE(a.status.ok() && b.status.ok());
  testing::FieldResult before = ReadField(*stub_, FieldRequest("meshes/hills", {0, 50}));
  ASSERT_TRUE(before.status.ok());
  EXPECT_TRUE(fs::exists(MeshFile(a.mesh)));

  Restart();
  std::vector<v1::Mesh> meshes = List();
  ASSERT_EQ(meshes.size(), 2u);
  v1::Mesh got;
  ASSERT_TRUE(GetMesh("meshes/hills", &got).ok());  // answered from the index, not loaded
  EXPECT_EQ(got.name(), a.mesh.name());
  EXPECT_EQ(got.vertex_count(), a.mesh.vertex_count());
  EXPECT_EQ(got.memory_bytes(), a.mesh.memory_bytes());
  EXPECT_EQ(got.create_time().seconds(), a.mesh.create_time().seconds());
  EXPECT_EQ(server_->store().resident_count(), 0u);
  ASSERT_TRUE(GetMesh(b.mesh.name(), &got).ok());
  EXPECT_TRUE(got.pinned());

  // First use loads from disk; the answer is bit-identical.
  testing::FieldResult after = ReadField(*stub_, FieldRequest("meshes/hills", {0, 50}));
  ASSERT_TRUE(after.status.ok()) << after.status.error_message();
  EXPECT_EQ(after.distances, before.distances);
  EXPECT_EQ(after.labels, before.labels);
  EXPECT_EQ(server_->store().disk_loads(), 1u);

  // Re-uploading is still idempotent; a delete removes the file and survives a restart.
  testing::UploadResult again = Upload(*stub_, GridOff(12, 9, true));
  EXPECT_EQ(again.mesh.name(), a.mesh.name());
  grpc::ClientContext context;
  v1::DeleteMeshRequest del;
  del.set_name("meshes/hills");
  v1::DeleteMeshResponse deleted;
  ASSERT_TRUE(stub_->DeleteMesh(&context, del, &deleted).ok());
  EXPECT_FALSE(fs::exists(MeshFile(a.mesh)));
  Restart();
  EXPECT_EQ(List().size(), 1u);
}

TEST_F(PersistenceTest, EvictionKeepsTheMeshOnDiskAndLoadsItBack) {
  std::string a = GridOff(20, 20, true), b = GridOff(21, 21, true);
  ServerOptions probe;
  Restart(probe);
  testing::UploadResult ua = Upload(*stub_, a);
  ASSERT_TRUE(ua.status.ok());
  // A budget that holds one of the two meshes at a time.
  ServerOptions small;
  small.mesh_budget_bytes = ua.mesh.memory_bytes() * 3 / 2;
  Restart(small);
  testing::UploadResult ub = Upload(*stub_, b);
  ASSERT_TRUE(ub.status.ok()) << ub.status.error_message();
  testing::FieldResult fa = ReadField(*stub_, FieldRequest(ua.mesh.name(), {0}));
  ASSERT_TRUE(fa.status.ok()) << fa.status.error_message();  // loaded, evicting b from memory
  testing::FieldResult fb = ReadField(*stub_, FieldRequest(ub.mesh.name(), {0}));
  ASSERT_TRUE(fb.status.ok()) << fb.status.error_message();  // b back from disk, a evicted
  EXPECT_GE(server_->store().evictions(), 1u);
  EXPECT_EQ(server_->store().disk_loads(), 2u);
  EXPECT_EQ(List().size(), 2u);  // eviction forgets nothing
  EXPECT_EQ(server_->store().resident_count(), 1u);
}

TEST_F(PersistenceTest, CorruptTruncatedAndForeignFilesAreSkippedAndTemporariesRemoved) {
  Restart();
  testing::UploadResult good = Upload(*stub_, GridOff(6, 6, true), "good");
  testing::UploadResult bad = Upload(*stub_, GridOff(8, 8, true), "flipped");
  testing::UploadResult cut = Upload(*stub_, GridOff(9, 9, true), "cut");
  ASSERT_TRUE(good.status.ok() && bad.status.ok() && cut.status.ok());
  server_->Shutdown(absl::Now() + absl::Seconds(10));
  server_.reset();

  // One byte flipped inside the payload: the index accepts it (the framing is intact) and its
  // first use answers DATA_LOSS naming the file; truncation is caught by the index.
  {
    std::fstream f(MeshFile(bad.mesh), std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(-100, std::ios::end);
    f.put('\x5a');
  }
  fs::resize_file(MeshFile(cut.mesh), fs::file_size(MeshFile(cut.mesh)) - 7);
  std::ofstream(dir_ / "meshes" / "notes.txt") << "not a mesh";
  std::ofstream(dir_ / "meshes" / (std::string(64, 'a') + ".gdxs")) << "GDXSTOR1 garbage";
  const fs::path temporary = dir_ / "meshes" / (good.mesh.name().substr(7) + ".gdxs.tmp.123.0");
  std::ofstream(temporary) << "half a write";

  Restart();
  const StartupReport& report = server_->startup_report();
  EXPECT_EQ(report.indexed, 2u);  // good and the flipped one
  ASSERT_EQ(report.skipped.size(), 3u);
  bool truncated_reported = false;
  for (const auto& s : report.skipped) {
    truncated_reported |=
        s.path == MeshFile(cut.mesh) && s.reason.find("truncated") != std::string::npos;
  }
  EXPECT_TRUE(truncated_reported);
  ASSERT_EQ(report.removed_temporaries.size(), 1u);
  EXPECT_FALSE(fs::exists(temporary));

  EXPECT_TRUE(ReadField(*stub_, FieldRequest("meshes/good", {0})).status.ok());
  grpc::Status s = ReadField(*stub_, FieldRequest("meshes/flipped", {0})).status;
  EXPECT_EQ(s.error_code(), grpc::StatusCode::DATA_LOSS) << s.error_message();
  // The message names the mesh, never the server's data directory.
  EXPECT_NE(s.error_message().find(bad.mesh.name()), std::string::npos) << s.error_message();
  EXPECT_EQ(s.error_message().find(dir_.string()), std::string::npos) << s.error_message();
  EXPECT_EQ(s.error_message().find(".gdxs"), std::string::npos) << s.error_message();
  v1::Mesh got;
  EXPECT_EQ(GetMesh("meshes/cut", &got).error_code(), grpc::StatusCode::NOT_FOUND);
  // The skipped files are left in place for an operator to inspect.
  EXPECT_TRUE(fs::exists(MeshFile(cut.mesh)));
}

uint32_t FileVersion(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[12] = {};
  in.read(head, sizeof head);
  uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<uint8_t>(head[8 + i]);
  return v;
}

TEST(MeshFileHeaderTest, RoundTripsEveryFieldAndRefusesTruncation) {
  MeshRecord r;
  r.id = std::string(64, 'c');
  r.display_name = "hills";
  r.aliases = {"a", "", "third name"};
  r.vertex_count = 11;
  r.face_count = 13;
  r.upload_bytes = 1234567;
  r.memory_bytes = 7654321;
  r.pinned = true;
  r.create_time = absl::FromUnixNanos(1764000000123456789);
  r.summary.report.file_vertices = 1;
  r.summary.report.boundary_vertices = 14;  // the first and the last count
  r.summary.report.saddle_vertices = 9;
  r.summary.internal_vertices = 12;
  r.summary.mean_edge_length = 0.1;
  r.summary.max_edge_length = 1.0 / 3;
  r.summary.bbox_min = {-1.5, -2.5, -1e300};
  r.summary.bbox_max = {1.5, 2.5, 5e-324};
  r.summary.bytes = 999;
  const std::string bytes = EncodeMeshFileHeader(r);
  absl::StatusOr<MeshRecord> back = DecodeMeshFileHeader(kMeshFileVersion, bytes);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->id, r.id);
  EXPECT_EQ(back->display_name, r.display_name);
  EXPECT_EQ(back->aliases, r.aliases);
  EXPECT_EQ(back->vertex_count, 11u);
  EXPECT_EQ(back->face_count, 13u);
  EXPECT_EQ(back->upload_bytes, r.upload_bytes);
  EXPECT_EQ(back->memory_bytes, r.memory_bytes);
  EXPECT_TRUE(back->pinned);
  EXPECT_EQ(back->create_time, r.create_time);
  EXPECT_EQ(back->summary.report.file_vertices, 1u);
  EXPECT_EQ(back->summary.report.boundary_vertices, 14u);
  EXPECT_EQ(back->summary.report.saddle_vertices, 9u);
  EXPECT_EQ(back->summary.internal_vertices, 12u);
  EXPECT_EQ(back->summary.max_edge_length, r.summary.max_edge_length);
  EXPECT_EQ(back->summary.bbox_min, r.summary.bbox_min);
  EXPECT_EQ(back->summary.bbox_max, r.summary.bbox_max);
  EXPECT_EQ(back->summary.bytes, 999u);
  EXPECT_FALSE(back->terrain.has_value());
  // Version 2 is version 3 without the terrain byte.
  absl::StatusOr<MeshRecord> v2 =
      DecodeMeshFileHeader(2, absl::string_view(bytes).substr(0, bytes.size() - 1));
  ASSERT_TRUE(v2.ok()) << v2.status();
  EXPECT_EQ(v2->summary.bytes, 999u);
  EXPECT_FALSE(v2->terrain.has_value());

  // A DEM's mesh keeps its map, every field.
  terrain::DemInfo& t = r.terrain.emplace();
  t.driver = "GTiff";
  t.raster_width = 1001;
  t.raster_height = 999;
  t.step = 3;
  t.grid_width = 334;
  t.grid_height = 333;
  t.nodata_cells = 17;
  t.barrier_cells = 19;
  t.barrier_faces = 23;
  t.file_crs_name = "WGS 84";
  t.file_crs_wkt = "GEOGCRS[...]";
  t.reprojected = true;
  t.mesh_crs_name = "WGS 84 / UTM zone 33N";
  t.mesh_crs_wkt = "PROJCRS[...]";
  t.horizontal_scale = 0.3048;
  t.vertical_unit = "US survey foot";
  t.vertical_scale = 1200.0 / 3937;
  t.geotransform = {14.99, 0.0002, 0, 45.16, 0, -0.0002};
  const std::string with_terrain = EncodeMeshFileHeader(r);
  absl::StatusOr<MeshRecord> dem = DecodeMeshFileHeader(kMeshFileVersion, with_terrain);
  ASSERT_TRUE(dem.ok()) << dem.status();
  ASSERT_TRUE(dem->terrain.has_value());
  EXPECT_EQ(*dem->terrain, t);
  EXPECT_EQ(dem->display_name, r.display_name);
  for (size_t cut :
       {size_t{0}, size_t{3}, bytes.size() / 2, bytes.size() - 1, with_terrain.size() - 9}) {
    EXPECT_EQ(DecodeMeshFileHeader(kMeshFileVersion, with_terrain.substr(0, cut)).status().code(),
              absl::StatusCode::kDataLoss)
        << cut;
  }
  for (size_t cut : {size_t{0}, size_t{3}, bytes.size() / 2, bytes.size() - 1}) {
    EXPECT_EQ(DecodeMeshFileHeader(kMeshFileVersion, bytes.substr(0, cut)).status().code(),
              absl::StatusCode::kDataLoss)
        << cut;
  }
  EXPECT_EQ(DecodeMeshFileHeader(kMeshFileVersion, bytes + "x").status().code(),
            absl::StatusCode::kDataLoss);
  EXPECT_EQ(DecodeMeshFileHeader(kMeshFileVersion + 1, bytes).status().code(),
            absl::StatusCode::kDataLoss);
}

// A data directory written before the private header (version 1: a geodex.v1.Mesh as the header)
// is served as it was, and a file is rewritten in the current version when its header next changes.
TEST_F(PersistenceTest, VersionOneFilesAreStillServed) {
  Restart();
  testing::UploadResult up = Upload(*stub_, GridOff(10, 8, true), "old");
  ASSERT_TRUE(up.status.ok());
  const std::string path = MeshFile(up.mesh);
  EXPECT_EQ(FileVersion(path), kMeshFileVersion);
  testing::FieldResult before = ReadField(*stub_, FieldRequest("meshes/old", {0, 30}));
  ASSERT_TRUE(before.status.ok());
  server_->Shutdown(absl::Now() + absl::Seconds(10));
  server_.reset();

  // The file as version 1 wrote it: the resource itself as the header, the same payload.
  std::string canonical;
  {
    MeshDisk::Index index;
    absl::StatusOr<MeshDisk> disk = MeshDisk::Open(dir_.string(), &index);
    ASSERT_TRUE(disk.ok());
    MeshRecord header;
    ASSERT_TRUE(disk->Read(up.mesh.name().substr(7), &header, &canonical).ok());
  }
  const std::string head = up.mesh.SerializeAsString();
  std::string bytes = "GDXSTOR1";
  auto put = [&](uint64_t v, int n) {
    for (int i = 0; i < n; ++i) bytes.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  };
  put(1, 4);
  put(head.size(), 4);
  bytes += head;
  put(canonical.size(), 8);
  bytes += canonical;
  Sha256 sha;
  sha.Update(bytes.data(), bytes.size());
  const std::array<uint8_t, 32> sum = sha.Finish();
  bytes.append(reinterpret_cast<const char*>(sum.data()), sum.size());
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  ASSERT_EQ(FileVersion(path), 1u);

  Restart();
  EXPECT_EQ(server_->startup_report().indexed, 1u);
  v1::Mesh got;
  ASSERT_TRUE(GetMesh("meshes/old", &got).ok());
  EXPECT_EQ(got.name(), up.mesh.name());
  EXPECT_EQ(got.vertex_count(), up.mesh.vertex_count());
  EXPECT_EQ(got.memory_bytes(), up.mesh.memory_bytes());
  EXPECT_EQ(got.info().mean_edge_length(), up.mesh.info().mean_edge_length());
  EXPECT_GT(got.info().mean_edge_length(), 0);
  testing::FieldResult after = ReadField(*stub_, FieldRequest("meshes/old", {0, 30}));
  ASSERT_TRUE(after.status.ok()) << after.status.error_message();
  EXPECT_EQ(after.distances, before.distances);

  // A new name rewrites the header in the current layout; both names survive a restart.
  ASSERT_TRUE(Upload(*stub_, GridOff(10, 8, true), "renamed").status.ok());
  EXPECT_EQ(FileVersion(path), kMeshFileVersion);
  Restart();
  EXPECT_TRUE(GetMesh("meshes/old", &got).ok());
  EXPECT_TRUE(GetMesh("meshes/renamed", &got).ok());
}

TEST_F(PersistenceTest, SamplesOnAFreshDirectoryOnly) {
  ServerOptions options;
  options.samples = true;
  Restart(options);
  std::vector<v1::Mesh> meshes = List();
  ASSERT_EQ(meshes.size(), 3u);
  for (const char* name : {"terrain", "torus", "sphere"}) {
    v1::Mesh mesh;
    ASSERT_TRUE(GetMesh(absl::StrCat("meshes/", name), &mesh).ok()) << name;
    EXPECT_GT(mesh.face_count(), 1000u);
  }
  testing::FieldResult field = ReadField(*stub_, FieldRequest("meshes/terrain", {0}));
  ASSERT_TRUE(field.status.ok());
  EXPECT_EQ(field.distances.size(), 65u * 65u);

  // A deleted sample stays deleted: samples are only added to a fresh directory.
  grpc::ClientContext context;
  v1::DeleteMeshRequest del;
  del.set_name("meshes/torus");
  v1::DeleteMeshResponse deleted;
  ASSERT_TRUE(stub_->DeleteMesh(&context, del, &deleted).ok());
  Restart(options);
  EXPECT_EQ(List().size(), 2u);
}

TEST_F(PersistenceTest, ImportDirectoryAtStart) {
  const fs::path import = dir_.string() + "-import";
  fs::create_directories(import);
  std::ofstream(import / "valley.off") << GridOff(5, 4, true);
  std::ofstream(import / "broken.off") << "OFF\n3 1 0\n0 0 0\n";
  ServerOptions options;
  options.import_dir = import.string();
  Restart(options);
  const StartupReport& report = server_->startup_report();
  EXPECT_EQ(report.imported.size(), 1u);
  ASSERT_EQ(report.import_errors.size(), 1u);
  EXPECT_NE(report.import_errors[0].find("broken.off"), std::string::npos)
      << report.import_errors[0];
  v1::Mesh mesh;
  ASSERT_TRUE(GetMesh("meshes/valley", &mesh).ok());
  EXPECT_EQ(mesh.vertex_count(), 30u);
  fs::remove_all(import);
}

}  // namespace
}  // namespace geodex::server
