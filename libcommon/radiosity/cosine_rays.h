// Cosine-distributed directions about a normal (Malley's method), the k-th from two counter-based
// numbers of a seed: the rays of rad-global's exposure and of its closed-room test. Private to
// libcommon/radiosity. Deterministic: a pure function of (normal, seed, k).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

#include "libcommon/radiosity/visibility.h"

namespace rad {

struct CosineRays {
  glm::dvec3 normal, t, b;
  explicit CosineRays(const glm::dvec3& n) : normal(n) {
    t = std::abs(n.x) > 0.5 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    t = glm::normalize(glm::cross(t, n));
    b = glm::cross(n, t);
  }
  glm::dvec3 operator()(uint64_t seed, size_t k) const {
    const double u = uniformOpen01(seed, 2 * k), v = uniformOpen01(seed, 2 * k + 1);
    const double r = std::sqrt(u), phi = 2.0 * M_PI * v;
    return r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(1.0 - u) * normal;
  }
};

}  // namespace rad
