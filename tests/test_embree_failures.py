"""compile/embree.py when things go wrong: no library to load (each candidate's reason kept),
Embree failing to allocate or reporting an error, and a failure part way through a mesh's
scenes or a list of meshes, which must release every scene made so far (a fake library
counts them). And ``mesh_tracer = "auto"`` made concrete for the farm."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from whitted.compile import embree as E
from whitted.errors import SceneError


class FakeLib:
    """The rtc* calls EmbreeLibrary makes, counting live scenes; fails where told."""

    def __init__(self, fail_buffers=False, error=0, fail_after=None):
        self.live: set[int] = set()
        self.next = 100
        self.fail_buffers, self.error, self.fail_after = fail_buffers, error, fail_after
        self.released_geometries = 0
        self.buffers: list = []

    def _handle(self):
        self.next += 1
        return self.next

    def rtcNewScene(self, device):  # noqa: N802 - Embree's names
        if self.fail_after is not None and len(self.live) >= self.fail_after:
            raise MemoryError("out of scenes")
        h = self._handle()
        self.live.add(h)
        return h

    def rtcNewGeometry(self, device, kind):  # noqa: N802
        return self._handle()

    def rtcSetNewGeometryBuffer(self, geom, *args):  # noqa: N802
        if self.fail_buffers:
            return 0
        buffer = ctypes.create_string_buffer(args[-2] * args[-1])  # stride x count bytes
        self.buffers.append(buffer)  # kept alive: triangle_scene copies into it
        return ctypes.addressof(buffer)

    def rtcReleaseGeometry(self, geom):  # noqa: N802
        self.released_geometries += 1

    def rtcReleaseScene(self, scene):  # noqa: N802
        self.live.discard(getattr(scene, "value", scene))

    def rtcGetDeviceError(self, device):  # noqa: N802
        return self.error

    def __getattr__(self, name):  # flags, quality, commits, attach: nothing to do
        return lambda *args: None


def _library(lib: FakeLib) -> E.EmbreeLibrary:
    library = object.__new__(E.EmbreeLibrary)
    library.lib, library.path, library.device = lib, "fake", 1
    return library


def test_buffers_that_cannot_be_allocated():
    lib = FakeLib(fail_buffers=True)
    with pytest.raises(MemoryError, match="^Embree could not allocate a mesh's buffers$"):
        _library(lib).triangle_scene(np.zeros((3, 3)), np.array([[0, 1, 2]]))
    assert lib.live == set() and lib.released_geometries == 1
    lib = FakeLib(fail_buffers=True, error=3)
    with pytest.raises(OSError) as info:
        _library(lib).triangle_scene(np.zeros((3, 3)), np.array([[0, 1, 2]]))
    assert str(info.value) == "Embree error 3 while allocating a mesh (fake)"


def test_a_failure_part_way_releases_every_scene_made():
    v, f = np.zeros((3, 3), np.float32), np.array([[0, 1, 2], [0, 2, 1]])
    mixed = np.array([True, False])
    lib = FakeLib(fail_after=2)  # the mixed mesh's third scene fails
    with pytest.raises(MemoryError):
        E._mesh_row(_library(lib), v, f, mixed)
    assert lib.live == set()
    lib = FakeLib(fail_after=2)  # two one-scene meshes, then the third fails
    with pytest.raises(MemoryError):
        E.build_mesh_scenes(_library(lib), [v, v, v], [f, f, f],
                            [np.ones(2, bool), np.zeros(2, bool), np.ones(2, bool)])
    assert lib.live == set()
    lib = FakeLib()
    rows = E.build_mesh_scenes(_library(lib), [v, v, v], [f, f, f],
                               [np.ones(2, bool), np.zeros(2, bool), mixed])
    a, b, c, d, e = sorted(lib.live)
    assert rows == [[a, a, 0], [b, 0, b], [c, d, e]]  # all, opaque, clear


def test_no_library_to_load(monkeypatch):
    monkeypatch.setattr(E, "_library", None)
    monkeypatch.setattr(E, "_library_error", None)
    monkeypatch.setattr(E, "library_candidates", lambda: ["/nonexistent/libembree4.so"])
    assert E.embree_library() is None
    assert E.why_not().startswith("/nonexistent/libembree4.so: /nonexistent/libembree4.so: ")
    with pytest.raises(SceneError) as info:
        E.attach_embree("embree", np.zeros((1, 4), np.int32), [np.zeros((3, 3))],
                        [np.array([[0, 1, 2]])], [np.zeros(1, np.int64)], np.zeros((1, 20)))
    assert str(info.value).startswith("render.mesh_tracer = 'embree': Embree is not available "
                                      "(/nonexistent/libembree4.so: ")
    monkeypatch.setattr(E, "_library_error", None)
    monkeypatch.setattr(E, "library_candidates", lambda: [])
    assert E.embree_library() is None
    assert E.why_not() == ("no libembree4 found (pip install 'whitted[embree]', or set "
                           "WHITTED_EMBREE_LIBRARY)")


def test_candidates(monkeypatch, tmp_path):
    monkeypatch.setenv("WHITTED_EMBREE_LIBRARY", "none")
    assert list(E.library_candidates()) == []
    monkeypatch.setenv("WHITTED_EMBREE_LIBRARY", str(tmp_path / "my.so"))
    asked = []
    monkeypatch.setattr(E.ctypes.util, "find_library",
                        lambda name: asked.append(name) or "libembree4.so.4")
    candidates = E.library_candidates()
    assert next(candidates) == str(tmp_path / "my.so")
    assert asked == []  # the system's search waits until the candidates before it failed
    assert list(candidates)[-1] == "libembree4.so.4"
    assert asked == ["embree4"]


def test_auto_made_concrete(monkeypatch):
    from whitted.scene import Scene

    fixed = Scene(render={"mesh_tracer": "whitted"})
    assert E.with_concrete_mesh_tracer(fixed) is fixed
    monkeypatch.setenv("WHITTED_MESH_TRACER", "whitted")
    assert E.with_concrete_mesh_tracer(Scene()).render.mesh_tracer == "whitted"
    assert E.attach_embree("whitted", "unchanged", [], [], [], None) == "unchanged"
