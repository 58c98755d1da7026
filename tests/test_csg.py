"""CSG: union, intersection, difference and merge, nested, checked against worked values and
against an exact interval computation; POV-Ray's material rule; one body for the media;
errors for children that bound no volume."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import ValidationError

from whitted.compile.scene import compile_scene
from whitted.kernels.accel import closest_hit, hit_material, surface_normals
from whitted.kernels.layout import PRIM_FLIP, PRIM_MEDIUM, PRIM_OBJECT
from whitted.scene import CSG, Box, Cone, Cylinder, Material, Plane, Scene, Sphere, Torus, Transform

CUBE = Box(min=(-1, -1, -1), max=(1, 1, 1))


class Compiled:
    def __init__(self, *shapes, materials=None):
        self.compiled = compile_scene(Scene(objects=list(shapes), materials=materials or {}))
        self.geo = self.compiled.geometry
        self.stack = np.empty(128, np.int32)

    def hit(self, o, d, tmin=0.0):
        o = tuple(map(float, o))
        d = tuple(map(float, d))
        t, prim, tri, b1, b2 = closest_hit(self.geo, o, d, float(tmin), math.inf, self.stack)
        if prim < 0:
            return None
        p = tuple(a + t * b for a, b in zip(o, d, strict=True))
        n, _ = surface_normals(self.geo, prim, tri, b1, b2, p)
        return t, np.array(n), int(prim)

    def hits(self, o, d):
        out = []
        tmin = 0.0
        while (h := self.hit(o, d, tmin)) is not None:
            out.append(h)
            tmin = h[0]
        return out

    def ts(self, o, d):
        return [h[0] for h in self.hits(o, d)]


def test_difference_of_a_box_and_a_sphere_is_a_hollow_block():
    c = Compiled(CSG(operation="difference", objects=[CUBE, Sphere(radius=0.5)]))
    # along x from -5: box face at -1, the cavity from -0.5 to 0.5, the far face at 1
    hits = c.hits((-5, 0, 0), (1, 0, 0))
    assert [h[0] for h in hits] == pytest.approx([4.0, 4.5, 5.5, 6.0], rel=1e-12)
    # the cavity's walls face into the cavity (the sphere's normals turned over)
    np.testing.assert_allclose([h[1] for h in hits],
                               [[-1, 0, 0], [1, 0, 0], [-1, 0, 0], [1, 0, 0]], atol=1e-12)
    # above the cavity only the block's faces show
    assert c.ts((-5, 0.7, 0), (1, 0, 0)) == pytest.approx([4.0, 6.0], rel=1e-12)


def test_intersection_of_a_box_and_a_sphere_rounds_the_corners():
    c = Compiled(CSG(operation="intersection", objects=[CUBE, Sphere(radius=1.3)]))
    assert c.ts((-5, 0, 0), (1, 0, 0)) == pytest.approx([4.0, 6.0], rel=1e-12)
    # through a corner region: y = z = 0.9 -> the sphere at x = -sqrt(1.69 - 1.62)
    x = math.sqrt(1.69 - 1.62)
    assert c.ts((-5, 0.9, 0.9), (1, 0, 0)) == pytest.approx([5 - x, 5 + x], rel=1e-12)
    # past the rounded corner: nothing
    assert c.hit((-5, 1.0 - 1e-9, 0.95), (1, 0, 0)) is None


def test_merge_has_no_inner_surfaces_and_union_keeps_them():
    pair = [Sphere(radius=1.0), Sphere(center=(1, 0, 0), radius=1.0)]
    # along x from -5: the first sphere from -1 to 1, the second from 0 to 2
    assert Compiled(CSG(operation="merge", objects=pair)).ts((-5, 0, 0), (1, 0, 0)) == \
        pytest.approx([4.0, 7.0], rel=1e-12)
    assert Compiled(CSG(operation="union", objects=pair)).ts((-5, 0, 0), (1, 0, 0)) == \
        pytest.approx([4.0, 5.0, 6.0, 7.0], rel=1e-12)


def test_nested_trees_and_difference_of_many():
    # a cube minus (the union of two spheres) minus a cylinder along y
    holes = CSG(operation="union", objects=[Sphere(center=(-1, 0, 0), radius=0.5),
                                            Sphere(center=(1, 0, 0), radius=0.5)])
    drill = Cylinder(base=(0, -2, 0), top=(0, 2, 0), radius=0.25)
    c = Compiled(CSG(operation="difference", objects=[CUBE, holes, drill]))
    # along x: the hemispherical dents take the faces' centres: -0.5, the drill -0.25..0.25
    assert c.ts((-5, 0, 0), (1, 0, 0)) == pytest.approx([4.5, 4.75, 5.25, 5.5], rel=1e-12)
    # along z through the drill: faces at -1, drill wall -0.25 .. 0.25, face at 1
    assert c.ts((0.0, 0.5, -5), (0, 0, 1)) == pytest.approx([4.0, 4.75, 5.25, 6.0],
                                                             rel=1e-12)


def test_a_difference_of_a_difference_turns_twice():
    # (cube - big sphere) - ... no: cube - (sphere r=0.8 - sphere r=0.4): a shell cut out,
    # leaving a ball of radius 0.4 floating in the cavity; its surface faces outward again
    inner = CSG(operation="difference", objects=[Sphere(radius=0.8), Sphere(radius=0.4)])
    c = Compiled(CSG(operation="difference", objects=[CUBE, inner]))
    hits = c.hits((-5, 0, 0), (1, 0, 0))
    assert [h[0] for h in hits] == pytest.approx([4, 4.2, 4.6, 5.4, 5.8, 6], rel=1e-12)
    np.testing.assert_allclose([h[1][0] for h in hits], [-1, 1, -1, 1, -1, 1], atol=1e-12)


def test_transform_of_the_whole_and_of_a_child():
    c = Compiled(CSG(operation="difference", objects=[
        CUBE, Sphere(radius=0.5, transform=Transform(translate=(0.0, 0.0, 1.0)))],
        transform=Transform(scale=2.0, translate=(0.0, 0.0, -10.0))))
    # the scaled cube spans z -12..-8; the dent (radius 1 at z = -8) takes its front face's
    # centre: from z = 0 down -z the first surface is the dent's bottom at z = -9
    h = c.hit((0, 0, 0), (0, 0, -1))
    assert h[0] == pytest.approx(9.0, rel=1e-12)
    np.testing.assert_allclose(h[1], [0, 0, 1], atol=1e-12)


def test_surfaces_keep_their_childs_material_and_the_cut_shows_the_cutters():
    red = Material(color=(1, 0, 0))
    blue = Material(color=(0, 0, 1))
    glass = Material(preset="glass")
    c = Compiled(CSG(operation="difference", material=glass, objects=[
        Box(min=(-1, -1, -1), max=(1, 1, 1), material=red),
        Sphere(radius=0.5, material=blue),
        Sphere(center=(0, 0.9, 0), radius=0.05)]))  # no material: the object's
    mats = c.compiled.materials
    geo = c.geo

    def colour(o, d, tmin=0.0):
        h = c.hit(o, d, tmin)
        return tuple(mats[hit_material(geo, h[2], -1), 0:3]), h[2]

    assert colour((-5, 0, 0), (1, 0, 0))[0] == (1, 0, 0)
    cut, prim = colour((-5, 0, 0), (1, 0, 0), 4.0)
    assert cut == (0, 0, 1)
    assert geo.prim_info[prim, PRIM_FLIP] == 1
    assert geo.prim_info[prim, PRIM_OBJECT] == 0
    small, _ = colour((0, 0.9, -5), (0, 0, 1))
    assert small == (1, 0, 0)  # the box's face first
    # every leaf's medium is the whole object's material (glass)
    leaves = [i for i in range(len(geo.prim_info)) if geo.prim_info[i, PRIM_MEDIUM] >= 0]
    assert len(leaves) == 3
    assert len({int(geo.prim_info[i, PRIM_MEDIUM]) for i in leaves}) == 1
    assert tuple(mats[int(geo.prim_info[leaves[0], PRIM_MEDIUM]), 0:3]) == glass.color


def _ray(origin, target):
    """(o, d) of the ray from ``origin`` toward ``target``; d is None when they nearly meet."""
    d = np.subtract(target, origin)
    return np.array(origin), (d if np.linalg.norm(d) >= 1e-3 else None)


def _interval(lo, hi):
    return (lo, hi) if lo < hi else None


def _box_interval(o, d):
    lo, hi = -math.inf, math.inf
    for k in range(3):
        if abs(d[k]) < 1e-300:
            if abs(o[k]) > 1.0:
                return None
            continue
        a, b = (-1 - o[k]) / d[k], (1 - o[k]) / d[k]
        lo, hi = max(lo, min(a, b)), min(hi, max(a, b))
    return _interval(lo, hi)


def _sphere_interval(o, d, c, r):
    oc = np.subtract(o, c)
    a = np.dot(d, d)
    b = np.dot(oc, d)
    disc = b * b - a * (np.dot(oc, oc) - r * r)
    if disc <= 0:
        return None
    s = math.sqrt(disc)
    return (-b - s) / a, (-b + s) / a


SCULPT = Compiled(CSG(operation="difference", objects=[
    CSG(operation="intersection", objects=[CUBE, Sphere(radius=1.35)]),
    Sphere(center=(0.3, 0.2, 0.1), radius=0.6)]))


@settings(max_examples=400, deadline=None)
@given(st.tuples(*[st.floats(-3, 3)] * 3), st.tuples(*[st.floats(-1, 1)] * 3))
def test_first_surface_matches_the_exact_intervals(origin, target):
    # (cube ∩ ball) − small ball: the solid along the ray is ([box] ∩ [ball]) minus (cut);
    # its first boundary point past 0 is the first hit
    o, d = _ray(origin, target)
    if d is None:
        return
    if any(abs(d[k]) < 1e-9 and abs(abs(o[k]) - 1) < 1e-9 for k in range(3)):
        return  # a ray in the plane of a face: which side it is on is not defined
    box = _box_interval(o, d)
    ball = _sphere_interval(o, d, (0, 0, 0), 1.35)
    cut = _sphere_interval(o, d, (0.3, 0.2, 0.1), 0.6)
    pieces = []
    if box and ball:
        lo, hi = max(box[0], ball[0]), min(box[1], ball[1])
        if lo < hi:
            pieces = _minus([(lo, hi)], cut)
    _assert_first_surface(SCULPT, o, d, pieces)


def _minus(pieces, cut):
    """The intervals ``pieces`` less the interval ``cut`` (None: nothing)."""
    if cut is None:
        return pieces
    return [q for p in pieces for q in ((p[0], min(p[1], cut[0])), (max(p[0], cut[1]), p[1]))
            if q[0] < q[1]]


def _assert_first_surface(compiled, o, d, pieces):
    """The first hit of the ray is the first end past 0 of the solid's intervals along it."""
    ends = sorted(x for p in pieces for x in p if x > 1e-9)
    h = compiled.hit(o, d)
    if not ends:
        assert h is None
        return
    assert h is not None
    assert h[0] == pytest.approx(ends[0], rel=1e-9, abs=1e-9)


