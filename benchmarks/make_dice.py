"""Writes benchmarks/dice100.toml (a hundred dice on a table) and examples/die.toml (one):
each die is a rounded cube (the intersection of a cube and a ball) minus 21 pips.

    python benchmarks/make_dice.py
"""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HALF = 0.5  # half the side of the cube
ROUND = 0.76  # radius of the ball that rounds its edges and corners
PIP = 0.085  # radius of a pip's ball
DEPTH = 0.045  # how deep a pip cuts into its face
FACES = {  # outward normal -> pips (opposite faces add up to 7)
    (0, 0, 1): 1, (0, 0, -1): 6, (1, 0, 0): 2, (-1, 0, 0): 5, (0, 1, 0): 3, (0, -1, 0): 4,
}
LAYOUT = {  # pip positions on a face in units of its grid step
    1: [(0, 0)], 2: [(-1, -1), (1, 1)], 3: [(-1, -1), (0, 0), (1, 1)],
    4: [(-1, -1), (-1, 1), (1, -1), (1, 1)], 5: [(-1, -1), (-1, 1), (0, 0), (1, -1), (1, 1)],
    6: [(-1, -1), (-1, 0), (-1, 1), (1, -1), (1, 0), (1, 1)],
}
STEP = 0.24


def _axes(normal):
    n = tuple(float(c) for c in normal)
    helper = (0.0, 1.0, 0.0) if abs(n[1]) < 0.5 else (1.0, 0.0, 0.0)
    u = (helper[1] * n[2] - helper[2] * n[1], helper[2] * n[0] - helper[0] * n[2],
         helper[0] * n[1] - helper[1] * n[0])
    v = (n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0])
    return n, u, v


def _vec(v) -> str:
    return "[" + ", ".join(f"{c:.6g}" for c in v) + "]"


def die_lines(name: str, translate, rotate) -> list[str]:
    """One die as an [[objects]] table (the pips as inline tables)."""
    lines = ["[[objects]]", f'name = "{name}"', 'type = "csg"', 'operation = "difference"',
             'material = "ivory"',
             f"transform = {{ rotate = {_vec(rotate)}, translate = {_vec(translate)} }}",
             "objects = [",
             '  { type = "csg", operation = "intersection", objects = [',
             f'    {{ type = "box", min = {_vec([-HALF] * 3)}, max = {_vec([HALF] * 3)} }},',
             f'    {{ type = "sphere", radius = {ROUND} }} ] }},']
    for normal, count in FACES.items():
        n, u, v = _axes(normal)
        for a, b in LAYOUT[count]:
            centre = [n[k] * (HALF + PIP - DEPTH) + STEP * (a * u[k] + b * v[k])
                      for k in range(3)]
            lines.append(f'  {{ type = "sphere", center = {_vec(centre)}, radius = {PIP}, '
                         'material = "pip" },')
    lines.append("]")
    return lines


HEADER = """[render]
width = {width}
height = {height}
max_depth = 3

[camera]
position = {camera}
look_at = {look_at}
fov = 40.0

[background]
gradient = {{ top = [0.2, 0.22, 0.3], bottom = [0.55, 0.55, 0.6] }}

[materials.ivory]
color = [0.92, 0.9, 0.84]
kd = 0.75
ks = 0.35
shininess = 60.0
kr = 0.04

[materials.pip]
color = [0.05, 0.05, 0.06]
kd = 0.6
ks = 0.2
shininess = 20.0

[[lights]]
type = "ambient"
intensity = 0.2

[[lights]]
type = "point"
position = [-6.0, 10.0, 8.0]
intensity = 0.8

[[lights]]
type = "point"
position = [7.0, 6.0, 4.0]
intensity = 0.3

[[objects]]
name = "table"
type = "plane"
point = [0.0, -0.5, 0.0]
material = {{ color = [0.25, 0.4, 0.3], kd = 0.8, ks = 0.05 }}
"""


def main() -> None:
    one = ["# A die: a rounded cube (the intersection of a cube and a ball) minus 21 pips, the",
           "# pips' cuts showing their own material (POV-Ray's rule). Written by",
           "# benchmarks/make_dice.py.", "",
           HEADER.format(width=480, height=360, camera="[2.2, 1.9, 2.6]",
                         look_at="[0.0, 0.0, 0.0]"),
           *die_lines("die", (0.0, 0.0, 0.0), (0.0, 20.0, 0.0))]
    (ROOT / "examples" / "die.toml").write_text("\n".join(one) + "\n", encoding="utf-8")
    many = ["# Benchmark \"dice100\": a hundred dice (each a rounded cube minus 21 pips: 23",
            "# solids of CSG) tumbled on a 10 x 10 grid. Written by benchmarks/make_dice.py.",
            "", HEADER.format(width=640, height=480, camera="[0.0, 15.0, 14.0]",
                              look_at="[0.0, 0.0, 0.0]")]
    for i in range(10):
        for j in range(10):
            k = 10 * i + j
            rotate = ((k * 37) % 4 * 90.0, (k * 53) % 360 * 1.0, (k * 11) % 4 * 90.0)
            many += die_lines(f"die {k}", (1.6 * (j - 4.5), 0.0, 1.6 * (i - 4.5)), rotate)
            many.append("")
    (ROOT / "benchmarks" / "dice100.toml").write_text("\n".join(many), encoding="utf-8")


if __name__ == "__main__":
    main()
