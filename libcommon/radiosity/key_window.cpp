// The key-time records' JSON and the key window's consistency check (key_window.h).
#include "libcommon/radiosity/key_window.h"

#include <cmath>

#include "libcommon/core/error.h"

namespace rad {

nlohmann::json KeyTimeReport::toJson() const {
  nlohmann::json j = {{"time", time},
                      {"links", links},
                      {"recomputed", recomputed},
                      {"reused", reused},
                      {"visibility_only", visibilityOnly},
                      {"nodes", nodes},
                      {"iterations", iterations},
                      {"refine_rounds", refineRounds},
                      {"link_cap_reached", linkCapReached},
                      {"cluster_links", clusterLinks},
                      {"cluster_links_reused", clusterLinksReused},
                      {"seconds_links", secondsLinks},
                      {"seconds_solve", secondsSolve},
                      {"seconds_coherence", secondsCoherence}};
  if (lampValues > 0) {  // a scene with lamps only: the others' reports stay as they were
    j["lamp_values"] = lampValues;
    j["lamp_values_reused"] = lampValuesReused;
  }
  if (!linkCensus.is_null()) j["link_census"] = linkCensus;
  return j;
}

KeyTimeReport KeyTimeReport::fromJson(const nlohmann::json& j) {
  KeyTimeReport r;
  if (!j.is_object()) return r;
  r.time = j.value("time", 0.0);
  r.links = j.value("links", size_t(0));
  r.recomputed = j.value("recomputed", size_t(0));
  r.reused = j.value("reused", size_t(0));
  r.visibilityOnly = j.value("visibility_only", size_t(0));
  r.nodes = j.value("nodes", size_t(0));
  r.iterations = j.value("iterations", 0);
  r.refineRounds = j.value("refine_rounds", 0);
  r.linkCapReached = j.value("link_cap_reached", false);
  r.clusterLinks = j.value("cluster_links", size_t(0));
  r.clusterLinksReused = j.value("cluster_links_reused", size_t(0));
  r.lampValues = j.value("lamp_values", size_t(0));
  r.lampValuesReused = j.value("lamp_values_reused", size_t(0));
  r.secondsLinks = j.value("seconds_links", 0.0);
  r.secondsSolve = j.value("seconds_solve", 0.0);
  r.secondsCoherence = j.value("seconds_coherence", 0.0);
  if (j.contains("link_census")) r.linkCensus = j["link_census"];
  return r;
}

void KeyWindow::validate(const std::string& where) const {
  const size_t K = keyCount(), N = size_t(hierarchy.size()), T = size_t(hierarchy.topCount());
  auto fail = [&](const std::string& what) { throw inputError(where, what); };
  if (K == 0) fail("has no key times");
  for (size_t k = 0; k < K; ++k)
    if (!std::isfinite(keyTimes[k]) || (k > 0 && !(keyTimes[k] > keyTimes[k - 1])))
      fail("key times do not strictly increase at key " + std::to_string(k));
  if (nodeCount.size() != K)
    fail("has " + std::to_string(nodeCount.size()) + " node counts; expected one per key (" +
         std::to_string(K) + ")");
  for (size_t k = 0; k < K; ++k)
    if (nodeCount[k] < (k > 0 ? nodeCount[k - 1] : T) || (nodeCount[k] - T) % 4 != 0 ||
        nodeCount[k] > N || (k + 1 == K && nodeCount[k] != N))
      fail("node count " + std::to_string(nodeCount[k]) + " of key " + std::to_string(k) +
           " does not fit the " + std::to_string(N) + " nodes");
  if (radiosity.size() != N * K || exposure.size() != N * K || goodClosure.size() != N * K)
    fail("per-node arrays do not have nodes x keys = " + std::to_string(N * K) + " values");
  for (size_t i = 0; i < N * K; ++i) {
    const glm::vec3& b = radiosity[i];
    if (!(std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.z)))
      fail("radiosity of node " + std::to_string(i / K) + " is not finite");
    if (!(exposure[i] >= 0.0f && exposure[i] <= 1.0f))
      fail("exposure of node " + std::to_string(i / K) + " is not in [0, 1]");
    if (!std::isfinite(goodClosure[i]))
      fail("closure factor of node " + std::to_string(i / K) + " is not finite");
  }
  if (!clusterIrradiance.empty() && clusterIrradiance.size() != T * K)
    fail("cluster irradiance has " + std::to_string(clusterIrradiance.size()) +
         " values; expected tops x keys = " + std::to_string(T * K));
  if (linkValues.size() != linkVisibility.size())
    fail("link values and visibilities differ in number");
  for (size_t i = 0; i < links.size(); ++i) {
    const GlobalLink& l = links[i];
    const uint64_t span = uint64_t(l.lastKey) - l.firstKey + 1;
    if (l.receiver >= N || l.shooter >= N || l.firstKey > l.lastKey || l.lastKey >= K ||
        l.receiver >= nodeCount[l.firstKey] || l.shooter >= nodeCount[l.firstKey] ||
        (l.sampleCount != 1 && l.sampleCount != span) ||
        uint64_t(l.sampleOffset) + l.sampleCount > linkValues.size())
      fail("link row " + std::to_string(i) + " is out of range");
  }
  for (size_t i = 0; i < badPairs.size(); ++i)
    if (badPairs[i].first >= T || badPairs[i].second >= T ||
        (i > 0 && !(badPairs[i - 1] < badPairs[i])))
      fail("bad pair " + std::to_string(i) + " names no top or is out of order");
}

}  // namespace rad