def _frustum_interval(o, d, axis, lo, hi, r_lo, r_hi):
    """The part of the line o + t d inside a capped cylinder or cone about coordinate axis
    ``axis`` (through the origin), from ``lo`` to ``hi`` along it, radius r_lo to r_hi."""
    k = (r_hi - r_lo) / (hi - lo)
    if abs(d[axis]) < 1e-300:
        if not lo < o[axis] < hi:
            return None
        slab = (-math.inf, math.inf)
    else:
        a, b = (lo - o[axis]) / d[axis], (hi - o[axis]) / d[axis]
        slab = (min(a, b), max(a, b))
    others = [j for j in range(3) if j != axis]
    # rho² - r(t)² <= 0 with r(t) = r_lo + k·(o_axis + t d_axis - lo): a quadratic in t
    r0 = r_lo + k * (o[axis] - lo)
    a = sum(d[j] ** 2 for j in others) - (k * d[axis]) ** 2
    b = sum(o[j] * d[j] for j in others) - r0 * k * d[axis]
    c = sum(o[j] ** 2 for j in others) - r0 * r0
    if abs(a) < 1e-12:
        return None  # a ray parallel to the side of a cone: not sampled here
    disc = b * b - a * c
    if disc <= 0:
        return None if a > 0 else _interval(*slab)
    s = math.sqrt(disc)
    t1, t2 = sorted(((-b - s) / a, (-b + s) / a))
    inside = [(t1, t2)] if a > 0 else [(-math.inf, t1), (t2, math.inf)]
    pieces = [(max(p[0], slab[0]), min(p[1], slab[1])) for p in inside]
    pieces = [p for p in pieces if p[0] < p[1]]
    return (min(p[0] for p in pieces), max(p[1] for p in pieces)) if pieces else None


