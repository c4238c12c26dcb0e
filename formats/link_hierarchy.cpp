#include "formats/link_hierarchy.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace rad {

namespace {

std::vector<glm::vec3> unflatten(const std::vector<float>& f) {
  std::vector<glm::vec3> out(f.size() / 3);
  for (size_t i = 0; i < out.size(); ++i) out[i] = {f[i * 3], f[i * 3 + 1], f[i * 3 + 2]};
  return out;
}

}  // namespace

PatchHierarchy hierarchyFromNodeIds(const std::vector<uint64_t>& ids, const Scene& scene,
                                    int64_t topCount, const std::string& where) {
  PatchHierarchy h(scene.inputPolygons());
  const size_t tops = size_t(h.topCount());
  if (ids.size() < tops || topCount != int64_t(tops))
    throw inputError(where, "was computed for a scene with " + std::to_string(topCount) +
                                " top-level patches; this scene has " + std::to_string(tops));
  for (size_t i = 0; i < tops; ++i)
    if (ids[i] != PatchId{uint32_t(i), 1}.packed())
      throw inputError(
          where, "node " + std::to_string(i) + " is not top-level patch " + std::to_string(i));
  for (size_t i = tops; i < ids.size();) {
    PatchId id = PatchId::fromPacked(ids[i]);
    if (id.top >= tops || id.level() < 1 || id.level() > PatchId::kMaxLevel || id.childIndex() != 0)
      throw inputError(where, "node " + std::to_string(i) + " has an invalid id");
    int parent = h.find(id.parent());
    if (parent < 0 || !h.isLeaf(parent) || i + 4 > ids.size())
      throw inputError(where, "node ids are not in subdivision order at node " + std::to_string(i));
    int first = h.subdivide(parent);
    for (int k = 0; k < 4; ++k)
      if (size_t(first + k) != i + k || h.node(first + k).id.packed() != ids[i + k])
        throw inputError(where,
                         "node ids are not in subdivision order at node " + std::to_string(i));
    i += 4;
  }
  return h;
}

void writeLinkHierarchy(const std::string& path, const GlobalSolution& s,
                        const Provenance& provenance, const nlohmann::json& metadata) {
  s.validate(path);
  ContainerWriter w(kLinkHierarchyKind, kLinkHierarchyMajor, kLinkHierarchyMinor);
  w.setProvenance(provenance);
  w.metadata() = metadata.is_object() ? metadata : nlohmann::json::object();
  size_t N = size_t(s.hierarchy.size()), K = s.keyTimes.size();
  w.metadata()["key_count"] = K;
  w.metadata()["node_count"] = N;
  w.metadata()["link_count"] = s.links.size();
  w.metadata()["top_count"] = s.hierarchy.topCount();

  w.addArray("key_times", s.keyTimes);
  std::vector<uint64_t> ids(N);
  std::vector<int32_t> parent(N);
  for (size_t i = 0; i < N; ++i) {
    ids[i] = s.hierarchy.node(int(i)).id.packed();
    parent[i] = s.hierarchy.node(int(i)).parent;
  }
  w.addArray("node_ids", ids);
  w.addArray("node_parent", parent);
  // The large arrays are handed to the writer as views (no copy): they stay alive in `s`
  // until w.write() below, and the file holds exactly their bytes (glm::vec3 is 3 floats).
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 is not 3 packed floats");
  w.addRawView("node_radiosity", DType::kF32, {N, K, 3}, s.nodeRadiosity.data(),
               s.nodeRadiosity.size() * sizeof(glm::vec3));
  if (!s.nodeExposure.empty()) w.addArrayView("node_exposure", s.nodeExposure, {N, K});
  w.addArray("leaf_row", s.leafRow);
  size_t L = s.leafVertexGoodIrradiance.size() / std::max<size_t>(1, K * 4);
  w.addRawView("leaf_vertex_good_irradiance", DType::kF32, {L, K, 4, 3},
               s.leafVertexGoodIrradiance.data(),
               s.leafVertexGoodIrradiance.size() * sizeof(glm::vec3));
  const LinkRowArrays rows = encodeLinkRows(s.links);
  w.addArrayView("links", rows.cols, {s.links.size(), 6});
  w.addArrayView("link_flags", rows.flags);
  w.addArrayView("link_sample_keys", s.linkSampleKeys);
  w.addArrayView("link_sample_values", s.linkSampleValues);
  if (!s.linkSampleVisibility.empty())
    w.addArrayView("link_sample_visibility", s.linkSampleVisibility);
  w.addArray("bad_pairs", encodeBadPairs(s.badPairs), {s.badPairs.size(), 2});
  if (!s.topClusterIrradiance.empty())  // since 1.3
    w.addRawView("top_cluster_irradiance", DType::kF32, {size_t(s.hierarchy.topCount()), K, 3},
                 s.topClusterIrradiance.data(), s.topClusterIrradiance.size() * sizeof(glm::vec3));
  w.write(path);
}

