// The result cache keeps what is asked for repeatedly (issue 56): a full cache evicts its
// least-asked fields first, least recently used among equals, and declines a field rather than
// push out one asked for more often.

#include "field_cache.h"

#include <memory>
#include <string>

#include "gtest/gtest.h"

namespace geodex::server {
namespace {

// A field of `n` distances (its bytes are FieldBytes: about 12 n).
std::shared_ptr<const DistanceField> FieldOf(size_t n) {
  auto field = std::make_shared<DistanceField>();
  field->distance.assign(n, 1.0);
  field->source.assign(n, 0);
  return field;
}

// A budget that holds two fields of 1000 distances and not three.
uint64_t TwoFields() { return FieldBytes(*FieldOf(1000)) * 5 / 2; }

TEST(FieldCacheTest, AmongEquallyAskedFieldsTheLeastRecentlyUsedGoes) {
  FieldCache cache(TwoFields());
  for (const char* key : {"a", "b", "c"}) {
    EXPECT_EQ(cache.Find(key), nullptr);  // one ask each
    cache.Insert(key, FieldOf(1000));
  }
  EXPECT_FALSE(cache.Contains("a"));
  EXPECT_TRUE(cache.Contains("b"));
  EXPECT_TRUE(cache.Contains("c"));
  EXPECT_EQ(cache.declined(), 0u);
}

TEST(FieldCacheTest, AFieldAskedForRepeatedlyStaysWhenOneOffFieldsArrive) {
  FieldCache cache(TwoFields());
  EXPECT_EQ(cache.Find("hot"), nullptr);
  cache.Insert("hot", FieldOf(1000));
  for (int i = 0; i < 3; ++i) EXPECT_NE(cache.Find("hot"), nullptr);
  EXPECT_EQ(cache.asks("hot"), 4u);
  // Ten one-off fields, each asked once: "hot" (the least recently used by the end) is never the
  // one evicted; each newcomer replaces the previous one-off field.
  for (int i = 0; i < 10; ++i) {
    const std::string key = "once" + std::to_string(i);
    EXPECT_EQ(cache.Find(key), nullptr);
    cache.Insert(key, FieldOf(1000));
    EXPECT_TRUE(cache.Contains(key)) << key;
  }
  EXPECT_TRUE(cache.Contains("hot"));
  EXPECT_FALSE(cache.Contains("once8"));
  EXPECT_EQ(cache.entries(), 2u);
}

TEST(FieldCacheTest, AFieldThatWouldEvictMoreAskedOnesIsDeclined) {
  FieldCache cache(TwoFields());
  for (const char* key : {"a", "b"}) {
    for (int i = 0; i < 3; ++i) cache.Find(key);
    cache.Insert(key, FieldOf(1000));
  }
  EXPECT_EQ(cache.Find("new"), nullptr);  // asked once: less than either
  cache.Insert("new", FieldOf(1000));
  EXPECT_FALSE(cache.Contains("new"));
  EXPECT_TRUE(cache.Contains("a"));
  EXPECT_TRUE(cache.Contains("b"));
  EXPECT_EQ(cache.declined(), 1u);
  // Asked as often as the least-asked entry, it is kept (that entry goes).
  cache.Find("new");
  cache.Find("new");
  cache.Insert("new", FieldOf(1000));
  EXPECT_TRUE(cache.Contains("new"));
  EXPECT_EQ(cache.entries(), 2u);
}

TEST(FieldCacheTest, APathSourceIsOfferedOnItsSecondAsk) {
  FieldCache cache(TwoFields());
  EXPECT_EQ(cache.Find("start"), nullptr);
  EXPECT_FALSE(cache.NotePathSource("start"));
  EXPECT_EQ(cache.Find("start"), nullptr);
  EXPECT_TRUE(cache.NotePathSource("start"));
}

TEST(FieldCacheTest, TheAskHistoryIsBoundedAndAges) {
  FieldCache cache(TwoFields());
  for (int i = 0; i < 3; ++i) cache.Find("old");
  // Many distinct keys fill the history: the counts are halved (one-off keys forgotten), so
  // "old" keeps 1 of its 3 asks after the first halving and is forgotten after the second.
  for (int i = 0; i < 5000; ++i) cache.Find("k" + std::to_string(i));
  EXPECT_EQ(cache.asks("old"), 1u);
  for (int i = 5000; i < 10000; ++i) cache.Find("k" + std::to_string(i));
  EXPECT_EQ(cache.asks("old"), 0u);
}

}  // namespace
}  // namespace geodex::server