DRILLED = Compiled(CSG(operation="difference", objects=[
    CUBE,
    Cylinder(base=(0, -1.5, 0), top=(0, 0.5, 0), radius=0.5),
    Cone(base=(-1.5, 0, 0), top=(1.5, 0, 0), radius=0.6, top_radius=0.2)]))


@settings(max_examples=400, deadline=None)
@given(st.tuples(*[st.floats(-3, 3)] * 3), st.tuples(*[st.floats(-1, 1)] * 3))
def test_first_surface_of_a_drilled_cube_matches_the_exact_intervals(origin, target):
    # cube − cylinder (its top cap inside the cube) − cone (through the cube along x): the
    # walk of frustum leaves (their first and last crossings) gives the first boundary point
    o, d = _ray(origin, target)
    if d is None:
        return
    if any(abs(d[k]) < 1e-9 for k in range(3)):
        return  # rays parallel to a face or a cap: whether they graze it is not defined
    for axis, plane, r in ((1, -1.5, 0.5), (1, 0.5, 0.5), (0, -1.5, 0.6), (0, 1.5, 0.2)):
        p = o + (plane - o[axis]) / d[axis] * d
        if abs(math.hypot(*(p[j] for j in range(3) if j != axis)) - r) < 1e-9:
            return  # through a cap's rim exactly: touch or crossing is not defined there
    cube = _box_interval(o, d)
    pieces = [cube] if cube else []
    pieces = _minus(pieces, _frustum_interval(o, d, 1, -1.5, 0.5, 0.5, 0.5))
    cone = _frustum_interval(o, d, 0, -1.5, 1.5, 0.6, 0.2)
    if cone is None and abs(sum(d[j] ** 2 for j in (1, 2)) - (0.4 / 3 * d[0]) ** 2) < 1e-12:
        return
    _assert_first_surface(DRILLED, o, d, _minus(pieces, cone))


def test_csg_children_must_bound_a_volume():
    with pytest.raises(ValidationError, match=r"objects\[1\] \(plane\).*no volume"):
        CSG(operation="difference", objects=[CUBE, Plane()])
    with pytest.raises(ValidationError, match="uncapped cylinder is open"):
        CSG(operation="union", objects=[CUBE, Cylinder(radius=1, capped=False)])
    with pytest.raises(ValidationError, match="at most 63 solids"):
        CSG(operation="union", objects=[Sphere(center=(k, 0, 0), radius=0.4)
                                        for k in range(64)])


