"""The builders' Python twins (jit/python_twins.py): the same arrays as the compiled builders,
bit for bit, on every example and bench scene at hand and on random inputs (OBJ text, boxes,
meshes); the choice between the two by size and cache; the twins leave the modules alone."""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from whitted.assets import obj_scan
from whitted.assets.mesh import clear_mesh_cache, load_obj_bytes
from whitted.compile import bvh as bvh_module
from whitted.compile.bvh import build_bvh
from whitted.compile.normals import smooth_corner_normals
from whitted.compile.scene import compile_scene, scene_needs_builders
from whitted.compile.wide_bvh import wide_nodes
from whitted.errors import SceneError
from whitted.jit import Kernel, python_twins
from whitted.jit.python_twins import as_python, compiled, for_size, python_twin
from whitted.kernels.layout import MESH_EMBREE
from whitted.scene.default import default_scene
from whitted.scene.io import load_scene
from whitted.scene.scene import Scene
from whitted.scene.shapes import Mesh, Sphere

ROOT = Path(__file__).resolve().parents[1]


def _same(a, b, where: str = "") -> None:
    """a and b equal to the bit: arrays by dtype, shape and bytes; containers item by item."""
    if isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray), where
        assert a.dtype == b.dtype and a.shape == b.shape, where
        assert a.tobytes() == b.tobytes(), where
    elif dataclasses.is_dataclass(a):
        for field in dataclasses.fields(a):
            if field.name != "build_seconds":
                _same(getattr(a, field.name), getattr(b, field.name), f"{where}.{field.name}")
    elif getattr(a, "_fields", None) and "mesh_info" in a._fields:  # the geometry's arrays
        for name in a._fields:
            x, y = getattr(a, name), getattr(b, name)
            if name == "mesh_info":  # Embree's scene addresses differ from build to build
                x, y = x[:, :MESH_EMBREE], y[:, :MESH_EMBREE]
            _same(x, y, f"{where}.{name}")
    elif isinstance(a, tuple | list):
        assert len(a) == len(b), where
        fields = getattr(a, "_fields", range(len(a)))
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _same(x, y, f"{where}.{list(fields)[i]}")
    else:
        assert a == b, where


def _both(make):
    """``make()`` with the compiled builders, then with their twins (the model files read
    again each time)."""
    clear_mesh_cache()
    with compiled():
        first = make()
    clear_mesh_cache()
    with as_python():
        second = make()
    clear_mesh_cache()
    return first, second


def _scene_files() -> list[Path]:
    files = [*sorted((ROOT / "examples").glob("*.toml")),
             *sorted((ROOT / "benchmarks").glob("*.toml"))]
    usable = []
    for path in files:
        try:
            scene = load_scene(path)
        except SceneError:  # a bench scene whose generated model is not made here
            continue
        if sum(len(o.faces) for o in scene.objects if isinstance(o, Mesh) and o.faces) < 10_000:
            usable.append(path)
    return usable


@pytest.mark.parametrize("path", ["default", *_scene_files()],
                         ids=lambda p: p if isinstance(p, str) else p.name)
def test_every_scene_compiles_to_the_same_arrays_either_way(path):
    scene = default_scene() if path == "default" else load_scene(path)
    if scene.is_animated:
        scene = scene.at_frame(0)
    a, b = _both(lambda: compile_scene(scene))
    _same(a, b, str(path))


def test_an_instanced_smooth_mesh_too():
    mesh = Mesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
                faces=[[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]], smooth=True)
    scene = Scene(objects=[Sphere(radius=1.0), mesh])
    a, b = _both(lambda: compile_scene(scene, flatten_limit=0))
    _same(a, b)


# --- random inputs ---------------------------------------------------------------------

_numbers = st.one_of(
    st.integers(-10**6, 10**6).map(str),
    st.floats(-1e6, 1e6, allow_nan=False).map(repr),
    st.floats(allow_nan=False, allow_infinity=False).map(lambda x: f"{x:.17e}"),
    st.sampled_from(["1e400", "-0", ".5", "2.", "1e-400", "123456789012345678901234",
                     "0.1e+22", "nan", "-inf", "1x", "+", "e5", "1e", "0x10"]),
)
_index = st.integers(-6, 8).map(str)
_corner = st.one_of(_index, st.tuples(_index, _index).map("/".join),
                    st.tuples(_index, _index).map(lambda p: f"{p[0]}//{p[1]}"),
                    st.tuples(_index, _index, _index).map("/".join))
