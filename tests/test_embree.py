"""Meshes traced by Embree (compile/embree.py, kernels/embree.py) against whitted's own walk:
the same hits, the same shadows through opaque and transparent triangles, images that do
not depend on the thread count, scenes released with the arrays that name them, and a clear
error where Embree is asked for and missing."""

from __future__ import annotations

import gc
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numba import njit

import whitted
from meshgen import uv_sphere
from whitted.compile import embree as embree_module
from whitted.compile.embree import embree_addresses, embree_library, resolve_mesh_tracer
from whitted.compile.scene import compile_scene
from whitted.errors import SceneError
from whitted.kernels.accel import closest_hit
from whitted.kernels.embree import float32_above, float32_below
from whitted.kernels.layout import BVH_STACK
from whitted.kernels.lighting import any_occluder

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
pytestmark = pytest.mark.skipif(embree_library() is None, reason="Embree not installed")


@njit(cache=False)
def _trace(geo, mats, origins, directions, out_t, out_tri, out_shadow, stack):
    for k in range(origins.shape[0]):
        o = (origins[k, 0], origins[k, 1], origins[k, 2])
        d = (directions[k, 0], directions[k, 1], directions[k, 2])
        t, prim, tri, b1, b2 = closest_hit(geo, o, d, 1e-9, np.inf, stack)
        out_t[k] = t if prim >= 0 else np.inf
        out_tri[k] = tri
        out_shadow[k] = any_occluder(geo, mats, o, d, 1e-9, 50.0, stack)


def _traced(compiled, origins, directions):
    n = len(origins)
    t, tri, shadow = np.empty(n), np.empty(n, np.int64), np.empty(n, np.int64)
    _trace(compiled.geometry, compiled.materials, np.ascontiguousarray(origins),
           np.ascontiguousarray(directions), t, tri, shadow, np.empty(BVH_STACK, np.int32))
    return t, tri, shadow


def _bumpy_sphere():
    v, f = uv_sphere(40, 80)
    rng = np.random.default_rng(11)
    return v * rng.uniform(0.97, 1.03, (len(v), 1)), f


def _rays(n, seed=5):
    rng = np.random.default_rng(seed)
    o = rng.uniform(-3.0, 3.0, (n, 3))
    target = rng.uniform(-1.2, 1.2, (n, 3))
    return o, target - o


@pytest.mark.parametrize("transform", [None, whitted.Transform(
    scale=(1.3, 0.7, 1.0), rotate=(20.0, 35.0, -10.0), translate=(0.5, -0.2, 0.3))],
    ids=["identity", "affine"])
def test_embree_finds_the_hits_of_whitteds_walk(transform):
    """Random rays at a bumpy closed mesh: the same rays hit, at the same distance (to float32
    precision) on the same triangle (but for a few rays that graze a shared edge)."""
    v, f = _bumpy_sphere()
    scene = whitted.Scene(objects=[whitted.Mesh(v, f, transform=transform)])
    walk = compile_scene(scene, flatten_limit=0, mesh_tracer="whitted")
    fast = compile_scene(scene, flatten_limit=0, mesh_tracer="embree")
    assert walk.mesh_tracer == "whitted" and fast.mesh_tracer == "embree"
    assert fast.geometry.mesh_info[0, 0] == -1 and len(fast.geometry.mesh_nodes) == 0
    o, d = _rays(20_000)
    t_walk, tri_walk, _ = _traced(walk, o, d)
    t_fast, tri_fast, _ = _traced(fast, o, d)
    hit = np.isfinite(t_walk)
    assert 8_000 < hit.sum() < 19_000
    assert (np.isfinite(t_fast) != hit).sum() <= 2  # a ray grazing the silhouette at most
    both = hit & np.isfinite(t_fast)
    # float32: the origin (|o| <= 5) is rounded to 3e-7, so distances agree to about 1e-6
    np.testing.assert_allclose(t_fast[both], t_walk[both], rtol=2e-6, atol=2e-6)
    assert (tri_fast[both] != tri_walk[both]).sum() <= 0.001 * both.sum()


def _two_material_mesh(monkeypatch, opaque_kt=0.0, clear_kt=0.9):
    """A unit quad in z = 0 of two triangles: the left one opaque, the right transparent."""
    from whitted.compile import scene as compile_module
    from whitted.compile.meshes import MeshSource

    v = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float)
    faces = np.array([[0, 1, 3], [1, 2, 3]])  # left-lower and right-upper halves
    mats = [whitted.Material(kt=opaque_kt), whitted.Material(kt=clear_kt, ior=1.0)]
    src = MeshSource("two.obj", v, faces, None, None, np.array([0, 1]), mats)
    monkeypatch.setattr(compile_module, "mesh_source", lambda *a: src)
    return whitted.Mesh(v, faces.tolist())