def test_unknown_material_inside_a_csg_names_its_place():
    with pytest.raises(ValidationError, match=r"objects\[0\]\.objects\[1\]\.material"):
        Scene(objects=[CSG(operation="union", objects=[CUBE, Sphere(radius=1,
                                                                       material="nope")])])


def test_torus_in_a_csg():
    # a ring cut in half by a box: along x at y = 0 the left half is gone
    c = Compiled(CSG(operation="difference", objects=[
        Torus(major_radius=2, minor_radius=0.5), Box(min=(-3, -1, -1), max=(0, 1, 1))]))
    assert c.ts((-10, 0, 0), (1, 0, 0)) == pytest.approx([11.5, 12.5], rel=1e-12)


def test_scenes_without_extras_keep_the_lean_kernels():
    assert Compiled(Sphere(radius=1)).geo.unbounded.dtype == np.int32
    assert Compiled(Torus(major_radius=1, minor_radius=0.2)).geo.unbounded.dtype == np.int64


CLI_SCENE = """
[[objects]]
type = "csg"
operation = "difference"
name = "die"
[[objects.objects]]
type = "csg"
operation = "intersection"
[[objects.objects.objects]]
type = "box"
min = [-1.0, -1.0, -1.0]
max = [1.0, 1.0, 1.0]
[[objects.objects.objects]]
type = "sphere"
radius = 1.35
[[objects.objects]]
type = "sphere"
name = "pip"
center = [0.0, 0.0, 1.0]
radius = 0.2
material = "mirror"
"""


def test_info_shows_the_tree(tmp_path):
    from typer.testing import CliRunner

    from whitted.cli.main import app

    path = tmp_path / "die.toml"
    path.write_text(CLI_SCENE)
    result = CliRunner().invoke(app, ["info", str(path)])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    start = next(i for i, line in enumerate(lines) if "csg difference 'die'" in line)
    assert [line.strip() for line in lines[start + 1:start + 5]] == [
        "objects[0] csg intersection material=inherited",
        "objects[0].objects[0] box material=inherited",
        "objects[0].objects[1] sphere material=inherited",
        "objects[1] sphere 'pip' material=mirror",
    ]


def test_a_plane_in_a_csg_is_a_one_line_error(tmp_path):
    from typer.testing import CliRunner

    from whitted.cli.main import app

    path = tmp_path / "bad.toml"
    path.write_text(CLI_SCENE.split('type = "sphere"\nname = "pip"')[0]
                    + 'type = "plane"\nname = "floor"\n')
    result = CliRunner().invoke(app, ["render", str(path), "-o", str(tmp_path / "x.png")])
    assert result.exit_code == 2
    message = result.output.strip()
    assert len(message.splitlines()) == 1
    assert "bad.toml" in message and "objects[0]" in message and "no volume" in message
    assert not (tmp_path / "x.png").exists()


def _cube_mesh(lo=-0.5, hi=0.5, drop=0):
    from whitted.scene import Mesh

    v = [[x, y, z] for x in (lo, hi) for y in (lo, hi) for z in (lo, hi)]
    # corners indexed 4x + 2y + z (0/1); two triangles per face, counter-clockwise outside
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4),
             (1, 5, 7, 3)]
    faces = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    return Mesh(vertices=v, faces=faces[drop:])


def test_a_closed_mesh_takes_part():
    # the unit cube minus a mesh cube of side 1 around (0.5, 0, 0): the cut at x = 0
    c = Compiled(CSG(operation="difference", objects=[CUBE, _cube_mesh(0.0, 1.0)
                                                      .model_copy(update={"transform": None})]))
    hits = c.hits((-5, 0.2, 0.3), (1, 0, 0))
    assert [h[0] for h in hits] == pytest.approx([4.0, 5.0], rel=1e-12)
    np.testing.assert_allclose(hits[1][1], [1, 0, 0], atol=1e-12)  # the cut faces +x
    # a mesh intersected with a ball, rays through its edges and corners included
    c = Compiled(CSG(operation="intersection", objects=[_cube_mesh(), Sphere(radius=0.6)]))
    assert c.ts((-5, 0, 0), (1, 0, 0)) == pytest.approx([4.5, 5.5], rel=1e-12)
    # y = z = 0.1 meets the faces x = -0.5 and 0.5 on the diagonal edges of their triangles
    assert c.ts((-5, 0.1, 0.1), (1, 0, 0)) == pytest.approx([4.5, 5.5], rel=1e-12)
    # at y = 0.45 the ball is inside the cube: its surface at x = -+sqrt(0.36 - 0.2025)
    x = math.sqrt(0.36 - 0.2025)
    assert c.ts((-5, 0.45, 0.0), (1, 0, 0)) == pytest.approx([5 - x, 5 + x], rel=1e-9)


def test_an_open_mesh_in_a_csg_is_a_one_line_error():
    from whitted.errors import SceneError

    with pytest.raises(SceneError, match=r"objects\[0\]\.objects\[1\] \(mesh\): the mesh is "
                                         r"open \(3 edges"):
        Compiled(CSG(operation="difference", objects=[CUBE, _cube_mesh(drop=1)]))


