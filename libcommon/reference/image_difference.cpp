// docs/design.md §10 ("How error is measured"): RMSE / mean and bias over non-emitters, the
// references' noise removed with two references of independent seeds.
#include "libcommon/reference/image_difference.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "libcommon/core/error.h"

namespace rad {

void DifferenceStats::add(const float* test, const float* reference, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) {
    const double a = test[i], b = reference[i];
    if (!std::isfinite(a) || !std::isfinite(b)) {
      ++nonFinite;
      continue;
    }
    const double d = a - b;
    ++samples;
    sumSquaredError += d * d;
    sumSquaredReference += b * b;
    maxAbsDifference = std::max(maxAbsDifference, std::abs(d));
    referencePeak = std::max(referencePeak, b);
  }
}

void DifferenceStats::merge(const DifferenceStats& o) {
  samples += o.samples;
  nonFinite += o.nonFinite;
  sumSquaredError += o.sumSquaredError;
  sumSquaredReference += o.sumSquaredReference;
  maxAbsDifference = std::max(maxAbsDifference, o.maxAbsDifference);
  referencePeak = std::max(referencePeak, o.referencePeak);
}

double DifferenceStats::rmse() const {
  return samples > 0 ? std::sqrt(sumSquaredError / double(samples)) : 0.0;
}

double DifferenceStats::relativeL2() const {
  if (sumSquaredError == 0.0) return 0.0;
  if (sumSquaredReference == 0.0) return std::numeric_limits<double>::infinity();
  return std::sqrt(sumSquaredError / sumSquaredReference);
}

