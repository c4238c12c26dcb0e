// Camera projection shared by rasterisers and ray casters.
// Matrices: Khronos, glTF 2.0 Specification §3.10.3 "Projection Matrices".
#include "libcommon/scene/camera_projection.h"

#include <cmath>
#include <limits>
#include <string>

#include "libcommon/core/error.h"

namespace rad {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string lensName(const Camera& lens) {
  return lens.name.empty() ? std::string("camera") : "camera " + lens.name;
}

void validate(const Camera& lens, ImageSize size) {
  if (size.width <= 0 || size.height <= 0)
    throw Error(ExitCode::kInternal, lensName(lens),
                "image size " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                    "; expected positive");
  if (!(lens.znear > 0.0))
    throw inputError(lensName(lens), "znear " + numberText(lens.znear) + "; expected > 0");
  if (lens.zfar != 0.0 && !(lens.zfar > lens.znear))
    throw inputError(lensName(lens), "zfar " + numberText(lens.zfar) + " not beyond znear " +
                                         numberText(lens.znear));
  if (lens.perspective) {
    if (!(lens.yfov > 0.0 && lens.yfov < kPi))
      throw inputError(lensName(lens), "yfov " + numberText(lens.yfov) + "; expected in (0, pi)");
    if (lens.aspectRatio < 0.0 || !std::isfinite(lens.aspectRatio))
      throw inputError(lensName(lens),
                       "aspectRatio " + numberText(lens.aspectRatio) + "; expected > 0 or absent");
  } else {
    if (!(lens.xmag > 0.0 && lens.ymag > 0.0))
      throw inputError(lensName(lens), "orthographic xmag/ymag must be > 0");
    if (lens.zfar == 0.0) throw inputError(lensName(lens), "orthographic camera without zfar");
  }
}

// Rows shared by both projections; depth row filled in by the callers. glm is column-major:
// m[col][row].
glm::dmat4 xywRows(const Camera& lens, ImageSize size) {
  glm::dmat4 m(0.0);
  if (lens.perspective) {
    double t = std::tan(0.5 * lens.yfov);
    m[0][0] = 1.0 / (effectiveAspect(lens, size) * t);
    m[1][1] = 1.0 / t;
    m[2][3] = -1.0;  // w = -z_eye
  } else {
    m[0][0] = 1.0 / lens.xmag;
    m[1][1] = 1.0 / lens.ymag;
    m[3][3] = 1.0;
  }
  return m;
}

}  // namespace

double effectiveAspect(const Camera& lens, ImageSize size) {
  return lens.aspectRatio > 0.0 ? lens.aspectRatio : size.aspect();
}

glm::dmat4 viewMatrix(const CameraView& view) {
  return glm::inverse(view.worldFromCamera);
}

glm::dmat4 projectionMatrix(const Camera& lens, ImageSize size) {
  validate(lens, size);
  glm::dmat4 m = xywRows(lens, size);
  double n = lens.znear, f = lens.zfar;
  if (lens.perspective) {
    if (f == 0.0) {
      m[2][2] = -1.0;
      m[3][2] = -2.0 * n;
    } else {
      m[2][2] = (f + n) / (n - f);
      m[3][2] = 2.0 * f * n / (n - f);
    }
  } else {
    m[2][2] = 2.0 / (n - f);
    m[3][2] = (f + n) / (n - f);
  }
  return m;
}

glm::dmat4 reversedZProjectionMatrix(const Camera& lens, ImageSize size) {
  validate(lens, size);
  glm::dmat4 m = xywRows(lens, size);
  double n = lens.znear, f = lens.zfar;
  if (lens.perspective) {
    // z_ndc = z_clip / d with d = -z_eye: infinite far: z_clip = n, so z_ndc = n / d.
    // Finite: z_ndc = n (f - d) / (d (f - n)), i.e. z_clip = (n z_eye + n f) / (f - n).
    if (f == 0.0) {
      m[3][2] = n;
    } else {
      m[2][2] = n / (f - n);
      m[3][2] = n * f / (f - n);
    }
  } else {
    // z_ndc = (f - d) / (f - n) = (z_eye + f) / (f - n).
    m[2][2] = 1.0 / (f - n);
    m[3][2] = f / (f - n);
  }
  return m;
}

glm::mat4 rasterClipFromLocal(const CameraView& view, ImageSize size,
                              const glm::dmat4& worldFromLocal) {
  return glm::mat4(reversedZProjectionMatrix(view.lens, size) * viewMatrix(view) * worldFromLocal);
}

