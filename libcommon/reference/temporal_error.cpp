// docs/design.md §10.6: the temporal error of a sequence against its references.
#include "libcommon/reference/temporal_error.h"

#include <algorithm>
#include <cmath>

namespace rad {

double TemporalSums::rmseOverMean() const {
  if (samples == 0 || sumReference <= 0.0) return 0.0;
  const double n = double(samples);
  double squared = sumSquared1 / n;
  if (twoReferences)
    squared = std::max(0.0, (sumSquared1 + sumSquared2) / (2.0 * n) - sumNoiseSquared / (2.0 * n));
  return std::sqrt(squared) / (sumReference / n);
}

double TemporalSums::rawRmseOverMean() const {
  if (samples == 0 || sumReference <= 0.0) return 0.0;
  return std::sqrt(sumSquared1 / double(samples)) / (sumReference / double(samples));
}

void TemporalError::addPair(const TemporalFrame& previous, const TemporalFrame& current) {
  const FloatImage& t0 = *previous.test;
  const FloatImage& t1 = *current.test;
  const FloatImage& r0 = *previous.reference;
  const FloatImage& r1 = *current.reference;
  const bool two = previous.reference2 && current.reference2;
  const bool edges = previous.edge && current.edge;
  const size_t channels = size_t(t1.channelCount());
  const size_t pixels = size_t(t1.width) * size_t(t1.height);
  ++framePairs;
  haveEdges = haveEdges || edges;
  for (size_t p = 0; p < pixels; ++p) {
    if ((*previous.emitter)[p] || (*current.emitter)[p]) continue;
    const bool isEdge = edges && ((*previous.edge)[p] || (*current.edge)[p]);
    TemporalSums* sets[2] = {&all, isEdge ? &edge : &interior};
    for (size_t c = 0; c < channels; ++c) {
      const size_t i = p * channels + c;
      const double dt = double(t1.pixels[i]) - double(t0.pixels[i]);
      const double dr1 = double(r1.pixels[i]) - double(r0.pixels[i]);
      const double dr2 =
          two ? double(current.reference2->pixels[i]) - double(previous.reference2->pixels[i])
              : dr1;
      if (!std::isfinite(dt) || !std::isfinite(dr1) || !std::isfinite(dr2)) continue;
      for (TemporalSums* s : sets) {
        ++s->samples;
        s->twoReferences = two;
        s->sumReference += 0.5 * (double(r0.pixels[i]) + double(r1.pixels[i]));
        s->sumSquared1 += (dt - dr1) * (dt - dr1);
        s->sumSquared2 += (dt - dr2) * (dt - dr2);
        s->sumNoiseSquared += (dr1 - dr2) * (dr1 - dr2);
      }
    }
  }
}

}  // namespace rad
