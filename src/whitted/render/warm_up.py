"""Getting the kernels ready before a render: loaded from the on-disk cache (every run after
the first), or compiled (the first run, or after the kernels changed).

Numba compiles one function at a time in a process, so on a cold cache the first compile is
shared with a second process (``python -m whitted.render.warm_up``) when there are two cores
or more. While this process compiles ``render_tiles`` (and its callees on the way, depth
first), the helper compiles a share of the render kernel's callees (``kernels/callees.py``),
then the light-buffer kernels, into the cache. When this process reaches one of the helper's
callees it waits for it (``KernelCache.wait_for_helper``, jit/dispatcher.py) and loads it
instead of compiling it a second time (with stock Numba, which has neither the twins nor the
wait, the helper compiles only the light buffers). Then it waits for the helper and loads
what it made. Whatever the helper did not finish is compiled here, so the result never
depends on the helper: it only saves time. The AOV kernel (depth, normal and object-id
images) is compiled when first used.

The scene builders and the OBJ reader are not part of a cold compile: on a small scene (the
default one) they run as Python until they are compiled (jit/python_twins.py), which
``whitted warm`` does, and so does the first scene too large for that
(:func:`~whitted.compile.scene.scene_needs_builders`): its helper compiles them after the
light buffers.

``whitted render`` starts the helper earlier (:func:`start_cold_compile_ahead`), before its
output checks, which read the scene's models.

A marker file in the cache folder (``whitted-ready-plain`` / ``whitted-ready-general``)
records that a variant is complete there, so a warm start starts no helper.

While a cold compile runs, :func:`compile_progress` says how far along it is (functions
compiled here and in the helper, against the count a full compile of the variant takes,
``EXPECTED_COMPILES``): the CLI shows it in its progress bar. Stopping is immediate: an
exception in the compile (Ctrl-C's ``KeyboardInterrupt`` in the main thread) stops the helper
instead of waiting for it, and a helper whose parent has gone ends itself.

Measured on the 2-core VM (fresh cache, the default scene's ``whitted render``): see
docs/performance.md.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..assets.mesh import load_obj_bytes
from ..compile.params import render_params
from ..compile.scene import (
    CompiledScene,
    compile_scene,
    scene_needs_builders,
    scene_needs_general_kernels,
)
from ..jit.cache import HELPER_ENV, prepare
from ..jit.progress import CompileReport
from ..jit.python_twins import builders_cached, mark_builders_cached
from ..jit.python_twins import compiled as compiled_builders
from ..kernels.features import EXTRAS_DTYPE
from ..kernels.layout import N_RAY_KINDS
from ..scene.lights import PointLight
from ..scene.scene import Scene
from ..scene.shapes import Mesh, Sphere

_lock = threading.Lock()
#: render kernel variants loaded here: (with mesh instances, with tori or CSG objects)
_ready: set[tuple[bool, bool]] = set()
_builders_ready = False
HELPER_WAIT_SECONDS = 120.0  # a helper still busy after this is stopped (never expected)
#: functions Numba compiles in a cold compile of each variant, this process and the helper
#: together (counted on the 2-core VM, an empty cache folder: 161 for the plain variant in one
#: process, a few more with the helper; 46 + 100 for the general one once the plain one is
#: cached, as a first render of a large scene or one with mesh instances compiles the plain
#: variant first; each kernel other kernels call counts once, as its twin). Only the progress
#: shown depends on it: a count that drifted
#: (kernels changed, a different split between the processes) makes the fraction
#: approximate; tests/test_warm_up.py holds the plain one to a real cold compile within 10 %.
EXPECTED_COMPILES = {False: 165, True: 146}
#: the same for the general variant compiled first, on a cache without the plain one (a
#: first render of a scene with a torus or a CSG object: :func:`first_variant`), whose
#: leaves it then compiles too: 107 + 160 on the 2-core VM
EXPECTED_GENERAL_ALONE_COMPILES = 267
#: the builders' and the OBJ reader's compiles, added where a cold compile makes them too
EXPECTED_BUILDER_COMPILES = 39
TINY_OBJ = b"""v 0.12345678901234567890 0 0
v 1 0 0
v 0 1 0
vt 0 0
vt 1 0
vt 0 1
vn 0 0 1
f 1/1/1 2/2/1 3/3/1
"""


def kernel_variant(compiled: CompiledScene) -> bool:
    """True for the general variant of the kernels (scenes with mesh instances, tori or CSG
    objects: kernels/features.py), False for the plain one."""
    return compiled.geometry.inst_box.dtype == np.float64


def _loaded_key(compiled: CompiledScene | None) -> tuple[bool, bool]:
    """Which render kernel a scene like ``compiled`` runs: (with mesh instances possible,
    with tori or CSG objects possible): (False, False) plain, (True, True) general. Each is
    its own specialisation, loaded (or compiled) by the warm-up, not by the render's first
    call, whose time would then include it."""
    if compiled is None:
        return False, False
    return kernel_variant(compiled), compiled.geometry.unbounded.dtype == np.dtype(EXTRAS_DTYPE)


def stand_in_scene(instances: bool) -> CompiledScene:
    """Arrays with no geometry but the types of a compiled scene of the given variant (True:
    the general one): enough to compile the render kernels without running any builder."""
    compiled = compile_scene(Scene())
    if instances:
        geometry = compiled.geometry._replace(
            inst_box=compiled.geometry.inst_box.astype(np.float64),
            unbounded=compiled.geometry.unbounded.astype(EXTRAS_DTYPE))
        compiled = dataclasses.replace(compiled, geometry=geometry)
    return compiled


def _builders_scene() -> Scene:
    # a bounded shape, a point light and a smooth mesh: the BVH, light-buffer and normal
    # builders run
    mesh = Mesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
                faces=[[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]], smooth=True)
    return Scene(objects=[Sphere(radius=1.0), mesh],
                 lights=[PointLight(position=(0, 5, 0))])


def compile_builders() -> None:
    """The kernels that load models and build a scene's arrays, compiled whatever the size
    of their inputs (small ones otherwise run as Python until this has run:
    jit/python_twins.py), and marked as compiled in the cache folder."""
    global _builders_ready
    if not _builders_ready:
        scene = _builders_scene()
        with compiled_builders():
            compile_scene(scene)  # the mesh flattened into the scene BVH
            compile_scene(scene, flatten_limit=0)  # the mesh instanced
            load_obj_bytes(TINY_OBJ, "warm-up.obj", Path("."))
        if os.environ.get(HELPER_ENV) != "1":  # the helper's files are sealed, and the
            mark_builders_cached()  # marker written, by the process that started it
        _builders_ready = True


def _compile_light_buffers(instances: bool = False) -> None:
    """The light-buffer kernels a scene with a point light runs (fast-math kernels that have
    no Python twin), for the variant's arrays (``instances``: a scene with a mesh instance,
    whose buffers list instance leaves too): what the helper compiles after its share of the
    render kernel."""
    if instances:
        compile_scene(_builders_scene(), flatten_limit=0)
    else:
        compile_scene(Scene(objects=[Sphere(radius=1.0)],
                            lights=[PointLight(position=(0, 5, 0))]))


def _stand_in_params(compiled: CompiledScene):
    scene = _builders_scene()
    return render_params(scene, compiled, scene.render.model_copy(update={"width": 1,
                                                                          "height": 1}))


def _compile_render_kernels(compiled: CompiledScene, aovs: bool = False) -> None:
    from ..kernels.tiles import adaptive_workspace, lane_workspace, render_aovs, render_tiles

    params = _stand_in_params(compiled)
    fb = np.zeros((1, 1, 3), np.float32)
    counters = np.zeros((1, N_RAY_KINDS), np.int64)
    no_tiles = np.zeros((0, 4), np.int32)  # compiles (or loads) without rendering
    render_tiles(no_tiles, fb, compiled.geometry, compiled.materials, compiled.lights,
                 params, counters, lane_workspace(params.max_depth), adaptive_workspace(), 0.0,
                 -1, 0, 1)
    if not aovs:
        return
    render_aovs(compiled.geometry, params._replace(height=0), np.zeros((1, 1), np.float32),
                np.zeros((1, 1, 3), np.float32), np.zeros((1, 1), np.int32),
                lane_workspace(0), 0, 1)


def _marker(instances: bool) -> Path | None:
    folder = prepare().folder
    if folder is None:
        return None
    return Path(folder) / ("whitted-ready-general" if instances else "whitted-ready-plain")


def kernels_cached(instances: bool = False) -> bool:
    """Whether the render kernels of the variant are complete in the kernel cache (a render
    loads them in a fraction of a second instead of compiling them)."""
    marker = _marker(instances)
    return marker is not None and marker.exists()


def _mark(marker: Path | None) -> None:
    """Record a complete variant (nothing where the folder cannot take it)."""
    if marker is not None:
        with contextlib.suppress(OSError):
            marker.touch()


class _CompileCount:
    """Functions compiled so far in this process (Numba's ``numba:compile`` events) and in
    the helper (one line ``.`` on its stdout per function), while a cold compile runs; and
    the helper's share of the render kernel's callees (a line ``done <name>`` as each is in
    the cache), which this process waits for instead of compiling them too."""

    def __init__(self, expected: int, delegated: tuple[str, ...] = (),
                 on_helper_end: Callable[[], None] | None = None) -> None:
        self.expected = expected
        self.on_helper_end = on_helper_end
        self.here = 0
        self.helper = 0
        self.pending = set(delegated)  # the helper's callees it has not finished
        self.helper_gone = False
        self._changed = threading.Condition()
        self.interrupted = False  # Ctrl-C seen (see _interrupt_at_safe_points)

    def check_interrupt(self) -> None:
        """Raise Ctrl-C's KeyboardInterrupt again, here, if it was raised where Python
        ignores exceptions (in an llvmlite object's ``__del__``, between two compiles)."""
        if self.interrupted:
            raise KeyboardInterrupt

    @property
    def fraction(self) -> float:
        return min(0.99, (self.here + self.helper) / max(1, self.expected))

    def read_helper(self, pipe) -> None:
        for line in pipe:  # on a thread of its own; ends when the helper closes its stdout
            if line.startswith("done "):
                with self._changed:
                    self.pending.discard(line[5:].strip())
                    self._changed.notify_all()
            elif line.strip() == "finished":  # its work is all in the cache
                if self.on_helper_end is not None:
                    self.on_helper_end()
            else:
                self.helper += 1
        with self._changed:
            self.helper_gone = True
            self._changed.notify_all()

    def wait_for_helper(self, name: str) -> bool:
        """Wait while the helper compiles kernel ``name`` (its twin's qualified name); True
        when it has (load it now), False when it is not the helper's or the helper is gone."""
        deadline = time.monotonic() + HELPER_WAIT_SECONDS
        with self._changed:
            if name not in self.pending:
                return False
            while (name in self.pending and not self.helper_gone
                   and time.monotonic() < deadline):
                self._changed.wait(0.1)  # a timeout: Ctrl-C reaches this thread at once
                self.check_interrupt()
            if name in self.pending and not self.helper_gone:  # a helper this slow is
                self.helper_gone = True  # taken for hung: no later kernel waits for it
            return name not in self.pending


class _CountCompiles:
    """A Numba event listener adding one to ``count.here`` per function compiled."""

    def __init__(self, count: _CompileCount) -> None:
        from numba.core import event

        class Listener(event.Listener):
            def on_start(self, ev) -> None:
                count.check_interrupt()

            def on_end(self, ev) -> None:
                count.here += 1
                count.check_interrupt()

        self._event = event
        self._listener = Listener()

    def __enter__(self):
        self._event.register("numba:compile", self._listener)
        return self

    def __exit__(self, *exc) -> None:
        self._event.unregister("numba:compile", self._listener)


_progress: _CompileCount | None = None
_label = "the kernels"


def compile_progress() -> float | None:
    """How far along the first (cold) compile of the kernels is, 0..1; None when no compile
    is running (the kernels load from the cache in a fraction of a second)."""
    count = _progress
    return None if count is None else count.fraction


def compile_label() -> str:
    """What the compile :func:`compile_progress` reports is of: "the kernels", or "the
    caustics kernels" (the photon tracer and the render kernel's kind with caustics)."""
    return _label


#: functions Numba compiles the first time a scene with caustics is rendered (the gather,
#: the render kernel's kind with caustics, the photon tracer: its IEEE twin, 124 kernels
#: and 9 overloads of their own, kernels/strict.py), once the plain variant is cached: the
#: 54 counted on the 2-core VM with the fast-math tracer, plus the twin's, less the tracer
#: the plain variant shared. As EXPECTED_COMPILES, it only scales the progress.
EXPECTED_CAUSTICS_COMPILES = 170


@contextlib.contextmanager
def caustics_compile():
    """Around the caustics stage of a render (render/api.py): the photon map and the render
    kernel's kind with caustics are compiled the first time a scene with caustics is
    rendered. From its first compile on, :func:`compile_progress` counts them (and
    :func:`compile_label` names them), so the CLI's bar says it is compiling, as for the
    render kernels; when everything loads from the cache it stays None. Ctrl-C stops it at
    the next compile, as it does a cold compile."""
    global _progress, _label
    from numba.core import event

    from ..jit import load_numba

    load_numba()
    count = _CompileCount(EXPECTED_CAUSTICS_COMPILES)

    class Listener(event.Listener):
        def on_start(self, ev) -> None:
            global _progress, _label
            if _progress is None:
                _label = "the caustics kernels"
                _progress = count
                _report_of(count, "the caustics kernels")  # the first compile: said
            count.check_interrupt()

        def on_end(self, ev) -> None:
            count.here += 1
            count.check_interrupt()

    listener = Listener()
    event.register("numba:compile", listener)
    report = None
    try:
        with _interrupt_at_safe_points(count):
            yield
    except BaseException as exc:
        if _progress is count:
            report = _report_of(count, "the caustics kernels")
            report.__exit__(type(exc), exc, None)
        raise
    else:
        if _progress is count:
            _report_of(count, "the caustics kernels").__exit__(None, None, None)
    finally:
        event.unregister("numba:compile", listener)
        if _progress is count:
            _progress = None
            _label = "the kernels"


def _report_of(count: _CompileCount, label: str) -> CompileReport:
    """The report (jit/progress.py: log records, a bar in the Python API) of a first
    compile, started with it."""
    report = getattr(count, "report", None)
    if report is None:
        report = count.report = CompileReport(label, compile_progress)
        report.__enter__()
    return report


def _start_helper(instances: bool, builders: bool = False) -> subprocess.Popen | None:
    from numba import config

    folder = prepare().folder
    if (config.DISABLE_JIT or os.environ.get("WHITTED_COMPILE_HELPER", "1") == "0"
            or folder is None or prepare().read_only  # it could save nothing there
            or len(os.sched_getaffinity(0)) < 2):
        return None
    # the helper uses this folder (checked here, and locked while it runs)
    env = dict(os.environ, NUMBA_CACHE_DIR=folder, **{HELPER_ENV: "1"})
    try:
        return subprocess.Popen(
            [sys.executable, "-m", "whitted.render.warm_up",
             "instances" if instances else "plain", str(os.getpid())]
            + (["builders"] if builders else []),
            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
            text=True, env=env)
    except OSError:  # no interpreter to start (frozen app, exotic platform): compile alone
        return None


def _finish_helper(helper: subprocess.Popen | None) -> None:
    """Wait for the helper (stopping it if it hangs): its last work, the light buffers (and
    the builders where the scene needs them compiled), is what this process needs next."""
    if helper is None:
        return
    try:
        helper.wait(HELPER_WAIT_SECONDS)
    except subprocess.TimeoutExpired:
        _stop_helper(helper)


def _stop_helper(helper: subprocess.Popen | None) -> None:
    """End the helper now (the compile was interrupted): what it cached so far stays."""
    if helper is not None and helper.poll() is None:
        helper.kill()
        helper.wait()


def warm_up_kernels(compiled: CompiledScene | None = None, builders: bool = False,
                    on_helper_end: Callable[[], None] | None = None) -> float:
    """Compile (first run) or load from the on-disk cache (later runs) the render kernels for
    scenes like ``compiled`` (kernels are specialised for scenes with and without mesh
    instances; without when None); on the first run also the builders and the AOV kernel.
    The render kernel serves uniform samples and adaptive anti-aliasing alike (a run-time
    choice). ``builders``: a cold compile compiles the builders too (a scene too large for
    their Python twins: :func:`scene_needs_builders`). ``on_helper_end``: called once, from
    another thread, when a cold compile's helper has finished its work: from then on this
    process compiles on one core (the render kernel's own module), and the caller may give
    the other core other work. Returns the seconds it took; 0 when all of it was already loaded
    in this process (or nothing had to be)."""
    with _lock:
        key = _loaded_key(compiled)
        if key in _ready:
            return 0.0
        instances = key[0]
        start = time.perf_counter()
        cache = prepare()
        marker = _marker(instances)
        if marker is not None and marker.exists():
            # warm: load the render kernel only; the builders, the model loaders and the AOV
            # kernel load from the cache when first called (a scene without OBJ files never
            # loads the OBJ reader, a plain render never the AOV kernel)
            _compile_render_kernels(compiled if compiled is not None
                                    else stand_in_scene(instances), aovs=False)
        else:
            # a second cold render of the variant waits here, then loads
            with _compile_lock(cache, instances):
                if marker is not None and marker.exists():  # another process compiled it
                    _compile_render_kernels(compiled if compiled is not None
                                            else stand_in_scene(instances), aovs=False)
                else:
                    _cold_compile(instances, compiled, builders, on_helper_end)
                cache.seal()
                _mark(marker)
        if cache.unsealed:
            cache.seal()
        _ready.add(key)
        return time.perf_counter() - start


#: (a variant's compile lock, the helper, whether it is the general variant) started ahead
#: of the cold compile by :func:`start_cold_compile_ahead`, until the compile adopts them
_ahead: tuple[object, subprocess.Popen, bool] | None = None
_ahead_lock = threading.Lock()  # not _lock: a compile holds that until it ends


def start_cold_compile_ahead(builders: bool = False, instances: bool = False) -> bool:
    """On a cold cache, start the compile helper now, before the work a command does ahead
    of its render: ``whitted render``'s output checks read the scene's models, which
    compiles the OBJ reader (3 s of CPU), and the helper compiles its share of the render
    kernel meanwhile instead of starting after it. The compile lock of the variant (the
    plain one, or ``instances``: the general one) is taken without waiting (another process
    compiling it: nothing is started, the render waits for it as before) and held until the
    render's warm-up adopts both (:func:`warm_up_kernels`) or
    :func:`stop_cold_compile_ahead` ends them. True when the helper was started."""
    global _ahead
    with _ahead_lock:
        if (_ahead is not None or (instances, instances) in _ready
                or kernels_cached(instances)):
            return _ahead is not None
        from ..jit import load_numba

        load_numba()
        lock = prepare().take_compile_lock("general" if instances else "plain")
        if lock is None:
            return False
        if kernels_cached(instances):  # finished by another process before the lock was free
            lock.release()
            return False
        helper = _start_helper(instances, builders and not builders_cached())
        if helper is None:
            lock.release()
            return False
        _ahead = (lock, helper, instances)
        return True


def stop_cold_compile_ahead() -> None:
    """End what :func:`start_cold_compile_ahead` started and no compile adopted (the
    command stopped before its render: a user mistake, Ctrl-C): the helper is stopped (what
    it cached stays, unsealed, for the next compile to check) and the lock released."""
    global _ahead
    with _ahead_lock:
        ahead, _ahead = _ahead, None
    if ahead is not None:
        _stop_helper(ahead[1])
        ahead[0].release()


@contextlib.contextmanager
def cold_compile_ahead(scene: Scene | None = None):
    """:func:`start_cold_compile_ahead` for the block (the helper compiles the builders too
    when ``scene`` needs them compiled; the general variant's helper for a scene that runs
    the general kernels first: :func:`first_variant`), :func:`stop_cold_compile_ahead` after
    it (nothing to stop once the block's render has adopted the helper)."""
    builders = scene is not None and scene_needs_builders(scene)
    start_cold_compile_ahead(builders, scene is not None and first_variant(scene, builders))
    try:
        yield
    finally:
        stop_cold_compile_ahead()


def first_variant(scene: Scene, builders: bool) -> bool:
    """The variant a first render of ``scene`` compiles first on a cold cache: the general
    one (True) for a scene that certainly runs it (a torus, a CSG object:
    :func:`~whitted.compile.scene.scene_needs_general_kernels`) and is small enough for the
    builders' Python twins, so that its first picture waits for one variant, not two; else
    the plain one, whose helper also compiles the builders a large scene needs (a large
    scene with tori or CSG compiles its general kernels after, as every scene with mesh
    instances does)."""
    return not builders and scene_needs_general_kernels(scene)


def _take_ahead(instances: bool):
    """The lock and helper started ahead for this variant, or None."""
    global _ahead
    with _ahead_lock:
        if _ahead is None or _ahead[2] != instances:
            return None
        ahead, _ahead = _ahead, None
        return ahead


@contextlib.contextmanager
def _compile_lock(cache, instances: bool):
    """The variant's compile lock: the one taken ahead, or taken now (waiting for another
    process that holds it)."""
    global _ahead
    ahead = _ahead if _ahead is not None and _ahead[2] == instances else None
    if ahead is not None:
        try:
            yield
        finally:
            with _ahead_lock:
                unused = _ahead is ahead  # not adopted: another process had compiled it
                if unused:
                    _ahead = None
            if unused:
                _stop_helper(ahead[1])
            ahead[0].release()
        return
    with cache.compile_lock("general" if instances else "plain"):
        yield


@contextlib.contextmanager
def _interrupt_at_safe_points(count: _CompileCount):
    """While a cold compile runs in the main thread with Python's own Ctrl-C handler: note
    the interrupt too, so that a KeyboardInterrupt that lands in a finaliser (and is only
    printed there) is raised again at the next compile event or wait."""
    if (threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGINT) is not signal.default_int_handler):
        yield
        return

    def on_sigint(signum, frame):
        count.interrupted = True
        signal.default_int_handler(signum, frame)

    signal.signal(signal.SIGINT, on_sigint)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def _delegated(instances: bool, here: bool = False) -> list:
    """The helper's share of the render kernel's callees (``here``: what this process
    compiles first meanwhile): (twin dispatcher, types) pairs; none with stock Numba (no
    twins to compile, nothing to wait for: jit/dispatcher.py)."""
    from ..jit import load_numba
    from ..jit.dispatcher import tuned

    load_numba()
    if not tuned():
        return []
    from ..kernels.callees import callees_here_first, render_callees

    stand_in = stand_in_scene(instances)
    chosen = callees_here_first if here else render_callees
    return [(dispatcher.callee, argument_types) for dispatcher, argument_types
            in chosen(stand_in.geometry, stand_in.materials, stand_in.lights,
                      _stand_in_params(stand_in))]


def _cold_compile(instances: bool, compiled: CompiledScene | None,
                  builders: bool = False,
                  on_helper_end: Callable[[], None] | None = None) -> None:
    """Compile the variant here while the helper compiles its share of the callees, the
    light buffers and (``builders``) the builders, counting both for
    :func:`compile_progress`; on any exception (Ctrl-C) the helper is stopped at once rather
    than waited for."""
    global _progress
    from ..jit import load_numba
    from ..jit.dispatcher import kernel_cache_class

    load_numba()  # Numba, with whitted's settings
    KernelCache = kernel_cache_class()  # noqa: N806 - None with stock Numba
    ahead = _take_ahead(instances)
    builders = builders and not builders_cached()
    helper = ahead[1] if ahead is not None else _start_helper(instances, builders)
    try:  # from here on, any exception (Ctrl-C) stops the helper
        delegated = ()
        if helper is not None and helper.stdout is not None:
            delegated = tuple(d.py_func.__qualname__ for d, _ in _delegated(instances))
        expected = EXPECTED_COMPILES[instances]
        if instances and not kernels_cached(False):
            expected = EXPECTED_GENERAL_ALONE_COMPILES
        count = _CompileCount(expected + EXPECTED_BUILDER_COMPILES * builders, delegated,
                              on_helper_end)
        if helper is not None and helper.stdout is not None:
            threading.Thread(target=count.read_helper, args=(helper.stdout,),
                             name="whitted-compile-helper-output", daemon=True).start()
        if delegated and KernelCache is not None:
            KernelCache.wait_for_helper = count.wait_for_helper
        _progress = count
        label = "the kernels"
        if instances:  # alone (the plain ones not cached: their leaves too) or after them
            label = ("the kernels for instances, tori and CSG"
                     + (" (the first kernels)" if expected == EXPECTED_GENERAL_ALONE_COMPILES
                        else ""))
        report = CompileReport(label, compile_progress)
        with report, _CountCompiles(count), _interrupt_at_safe_points(count):
            if delegated:  # this process's first share, while the helper compiles its own
                for dispatcher, argument_types in _delegated(instances, here=True):
                    dispatcher.compile(argument_types)
            _compile_render_kernels(compiled if compiled is not None
                                    else stand_in_scene(instances))
            if KernelCache is not None:
                KernelCache.wait_for_helper = None
            _finish_helper(helper)
            _compile_light_buffers(instances)  # loaded where the helper compiled them
            if builders:
                compile_builders()
    except BaseException:
        _stop_helper(helper)
        raise
    finally:
        if KernelCache is not None:
            KernelCache.wait_for_helper = None
        _progress = None


def precompile_for_render(instances: bool, builders: bool = False) -> None:
    """The helper's work: its share of the render kernel's callees (a line ``done <name>``
    after each), then the light buffers and (``builders``) the builders, into the on-disk
    cache; then a line ``finished``."""
    for dispatcher, argument_types in _delegated(instances):
        dispatcher.compile(argument_types)
        print("done", dispatcher.py_func.__qualname__, flush=True)
    _compile_light_buffers(instances)
    if builders:
        compile_builders()
    print("finished", flush=True)


def _end_with_parent(parent: int) -> None:
    """The helper's watchdog: end this process when the process that started it has gone
    (killed, or stopped without waiting), instead of compiling for nobody."""
    while True:
        time.sleep(0.2)
        if os.getppid() != parent:
            os._exit(1)


def _helper_main(argv: list[str]) -> None:
    from ..jit.collector import keep_leftovers

    keep_leftovers()  # this process ends with its compiles (jit/collector.py)
    instances = bool(argv) and argv[0] == "instances"
    builders = "builders" in argv[2:]
    if len(argv) > 1:
        threading.Thread(target=_end_with_parent, args=(int(argv[1]),), daemon=True).start()

    class Report:  # one line per function compiled: the parent counts them for its progress
        def __enter__(self):
            from numba.core import event

            class Listener(event.Listener):
                def on_start(self, ev) -> None:
                    pass

                def on_end(self, ev) -> None:
                    print(".", flush=True)

            self.listener = Listener()
            event.register("numba:compile", self.listener)

        def __exit__(self, *exc) -> None:
            from numba.core import event

            event.unregister("numba:compile", self.listener)

    try:
        with Report():
            precompile_for_render(instances, builders)
    except BrokenPipeError:  # the parent stopped reading: it has gone
        os._exit(1)


if __name__ == "__main__":
    _helper_main(sys.argv[1:])
