// Values keyed by an ordered pair (row, column) of small non-negative integers, stored as a
// compressed row table: per row the start of its entries, and within a row the columns sorted.
// The coherence caches of rad-global (a key time's link values that the next key may take
// over, paper §4.2) are built once per key and looked up once per new link: an
// std::unordered_map costs ~100 bytes and one allocation per entry; this costs the value plus
// 8 bytes.
#pragma once

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

#include <tbb/parallel_for.h>

namespace rad {

// n items in row order by a stable counting sort (every rowOf(i) < rows): rowStart (rows + 1
// entries) and order, whose [rowStart[r], rowStart[r + 1]) are row r's items in their order.
struct RowOrder {
  std::vector<uint32_t> rowStart, order;
};
template <class RowOf>
RowOrder sortByRow(size_t n, uint32_t rows, RowOf rowOf) {
  RowOrder out;
  out.rowStart.assign(size_t(rows) + 1, 0);
  out.order.resize(n);
  // In parallel over up to kMaxParts fixed parts of the items (so the same whatever the thread
  // count): each counts its rows, and a row's items from part c follow those of the parts
  // before it, which is the one-pass order (a serial pass over the links leaves the other cores
  // idle at every round's gather lists).
  constexpr size_t kMinPart = size_t(1) << 16, kMaxParts = 16;
  const size_t parts = std::min(kMaxParts, (n + kMinPart - 1) / kMinPart);
  if (parts <= 1) {
    for (size_t i = 0; i < n; ++i) ++out.rowStart[size_t(rowOf(i)) + 1];
    std::partial_sum(out.rowStart.begin(), out.rowStart.end(), out.rowStart.begin());
    std::vector<uint32_t> fill(out.rowStart.begin(), out.rowStart.end() - 1);
    for (size_t i = 0; i < n; ++i) out.order[fill[rowOf(i)]++] = uint32_t(i);
    return out;
  }
  const size_t per = (n + parts - 1) / parts;
  std::vector<std::vector<uint32_t>> fill(parts);  // per part: its counts, then its next slots
  tbb::parallel_for(size_t(0), parts, [&](size_t c) {
    fill[c].assign(rows, 0);
    for (size_t i = c * per; i < std::min(n, (c + 1) * per); ++i) ++fill[c][rowOf(i)];
  });
  for (uint32_t r = 0; r < rows; ++r) {
    uint32_t at = out.rowStart[r];
    for (size_t c = 0; c < parts; ++c) {
      const uint32_t k = fill[c][r];
      fill[c][r] = at;
      at += k;
    }
    out.rowStart[size_t(r) + 1] = at;
  }
  tbb::parallel_for(size_t(0), parts, [&](size_t c) {
    for (size_t i = c * per; i < std::min(n, (c + 1) * per); ++i)
      out.order[fill[c][rowOf(i)]++] = uint32_t(i);
  });
  return out;
}

template <class V>
class PairTable {
 public:
  PairTable() = default;

  // Entry i is (keys[i].first, keys[i].second) -> values[i]; every row < rows. Of entries with
  // the same key, the first one is found.
  PairTable(const std::vector<std::pair<uint32_t, uint32_t>>& keys, std::vector<V> values,
            uint32_t rows) {
    const size_t n = keys.size();
    // Counting sort by row (stable), then each row by column (stable: the first of equal keys
    // stays first, and lower_bound finds it), the rows in parallel. The values stay where they
    // are, reached through the sorted order: moving the values into it, cycle by cycle, would be
    // most of the cache build, serially; the order kept is 4 bytes an entry, as a second array of
    // values would have been 40.
    RowOrder byRow = sortByRow(n, rows, [&](size_t i) { return keys[i].first; });
    rowStart_ = std::move(byRow.rowStart);
    entry_ = std::move(byRow.order);
    column_.resize(n);
    tbb::parallel_for(uint32_t(0), rows, [&](uint32_t r) {
      const auto first = entry_.begin() + rowStart_[r], last = entry_.begin() + rowStart_[r + 1];
      std::stable_sort(first, last,
                       [&](uint32_t a, uint32_t b) { return keys[a].second < keys[b].second; });
      for (uint32_t j = rowStart_[r]; j < rowStart_[r + 1]; ++j)
        column_[j] = keys[entry_[j]].second;
    });
    values_ = std::move(values);
  }

  static constexpr uint32_t kNotFound = ~uint32_t(0);

  // The entry of (row, column), or kNotFound.
  uint32_t indexOf(uint32_t row, uint32_t column) const {
    if (size_t(row) + 1 >= rowStart_.size()) return kNotFound;
    auto first = column_.begin() + rowStart_[row], last = column_.begin() + rowStart_[row + 1];
    auto it = std::lower_bound(first, last, column);
    return it != last && *it == column ? uint32_t(it - column_.begin()) : kNotFound;
  }
  // The value of (row, column), or null.
  const V* find(uint32_t row, uint32_t column) const {
    const uint32_t i = indexOf(row, column);
    return i == kNotFound ? nullptr : &values_[entry_[i]];
  }
  const V& value(uint32_t index) const { return values_[entry_[index]]; }

  size_t size() const { return values_.size(); }
  bool empty() const { return values_.empty(); }

 private:
  std::vector<uint32_t> rowStart_;  // rows + 1
  std::vector<uint32_t> column_;    // per entry, sorted within its row
  std::vector<uint32_t> entry_;     // per entry, the index of its value
  std::vector<V> values_;           // in the order given
};

}  // namespace rad
