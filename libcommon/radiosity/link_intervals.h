// The links' activity intervals of the space-time merge (paper §4.2), private to
// libcommon/radiosity: space_time_radiosity.cpp adds each key time's link values as the key is
// solved (or replays a key window's), and reads the rows back in (receiver, shooter) order for
// GlobalSolution's links and samples, or a KeyWindow's. Not thread-safe; one per space-time
// run.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>
#include <tuple>
#include <utility>
#include <vector>

#include <tbb/parallel_sort.h>

namespace rad {

// The links' activity intervals (paper §4.2), built incrementally as each key time finishes so
// that memory holds the compact result, not every key's links: per link, its rows (maximal runs
// of consecutive keys with the same refined flag) and, for a row whose F·V changes, its F·V at
// every key of the run. A row whose F·V has not changed (yet) keeps only its first value; when
// it first changes, the run so far is written out as copies of that value. The rows and their
// values are exactly those of GlobalSolution::links / linkSample* (keys are implied: a row's
// samples are at firstKey..lastKey, or only at firstKey when constant).
class LinkIntervals {
 public:
  static constexpr uint32_t kNone = ~uint32_t(0);

  struct Row {
    uint32_t firstKey = 0, lastKey = 0;
    float firstFv = 0, firstVisibility = 0;
    // (F·V, V) at every key of the run once one differed from (firstFv, firstVisibility) in
    // its bits, else none.
    uint32_t firstBlock = kNone, lastBlock = kNone;
    uint32_t valueCount = 0;
    uint32_t nextRow = kNone;  // the same link's next row (later keys)
    bool refined = false, constant = true, visibilityChanged = false;
  };

  struct LinkRows {
    uint32_t first, last;  // the link's first and last row
  };
  // One link's value at one key.
  struct KeyValue {
    uint64_t link;  // linkOf(receiver, shooter)
    float fv, visibility;
    bool refined;
  };
  static uint64_t linkOf(int receiver, int shooter) {
    return (uint64_t(uint32_t(receiver)) << 32) | uint32_t(shooter);
  }

  // Every link's value at key `key`; keys arrive in increasing order. The links so far are a
  // vector sorted by link, merged with this key's sorted values: 16 bytes per link instead of
  // a hash map's ~40.
  void addKey(std::vector<KeyValue> values, uint32_t key) {
    // Sorted in parallel (a serial sort leaves the other cores idle): a key's links
    // are distinct pairs, and were two the same, the order of the values' bits would place them
    // the same whatever the threads.
    tbb::parallel_sort(values.begin(), values.end(), [](const KeyValue& a, const KeyValue& b) {
      if (a.link != b.link) return a.link < b.link;
      const auto bits = [](const KeyValue& v) {
        uint32_t fv, vis;
        std::memcpy(&fv, &v.fv, sizeof fv);
        std::memcpy(&vis, &v.visibility, sizeof vis);
        return std::make_tuple(fv, vis, v.refined);
      };
      return bits(a) < bits(b);
    });
    // The new links counted first, so that the merged vector is allocated once at its size, and
    // the rows this key may start (at most), so that the rows grow once: grown row by row, the
    // copy of every row made so far at each step set rad-global's peak at key 0, which makes
    // nearly every row.
    size_t fresh = 0, newRows = 0;
    for (size_t i = 0, j = 0; i < values.size(); ++i) {
      while (j < links_.size() && links_[j].first < values[i].link) ++j;
      const bool known = j < links_.size() && links_[j].first == values[i].link;
      const bool repeated = i > 0 && values[i - 1].link == values[i].link;
      fresh += !known && !repeated ? 1 : 0;
      newRows +=
          !known || repeated || !continues(rows_[links_[j].second.last], key, values[i].refined)
              ? 1
              : 0;
    }
    if (rows_.size() + newRows > rows_.capacity())
      rows_.reserve(std::max(rows_.size() + newRows, rows_.size() + rows_.size() / 8 + 1024));
    std::vector<std::pair<uint64_t, LinkRows>> merged;
    merged.reserve(links_.size() + fresh);
    size_t j = 0;
    for (const KeyValue& v : values) {
      while (j < links_.size() && links_[j].first < v.link) merged.push_back(links_[j++]);
      if (j < links_.size() && links_[j].first == v.link) merged.push_back(links_[j++]);
      const bool isNew = merged.empty() || merged.back().first != v.link;
      if (isNew) merged.emplace_back(v.link, LinkRows{kNone, kNone});
      add(merged.back().second, isNew, key, v.fv, v.visibility, v.refined);
    }
    while (j < links_.size()) merged.push_back(links_[j++]);
    links_.swap(merged);
  }

  // Whether a value at key `key`, refined or not, goes on the run of row r (else it starts a row).
  static bool continues(const Row& r, uint32_t key, bool refined) {
    return r.lastKey + 1 == key && r.refined == refined;
  }

