#include "formats/key_window.h"

#include <cmath>

#include "formats/link_hierarchy.h"

namespace rad {

namespace {

static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 is not 3 packed floats");

std::vector<glm::vec3> unflatten(const std::vector<float>& f) {
  std::vector<glm::vec3> out(f.size() / 3);
  for (size_t i = 0; i < out.size(); ++i) out[i] = {f[i * 3], f[i * 3 + 1], f[i * 3 + 2]};
  return out;
}

// A non-negative integer of the metadata, or a one-line error naming the key.
uint64_t metadataCount(const ContainerReader& r, const char* key) {
  const nlohmann::json& m = r.metadata();
  const auto it = m.find(key);
  if (it == m.end() || !it->is_number_unsigned())
    throw inputError(
        r.path(), std::string("metadata \"") + key + "\" is missing or not a non-negative integer");
  return it->get<uint64_t>();
}

// Array `name` with exactly `count` elements of T.
template <class T>
std::vector<T> sizedArray(const ContainerReader& r, const std::string& name, uint64_t count) {
  std::vector<T> a = r.array<T>(name);
  if (a.size() != count)
    throw inputError(r.path(), "array '" + name + "' has " + std::to_string(a.size()) +
                                   " values; expected " + std::to_string(count));
  return a;
}

}  // namespace

void writeKeyWindow(const std::string& path, const KeyWindow& w, const Provenance& provenance,
                    const nlohmann::json& metadata) {
  w.validate(path);
  ContainerWriter out(kKeyWindowKind, kKeyWindowMajor, kKeyWindowMinor);
  out.setProvenance(provenance);
  nlohmann::json& m = out.metadata();
  m = metadata.is_object() ? metadata : nlohmann::json::object();
  const size_t N = size_t(w.hierarchy.size()), K = w.keyCount(), M = w.links.size();
  const size_t T = size_t(w.hierarchy.topCount());
  m["key_count"] = K;
  m["node_count"] = N;
  m["link_count"] = M;
  m["top_count"] = T;
  m["first_key"] = w.firstKey;
  nlohmann::json reports = nlohmann::json::array();
  for (const KeyTimeReport& r : w.reports) reports.push_back(r.toJson());
  m["key_reports"] = reports;

  out.addArray("key_times", w.keyTimes);
  out.addArray("key_node_count", w.nodeCount);
  std::vector<uint64_t> ids(N);
  for (size_t i = 0; i < N; ++i) ids[i] = w.hierarchy.node(int(i)).id.packed();
  out.addArray("node_ids", ids);
  out.addRawView("node_radiosity", DType::kF32, {N, K, 3}, w.radiosity.data(),
                 w.radiosity.size() * sizeof(glm::vec3));
  out.addArrayView("node_exposure", w.exposure, {N, K});
  out.addArrayView("node_good_closure", w.goodClosure, {N, K});
  const LinkRowArrays rows = encodeLinkRows(w.links);
  out.addArrayView("links", rows.cols, {M, 6});
  out.addArrayView("link_flags", rows.flags);
  out.addArrayView("link_values", w.linkValues);
  out.addArrayView("link_visibility", w.linkVisibility);
  out.addArray("bad_pairs", encodeBadPairs(w.badPairs), {w.badPairs.size(), 2});
  if (!w.clusterIrradiance.empty())
    out.addRawView("top_cluster_irradiance", DType::kF32, {T, K, 3}, w.clusterIrradiance.data(),
                   w.clusterIrradiance.size() * sizeof(glm::vec3));
  out.write(path);
}

KeyWindow readKeyWindow(const ContainerReader& r, const Scene& scene) {
  const std::string& where = r.path();
  r.requireKind(kKeyWindowKind, kKeyWindowMajor);
  KeyWindow w;
  w.keyTimes = r.array<double>("key_times");
  const uint64_t K = w.keyTimes.size();
  if (metadataCount(r, "key_count") != K)
    throw inputError(where, "metadata key_count differs from the key times' number");
  const uint64_t firstKey = metadataCount(r, "first_key");
  if (firstKey > UINT32_MAX) throw inputError(where, "first_key is out of range");
  w.firstKey = uint32_t(firstKey);
  std::vector<uint64_t> ids = r.array<uint64_t>("node_ids");
  w.hierarchy = hierarchyFromNodeIds(ids, scene, int64_t(metadataCount(r, "top_count")), where);
  const uint64_t N = ids.size(), T = uint64_t(w.hierarchy.topCount());
  // Products of sizes from the file: each factor is bounded by an array's length, so none
  // overflows before the array comparison fails.
  w.nodeCount = sizedArray<uint32_t>(r, "key_node_count", K);
  w.radiosity = unflatten(sizedArray<float>(r, "node_radiosity", N * K * 3));
  w.exposure = sizedArray<float>(r, "node_exposure", N * K);
  w.goodClosure = sizedArray<float>(r, "node_good_closure", N * K);
  w.links = readLinkRows(r, where);
  w.linkValues = r.array<float>("link_values");
  w.linkVisibility = r.array<float>("link_visibility");
  w.badPairs = readBadPairs(r, where);
  if (r.has("top_cluster_irradiance"))
    w.clusterIrradiance = unflatten(sizedArray<float>(r, "top_cluster_irradiance", T * K * 3));
  const auto reports = r.metadata().find("key_reports");
  if (reports != r.metadata().end() && reports->is_array() && reports->size() == K)
    for (const nlohmann::json& j : *reports) w.reports.push_back(KeyTimeReport::fromJson(j));
  w.validate(where);
  return w;
}

void requireSameRun(const ContainerReader& r, const nlohmann::json& parameters,
                    const std::string& sceneHash) {
  std::vector<std::string> keys;
  for (const auto& [key, value] : parameters.items()) keys.push_back(key);
  const std::vector<std::string> differ =
      parameterMismatch(r.provenance().parameters, parameters, keys);
  if (!differ.empty()) throw inputError(r.path(), differ.front());
  const std::vector<InputRecord>& inputs = r.provenance().inputs;
  if (inputs.empty() || inputs.front().hash != sceneHash)
    throw inputError(r.path(),
                     "was computed from another scene (" +
                         (inputs.empty() ? std::string("none recorded") : inputs.front().hash) +
                         "; this scene is " + sceneHash + ")");
}

std::vector<KeyWindow> readKeyWindows(const std::vector<std::string>& paths, const Scene& scene,
                                      const nlohmann::json& parameters,
                                      const std::string& sceneHash) {
  std::vector<KeyWindow> windows;
  for (const std::string& path : paths) {
    const ContainerReader r = ContainerReader::open(path);
    r.requireKind(kKeyWindowKind, kKeyWindowMajor);
    requireSameRun(r, parameters, sceneHash);
    windows.push_back(readKeyWindow(r, scene));
  }
  return windows;
}

nlohmann::json summarizeKeyWindow(const ContainerReader& r) {
  nlohmann::json j;
  const nlohmann::json& m = r.metadata();
  const std::vector<double> keys = r.array<double>("key_times");
  j["window"] = {{"frames", m.value("window", nlohmann::json())},
                 {"first_key", m.value("first_key", nlohmann::json())},
                 {"keys", keys.size()},
                 {"run_keys", m.value("run_key_count", nlohmann::json())}};
  if (!keys.empty()) j["key_times"] = {{"first", keys.front()}, {"last", keys.back()}};
  j["nodes"] = r.info("node_ids").count();
  const std::vector<uint8_t> flags = r.array<uint8_t>("link_flags");
  size_t refined = 0;
  for (uint8_t f : flags) refined += (f & kLinkRefined) != 0;
  j["link_rows"] = {{"total", flags.size()}, {"refined", refined}};
  j["bad_pairs"] = r.info("bad_pairs").count() / 2;
  const std::vector<float> b = r.array<float>("node_radiosity");
  size_t nonFinite = 0;
  float maxB = 0.0f;
  for (float x : b) {
    if (!std::isfinite(x))
      ++nonFinite;
    else
      maxB = std::max(maxB, x);
  }
  j["radiosity"] = {{"max", maxB}, {"non_finite", nonFinite}};
  return j;
}

}  // namespace rad
