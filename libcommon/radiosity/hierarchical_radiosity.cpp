// Hierarchical radiosity at one key time (Hanrahan, Salzman, Aupperle 1991); see the header.
#include "libcommon/radiosity/hierarchical_radiosity.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>

#include <tbb/parallel_for.h>

#include "libcommon/core/error.h"

namespace rad {

namespace {

double maxComponent(const glm::dvec3& v) {
  return std::max(v.x, std::max(v.y, v.z));
}

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Size of a polygon (largest vertex distance from the first vertex), for relative tolerances.
double polygonSize(const Polygon& p) {
  double s = 0;
  for (int i = 1; i < p.count; ++i) s = std::max(s, glm::length(p.v[i] - p.v[0]));
  return s;
}

// Some vertex of `p` lies strictly in front of the plane of `q`.
bool someVertexInFront(const Polygon& p, const Polygon& q) {
  glm::dvec3 n = q.normal();
  if (n == glm::dvec3(0.0)) return false;
  glm::dvec3 c = q.centroid();
  double tol = 1e-12 * std::max(polygonSize(p), polygonSize(q));
  for (int i = 0; i < p.count; ++i)
    if (glm::dot(n, p.v[i] - c) > tol) return true;
  return false;
}

// 2D convex hull (Andrew's monotone chain), counter-clockwise, collinear points dropped.
std::vector<glm::dvec2> convexHull2d(std::vector<glm::dvec2> p) {
  std::sort(p.begin(), p.end(), [](const glm::dvec2& a, const glm::dvec2& b) {
    return a.x < b.x || (a.x == b.x && a.y < b.y);
  });
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return p;
  auto cross = [](const glm::dvec2& o, const glm::dvec2& a, const glm::dvec2& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
  };
  std::vector<glm::dvec2> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i - 1]) <= 0) --k;
    h[k++] = p[i - 1];
  }
  h.resize(k - 1);
  return h;
}

}  // namespace

double linkFormFactor(const Polygon& p, const Polygon& q, int order, double relTol) {
  if (order != kAutoOrder) return polygonToPolygonFormFactor(p, q, order);
  // Integrate over the smaller patch and use reciprocity: a Gauss rule on the larger one misses
  // the log-singular strip along a shared edge (README of the reference: perp_common_edge_*).
  double ap = p.area(), aq = q.area();
  bool swap = ap > aq;
  const Polygon& from = swap ? q : p;
  const Polygon& to = swap ? p : q;
  double d = glm::length(from.centroid() - to.centroid());
  double size = std::max(polygonSize(from), polygonSize(to));
  double f;
  if (d < size)  // near contact: no fixed rule is accurate, adapt
    f = polygonToPolygonFormFactorAdaptive(from, to, relTol, 1e-12, 4096).value;
  else
    f = polygonToPolygonFormFactor(from, to, kAutoOrder);
  return swap ? std::min(1.0, f * aq / ap) : f;
}

std::vector<SurfaceProperties> surfacePropertiesOf(const Scene& scene,
                                                   const PatchHierarchy& hierarchy) {
  std::vector<SurfaceProperties> out(size_t(hierarchy.topCount()));
  for (int t = 0; t < hierarchy.topCount(); ++t) {
    int m = hierarchy.top(t).material;
    if (m >= 0 && m < int(scene.materials.size())) {
      const Material& mat = scene.materials[size_t(m)];
      out[size_t(t)].reflectance = glm::clamp(mat.reflectance, glm::dvec3(0.0), glm::dvec3(1.0));
      out[size_t(t)].emission = glm::max(mat.emission, glm::dvec3(0.0)) * M_PI;  // B_e = pi L_e
    } else {
      out[size_t(t)].reflectance = glm::dvec3(1.0);  // glTF default material: white, no emission
    }
  }
  return out;
}

bool mutuallyFacing(const Polygon& p, const Polygon& q) {
  return someVertexInFront(p, q) && someVertexInFront(q, p);
}

