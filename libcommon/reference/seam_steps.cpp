// docs/design.md §10.5: luminance steps across seams of coplanar patches of one material.
#include "libcommon/reference/seam_steps.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "libcommon/reference/image_difference.h"

namespace rad {

namespace {

double relative(double numerator, double mean) {
  if (numerator == 0.0) return 0.0;
  if (!(mean > 0.0)) return std::copysign(std::numeric_limits<double>::infinity(), numerator);
  return numerator / mean;
}

}  // namespace

void SeamSums::merge(const SeamSums& o) {
  if (pairs == 0) {
    frame = o.frame;
    x = o.x;
    y = o.y;
  }
  pairs += o.pairs;
  testA += o.testA;
  testB += o.testB;
  reference1A += o.reference1A;
  reference1B += o.reference1B;
  reference2A += o.reference2A;
  reference2B += o.reference2B;
}

double SeamSums::localMean() const {
  return pairs > 0 ? (reference1A + reference1B + reference2A + reference2B) / (4.0 * double(pairs))
                   : 0.0;
}

double SeamSums::testStep() const {
  return pairs > 0 ? relative((testA - testB) / double(pairs), localMean()) : 0.0;
}

double SeamSums::referenceStep() const {
  if (pairs == 0) return 0.0;
  const double step = (reference1A - reference1B + reference2A - reference2B) / 2.0;
  return relative(step / double(pairs), localMean());
}

double SeamSums::floor() const {
  if (pairs == 0) return 0.0;
  const double difference = ((reference1A - reference1B) - (reference2A - reference2B)) / 2.0;
  return relative(difference / double(pairs), localMean());
}

void SeamSteps::merge(const SeamSteps& o) {
  twoReferences = twoReferences || o.twoReferences;
  for (const auto& [key, sums] : o.seams) seams[key].merge(sums);
}

SeamSummary summariseSeams(const SeamSteps& steps, long long minPairs) {
  SeamSummary s;
  s.minPairs = minPairs;
  s.seamsFound = (long long)steps.seams.size();
  for (const auto& [key, seam] : steps.seams) {
    if (seam.pairs < minPairs) continue;
    ++s.seamsMeasured;
    s.pairs += seam.pairs;
    const double t = std::abs(seam.testStep()), r = std::abs(seam.referenceStep());
    const double e = std::abs(seam.excess());
    s.meanAbsTestStep += t;
    s.meanAbsReferenceStep += r;
    s.meanAbsExcess += e;
    s.maxAbsTestStep = std::max(s.maxAbsTestStep, t);
    s.maxAbsReferenceStep = std::max(s.maxAbsReferenceStep, r);
    s.maxAbsExcess = std::max(s.maxAbsExcess, e);
    if (steps.twoReferences) s.maxFloor = std::max(s.maxFloor, std::abs(seam.floor()));
    s.byExcess.push_back(key);
  }
  if (s.seamsMeasured > 0) {
    s.meanAbsTestStep /= double(s.seamsMeasured);
    s.meanAbsReferenceStep /= double(s.seamsMeasured);
    s.meanAbsExcess /= double(s.seamsMeasured);
  }
  // Largest |excess| first; ties by patch pair, so the order is deterministic.
  std::stable_sort(s.byExcess.begin(), s.byExcess.end(), [&](const auto& a, const auto& b) {
    return std::abs(steps.seams.at(a).excess()) > std::abs(steps.seams.at(b).excess());
  });
  return s;
}

SeamSteps measureSeams(const FloatImage& test, const FloatImage& reference,
                       const FloatImage* reference2, const std::vector<uint8_t>& emitter,
                       const FrameSurfaces& surfaces, const EdgePixels& edges, int frame) {
  const std::vector<double> w = luminanceWeights(reference.channels);
  const size_t nc = size_t(reference.channelCount());
  const int W = surfaces.width, H = surfaces.height;
  SeamSteps steps;
  steps.twoReferences = reference2 != nullptr;
  // Luminance of a pixel in each image; false when a value is not finite.
  auto luminance = [&](size_t p, double& t, double& r1, double& r2) {
    t = r1 = r2 = 0.0;
    for (size_t c = 0; c < nc; ++c) {
      const double a = test.pixels[p * nc + c], b = reference.pixels[p * nc + c];
      const double b2 = reference2 ? double(reference2->pixels[p * nc + c]) : b;
      if (!std::isfinite(a) || !std::isfinite(b) || !std::isfinite(b2)) return false;
      t += w[c] * a;
      r1 += w[c] * b;
      r2 += w[c] * b2;
    }
    return true;
  };
  auto usable = [&](size_t p) {
    const int patch = surfaces.patchOfPixel[p];
    return patch >= 0 && !edges.edge[p] && !emitter[p] && !surfaces.emits(patch);
  };
  auto addPair = [&](int x, int y, int u, int v) {
    const size_t p = size_t(y) * size_t(W) + size_t(x), q = size_t(v) * size_t(W) + size_t(u);
    const int a = surfaces.patchOfPixel[p], b = surfaces.patchOfPixel[q];
    if (a == b || !usable(p) || !usable(q) || !surfaces.sameSurface(a, b)) return;
    const bool aFirst = a < b;
    const size_t pa = aFirst ? p : q, pb = aFirst ? q : p;
    double ta, ra, ra2, tb, rb, rb2;
    if (!luminance(pa, ta, ra, ra2) || !luminance(pb, tb, rb, rb2)) return;
    SeamSums& s = steps.seams[{std::min(a, b), std::max(a, b)}];
    if (s.pairs == 0) {
      s.frame = frame;
      s.x = int(pa % size_t(W));
      s.y = int(pa / size_t(W));
    }
    ++s.pairs;
    s.testA += ta;
    s.testB += tb;
    s.reference1A += ra;
    s.reference1B += rb;
    s.reference2A += ra2;
    s.reference2B += rb2;
  };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (x + 1 < W) addPair(x, y, x + 1, y);
      if (y + 1 < H) addPair(x, y, x, y + 1);
    }
  return steps;
}

}  // namespace rad
