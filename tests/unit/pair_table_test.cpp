// PairTable (the coherence caches' lookup): every key finds its value, against std::map.
// sortByRow (the stable counting sort by row the tables and rad-global's lists use): the order
// of std::stable_sort, in one pass or in parallel parts, whatever the thread count.

#include "libcommon/radiosity/pair_table.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <random>

#include <tbb/task_arena.h>

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

// Large enough for the parallel parts (2^16 items a part at least), and small for one pass.
TEST(SortByRow, IsTheStableSortOfTheItemsByRowInPartsOrInOnePass) {
  for (const size_t n : {size_t(1000), size_t(300000)}) {
    std::mt19937 rng(11);
    const uint32_t rows = 97;
    std::vector<uint32_t> row(n);
    for (uint32_t& r : row) r = uint32_t(rng() % rows);
    std::vector<uint32_t> expected(n);
    std::iota(expected.begin(), expected.end(), 0u);
    std::stable_sort(expected.begin(), expected.end(),
                     [&](uint32_t a, uint32_t b) { return row[a] < row[b]; });
    for (const int threads : {1, 2}) {
      RowOrder got;
      tbb::task_arena(threads).execute(
          [&] { got = sortByRow(n, rows, [&](size_t i) { return row[i]; }); });
      EXPECT_EQ(got.order, expected) << n << " items, " << threads << " threads";
      ASSERT_EQ(got.rowStart.size(), size_t(rows) + 1);
      EXPECT_EQ(got.rowStart.front(), 0u);
      EXPECT_EQ(got.rowStart.back(), uint32_t(n));
      for (uint32_t r = 0; r < rows; ++r)
        for (uint32_t k = got.rowStart[r]; k < got.rowStart[r + 1]; ++k)
          ASSERT_EQ(row[got.order[k]], r) << n << " items, row " << r;
    }
  }
}

}  // namespace
}  // namespace rad
