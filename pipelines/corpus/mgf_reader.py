"""Reads an MGF file and its includes into triangles per object and material.

Greg Ward's Materials and Geometry Format, version 1.0 (May 1995); the entity pages quoted
below are those of the MGF specification. Everything is in world coordinates: each geometric
entity is placed by the transform in effect when it is given (vertices are not transformed when
defined: MGF spec, entity v), then by the root transform (the scene's up axis and scale).

Entities read: # c cxy cspec cct cmix m sides rd ed rs ts td ir v p n f o xf i ies sph cyl
cone ring torus prism (ies: the luminaire's flux on diffuse emitting rectangles, see
ies_luminaire.py). Unknown entities are skipped and counted, as the MGF parser does (MGF
footnotes, "ignoring new entities"). Vertex normals (n) are read for rings and tori only; faces
are flat (rad's radiosity elements are), so face normals are counted as dropped.
"""
import os

import held_out
import ies_luminaire
import mgf_colour
import mgf_material
import mgf_primitives
import mgf_transform
import mesh_cleanup
import polygon_triangulation


class MgfError(ValueError):
    """`file:line: what is wrong`."""


class _Colour:
    def __init__(self, xy=mgf_colour.NEUTRAL_XY):
        self.xy = xy


class _Vertex:
    def __init__(self, template=None):
        self.p = template.p if template else (0.0, 0.0, 0.0)
        self.n = template.n if template else None


class Report:
    """What the conversion did and dropped, for INDEX.txt and the converter's summary."""

    def __init__(self):
        self.faces = {}        # triangulation method -> faces
        self.primitives = {}   # sph, cyl, ... -> count
        self.unknown = {}      # entity -> count
        self.face_normals = 0  # faces whose vertices carry normals (ignored)
        self.duplicates = 0    # triangles dropped as exact copies of others
        self.reoriented = (0, 0)  # closed objects (and their triangles) turned outward
        self.luminaires = {}   # IES file -> [instances, flux down, flux up (lm), notes]
        self.invisible = {}    # material name -> polygons left out (mgf_material: invisible)
        self.files = []

    def count(self, table, key, n=1):
        table[key] = table.get(key, 0) + n


class MgfScene:
    """nodes: {node name: {material key: [triangle (3 points)]}}, in order of appearance;
    materials: {material key: (name, Material)}."""

    def __init__(self):
        self.nodes = {}
        self.materials = {}
        self.report = Report()


