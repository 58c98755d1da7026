"""Writes cones.obj + cones.mtl: the coursework's four cones of 642 triangles in total.

Four cones with 80, 80, 80 and 81 segments, each a fan of side triangles to the apex (smooth:
corner normals ``vn`` perpendicular to the slant) and a flat base cap fanned from its centre:
2 x segments triangles a cone, 2 x 321 = 642 in all. Each cone has its own material.
Run from anywhere: ``python examples/models/make_cones.py``; the output is deterministic.
"""

from __future__ import annotations

import math
from pathlib import Path

CONES = [  # (name, base centre, radius, height, segments, Kd)
    ("cone_teal", (-2.35, 0.0, 1.45), 0.42, 1.25, 80, (0.05, 0.55, 0.55)),
    ("cone_gold", (2.45, 0.0, 1.35), 0.42, 1.25, 80, (0.85, 0.62, 0.12)),
    ("cone_rose", (-0.95, 0.0, -0.75), 0.34, 1.05, 80, (0.85, 0.3, 0.45)),
    ("cone_lime", (1.05, 0.0, -0.55), 0.34, 1.05, 81, (0.45, 0.75, 0.15)),
]


def cone_lines(name, base, radius, height, segments, v0, vn0):
    bx, by, bz = base
    lines = [f"o {name}", f"usemtl {name}"]
    ring = []
    for k in range(segments):
        a = 2 * math.pi * k / segments
        ring.append((bx + radius * math.cos(a), by, bz + radius * math.sin(a)))
    apex = (bx, by + height, bz)
    centre = (bx, by, bz)
    for p in [*ring, apex, centre]:
        lines.append("v {:.6f} {:.6f} {:.6f}".format(*p))
    slope = radius / height
    for k in range(segments):
        a = 2 * math.pi * k / segments
        n = (math.cos(a), slope, math.sin(a))
        s = math.sqrt(sum(c * c for c in n))
        lines.append("vn {:.6f} {:.6f} {:.6f}".format(*(c / s for c in n)))
    lines.append("vn 0 -1 0")
    apex_i, centre_i = v0 + segments, v0 + segments + 1
    down = vn0 + segments
    lines.append("s 1")
    for k in range(segments):
        a, b = v0 + k, v0 + (k + 1) % segments
        na, nb = vn0 + k, vn0 + (k + 1) % segments
        # counter-clockwise seen from outside; the apex takes the mean of its side normals
        lines.append(f"f {a}//{na} {apex_i}//{na} {b}//{nb}")
    lines.append("s off")
    for k in range(segments):
        a, b = v0 + k, v0 + (k + 1) % segments
        lines.append(f"f {centre_i}//{down} {a}//{down} {b}//{down}")
    return lines, segments + 2, segments + 1


def main() -> None:
    here = Path(__file__).resolve().parent
    obj = ["# four cones, 642 triangles (see make_cones.py)", "mtllib cones.mtl"]
    mtl = ["# materials of cones.obj"]
    v0, vn0 = 1, 1
    for name, base, radius, height, segments, kd in CONES:
        lines, nv, nn = cone_lines(name, base, radius, height, segments, v0, vn0)
        obj += lines
        v0 += nv
        vn0 += nn
        mtl += [f"newmtl {name}", "Ka {:.3f} {:.3f} {:.3f}".format(*kd),
                "Kd {:.3f} {:.3f} {:.3f}".format(*kd), "Ks 0.4 0.4 0.4", "Ns 60", "illum 2"]
    (here / "cones.obj").write_text("\n".join(obj) + "\n")
    (here / "cones.mtl").write_text("\n".join(mtl) + "\n")


if __name__ == "__main__":
    main()
