// TextureMovieBakerStats (texture_movie_baker.h): each counter named once, in forEachStat, from
// which --report's JSON and the sum over workers both come.
#include <algorithm>
#include <string>

#include "libcommon/movies/texture_movie_baker.h"

namespace rad {
namespace {

// Every counter of TextureMovieBakerStats, once: its group in --report's JSON ("" for the top
// level), its key there, and the field of each of `stats` (one or two records, so that one list
// serves toJson and operator+=). The warnings are not counters and are handled apart.
template <class F, class... Stats>
void forEachStat(F&& f, Stats&... stats) {
  f("", "movies", stats.movies...);
  f("", "constant_movies", stats.constantMovies...);
  f("", "keys", stats.keys...);
  f("", "texels", stats.texels...);
  f("", "bad_pairs", stats.badPairs...);
  f("", "static_pairs", stats.staticPairs...);
  f("", "dynamic_pairs", stats.dynamicPairs...);
  f("", "samples", stats.samples...);
  f("", "weak_pairs", stats.weakPairs...);
  f("", "blockers_static", stats.staticBlockers...);
  f("", "blockers_dynamic", stats.dynamicBlockers...);
  f("", "render_passes", stats.passes...);
  f("", "sample_passes", stats.samplePasses...);
  f("", "ray_cast_passes", stats.rayCastPasses...);
  f("", "render_passes_saved_by_coherence", stats.passesSavedByCoherence...);
  f("", "covered_texels_filled", stats.coveredTexelsFilled...);
  const char* gather = "good_layer_gather";
  f(gather, "links", stats.gather.links...);
  f(gather, "entries", stats.gather.entries...);
  f(gather, "cached_entries", stats.gather.cachedEntries...);
  f(gather, "tile_entries", stats.gather.tileEntries...);
  f(gather, "partial_links", stats.gather.partialLinks...);
  f(gather, "partial_links_moving_blockers", stats.gather.partialLinksMovingBlockers...);
  f(gather, "partial_links_few_rays", stats.gather.partialLinksFewRays...);
  f(gather, "partial_tile_links_per_texel", stats.gather.partialTileLinksPerTexel...);
  f(gather, "near_shooter_leaves", stats.gather.nearShooterLeaves...);
  f(gather, "near_shooter_seconds", stats.gather.nearShooterSeconds...);
  f("", "form_factor_texels", stats.formFactorTexels...);
  f("", "form_factor_texels_interpolated", stats.formFactorTexelsInterpolated...);
  const char* seconds = "seconds";
  f(seconds, "good_layer", stats.secondsGood...);
  f(seconds, "form_factors", stats.secondsFormFactor...);
  f(seconds, "transmittance", stats.secondsTransmittance...);
  f(seconds, "combine", stats.secondsCombine...);
  f(seconds, "form_factor_max_scan", stats.secondsFormFactorScan...);
}

}  // namespace

nlohmann::json TextureMovieBakerStats::toJson() const {
  nlohmann::json j = nlohmann::json::object();
  forEachStat([&](const char* group, const char* key,
                  const auto& value) { (*group ? j[group][key] : j[key]) = value; },
              *this);
  j["warnings"] = warnings;
  return j;
}

TextureMovieBakerStats& TextureMovieBakerStats::operator+=(const TextureMovieBakerStats& o) {
  forEachStat([](const char*, const char*, auto& mine, const auto& theirs) { mine += theirs; },
              *this, o);
  for (const std::string& w : o.warnings)
    if (std::find(warnings.begin(), warnings.end(), w) == warnings.end()) warnings.push_back(w);
  return *this;
}

}  // namespace rad
