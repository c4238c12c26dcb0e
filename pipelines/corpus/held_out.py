"""The RenderPark scenes kept out of the project for checking (issues 56 and 58).

`office2` (etc/office2/office2.mgf, also seen as etc/oficina002/office2.mgf) and the classroom
(etc/salon/classroom.mgf) judge the project's work on scenes it never saw; any copy of them,
under any folder, is refused by name before a byte of it is read, and never fetched.
"""
import os
import re

_HELD_OUT = re.compile(r"office2|oficina002|classroom|salon", re.IGNORECASE)


class HeldOutError(ValueError):
    pass


def check(path):
    """Raises HeldOutError when a component of path names a held-out scene."""
    parts = os.path.normpath(str(path)).replace("\\", "/").split("/")
    for part in parts:
        if _HELD_OUT.search(part):
            raise HeldOutError(f"{path}: '{part}' is a held-out scene (office2, classroom): "
                               "kept out of the project for checking; refused")