_line = st.one_of(
    st.lists(_numbers, min_size=2, max_size=4).map(lambda n: "v " + " ".join(n)),
    st.lists(_numbers, min_size=1, max_size=3).map(lambda n: "vt " + " ".join(n)),
    st.lists(_numbers, min_size=2, max_size=3).map(lambda n: "vn " + " ".join(n)),
    st.lists(_corner, min_size=2, max_size=5).map(lambda c: "f " + " ".join(c)),
    st.sampled_from(["# a comment", "usemtl red", "mtllib none.mtl", "g part", "s 1", "",
                     "o thing \\", "   \t"]),
)
_obj_text = st.tuples(st.lists(_line, max_size=25),
                      st.sampled_from(["\n", "\r\n", "\r"])).map(
    lambda t: (t[1].join(t[0]) + t[1]).encode())


def _read(data: bytes):
    try:
        mesh = load_obj_bytes(data, "x.obj", ROOT)
    except SceneError as exc:
        return str(exc)
    return (mesh.vertices, mesh.faces, mesh.normals, mesh.uvs, mesh.face_material,
            mesh.warnings, mesh.vertex_records, mesh.triangle_records)


def _same_or_both_none(a, b) -> None:
    if isinstance(a, str) or isinstance(b, str):
        assert a == b
        return
    for x, y in zip(a, b, strict=True):
        if x is None or y is None:
            assert x is None and y is None
        else:
            _same(x, y)


@given(_obj_text)
def test_the_obj_reader_reads_random_files_alike(data):
    a, b = _both(lambda: _read(data))
    _same_or_both_none(a, b)


@given(st.binary(max_size=300))
def test_the_obj_reader_fails_alike_on_random_bytes(data):
    a, b = _both(lambda: _read(data))
    _same_or_both_none(a, b)


_coordinate = st.floats(-1e3, 1e3, allow_nan=False, width=64)


@given(st.lists(st.tuples(_coordinate, _coordinate, _coordinate, _coordinate, _coordinate,
                          _coordinate), min_size=1, max_size=200),
       st.integers(1, 8), st.integers(2, 16), st.booleans())
def test_bvhs_of_random_boxes_are_built_alike(boxes, leaf, bins, all_axes):
    corners = np.array(boxes, np.float64).reshape(-1, 2, 3)
    lo, hi = corners.min(axis=1), corners.max(axis=1)

    def build():
        tree = build_bvh(lo, hi, max_leaf_size=leaf, n_bins=bins, all_axes=all_axes)
        return tree, wide_nodes(tree)

    a, b = _both(build)
    _same(a, b)


def test_coordinates_near_the_largest_double_build_alike():
    """Centres 3e308 apart: the spread of the centroids overflows to inf, so the binning's
    scale is 0 and inf * 0 is NaN; both builders put such a centroid in the first bin."""
    lo = np.array([[-1.5e308, 0, 0], [1.5e308, 0, 0], [0, 0, 0], [1, 1, 1]], np.float64)
    hi = lo + 1.0
    hi[:2, 0] = lo[:2, 0]

    def build():
        tree = build_bvh(lo, hi, max_leaf_size=1)
        return tree, wide_nodes(tree)

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow warning from the twins either
        a, b = _both(build)
    _same(a, b)
    assert sorted(a[0].prim_order.tolist()) == [0, 1, 2, 3]


@given(st.integers(4, 40), st.integers(0, 2**32 - 1), st.floats(0, 180), st.booleans())
def test_smooth_normals_of_random_meshes_are_alike(n, seed, crease, snapped):
    rng = np.random.default_rng(seed)
    vertices = rng.normal(size=(n, 3))
    if snapped:  # repeated positions: corners welded across faces
        vertices = np.round(vertices)
    faces = rng.integers(0, n, size=(2 * n, 3))
    a, b = _both(lambda: smooth_corner_normals(vertices, faces, crease))
    _same(a, b)


