#!/usr/bin/env python3
"""Writes the seam test scenes of issue 56 as glTF 2.0: walls tessellated the way converters and
exporters do, whose shading must be continuous across every shared edge of coplanar triangles.

  office-fan.gltf   a 5 x 4 x 2.8 m office: the long wall fan-triangulated around a door and a
                    window (a few outline vertices joined to the openings' corners, as MGF and
                    RenderPark converters triangulate: long slivers of very different sizes
                    meeting at a few vertices), the other walls two big triangles each but one,
                    which is a fine regular grid; a 1.3 x 0.04 x 0.04 m emissive tube lamp near
                    the ceiling, a desk under the window, a camera facing the fan wall that
                    slides slowly sideways over 4 s (frames 0-95 at 24 fps).
  slivers.gltf      a wall fanned from a point of its bottom edge under a tube lamp: slivers whose
                    top edges are on a geometric ladder (aspect ratios from about 1:1000 to 1:2),
                    beside a triangle 1,000 times the thinnest sliver's area.
  t-junctions.gltf  a wall split into one big quad beside a grid of small quads, so the grid's
                    vertices on the shared edge are T-junctions of the big quad's edge.
  ngon.gltf         an L-shaped wall and a wall pierced by a window, each one n-gon triangulated
                    by ear clipping in its vertex order (as Blender's polyfill does for the glTF
                    exporter; the window is joined to the outline by a bridge edge).

The three small scenes are static (frame 0 alone). Vertices are shared between the triangles of
a mesh (indexed, as exporters write them). Only the standard library is used and the output is
deterministic, so regenerated files are byte-identical.

usage: make_seam_scenes.py OUTDIR [NAME ...]     (no NAME: every scene)
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_paper_scenes as paper  # noqa: E402

FPS = 24.0
WHITE, FLOOR, WOOD, LIGHT = range(4)
MATERIALS = [
    ("white", (0.75, 0.75, 0.72), None),
    ("floor", (0.45, 0.42, 0.38), None),
    ("wood", (0.55, 0.38, 0.22), None),
    ("light", (0.8, 0.8, 0.8), (1.0, 0.95, 0.85)),
]


class Gltf(paper.Gltf):
    """make_paper_scenes' glTF writer with this file's materials; meshes are indexed."""

    def mesh(self, name, verts, tris, material):
        return self.indexed_mesh(name, verts, tris, material)

    def write(self, path, light_strength):
        super().write(path, light_strength, MATERIALS)


# --- tessellations (2D, in a wall's plane) --------------------------------------------------

def cross2(o, a, b):
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def inside_triangle(p, a, b, c):
    """p strictly inside or on an edge of the CCW triangle abc (not at a corner)."""
    if p in (a, b, c):
        return False
    return cross2(a, b, p) >= 0 and cross2(b, c, p) >= 0 and cross2(c, a, p) >= 0


def ear_clip(ring):
    """Triangles (index triples into ring, CCW) of the simple CCW polygon ring, by ear clipping
    in the ring's order: the first ear found from the ring's start is cut, then the search goes
    on from the vertex after it (Blender's polyfill and MGF's converters cut ears this way, which
    fans a convex run of vertices from one corner). A bridged ring (a hole joined to the outline
    by an edge walked both ways) repeats the bridge's two points; they are not taken as inside."""
    idx = list(range(len(ring)))
    tris = []
    start = 0
    while len(idx) > 3:
        n = len(idx)
        for s in range(n):
            k = (start + s) % n
            a, b, c = idx[k - 1], idx[k], idx[(k + 1) % n]
            pa, pb, pc = ring[a], ring[b], ring[c]
            if cross2(pa, pb, pc) <= 1e-12:
                continue
            if any(inside_triangle(ring[i], pa, pb, pc) for i in idx if i not in (a, b, c)):
                continue
            tris.append((a, b, c))
            del idx[k]
            start = k % len(idx)
            break
        else:
            raise ValueError("ear_clip: no ear in %r" % [ring[i] for i in idx])
    tris.append(tuple(idx))
    return tris


