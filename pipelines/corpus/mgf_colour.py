"""MGF colours (cxy, cspec, cct, cmix) to CIE xy, and CIE xyY to the linear RGB of glTF.

MGF colours are absolute and relative to the equal-energy white E: `cxy 0.3333 0.3333` is a
neutral grey (MGF spec, entity cxy; application notes 6.1.1). The conversion to RGB uses the
Rec. 709 / sRGB primaries with E as the white point, as RenderPark and the MGF notes do (with
their "nominal CRT" green at x = 0.29), so an MGF neutral maps to R = G = B and a reflectance
`rd` of a neutral colour to exactly `rd` in every channel.

Spectra (cspec, cct) are reduced to xy with the analytic fit of the CIE 1931 2-degree colour
matching functions of Wyman, Sloan and Shirley 2013, "Simple Analytic Approximations to the CIE
XYZ Color Matching Functions" (JCGT 2(2)), good to about a percent of the tabulated curves:
enough for the chromaticity of a surface. Only the Python standard library is used.
"""
import math

# Rec. 709 primaries; the white point is MGF's equal-energy white E (x = y = 1/3).
_PRIMARIES = ((0.640, 0.330), (0.300, 0.600), (0.150, 0.060))
NEUTRAL_XY = (1.0 / 3.0, 1.0 / 3.0)


def _lobe(lam, mu, sigma_below, sigma_above):
    s = sigma_below if lam < mu else sigma_above
    t = (lam - mu) / s
    return math.exp(-0.5 * t * t)


def colour_matching(lam):
    """(xbar, ybar, zbar) at wavelength lam in nm (Wyman, Sloan, Shirley 2013, multi-lobe fit)."""
    x = (1.056 * _lobe(lam, 599.8, 37.9, 31.0) + 0.362 * _lobe(lam, 442.0, 16.0, 26.7)
         - 0.065 * _lobe(lam, 501.1, 20.4, 26.2))
    y = 0.821 * _lobe(lam, 568.8, 46.9, 40.5) + 0.286 * _lobe(lam, 530.9, 16.3, 31.1)
    z = 1.217 * _lobe(lam, 437.0, 11.8, 36.0) + 0.681 * _lobe(lam, 459.0, 26.0, 13.8)
    return x, y, z


def _xy_of_xyz(big_x, big_y, big_z):
    s = big_x + big_y + big_z
    if s <= 0.0 or big_y <= 0.0:
        raise ValueError("colour has no luminance")
    return big_x / s, big_y / s


def spectrum_xy(lmin, lmax, values):
    """xy of a relative spectrum sampled evenly from lmin to lmax nm (MGF cspec); zero outside."""
    n = len(values)
    if n < 2 or lmax <= lmin:
        raise ValueError("cspec needs at least two samples over a positive range")
    step = (lmax - lmin) / (n - 1)
    acc = [0.0, 0.0, 0.0]
    # Integrate over 380-780 nm at 1 nm, the spectrum linearly interpolated between samples.
    for lam in range(380, 781):
        if lam < lmin or lam > lmax:
            continue
        f = (lam - lmin) / step
        i = min(int(f), n - 2)
        s = values[i] + (values[i + 1] - values[i]) * (f - i)
        cmf = colour_matching(lam)
        for k in range(3):
            acc[k] += s * cmf[k]
    return _xy_of_xyz(*acc)


def blackbody_xy(kelvin):
    """xy of a black body at the given temperature (MGF cct)."""
    if kelvin <= 0.0:
        raise ValueError("cct needs a positive temperature")
    c2 = 1.4388e7  # second radiation constant, nm K
    acc = [0.0, 0.0, 0.0]
    for lam in range(380, 781):
        e = 1.0 / (lam ** 5 * math.expm1(c2 / (lam * kelvin)))
        cmf = colour_matching(lam)
        for k in range(3):
            acc[k] += e * cmf[k]
    return _xy_of_xyz(*acc)


def mix_xy(weighted):
    """xy of a cmix: [(w, (x, y)), ...], each weight the component's relative luminance Y."""
    acc = [0.0, 0.0, 0.0]
    for w, (x, y) in weighted:
        if y <= 0.0:
            raise ValueError("cmix of a colour without luminance")
        acc[0] += w * x / y
        acc[1] += w
        acc[2] += w * (1.0 - x - y) / y
    return _xy_of_xyz(*acc)


def _solve3(m, v):
    """m x = v for a 3x3 m (Cramer's rule)."""
    def det(a):
        return (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]))
    d = det(m)
    out = []
    for c in range(3):
        mc = [[v[r] if k == c else m[r][k] for k in range(3)] for r in range(3)]
        out.append(det(mc) / d)
    return out


def _rgb_to_xyz_matrix():
    cols = [(x / y, 1.0, (1.0 - x - y) / y) for x, y in _PRIMARIES]
    p = [[cols[c][r] for c in range(3)] for r in range(3)]
    white = (NEUTRAL_XY[0] / NEUTRAL_XY[1], 1.0, (1 - sum(NEUTRAL_XY)) / NEUTRAL_XY[1])
    s = _solve3(p, white)
    return [[p[r][c] * s[c] for c in range(3)] for r in range(3)]


_RGB_TO_XYZ = _rgb_to_xyz_matrix()


def xyY_to_rgb(x, y, big_y):
    """Linear RGB (Rec. 709 primaries, white E) of chromaticity xy at luminance Y.

    Returns (rgb, clipped): channels below zero (outside the RGB gamut) are set to zero, and
    clipped says so. A chromaticity with y = 0 has no luminance: black, clipped (RenderPark's
    rule for it).
    """
    if y <= 0.0:
        return [0.0, 0.0, 0.0], big_y > 0.0
    xyz = (x / y * big_y, big_y, (1.0 - x - y) / y * big_y)
    rgb = _solve3(_RGB_TO_XYZ, xyz)
    clipped = any(c < -1e-9 for c in rgb)
    return [max(0.0, c) for c in rgb], clipped


def luminance(rgb):
    """Y of a linear RGB triple in the same space."""
    return sum(_RGB_TO_XYZ[1][c] * rgb[c] for c in range(3))