uint64_t linkSeed(PatchId receiver, PatchId shooter) {
  return splitMix64(splitMix64(splitMix64(receiver.packed()) ^ shooter.packed()) +
                    0x9E3779B97F4A7C15ull);
}

glm::dvec3 KeySolution::absorbedPower(const PatchHierarchy& h,
                                      const std::vector<SurfaceProperties>& surfaces) const {
  glm::dvec3 sum(0.0);
  for (size_t i = 0; i < split.size(); ++i) {
    if (split[i] || !inTree(int(i), h)) continue;
    const SurfaceProperties& s = surfaces[h.node(int(i)).id.top];
    sum += area[i] * (glm::dvec3(1.0) - s.reflectance) * irradiance[i];
  }
  return sum;
}

glm::dvec3 KeySolution::emittedPower(const PatchHierarchy& h,
                                     const std::vector<SurfaceProperties>& surfaces) const {
  glm::dvec3 sum(0.0);
  for (int t = 0; t < h.topCount(); ++t) sum += area[size_t(t)] * surfaces[size_t(t)].emission;
  return sum;
}

KeySolution solveKeyTime(PatchHierarchy& h, const std::vector<SurfaceProperties>& surfaces,
                         const KeySolveInput& input, const RadiosityOptions& opt) {
  const int T = h.topCount();
  if (int(surfaces.size()) != T || int(input.topToWorld.size()) != T)
    throw Error(ExitCode::kInternal, "", "solveKeyTime: per-top arrays have the wrong size");
  KeySolution s;
  std::vector<glm::dvec3> B;
  // World geometry of every node of the union hierarchy (nodes made here are appended).
  auto ensureNodes = [&]() {
    for (int i = int(s.world.size()); i < h.size(); ++i) {
      const PatchNode& n = h.node(i);
      s.world.push_back(n.local.transformed(input.topToWorld[n.id.top]));
      s.area.push_back(s.world.back().area());
      s.split.push_back(0);
      B.push_back(n.parent >= 0 ? B[size_t(n.parent)] : surfaces[n.id.top].emission);
    }
  };
  ensureNodes();

  // Absolute refinement threshold: eps times the largest emitted power over the channels.
  glm::dvec3 emitted(0.0);
  double rhoMax = 0.0;
  for (int t = 0; t < T; ++t) {
    emitted += s.area[size_t(t)] * surfaces[size_t(t)].emission;
    rhoMax = std::max(rhoMax, maxComponent(surfaces[size_t(t)].reflectance));
  }
  const double epsAbs = opt.eps * maxComponent(emitted);
  const bool refineOn = opt.refine && epsAbs > 0.0;

  auto t0 = std::chrono::steady_clock::now();
  // Top-level links between every mutually facing pair.
  for (int p = 0; p < T; ++p)
    for (int q = 0; q < T; ++q)
      if (p != q && s.area[size_t(p)] > 0 && s.area[size_t(q)] > 0 &&
          mutuallyFacing(s.world[size_t(p)], s.world[size_t(q)])) {
        SolverLink l;
        l.receiver = p;
        l.shooter = q;
        s.links.push_back(l);
      }

  size_t evaluated = 0;  // links [0, evaluated) have their estimate and visibility
  auto evaluateNew = [&]() {
    size_t begin = evaluated, end = s.links.size();
    tbb::parallel_for(begin, end, [&](size_t li) {
      SolverLink& l = s.links[li];
      const PatchNode& r = h.node(l.receiver);
      const PatchNode& q = h.node(l.shooter);
      const Polygon& P = s.world[size_t(l.receiver)];
      const Polygon& Q = s.world[size_t(l.shooter)];
      auto shadowRays = [&] {
        return input.visibility ? input.visibility->visibility(P, Q, opt.rays, linkSeed(r.id, q.id),
                                                               r.id.top, q.id.top)
                                : 1.0;
      };
      if (input.reuse) {
        auto it = input.reuse->find({r.id.packed(), q.id.packed()});
        if (it != input.reuse->end()) {
          // The values, never a decision: F starts as the estimate as in a fresh evaluation,
          // and computeAccurate takes the known accurate F instead of integrating again.
          const CachedLink& c = it->second;
          l.estimate = c.estimate;
          l.spreadArea = c.spreadArea;
          l.formFactor = l.estimate;
          l.knownFormFactor = c.formFactor;
          if (c.visibilityValid) {
            l.visibility = c.visibility;
            l.reused = true;
          } else {
            l.visibility = shadowRays();
            l.visibilityOnly = true;
          }
          return;
        }
      }
      double ap = s.area[size_t(l.receiver)], aq = s.area[size_t(l.shooter)];
      // Both directions: the centroid estimate alone can miss a near-contact pair.
      const double fpq = formFactorEstimate(P, Q), fqp = formFactorEstimate(Q, P);
      l.estimate = std::min(1.0, std::max(fpq, fqp * aq / ap));
      l.formFactor = l.estimate;
      if (opt.oracle != RefinementOracle::kPower)
        l.spreadArea = std::max(ap * formFactorSpread(P, Q, fpq), aq * formFactorSpread(Q, P, fqp));
      l.visibility = shadowRays();
    });
    evaluated = end;
  };

  // Which node a link would split, or -1 (HSA'91: the larger one, if above minArea).
  auto nodeToSplit = [&](const SolverLink& l) {
    int a = l.receiver, b = l.shooter;
    if (s.area[size_t(b)] > s.area[size_t(a)]) std::swap(a, b);
    for (int n : {a, b})
      if (s.area[size_t(n)] > opt.minArea && h.node(n).id.level() < PatchId::kMaxLevel) return n;
    return -1;
  };
  // Refines the links of `work` (and the links that makes) until the oracle is satisfied.
  auto refinePass = [&](std::vector<size_t> work) {
    size_t count = 0;
    while (!work.empty()) {
      evaluateNew();
      std::vector<size_t> next;
      for (size_t li : work) {
        if (s.links[li].refined) continue;
        SolverLink l = s.links[li];
        double bv = maxComponent(B[size_t(l.shooter)]) * l.visibility;
        bool power = bv * l.estimate * s.area[size_t(l.receiver)] > epsAbs;
        bool error = bv * l.spreadArea > epsAbs;
        bool want = (opt.oracle == RefinementOracle::kPower   ? power
                     : opt.oracle == RefinementOracle::kError ? error
                                                              : power || error);
        if (!want) continue;
        int node = nodeToSplit(l);
        if (node < 0) continue;
        bool fresh = !s.split[size_t(node)];
        int first = h.subdivide(node);
        ensureNodes();
        s.split[size_t(node)] = 1;
        if (fresh)  // children enter this key's tree with their parent's radiosity
          for (int c = 0; c < 4; ++c) B[size_t(first + c)] = B[size_t(node)];
        s.links[li].refined = true;
        for (int c = 0; c < 4; ++c) {
          SolverLink child;
          child.receiver = node == l.receiver ? first + c : l.receiver;
          child.shooter = node == l.receiver ? l.shooter : first + c;
          next.push_back(s.links.size());
          s.links.push_back(child);
        }
        ++count;
      }
      work.swap(next);
    }
    return count;
  };

  auto computeAccurate = [&]() {
    tbb::parallel_for(size_t(0), s.links.size(), [&](size_t li) {
      SolverLink& l = s.links[li];
      if (l.refined || l.accurate) return;
      if (l.visibility > 0.0) {
        if (l.knownFormFactor >= 0.0) {
          l.formFactor = l.knownFormFactor;
        } else {
          l.formFactor = linkFormFactor(s.world[size_t(l.receiver)], s.world[size_t(l.shooter)],
                                        opt.quadratureOrder, opt.formFactorTolerance);
          l.reused = false;  // computed here after all
          l.visibilityOnly = false;
        }
      }
      l.accurate = true;
    });
  };

  // Gather + push-pull (HSA'91 §5), Gauss-Seidel over the top-level patches.
  std::vector<size_t> adjStart, adj;
  std::vector<glm::dvec3> irr;
  double maxDelta = 0, maxB = 0;
  std::function<glm::dvec3(int, const glm::dvec3&)> pushPull = [&](int i, const glm::dvec3& down) {
    glm::dvec3 H = down;
    for (size_t k = adjStart[size_t(i)]; k < adjStart[size_t(i) + 1]; ++k) {
      const SolverLink& l = s.links[adj[k]];
      H += double(l.fv()) * B[size_t(l.shooter)];
    }
    irr[size_t(i)] = H;
    if (!s.split[size_t(i)]) {
      const SurfaceProperties& sp = surfaces[h.node(i).id.top];
      glm::dvec3 b = sp.emission + sp.reflectance * H;
      maxDelta = std::max(maxDelta, maxComponent(glm::abs(b - B[size_t(i)])));
      maxB = std::max(maxB, maxComponent(glm::abs(b)));
      B[size_t(i)] = b;
      return b * s.area[size_t(i)];
    }
    int first = h.node(i).firstChild;
    glm::dvec3 sum(0.0);
    double areaSum = 0;
    for (int c = 0; c < 4; ++c) {
      sum += pushPull(first + c, H);
      areaSum += s.area[size_t(first + c)];
    }
    B[size_t(i)] = areaSum > 0 ? sum / areaSum : B[size_t(first)];
    return B[size_t(i)] * s.area[size_t(i)];
  };
  const double stopChange = opt.tol * std::max(1.0 - rhoMax, 1e-6);
  auto solve = [&]() {
    size_t N = size_t(h.size());
    adjStart.assign(N + 1, 0);
    for (const SolverLink& l : s.links)
      if (!l.refined) ++adjStart[size_t(l.receiver) + 1];
    for (size_t i = 0; i < N; ++i) adjStart[i + 1] += adjStart[i];
    adj.assign(adjStart[N], 0);
    std::vector<size_t> fill(adjStart.begin(), adjStart.end() - 1);
    for (size_t li = 0; li < s.links.size(); ++li)
      if (!s.links[li].refined) adj[fill[size_t(s.links[li].receiver)]++] = li;
    irr.assign(N, glm::dvec3(0.0));
    for (int it = 0; it < opt.maxIterations; ++it) {
      maxDelta = maxB = 0;
      for (int t = 0; t < T; ++t) pushPull(t, glm::dvec3(0.0));
      ++s.iterations;
      s.lastChange = maxB > 0 ? maxDelta / maxB : 0.0;
      if (s.lastChange < stopChange) break;
    }
  };

  std::vector<size_t> work(s.links.size());
  for (size_t i = 0; i < work.size(); ++i) work[i] = i;
  for (int round = 0;; ++round) {
    auto tl = std::chrono::steady_clock::now();
    size_t refined = 0;
    if (refineOn)
      refined = refinePass(work);
    else
      evaluateNew();
    if (round > 0 && refined == 0) {
      s.secondsLinks += secondsSince(tl);
      break;
    }
    computeAccurate();
    s.secondsLinks += secondsSince(tl);
    auto ts = std::chrono::steady_clock::now();
    solve();
    s.secondsSolve += secondsSince(ts);
    s.refineRounds = round + 1;
    if (!refineOn || round + 1 >= opt.maxRefineRounds) break;
    work.clear();
    for (size_t i = 0; i < s.links.size(); ++i)
      if (!s.links[i].refined) work.push_back(i);
  }
  (void)t0;
  for (const SolverLink& l : s.links) {
    (l.reused ? s.linksReused : s.linksComputed)++;
    s.linksVisibilityOnly += l.visibilityOnly ? 1 : 0;
  }
  s.radiosity = std::move(B);
  s.irradiance = std::move(irr);
  s.irradiance.resize(size_t(h.size()), glm::dvec3(0.0));
  return s;
}

