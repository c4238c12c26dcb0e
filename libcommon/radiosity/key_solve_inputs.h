// What the space-time pass (space_time_radiosity.h, paper §4.2) derives from the animated
// scene for a key-time solve's KeySolveInput: which top-level patches move over an interval,
// the cluster hierarchy to link from, the top-level patches' transforms at a time, and which
// of the previous key's cluster links stay valid. Pure functions of the scene and the times:
// deterministic.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "libcommon/radiosity/cluster_links.h"
#include "libcommon/radiosity/cluster_tree.h"
#include "libcommon/radiosity/hierarchical_radiosity.h"
#include "libcommon/scene/patch_hierarchy.h"
#include "libcommon/scene/scene.h"

namespace rad {

// Per top-level patch: its node moves somewhere in [t0, t1] (KeySolveInput::movingTops).
std::vector<char> movingTopsOf(const Scene& scene, const PatchHierarchy& hierarchy, double t0,
                               double t1);

// Values of `previous`'s cluster links (solved at t0) that stay valid until t1: both ends static
// over [t0, t1] and no moving node's swept bounds meeting the box around both ends (the convex
// hull of the two lies in it).
ClusterLinkCache reusableClusterLinks(const KeySolution& previous, const ClusterTree& tree,
                                      const PatchHierarchy& hierarchy, const Scene& scene,
                                      double t0, double t1);

// The cluster hierarchy of the animation [t0, t1] (KeySolveInput::clusters): static patches
// placed at t0, each moving node's in its own frame.
ClusterTree clusterTreeOf(const Scene& scene, const PatchHierarchy& hierarchy, double t0,
                          double t1);

// World transform of every top-level patch's node at time t.
std::vector<glm::dmat4> topTransforms(const Scene& scene, const PatchHierarchy& hierarchy,
                                      double t);

}  // namespace rad
