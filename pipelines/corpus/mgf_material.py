"""An MGF material (m: rd, ed, rs, ts, td, sides, ir) as the diffuse glTF material rad reads.

- Reflectance: rd in the colour given with it, as linear RGB (mgf_colour: Rec. 709 primaries,
  white E). rad's surfaces are Lambertian (docs/design.md section 4), so the diffuse part is the
  nearest equivalent: RenderPark's radiosity takes the same (its Galerkin elements use the
  BRDF's diffuse component only). rs, ts, td and ir are dropped and reported. A colour outside
  the RGB gamut is clipped at zero; a reflectance whose largest channel passes 0.999 (rad's and
  RenderPark's bound; a saturated colour of high rd) is scaled down whole, keeping its hue, as
  RenderPark does.
- Emission: ed is a diffuse emittance (luminous exitance) in lm/m^2 (MGF spec, entity ed), so
  the luminance is ed / pi cd/m^2; rad's emission is an exitant radiance, converted from
  photometric units with RenderPark's white efficacy, 183.07 lm/W (the luminous efficacy of
  equal-energy white): L_e = ed / (pi * 183.07) W m^-2 sr^-1 in the colour given with ed.
  glTF stores it as emissiveFactor (largest channel 1) x KHR_materials_emissive_strength.
- Invisible: a material that reflects and emits nothing and transmits everything (ts + td of
  at least 0.999: Radiance's `illum` shells around lamps, converted to MGF as `ts 1 0`) would be
  an opaque black surface here, hiding what it surrounds; the reader leaves its faces out and
  reports them.
- Sides: RenderPark forces every surface one-sided by default (-force-onesided), and so does
  this converter ('one'); 'mgf' keeps MGF's own rule (two-sided unless `sides 1`), 'two' makes
  every surface two-sided (glTF doubleSided).
"""
import math

import mgf_colour

WHITE_EFFICACY = 183.07  # lm/W, RenderPark's src/common/cie.cpp
MAX_REFLECTANCE = 0.999  # rad's bound (formats/gltf_scene.md, Materials)


class Material:
    """The MGF material context: every value with the chromaticity current when it was set."""

    def __init__(self, template=None):
        if template is not None:
            self.__dict__.update(template.__dict__)
            return
        neutral = mgf_colour.NEUTRAL_XY
        self.rd, self.rd_xy = 0.0, neutral
        self.ed, self.ed_xy = 0.0, neutral
        self.rs, self.rs_xy, self.rs_roughness = 0.0, neutral, 0.0
        self.ts, self.ts_xy, self.ts_roughness = 0.0, neutral, 0.0
        self.td, self.td_xy = 0.0, neutral
        self.sides = 2
        self.ir = None

    def invisible(self):
        """Transmits everything, reflects and emits nothing (see the module's note)."""
        return self.rd == 0.0 and self.rs == 0.0 and self.ed == 0.0 and self.ts + self.td >= MAX_REFLECTANCE

    def key(self):
        return tuple(sorted(self.__dict__.items()))


def _rounded(rgb):
    return [round(c, 6) for c in rgb]


def to_gltf(mat, sides_mode):
    """(gltf fields, emitted RGB radiance, notes): notes are (kind, text), kind 'changed' (a
    colour clipped or scaled) or the component dropped ('rs', 'ts', 'td', 'ir') with its value."""
    notes = []
    rgb, clipped = mgf_colour.xyY_to_rgb(*mat.rd_xy, mat.rd)
    if clipped:
        notes.append(("changed", f"rd colour {mat.rd_xy[0]:.3f},{mat.rd_xy[1]:.3f} clipped to the RGB gamut"))
    top = max(rgb)
    if top > MAX_REFLECTANCE:
        notes.append(("changed", f"rd {mat.rd:g} in its colour gives a channel of {top:.3f}; scaled to {MAX_REFLECTANCE}"))
        rgb = [c * MAX_REFLECTANCE / top for c in rgb]
    for name in ("rs", "ts", "td"):
        if getattr(mat, name) > 0.0:
            notes.append((name, getattr(mat, name)))
    if mat.ir is not None:
        notes.append(("ir", mat.ir[0]))
    fields = {"pbrMetallicRoughness": {"baseColorFactor": _rounded(rgb) + [1.0],
                                       "metallicFactor": 0.0, "roughnessFactor": 1.0}}
    emission = [0.0, 0.0, 0.0]
    if mat.ed > 0.0:
        emission, clipped = mgf_colour.xyY_to_rgb(*mat.ed_xy, mat.ed / (math.pi * WHITE_EFFICACY))
        if clipped:
            notes.append(("changed", "ed colour clipped to the RGB gamut"))
        strength = max(emission)
        if strength > 0.0:
            fields["emissiveFactor"] = _rounded([c / strength for c in emission])
            if strength != 1.0:
                fields["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
    two_sided = {"one": False, "two": True, "mgf": mat.sides == 2}[sides_mode]
    if two_sided:
        fields["doubleSided"] = True
    return fields, emission, notes
