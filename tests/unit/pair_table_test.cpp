// PairTable (the coherence caches' lookup): every key finds its value, against std::map.

#include "libcommon/radiosity/pair_table.h"

#include <map>
#include <random>

#include <gtest/gtest.h>

namespace rad {
namespace {

TEST(PairTable, FindsEveryKeyAndNothingElseAsAMapDoes) {
  std::mt19937 rng(7);
  const uint32_t rows = 50;
  std::vector<std::pair<uint32_t, uint32_t>> keys;
  std::vector<int> values;
  std::map<std::pair<uint32_t, uint32_t>, int> expected;
  for (int i = 0; i < 2000; ++i) {
    std::pair<uint32_t, uint32_t> k{uint32_t(rng() % rows), uint32_t(rng() % 300)};
    keys.push_back(k);
    values.push_back(i);
    expected.emplace(k, i);  // the first of equal keys, as the table finds
  }
  const PairTable<int> table(keys, values, rows);
  EXPECT_EQ(table.size(), keys.size());
  for (uint32_t r = 0; r < rows + 3; ++r)
    for (uint32_t c = 0; c < 310; ++c) {
      auto it = expected.find({r, c});
      const int* found = table.find(r, c);
      if (it == expected.end()) {
        EXPECT_EQ(found, nullptr) << r << ", " << c;
      } else {
        ASSERT_NE(found, nullptr) << r << ", " << c;
        EXPECT_EQ(*found, it->second) << r << ", " << c;
      }
    }
}

TEST(PairTable, AnEmptyTableFindsNothing) {
  EXPECT_EQ(PairTable<int>().find(0, 0), nullptr);
  const PairTable<int> noEntries({}, {}, 4);
  EXPECT_TRUE(noEntries.empty());
  EXPECT_EQ(noEntries.find(3, 0), nullptr);
  EXPECT_EQ(noEntries.find(4, 0), nullptr);
}

}  // namespace
}  // namespace rad