@pytest.mark.parametrize("override", [None, "clear", "opaque"])
def test_shadows_through_mixed_materials_match_the_walk(monkeypatch, override):
    """A mesh whose triangles mix an opaque and a transparent material blocks a shadow ray
    through the opaque one (1), tints it through the transparent one (2), and an object's
    material overrides both: Embree (two more scenes, one per kind) agrees with the walk."""
    mesh = _two_material_mesh(monkeypatch)
    if override is not None:
        mesh = mesh.model_copy(update={"material": whitted.Material(
            kt=0.9 if override == "clear" else 0.0)})
    scene = whitted.Scene(objects=[mesh])
    n = 2000
    rng = np.random.default_rng(2)
    o = np.column_stack([rng.uniform(-1.5, 1.5, (n, 2)), np.full(n, 2.0)])
    d = np.tile([0.0, 0.0, -1.0], (n, 1))
    walk = compile_scene(scene, flatten_limit=0, mesh_tracer="whitted")
    fast = compile_scene(scene, flatten_limit=0, mesh_tracer="embree")
    rows = embree_addresses(fast.geometry.mesh_info)[0]
    assert (rows[1] != rows[2]) == (rows[1] != 0 and rows[2] != 0)
    assert (embree_addresses(walk.geometry.mesh_info) == 0).all()
    _, _, s_walk = _traced(walk, o, d)
    _, _, s_fast = _traced(fast, o, d)
    np.testing.assert_array_equal(s_fast, s_walk)
    expect = {None: {0, 1, 2}, "clear": {0, 2}, "opaque": {0, 1}}[override]
    assert set(np.unique(s_walk)) == expect


def test_embree_images_do_not_depend_on_threads_or_builds():
    """Same scene, any thread count, any build of the Embree scenes: the same bits; and the
    same picture as whitted's own walk but for float32 rounding on a few pixels."""
    from whitted.render.api import RenderJob

    v, f = _bumpy_sphere()
    scene = whitted.Scene(
        objects=[whitted.Mesh(v, f, material=whitted.Material(kr=0.3)),
                 whitted.Plane(point=(0, -1.1, 0), normal=(0, 1, 0))],
        lights=[whitted.PointLight(position=(3, 4, 5)), whitted.AmbientLight(intensity=0.2)],
    )
    scene.camera.position = (0.0, 0.5, 4.0)
    scene = scene.with_settings(width=96, height=64)

    def render(tracer, threads):
        compiled = compile_scene(scene, flatten_limit=0, mesh_tracer=tracer)
        return RenderJob(scene, threads=threads, compiled=compiled).run().pixels

    one = render("embree", 1)
    two = render("embree", 2)
    np.testing.assert_array_equal(one, two)
    np.testing.assert_array_equal(render("embree", 2), two)
    differ = np.abs(render("whitted", 2) - two).max(axis=2) > 1 / 255
    assert differ.mean() < 0.01


def test_embree_scenes_are_released_with_their_arrays(monkeypatch):
    """Every Embree scene a compile makes is released once, when the last array naming it
    goes; a film's memo keeps one for the next frame and releases it in turn."""
    library = embree_library()
    released: list[int] = []
    retained: list[int] = []
    real_release, real_retain = library.release, library.retain
    monkeypatch.setattr(library, "release", lambda h: (released.append(h), real_release(h)))
    monkeypatch.setattr(library, "retain", lambda h: (retained.append(h), real_retain(h)))
    v, f = uv_sphere(8, 16)
    scene = whitted.Scene(objects=[whitted.Mesh(v, f)])
    compiled = compile_scene(scene, flatten_limit=0, mesh_tracer="embree")
    handle = int(embree_addresses(compiled.geometry.mesh_info)[0, 0])
    view = compiled.geometry.mesh_info[0:]
    del compiled
    gc.collect()
    assert released == []  # a view of the array still names it
    del view
    gc.collect()
    assert released == [handle]

    from whitted.compile.reuse import BvhMemo

    released.clear()
    memo = BvhMemo()
    with memo:
        first = compile_scene(scene, flatten_limit=0, mesh_tracer="embree")
        second = compile_scene(scene, flatten_limit=0, mesh_tracer="embree")
    kept = int(embree_addresses(first.geometry.mesh_info)[0, 0])
    assert int(embree_addresses(second.geometry.mesh_info)[0, 0]) == kept  # built once
    assert retained.count(kept) == 2
    del first, second
    gc.collect()
    assert released == [kept, kept]  # each compile's reference
    del memo
    gc.collect()
    assert released == [kept, kept, kept]  # and the memo's


def test_tracer_choice_and_its_errors(monkeypatch):
    monkeypatch.delenv("WHITTED_MESH_TRACER", raising=False)
    assert resolve_mesh_tracer("auto") == "embree"
    assert resolve_mesh_tracer("whitted") == "whitted"
    monkeypatch.setenv("WHITTED_MESH_TRACER", "whitted")
    assert resolve_mesh_tracer("auto") == "whitted"
    assert resolve_mesh_tracer("embree") == "embree"  # the scene's own word wins
    monkeypatch.setenv("WHITTED_MESH_TRACER", "fast")
    with pytest.raises(SceneError, match="WHITTED_MESH_TRACER"):
        resolve_mesh_tracer("auto")
    monkeypatch.delenv("WHITTED_MESH_TRACER")
    monkeypatch.setattr(embree_module, "embree_library", lambda: None)
    monkeypatch.setattr(embree_module, "why_not", lambda: "no libembree4 found")
    assert resolve_mesh_tracer("auto") == "whitted"
    with pytest.raises(SceneError, match="Embree is not available"):
        resolve_mesh_tracer("embree")