class _Reader:
    def __init__(self, root_matrix, qcd):
        self.scene = MgfScene()
        self.qcd = qcd
        self.colours, self.vertices, self.materials = {}, {}, {}
        self.colour = _Colour()
        self.vertex = _Vertex()
        self.material = mgf_material.Material()
        self.material_name = "unnamed"
        self.objects = []
        self.transforms = [[root_matrix]]  # stack of accumulated instance lists
        self.include_counts = {}
        self.where = ""

    # ---- errors and lines ------------------------------------------------------------------

    def fail(self, what):
        raise MgfError(f"{self.where}: {what}")

    def _lines(self, path):
        with open(path, encoding="latin-1") as f:
            pending, start = "", 0
            for number, line in enumerate(f, 1):
                line = line.rstrip("\n").rstrip("\r")
                if not pending:
                    start = number
                if line.endswith("\\"):
                    pending += line[:-1] + " "
                    continue
                yield start, pending + line
                pending = ""
            if pending:
                yield start, pending

    def read_file(self, path):
        held_out.check(path)
        if not os.path.isfile(path):
            if self.where == path:
                raise MgfError(f"{path}: no such file")
            self.fail(f"include {path}: no such file")
        self.scene.report.files.append(path)
        depth_o, depth_xf = len(self.objects), len(self.transforms)
        for number, line in self._lines(path):
            words = line.split()
            if not words or words[0].startswith("#"):
                continue
            self.where = f"{path}:{number}"
            self.entity(words, path)
        if len(self.objects) != depth_o or len(self.transforms) != depth_xf:
            self.scene.report.count(self.scene.report.unknown, "unbalanced o/xf at end of file")
            del self.objects[depth_o:]
            del self.transforms[depth_xf:]

    # ---- numbers and names ----------------------------------------------------------------

    def numbers(self, words, n=None):
        try:
            values = [float(w) for w in words]
        except ValueError:
            self.fail(f"'{' '.join(words)}': expected numbers")
        if n is not None and len(values) != n:
            self.fail(f"expected {n} numbers, got {len(values)}")
        return values

    def vertex_named(self, name):
        v = self.vertices.get(name)
        if v is None:
            self.fail(f"undefined vertex '{name}'")
        return v

    # ---- entities -------------------------------------------------------------------------

    def entity(self, words, path):
        kind, args = words[0], words[1:]
        handler = _HANDLERS.get(kind)
        if handler is None:
            self.scene.report.count(self.scene.report.unknown, kind if len(kind) < 24 else kind[:24] + "...")
            return
        handler(self, args, path)

    def context(self, args, table, make, what):
        """MGF's c, m and v: `X` unnamed, `X id` reuse, `X id =` new, `X id = template` copy."""
        if not args:
            return None, make(None)
        name = args[0]
        if len(args) == 1:
            if name not in table:
                self.fail(f"undefined {what} '{name}'")
            return name, table[name]
        if args[1] != "=" or len(args) > 3:
            self.fail(f"expected '{what} name = [template]'")
        template = None
        if len(args) == 3:
            if args[2] not in table:
                self.fail(f"undefined {what} '{args[2]}'")
            template = table[args[2]]
        table[name] = make(template)
        return name, table[name]

    def on_c(self, args, _):
        _, self.colour = self.context(args, self.colours,
                                      lambda t: _Colour(t.xy if t else mgf_colour.NEUTRAL_XY), "colour")

    def on_cxy(self, args, _):
        x, y = self.numbers(args, 2)
        # The spec asks x > 0, y > 0, x + y < 1; RenderPark's scenes hold x = 0 (clipped to the
        # gamut later) and y = 0 (black, as RenderPark makes it).
        if x < 0 or y < 0 or x + y > 1:
            self.fail(f"cxy {x} {y}: expected x >= 0, y >= 0, x + y <= 1")
        self.colour.xy = (x, y)

    def on_cspec(self, args, _):
        values = self.numbers(args)
        try:
            self.colour.xy = mgf_colour.spectrum_xy(values[0], values[1], values[2:])
        except (ValueError, IndexError) as e:
            self.fail(f"cspec: {e}")

    def on_cct(self, args, _):
        try:
            self.colour.xy = mgf_colour.blackbody_xy(self.numbers(args, 1)[0])
        except ValueError as e:
            self.fail(f"cct: {e}")

    def on_cmix(self, args, _):
        if len(args) < 2 or len(args) % 2:
            self.fail("cmix: expected weight colour pairs")
        pairs = []
        for i in range(0, len(args), 2):
            name = args[i + 1]
            if name not in self.colours:
                self.fail(f"cmix: undefined colour '{name}'")
            pairs.append((self.numbers([args[i]])[0], self.colours[name].xy))
        self.colour.xy = mgf_colour.mix_xy(pairs)

    def on_m(self, args, _):
        name, self.material = self.context(args, self.materials, mgf_material.Material, "material")
        self.material_name = name or "unnamed"

    def on_sides(self, args, _):
        n = self.numbers(args, 1)[0]
        if n not in (1, 2):
            self.fail("sides: expected 1 or 2")
        self.material.sides = int(n)

    def on_component(self, args, kind):
        m = self.material
        if kind in ("rd", "ed", "td"):
            value = self.numbers(args, 1)[0]
            setattr(m, kind, value)
            setattr(m, kind + "_xy", self.colour.xy)
        else:  # rs, ts: value and roughness
            value, roughness = self.numbers(args, 2)
            setattr(m, kind, value)
            setattr(m, kind + "_xy", self.colour.xy)
            setattr(m, kind + "_roughness", roughness)
        if value < 0:
            self.fail(f"{kind} {value}: expected a non-negative value")

    def on_ir(self, args, _):
        self.material.ir = tuple(self.numbers(args, 2))

    def on_v(self, args, _):
        _, self.vertex = self.context(args, self.vertices, _Vertex, "vertex")

    def on_p(self, args, _):
        self.vertex.p = tuple(self.numbers(args, 3))

    def on_n(self, args, _):
        n = tuple(self.numbers(args, 3))
        self.vertex.n = n if any(n) else None

    def on_o(self, args, _):
        if args:
            self.objects.append(args[0])
        elif self.objects:
            self.objects.pop()

    def on_xf(self, args, _):
        if not args:
            if len(self.transforms) > 1:
                self.transforms.pop()
            return
        self.transforms.append(self.combine(args))

    def combine(self, args):
        try:
            inner, _ = mgf_transform.parse(args)
        except mgf_transform.TransformError as e:
            self.fail(f"xf: {e}")
        return [mgf_transform.multiply(outer, m) for outer in self.transforms[-1] for m in inner]

    def on_i(self, args, path):
        if not args:
            self.fail("i: expected a file name")
        target = os.path.normpath(os.path.join(os.path.dirname(path), args[0]))
        try:
            instances, is_array = mgf_transform.parse(args[1:])
        except mgf_transform.TransformError as e:
            self.fail(f"i: {e}")
        stem = os.path.splitext(os.path.basename(target))[0]
        n = self.include_counts[stem] = self.include_counts.get(stem, 0) + 1
        base = stem if n == 1 else f"{stem}-{n}"
        where = self.where
        for k, m in enumerate(instances):
            self.objects.append(f"{base}[{k}]" if is_array else base)
            self.transforms.append([mgf_transform.multiply(outer, m) for outer in self.transforms[-1]])
            self.read_file(target)
            self.transforms.pop()
            self.objects.pop()
            self.where = where

    def on_ies(self, args, path):
        """MGF spec, entity ies: `ies file [-m multiplier] [transform]`, the transform as an
        enclosing xf. Each emitting rectangle gets its own material (ed in lm/m^2, neutral
        colour, no reflectance), named after the file; the material in effect is kept. The exitance
        is the flux over the opening's own area: a transform that scales (the NRC designs scale
        to feet and back, net 1) would change the flux by its area factor."""
        if not args:
            self.fail("ies: expected a file name")
        target = os.path.normpath(os.path.join(os.path.dirname(path), args[0]))
        held_out.check(target)
        rest, multiplier = args[1:], 1.0
        if rest[:1] == ["-m"]:
            if len(rest) < 2:
                self.fail("ies: -m without a multiplier")
            multiplier, rest = self.numbers(rest[1:2], 1)[0], rest[2:]
        try:
            with open(target, encoding="latin-1") as f:
                lum = ies_luminaire.parse(f.read(), multiplier)
        except OSError:
            self.fail(f"ies {target}: no such file")
        except ies_luminaire.IesError as e:
            self.fail(f"ies {target}: {e}")
        self.scene.report.files.append(target)
        stem = os.path.splitext(os.path.basename(target))[0]
        n = self.include_counts[stem] = self.include_counts.get(stem, 0) + 1
        self.objects.append(stem if n == 1 else f"{stem}-{n}")
        placed = self.combine(rest)
        self.transforms.append(placed)
        kept = (self.material, self.material_name)
        for polygon, exitance in ies_luminaire.emitters(lum):
            self.material = mgf_material.Material()
            self.material.ed = exitance
            self.material_name = f"{stem}_output"
            self.emit([polygon])
        self.material, self.material_name = kept
        self.transforms.pop()
        self.objects.pop()
        entry = self.scene.report.luminaires.setdefault(target, [0, lum.flux_down, lum.flux_up, lum.notes])
        entry[0] += len(placed)

    # ---- geometry ---------------------------------------------------------------------------

    def emit(self, polygons):
        """Adds local-frame polygons under the current object and material, once per instance;
        none if the material is invisible (mgf_material), counted."""
        if self.material.invisible():
            self.scene.report.count(self.scene.report.invisible, self.material_name,
                                    len(polygons) * len(self.transforms[-1]))
            return
        node = "/".join(self.objects) or "scene"
        key = (self.material_name,) + self.material.key()
        if key not in self.scene.materials:
            self.scene.materials[key] = (self.material_name, mgf_material.Material(self.material))
        tris = self.scene.nodes.setdefault(node, {}).setdefault(key, [])
        for m in self.transforms[-1]:
            flip = mgf_transform.determinant(m) < 0
            for poly in polygons:
                world = [mgf_transform.apply(m, p) for p in poly]
                if flip:
                    world.reverse()
                triangles, method = polygon_triangulation.triangulate(world)
                self.scene.report.count(self.scene.report.faces, method)
                tris.extend(tuple(world[i] for i in t) for t in triangles)

    def on_f(self, args, _):
        if len(args) < 3:
            self.fail("f: expected at least 3 vertices")
        verts = [self.vertex_named(a) for a in args]
        if any(v.n for v in verts):
            self.scene.report.face_normals += 1
        self.emit([[v.p for v in verts]])

    def primitive(self, kind, make):
        try:
            polys = make()
        except ValueError as e:
            self.fail(f"{kind}: {e}")
        self.scene.report.count(self.scene.report.primitives, kind)
        self.emit(polys)

    def on_sph(self, args, _):
        if len(args) != 2:
            self.fail("sph: expected a vertex and a radius")
        c, r = self.vertex_named(args[0]), self.numbers(args[1:], 1)[0]
        self.primitive("sph", lambda: mgf_primitives.sphere(c.p, r, self.qcd))

    def on_cyl(self, args, _):
        if len(args) != 3:
            self.fail("cyl: expected vertex radius vertex")
        a, r, b = self.vertex_named(args[0]), self.numbers(args[1:2], 1)[0], self.vertex_named(args[2])
        self.primitive("cyl", lambda: mgf_primitives.cylinder(a.p, r, b.p, self.qcd))

    def on_cone(self, args, _):
        if len(args) != 4:
            self.fail("cone: expected vertex radius vertex radius")
        a, b = self.vertex_named(args[0]), self.vertex_named(args[2])
        r1, r2 = self.numbers([args[1], args[3]], 2)
        self.primitive("cone", lambda: mgf_primitives.cone(a.p, r1, b.p, r2, self.qcd))

    def centre_with_normal(self, name, kind):
        v = self.vertex_named(name)
        if v.n is None:
            self.fail(f"{kind}: vertex '{name}' has no normal")
        return v

    def on_ring(self, args, _):
        if len(args) != 3:
            self.fail("ring: expected vertex rmin rmax")
        c = self.centre_with_normal(args[0], "ring")
        rmin, rmax = self.numbers(args[1:], 2)
        self.primitive("ring", lambda: mgf_primitives.ring(c.p, c.n, rmin, rmax, self.qcd))

    def on_torus(self, args, _):
        if len(args) != 3:
            self.fail("torus: expected vertex rmin rmax")
        c = self.centre_with_normal(args[0], "torus")
        rmin, rmax = self.numbers(args[1:], 2)
        self.primitive("torus", lambda: mgf_primitives.torus(c.p, c.n, rmin, rmax, self.qcd))

    def on_prism(self, args, _):
        if len(args) < 4:
            self.fail("prism: expected at least 3 vertices and a length")
        pts = [self.vertex_named(a).p for a in args[:-1]]
        length = self.numbers(args[-1:], 1)[0]
        self.primitive("prism", lambda: mgf_primitives.prism(pts, length))