_SOLIDS = st.one_of(
    st.builds(lambda c, r: {"type": "sphere", "center": c, "radius": r},
              st.tuples(*[st.floats(-1, 1)] * 3), st.floats(0.05, 1.5)),
    st.builds(lambda a, b: {"type": "box", "min": list(np.minimum(a, b) - 0.01),
                            "max": list(np.maximum(a, b) + 0.01)},
              st.tuples(*[st.floats(-1, 1)] * 3), st.tuples(*[st.floats(-1, 1)] * 3)),
    st.builds(lambda r1, r2: {"type": "torus", "major_radius": r1, "minor_radius": r2},
              st.floats(0.2, 1.5), st.floats(0.05, 0.5)),
)
_TREES = st.recursive(
    _SOLIDS,
    lambda children: st.builds(
        lambda op, objs: {"type": "csg", "operation": op, "objects": objs},
        st.sampled_from(["union", "intersection", "difference", "merge"]),
        st.lists(children, min_size=1, max_size=4)),
    max_leaves=12,
)


@settings(max_examples=60, deadline=None)
@given(_TREES.filter(lambda t: t["type"] == "csg"), st.tuples(*[st.floats(-1, 1)] * 3))
def test_random_trees_compile_and_answer_every_ray(tree, aim):
    # any tree the model accepts compiles, and a ray at it gets a hit in front of it or none;
    # the hit's surface is one of the tree's own rows (a leaf of this object)
    c = Compiled(Scene.model_validate({"objects": [tree]}).objects[0])
    d = np.subtract(aim, (0.3, 0.2, 6.0))
    h = c.hit((0.3, 0.2, 6.0), d)
    if h is not None:
        assert 0 < h[0] < math.inf
        assert c.geo.prim_info[h[2], PRIM_OBJECT] == 0
        assert abs(np.linalg.norm(h[1]) - 1) < 1e-9


def test_csg_scene_is_the_same_on_any_number_of_threads():
    import whitted

    scene = whitted.load_scene("benchmarks/csg.toml").with_settings(width=64, height=48)
    one = whitted.render(scene, threads=1).pixels
    two = whitted.render(scene, threads=2).pixels
    assert np.array_equal(one, two)
    assert one.std() > 0.05  # a picture, not a blank


def _clear(attenuation):
    # transmits everything (no bending, no reflection, no shading): a pixel seen through it
    # is the background times exp(-attenuation x the length inside)
    return {"color": [1.0, 1.0, 1.0], "ka": 0.0, "kd": 0.0, "ks": 0.0, "kr": 0.0, "kt": 1.0,
            "ior": 1.0, "attenuation": attenuation}


def _through(objects, xs):
    """Pixels along the row through y = 0 at these x (linear values). Each crossing starts
    the next ray 1e-6 off the surface (the automatic offset here): lengths agree to ~1e-5."""
    import whitted

    scene = Scene.model_validate({
        "render": {"width": 20, "height": 1, "transfer": "linear", "max_depth": 10,
                   "min_weight": 0.0, "threads": 1},
        "camera": {"position": [0.0, 0.0, 10.0], "look_at": [0.0, 0.0, 0.0],
                   "projection": "orthographic", "ortho_height": 0.2},
        "background": {"color": [1.0, 1.0, 1.0]},
        "objects": objects})
    image = whitted.render(scene).pixels[0, :, 0]
    # pixel k's centre is at x = -2 + (k + 0.5) * 0.2
    return [float(image[int(round((x + 2.0) / 0.2 - 0.5))]) for x in xs]


def test_a_hollow_block_absorbs_along_its_material_only():
    # a block 2 thick minus a ball of radius 0.5: through the centre 1 unit of material, at
    # x = 0.9 all 2 (the ball's chord there is 0)
    block = {"type": "csg", "operation": "difference", "material": _clear(0.5),
             "objects": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 1]},
                         {"type": "sphere", "radius": 0.5}]}
    centre, edge = _through([block], [0.1, 0.9])
    chord = 2 * math.sqrt(0.25 - 0.01)
    assert centre == pytest.approx(math.exp(-0.5 * (2 - chord)), rel=1e-5)
    assert edge == pytest.approx(math.exp(-0.5 * 2), rel=1e-5)


def test_overlapping_children_are_one_body_and_water_fills_the_hole():
    # a union of two overlapping balls absorbs over the length of their union, not twice
    # over the overlap: at x = 0.1, balls of radius 1 at z = +-0.5 span z from -1.495 to
    # 1.495 (each chord half 0.99499)
    half = math.sqrt(1 - 0.01)
    for operation in ("union", "merge"):
        pair = {"type": "csg", "operation": operation, "material": _clear(0.4),
                "objects": [{"type": "sphere", "center": [0, 0, 0.5], "radius": 1.0},
                            {"type": "sphere", "center": [0, 0, -0.5], "radius": 1.0}]}
        (value,) = _through([pair], [0.1])
        assert value == pytest.approx(math.exp(-0.4 * (2 * half + 1.0)), rel=1e-5)
    # ice around a hole filled by water a hair (1e-4) larger: ice outside the hole, water in
    block = {"type": "csg", "operation": "difference", "material": _clear(0.5),
             "objects": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 1]},
                         {"type": "sphere", "radius": 0.5}]}
    water = {"type": "sphere", "radius": 0.5001, "material": _clear(2.0)}
    (value,) = _through([block, water], [0.1])
    chord = 2 * math.sqrt(0.25 - 0.01)
    assert value == pytest.approx(math.exp(-0.5 * (2 - chord) - 2.0 * chord), rel=2e-3)