glm::mat4 rasterClipFromLocal(const CameraView& view, ImageSize size,
                              const glm::dmat4& worldFromLocal, glm::dvec2 ndcScale) {
  glm::dmat4 scale(1.0);
  scale[0][0] = ndcScale.x;
  scale[1][1] = ndcScale.y;
  return glm::mat4(scale * reversedZProjectionMatrix(view.lens, size) * viewMatrix(view) *
                   worldFromLocal);
}

glm::dmat4 clipFromWorld(const CameraView& view, ImageSize size) {
  return projectionMatrix(view.lens, size) * viewMatrix(view);
}

double viewDepth(const CameraView& view, const glm::dvec3& world) {
  return -(viewMatrix(view) * glm::dvec4(world, 1.0)).z;
}

ProjectedPoint projectToPixel(const CameraView& view, ImageSize size, const glm::dvec3& world) {
  glm::dvec4 eye = viewMatrix(view) * glm::dvec4(world, 1.0);
  glm::dvec4 clip = projectionMatrix(view.lens, size) * eye;
  ProjectedPoint p;
  p.depth = -eye.z;
  p.inFront = clip.w > 0.0;
  if (p.inFront) {
    double xn = clip.x / clip.w, yn = clip.y / clip.w;
    p.pixel = glm::dvec2((xn + 1.0) * 0.5 * size.width, (1.0 - yn) * 0.5 * size.height);
    double w = clip.w;
    p.inFrustum =
        -w <= clip.x && clip.x <= w && -w <= clip.y && clip.y <= w && -w <= clip.z && clip.z <= w;
  }
  return p;
}

PrimaryRays::PrimaryRays(const CameraView& view, ImageSize size) : view_(view), size_(size) {
  validate(view.lens, size);
  const Camera& lens = view.lens;
  const glm::dmat4& m = view.worldFromCamera;
  const glm::dvec3 right(m[0]), up(m[1]), back(m[2]), eye(m[3]);
  origin0_ = eye;
  direction0_ = -back;
  if (lens.perspective) {
    halfTan_ = std::tan(0.5 * lens.yfov);
    aspect_ = effectiveAspect(lens, size);
    // Eye direction (xn aspect t, yn t, -1), as at() builds it before normalising.
    directionX_ = (aspect_ * halfTan_) * right;
    directionY_ = halfTan_ * up;
  } else {
    originX_ = lens.xmag * right;
    originY_ = lens.ymag * up;
  }
}

Ray PrimaryRays::at(const glm::dvec2& pixel) const {
  const Camera& lens = view_.lens;
  double xn = 2.0 * pixel.x / size_.width - 1.0;
  double yn = 1.0 - 2.0 * pixel.y / size_.height;
  const double inf = std::numeric_limits<double>::infinity();
  glm::dvec3 originEye, dirEye;
  Ray r;
  if (lens.perspective) {
    const double t = halfTan_;
    // Inverse of the projection's x, y rows at eye depth 1.
    dirEye = glm::dvec3(xn * aspect_ * t, yn * t, -1.0);
    originEye = glm::dvec3(0.0);
    double len = glm::length(dirEye);  // ray length per unit of eye depth
    r.tNear = lens.znear * len;
    r.tFar = lens.zfar == 0.0 ? inf : lens.zfar * len;
    dirEye /= len;
  } else {
    originEye = glm::dvec3(xn * lens.xmag, yn * lens.ymag, 0.0);
    dirEye = glm::dvec3(0.0, 0.0, -1.0);
    r.tNear = lens.znear;
    r.tFar = lens.zfar;
  }
  const glm::dmat4& m = view_.worldFromCamera;
  r.origin = glm::dvec3(m * glm::dvec4(originEye, 1.0));
  glm::dvec3 d = glm::dvec3(m * glm::dvec4(dirEye, 0.0));
  double dl = glm::length(d);
  // worldFromCamera is rigid by contract; renormalising keeps tNear/tFar in world metres
  // even if a scale slipped through.
  r.direction = d / dl;
  r.tNear *= dl;
  r.tFar *= dl;
  return r;
}

Ray primaryRay(const CameraView& view, ImageSize size, const glm::dvec2& pixel) {
  return PrimaryRays(view, size).at(pixel);
}

}  // namespace rad
