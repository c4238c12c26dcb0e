// How rad-movies cuts movies into render-farm pieces and deals them to the shards (issue 58;
// docs/design.md §6.3, §7; formats/texture_movie_piece.md "The cut"). Two rules:
//
// - By keys (--piece-keys K): a movie of N > K keys is ceil(N / K) pieces; every movie's pieces
//   are dealt to the shards in id and piece order. Nothing about cost is known before baking.
// - By known cost (--piece-costs REPORT... --piece-seconds T): the movies reports of an earlier
//   run of the same movies (rad-movies --report; their work_seconds) give each movie's seconds s
//   and planning p. A movie of s > T seconds is min(N, ceil(s / T)) pieces, each estimated at
//   p + (s - p) n / N for its n keys (every piece plans the whole movie, §6.3); the cheap ones
//   stay whole, so they pay their planning once. The units are dealt longest first, each to the
//   shard with the least estimated work so far (list scheduling), so that the farm's longest
//   task is short. A movie the reports do not name is cut by keys. The cut decides only which
//   task bakes which keys: every key is the whole bake's and the merged movie its bytes.
//
// Every task and the merge compute the same cut from the same reports (read in the order given),
// so the tasks need not talk to each other.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace rad {

class MovieCut {
 public:
  // By keys only (pieceKeys <= 0: every movie whole).
  explicit MovieCut(int pieceKeys = 0) : pieceKeys_(pieceKeys) {}
  // By known cost from `reports` (rad-movies --report files); pieceKeys for the movies they do
  // not name. Throws rad::inputError(report, ...) for a report that cannot be read or holds no
  // work_seconds, a usage Error for pieceSeconds <= 0.
  static MovieCut fromReports(const std::vector<std::string>& reports, double pieceSeconds,
                              int pieceKeys);

  // The pieces of movie `movie` of `keys` keys (1: baked whole).
  int pieceCount(uint32_t movie, int keys) const;
  // Whether any movie may be cut (false: every movie whole, no merge).
  bool cuts() const { return pieceKeys_ > 0 || !costs_.empty(); }
  bool byCost() const { return !costs_.empty(); }
  // The estimated seconds of piece `index` of `count` of the movie (0 when it is not in the
  // reports): what the deal by cost balances.
  double estimate(uint32_t movie, int keys, int index, int count) const;

 private:
  struct Cost {
    double seconds = 0.0, plan = 0.0;
  };
  int pieceKeys_ = 0;
  double pieceSeconds_ = 0.0;
  std::map<uint32_t, Cost> costs_;
};

// Deals units of estimated seconds `estimates` to `shards` shards, longest first (ties: lower
// unit first), each to the shard with the least so far (ties: the lower shard). Returns each
// unit's shard.
std::vector<int> dealByCost(const std::vector<double>& estimates, int shards);

}  // namespace rad
