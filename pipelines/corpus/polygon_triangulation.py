"""Triangulation of MGF faces (`f`): n-gons, concave ones, and faces with holes given as seams.

As RenderPark and the MGF translators do, a convex face is a fan from its first vertex (the
long slivers of such fans are part of what the corpus exercises: issue 56). A concave face, or
one whose outline touches itself (MGF has no holes: a hole is joined to the outline by a seam
traversed both ways, "f v1 v2 v3 v4 v5 v6 v7 v8 v5 v4", MGF spec, entity f), is cut by ear
clipping in the plane of its Newell normal: an ear is a convex corner whose triangle holds no
other vertex of the face, a vertex at the same place as one of the ear's corners (the two ends
of a seam) not counting. Indices refer to the face's own vertex list; the winding of every
triangle is the face's.
"""
import math


def newell_normal(points):
    """Twice the signed vector area of a closed polygon (Newell's method)."""
    nx = ny = nz = 0.0
    n = len(points)
    for i in range(n):
        x0, y0, z0 = points[i]
        x1, y1, z1 = points[(i + 1) % n]
        nx += (y0 - y1) * (z0 + z1)
        ny += (z0 - z1) * (x0 + x1)
        nz += (x0 - x1) * (y0 + y1)
    return nx, ny, nz


def triangle_area(a, b, c):
    u = (b[0] - a[0], b[1] - a[1], b[2] - a[2])
    v = (c[0] - a[0], c[1] - a[1], c[2] - a[2])
    cx, cy, cz = u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]
    return 0.5 * math.sqrt(cx * cx + cy * cy + cz * cz)


def _project(points, normal):
    """2D coordinates in the plane most facing the normal, counter-clockwise seen from it."""
    axis = max(range(3), key=lambda k: abs(normal[k]))
    u, v = [(1, 2), (2, 0), (0, 1)][axis]
    if normal[axis] < 0:
        u, v = v, u
    return [(p[u], p[v]) for p in points]


def _cross(o, a, b):
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _is_convex(p2, eps):
    """Every corner turns left (or goes straight) and the outline winds once, no repeated point."""
    n = len(p2)
    if len(set(p2)) != n:
        return False
    turning = 0.0
    for i in range(n):
        a, b, c = p2[i - 1], p2[i], p2[(i + 1) % n]
        if _cross(a, b, c) < -eps:
            return False
        a1 = math.atan2(b[1] - a[1], b[0] - a[0])
        a2 = math.atan2(c[1] - b[1], c[0] - b[0])
        d = a2 - a1
        while d <= -math.pi:
            d += 2 * math.pi
        while d > math.pi:
            d -= 2 * math.pi
        turning += d
    return abs(turning - 2 * math.pi) < 1e-6


def _inside_or_on(p, a, b, c, eps):
    return _cross(a, b, p) >= -eps and _cross(b, c, p) >= -eps and _cross(c, a, p) >= -eps


def _ear_clip(p2, eps):
    """Triangles (index triples) of a simple polygon, possibly with seams; and whether every
    step found an ear (False: the rest was cut at its least bad corner)."""
    idx = list(range(len(p2)))
    tris = []
    clean = True
    while len(idx) > 3:
        m = len(idx)
        chosen = None
        for k in range(m):
            a, b, c = idx[k - 1], idx[k], idx[(k + 1) % m]
            if _cross(p2[a], p2[b], p2[c]) <= eps:
                continue
            corners = (p2[a], p2[b], p2[c])
            if any(j not in (a, b, c) and p2[j] not in corners
                   and _inside_or_on(p2[j], *corners, eps) for j in idx):
                continue
            chosen = k
            break
        if chosen is None:
            # A corner with no area (collinear, or the turn of a seam) encloses nothing: drop it.
            flat = [k for k in range(m) if abs(_cross(p2[idx[k - 1]], p2[idx[k]], p2[idx[(k + 1) % m]])) <= eps]
            if flat:
                idx.pop(flat[0])
                continue
            clean = False
            chosen = max(range(m), key=lambda k: _cross(p2[idx[k - 1]], p2[idx[k]], p2[idx[(k + 1) % m]]))
        a, b, c = idx[chosen - 1], idx[chosen], idx[(chosen + 1) % m]
        if _cross(p2[a], p2[b], p2[c]) > eps:
            tris.append((a, b, c))
        idx.pop(chosen)
    if len(idx) == 3 and _cross(*(p2[j] for j in idx)) > eps:
        tris.append(tuple(idx))
    return tris, clean


def triangulate(points):
    """Triangles of a planar (or nearly planar) face given by its 3D points in MGF order.

    Returns (triangles, method): method is 'triangle', 'fan', 'ears', 'ears-forced' (ear clipping
    found no ear somewhere: a self-intersecting face) or 'degenerate' (no area; no triangles).
    Consecutive repeated points are skipped; zero-area triangles are not returned.
    """
    keep = [i for i in range(len(points)) if points[i] != points[i - 1]] if len(points) > 1 else []
    pts = [points[i] for i in keep]
    normal = newell_normal(pts) if len(pts) >= 3 else (0.0, 0.0, 0.0)
    lo = [min(p[k] for p in pts) for k in range(3)] if pts else [0, 0, 0]
    hi = [max(p[k] for p in pts) for k in range(3)] if pts else [0, 0, 0]
    size2 = sum((hi[k] - lo[k]) ** 2 for k in range(3))
    if len(pts) < 3 or math.sqrt(sum(c * c for c in normal)) <= 1e-12 * size2:
        return [], "degenerate"
    eps = 1e-12 * size2
    if len(pts) == 3:
        return [(keep[0], keep[1], keep[2])], "triangle"
    p2 = _project(pts, normal)
    if _is_convex(p2, eps):
        tris = [(0, i, i + 1) for i in range(1, len(pts) - 1) if _cross(p2[0], p2[i], p2[i + 1]) > eps]
        method = "fan"
    else:
        tris, clean = _ear_clip(p2, eps)
        method = "ears" if clean else "ears-forced"
    return [(keep[a], keep[b], keep[c]) for a, b, c in tris], method
