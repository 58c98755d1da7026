"""``whitted warm``: one command compiles every kernel variant a scene can reach; each tiny
scene it renders reaches the variant it is named after."""

from __future__ import annotations

import json
import math
import os
import select
import signal
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from whitted.compile.scene import compile_scene
from whitted.kernels.features import EXTRAS_DTYPE
from whitted.render.variants import GEOMETRY, KINDS, tiny_scene, variant_names
from whitted.scene import Scene

ROOT = Path(__file__).resolve().parents[1]


def _whitted(*args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    return subprocess.run([sys.executable, "-m", "whitted", *args], capture_output=True,
                          text=True, timeout=900, env=env)


def test_every_variant_is_named_once():
    names = variant_names()
    assert len(names) == len(set(names)) == len(GEOMETRY) * len(KINDS) == 6


def test_instances_and_extras_share_the_general_kernels():
    """A scene with mesh instances, one with a torus and one with both run the same
    specialisation (the general kernels); a scene with neither the plain one."""
    from numba import typeof

    from whitted.scene import Sphere

    instanced = compile_scene(tiny_scene(False, "render"), flatten_limit=0)
    torus = compile_scene(tiny_scene(True, "render"))
    both = compile_scene(tiny_scene(True, "render"), flatten_limit=0)
    plain = compile_scene(tiny_scene(False, "render"))
    assert len(instanced.geometry.inst_prims) == 1 and len(torus.geometry.inst_prims) == 0
    general = typeof(both.geometry)
    assert typeof(instanced.geometry) == typeof(torus.geometry) == general
    assert typeof(plain.geometry) != general
    assert plain.geometry.inst_box.dtype == np.float32
    assert plain.geometry.unbounded.dtype == np.int32
    sphere = compile_scene(Scene(objects=[Sphere(radius=1.0)]))
    assert typeof(sphere.geometry) == typeof(plain.geometry)


@pytest.mark.parametrize("geometry", list(GEOMETRY))
def test_each_tiny_scene_reaches_its_variant(geometry):
    instances, extras = GEOMETRY[geometry]
    for kind in KINDS:
        scene = tiny_scene(extras, kind)
        compiled = compile_scene(scene, flatten_limit=0 if instances else 65_536)
        geo = compiled.geometry
        assert (geo.inst_box.dtype == np.float64) == instances, kind
        assert (geo.unbounded.dtype == np.dtype(EXTRAS_DTYPE)) == extras, kind
        assert (scene.render.caustics.photons > 0) == (kind == "caustics")
        assert scene.render.antialias is None  # a run-time choice of the render kernel


def test_a_caustics_variant_compiles_the_photon_tracer_and_no_render_kernel(monkeypatch):
    # a render with caustics runs its geometry's render kernel (the render variant): the
    # caustics variant traces the tiny scene's photons and renders nothing, so two workers
    # of ``whitted warm`` never compile the general render kernel at once
    import importlib

    from whitted.render.variants import warm_variant

    photon_map = importlib.import_module("whitted.compile.photon_map")
    api = importlib.import_module("whitted.render.api")

    traced = []

    def photon_lights(compiled, params, settings):
        traced.append((compiled.geometry.inst_box.dtype, compiled.geometry.unbounded.dtype,
                       settings.photons))

    class NoRender:
        def __init__(self, *args, **kwargs):
            raise AssertionError("the caustics variant rendered")

    monkeypatch.setattr(photon_map, "photon_lights", photon_lights)
    monkeypatch.setattr(api, "RenderJob", NoRender)
    assert warm_variant("general/caustics") >= 0
    assert warm_variant("plain/caustics") >= 0
    assert traced == [(np.float64, np.dtype(EXTRAS_DTYPE), 2000),
                      (np.float32, np.int32, 2000)]
    with pytest.raises(AssertionError, match="rendered"):  # the other kinds do render
        warm_variant("plain/render")


def test_a_variant_already_in_the_cache_loads(tmp_path):
    result = _whitted("warm", "--variant", "plain/render")
    assert result.returncode == 0, result.stderr
    entry = json.loads(result.stdout.strip().splitlines()[-1])
    assert entry["name"] == "plain/render" and entry["seconds"] >= 0


@pytest.mark.parametrize("args, message", [
    (["--jobs", "-1"], "--jobs: must be 0"),
    (["--jobs", "5000"], "--jobs: must be 0"),
    (["--variant", "nope/render"], "unknown variant 'nope/render'"),
])
def test_mistakes_are_one_line(args, message):
    result = _whitted("warm", *args)
    assert result.returncode == 2
    assert result.stderr.strip().count("\n") == 0 and message in result.stderr


def test_the_queue_hands_a_general_kind_out_only_after_the_general_render_kernel():
    from whitted.cli.warm import _all_names, _Queue

    queue = _Queue(_all_names(), done=("plain/render",))
    assert queue.take() == "general/render"  # the longest chain first
    assert queue.take() == "stefan"
    # the photon tracer shares no kernel with the render kernel: it starts at once
    assert queue.take() == "general/caustics"
    taken = []
    while True:  # what another worker gets meanwhile: never a general kind
        name = queue.todo and next((n for n in queue.todo if not n.startswith("general/")),
                                   None)
        if not name:
            break
        assert queue.take() == name
        taken.append(name)
    assert sorted(taken) == ["builders", "plain/aovs", "plain/caustics"]
    assert queue.todo == ["general/aovs"]
    queue.finish("general/render", 12.5)
    assert queue.take() == "general/aovs"


def test_the_longest_compiles_are_handed_out_first():
    # longest first: the Stefan solver (about half a minute) is handed out before the short
    # variants, so that with two workers the last to finish is a short one
    from whitted.cli.warm import _all_names, _Queue

    queue = _Queue(_all_names(), done=("plain/render",))
    order = [queue.take() for _ in range(6)]
    assert order == ["general/render", "stefan", "general/caustics", "builders",
                     "plain/caustics", "plain/aovs"]


def test_two_workers_finish_within_a_short_variant_of_each_other():
    # a model, not a measurement: the queue's order played out over the costs it is built
    # from (each worker takes the first variant ready when it is free); the two workers end
    # less than the builders' compile apart, and within one short variant of half the work
    from whitted.cli.warm import _COST, _all_names, _first, _order

    todo = _order(_all_names())
    done_at = {"plain/render": 0.0}
    free = [0.0, 0.0]
    while todo:
        worker = free.index(min(free))
        ready = [n for n in todo
                 if _first(n) is None or done_at.get(_first(n), math.inf) <= free[worker]]
        if not ready:  # what is left waits for a variant still compiling
            free[worker] = min(done_at[_first(n)] for n in todo)
            continue
        todo.remove(ready[0])
        free[worker] += _COST[ready[0]]
        done_at[ready[0]] = free[worker]
    assert abs(free[0] - free[1]) < _COST["builders"]
    assert max(free) < sum(_COST.values()) / 2 + _COST["general/aovs"]


def test_no_variant_is_adaptive_anti_aliasing():
    # adaptive anti-aliasing is a run-time choice of the render kernel: its geometry's
    # ``render`` variant serves it, no kind of its own is compiled
    from whitted.cli.warm import _all_names

    assert _all_names() == ["plain/caustics", "plain/aovs", "general/render",
                            "general/caustics", "general/aovs", "builders", "stefan"]
    assert KINDS == ("render", "caustics", "aovs")


def test_a_failed_general_render_kernel_fails_its_kinds_without_compiling_them():
    from whitted.cli.warm import _Queue

    queue = _Queue(["general/render", "general/aovs", "plain/aovs"], done=("plain/render",))
    assert queue.take() == "general/render"
    assert queue.take() == "plain/aovs"
    queue.finish("general/render", None, "boom")
    assert queue.take() is None
    assert queue.failed == {"general/render", "general/aovs"} and queue.errors == ["boom"]


def test_a_worker_answers_each_name_it_reads_with_one_line():
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    result = subprocess.run([sys.executable, "-m", "whitted", "warm", "--serve"],
                            input="plain/render\n\nplain/render\n", capture_output=True,
                            text=True, timeout=900, env=env)
    assert result.returncode == 0, result.stderr
    lines = [json.loads(line) for line in result.stdout.splitlines()]
    assert [entry["name"] for entry in lines] == ["plain/render", "plain/render"]
    assert all(entry["seconds"] >= 0 for entry in lines)


@pytest.mark.parametrize("cached, names, lines", [
    (True, [], ["loading the default scene's kernels (compiled before)"]),
    (False, ["plain/aovs"], ["compiling the default scene's kernels (the first time)",
                             "1 more variant in 1 process, each compiled unless the cache "
                             "has it"]),
])
def test_warm_says_whether_it_compiles_or_loads(tmp_path, monkeypatch, cached, names, lines):
    """What `whitted warm` says before its work: loading kernels compiled before, or
    compiling them (never 'the first time' on a warm cache, nor a count of cores)."""
    import importlib

    from cli_run import run_main
    from whitted.cli import warm

    warm_up = importlib.import_module("whitted.render.warm_up")

    monkeypatch.setattr(warm_up, "kernels_cached", lambda instances=False: cached)
    monkeypatch.setattr(warm_up, "warm_up_kernels", lambda **kwargs: 0.25)
    monkeypatch.setattr(warm, "_all_names", lambda: names)

    # every variant was in the cache
    def work(queue, procs, helper=False, worker=0, processes=1):
        queue.wait_turn(worker)
        while (name := queue.take()) is not None:
            queue.finish(name, 0.5)

    monkeypatch.setattr(warm, "_work", work)
    code, out, err = run_main("warm", cwd=tmp_path)
    assert code == 0, err
    assert err.splitlines() == lines
    assert out.splitlines()[:1 + len(names)] == [f"{'plain/render':28}    0.25 s"] + [
        f"{name:28}    0.50 s" for name in names]
    assert out.splitlines()[-1].startswith("every kernel is in the cache: ")


def test_the_first_worker_starts_once_the_compile_helper_has_finished(monkeypatch, tmp_path):
    """While the default scene's render kernel compiles its own module (one core), the
    compile helper, done with its share, leaves a core idle: the first worker starts then,
    the second once the default scene's kernels are done."""
    from cli_run import run_main
    from whitted.cli import warm
    from whitted.render import api, warm_up

    turns = [threading.Event(), threading.Event()]
    seen_during_compile = []

    def warm_up_kernels(on_helper_end=None):
        seen_during_compile.append([t.is_set() for t in turns])
        on_helper_end()  # the helper's last line
        seen_during_compile.append([turns[0].wait(30), turns[1].is_set()])
        return 0.25

    def work(queue, procs, helper=False, worker=0, processes=1):
        if queue.wait_turn(worker):
            turns[worker].set()
            while (name := queue.take()) is not None:
                queue.finish(name, 0.5)

    monkeypatch.setattr(api, "available_threads", lambda: 2)
    monkeypatch.setattr(warm_up, "kernels_cached", lambda instances=False: False)
    monkeypatch.setattr(warm_up, "warm_up_kernels", warm_up_kernels)
    monkeypatch.setattr(warm, "_work", work)
    code, out, err = run_main("warm", cwd=tmp_path)
    assert code == 0, err
    assert seen_during_compile == [[False, False], [True, False]]
    assert all(t.is_set() for t in turns)
    assert out.splitlines()[-1].startswith("every kernel is in the cache: ")


def test_no_worker_starts_once_the_command_ends(monkeypatch):
    import subprocess

    from whitted.cli import warm

    popens = []
    monkeypatch.setattr(subprocess, "Popen", lambda *args, **kwargs: popens.append(args))
    queue = warm._Queue(["stefan"])
    waiting = threading.Event()
    wait_turn = queue.wait_turn

    def wait_turn_seen(worker):
        with queue._changed:  # set while holding the lock wait_turn takes: it then waits
            waiting.set()
            return wait_turn(worker)

    monkeypatch.setattr(queue, "wait_turn", wait_turn_seen)
    procs: list = []
    outcome = []
    worker = threading.Thread(
        target=lambda: outcome.append(warm._work(queue, procs, False, 0)))
    worker.start()
    assert waiting.wait(30)  # the worker waits for its turn, which never comes
    queue.close()  # Ctrl-C during the default scene's compile
    worker.join(30)
    assert not worker.is_alive() and outcome == [None]  # it ended, without an exception
    assert popens == [] and procs == []
    assert queue.start(0, procs, ["whitted"], {}, None) is None
    assert popens == []


def test_workers_compile_without_a_helper_of_their_own(monkeypatch):
    # the workers keep the cores busy; a helper beside each would compile kernels twice
    import io
    import subprocess

    from whitted.cli import warm

    started = []

    class FakeWorker:
        def __init__(self, args, **kwargs):
            started.append((args, kwargs))
            self.stdin, self.stdout = io.StringIO(), io.StringIO()
            self.returncode = 0

        def poll(self):
            return None

        def wait(self):
            return 0

    monkeypatch.setattr(subprocess, "Popen", FakeWorker)
    monkeypatch.setenv("WHITTED_COMPILE_HELPER", "1")
    queue = warm._Queue([])
    queue.open_to(1)
    warm._work(queue, [], processes=3)
    warm._work(queue, [], helper=True, processes=5)  # a core to spare for one
    (args, kwargs), (_, spare) = started
    assert args[-2:] == ["warm", "--serve"]
    assert kwargs["env"]["WHITTED_COMPILE_HELPER"] == "0"
    assert spare["env"]["WHITTED_COMPILE_HELPER"] == "1"
    assert kwargs["env"]["WHITTED_COMPILE_PROCESSES"] == "3"
    assert spare["env"]["WHITTED_COMPILE_PROCESSES"] == "5"


@pytest.mark.parametrize("jobs, cores, helper", [(2, 2, False), (0, 2, False), (1, 2, True),
                                                 (2, 8, True), (3, 4, False)])
def test_a_worker_gets_a_helper_only_where_there_is_a_core_for_it(monkeypatch, tmp_path, jobs,
                                                                   cores, helper):
    from cli_run import run_main
    from whitted.cli import warm
    from whitted.render import api, warm_up

    monkeypatch.setattr(api, "available_threads", lambda: cores)
    monkeypatch.setattr(warm_up, "kernels_cached", lambda instances=False: True)
    monkeypatch.delenv("WHITTED_COMPILE_PROCESSES", raising=False)
    sharing = []
    # this process (and its compile helper) compiles beside the workers: told too
    monkeypatch.setattr(warm_up, "warm_up_kernels", lambda **kwargs: sharing.append(
        int(os.environ["WHITTED_COMPILE_PROCESSES"])) or 0.25)
    seen = []

    def work(queue, procs, helper=False, worker=0, processes=1):
        seen.append(helper)
        sharing.append(processes)
        queue.wait_turn(worker)
        while (name := queue.take()) is not None:
            queue.finish(name, 0.5)

    monkeypatch.setattr(warm, "_work", work)
    code, _, err = run_main("warm", "--jobs", str(jobs), cwd=tmp_path)
    assert code == 0, err
    assert seen and set(seen) == {helper}
    # the processes compiling side by side, that share the memory budget of what their
    # compiles leave (jit/collector.py): this one, the workers and their helpers
    workers = min(jobs or cores, len(seen))
    assert set(sharing) == {1 + workers * (2 if helper else 1)}
    assert "WHITTED_COMPILE_PROCESSES" not in os.environ  # for the command's time only


@pytest.mark.parametrize("signum, code, word", [(signal.SIGINT, 130, "interrupted"),
                                                (signal.SIGTERM, 143, "terminated")])
def test_a_signal_after_the_first_worker_started_early_kills_it(monkeypatch, tmp_path, signum,
                                                                code, word):
    """Ctrl-C (or SIGTERM) while the default scene's render kernel still compiles, its helper
    done and the first worker already started beside it: that worker is killed, no other
    starts, and nothing is said to be in the cache."""
    import subprocess

    from cli_run import run_main
    from whitted.render import api, warm_up

    started, killed = [], []

    class BusyWorker:  # a worker process compiling its first variant, until killed
        returncode = -9

        def __init__(self, args, **kwargs):
            started.append(self)
            self.stdin = self
            self.stdout = self
            self.ended = threading.Event()

        def write(self, text):
            pass

        def flush(self):
            pass

        def readline(self):
            self.ended.wait(30)  # compiling until killed: then no answer
            return ""

        def close(self):
            pass

        def poll(self):
            return -9 if self in killed else None

        def kill(self):
            if self not in killed:  # its feeding thread may kill it again as it ends
                killed.append(self)
            self.ended.set()

        def wait(self, timeout=None):
            return -9

    worker_started = threading.Event()
    popen = BusyWorker

    def starts_and_tells(*args, **kwargs):
        proc = popen(*args, **kwargs)
        worker_started.set()
        return proc

    def warm_up_kernels(on_helper_end=None):
        on_helper_end()  # the helper's last line
        assert worker_started.wait(30)  # the first worker is compiling
        os.kill(os.getpid(), signum)  # then the signal, during the render kernel's module
        threading.Event().wait(30)
        return 0.25

    monkeypatch.setattr(subprocess, "Popen", starts_and_tells)
    monkeypatch.setattr(api, "available_threads", lambda: 2)
    monkeypatch.setattr(warm_up, "kernels_cached", lambda instances=False: False)
    monkeypatch.setattr(warm_up, "warm_up_kernels", warm_up_kernels)
    status, out, err = run_main("warm", cwd=tmp_path)
    assert status == code
    assert len(started) == 1 and killed == started  # the second never started
    assert err.splitlines()[-1] == (f"{word}: 0 of 8 kinds of kernels were compiled and are "
                                    "kept in the cache; whitted warm again compiles the rest")
    assert "every kernel is in the cache" not in out


@pytest.mark.parametrize("signum, code, word", [(signal.SIGINT, 130, "interrupted"),
                                                (signal.SIGTERM, 143, "terminated")])
def test_a_signal_stops_the_workers_and_keeps_what_was_compiled(monkeypatch, tmp_path, signum,
                                                                code, word):
    """Ctrl-C (or SIGTERM) while the workers compile: they are stopped at once, not left to
    finish their variant, and the one line says what the cache keeps."""
    from cli_run import run_main
    from whitted.cli import warm
    from whitted.render import warm_up

    monkeypatch.setattr(warm_up, "kernels_cached", lambda instances=False: True)
    monkeypatch.setattr(warm_up, "warm_up_kernels", lambda **kwargs: 0.25)
    killed = []

    class BusyWorker:  # a worker process still compiling
        def poll(self):
            return None if not killed else -9

        def kill(self):
            killed.append(True)

        def wait(self):
            return -9

    def work(queue, procs, helper=False, worker=0, processes=1):
        queue.wait_turn(worker)
        procs.append(BusyWorker())
        name = queue.take()
        queue.finish(name, 0.5)  # one variant done, then the signal during the next
        queue.take()
        os.kill(os.getpid(), signum)
        threading.Event().wait(30)  # compiling (a daemon thread, left behind)

    monkeypatch.setattr(warm, "_work", work)
    status, out, err = run_main("warm", "--jobs", "1", cwd=tmp_path)
    assert status == code
    assert killed == [True]
    assert err.splitlines()[-1] == (f"{word}: 2 of 8 kinds of kernels were compiled and are "
                                    "kept in the cache; whitted warm again compiles the rest")
    assert "every kernel is in the cache" not in out


def test_ctrl_c_during_the_first_compile_leaves_no_process_behind(tmp_path):
    """A real ``whitted warm`` on an empty cache, interrupted while it compiles the default
    scene's kernels (its compile helper running beside it): status 130, one line, and the
    helper gone with it (stopped by it, or, where the signal came while it was being started,
    by its own watchdog a moment later)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), WHITTED_CACHE_DIR=str(tmp_path))
    proc = subprocess.Popen([sys.executable, "-m", "whitted", "warm"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stderr is not None
    first = proc.stderr.readline()  # said once the compile begins
    assert "compiling the default scene's kernels" in first

    def helpers() -> list[str]:  # the compile helper names its parent's pid
        found = subprocess.run(["pgrep", "-f", f"whitted.render.warm_up .* {proc.pid}$"],
                               capture_output=True, text=True)
        return found.stdout.split()

    while not helpers():  # until the helper has started (it does before the first kernel)
        assert proc.poll() is None, "the compile ended without its helper"
    (helper,) = helpers()
    proc.send_signal(signal.SIGINT)
    out, rest = proc.communicate(timeout=120)
    assert proc.returncode == 130, rest
    assert rest.strip().splitlines() == [
        "interrupted: 0 of 8 kinds of kernels were compiled and are kept in the cache; "
        "whitted warm again compiles the rest"]
    try:  # the helper's end, waited for as an event (a Linux pidfd), not a time
        ended = os.pidfd_open(int(helper))
    except ProcessLookupError:
        return  # gone already
    poller = select.poll()
    poller.register(ended, select.POLLIN)
    try:
        assert poller.poll(60_000), "the compile helper outlived whitted warm"
    finally:
        os.close(ended)


def test_the_workers_are_given_up_once_a_signal_was_seen(monkeypatch):
    # a KeyboardInterrupt that landed in a finaliser is only printed there: the wait for the
    # workers looks at the guard's flag too
    from whitted.cli import warm

    started = threading.Event()

    def work(queue, procs, helper=False, worker=0, processes=1):
        started.set()
        threading.Event().wait(30)  # compiling (a daemon thread, left behind)

    monkeypatch.setattr(warm, "_work", work)
    with pytest.raises(KeyboardInterrupt):
        threads = warm._start_workers(warm._Queue(["stefan"]), [], 1, 2)
        warm._wait_workers(threads, stop=started.is_set)