def test_cli_says_in_one_line_when_embree_is_missing(tmp_path):
    """``mesh_tracer = "embree"`` where Embree cannot load: exit 2, one line, no traceback;
    ``auto`` renders with whitted's walk."""
    v, f = uv_sphere(100, 200)  # two objects of 39,600 triangles: instanced
    obj = tmp_path / "ball.obj"
    obj.write_text("".join(f"v {x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in v)
                   + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in f))
    lines = ["[render]", "width = 16", "height = 16", 'mesh_tracer = "embree"', "",
             "[[objects]]", 'type = "mesh"', 'file = "ball.obj"', "",
             "[[objects]]", 'type = "mesh"', 'file = "ball.obj"',
             "transform = { translate = [3.0, 0.0, 0.0] }"]
    scene_file = tmp_path / "mesh.toml"
    scene_file.write_text("\n".join(lines) + "\n")
    env = dict(os.environ, WHITTED_EMBREE_LIBRARY="none")
    env.pop("WHITTED_MESH_TRACER", None)
    whitted_cli = [sys.executable, "-m", "whitted", "render", str(scene_file), "-q", "-o"]
    out = subprocess.run(whitted_cli + [str(tmp_path / "x.png")], capture_output=True,
                         text=True, env=env, timeout=300)
    assert out.returncode == 2, out.stderr
    message = out.stderr.strip().splitlines()
    assert len(message) == 1 and "Embree is not available" in message[0], out.stderr
    assert "mesh.toml" in message[0] or "mesh_tracer" in message[0]
    assert not (tmp_path / "x.png").exists()
    out = subprocess.run(whitted_cli + [str(tmp_path / "y.png"), "--set",
                                        "render.mesh_tracer=auto"],
                         capture_output=True, text=True, env=env, timeout=300)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "y.png").exists()


def test_scenes_without_big_meshes_never_load_embree(tmp_path):
    """Embree is loaded by the first scene that stores a mesh for instancing, not before: a
    plain render (and the small meshes flattened into the scene BVH) leaves it unloaded."""
    code = ("import whitted\n"
            "from whitted.compile import embree\n"
            f"whitted.render({str(EXAMPLES / 'glass_cube.toml')!r}, width=16, height=12)\n"
            "maps = open('/proc/self/maps').read()\n"
            "print('LOADED' if 'embree' in maps or embree._library is not None else 'CLEAN')\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=600, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "CLEAN"


@njit(cache=False)
def _inward(xs, above, below):
    for k in range(xs.shape[0]):
        above[k] = float32_above(xs[k])
        below[k] = float32_below(xs[k])


def _reference_above(x):
    y = np.float32(x)
    if np.float64(y) <= x:
        y = np.nextafter(y, np.float32(np.inf))
    return np.float64(y)


def _reference_below(x):
    if x == np.inf:
        return x
    y = np.float32(x)
    if np.float64(y) >= x:
        y = np.nextafter(y, np.float32(-np.inf))
    return np.float64(y)


def test_segment_ends_round_inward_to_the_next_float32_as_nextafter_does():
    """Embree's closed float32 segment from whitted's open one: the bit-level step of
    kernels/embree.py gives np.nextafter's float32 on every kind of value (zeros of both
    signs, subnormals, the largest finite, infinities, values a float32 holds exactly and
    values between two), bit for bit."""
    tiny = float(np.finfo(np.float32).smallest_subnormal)
    big = float(np.finfo(np.float32).max)
    special = [0.0, -0.0, tiny, -tiny, tiny / 3, -tiny / 3, 2 * tiny, 1e-40, -1e-40,
               1.1754942e-38, 1.0, -1.0, 0.1, -0.1, 1e-4, 50.0, 1e30, big, -big,
               big * (1 + 1e-9), -big * (1 + 1e-9), 1e39, -1e39, 1e300, -1e300,
               np.inf, -np.inf, np.nan]
    rng = np.random.default_rng(3)
    random = rng.standard_normal(2000) * 10.0 ** rng.uniform(-40, 38, 2000)
    exact = rng.standard_normal(500).astype(np.float32).astype(np.float64)
    xs = np.concatenate([special, random, exact])
    above, below = np.empty_like(xs), np.empty_like(xs)
    _inward(xs, above, below)
    with np.errstate(over="ignore"):
        want_above = np.array([_reference_above(x) for x in xs])
        want_below = np.array([_reference_below(x) for x in xs])
    assert above.view(np.int64).tolist() == want_above.view(np.int64).tolist()
    assert below.view(np.int64).tolist() == want_below.view(np.int64).tolist()
    finite = np.isfinite(xs) & (np.abs(xs) < big)
    assert np.all(above[finite] > xs[finite]) and np.all(below[finite] < xs[finite])
