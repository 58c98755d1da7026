"""The warm-up that gets kernels ready before a render, and its compile helper process."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from whitted.compile.scene import compile_scene
from whitted.kernels import tiles
from whitted.render import warm_up
from whitted.scene.scene import Scene

#: run in a process of its own on an empty cache folder, without the helper: every kernel
#: below render_tiles is compiled there, each for the types its callers ask for
_SIGNATURES = r"""
import sys

import numpy as np

from whitted.compile.params import render_params
from whitted.kernels import tiles
from whitted.kernels.callees import callees_here_first, render_callees
from whitted.kernels.layout import N_RAY_KINDS
from whitted.render import warm_up
from whitted.scene.scene import RenderSettings, Scene

stand_in = warm_up.stand_in_scene(sys.argv[1] == "general")
params = render_params(Scene(), stand_in, RenderSettings(width=1, height=1))
arrays = (stand_in.geometry, stand_in.materials, stand_in.lights, params)
delegated, here = render_callees(*arrays), callees_here_first(*arrays)
assert delegated and here
tiles.render_tiles(np.zeros((0, 4), np.int32), np.zeros((1, 1, 3), np.float32),
                   stand_in.geometry, stand_in.materials, stand_in.lights, params,
                   np.zeros((1, N_RAY_KINDS), np.int64), tiles.lane_workspace(1),
                   tiles.adaptive_workspace(), 0.0, -1, 0, 1)
for dispatcher, argument_types in delegated + here:
    asked = list(dispatcher.callee.overloads)
    if tuple(argument_types) not in asked:
        print(f"{dispatcher.py_func.__name__}: render_tiles compiled {asked}, "
              f"the helper would compile {argument_types}")