namespace {

// radiosityOnly: keyTimes, hierarchy, nodeRadiosity and leafRow only (links, link samples,
// good irradiance, bad pairs and cluster irradiance stay empty; readLinkHierarchyRadiosity).
GlobalSolution readSolution(const ContainerReader& r, const Scene& scene, bool radiosityOnly) {
  const std::string& where = r.path();
  r.requireKind(kLinkHierarchyKind, kLinkHierarchyMajor);
  GlobalSolution s;
  s.keyTimes = r.array<double>("key_times");
  size_t K = s.keyTimes.size();
  std::vector<uint64_t> ids = r.array<uint64_t>("node_ids");
  s.hierarchy =
      hierarchyFromNodeIds(ids, scene, r.metadata().value("top_count", int64_t(-1)), where);
  const size_t tops = size_t(s.hierarchy.topCount());
  size_t N = ids.size();
  std::vector<float> b = r.array<float>("node_radiosity");
  if (b.size() != N * K * 3) throw inputError(where, "node_radiosity has the wrong size");
  s.nodeRadiosity = unflatten(b);
  s.leafRow = r.array<int32_t>("leaf_row");
  // Since 1.2; rad-compose's fallback divides the lamps' leaf average by it.
  if (r.has("node_exposure")) s.nodeExposure = r.array<float>("node_exposure");
  if (radiosityOnly) {
    s.validateRadiosity(where);
    return s;
  }
  s.leafVertexGoodIrradiance = unflatten(r.array<float>("leaf_vertex_good_irradiance"));
  s.links = readLinkRows(r, where);
  s.linkSampleKeys = r.array<uint32_t>("link_sample_keys");
  s.linkSampleValues = r.array<float>("link_sample_values");
  if (r.has("link_sample_visibility"))  // since 1.2
    s.linkSampleVisibility = r.array<float>("link_sample_visibility");
  s.badPairs = readBadPairs(r, where);
  if (r.has("top_cluster_irradiance")) {  // since 1.3
    std::vector<float> h = r.array<float>("top_cluster_irradiance");
    if (h.size() != tops * K * 3)
      throw inputError(where, "top_cluster_irradiance has " + std::to_string(h.size()) +
                                  " values; expected " + std::to_string(tops * K * 3) + " (" +
                                  std::to_string(tops) + " tops x " + std::to_string(K) +
                                  " keys x 3)");
    s.topClusterIrradiance = unflatten(h);
  }
  s.validate(where);
  return s;
}

}  // namespace

LinkRowArrays encodeLinkRows(const std::vector<GlobalLink>& links) {
  LinkRowArrays a;
  a.cols.resize(links.size() * 6);
  a.flags.resize(links.size());
  for (size_t i = 0; i < links.size(); ++i) {
    const GlobalLink& l = links[i];
    const uint32_t row[6] = {l.receiver, l.shooter,      l.firstKey,
                             l.lastKey,  l.sampleOffset, l.sampleCount};
    std::copy(row, row + 6, a.cols.begin() + long(i) * 6);
    a.flags[i] = l.flags;
  }
  return a;
}

std::vector<uint32_t> encodeBadPairs(const std::vector<std::pair<uint32_t, uint32_t>>& pairs) {
  std::vector<uint32_t> out;
  out.reserve(pairs.size() * 2);
  for (const auto& [r, s] : pairs) out.insert(out.end(), {r, s});
  return out;
}