  // The link's value at key `key` (`fresh`: its first).
  void add(LinkRows& lr, bool fresh, uint32_t key, float fv, float visibility, bool refined) {
    if (!fresh) {
      Row& r = rows_[lr.last];
      if (continues(r, key, refined)) {  // the run goes on
        r.lastKey = key;
        r.visibilityChanged |= visibility != r.firstVisibility;
        r.constant &= fv == r.firstFv && visibility == r.firstVisibility;
        // Values are kept from the first one that differs in its bits (F·V or V changed, or
        // only the sign of a zero: such a row stays constant, but its values are kept exact).
        if (r.valueCount == 0 &&
            (!r.constant || !sameBits(fv, r.firstFv) || !sameBits(visibility, r.firstVisibility)))
          for (uint32_t k = r.firstKey; k < key; ++k) append(r, {r.firstFv, r.firstVisibility});
        if (r.valueCount > 0) append(r, {fv, visibility});
        return;
      }
    }
    // A new row: the link's first, or a gap / a change of the refined flag ends the last one.
    Row r;
    r.firstKey = r.lastKey = key;
    r.firstFv = fv;
    r.firstVisibility = visibility;
    r.refined = refined;
    uint32_t index = uint32_t(rows_.size());
    // Grown by an eighth, not doubled: key 0 makes nearly every row at once, and doubling
    // would leave up to as much again unused.
    if (rows_.size() == rows_.capacity()) rows_.reserve(rows_.size() + rows_.size() / 8 + 1024);
    rows_.push_back(r);
    if (fresh)
      lr.first = index;
    else
      rows_[lr.last].nextRow = index;
    lr.last = index;
  }

  // (link, first row) in ascending link order. Ends the adding (the link index is freed).
  std::vector<std::pair<uint64_t, uint32_t>> takeSortedLinks() {
    std::vector<std::pair<uint64_t, uint32_t>> v;
    v.reserve(links_.size());
    for (const auto& [key, lr] : links_) v.emplace_back(key, lr.first);
    std::vector<std::pair<uint64_t, LinkRows>>().swap(links_);
    return v;
  }
  const Row& row(uint32_t i) const { return rows_[i]; }
  size_t rowCount() const { return rows_.size(); }
  // The rows' allocated room: addKey grows it at most once a key, to at least what the key starts.
  size_t rowCapacity() const { return rows_.capacity(); }
  // The samples a row contributes to GlobalSolution::linkSample*.
  static uint32_t sampleCount(const Row& r) { return r.constant ? 1 : r.valueCount; }
  // Every key of the row has the bits of its first value (no per-key values kept).
  static bool sameBitsThroughout(const Row& r) { return r.valueCount == 0; }
  // Calls f(key, fv, visibility) for every key of the row's run.
  template <class F>
  void forEachKey(const Row& r, F&& f) const {
    if (r.valueCount == 0) {  // every value had the bits of the first
      for (uint32_t k = r.firstKey; k <= r.lastKey; ++k) f(k, r.firstFv, r.firstVisibility);
      return;
    }
    uint32_t k = r.firstKey, left = r.valueCount;
    for (uint32_t b = r.firstBlock; b != kNone && left > 0; b = block(b).next) {
      const Block& blk = block(b);
      for (uint32_t j = 0; j < kBlockValues && left > 0; ++j, --left)
        f(k++, blk.values[j].fv, blk.values[j].visibility);
    }
  }

 private:
  // Values live in fixed-size blocks chained per row, allocated from slabs that never move: no
  // per-link vector slack and no reallocation copies (a row wastes less than one block).
  struct Value {
    float fv, visibility;
  };
  static constexpr uint32_t kBlockValues = 7;
  struct Block {
    Value values[kBlockValues];
    uint32_t next;
  };
  static bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }
  static constexpr uint32_t kSlabShift = 14;  // 16384 blocks of 64 bytes: 1 MiB slabs

  Block& block(uint32_t i) { return slabs_[i >> kSlabShift][i & ((1u << kSlabShift) - 1)]; }
  const Block& block(uint32_t i) const {
    return slabs_[i >> kSlabShift][i & ((1u << kSlabShift) - 1)];
  }
  uint32_t newBlock() {
    if ((blockCount_ >> kSlabShift) >= slabs_.size())
      slabs_.push_back(std::make_unique<Block[]>(size_t(1) << kSlabShift));
    uint32_t i = blockCount_++;
    block(i).next = kNone;
    return i;
  }
  void append(Row& r, Value v) {
    uint32_t slot = r.valueCount % kBlockValues;
    if (slot == 0) {
      uint32_t b = newBlock();
      if (r.lastBlock == kNone)
        r.firstBlock = b;
      else
        block(r.lastBlock).next = b;
      r.lastBlock = b;
    }
    block(r.lastBlock).values[slot] = v;
    ++r.valueCount;
  }

  std::vector<std::pair<uint64_t, LinkRows>> links_;  // sorted by link
  std::vector<Row> rows_;
  std::vector<std::unique_ptr<Block[]>> slabs_;
  uint32_t blockCount_ = 0;
};

}  // namespace rad
