// Frame-to-frame coherence of rad-compose's samples. Contracts and the reasons in still_samples.h.
#include "libcommon/compose/still_samples.h"

#include <cstring>

namespace rad {
namespace {

bool sameBits(const glm::dmat4& a, const glm::dmat4& b) {
  return std::memcmp(&a[0][0], &b[0][0], sizeof(glm::dmat4)) == 0;
}

bool sameBits(double a, double b) {
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}

// The lens and the placement, bit for bit (the camera's name is not part of the view).
bool sameView(const CameraView& a, const CameraView& b) {
  const Camera &p = a.lens, &q = b.lens;
  return p.perspective == q.perspective && sameBits(p.yfov, q.yfov) &&
         sameBits(p.aspectRatio, q.aspectRatio) && sameBits(p.xmag, q.xmag) &&
         sameBits(p.ymag, q.ymag) && sameBits(p.znear, q.znear) && sameBits(p.zfar, q.zfar) &&
         sameBits(a.worldFromCamera, b.worldFromCamera);
}

}  // namespace

void StillSamples::beginFrame(const CameraView& view, const std::vector<glm::dmat4>& transforms,
                              std::vector<std::vector<uint64_t>> moviePatchesByTop,
                              size_t samples) {
  ++frame_;
  const bool stillCamera = frame_ > 1 && sameView(view, lastView_) &&
                           transforms.size() == lastTransforms_.size() &&
                           moviePatchesByTop.size() == lastMovies_.size();
  stillSince_.resize(transforms.size(), frame_);
  sameMoviesSince_.resize(moviePatchesByTop.size(), frame_);
  for (size_t k = 0; k < transforms.size(); ++k)
    if (!stillCamera || !sameBits(transforms[k], lastTransforms_[k])) stillSince_[k] = frame_;
  for (size_t t = 0; t < moviePatchesByTop.size(); ++t)
    if (!stillCamera || moviePatchesByTop[t] != lastMovies_[t]) sameMoviesSince_[t] = frame_;
  if (stillCamera && ids_.size() != samples) {  // the first still frame, or another grid
    ids_.assign(samples, 0);
    topFrame_.assign(samples, 0);
    movieFrame_.assign(samples, 0);
    topUv_.assign(samples, glm::dvec2(0.0));
    movieUv_.assign(samples, glm::dvec2(0.0));
    moviePatch_.assign(samples, 0);
  }
  enabled_ = stillCamera;
  lastView_ = view;
  lastTransforms_ = transforms;
  lastMovies_ = std::move(moviePatchesByTop);
}

}  // namespace rad