_HANDLERS = {
    "c": _Reader.on_c, "cxy": _Reader.on_cxy, "cspec": _Reader.on_cspec, "cct": _Reader.on_cct,
    "cmix": _Reader.on_cmix, "m": _Reader.on_m, "sides": _Reader.on_sides, "ir": _Reader.on_ir,
    "rd": lambda r, a, p: r.on_component(a, "rd"), "ed": lambda r, a, p: r.on_component(a, "ed"),
    "rs": lambda r, a, p: r.on_component(a, "rs"), "ts": lambda r, a, p: r.on_component(a, "ts"),
    "td": lambda r, a, p: r.on_component(a, "td"),
    "v": _Reader.on_v, "p": _Reader.on_p, "n": _Reader.on_n, "o": _Reader.on_o, "xf": _Reader.on_xf,
    "i": _Reader.on_i, "ies": _Reader.on_ies, "f": _Reader.on_f, "sph": _Reader.on_sph, "cyl": _Reader.on_cyl,
    "cone": _Reader.on_cone, "ring": _Reader.on_ring, "torus": _Reader.on_torus,
    "prism": _Reader.on_prism,
}


def read(path, root_matrix=mgf_transform.IDENTITY, qcd=mgf_primitives.DEFAULT_QCD):
    """The scene of an MGF file; MgfError (or held_out.HeldOutError) on bad or held-out input."""
    reader = _Reader(root_matrix, qcd)
    reader.where = path
    reader.read_file(path)
    reader.scene.report.duplicates = mesh_cleanup.drop_duplicates(reader.scene)
    return reader.scene