std::vector<glm::dmat4> topTransforms(const Scene& scene, const PatchHierarchy& hierarchy,
                                      double t) {
  std::vector<glm::dmat4> out(size_t(hierarchy.topCount()), glm::dmat4(1.0));
  std::unordered_map<int, glm::dmat4> perNode;
  for (int i = 0; i < hierarchy.topCount(); ++i) {
    int node = hierarchy.top(i).node;
    if (node < 0) continue;
    auto it = perNode.find(node);
    if (it == perNode.end()) it = perNode.emplace(node, scene.worldTransform(node, t)).first;
    out[size_t(i)] = it->second;
  }
  return out;
}

SceneVisibility::SceneVisibility(const Scene& scene, const PatchHierarchy& h, double t0, double t1)
    : scene_(scene) {
  auto addPolygon = [](std::vector<VisibilityTriangle>& out, const Polygon& p, uint32_t id) {
    out.push_back({{p.v[0], p.v[1], p.v[2]}, id});
    if (p.count == 4) out.push_back({{p.v[0], p.v[2], p.v[3]}, id});
  };
  std::vector<VisibilityTriangle> statics;
  std::vector<int> dynamicNodes;
  std::unordered_map<int, std::vector<VisibilityTriangle>> local;
  std::unordered_map<int, bool> dynamic;
  for (int i = 0; i < h.topCount(); ++i) {
    const InputPolygon& top = h.top(i);
    int node = top.node;
    auto d = dynamic.find(node);
    if (d == dynamic.end())
      d = dynamic.emplace(node, node >= 0 && scene.isDynamic(node, t0, t1)).first;
    if (d->second) {
      if (!local.count(node)) dynamicNodes.push_back(node);
      addPolygon(local[node], top.local, uint32_t(i));
    } else {
      glm::dmat4 m = node >= 0 ? scene.worldTransform(node, t0) : glm::dmat4(1.0);
      addPolygon(statics, top.local.transformed(m), uint32_t(i));
    }
  }
  vis_ = std::make_unique<VisibilityScene>(statics);
  for (int node : dynamicNodes)
    instances_.emplace_back(node, vis_->addInstance(local[node], scene.worldTransform(node, t0)));
  vis_->commit();
}

