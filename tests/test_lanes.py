"""Render lanes: how the tiles of one render are shared between threads. Each lane's scratch
memory lies on cache lines of its own, rays are counted per tile whichever lane renders it,
lane 0 runs on the calling thread, and a lane that fails does not leave the others writing
after the render returns."""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import whitted
from whitted.compile.params import render_params
from whitted.compile.scene import compile_scene
from whitted.kernels.layout import N_RAY_KINDS, RAY_PRIMARY, RAY_SHADOW
from whitted.kernels.tiles import (
    CACHE_LINE,
    adaptive_workspace,
    lane_workspace,
    own_lines,
    render_tiles,
)
from whitted.render.api import run_lanes, tile_grid


def _lines(a: np.ndarray) -> range:
    """The cache lines (by number) that array ``a``'s bytes lie on."""
    start = a.ctypes.data
    return range(start // CACHE_LINE, (start + a.nbytes - 1) // CACHE_LINE + 1)


@pytest.mark.parametrize(("shape", "dtype"), [(5, np.int64), ((3, 7), np.float64),
                                              ((2, 2), np.int8), ((4, 3, 3), np.float64)])
def test_own_lines_gives_a_zeroed_array_starting_a_line_with_a_free_line_after_it(shape, dtype):
    a = own_lines(shape, dtype)
    assert a.shape == (shape if isinstance(shape, tuple) else (shape,))
    assert a.dtype == np.dtype(dtype)
    assert a.flags.c_contiguous and a.flags.writeable
    assert a.ctypes.data % CACHE_LINE == 0
    assert not a.any()
    owner = a.base
    while owner.base is not None:
        owner = owner.base
    # the allocation holds the whole line after the last byte: nothing else can lie there
    end = a.ctypes.data + a.nbytes
    assert owner.ctypes.data + owner.nbytes >= end + CACHE_LINE


def test_two_lanes_scratch_memory_shares_no_cache_line():
    arrays = [*lane_workspace(5), *lane_workspace(5)]
    assert len(arrays) == 16
    for i, a in enumerate(arrays):
        for b in arrays[i + 1:]:
            assert not set(_lines(a)) & set(_lines(b))


def _scene():
    return whitted.Scene(
        render=whitted.RenderSettings(width=64, height=48, max_depth=3),
        camera=whitted.Camera(position=(0, 1, 5), look_at=(0, 0, 0), fov=50),
        lights=[whitted.PointLight(position=(3, 5, 4))],
        objects=[
            whitted.Plane(point=(0, -1, 0), normal=(0, 1, 0)),
            whitted.Sphere(center=(0, 0, 0), radius=1.0,
                           material=whitted.Material(kr=0.5, kt=0.4, ior=1.5)),
        ],
    )


def _counted(lanes: int) -> tuple[np.ndarray, np.ndarray]:
    scene = _scene()
    compiled = compile_scene(scene)
    params = render_params(scene, compiled, scene.render)
    tiles = tile_grid(params.width, params.height)
    fb = np.zeros((params.height, params.width, 3), np.float32)
    counters = np.full((len(tiles), N_RAY_KINDS), -7, np.int64)  # stale values
    works = [lane_workspace(params.max_depth) for _ in range(lanes)]
    for lane in range(lanes):
        render_tiles(tiles, fb, compiled.geometry, compiled.materials, compiled.lights, params,
                     counters, works[lane], adaptive_workspace(), 0.0, -1, lane, lanes)
    return fb, counters


def test_each_tiles_rays_are_counted_the_same_whichever_lane_renders_it():
    fb1, one = _counted(1)
    fb3, three = _counted(3)
    assert np.array_equal(fb1, fb3)
    assert np.array_equal(one, three)
    # a 16 x 16 tile of this 64 x 48 image: one camera ray a pixel, a shadow ray per lit hit
    assert (one[:, RAY_PRIMARY] == 256).all()
    assert one[:, RAY_SHADOW].sum() > 0
    assert (one >= 0).all()


def test_lane_zero_runs_on_the_calling_thread_and_every_lane_runs_once():
    seen: dict[int, str] = {}
    lock = threading.Lock()

    def fn(lane: int, lanes: int) -> None:
        assert lanes == 3
        with lock:
            assert lane not in seen
            seen[lane] = threading.current_thread().name

    with ThreadPoolExecutor(2, thread_name_prefix="lane") as pool:
        run_lanes(fn, 3, pool)
    assert seen[0] == threading.current_thread().name
    assert {seen[1], seen[2]} <= {f"lane_{k}" for k in range(2)}
    assert seen[1] != seen[0] and seen[2] != seen[0]


def test_a_failing_first_lane_still_waits_for_the_others():
    raised = threading.Event()
    finished = threading.Event()

    def fn(lane: int, lanes: int) -> None:
        if lane == 0:
            raised.set()
            raise RuntimeError("lane 0 failed")
        # still working when lane 0 fails: run_lanes must not return before this ends
        assert raised.wait(10)
        finished.set()

    with ThreadPoolExecutor(1) as pool, pytest.raises(RuntimeError, match="lane 0 failed"):
        run_lanes(fn, 2, pool)
    assert finished.is_set()


def test_a_failing_other_lane_is_raised_after_lane_zero_ends():
    order: list[str] = []

    def fn(lane: int, lanes: int) -> None:
        if lane == 1:
            raise ValueError("lane 1 failed")
        order.append("lane 0 done")

    with ThreadPoolExecutor(1) as pool, pytest.raises(ValueError, match="lane 1 failed"):
        run_lanes(fn, 2, pool)
    assert order == ["lane 0 done"]


class _Stop(Exception):
    pass


def test_a_failing_lane_stops_the_others_before_the_image_is_done():
    """The progress callback raises at its first report (and not again): the error comes
    back, and the other lane stops at its next run instead of rendering the rest of the image
    first."""
    from whitted.render import RenderJob

    scene = _scene().model_copy(update={
        "render": whitted.RenderSettings(width=512, height=512, max_depth=3),
        "background": whitted.Background(color=(0.5, 0.5, 0.5))})
    reports = []

    def progress(p):
        reports.append(p.tiles_done)
        if len(reports) == 1:
            raise _Stop

    job = RenderJob(scene, threads=2, progress=progress)
    with pytest.raises(_Stop):
        job.run()
    tiles = job.framebuffer.reshape(32, 16, 32, 16, 3).any(axis=(1, 3, 4))
    assert 0 < tiles.sum() < tiles.size  # before: the other lane rendered all that was left
