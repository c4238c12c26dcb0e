"""MGF transforms (the arguments of `xf` and `i`) as lists of affine matrices.

MGF spec, entity xf and section 2.2.2: the arguments act on the geometry in the order given
(`-t -15 0 35 -ry -20 -t 15 0 -35` rotates about a point); an enclosed transform is prepended to
its enclosing one, so world = outer * inner. `-a N ARGS` makes N instances, the k-th moved by
ARGS applied k times; several `-a` make a multi-dimensional array; `-i N ARGS` applies ARGS N
times; the scope of an `-a` or `-i` runs to the next `-a` or `-i`. A transform is a list of
instance matrices (one unless there are arrays), row-major 3x4 affine [R | t].
"""
import math

IDENTITY = ((1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0))


def multiply(a, b):
    """a * b: b applied first."""
    out = []
    for r in range(3):
        row = [sum(a[r][k] * b[k][c] for k in range(3)) for c in range(3)]
        row.append(sum(a[r][k] * b[k][3] for k in range(3)) + a[r][3])
        out.append(tuple(row))
    return tuple(out)


def determinant(m):
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def apply(m, p):
    return (m[0][0] * p[0] + m[0][1] * p[1] + m[0][2] * p[2] + m[0][3],
            m[1][0] * p[0] + m[1][1] * p[1] + m[1][2] * p[2] + m[1][3],
            m[2][0] * p[0] + m[2][1] * p[1] + m[2][2] * p[2] + m[2][3])


def apply_direction(m, d):
    """A direction through the linear part (normals of rings and tori: the MGF parser does the
    same, and its transforms are similarities, where this is exact up to length)."""
    return (m[0][0] * d[0] + m[0][1] * d[1] + m[0][2] * d[2],
            m[1][0] * d[0] + m[1][1] * d[1] + m[1][2] * d[2],
            m[2][0] * d[0] + m[2][1] * d[1] + m[2][2] * d[2])


def _rotation(axis, degrees):
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    if axis == 0:
        return ((1, 0, 0, 0), (0, c, -s, 0), (0, s, c, 0))
    if axis == 1:
        return ((c, 0, s, 0), (0, 1, 0, 0), (-s, 0, c, 0))
    return ((c, -s, 0, 0), (s, c, 0, 0), (0, 0, 1, 0))


def _power(m, k):
    out = IDENTITY
    for _ in range(k):
        out = multiply(m, out)
    return out


class TransformError(ValueError):
    pass


def _number(tokens, i, what):
    try:
        return float(tokens[i])
    except (IndexError, ValueError):
        raise TransformError(f"{what}: expected a number") from None


def _count(tokens, i, flag):
    try:
        n = int(tokens[i])
    except (IndexError, ValueError):
        raise TransformError(f"{flag}: expected a count") from None
    if n < 1:
        raise TransformError(f"{flag} {n}: expected a count of at least 1")
    return n


def parse(tokens):
    """The instance matrices of a transform's arguments (tokens after `xf` or `i FILE`).

    Returns (matrices, is_array): one matrix per instance, in array order (first index fastest).
    """
    segments = [("i", 1, IDENTITY)]  # (kind, count, matrix of the segment's arguments)
    i = 0
    while i < len(tokens):
        flag = tokens[i]
        if flag in ("-a", "-i"):
            segments.append((flag[1], _count(tokens, i + 1, flag), IDENTITY))
            i += 2
            continue
        if flag == "-t":
            step = ((1, 0, 0, _number(tokens, i + 1, "-t")), (0, 1, 0, _number(tokens, i + 2, "-t")),
                    (0, 0, 1, _number(tokens, i + 3, "-t")))
            i += 4
        elif flag in ("-rx", "-ry", "-rz"):
            step = _rotation("xyz".index(flag[2]), _number(tokens, i + 1, flag))
            i += 2
        elif flag == "-s":
            f = _number(tokens, i + 1, "-s")
            if f == 0.0:
                raise TransformError("-s 0: a scale must not be zero")
            step = ((f, 0, 0, 0), (0, f, 0, 0), (0, 0, f, 0))
            i += 2
        elif flag in ("-mx", "-my", "-mz"):
            axis = "xyz".index(flag[2])
            step = tuple(tuple((-1.0 if (r == axis and c == axis) else float(r == c)) if c < 3 else 0.0
                               for c in range(4)) for r in range(3))
            i += 1
        else:
            raise TransformError(f"unknown transform argument '{flag}'")
        kind, count, m = segments[-1]
        segments[-1] = (kind, count, multiply(step, m))
    instances = [IDENTITY]
    for kind, count, m in segments:
        if kind == "i":
            p = _power(m, count)
            instances = [multiply(p, inst) for inst in instances]
        else:
            instances = [multiply(_power(m, k), inst) for k in range(count) for inst in instances]
    return instances, any(kind == "a" for kind, _, _ in segments)
