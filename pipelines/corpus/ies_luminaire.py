"""An IES luminaire (MGF's `ies` entity) as diffuse emitting rectangles of its total output.

rad's emitters are diffuse (docs/design.md section 4), so a luminaire's measured candela
distribution cannot be kept; what is kept is its luminous flux, on the luminous opening the IES
file gives, split as Radiance's ies2rad places a luminaire's sources: the flux below the
horizontal (vertical angles under 90 degrees, IES type C photometry: 0 is the nadir) leaves a
rectangle facing down at z = -height/2, the flux above it a rectangle facing up at +height/2;
width along x, length along y, centred on the origin, in metres (the MGF spec, entity ies: the
luminaire is then placed by the entity's transform). The emittance is the flux over the
rectangle's area (lm/m^2, MGF's ed), so the room receives the luminaire's output, not its
distribution.

Read: IESNA LM-63 (1986, 1991, 1995 and 2002 layouts): keyword lines up to TILT=, the TILT
data when TILT=INCLUDE (a TILT=<file> is ignored and reported), then the numbers (blanks or commas
between): lamps, lumens per lamp, candela multiplier, vertical and horizontal angle counts,
photometric type, units (1 feet, 2 metres), width, length, height, ballast factor, ballast-lamp
factor, input watts, the angles and the candela values. Flux = candela multiplier x ballast
factor x ballast-lamp factor x MGF's -m x the integral of I over the sphere; the horizontal
angles' last value gives the symmetry (0: about the axis, 90: quadrants, 180: bilateral, 360:
none).
"""
import math
import re

FEET = 0.3048
_THETA_STEP = 0.25  # degrees; the candela curve is integrated on this grid, linear between samples


class IesError(ValueError):
    """`what is wrong` (the reader adds file and line)."""


class Luminaire:
    def __init__(self, width, length, height, flux_down, flux_up, notes):
        self.width, self.length, self.height = width, length, height
        self.flux_down, self.flux_up = flux_down, flux_up
        self.notes = notes


def _numbers(text):
    """The numbers up to the first word that is not one (some files end in remarks)."""
    out = []
    for word in re.split(r"[\s,]+", text.strip()):
        try:
            out.append(float(word))
        except ValueError:
            break
    return out


def _after_tilt(lines):
    """(the numbers after the TILT data, notes)."""
    for k, line in enumerate(lines):
        if not line.strip().upper().startswith("TILT="):
            continue
        tilt = line.strip()[5:].strip().upper()
        rest = _numbers("\n".join(lines[k + 1:]))
        if tilt == "INCLUDE":
            if len(rest) < 2:
                raise IesError("TILT=INCLUDE without its data")
            n = int(rest[1])
            return rest[2 + 2 * n:], ["TILT data ignored (the luminaire is not tilted)"]
        notes = [] if tilt == "NONE" else [f"TILT={line.strip()[5:].strip()} ignored"]
        return rest, notes
    raise IesError("no TILT= line")


def _interpolated(angles, values, theta):
    """I(theta), linear between samples and zero outside the sampled range."""
    if theta < angles[0] or theta > angles[-1]:
        return 0.0
    for i in range(1, len(angles)):
        if theta <= angles[i]:
            span = angles[i] - angles[i - 1]
            t = 0.0 if span <= 0 else (theta - angles[i - 1]) / span
            return values[i - 1] + t * (values[i] - values[i - 1])
    return values[-1]


def _vertical_flux(angles, values):
    """(flux per radian of azimuth below and above the horizontal): the integral of
    I(theta) sin(theta) d(theta), midpoint rule on a fine grid."""
    down = up = 0.0
    step = math.radians(_THETA_STEP)
    for k in range(int(round(180.0 / _THETA_STEP))):
        theta = (k + 0.5) * _THETA_STEP
        part = _interpolated(angles, values, theta) * math.sin(math.radians(theta)) * step
        if theta < 90.0:
            down += part
        else:
            up += part
    return down, up


def _symmetry(horizontal):
    last = horizontal[-1]
    if len(horizontal) == 1 or last == 0.0:
        return 2.0 * math.pi, None
    for whole, copies in ((90.0, 4.0), (180.0, 2.0)):
        if abs(last - whole) < 1e-6:
            return copies, whole
    return 1.0, last


def _flux(vertical, horizontal, candela):
    """(flux below, flux above the horizontal) in candela x steradian."""
    per_plane = [_vertical_flux(vertical, row) for row in candela]
    copies, _ = _symmetry(horizontal)
    if len(per_plane) == 1 or horizontal[-1] == 0.0:
        return tuple(copies * x for x in per_plane[0])
    down = up = 0.0
    for i in range(1, len(horizontal)):
        dphi = math.radians(horizontal[i] - horizontal[i - 1])
        down += 0.5 * (per_plane[i - 1][0] + per_plane[i][0]) * dphi
        up += 0.5 * (per_plane[i - 1][1] + per_plane[i][1]) * dphi
    return down * copies, up * copies


def parse(text, multiplier=1.0):
    """The luminaire of an IES file's text; multiplier is MGF's -m (scales the candelas)."""
    numbers, notes = _after_tilt(text.splitlines())
    if len(numbers) < 13:
        raise IesError("fewer than the 13 numbers that describe the luminaire")
    _, _, cd_mult, n_vert, n_horiz, phot_type, units, width, length, height = numbers[:10]
    ballast, ballast_lamp = numbers[10], numbers[11]
    n_vert, n_horiz = int(n_vert), int(n_horiz)
    body = numbers[13:]
    if n_vert < 1 or n_horiz < 1 or len(body) < n_vert + n_horiz + n_vert * n_horiz:
        raise IesError(f"{n_vert} x {n_horiz} angles announced, {len(body)} numbers follow")
    if int(phot_type) != 1:
        raise IesError(f"photometric type {int(phot_type)}: only type C (1) is read")
    vertical = body[:n_vert]
    horizontal = body[n_vert:n_vert + n_horiz]
    values = body[n_vert + n_horiz:n_vert + n_horiz + n_vert * n_horiz]
    candela = [values[i * n_vert:(i + 1) * n_vert] for i in range(n_horiz)]
    scale = cd_mult * ballast * ballast_lamp * multiplier
    down, up = _flux(vertical, horizontal, candela)
    unit = FEET if int(units) == 1 else 1.0
    dims = [abs(width) * unit, abs(length) * unit, abs(height) * unit]
    if width < 0 or length < 0:
        notes.append("round opening taken as its bounding rectangle")
    if dims[0] <= 0 or dims[1] <= 0:
        raise IesError("a luminous opening without area (width or length 0)")
    return Luminaire(dims[0], dims[1], dims[2], down * scale, up * scale, notes)


def emitters(lum):
    """[(polygon in the luminaire's frame, luminous exitance lm/m^2)]: one rectangle per
    hemisphere that receives flux, one-sided, facing away from the luminaire."""
    hw, hl, hh = lum.width / 2.0, lum.length / 2.0, lum.height / 2.0
    area = lum.width * lum.length
    out = []
    if lum.flux_down > 0.0:  # counter-clockwise seen from below: faces -z
        out.append(([(-hw, -hl, -hh), (-hw, hl, -hh), (hw, hl, -hh), (hw, -hl, -hh)], lum.flux_down / area))
    if lum.flux_up > 0.0:  # counter-clockwise seen from above: faces +z
        out.append(([(-hw, -hl, hh), (hw, -hl, hh), (hw, hl, hh), (-hw, hl, hh)], lum.flux_up / area))
    return out
