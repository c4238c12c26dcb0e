// The per-texel good-link gather (formula and sources in good_link_gather.h).
#include "libcommon/movies/good_link_gather.h"

#include <algorithm>
#include <array>
#include <map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "libcommon/radiosity/form_factor.h"

namespace rad {

GoodLinksByReceiver::GoodLinksByReceiver(const GlobalSolution& s) {
  const size_t N = size_t(s.hierarchy.size());
  start.assign(N + 1, 0);
  for (const GlobalLink& l : s.links)
    if (!(l.flags & (kLinkBad | kLinkRefined)) && l.receiver < N) ++start[l.receiver + 1];
  for (size_t i = 0; i < N; ++i) start[i + 1] += start[i];
  rows.resize(start[N]);
  std::vector<uint32_t> next(start.begin(), start.end() - 1);
  for (uint32_t r = 0; r < uint32_t(s.links.size()); ++r) {
    const GlobalLink& l = s.links[r];
    if (!(l.flags & (kLinkBad | kLinkRefined)) && l.receiver < N) rows[next[l.receiver]++] = r;
  }
}

GoodLinkGather::GoodLinkGather(const Scene& scene, const GlobalSolution& solution,
                               const GoodLinksByReceiver& byReceiver, const MovieExtent& request,
                               const MovieTexels& texels, const std::vector<double>& movieKeyTimes,
                               double shooterRatio, double weakShare, double cacheBytes,
                               GoodLinkGatherStats& stats)
    : scene_(scene),
      solution_(solution),
      shooterRatio_(shooterRatio),
      weakShare_(weakShare),
      texels_(texels),
      keyTimes_(movieKeyTimes),
      receiverTop_(int(request.patch.top)) {
  planLinks(byReceiver, request);
  // The global keys the movie's key times fall between.
  std::vector<char> needed(size_t(solution.keyCount()), 0);
  for (double t : keyTimes_) {
    int k0, k1;
    double w;
    solution.keyWeights(t, k0, k1, w);
    needed[size_t(k0)] = needed[size_t(k1)] = 1;
  }
  planWeights(needed);
  planTexels(cacheBytes);
  stats.links += long(links_.size());
  stats.entries += long(texelLinks_.size());
  if (cached_) stats.cachedEntries += long(texelLinks_.size());
  stats.interpolatedEntries += long(texelNodes_.size());
}

Polygon GoodLinkGather::nodeWorld(uint32_t node, double t) const {
  const PatchNode& n = solution_.hierarchy.node(int(node));
  return n.local.transformed(scene_.worldTransform(solution_.hierarchy.topOf(int(node)).node, t));
}

// The links whose receiver is the movie's node, one of its ancestors or one of its descendants:
// every texel's chain is made of these.
void GoodLinkGather::planLinks(const GoodLinksByReceiver& byReceiver, const MovieExtent& request) {
  const PatchHierarchy& h = solution_.hierarchy;
  std::vector<int> receivers;
  int movieNode = h.find(request.patch);
  for (PatchId id = request.patch; movieNode < 0 && id.level() > 0;) {  // deepest existing
    id = id.parent();
    movieNode = h.find(id);
  }
  if (movieNode < 0) movieNode = receiverTop_;
  for (int a = h.node(movieNode).parent; a >= 0; a = h.node(a).parent) receivers.push_back(a);
  std::vector<int> stack{movieNode};
  while (!stack.empty()) {
    const int n = stack.back();
    stack.pop_back();
    receivers.push_back(n);
    if (!h.isLeaf(n))
      for (int c = 0; c < 4; ++c) stack.push_back(h.node(n).firstChild + c);
  }
  std::sort(receivers.begin(), receivers.end());
  const double t0 = keyTimes_.front(), t1 = keyTimes_.back();
  const bool receiverMoves = scene_.isDynamic(h.top(receiverTop_).node, t0, t1);
  std::vector<uint32_t> shooters;
  for (int r : receivers) {
    const Polygon receiver = nodeWorld(uint32_t(r), t0);
    for (uint32_t k = byReceiver.start[size_t(r)]; k < byReceiver.start[size_t(r) + 1]; ++k) {
      const uint32_t row = byReceiver.rows[k];
      const uint32_t shooter = solution_.links[row].shooter;
      const bool moves = receiverMoves || scene_.isDynamic(h.topOf(int(shooter)).node, t0, t1);
      shooterParts(receiver, shooter, t0, shooters);
      for (uint32_t q : shooters) {
        Link l;
        l.row = row;
        l.shooter = q;
        l.moves = moves;
        links_.push_back(std::move(l));
      }
    }
  }
}

// The parts of a link's shooter a texel gathers from: the shooter's union sub-tree, descended
// while a node is larger than shooterRatio times its distance to the receiver. The point form
// factor weights the near part of a shooter most; with the shooter's B constant over a coarse
// node, two neighbouring receivers linked to different levels of the same wall would see its
// light with a step between them (3 % on the bundled scene's back wall). Near parts take their
// own B; far ones, over which F hardly varies, keep the link's node.
void GoodLinkGather::shooterParts(const Polygon& receiver, uint32_t shooter, double t,
                                  std::vector<uint32_t>& out) const {
  const PatchHierarchy& h = solution_.hierarchy;
  out.clear();
  std::vector<uint32_t> stack{shooter};
  while (!stack.empty()) {
    const uint32_t q = stack.back();
    stack.pop_back();
    bool split = !h.isLeaf(int(q)) && shooterRatio_ > 0.0;
    if (split) {
      const Polygon world = nodeWorld(q, t);
      double d = distanceToPolygon(receiver.centroid(), world);
      for (int i = 0; i < receiver.count; ++i)
        d = std::min(d, distanceToPolygon(receiver.v[i], world));
      split = polygonSize(world) > shooterRatio_ * d;
    }
    if (!split) {
      out.push_back(q);
      continue;
    }
    for (int c = 3; c >= 0; --c) stack.push_back(uint32_t(h.node(int(q)).firstChild + c));
  }
}

// Per link and needed global key: B_q(k) \bar V(k), with \bar V = V / e clamped to [0, 1] (a
// file before linkhier 1.2 has no V: F·V / (\bar F e), \bar F once for a link that does not
// move).
void GoodLinkGather::planWeights(const std::vector<char>& needed) {
  const int K = solution_.keyCount();
  const bool storedVisibility = !solution_.linkSampleVisibility.empty();
  tbb::parallel_for(size_t(0), links_.size(), [&](size_t j) {
    Link& l = links_[j];
    const GlobalLink& g = solution_.links[l.row];
    l.weight.assign(size_t(K), glm::dvec3(0.0));
    double fixedF = -1.0;
    for (int k = 0; k < K; ++k) {
      if (!needed[size_t(k)]) continue;
      const double fv = solution_.linkFvAtKey(g, k);
      if (!(fv > 0.0)) continue;
      double v = 1.0;
      if (storedVisibility) {
        v = solution_.linkVisibilityAtKey(g, k);
      } else {
        double f = fixedF;
        if (f < 0.0) {
          const double t = solution_.keyTimes[size_t(k)];
          f = areaAverageFormFactor(nodeWorld(g.receiver, t), nodeWorld(g.shooter, t), 1e-4);
          if (!l.moves) fixedF = f;
        }
        v = f > 0.0 ? fv / f : 0.0;
      }
      // A receiver partly covered by a touching solid: V counts the covered sample points as
      // occluded towards shooters outside the solid; the texel is exposed.
      const double e = solution_.exposureAtKey(int(g.receiver), k);
      v = e > 0.0 ? std::clamp(v / e, 0.0, 1.0) : 0.0;
      l.weight[size_t(k)] = solution_.radiosityAtKey(int(l.shooter), k) * v;
    }
  });
}

// Which links a texel evaluates itself (near and strong) and which are interpolated from the
// receiver node's corners: far ones, over which F varies so slowly that the error of bilinear
// interpolation (as (size / distance)^2) is negligible, and weak ones, under weakShare_ of the
// irradiance the node's chain gathers (cubic, 189 patches, had 600 links per texel, most of
// them carrying a fraction of a per cent).
void GoodLinkGather::classifyLinks(const std::map<int, uint32_t>& nodeOf, double t0) {
  const PatchHierarchy& h = solution_.hierarchy;
  std::vector<double> strength(links_.size(), 0.0);
  std::vector<double> nodeStrength(nodes_.size(), 0.0);
  std::vector<char> far(links_.size(), 0);
  tbb::parallel_for(size_t(0), links_.size(), [&](size_t j) {
    const int r = int(solution_.links[links_[j].row].receiver);
    const Polygon receiver = nodeWorld(uint32_t(r), t0), shooter = nodeWorld(links_[j].shooter, t0);
    double d = distanceToPolygon(receiver.centroid(), shooter);
    for (int i = 0; i < receiver.count; ++i)
      d = std::min(d, distanceToPolygon(receiver.v[i], shooter));
    far[j] = d > kFarRatio * polygonSize(receiver);
    double b = 0.0;
    for (const glm::dvec3& w : links_[j].weight) b = std::max(b, std::max(w.x, std::max(w.y, w.z)));
    strength[j] = b * areaAverageFormFactor(receiver, shooter, 1e-2);
  });
  for (size_t j = 0; j < links_.size(); ++j)
    nodeStrength[nodeOf.at(int(solution_.links[links_[j].row].receiver))] += strength[j];
  for (size_t j = 0; j < links_.size(); ++j) {
    const int r = int(solution_.links[links_[j].row].receiver);
    double chain = 0.0;  // what the receiver node and its ancestors gather
    for (int a = r; a >= 0; a = h.node(a).parent) {
      auto it = nodeOf.find(a);
      if (it != nodeOf.end()) chain += nodeStrength[it->second];
    }
    links_[j].far = far[j] || strength[j] < weakShare_ * chain;
    ReceiverNode& n = nodes_[nodeOf.at(r)];
    (links_[j].far ? n.farLinks : n.nearLinks).push_back(uint32_t(j));
  }
}

// The receiver nodes the texels' chains run through, each with its far links and corners, and per
// texel its near links (form factors kept when no end moves and the terms fit in `cacheBytes`).
void GoodLinkGather::planTexels(double cacheBytes) {
  const PatchHierarchy& h = solution_.hierarchy;
  const InputPolygon& top = h.top(receiverTop_);
  const bool triangle = top.local.count == 3;
  const double t0 = keyTimes_.front();
  std::map<int, uint32_t> nodeOf;  // receiver node -> nodes_ index
  for (uint32_t j = 0; j < uint32_t(links_.size()); ++j) {
    const int r = int(solution_.links[links_[j].row].receiver);
    auto [it, fresh] = nodeOf.emplace(r, uint32_t(nodes_.size()));
    if (fresh) {
      ReceiverNode n;
      n.node = r;
      n.corners = triangle ? 3 : 4;
      static const glm::dvec2 quad[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      static const glm::dvec2 tri[3] = {{0, 0}, {1, 0}, {0, 1}};
      for (int c = 0; c < n.corners; ++c)
        n.cornerLocal[size_t(c)] = polygonPointAt(
            top.local, topUvFromNodeUv(h.node(r).id, triangle ? tri[c] : quad[c], triangle));
      nodes_.push_back(n);
    }
    (void)it;
  }
  classifyLinks(nodeOf, t0);
  const size_t T = texels_.topUv.size();
  texelStart_.assign(T + 1, 0);
  texelNodeStart_.assign(T + 1, 0);
  for (size_t x = 0; x < T; ++x) {
    for (int a = leafAtTopUv(h, receiverTop_, texels_.topUv[x]); a >= 0; a = h.node(a).parent) {
      auto it = nodeOf.find(a);
      if (it == nodeOf.end()) continue;
      const ReceiverNode& n = nodes_[it->second];
      if (!n.farLinks.empty()) {
        texelNodes_.push_back(it->second);
        texelNodeUv_.push_back(clampToParameterDomain(
            nodeUvFromTopUv(h.node(a).id, texels_.topUv[x], triangle), triangle));
      }
      texelLinks_.insert(texelLinks_.end(), n.nearLinks.begin(), n.nearLinks.end());
    }
    texelStart_[x + 1] = uint32_t(texelLinks_.size());
    texelNodeStart_[x + 1] = uint32_t(texelNodes_.size());
  }
  // The form factors of links that do not move, once per movie (within the budget); a moving
  // link's are recomputed at every key.
  cached_ = double(texelLinks_.size()) * sizeof(float) <= cacheBytes;
  const TexelFrame frame = texelFrame(t0);
  std::vector<Polygon> shooter(links_.size());
  for (size_t j = 0; j < links_.size(); ++j) shooter[j] = nodeWorld(links_[j].shooter, t0);
  tbb::parallel_for(size_t(0), nodes_.size(), [&](size_t i) {
    ReceiverNode& n = nodes_[i];
    n.cornerFormFactor.assign(n.farLinks.size() * 4, 0.0);
    for (size_t f = 0; f < n.farLinks.size(); ++f)
      cornerFormFactors(n, frame, nodeWorld(uint32_t(n.node), t0), shooter[n.farLinks[f]],
                        &n.cornerFormFactor[f * 4]);
  });
  if (!cached_) return;
  texelFormFactor_.resize(texelLinks_.size());
  tbb::parallel_for(size_t(0), T, [&](size_t x) {
    const glm::dvec3 p(frame.m * glm::dvec4(texels_.localPoint[x], 1.0));
    for (uint32_t e = texelStart_[x]; e < texelStart_[x + 1]; ++e) {
      const uint32_t j = texelLinks_[e];
      texelFormFactor_[e] =
          links_[j].moves ? 0.0f : float(pointToPolygonFormFactor(p, frame.n, shooter[j]));
    }
  });
}

// A far link's form factors at the receiver node's corners, scaled so that their interpolation
// keeps the node's area average F(node -> shooter): F is peaked over a receiver facing its
// shooter, and its corner values alone, interpolated, made every scene 1-8 % too dark.
void GoodLinkGather::cornerFormFactors(const ReceiverNode& n, const TexelFrame& frame,
                                       const Polygon& receiverWorld, const Polygon& shooter,
                                       double* out) const {
  double mean = 0.0;
  for (int c = 0; c < n.corners; ++c) {
    out[c] = pointToPolygonFormFactor(
        glm::dvec3(frame.m * glm::dvec4(n.cornerLocal[size_t(c)], 1.0)), frame.n, shooter);
    mean += out[c] / n.corners;
  }
  const double average = areaAverageFormFactor(receiverWorld, shooter, 1e-3);
  if (mean > 0.0) {
    for (int c = 0; c < n.corners; ++c) out[c] *= average / mean;
  } else {
    for (int c = 0; c < n.corners; ++c) out[c] = average;
  }
}

GoodLinkGather::TexelFrame GoodLinkGather::texelFrame(double t) const {
  const InputPolygon& top = solution_.hierarchy.top(receiverTop_);
  TexelFrame f;
  f.m = scene_.worldTransform(top.node, t);
  f.n = glm::normalize(
      glm::dvec3(glm::transpose(glm::inverse(f.m)) * glm::dvec4(top.local.normal(), 0.0)));
  return f;
}

void GoodLinkGather::gather(double t, std::vector<glm::dvec3>& acc) const {
  int k0, k1;
  double w;
  solution_.keyWeights(t, k0, k1, w);
  std::vector<glm::dvec3> weight(links_.size());
  std::vector<Polygon> shooter(links_.size());
  for (size_t j = 0; j < links_.size(); ++j) {
    const Link& l = links_[j];
    weight[j] = (1.0 - w) * l.weight[size_t(k0)] + w * l.weight[size_t(k1)];
    if (l.moves || !cached_) shooter[j] = nodeWorld(l.shooter, t);
  }
  const TexelFrame frame = texelFrame(t);
  // Far links: their irradiance at each receiver node's corners.
  std::vector<std::array<glm::dvec3, 4>> cornerH(nodes_.size());
  for (size_t i = 0; i < nodes_.size(); ++i) {
    const ReceiverNode& n = nodes_[i];
    cornerH[i].fill(glm::dvec3(0.0));
    for (size_t f = 0; f < n.farLinks.size(); ++f) {
      const uint32_t j = n.farLinks[f];
      double moving[4];
      const double* F = &n.cornerFormFactor[f * 4];
      if (links_[j].moves) {
        cornerFormFactors(n, frame, nodeWorld(uint32_t(n.node), t), shooter[j], moving);
        F = moving;
      }
      for (int c = 0; c < n.corners; ++c) cornerH[i][size_t(c)] += F[c] * weight[j];
    }
  }
  tbb::parallel_for(size_t(0), texels_.topUv.size(), [&](size_t x) {
    const glm::dvec3 p(frame.m * glm::dvec4(texels_.localPoint[x], 1.0));
    glm::dvec3 H(0.0);
    for (uint32_t e = texelStart_[x]; e < texelStart_[x + 1]; ++e) {
      const uint32_t j = texelLinks_[e];
      if (weight[j] == glm::dvec3(0.0)) continue;
      const double f = cached_ && !links_[j].moves
                           ? double(texelFormFactor_[e])
                           : pointToPolygonFormFactor(p, frame.n, shooter[j]);
      H += f * weight[j];
    }
    for (uint32_t e = texelNodeStart_[x]; e < texelNodeStart_[x + 1]; ++e) {
      const ReceiverNode& n = nodes_[texelNodes_[e]];
      const std::array<glm::dvec3, 4>& c = cornerH[texelNodes_[e]];
      const glm::dvec2 uv = texelNodeUv_[e];
      H += n.corners == 3 ? (1.0 - uv.x - uv.y) * c[0] + uv.x * c[1] + uv.y * c[2]
                          : (1.0 - uv.x) * (1.0 - uv.y) * c[0] + uv.x * (1.0 - uv.y) * c[1] +
                                uv.x * uv.y * c[2] + (1.0 - uv.x) * uv.y * c[3];
    }
    acc[x] = H;
  });
}

}  // namespace rad
