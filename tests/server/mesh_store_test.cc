#include "mesh_store.h"

#include "geodex/mesh_id.h"
#include "gtest/gtest.h"
#include "server_test_util.h"

namespace geodex::server {
namespace {

std::shared_ptr<StoredMesh> Make(int cells, bool pinned = false, std::string alias = "") {
  std::string off = testing::GridOff(cells, cells, true);
  MeshData data = *ReadMeshFromBuffer(off, MeshFormat::kOff, "x.off");
  std::string id = ComputeMeshId(data);
  auto stored = MakeStoredMesh(id, *TriangleMesh::Build(data));
  stored->pinned = pinned;
  stored->display_name = std::move(alias);
  return stored;
}

TEST(MeshStoreTest, InsertGetDeleteAndAlias) {
  MeshStore store(uint64_t{1} << 30);
  auto a = Make(4, false, "small");
  std::string id = a->id;
  ASSERT_TRUE(store.Insert(a).ok());
  EXPECT_EQ((*store.Get(id))->id, id);
  EXPECT_EQ((*store.Get("small"))->id, id);
  EXPECT_EQ(store.Get("nope").status().code(), absl::StatusCode::kNotFound);
  // Re-insert: same entry.
  EXPECT_EQ(*store.Insert(Make(4)), *store.Get(id));
  // Alias already used by another mesh.
  EXPECT_EQ(store.Insert(Make(5, false, "small")).status().code(),
            absl::StatusCode::kInvalidArgument);
  std::shared_ptr<const StoredMesh> held = *store.Get(id);
  ASSERT_TRUE(store.Delete("small").ok());
  EXPECT_EQ(store.Get(id).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store.Delete(id).code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(held->mesh->face_count(), 32u);  // a holder keeps the mesh alive
  EXPECT_EQ(store.used_bytes(), 0u);
}

TEST(MeshStoreTest, LruEvictionUnderBudgetSparesPinnedAndRecentlyUsed) {
  auto m1 = Make(10), m2 = Make(11), m3 = Make(12), m4 = Make(13);
  uint64_t most =
      std::max({m1->memory_bytes, m2->memory_bytes, m3->memory_bytes, m4->memory_bytes});
  MeshStore store(3 * most);
  m1->pinned = true;
  ASSERT_TRUE(store.Insert(m1).ok());
  ASSERT_TRUE(store.Insert(m2).ok());
  ASSERT_TRUE(store.Insert(m3).ok());
  ASSERT_TRUE(store.Get(m2->id).ok());  // m3 is now the least recently used unpinned mesh
  ASSERT_TRUE(store.Insert(m4).ok());
  EXPECT_TRUE(store.Contains(m1->id));
  EXPECT_TRUE(store.Contains(m2->id));
  EXPECT_FALSE(store.Contains(m3->id));
  EXPECT_TRUE(store.Contains(m4->id));
  EXPECT_GE(store.evictions(), 1u);
  EXPECT_LE(store.used_bytes(), store.budget_bytes());
}

TEST(MeshStoreTest, TooLargeOrBlockedByPinnedIsResourceExhausted) {
  auto small = Make(4, true);
  auto big = Make(30);
  MeshStore store(big->memory_bytes - 1);
  absl::Status status = store.Insert(big).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(status.message().find("mesh_budget_bytes"), std::string::npos) << status;
  MeshStore store2(big->memory_bytes + small->memory_bytes / 2);
  ASSERT_TRUE(store2.Insert(small).ok());
  EXPECT_EQ(store2.Insert(big).status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_TRUE(store2.Contains(small->id));  // nothing evicted by a failed insert
}

TEST(MeshStoreTest, ListPagesInIdOrder) {
  MeshStore store(uint64_t{1} << 30);
  for (int cells = 2; cells < 9; ++cells) ASSERT_TRUE(store.Insert(Make(cells)).ok());
  std::vector<std::string> ids;
  std::string after;
  bool more = true;
  while (more) {
    auto page = store.List(after, 3, &more);
    ASSERT_FALSE(page.empty());
    for (const auto& m : page) ids.push_back(m->id);
    after = ids.back();
  }
  ASSERT_EQ(ids.size(), 7u);
  EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));
}

}  // namespace
}  // namespace geodex::server
