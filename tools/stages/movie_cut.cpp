// The cut of movies into render-farm pieces. Contracts in movie_cut.h.
#include "tools/stages/movie_cut.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
#include <sstream>

#include <nlohmann/json.hpp>

#include "libcommon/core/error.h"

namespace rad {

MovieCut MovieCut::fromReports(const std::vector<std::string>& reports, double pieceSeconds,
                               int pieceKeys) {
  if (!(pieceSeconds > 0.0)) throw Error(ExitCode::kUsage, "--piece-seconds", "must be > 0");
  MovieCut cut(pieceKeys);
  cut.pieceSeconds_ = pieceSeconds;
  // Per movie: the seconds and planning of its units; a movie baked in n pieces paid its
  // planning n times, the whole bake once.
  struct Sum {
    double seconds = 0.0, plan = 0.0;
    int units = 0;
  };
  std::map<uint32_t, Sum> sums;
  for (const std::string& path : reports) {
    std::ifstream in(path);
    if (!in) throw inputError(path, "cannot read the movies report");
    std::stringstream text;
    text << in.rdbuf();
    nlohmann::json report;
    try {
      report = nlohmann::json::parse(text.str());
    } catch (const nlohmann::json::exception& e) {
      throw inputError(path, std::string("not a rad-movies report: ") + e.what());
    }
    if (!report.contains("work_seconds") || !report["work_seconds"].is_array())
      throw inputError(path, "no work_seconds: not a rad-movies --report of this version");
    for (const nlohmann::json& w : report["work_seconds"]) {
      Sum& s = sums[w.at("movie").get<uint32_t>()];
      s.seconds += w.at("seconds").get<double>();
      s.plan += w.at("seconds_plan").get<double>();
      ++s.units;
    }
  }
  for (const auto& [movie, s] : sums) {
    const double plan = s.plan / s.units;
    cut.costs_[movie] = {std::max(plan, s.seconds - (s.units - 1) * plan), plan};
  }
  return cut;
}

int MovieCut::pieceCount(uint32_t movie, int keys) const {
  const auto it = costs_.find(movie);
  if (it == costs_.end())
    return pieceKeys_ > 0 && keys > pieceKeys_ ? (keys + pieceKeys_ - 1) / pieceKeys_ : 1;
  const double pieces = std::ceil(it->second.seconds / pieceSeconds_);
  return std::max(1, std::min(keys, pieces >= double(keys) ? keys : int(pieces)));
}

double MovieCut::estimate(uint32_t movie, int keys, int index, int count) const {
  const auto it = costs_.find(movie);
  if (it == costs_.end() || keys <= 0) return 0.0;
  const Cost& c = it->second;
  const int n = int(int64_t(keys) * (index + 1) / count - int64_t(keys) * index / count);
  return c.plan + (c.seconds - c.plan) * double(n) / double(keys);
}

std::vector<int> dealByCost(const std::vector<double>& estimates, int shards) {
  std::vector<size_t> order(estimates.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return estimates[a] > estimates[b]; });
  std::vector<double> load(size_t(std::max(1, shards)), 0.0);
  std::vector<int> shardOf(estimates.size(), 0);
  for (size_t u : order) {
    const size_t s = size_t(std::min_element(load.begin(), load.end()) - load.begin());
    load[s] += estimates[u];
    shardOf[u] = int(s);
  }
  return shardOf;
}

}  // namespace rad
