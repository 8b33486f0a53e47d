// SlotSet (rdm/bake/slot_set.h) against std::set on random and structured sets, its bytes as
// rdms.bin stores them, and rdms.bin in both formats.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <set>

#include "rdm/bake/slot_set.h"
#include "rdm/bake/unit_checkpoint.h"
#include "rdm/base/hash.h"

namespace rdm {
namespace {

std::vector<uint32_t> sortedOf(const std::set<uint32_t>& s) {
  return {s.begin(), s.end()};
}

// Clusters of runs and single indices over [0, range), as path sets look.
std::set<uint32_t> randomSet(std::mt19937& rng, uint32_t range) {
  std::set<uint32_t> s;
  const int clusters = int(rng() % 6);
  for (int c = 0; c < clusters; ++c) {
    const uint32_t start = rng() % range, length = rng() % 40;
    for (uint32_t v = start; v < std::min(range, start + length); ++v) s.insert(v);
  }
  const int singles = int(rng() % 20);
  for (int i = 0; i < singles; ++i) s.insert(rng() % range);
  return s;
}

TEST(SlotSet, MatchesStdSetForUnionAndIntersectionTests) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 500; ++trial) {
    const uint32_t range = trial % 2 ? 300u : 0xffffffffu;
    std::set<uint32_t> a = randomSet(rng, range), b = randomSet(rng, range);
    SlotSet set = SlotSet::fromSorted(sortedOf(a));
    ASSERT_EQ(set.values(), sortedOf(a));
    ASSERT_EQ(set.count(), a.size());
    const std::vector<uint32_t> probe = sortedOf(b);
    bool expect_meet = false;
    for (uint32_t v : b) expect_meet = expect_meet || a.count(v);
    ASSERT_EQ(set.meets(probe), expect_meet) << trial;
    set.unite(probe);
    a.insert(b.begin(), b.end());
    ASSERT_EQ(set.values(), sortedOf(a)) << trial;
    ASSERT_EQ(set.count(), a.size());
    ASSERT_EQ(set, SlotSet::fromSorted(sortedOf(a)));  // one encoding per set
    auto parsed = SlotSet::fromBytes(set.bytes(), a.size());
    ASSERT_TRUE(parsed.has_value());
    ASSERT_EQ(*parsed, set);
  }
}

TEST(SlotSet, ExtremesAndEmptySets) {
  SlotSet empty;
  EXPECT_TRUE(empty.empty());
  EXPECT_FALSE(empty.meets({0, 5}));
  empty.unite({});
  EXPECT_TRUE(empty.values().empty());
  SlotSet edge = SlotSet::fromSorted({0, 1, 0xfffffffeu, 0xffffffffu});
  EXPECT_EQ(edge.values(), (std::vector<uint32_t>{0, 1, 0xfffffffeu, 0xffffffffu}));
  EXPECT_TRUE(edge.meets({0xffffffffu}));
  EXPECT_FALSE(edge.meets({2, 3, 0xfffffffdu}));
  edge.unite({2, 0xfffffffdu});
  EXPECT_EQ(edge.count(), 6u);
}

// A path set that covers a 64 x 4 x 64 region of a 256 x 16 x 256 grid (x fastest): 256
// runs, at most 3 bytes each, against 65,536 x 4 bytes as u32 values.
TEST(SlotSet, ARegionTakesBytesPerRowNotPerSlot) {
  std::vector<uint32_t> region;
  for (uint32_t z = 100; z < 164; ++z)
    for (uint32_t y = 2; y < 6; ++y)
      for (uint32_t x = 50; x < 114; ++x) region.push_back((z * 16 + y) * 256 + x);
  const SlotSet set = SlotSet::fromSorted(region);
  EXPECT_EQ(set.count(), region.size());
  EXPECT_LE(set.bytes().size(), 256u * 4u);
  EXPECT_EQ(set.values(), region);
}

TEST(SlotSet, MalformedBytesAreRefused) {
  const SlotSet set = SlotSet::fromSorted({3, 4, 5, 90});
  std::string cut = set.bytes().substr(0, set.bytes().size() - 1);
  EXPECT_FALSE(SlotSet::fromBytes(cut, 100).has_value());
  EXPECT_FALSE(SlotSet::fromBytes(set.bytes(), 3).has_value());  // more indices than allowed
  std::string overflow = "\xff\xff\xff\xff\x7f";                 // gap 2^35 - 1
  EXPECT_FALSE(SlotSet::fromBytes(overflow + '\0', 100).has_value());
  std::string endless(12, '\x80');  // a varint that never ends
  EXPECT_FALSE(SlotSet::fromBytes(endless, 100).has_value());
}

std::string sealedBytes(std::string body) {
  const uint64_t h = contentHash(body);
  body.append(reinterpret_cast<const char*>(&h), sizeof(h));
  return body;
}

template <class T>
void put(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(v));
}

// rdms.bin of the previous format (u32 arrays, "RM RMDS1") still reads; the current one
// round-trips.
TEST(SlotSet, RdmRecordsReadBothFormats) {
  std::string v1;
  put(v1, uint64_t(0x3153444d52204d52ull));
  put(v1, uint64_t(1));
  for (int32_t v : {1, 2, 3, 7, 8}) put(v1, v);  // slot, level, size
  put(v1, uint64_t(3)), v1 += "j-1";
  put(v1, uint8_t(1));
  put(v1, uint64_t(3));
  for (uint32_t v : {4u, 5u, 9u}) put(v1, v);
  put(v1, uint64_t(1)), put(v1, uint32_t(4));
  auto old = decodeRdmRecords(sealedBytes(v1));
  ASSERT_TRUE(old.has_value()) << "the RDM id layout of rdms.bin changed";
  ASSERT_EQ(old->size(), 1u);
  EXPECT_EQ((*old)[0].origin_job, "j-1");
  EXPECT_TRUE((*old)[0].smooth);
  EXPECT_EQ((*old)[0].full_set.values(), (std::vector<uint32_t>{4, 5, 9}));
  EXPECT_EQ((*old)[0].first_set.values(), (std::vector<uint32_t>{4}));
  auto again = decodeRdmRecords(encodeRdmRecords(*old));
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ((*again)[0].full_set, (*old)[0].full_set);
  EXPECT_EQ((*again)[0].first_set, (*old)[0].first_set);
  std::string torn = encodeRdmRecords(*old);
  torn[torn.size() / 2] ^= 1;
  EXPECT_FALSE(decodeRdmRecords(torn).has_value());
}

}  // namespace
}  // namespace rdm