"""


@pytest.mark.parametrize("variant", ["plain", "general"])
def test_helper_compiles_the_signatures_render_tiles_calls(tmp_path, variant):
    """The helper's work is only of use if the render kernel asks for exactly these variants.

    A process of its own compiles render_tiles on an empty cache folder without the helper:
    every kernel below it is compiled there for the types its callers ask for (directly, or
    through an overload whose implementation is a kernel's body, extras.py), and those are
    what each listed kernel's twin then holds in ``overloads``. In this process a caller
    loaded from the cache, or an overload's body compiled by an earlier test, would ask for
    nothing."""
    from whitted.jit.dispatcher import tuned

    if not tuned():
        pytest.skip("the helper works with the tuned dispatcher only")
    env = {**os.environ, "WHITTED_CACHE_DIR": str(tmp_path), "WHITTED_COMPILE_HELPER": "0"}
    result = subprocess.run([sys.executable, "-c", _SIGNATURES, variant], env=env,
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout == ""


def test_warm_up_marks_the_cache_folder():
    warm_up.warm_up_kernels()
    assert warm_up._marker(False).exists()
    assert warm_up.warm_up_kernels() == 0.0  # already loaded in this process


def test_helper_process_runs_to_completion():
    """``python -m whitted.render.warm_up`` (with the cache already warm: it loads)."""
    warm_up.warm_up_kernels()
    result = subprocess.run([sys.executable, "-m", "whitted.render.warm_up", "plain"],
                            capture_output=True, text=True, env=dict(os.environ),
                            timeout=300)
    assert result.returncode == 0, result.stderr


def test_no_helper_when_disabled(monkeypatch):
    monkeypatch.setenv("WHITTED_COMPILE_HELPER", "0")
    assert warm_up._start_helper(False) is None


def test_waits_for_the_helpers_callees_and_counts_its_compiles():
    """The render process waits for a kernel the helper compiles (True: load it), not for
    others (False at once), and stops waiting when the helper has gone without it."""
    import threading
    import time

    lines: list[str] = []
    more = threading.Event()

    def helper_output():  # what the helper prints, line by line, as it goes
        for k in range(3):
            more.wait(5)
            yield from lines[k:k + 1]
        more.wait(5)

    count = warm_up._CompileCount(10, ("a__callee", "b__callee"))
    reader = threading.Thread(target=count.read_helper, args=(helper_output(),))
    assert count.wait_for_helper("c__callee") is False  # not the helper's: compile here
    lines.extend([".\n", ".\n", "done a__callee\n"])
    reader.start()
    start = time.monotonic()
    more.set()
    assert count.wait_for_helper("a__callee") is True
    reader.join(5)
    assert count.helper == 2 and count.fraction == 0.2
    # the helper ended without b: the render process compiles it itself
    assert count.helper_gone
    assert count.wait_for_helper("b__callee") is False
    assert time.monotonic() - start < 5


@pytest.mark.parametrize("output, told", [
    ([".\n", "done a__callee\n", ".\n", "finished\n"], 1),
    ([".\n", "done a__callee\n"], 0),  # killed before the end of its work
])
def test_the_helper_s_end_is_told_once_its_work_is_finished(output, told):
    """The caller of a cold compile hears that the helper has finished (its last line), so
    it may give that core other work while the render kernel's own module compiles; a
    helper that ended without finishing (stopped, or failed) tells nothing."""
    ends = []
    count = warm_up._CompileCount(10, ("a__callee",), on_helper_end=lambda: ends.append(1))
    count.read_helper(iter(output))
    assert len(ends) == told
    assert count.helper == output.count(".\n")  # "finished" is not a compile
    assert count.helper_gone and not count.pending


def test_the_helper_says_finished_after_its_last_work(monkeypatch, capsys):
    done = []
    monkeypatch.setattr(warm_up, "_delegated", lambda instances: [])
    monkeypatch.setattr(warm_up, "_compile_light_buffers",
                        lambda instances: done.append("light buffers"))
    monkeypatch.setattr(warm_up, "compile_builders", lambda: done.append("builders"))
    warm_up.precompile_for_render(False, builders=True)
    assert done == ["light buffers", "builders"]
    assert capsys.readouterr().out.splitlines() == ["finished"]


def test_a_hung_helper_is_waited_for_once(monkeypatch):
    """A helper that neither finishes a kernel nor exits costs one wait, not one per kernel
    it was to compile: after the first wait runs out, the render process compiles the rest
    itself without waiting."""
    monkeypatch.setattr(warm_up, "HELPER_WAIT_SECONDS", 0.0)  # the first wait runs out now
    count = warm_up._CompileCount(10, ("a__callee", "b__callee", "c__callee"))
    assert count.wait_for_helper("a__callee") is False
    assert count.helper_gone

    def no_waiting(timeout=None):
        raise AssertionError("waited for a helper taken for hung")

    monkeypatch.setattr(warm_up, "HELPER_WAIT_SECONDS", 600.0)
    monkeypatch.setattr(count._changed, "wait", no_waiting)
    assert count.wait_for_helper("b__callee") is False
    assert count.wait_for_helper("c__callee") is False


def test_the_warm_up_loads_the_kernel_a_torus_or_csg_scene_renders_with():
    """Scenes with tori or CSG objects run their own specialisation of the render kernel. The
    warm-up must load it (not the render's first call, whose time would then include a cache
    load: the csg benchmark's render read 0.10 s instead of 0.075 s), also after the plain one
    is loaded in this process."""
    from whitted.compile.scene import compile_scene
    from whitted.scene import Torus

    warm_up.warm_up_kernels()  # the plain kernel, as RenderJob.run loads first
    compiled = compile_scene(Scene(objects=[Torus(major_radius=1.0, minor_radius=0.25)]))
    assert compiled.geometry.unbounded.dtype == np.int64  # the kind with extras
    warm_up.warm_up_kernels(compiled)

    def geometry_dtypes(sig):
        return [str(t.dtype) for t in sig[2].types]

    wanted = [str(a.dtype) for a in compiled.geometry]
    assert any(geometry_dtypes(sig) == wanted for sig in tiles.render_tiles.signatures)
    assert warm_up.warm_up_kernels(compiled) == 0.0  # and only once


def test_the_expected_compile_count_is_the_real_one(tmp_path):
    """The progress bar of a first compile reaches its end when the count of functions
    compiled reaches ``EXPECTED_COMPILES``: a cold compile of the plain variant (an empty
    cache folder, in a process of its own, without the helper, which only moves compiles
    from one process to the other) compiles that many, give or take 10 %."""
    script = (
        "from numba.core import event\n"
        "from whitted.jit import load_numba\n"
        "from whitted.render import warm_up\n"
        "load_numba()\n"
        "with event.install_recorder('numba:compile') as rec:\n"
        "    warm_up.warm_up_kernels()\n"
        "print(sum(1 for _, ev in rec.buffer if ev.is_end))\n")
    env = dict(os.environ, WHITTED_CACHE_DIR=str(tmp_path), WHITTED_COMPILE_HELPER="0")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            env=env, timeout=600)
    assert result.returncode == 0, result.stderr
    compiled = int(result.stdout.split()[-1])
    expected = warm_up.EXPECTED_COMPILES[False]
    assert abs(compiled - expected) <= 0.1 * expected, (compiled, expected)


#: a compile helper is started only with two cores or more and the helper not switched off
helpers_start = pytest.mark.skipif(
    len(os.sched_getaffinity(0)) < 2 or os.environ.get("WHITTED_COMPILE_HELPER") == "0"
    or os.environ.get("NUMBA_DISABLE_JIT") == "1",
    reason="no compile helper is started here (one core, or switched off)")


@pytest.fixture
def ahead_stopped():
    """Whatever a test leaves started ahead (a failed assertion) is stopped after it."""
    yield
    warm_up.stop_cold_compile_ahead()


def _started_helpers(monkeypatch) -> list:
    """The helpers warm_up starts from now on (their Popen objects)."""
    started = []
    start = warm_up._start_helper

    def recording(instances, builders=False):
        helper = start(instances, builders)
        if helper is not None:
            started.append(helper)
        return helper

    monkeypatch.setattr(warm_up, "_start_helper", recording)
    return started


@helpers_start
def test_the_helper_started_ahead_is_adopted_by_the_compile(monkeypatch, tmp_path,
                                                            ahead_stopped):
    """``whitted render`` starts the helper before its output checks (which compile the OBJ
    reader on a cold cache); the render's warm-up then uses that helper and that lock, and
    releases the lock when done. Cold here as far as the warm-up knows (no marker), the
    kernels themselves load from the test cache."""
    warm_up.warm_up_kernels()  # the kernels in the cache, and the plain variant loaded here
    marker = tmp_path / "whitted-ready-plain"
    monkeypatch.setattr(warm_up, "_marker", lambda instances: marker)
    monkeypatch.setattr(warm_up, "_ready", set())
    started = _started_helpers(monkeypatch)
    assert warm_up.start_cold_compile_ahead()
    assert warm_up.start_cold_compile_ahead()  # once: the same helper
    assert len(started) == 1
    cache = warm_up.prepare()
    assert cache.take_compile_lock("plain") is None  # held ahead
    warm_up.warm_up_kernels()
    assert len(started) == 1 and started[0].poll() is not None  # adopted, waited for
    assert warm_up._ahead is None and marker.exists()
    lock = cache.take_compile_lock("plain")
    assert lock is not None  # released
    lock.release()


@helpers_start
@pytest.mark.parametrize("shape, variant", [
    ('type = "sphere"\nradius = 1.0', "plain"),
    # a scene that runs the general kernels starts their helper, not the plain one's
    ('type = "torus"\nmajor_radius = 1.0\nminor_radius = 0.25', "instances"),
])
def test_a_command_that_ends_before_its_render_stops_the_helper_started_ahead(
        monkeypatch, tmp_path, ahead_stopped, shape, variant):
    """A user mistake found by the output checks (a folder that does not exist): exit 2,
    and the helper started ahead is stopped and the lock released, not left running."""
    from typer.testing import CliRunner

    from whitted.cli.main import app

    monkeypatch.setattr(warm_up, "kernels_cached", lambda instances=False: False)
    monkeypatch.setattr(warm_up, "_ready", set())
    started = _started_helpers(monkeypatch)
    scene = tmp_path / "s.toml"
    scene.write_text(f"[[objects]]\n{shape}\n")
    out = tmp_path / "no such folder" / "x.png"
    result = CliRunner().invoke(app, ["render", str(scene), "-o", str(out)])
    assert result.exit_code == 2, result.output
    assert result.stderr.startswith("error:") and "no such folder" in result.stderr
    assert len(started) == 1 and started[0].poll() is not None
    assert started[0].args[3] == variant  # python -m whitted.render.warm_up VARIANT ...
    assert warm_up._ahead is None
    for name in ("plain", "general"):
        lock = warm_up.prepare().take_compile_lock(name)
        assert lock is not None
        lock.release()


@helpers_start
def test_the_general_helper_started_ahead_is_adopted_by_the_general_compile(
        monkeypatch, tmp_path, ahead_stopped):
    """As for the plain variant: a torus scene's first render uses the general helper
    started ahead and releases the general variant's lock."""
    from whitted.scene import Torus

    compiled = compile_scene(Scene(objects=[Torus(major_radius=1.0, minor_radius=0.25)]))
    warm_up.warm_up_kernels(compiled)  # in the test cache, and loaded here
    marker = tmp_path / "whitted-ready-general"
    monkeypatch.setattr(warm_up, "_marker", lambda instances: marker)
    monkeypatch.setattr(warm_up, "_ready", set())
    started = _started_helpers(monkeypatch)
    assert warm_up.start_cold_compile_ahead(instances=True)
    assert warm_up._take_ahead(False) is None  # not the plain variant's
    cache = warm_up.prepare()
    assert cache.take_compile_lock("general") is None  # held ahead
    warm_up.warm_up_kernels(compiled)
    assert len(started) == 1 and started[0].poll() is not None  # adopted, waited for
    assert started[0].args[3] == "instances"
    assert warm_up._ahead is None and marker.exists()
    lock = cache.take_compile_lock("general")
    assert lock is not None  # released
    lock.release()


def test_no_helper_ahead_on_a_warm_cache(monkeypatch):
    warm_up.warm_up_kernels()
    started = _started_helpers(monkeypatch)
    assert not warm_up.start_cold_compile_ahead()
    assert started == []


def test_no_helper_ahead_when_the_kernels_were_finished_while_the_lock_was_taken(
        monkeypatch, ahead_stopped):
    """Another process may finish the compile (and free the lock) between the first look
    at the cache and the lock: then nothing is started and the lock is not kept."""
    answers = iter([False, True])
    monkeypatch.setattr(warm_up, "kernels_cached", lambda instances=False: next(answers))
    monkeypatch.setattr(warm_up, "_ready", set())
    started = _started_helpers(monkeypatch)
    assert not warm_up.start_cold_compile_ahead()
    assert started == [] and warm_up._ahead is None
    lock = warm_up.prepare().take_compile_lock("plain")
    assert lock is not None  # not held
    lock.release()