def test_a_mesh_leafs_triangles_are_not_walked_as_leaves():
    # the root row counts the tree's rows only (cube, mesh leaf, difference): the mesh's 12
    # triangles come after the tree and are reached through the mesh leaf
    c = Compiled(CSG(operation="difference", objects=[CUBE, _cube_mesh(0.0, 1.0)
                                                      .model_copy(update={"transform": None})]))
    assert c.geo.prim_params[0, :2].tolist() == [3.0, 2.0]


def test_a_row_of_62_balls_every_crossing_in_order():
    # the most leaves a CSG object may have (62 and its operation: the walk keeps each
    # leaf's next crossing in 64 frame slots): a union of 62 balls of radius 0.5 spaced 1.0
    # apart along x, crossed at z = 0.3 (chords of half-length 0.4 that do not meet); a
    # difference of the first ball minus a small ball at x = 0.5 and the 60 others (outside
    # it) shows its front and the cut at x = 0.25
    balls = [Sphere(center=(float(k), 0.0, 0.0), radius=0.5) for k in range(62)]
    c = Compiled(CSG(operation="union", objects=balls))
    ts = c.ts((-10.0, 0.0, 0.3), (1.0, 0.0, 0.0))
    h = math.sqrt(0.25 - 0.09)
    assert len(ts) == 124
    assert ts[:4] == pytest.approx([10 - h, 10 + h, 11 - h, 11 + h], rel=1e-12)
    assert ts[-1] == pytest.approx(71 + h, rel=1e-12)
    cut = CSG(operation="difference",
              objects=[balls[0], Sphere(center=(0.5, 0.0, 0.0), radius=0.25), *balls[2:]])
    c = Compiled(cut)
    assert c.ts((-10.0, 0.0, 0.0), (1.0, 0.0, 0.0)) == pytest.approx([9.5, 10.25], rel=1e-12)


def _die():
    """A die as benchmarks/make_dice.py builds it: a rounded cube minus 21 pips."""
    import importlib.util
    from pathlib import Path

    spec = importlib.util.spec_from_file_location(
        "make_dice", Path(__file__).resolve().parents[1] / "benchmarks" / "make_dice.py")
    dice = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(dice)
    pips = []
    for normal, count in dice.FACES.items():
        n, u, v = dice._axes(normal)
        for a, b in dice.LAYOUT[count]:
            pips.append(Sphere(center=tuple(n[k] * (dice.HALF + dice.PIP - dice.DEPTH)
                                            + dice.STEP * (a * u[k] + b * v[k])
                                            for k in range(3)), radius=dice.PIP))
    body = CSG(operation="intersection", objects=[
        Box(min=(-dice.HALF,) * 3, max=(dice.HALF,) * 3), Sphere(radius=dice.ROUND)])
    return CSG(operation="difference", objects=[body, *pips]), dice


DIE, DICE = _die()
DIE_FAST = Compiled(DIE)
DIE_PLAIN = Compiled(DIE)  # the same rows, walked by the general postfix passes
DIE_PLAIN.geo = DIE_PLAIN.geo._replace(prim_params=DIE_PLAIN.geo.prim_params.copy())
DIE_PLAIN.geo.prim_params[0, 9:11] = 0.0


def test_a_dies_cuts_are_grouped_face_by_face():
    # 23 leaves (box, ball, 21 pips), the first operand's 3 rows walked alone, and the pips
    # in groups of neighbours, each group's box enclosing its pips and no pip of another face
    P = DIE_FAST.geo.prim_params
    assert P[0, :2].tolist() == [25.0, 23.0] and P[0, 9] == 3.0
    groups = P[26:26 + int(P[0, 10])]
    assert groups[0, 0] == 2 and groups[-1, 1] == 23
    assert (groups[1:, 0] == groups[:-1, 1]).all()  # a partition of the cuts, in order
    assert 6 <= len(groups) <= 10
    for g in groups:
        centres = np.array([DIE.objects[k - 1].center for k in range(int(g[0]), int(g[1]))])
        assert (centres - DICE.PIP >= g[2:5]).all() and (centres + DICE.PIP <= g[5:8]).all()
        faces = {(int(np.argmax(abs(c))), bool(c[np.argmax(abs(c))] > 0)) for c in centres}
        assert len(faces) == 1  # the pips of one face


