// global.rlh: the space-time link hierarchy rad-global writes (container kind "linkhier").
// Arrays and metadata: formats/link_hierarchy.md.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/container.h"
#include "libcommon/radiosity/global_solution.h"
#include "libcommon/scene/scene.h"

namespace rad {

constexpr const char* kLinkHierarchyKind = "linkhier";
constexpr int kLinkHierarchyMajor = 1;
constexpr int kLinkHierarchyMinor = 3;

// Writes `solution` atomically. `metadata` (an object) is stored as the kind's metadata; the
// writer adds key_count, node_count, link_count, top_count.
void writeLinkHierarchy(const std::string& path, const GlobalSolution& solution,
                        const Provenance& provenance, const nlohmann::json& metadata);

// Reads and validates a linkhier container against the scene it was computed for: the
// top-level patches are rebuilt from scene.inputPolygons() and must agree in number; node ids
// must form the hierarchy in subdivision order. Errors are rad::inputError(path, ...).
GlobalSolution readLinkHierarchy(const ContainerReader& reader, const Scene& scene);
GlobalSolution readLinkHierarchy(const std::string& path, const Scene& scene);
// The same checks and content without the links, their F·V samples, the good irradiance, the bad
// pairs and the cluster irradiance (left empty): keyTimes, hierarchy, nodeRadiosity and leafRow,
// all rad-compose reads (radiosity(), leafAtTopUv, autoExposureEV), so that it holds none of the
// rest. The container's checksums still cover the arrays not copied.
GlobalSolution readLinkHierarchyRadiosity(const ContainerReader& reader, const Scene& scene);

// The hierarchy whose dense node ids are `ids` (node_ids of linkhier and keywindow files): the
// scene's top-level patches (`topCount`, from the file's metadata, must be their number), then
// groups of 4 siblings in subdivision order. Errors are rad::inputError(where, ...).
PatchHierarchy hierarchyFromNodeIds(const std::vector<uint64_t>& ids, const Scene& scene,
                                    int64_t topCount, const std::string& where);

// The `links` [M, 6] / `link_flags` [M] and `bad_pairs` [P, 2] arrays, as linkhier and keywindow
// files store them (formats/link_hierarchy.md): encoded for a writer (which keeps them alive
// while its views point at them) and decoded by a reader; errors are rad::inputError(where, ...).
struct LinkRowArrays {
  std::vector<uint32_t> cols;
  std::vector<uint8_t> flags;
};
LinkRowArrays encodeLinkRows(const std::vector<GlobalLink>& links);
std::vector<uint32_t> encodeBadPairs(const std::vector<std::pair<uint32_t, uint32_t>>& pairs);
std::vector<GlobalLink> readLinkRows(const ContainerReader& reader, const std::string& where);
std::vector<std::pair<uint32_t, uint32_t>> readBadPairs(const ContainerReader& reader,
                                                        const std::string& where);

// rad-inspect's content summary of a linkhier container (no scene needed).
nlohmann::json summarizeLinkHierarchy(const ContainerReader& reader);

}  // namespace rad