void SceneVisibility::setTime(double t) {
  for (auto& [node, id] : instances_)
    vis_->setInstanceTransform(id, scene_.worldTransform(node, t));
  vis_->commit();
}

bool shaftMeetsBox(const Polygon& a, const Polygon& b, const glm::dvec3& lo, const glm::dvec3& hi) {
  std::vector<glm::dvec3> pts;
  for (int i = 0; i < a.count; ++i) pts.push_back(a.v[i]);
  for (int i = 0; i < b.count; ++i) pts.push_back(b.v[i]);
  glm::dvec3 plo(pts[0]), phi(pts[0]);
  for (const glm::dvec3& p : pts) plo = glm::min(plo, p), phi = glm::max(phi, p);
  for (int k = 0; k < 3; ++k)
    if (hi[k] < plo[k] || lo[k] > phi[k]) return false;
  double scale = glm::length(phi - plo) + glm::length(hi - lo);
  for (int k = 0; k < 3; ++k) {
    int i = (k + 1) % 3, j = (k + 2) % 3;
    std::vector<glm::dvec2> p2;
    for (const glm::dvec3& p : pts) p2.push_back({p[i], p[j]});
    std::vector<glm::dvec2> hull = convexHull2d(p2);
    if (hull.size() < 2) continue;
    glm::dvec2 corners[4] = {{lo[i], lo[j]}, {hi[i], lo[j]}, {hi[i], hi[j]}, {lo[i], hi[j]}};
    for (size_t e = 0; e < hull.size(); ++e) {
      glm::dvec2 p0 = hull[e], p1 = hull[(e + 1) % hull.size()];
      glm::dvec2 d = p1 - p0;
      glm::dvec2 outward(d.y, -d.x);  // right of a CCW edge
      double len = glm::length(outward);
      if (len == 0) continue;
      outward /= len;
      bool allOutside = true;
      for (const glm::dvec2& c : corners)
        if (glm::dot(outward, c - p0) <= 1e-12 * scale) {
          allOutside = false;
          break;
        }
      if (allOutside) return false;
    }
  }
  return true;
}

}  // namespace rad