def bridged(outline, hole):
    """One ring from a CCW outline and a hole (CCW as given, walked CW here): the hole's first
    corner is joined to the outline vertex nearest to it by a bridge edge walked both ways."""
    h = list(reversed(hole))
    o = min(range(len(outline)),
            key=lambda i: (outline[i][0] - h[0][0]) ** 2 + (outline[i][1] - h[0][1]) ** 2)
    return outline[:o + 1] + h + [h[0]] + outline[o:]


def area2(ring, tris):
    return sum(cross2(ring[a], ring[b], ring[c]) for a, b, c in tris) / 2


def ring_area(ring):
    return sum(ring[i - 1][0] * ring[i][1] - ring[i][0] * ring[i - 1][1]
               for i in range(len(ring))) / 2


def wall(origin, du, dv, points, tris):
    """points in the wall's (u, v) plane onto origin + u du + v dv (front = du x dv)."""
    verts = [tuple(origin[k] + p[0] * du[k] + p[1] * dv[k] for k in range(3)) for p in points]
    return verts, [tuple(t) for t in tris]


def dedup(ring, tris):
    """Merges repeated points of a bridged ring so the mesh shares its vertices."""
    pts, where, remap = [], {}, []
    for p in ring:
        if p not in where:
            where[p] = len(pts)
            pts.append(p)
        remap.append(where[p])
    return pts, [tuple(remap[i] for i in t) for t in tris]


def grid(w, h, nu, nv, u0=0.0):
    """A regular nu x nv grid of quads over [u0, u0 + w] x [0, h], two triangles a quad."""
    pts = [(u0 + w * i / nu, h * j / nv) for j in range(nv + 1) for i in range(nu + 1)]
    tris = []
    for j in range(nv):
        for i in range(nu):
            a = j * (nu + 1) + i
            b, c, d = a + 1, a + nu + 2, a + nu + 1
            tris += [(a, b, c), (a, c, d)]
    return pts, tris


def rect(w, h):
    return [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)], [(0, 1, 2), (0, 2, 3)]


def checked(name, ring, tris, expected_area):
    got = area2(ring, tris)
    if abs(got - expected_area) > 1e-9 * max(1.0, expected_area) or \
            any(cross2(ring[a], ring[b], ring[c]) <= 0 for a, b, c in tris):
        raise ValueError("%s: bad triangulation (area %g, expected %g)" % (name, got, expected_area))
    return tris


def fan_wall(W, H, door, window, top_vertices):
    """The office's long wall W x H: its outline runs round a door (x0, x1, top) on the floor
    and keeps vertices on its top edge at top_vertices (where a converter's neighbouring faces
    met it); a window (x0, x1, y0, y1) is a hole bridged to it. Ear clipping in the outline's
    order joins the outline's few vertices to the openings' corners with long slivers."""
    dx0, dx1, dtop = door
    wx0, wx1, wy0, wy1 = window
    outline = [(0.0, 0.0), (dx0, 0.0), (dx0, dtop), (dx1, dtop), (dx1, 0.0), (W, 0.0), (W, H)]
    outline += [(u, H) for u in sorted(top_vertices, reverse=True)] + [(0.0, H)]
    hole = [(wx0, wy0), (wx1, wy0), (wx1, wy1), (wx0, wy1)]
    ring = bridged(outline, hole)
    tris = ear_clip(ring)
    expected = W * H - (dx1 - dx0) * dtop - (wx1 - wx0) * (wy1 - wy0)
    checked("fan wall", ring, tris, expected)
    return dedup(ring, tris)


def sliver_fan(W, H, apex, first, ratio, last):
    """A W x H wall fanned from apex (apex, 0) on its bottom edge: slivers to the top edge's
    points apex, apex + first, apex + first (1 + ratio), ... up to `last` (each gap `ratio` times
    the one before), then big triangles from the same apex to the wall's corners. The thinnest
    sliver is `first` wide at the top and H long; its neighbour on the left, (apex, 0), (apex, H),
    (0, H), is W apex H / 2 large."""
    tops = [apex]
    gap = first
    while tops[-1] + gap < last:
        tops.append(tops[-1] + gap)
        gap *= ratio
    tops.append(last)
    pts = [(apex, 0.0), (W, 0.0), (W, H)] + [(x, H) for x in reversed(tops)] + [(0.0, H),
                                                                                 (0.0, 0.0)]
    tris = [(0, i, i + 1) for i in range(1, len(pts) - 1)]
    checked("slivers", pts, tris, W * H)
    return pts, tris


