// Projected area of a patch in pixels, clipped to the view frustum, ignoring occlusion: the
// denominator of a patch's visible fraction in rad-intervals (Martín, Pueyo, Tost, "Frame
// rate independent texture movies for animated radiosity", §4.3; docs/design.md §6.2
// rad-intervals).
//
// Computed analytically on the CPU, so it is exact up to rounding and costs a few hundred
// flops per polygon: clip the polygon in homogeneous clip space against the six frustum planes
// (Sutherland & Hodgman 1974; Blinn & Newell 1978, "Clipping using homogeneous coordinates"),
// divide by w, map to pixel coordinates (camera_projection.h) and take the shoelace area.
#pragma once

#include <glm/glm.hpp>

#include "libcommon/scene/camera_projection.h"
#include "libcommon/scene/geometry.h"

namespace rad {

// Area in pixels (>= 0, orientation ignored: a back-facing polygon counts too; the caller
// decides whether one-sided patches matter) of the world-space polygon's image, clipped to
// the frustum. 0 for a polygon entirely outside or behind the camera.
double projectedAreaPixels(const CameraView& view, ImageSize size, const Polygon& world);

// Same with a precomputed clip-from-world (clipFromWorld(view, size), times a model matrix for
// a polygon given in its local frame) for tight loops over many patches. Convex polygons of
// up to 10 vertices (more throws rad::Error(kInternal)).
double projectedAreaPixels(const glm::dmat4& clipFromPolygon, ImageSize size,
                           const glm::dvec3* points, int count);

}  // namespace rad