std::vector<GlobalLink> readLinkRows(const ContainerReader& r, const std::string& where) {
  const std::vector<uint32_t> cols = r.array<uint32_t>("links");
  const std::vector<uint8_t> flags = r.array<uint8_t>("link_flags");
  if (cols.size() != flags.size() * 6)
    throw inputError(where, "links and link_flags differ in size");
  std::vector<GlobalLink> links(flags.size());
  for (size_t i = 0; i < flags.size(); ++i) {
    const uint32_t* c = &cols[i * 6];
    links[i] = {c[0], c[1], c[2], c[3], c[4], c[5], flags[i]};
  }
  return links;
}

std::vector<std::pair<uint32_t, uint32_t>> readBadPairs(const ContainerReader& r,
                                                        const std::string& where) {
  const std::vector<uint32_t> pairs = r.array<uint32_t>("bad_pairs");
  if (pairs.size() % 2) throw inputError(where, "bad_pairs has an odd size");
  std::vector<std::pair<uint32_t, uint32_t>> out;
  out.reserve(pairs.size() / 2);
  for (size_t i = 0; i < pairs.size(); i += 2) out.emplace_back(pairs[i], pairs[i + 1]);
  return out;
}

GlobalSolution readLinkHierarchy(const ContainerReader& r, const Scene& scene) {
  return readSolution(r, scene, false);
}

GlobalSolution readLinkHierarchyRadiosity(const ContainerReader& r, const Scene& scene) {
  return readSolution(r, scene, true);
}

GlobalSolution readLinkHierarchy(const std::string& path, const Scene& scene) {
  return readLinkHierarchy(ContainerReader::open(path), scene);
}

nlohmann::json summarizeLinkHierarchy(const ContainerReader& r) {
  nlohmann::json j;
  std::vector<double> keys = r.array<double>("key_times");
  j["key_times"] =
      keys.empty()
          ? nlohmann::json(nullptr)
          : nlohmann::json{{"count", keys.size()}, {"first", keys.front()}, {"last", keys.back()}};
  std::vector<uint64_t> ids = r.array<uint64_t>("node_ids");
  std::map<int, int> perLevel;
  for (uint64_t id : ids) perLevel[PatchId::fromPacked(id).level()]++;
  nlohmann::json levels = nlohmann::json::object();
  for (auto& [l, n] : perLevel) levels[std::to_string(l)] = n;
  j["nodes"] = {{"total", ids.size()}, {"per_level", levels}};
  std::vector<uint8_t> flags = r.array<uint8_t>("link_flags");
  std::vector<uint32_t> cols = r.array<uint32_t>("links");
  size_t bad = 0, vis = 0, refined = 0, constant = 0;
  for (size_t i = 0; i < flags.size(); ++i) {
    bad += (flags[i] & kLinkBad) != 0;
    vis += (flags[i] & kLinkVisibilityEvent) != 0;
    refined += (flags[i] & kLinkRefined) != 0;
    if (i * 6 + 5 < cols.size()) constant += cols[i * 6 + 5] == 1;
  }
  j["links"] = {{"total", flags.size()},      {"bad", bad},
                {"good", flags.size() - bad}, {"refined", refined},
                {"visibility_events", vis},   {"single_sample", constant}};
  j["bad_pairs"] = r.info("bad_pairs").count() / 2;
  std::vector<float> b = r.array<float>("node_radiosity");
  size_t nonFinite = 0, negative = 0;
  float maxB = 0.0f;
  for (float x : b) {
    if (!std::isfinite(x))
      ++nonFinite;
    else {
      if (x < 0) ++negative;
      maxB = std::max(maxB, x);
    }
  }
  j["radiosity"] = {{"max", maxB}, {"non_finite", nonFinite}, {"negative", negative}};
  if (r.has("top_cluster_irradiance")) {  // since 1.3; the mean is over the finite values
    std::vector<float> h = r.array<float>("top_cluster_irradiance");
    size_t nonFiniteH = 0, negativeH = 0, finiteH = 0;
    double sumH = 0.0;
    float maxH = 0.0f;
    for (float x : h) {
      if (!std::isfinite(x)) {
        ++nonFiniteH;
        continue;
      }
      if (x < 0) ++negativeH;
      ++finiteH;
      sumH += x;
      maxH = std::max(maxH, x);
    }
    j["cluster_irradiance"] = {{"max", maxH},
                               {"mean", finiteH ? sumH / double(finiteH) : 0.0},
                               {"non_finite", nonFiniteH},
                               {"negative", negativeH}};
  }
  return j;
}

}  // namespace rad
