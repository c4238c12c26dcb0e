// The links' activity intervals of the space-time merge (libcommon/radiosity/link_intervals.h):
// a link's rows follow its runs of keys, and the rows grow once a key, not row by row.
#include "libcommon/radiosity/link_intervals.h"

#include <vector>

#include <gtest/gtest.h>

namespace rad {
namespace {

std::vector<LinkIntervals::KeyValue> valuesOf(int links, float fv, bool refined = false) {
  std::vector<LinkIntervals::KeyValue> v;
  for (int i = links - 1; i >= 0; --i)  // in reverse order: addKey sorts them
    v.push_back({LinkIntervals::linkOf(i + 1, 2 * i + 1), fv, 1.0f, refined});
  return v;
}

// A run goes on while the keys are consecutive and the refined flag stays; a gap or a change
// starts a row; a changed F·V keeps the run's values.
TEST(LinkIntervals, RowsFollowEachLinksRunsOfKeys) {
  LinkIntervals li;
  li.addKey(valuesOf(3, 0.5f), 0);
  li.addKey(valuesOf(3, 0.5f), 1);  // the runs go on
  EXPECT_EQ(li.rowCount(), 3u);
  std::vector<LinkIntervals::KeyValue> third = valuesOf(3, 0.5f);
  third[0].refined = true;  // link (3, 5): a new row
  third[1].fv = 0.25f;      // link (2, 3): its run keeps values
  li.addKey(third, 2);
  EXPECT_EQ(li.rowCount(), 4u);
  li.addKey(valuesOf(2, 0.5f), 4);  // a gap: links (1, 1) and (2, 3) start rows
  EXPECT_EQ(li.rowCount(), 6u);
  const auto links = li.takeSortedLinks();
  ASSERT_EQ(links.size(), 3u);
  // (1, 1): keys 0-2 (one run, constant), then 4.
  const LinkIntervals::Row& a = li.row(links[0].second);
  EXPECT_EQ(a.firstKey, 0u);
  EXPECT_EQ(a.lastKey, 2u);
  EXPECT_TRUE(a.constant);
  EXPECT_NE(a.nextRow, LinkIntervals::kNone);
  EXPECT_EQ(li.row(a.nextRow).firstKey, 4u);
  // (2, 3): keys 0-2, its F·V changed at 2, so every key's value is kept.
  const LinkIntervals::Row& c = li.row(links[1].second);
  EXPECT_FALSE(c.constant);
  EXPECT_EQ(LinkIntervals::sampleCount(c), 3u);
  // (3, 5): keys 0-1 unrefined, 2 refined.
  const LinkIntervals::Row& d = li.row(links[2].second);
  EXPECT_EQ(d.lastKey, 1u);
  EXPECT_TRUE(li.row(d.nextRow).refined);
}

// The first key makes a row for nearly every link at once: the rows are allocated once, at the
// size the key needs. Grown row by row (by an eighth), each step copied every row so far, and
// the copy beside the rows set rad-global's peak on a one-key run (docs/results.md, "rad-global's
// peak on the bathroom"). A key whose runs all go on allocates nothing.
TEST(LinkIntervals, RowsGrowOnceAKey) {
  LinkIntervals li;
  const int n = 100000;
  li.addKey(valuesOf(n, 0.5f), 0);
  EXPECT_EQ(li.rowCount(), size_t(n));
  EXPECT_EQ(li.rowCapacity(), size_t(n));
  li.addKey(valuesOf(n, 0.5f), 1);
  EXPECT_EQ(li.rowCount(), size_t(n));
  EXPECT_EQ(li.rowCapacity(), size_t(n));
  li.addKey(valuesOf(n, 0.5f, true), 2);  // every link changes its flag: n new rows
  EXPECT_EQ(li.rowCount(), size_t(2 * n));
  EXPECT_EQ(li.rowCapacity(), size_t(2 * n));
}

}  // namespace
}  // namespace rad