def test_a_ray_into_a_pip_meets_its_floor():
    # straight down the z axis onto the face with one pip: the pip's ball (centre at
    # z = 0.5 + 0.085 - 0.045, radius 0.085) is the floor of the dent, at z = 0.455;
    # beside the pips, the face itself at z = 0.5
    floor = DICE.HALF + DICE.PIP - DICE.DEPTH - DICE.PIP
    for c in (DIE_FAST, DIE_PLAIN):
        t, n, _ = c.hit((0.0, 0.0, 5.0), (0.0, 0.0, -1.0))
        assert t == pytest.approx(5.0 - floor, rel=1e-12)
        np.testing.assert_allclose(n, [0, 0, 1], atol=1e-12)  # the cut turned over
        assert c.hit((0.12, -0.3, 5.0), (0.0, 0.0, -1.0))[0] == pytest.approx(4.5, rel=1e-12)


@settings(max_examples=300, deadline=None)
@given(st.tuples(*[st.floats(-3, 3)] * 3), st.tuples(*[st.floats(-0.7, 0.7)] * 3))
def test_grouped_cuts_answer_as_the_general_walk(origin, target):
    # the cut mask and the skipped groups change no answer: every crossing along the ray,
    # surface and row, as the postfix passes over the whole tree give them
    d = np.subtract(target, origin)
    if np.linalg.norm(d) < 1e-3:
        return
    fast = DIE_FAST.hits(origin, d)
    plain = DIE_PLAIN.hits(origin, d)
    assert [(h[0], h[2]) for h in fast] == [(h[0], h[2]) for h in plain]


def _ball_mesh(subdivisions):
    """A unit icosphere of 20 * 4**subdivisions triangles (closed), as a Mesh."""
    import trimesh

    from whitted.scene import Mesh

    ball = trimesh.creation.icosphere(subdivisions=subdivisions)
    return Mesh(vertices=ball.vertices.tolist(), faces=ball.faces.tolist())


BITE = Box(min=(0.0, 0.0, -2.0), max=(2.0, 2.0, 0.5))


@pytest.mark.parametrize("transform", [None, Transform(scale=(1.0, 0.5, 1.5),
                                                       translate=(0.2, -0.1, 0.3))])
def test_a_big_mesh_ball_minus_a_box_is_the_analytic_one(transform):
    # 81,920 triangles (over the old limit of 65,536, crossings through the mesh's own BVH),
    # as the child of a CSG with or without its own transform (then in the mesh's space):
    # the same first hits as the exact ball minus the box, to the tessellation's error
    # (an icosphere's flat faces lie within 1 - cos(half the edge's angle) ~ 5e-5 of it)
    mesh = _ball_mesh(6).model_copy(update={"transform": transform})
    ball = Sphere(radius=1.0, transform=transform)
    tess = Compiled(CSG(operation="difference", objects=[mesh, BITE]))
    exact = Compiled(CSG(operation="difference", objects=[ball, BITE]))
    assert len(tess.compiled.geometry.prim_info) > 81_920
    assert tess.geo.prim_params[1, 2] >= 1  # the mesh leaf names its stored mesh (+1)
    rays = [((0.3, 0.3, 5.0), (0.0, 0.0, -1.0)), ((0.6, 0.55, 5.0), (0.0, 0.0, -1.0)),
            ((0.7, 0.6, 5.0), (0.0, 0.0, -1.0)), ((5.0, 0.3, 0.2), (-1.0, 0.0, 0.0)),
            ((-0.5, 0.2, 5.0), (0.0, 0.0, -1.0)), ((0.1, -4.0, 0.1), (0.05, 1.0, 0.02)),
            ((3.0, 2.0, 4.0), (-0.7, -0.45, -1.0))]
    shown = 0
    for o, d in rays:
        a = tess.hits(o, d)
        b = exact.hits(o, d)
        assert len(a) == len(b), (o, d)
        for (ta, na, _), (tb, nb, _) in zip(a, b, strict=True):
            assert ta == pytest.approx(tb, abs=2e-4)
            assert np.dot(na, nb) > 0.97  # flat faces: the normal within ~1.5 degrees
        shown += len(a)
    assert shown >= 8
    if transform is None:  # the worked values: the ball at (0.3, 0.3), the box's cut face
        assert tess.hit((0.3, 0.3, 5.0), (0.0, 0.0, -1.0))[0] == pytest.approx(
            5.0 - math.sqrt(1 - 0.18), abs=1e-4)
        t, n, _ = tess.hit((5.0, 0.3, 0.2), (-1.0, 0.0, 0.0))
        assert t == pytest.approx(5.0, rel=1e-12)  # x = 0, inside the ball
        np.testing.assert_allclose(n, [1, 0, 0], atol=1e-12)
        assert tess.hit((0.7, 0.6, 5.0), (0.0, 0.0, -1.0)) is None  # bitten away


def test_one_big_mesh_in_two_csg_objects():
    # the same file-less mesh in two objects (each its own stored copy and rows): both cut
    mesh = _ball_mesh(5)
    scene = Scene(objects=[
        CSG(operation="intersection", objects=[mesh, Box(min=(-2, -2, -2), max=(2, 2, 0.0))]),
        CSG(operation="intersection", objects=[mesh, Box(min=(-2, -2, -2), max=(2, 2, 0.0))],
            transform=Transform(translate=(3.0, 0.0, 0.0)))])
    c = Compiled(*scene.objects)
    for x in (0.0, 3.0):
        t, n, _ = c.hit((x + 0.2, 0.1, 5.0), (0.0, 0.0, -1.0))
        assert t == pytest.approx(5.0, rel=1e-12)  # the box's face z = 0 inside the ball
        np.testing.assert_allclose(n, [0, 0, 1], atol=1e-12)
        t, _, _ = c.hit((x + 0.2, 0.1, -5.0), (0.0, 0.0, 1.0))
        assert t == pytest.approx(5.0 - math.sqrt(1 - 0.05), abs=3e-4)


