"""The MGF text the corpus tests build their scenes on: a grey 10 x 10 m floor at z = 0, one
object, so that each test adds only what it tests (a luminaire, a mirrored pair)."""

FLOOR_MGF = """
m grey =
\tc
\trd 0.5
v f0 =
\tp -5 -5 0
v f1 =
\tp 5 -5 0
v f2 =
\tp 5 5 0
v f3 =
\tp -5 5 0
o floor
f f0 f1 f2 f3
o
"""