def t_junction_wall(W, H, split, nu, nv):
    """A W x H wall: [0, split] one quad (two triangles), [split, W] an nu x nv grid; the grid's
    vertices on u = split are T-junctions of the quad's edge."""
    pts = [(0.0, 0.0), (split, 0.0), (split, H), (0.0, H)]
    tris = [(0, 1, 2), (0, 2, 3)]
    gp, gt = grid(W - split, H, nu, nv, split)
    tris += [tuple(i + len(pts) for i in t) for t in gt]
    pts += gp
    checked("t-junctions", pts, tris, W * H)
    return pts, tris


def l_wall(W, H, cut_u, cut_v):
    """An L-shaped n-gon: W x H without its top-right cut_u x cut_v corner, plus a few vertices
    along its long edges (an exporter's n-gon keeps the vertices of the faces it was cut from)."""
    ring = [(0.0, 0.0), (W / 3, 0.0), (2 * W / 3, 0.0), (W, 0.0), (W, H - cut_v),
            (W - cut_u, H - cut_v), (W - cut_u, H), (0.0, H), (0.0, H / 2)]
    tris = ear_clip(ring)
    checked("l wall", ring, tris, ring_area(ring))
    return ring, tris


def pierced_wall(W, H, window):
    wx0, wx1, wy0, wy1 = window
    outline = [(0.0, 0.0), (W, 0.0), (W, H), (0.0, H)]
    ring = bridged(outline, [(wx0, wy0), (wx1, wy0), (wx1, wy1), (wx0, wy1)])
    tris = ear_clip(ring)
    checked("pierced wall", ring, tris, W * H - (wx1 - wx0) * (wy1 - wy0))
    return dedup(ring, tris)


# --- 3D pieces -------------------------------------------------------------------------------

def box(x0, y0, z0, x1, y1, z1, bottom=True):
    """Axis-aligned box, faces outwards, as (verts, tris)."""
    return quads(paper.box(x0, y0, z0, x1, y1, z1, bottom))


def quads(qs):
    verts, tris = [], []
    for q in qs:
        b = len(verts)
        verts += q
        tris += [(b, b + 1, b + 2), (b, b + 2, b + 3)]
    return verts, tris


def join(*parts):
    verts, tris = [], []
    for v, t in parts:
        tris += [tuple(i + len(verts) for i in tri) for tri in t]
        verts += v
    return verts, tris


def desk(x0, z0, x1, z1):
    top = box(x0, 0.72, z0, x1, 0.75, z1)
    legs = [box(x - 0.03, 0.0, z - 0.03, x + 0.03, 0.72, z + 0.03, bottom=False)
            for x in (x0 + 0.05, x1 - 0.05) for z in (z0 + 0.05, z1 - 0.05)]
    return join(top, *legs)


def room_walls(g, W, H, D, far_wall, left_wall=None):
    """An inward-facing room [0,W] x [0,H] x [0,D]: the far wall (z = D) from far_wall's
    (points, tris) in its (u = x, v = y) plane seen from inside (u runs to -x, so front faces
    -z), the left wall (x = 0) from left_wall or two triangles, the rest two triangles each."""
    # z = D, seen from inside (front -z): u along -x from x = W, v along +y.
    pts, tris = far_wall
    g.node("far_wall", g.mesh("far_wall", *wall((W, 0, D), (-1, 0, 0), (0, 1, 0), pts, tris),
                              WHITE))
    pts, tris = left_wall or rect(D, H)
    g.node("left_wall", g.mesh("left_wall", *wall((0, 0, D), (0, 0, -1), (0, 1, 0), pts, tris),
                               WHITE))
    for name, origin, du, dv, w, h, mat in (
            ("right_wall", (W, 0, 0), (0, 0, 1), (0, 1, 0), D, H, WHITE),
            ("near_wall", (0, 0, 0), (1, 0, 0), (0, 1, 0), W, H, WHITE),
            ("floor", (0, 0, 0), (0, 0, 1), (1, 0, 0), D, W, FLOOR),
            ("ceiling", (0, H, 0), (1, 0, 0), (0, 0, 1), W, D, WHITE)):
        pts, tris = rect(w, h)
        g.node(name, g.mesh(name, *wall(origin, du, dv, pts, tris), mat))


