"""Repairs a read MGF scene needs before rad can use it: copies of triangles, inside-out objects.

MGF materials are two-sided unless they say `sides 1`, so many MGF files never needed a
consistent winding; rad's surfaces, like RenderPark's by default, are one-sided (a patch lights
and is lit on its front only), so a wall facing away from the room leaves the room dark.
Both passes work on MgfScene.nodes ({node: {material key: [triangle]}}) in place.
"""
import struct


def _f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def _canonical(tri):
    """The triangle's corners in float32, rotated to start at the smallest: equal for the same
    triangle in the same winding, different for the opposite winding."""
    q = [tuple(_f32(c) for c in p) for p in tri]
    i = q.index(min(q))
    return tuple(q[i:] + q[:i])


def drop_duplicates(scene):
    """Removes triangles with the same three corners, in the same winding, as an earlier one:
    coincident copies of a surface, such as a file included twice, fight in depth and double
    the patches. Opposite windings (a thin sheet's two sides) are kept. Returns how many."""
    seen, dropped = set(), 0
    for by_material in scene.nodes.values():
        for key, tris in by_material.items():
            kept = []
            for tri in tris:
                canon = _canonical(tri)
                if canon in seen:
                    dropped += 1
                    continue
                seen.add(canon)
                kept.append(tri)
            by_material[key] = kept
    return dropped


def _closed_volume(tris):
    """The signed volume of an object's triangles when they close a surface (every edge met
    once in each direction, corners matched exactly), else None."""
    edges = {}
    for tri in tris:
        q = [tuple(_f32(c) for c in p) for p in tri]
        for a, b in ((q[0], q[1]), (q[1], q[2]), (q[2], q[0])):
            edges[(a, b)] = edges.get((a, b), 0) + 1
    if not edges or any(edges.get((b, a), 0) != n for (a, b), n in edges.items()):
        return None
    n = 3 * len(tris)
    centre = [sum(p[k] for tri in tris for p in tri) / n for k in range(3)]
    volume = 0.0
    for a, b, c in tris:
        u = [a[k] - centre[k] for k in range(3)]
        v = [b[k] - centre[k] for k in range(3)]
        w = [c[k] - centre[k] for k in range(3)]
        volume += (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
                   + u[2] * (v[0] * w[1] - v[1] * w[0])) / 6.0
    return volume


def orient_closed_outward(scene):
    """Reverses every object whose triangles close a surface around a negative volume (an
    inside-out box: its faces look into the solid, so from outside one sees only backs).
    Open objects keep their winding: there is no inside to tell. Returns (objects, triangles)."""
    objects = triangles = 0
    for by_material in scene.nodes.values():
        tris = [t for ts in by_material.values() for t in ts]
        volume = _closed_volume(tris)
        if volume is None or volume >= 0.0:
            continue
        for key, ts in by_material.items():
            by_material[key] = [(c, b, a) for a, b, c in ts]
        objects += 1
        triangles += len(tris)
    return objects, triangles