double DifferenceStats::psnr() const {
  if (!(referencePeak > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  if (sumSquaredError == 0.0) return std::numeric_limits<double>::infinity();
  const double mse = sumSquaredError / double(samples);
  return 10.0 * std::log10(referencePeak * referencePeak / mse);
}

void requireSameShape(const FloatImage& a, const FloatImage& b, const std::string& where) {
  if (a.width != b.width || a.height != b.height)
    throw inputError(where, "size " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                                " differs from the reference's " + std::to_string(b.width) + "x" +
                                std::to_string(b.height));
  if (a.channelCount() != b.channelCount())
    throw inputError(where, std::to_string(a.channelCount()) + " channels; the reference has " +
                                std::to_string(b.channelCount()));
}

void FlickerStats::addPair(const FloatImage& testPrevious, const FloatImage& test,
                           const FloatImage& referencePrevious, const FloatImage& reference,
                           double staticTolerance) {
  requireSameShape(testPrevious, reference, "flicker: previous test frame");
  requireSameShape(test, reference, "flicker: test frame");
  requireSameShape(referencePrevious, reference, "flicker: previous reference frame");
  ++framePairs;
  const std::size_t nc = std::size_t(reference.channelCount());
  const std::size_t pixels = std::size_t(reference.width) * std::size_t(reference.height);
  for (std::size_t p = 0; p < pixels; ++p) {
    const std::size_t base = p * nc;
    bool isStatic = true;
    for (std::size_t c = 0; c < nc && isStatic; ++c) {
      const double r0 = referencePrevious.pixels[base + c], r1 = reference.pixels[base + c];
      // NaN compares false, so a non-finite reference pixel never counts as static.
      isStatic = std::abs(r1 - r0) <= staticTolerance;
    }
    if (!isStatic) continue;
    bool finite = true;
    for (std::size_t c = 0; c < nc; ++c)
      finite = finite && std::isfinite(test.pixels[base + c]) &&
               std::isfinite(testPrevious.pixels[base + c]);
    if (!finite) continue;
    ++staticPixels;
    for (std::size_t c = 0; c < nc; ++c) {
      const double d =
          std::abs(double(test.pixels[base + c]) - double(testPrevious.pixels[base + c]));
      sumAbsChange += d;
      maxAbsChange = std::max(maxAbsChange, d);
      ++samples;
    }
  }
}

DifferenceStats compareImages(const FloatImage& test, const FloatImage& reference,
                              const std::string& testWhere) {
  requireSameShape(test, reference, testWhere);
  DifferenceStats s;
  s.add(test.pixels.data(), reference.pixels.data(), test.pixels.size());
  return s;
}

// ---- docs/design.md §10
// ---------------------------------------------------------------------------

std::vector<double> luminanceWeights(const std::vector<std::string>& channels) {
  std::vector<double> w(channels.size(), 0.0);
  const char* names[3] = {"R", "G", "B"};
  const double rec709[3] = {0.2126, 0.7152, 0.0722};
  int found = 0;
  for (int k = 0; k < 3; ++k)
    for (std::size_t c = 0; c < channels.size(); ++c)
      if (channels[c] == names[k]) {
        w[c] = rec709[k];
        ++found;
        break;
      }
  if (found == 3) return w;
  std::fill(w.begin(), w.end(), channels.empty() ? 0.0 : 1.0 / double(channels.size()));
  return w;
}

std::string EmitterRule::toString() const {
  std::ostringstream os;
  if (threshold)
    os << "Y > " << *threshold;
  else
    os << "Y > " << kMedianFactor << " x median luminance of the lit reference pixels";
  return os.str();
}

namespace {

double pixelLuminance(const float* p, const std::vector<double>& w) {
  double y = 0.0;
  for (std::size_t c = 0; c < w.size(); ++c) y += w[c] * double(p[c]);
  return y;
}

void requireMaskShape(const FloatImage& mask, const FloatImage& reference,
                      const std::string& where) {
  if (mask.width != reference.width || mask.height != reference.height)
    throw inputError(where, "size " + std::to_string(mask.width) + "x" +
                                std::to_string(mask.height) + " differs from the reference's " +
                                std::to_string(reference.width) + "x" +
                                std::to_string(reference.height));
  if (mask.channelCount() < 1) throw inputError(where, "emitter mask has no channel");
}

double ratio(double numerator, double mean) {
  if (numerator == 0.0) return 0.0;
  if (!(mean > 0.0)) return std::copysign(std::numeric_limits<double>::infinity(), numerator);
  return numerator / mean;
}

}  // namespace

double emitterThreshold(const FloatImage& reference, const EmitterRule& rule) {
  if (rule.threshold) return *rule.threshold;
  const std::vector<double> w = luminanceWeights(reference.channels);
  const std::size_t nc = std::size_t(reference.channelCount());
  const std::size_t pixels = std::size_t(reference.width) * std::size_t(reference.height);
  std::vector<double> lit;
  lit.reserve(pixels);
  for (std::size_t p = 0; p < pixels; ++p) {
    const double y = pixelLuminance(&reference.pixels[p * nc], w);
    if (std::isfinite(y) && y > 0.0) lit.push_back(y);
  }
  if (lit.empty()) return std::numeric_limits<double>::infinity();
  auto middle = lit.begin() + std::ptrdiff_t(lit.size() / 2);
  std::nth_element(lit.begin(), middle, lit.end());
  return EmitterRule::kMedianFactor * *middle;
}

void PixelSetStats::merge(const PixelSetStats& o) {
  pixels += o.pixels;
  samples += o.samples;
  twoReferences = twoReferences || o.twoReferences;
  sumReference += o.sumReference;
  sumError += o.sumError;
  sumSquaredError1 += o.sumSquaredError1;
  sumSquaredError2 += o.sumSquaredError2;
  sumSquaredBetween += o.sumSquaredBetween;
}

double PixelSetStats::meanReference() const {
  return samples > 0 ? sumReference / double(samples) : 0.0;
}

double PixelSetStats::rawRmse() const {
  if (samples == 0) return 0.0;
  const double sum = twoReferences ? (sumSquaredError1 + sumSquaredError2) / 2.0 : sumSquaredError1;
  return std::sqrt(sum / double(samples));
}

double PixelSetStats::noise() const {
  if (samples == 0 || !twoReferences) return 0.0;
  return std::sqrt(sumSquaredBetween / (2.0 * double(samples)));
}

double PixelSetStats::rmse() const {
  const double raw = rawRmse(), n = noise();
  return std::sqrt(std::max(0.0, raw * raw - n * n));
}

double PixelSetStats::rmseOverMean() const {
  return ratio(rmse(), meanReference());
}
double PixelSetStats::rawRmseOverMean() const {
  return ratio(rawRmse(), meanReference());
}
double PixelSetStats::noiseOverMean() const {
  return ratio(noise(), meanReference());
}
double PixelSetStats::bias() const {
  return samples > 0 ? ratio(sumError / double(samples), meanReference()) : 0.0;
}

void ErrorFigures::merge(const ErrorFigures& o) {
  surfaces.merge(o.surfaces);
  emitters.merge(o.emitters);
  if (groups.size() < o.groups.size()) groups.resize(o.groups.size());
  for (size_t g = 0; g < o.groups.size(); ++g) groups[g].merge(o.groups[g]);
  if (regions.size() < o.regions.size()) regions.resize(o.regions.size());
  for (size_t g = 0; g < o.regions.size(); ++g) regions[g].merge(o.regions[g]);
}

EmitterPixels findEmitterPixels(const FloatImage& reference, const FloatImage* reference2,
                                const EmitterRule& rule, const FloatImage* emitterMask) {
  const std::size_t pixels = std::size_t(reference.width) * std::size_t(reference.height);
  EmitterPixels e;
  e.isEmitter.assign(pixels, 0);
  if (emitterMask) {
    e.threshold = std::numeric_limits<double>::quiet_NaN();
    const std::size_t maskChannels = std::size_t(emitterMask->channelCount());
    for (std::size_t p = 0; p < pixels; ++p)
      e.isEmitter[p] = emitterMask->pixels[p * maskChannels] > 0.5f;
    return e;
  }
  FloatImage mean;
  if (reference2) {
    mean = reference;
    for (std::size_t i = 0; i < mean.pixels.size(); ++i)
      mean.pixels[i] = 0.5f * (reference.pixels[i] + reference2->pixels[i]);
  }
  const FloatImage& r = reference2 ? mean : reference;
  e.threshold = emitterThreshold(r, rule);
  const std::vector<double> w = luminanceWeights(reference.channels);
  const std::size_t nc = std::size_t(reference.channelCount());
  for (std::size_t p = 0; p < pixels; ++p)
    e.isEmitter[p] = pixelLuminance(&r.pixels[p * nc], w) > e.threshold;
  return e;
}

namespace {

// Sizes `figures` to the groups' count; throws when the groups are not of the image's size.
void prepareGroups(const PixelGroups* groups, std::size_t pixels, bool twoReferences,
                   const std::string& where, std::vector<PixelSetStats>& figures) {
  if (!groups) return;
  if (groups->ofPixel.size() != pixels)
    throw inputError(where, "pixel groups (item buffer) are not of the image's size");
  figures.resize(size_t(std::max(groups->count, 0)));
  for (PixelSetStats& g : figures) g.twoReferences = twoReferences;
}

PixelSetStats* groupOf(const PixelGroups* groups, std::vector<PixelSetStats>& figures,
                       std::size_t p) {
  const int g = groups ? groups->ofPixel[p] : -1;
  return g >= 0 && g < int(figures.size()) ? &figures[size_t(g)] : nullptr;
}

}  // namespace

ErrorFigures measureError(const FloatImage& test, const FloatImage& reference,
                          const FloatImage* reference2, const EmitterRule& rule,
                          const std::string& testWhere, const std::string& reference2Where,
                          const FloatImage* emitterMask, const std::string& maskWhere,
                          const PixelGroups* groups, const PixelGroups* regions) {
  requireSameShape(test, reference, testWhere);
  if (reference2) requireSameShape(*reference2, reference, reference2Where);
  if (emitterMask) requireMaskShape(*emitterMask, reference, maskWhere);
  ErrorFigures f;
  f.surfaces.twoReferences = f.emitters.twoReferences = reference2 != nullptr;
  const EmitterPixels emitters = findEmitterPixels(reference, reference2, rule, emitterMask);
  f.emitterThreshold = emitters.threshold;
  const std::size_t nc = std::size_t(reference.channelCount());
  const std::size_t pixels = std::size_t(reference.width) * std::size_t(reference.height);
  prepareGroups(groups, pixels, reference2 != nullptr, testWhere, f.groups);
  prepareGroups(regions, pixels, reference2 != nullptr, testWhere, f.regions);
  for (std::size_t p = 0; p < pixels; ++p) {
    const std::size_t base = p * nc;
    bool finite = true;
    for (std::size_t c = 0; c < nc; ++c)
      finite = finite && std::isfinite(test.pixels[base + c]) &&
               std::isfinite(reference.pixels[base + c]) &&
               (!reference2 || std::isfinite(reference2->pixels[base + c]));
    if (!finite) continue;
    const bool emitter = emitters.isEmitter[p] != 0;
    PixelSetStats& s = emitter ? f.emitters : f.surfaces;
    PixelSetStats* group = emitter ? nullptr : groupOf(groups, f.groups, p);
    PixelSetStats* region = emitter ? nullptr : groupOf(regions, f.regions, p);
    for (PixelSetStats* x : {&s, group, region})
      if (x) ++x->pixels;
    for (std::size_t c = 0; c < nc; ++c) {
      const double t = test.pixels[base + c], r1 = reference.pixels[base + c];
      const double r2 = reference2 ? double(reference2->pixels[base + c]) : r1;
      const double rm = reference2 ? 0.5 * (r1 + r2) : r1;
      for (PixelSetStats* x : {&s, group, region}) {
        if (!x) continue;
        ++x->samples;
        x->sumReference += rm;
        x->sumError += t - rm;
        x->sumSquaredError1 += (t - r1) * (t - r1);
        x->sumSquaredError2 += (t - r2) * (t - r2);
        x->sumSquaredBetween += (r1 - r2) * (r1 - r2);
      }
    }
  }
  return f;
}

}  // namespace rad