def test_a_ray_through_a_rim_keeps_the_inside_state_right():
    """A ray aimed exactly at the rim of a cone's top cap often gets only one of its two
    crossings there (rounding puts the point a hair outside both the side and the cap): the
    walk must not take the other crossing for an entry. Box minus cone, the cone standing
    out of the box: rays enter the cone through its top rim (above the box), go down inside
    it and leave through its wall inside the box, which is the first surface they see (the
    box's top face is cut away where the cone passes). The same rays moved a little inward,
    clear of the rim, see the same wall."""
    cone = Cone(base=(0, -1, 0), top=(0, 1, 0), radius=1.0, top_radius=0.5)
    c = Compiled(CSG(operation="difference",
                     objects=[Box(min=(-2, -2, -2), max=(2, 0.5, 2)), cone]))
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(400):
        a = rng.uniform(0.0, 2.0 * math.pi)
        rim = np.array([0.5 * math.cos(a), 1.0, 0.5 * math.sin(a)])
        inward = -np.array([math.cos(a), 0.0, math.sin(a)])
        d = 0.35 * inward + np.array([0.0, -1.0, 0.0]) + rng.normal(0.0, 0.03, 3)
        d /= np.linalg.norm(d)
        o = rim - 3.0 * d
        at_rim = c.hit(o, d)
        clear = c.hit(o + 1e-6 * inward, d)
        assert at_rim is not None and clear is not None
        p = o + at_rim[0] * d
        assert p[1] < 0.5 - 1e-6  # below the box's top face: the cone's wall, not the face
        assert at_rim[0] == pytest.approx(clear[0], abs=1e-4)
        checked += 1
    assert checked == 400


# Two leaves walked by parity take a shorter walk (kernels/csg.py _pair_walk); the same tree
# with a third leaf that changes nothing takes the general one. Both must give the same
# surfaces, to the bit, in the same order.
_FAR = Sphere(center=(50.0, 50.0, 50.0), radius=0.1)  # no ray below comes near it
_ALL = Sphere(radius=100.0)  # holds every ray's whole stretch near the pair
_LENS = Sphere(center=(0.5, 0.1, 0.0), radius=1.1)
_RING = Torus(major_radius=0.9, minor_radius=0.3, transform=Transform(rotate=(70.0, 0.0, 0.0)))
_PAIRS = [
    (op, first, second)
    for op in ("union", "intersection", "difference", "merge")
    for first, second in ((CUBE, Sphere(center=(0.6, 0.6, 0.6), radius=0.9)),
                          (Sphere(center=(-0.5, 0.0, 0.0), radius=1.0), _LENS),
                          (_RING, Box(min=(-1.5, -1.0, -1.5), max=(0.0, 1.0, 1.5))),
                          (CUBE, Cylinder(base=(0.0, -2.0, 0.0), top=(0.0, 1.0, 0.0),
                                          radius=0.4)),
                          (Cone(base=(0.0, -1.2, 0.0), top=(0.3, 1.2, 0.2), radius=1.0,
                                top_radius=0.3), _LENS))
]
_PAIR_SCENES = [
    (Compiled(CSG(operation=op, objects=[a, b])),
     Compiled(CSG(operation=op, objects=[a, b, _ALL if op == "intersection" else _FAR])))
    for op, a, b in _PAIRS
]


@settings(max_examples=300, deadline=None)
@given(st.integers(0, len(_PAIRS) - 1), st.tuples(*[st.floats(-3, 3)] * 3),
       st.tuples(*[st.floats(-1.5, 1.5)] * 3))
def test_a_pair_of_leaves_answers_as_the_general_walk(which, origin, target):
    d = np.subtract(target, origin)
    if np.linalg.norm(d) < 1e-3:
        return
    pair, general = _PAIR_SCENES[which]
    got = [(t, prim) for t, _, prim in pair.hits(origin, d)]
    want = [(t, prim) for t, _, prim in general.hits(origin, d)]
    assert got == want


def test_the_pair_walk_is_taken_and_finds_every_surface():
    # the ball minus the lens along the x axis: in at -1.5, out where the lens starts
    # (0.5 - sqrt(1.1^2 - 0.1^2)), and nothing of the lens itself past the ball's end
    pair, _ = _PAIR_SCENES[[i for i, p in enumerate(_PAIRS)
                            if p[0] == "difference" and p[2] is _LENS][0]]
    ts = pair.ts((-3.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    x_lens = 0.5 - math.sqrt(1.1 ** 2 - 0.1 ** 2)
    assert ts == pytest.approx([-1.5 + 3.0, x_lens + 3.0], rel=1e-12)