# --- the choice ------------------------------------------------------------------------

def test_a_twin_is_plain_python_and_leaves_the_module_alone():
    twin = python_twin(obj_scan.scan_obj)
    assert not isinstance(twin, Kernel) and twin.__code__ is obj_scan.scan_obj.py_func.__code__
    # the kernels it calls are twins too, in a copy of the module's globals
    assert twin.__globals__ is not vars(obj_scan)
    assert twin.__globals__["parse_number"] is python_twin(obj_scan.parse_number)
    assert isinstance(obj_scan.parse_number, Kernel)  # the module's own: untouched
    assert python_twin(obj_scan.scan_obj) is twin  # made once
    text = np.frombuffer(b"1.25e2", np.uint8)
    assert twin.__globals__["parse_number"](text, 0, 6) == (obj_scan._NUMBER_EXACT, 125.0)
    with pytest.raises(TypeError, match="not a whitted kernel"):
        python_twin(len)


def _twin(chosen):
    """The twin for_size chose (it calls it with NumPy's warnings off), or None."""
    return getattr(chosen, "__wrapped__", None)


@pytest.fixture
def unwarmed(monkeypatch, tmp_path):
    """An automatic choice, with the builders' marker in an empty folder of its own."""
    monkeypatch.setattr(python_twins, "default_mode", None)
    marker = tmp_path / python_twins.BUILDERS_MARKER
    monkeypatch.setattr(python_twins, "_marker", lambda: marker)
    # a kernel not yet compiled in this process (the cached ones have been, by other tests)
    return marker


def test_small_inputs_run_the_twin_until_the_builders_are_cached(unwarmed, monkeypatch):
    kernel = bvh_module._pack
    monkeypatch.setattr(python_twins, "_compiled_here", lambda k: False)
    assert _twin(for_size(kernel, 10, 100)) is python_twin(kernel)
    assert _twin(for_size(kernel, 100, 100)) is python_twin(kernel)  # the limit is inclusive
    assert for_size(kernel, 101, 100) is kernel  # too large: compiled
    with compiled():
        assert for_size(kernel, 10, 100) is kernel
    python_twins.mark_builders_cached()
    assert unwarmed.exists() and python_twins.builders_cached()
    assert for_size(kernel, 10, 100) is kernel
    with as_python():
        assert _twin(for_size(kernel, 10**9, 100)) is python_twin(kernel)


def test_a_builder_compiled_in_this_process_is_used_for_every_size(unwarmed):
    kernel = bvh_module._build
    with compiled():
        build_bvh(np.zeros((3, 3)), np.ones((3, 3)))
    assert for_size(kernel, 1, 100) is kernel


def test_no_cache_folder_means_twins_for_small_inputs(monkeypatch):
    monkeypatch.setattr(python_twins, "default_mode", None)
    monkeypatch.setattr(python_twins, "_marker", lambda: None)
    monkeypatch.setattr(python_twins, "_compiled_here", lambda k: False)
    assert not python_twins.builders_cached()
    python_twins.mark_builders_cached()  # nowhere to mark: nothing happens
    assert _twin(for_size(bvh_module._build, 1, 100)) is python_twin(bvh_module._build)


def test_which_scenes_need_the_builders_compiled(tmp_path):
    assert not scene_needs_builders(default_scene())
    many = Scene(objects=[Sphere(center=(i, 0, 0), radius=0.1)
                          for i in range(bvh_module.PYTHON_LIMIT + 1)])
    assert scene_needs_builders(many)
    big = tmp_path / "big.obj"
    big.write_bytes(b"v 0 0 0\n" * (obj_scan.PYTHON_LIMIT_BYTES // 8 + 1))
    small = tmp_path / "small.obj"
    small.write_bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    on_disk = Scene(objects=[Mesh(file="big.obj")]).with_base_dir(tmp_path)
    assert scene_needs_builders(on_disk)
    assert not scene_needs_builders(Scene(objects=[Mesh(file="small.obj")])
                                    .with_base_dir(tmp_path))
    # a missing model is reported where it is read, not here
    assert not scene_needs_builders(Scene(objects=[Mesh(file="small.obj")])
                                    .with_base_dir(tmp_path / "nowhere"))