def tube_lamp(g, x0, x1, y, z, t=0.04):
    g.node("tube_lamp", g.mesh("tube_lamp", *box(x0, y - t / 2, z - t / 2, x1, y + t / 2,
                                                   z + t / 2), LIGHT))


# --- scenes ----------------------------------------------------------------------------------

def office_fan():
    g = Gltf("office-fan")
    W, H, D = 5.0, 2.8, 4.0
    # The far wall's u runs from x = W to x = 0: the door is on the image's left.
    fan = fan_wall(W, H, door=(3.6, 4.5, 2.1), window=(0.8, 2.6, 0.9, 2.1),
                   top_vertices=(1.7, 4.05))
    room_walls(g, W, H, D, fan, left_wall=grid(D, H, 8, 6))
    tube_lamp(g, 1.85, 3.15, 2.62, 3.1)
    g.node("desk", g.mesh("desk", *desk(2.6, 3.25, 4.0, 3.9), WOOD))
    cam = g.node("camera", camera=g.camera(0.9))
    times = [0.0, 2.0, 4.0]
    target = (2.5, 1.3, D)
    eyes = [(2.1, 1.55, 0.35), (2.5, 1.6, 0.3), (2.9, 1.55, 0.35)]
    g.animate(cam, "translation", times, eyes)
    g.animate(cam, "rotation", times, [paper.quat_look(e, target) for e in eyes])
    return g


def small_room(name, far_wall, lamp_z=1.9):
    """A 4 x 2.5 x 2.5 m room whose far wall is far_wall, a tube lamp 0.6 m in front of it near
    the ceiling, a static camera facing it."""
    g = Gltf(name)
    W, H, D = 4.0, 2.5, 2.5
    room_walls(g, W, H, D, far_wall)
    tube_lamp(g, 1.35, 2.65, 2.3, lamp_z)
    cam = g.node("camera", camera=g.camera(0.95))
    eye = (2.0, 1.3, 0.05)
    g.nodes[cam]["translation"] = list(eye)
    g.nodes[cam]["rotation"] = list(paper.quat_look(eye, (2.0, 1.2, D)))
    return g


def slivers():
    # u runs from x = W: the fan's apex is under the lamp, its slivers sweep through the bright
    # spot the lamp makes on the wall.
    return small_room("slivers", sliver_fan(4.0, 2.5, apex=2.0, first=0.002, ratio=2.0, last=3.4))


def t_junctions():
    return small_room("t-junctions", t_junction_wall(4.0, 2.5, split=2.2, nu=6, nv=10))


def ngon():
    g = small_room("ngon", pierced_wall(4.0, 2.5, (2.3, 3.3, 1.0, 1.9)))
    # An L-shaped panel standing 5 cm proud of the left wall, facing +x.
    pts, tris = l_wall(1.6, 1.8, 0.7, 0.8)
    g.node("l_panel", g.mesh("l_panel", *wall((0.05, 0.2, 1.9), (0, 0, -1), (0, 1, 0), pts, tris),
                             WHITE))
    return g


SCENES = [("office-fan", office_fan), ("slivers", slivers), ("t-junctions", t_junctions),
          ("ngon", ngon)]
LIGHT_STRENGTH = 40.0


def main():
    paper.scene_set_main("make_seam_scenes.py", __doc__,
                         [(name, lambda make=make: (make(), LIGHT_STRENGTH))
                          for name, make in SCENES])


if __name__ == "__main__":
    main()
