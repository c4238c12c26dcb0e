"""MGF's curved and extruded primitives as polygons: sph, cyl, cone, ring, torus, prism.

The tessellation is RenderPark's (its MGF parser, after Ward's): a circle is cut into
4 x QCD segments (QCD "quarter circle divisions", RenderPark's default 4), a sphere into 2 x QCD
cone bands from pole to pole, a torus into 4 x QCD cones around its axis. Orientation follows
the MGF spec: normals outward for positive radii (or length), inward for negative ones; a ring
faces along its centre vertex's normal; a prism's first face keeps the winding given and the
solid is extruded behind it. Each function returns polygons (lists of 3D points in the MGF
file's own frame), which the reader transforms and triangulates like faces.
"""
import math

DEFAULT_QCD = 4


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _add(a, b, s=1.0):
    return (a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _unit(a):
    n = math.sqrt(_dot(a, a))
    if n == 0.0:
        raise ValueError("zero-length direction")
    return (a[0] / n, a[1] / n, a[2] / n)


def _axes(w):
    """u, v with u x v = w, all unit."""
    w = _unit(w)
    helper = (1.0, 0.0, 0.0) if abs(w[0]) < 0.6 else (0.0, 1.0, 0.0)
    u = _unit(_cross(helper, w))
    return u, _cross(w, u)


def _circle(centre, u, v, radius, segments):
    return [_add(_add(centre, u, radius * math.cos(2 * math.pi * i / segments)), v,
                 radius * math.sin(2 * math.pi * i / segments)) for i in range(segments)]


def _polygon_normal(poly):
    n = (0.0, 0.0, 0.0)
    for i in range(len(poly)):
        n = _add(n, _cross(poly[i - 1], poly[i]))
    return n


def _orient(poly, outward):
    """poly wound so that its normal points along `outward` (a direction at its centroid)."""
    return poly if _dot(_polygon_normal(poly), outward) >= 0.0 else poly[::-1]


def cone(p1, r1, p2, r2, qcd=DEFAULT_QCD):
    """A truncated cone between the circles (p1, r1) and (p2, r2); open ends."""
    if (r1 < 0) != (r2 < 0) and r1 != 0 and r2 != 0:
        raise ValueError("cone radii of different signs")
    inward = r1 < 0 or r2 < 0
    axis = _sub(p2, p1)
    u, v = _axes(axis)
    w = _unit(axis)
    n = 4 * qcd
    c1 = _circle(p1, u, v, abs(r1), n)
    c2 = _circle(p2, u, v, abs(r2), n)
    polys = []
    for i in range(n):
        j = (i + 1) % n
        quad = [c1[i], c1[j], c2[j], c2[i]]
        centroid = tuple(sum(q[k] for q in quad) / 4 for k in range(3))
        rel = _sub(centroid, p1)
        radial = _add(rel, w, -_dot(rel, w))
        polys.append(_orient(quad, radial if not inward else _add((0, 0, 0), radial, -1.0)))
    return polys


def cylinder(p1, r, p2, qcd=DEFAULT_QCD):
    return cone(p1, r, p2, r, qcd)


def sphere(centre, r, qcd=DEFAULT_QCD):
    """2 x qcd bands of cones from the +z pole to the -z pole."""
    polys = []
    bands = 2 * qcd
    for i in range(1, bands + 1):
        t0, t1 = (i - 1) * math.pi / bands, i * math.pi / bands
        a = (centre[0], centre[1], centre[2] + abs(r) * math.cos(t0))
        b = (centre[0], centre[1], centre[2] + abs(r) * math.cos(t1))
        ra = 0.0 if i == 1 else abs(r) * math.sin(t0)  # the poles exactly
        rb = 0.0 if i == bands else abs(r) * math.sin(t1)
        for quad in cone(a, ra, b, rb, qcd):
            centroid = tuple(sum(q[k] for q in quad) / len(quad) for k in range(3))
            polys.append(_orient(quad, _add((0, 0, 0), _sub(centroid, centre), -1.0 if r < 0 else 1.0)))
    return polys


def ring(centre, normal, rmin, rmax, qcd=DEFAULT_QCD):
    """The annulus rmin..rmax (a disc when rmin = 0) facing along normal."""
    if rmin < 0 or rmax <= rmin:
        raise ValueError("ring needs 0 <= rmin < rmax")
    u, v = _axes(normal)
    n = 4 * qcd
    inner = _circle(centre, u, v, rmin, n) if rmin > 0 else [centre] * n
    outer = _circle(centre, u, v, rmax, n)
    return [_orient([inner[i], outer[i], outer[(i + 1) % n], inner[(i + 1) % n]], normal) for i in range(n)]


def torus(centre, normal, rmin, rmax, qcd=DEFAULT_QCD):
    """The torus between radii rmin and rmax around normal: 4 x qcd cones along its tube."""
    if (rmin < 0) != (rmax < 0) and rmin != 0:
        raise ValueError("torus radii of different signs")
    if abs(rmax) <= abs(rmin):
        raise ValueError("torus needs |rmax| > |rmin|")
    inward = rmax < 0
    big, tube = (abs(rmin) + abs(rmax)) / 2, (abs(rmax) - abs(rmin)) / 2
    w = _unit(normal)
    u, v = _axes(w)
    n = 4 * qcd
    polys = []
    for j in range(n):
        p0, p1 = 2 * math.pi * j / n, 2 * math.pi * (j + 1) / n
        h0, h1 = tube * math.sin(p0), tube * math.sin(p1)
        r0, r1 = big + tube * math.cos(p0), big + tube * math.cos(p1)
        for quad in cone(_add(centre, w, h0), r0, _add(centre, w, h1), r1, qcd):
            centroid = tuple(sum(q[k] for q in quad) / 4 for k in range(3))
            rel = _sub(centroid, centre)
            radial = _add(rel, w, -_dot(rel, w))
            tube_centre = _add(centre, _unit(radial), big)
            out = _sub(centroid, tube_centre)
            polys.append(_orient(quad, out if not inward else _add((0, 0, 0), out, -1.0)))
    return polys


def prism(points, length):
    """The closed prism of the face `points` extruded by `length` behind it (MGF prism)."""
    normal = _unit(_polygon_normal(points))
    offset = (-length * normal[0], -length * normal[1], -length * normal[2])
    far = [_add(p, offset) for p in points]
    polys = [list(points), far[::-1]]
    n = len(points)
    for k in range(n):
        j = (k + 1) % n
        polys.append([points[k], far[k], far[j], points[j]])
    return polys
