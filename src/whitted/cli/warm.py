"""``whitted warm``: every kernel a command can reach compiled into the per-user kernel cache
ahead of use (``make demo`` runs it), so no later render, film or Stefan run stops for a first
compile.

The default scene's kernels come first, in this process and its compile helper (both
cores). The other variants (render/variants.py), the scene builders with the OBJ reader
(which a small scene runs as Python until they are compiled: jit/python_twins.py) and the
Stefan solver's kernels are handed out, one at a time and the longest first, to ``--jobs``
worker processes (one per core), each compiling into the same cache (jit/cache.py keeps it
consistent): the first as soon as the compile helper has finished (this process then
compiles the default render kernel's own module, on one core), the others once the default
scene's kernels are done. A worker compiles without a helper process of its own
(render/warm_up.py) unless there are cores for both: the workers already keep the cores busy,
and a helper beside them compiled some kernels in both processes (measured: the same CPU,
the last worker done 2-3 s later). A kind that shares its
geometry's render kernel's callees (the AOV kernel) is handed out only once that render
kernel is in the cache: it then loads them instead of compiling them a second
time in another process. Adaptive anti-aliasing is a run-time choice of the render kernel:
the ``render`` variants serve it. The photon tracers (the caustics variants: the tracer
only, the render with caustics is the render kernel's) share nothing with the render kernels
and start at once. A variant already in the cache loads in a fraction of a second, so a
second ``whitted warm`` is quick. Ctrl-C or SIGTERM stops every compile at once, the workers'
and the compile helper's too (exit 130 or 143, one line): what was compiled stays in the
cache, and the next ``whitted warm`` compiles the rest.
"""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from typing import Annotated

import typer

from .app import app, fail
from .console import err, out
from .interrupt import InterruptGuard

STEFAN = "stefan"
BUILDERS = "builders"


def _all_names() -> list[str]:
    from ..render.variants import variant_names

    return [n for n in variant_names() if n != "plain/render"] + [BUILDERS, STEFAN]


def _first(name: str) -> str | None:
    """The variant that must be in the cache before ``name`` is compiled: the render kernel
    of its geometry, whose callees it shares (plain/render is compiled before any; the
    photon tracer of the caustics variants shares none)."""
    geometry, _, kind = name.partition("/")
    if name in (STEFAN, BUILDERS) or kind in ("render", "caustics"):
        return None
    return f"{geometry}/render"


# What each variant's compile costs, in seconds of one core of a 2-core machine from an empty
# cache (plain/render in it), as `whitted warm` measured them side by side: only the order
# matters, so the longest are handed out first and the short ones fill in around them.
_COST = {"general/render": 41.0, "general/caustics": 23.0, STEFAN: 26.0, BUILDERS: 6.0,
         "plain/caustics": 4.3, "general/aovs": 1.7, "plain/aovs": 0.8}


def _order(names: list[str]) -> list[str]:
    """The order variants are handed out in: longest first (a variant whose cost is not
    known counts as a long one), so that the last to finish is a short one and the cores
    end together."""
    return sorted(names, key=lambda name: (-_COST.get(name, 60.0), name))


def _warm_one(name: str) -> float:
    if name == STEFAN:
        from ..stefan.warm import warm_stefan_kernels

        return warm_stefan_kernels()
    if name == BUILDERS:
        from ..render.warm_up import compile_builders

        start = time.perf_counter()
        compile_builders()
        return time.perf_counter() - start
    from ..render.variants import warm_variant

    return warm_variant(name)


def _warm_here(names: list[str]) -> None:
    """Warm ``names`` in this process, one JSON line per name on stdout."""
    for name in names:
        print(json.dumps({"name": name, "seconds": _warm_one(name)}), flush=True)


def _serve() -> None:
    """A worker of ``whitted warm``: warm each name read from stdin (one a line), answering
    each with its JSON line, until stdin ends."""
    for line in sys.stdin:
        name = line.strip()
        if name:
            print(json.dumps({"name": name, "seconds": _warm_one(name)}), flush=True)


class _Queue:
    """The variants left, handed out in order, each once the variant it needs is done."""

    def __init__(self, names: list[str], done: tuple[str, ...] = ()) -> None:
        self.todo = _order(names)
        self.done: set[str] = set(done)
        self.failed: set[str] = set()
        self.times: dict[str, float] = {}
        self.errors: list[str] = []
        self.open = 0  # workers that may start (the first while the default scene's
        self.closed = False  # render kernel is still compiling: a core of its own)
        self._changed = threading.Condition()

    def open_to(self, workers: int) -> None:
        """Let the first ``workers`` workers start."""
        with self._changed:
            self.open = max(self.open, workers)
            self._changed.notify_all()

    def close(self) -> None:
        """No worker starts any more (the command is ending)."""
        with self._changed:
            self.closed = True
            self._changed.notify_all()

    def wait_turn(self, worker: int) -> bool:
        """Wait until worker number ``worker`` may start: True, or False when the command
        ends first."""
        with self._changed:
            while self.open <= worker and not self.closed:
                self._changed.wait()
            return not self.closed

    def start(self, worker: int, procs: list[subprocess.Popen], command: list[str],
              env: dict, stderr) -> subprocess.Popen | None:
        """Worker ``worker``'s process, started once it may start (None: the command ends
        first); put in ``procs`` under the same lock that :meth:`close` takes, so that the
        command ending kills every worker it started."""
        if not self.wait_turn(worker):
            return None
        with self._changed:
            if self.closed:
                return None
            proc = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                    stderr=stderr, text=True, env=env)
            procs.append(proc)
            return proc

    def take(self) -> str | None:
        """The next variant ready to compile, waiting while every one left waits for another
        in progress; None when none is left (or what is left cannot be done)."""
        with self._changed:
            while self.todo:
                for name in self.todo:
                    first = _first(name)
                    if first in self.failed:  # what it needs failed: it fails with it
                        self.todo.remove(name)
                        self.failed.add(name)
                        break
                    if first is None or first in self.done:
                        self.todo.remove(name)
                        return name
                else:
                    self._changed.wait()
            return None

    def finish(self, name: str, seconds: float | None, error: str = "") -> None:
        with self._changed:
            if seconds is None:
                self.failed.add(name)
                if error:
                    self.errors.append(error)
            else:
                self.done.add(name)
                self.times[name] = seconds
            self._changed.notify_all()


def _work(queue: _Queue, procs: list[subprocess.Popen], helper: bool = False,
          worker: int = 0, processes: int = 1) -> None:
    """Feed worker process number ``worker`` from the queue, once it may start, until nothing
    is left or it fails; ``helper``: whether its compiles may start a compile helper (a core
    of their own for each); ``processes``: how many compile side by side, this one's
    included (each keeps what its compiles leave within its share: jit/collector.py)."""
    from ..jit.collector import PROCESSES_ENV

    # its stderr read only if it fails (a pipe could fill up while nobody reads it)
    with tempfile.TemporaryFile("w+") as stderr:
        env = dict(os.environ, **{PROCESSES_ENV: str(processes)})
        if not helper:  # the other workers are using the other cores (module docstring)
            env["WHITTED_COMPILE_HELPER"] = "0"
        proc = queue.start(worker, procs, [sys.executable, "-m", "whitted", "warm", "--serve"],
                           env, stderr)
        if proc is None:
            return
        assert proc.stdin is not None and proc.stdout is not None
        try:
            while (name := queue.take()) is not None:
                try:
                    proc.stdin.write(name + "\n")
                    proc.stdin.flush()
                except OSError:
                    line = ""
                else:
                    line = proc.stdout.readline()
                try:
                    entry = json.loads(line)
                    queue.finish(name, float(entry["seconds"]))
                except (ValueError, KeyError, TypeError):  # the worker failed on it
                    proc.kill()
                    proc.wait()
                    stderr.seek(0)
                    lines = stderr.read().strip().splitlines()
                    queue.finish(name, None, lines[-1] if lines else
                                 f"{name}: exit status {proc.returncode}")
                    return
        finally:
            if proc.poll() is None:
                proc.stdin.close()
                proc.wait()


def _worker_helpers(workers: int, cores: int) -> bool:
    """Whether each worker's compiles may start a compile helper: only where there is a core
    for it too."""
    return 2 * workers <= cores


def _compiling_processes(workers: int, cores: int) -> int:
    """How many processes compile side by side: this one, the workers and their helpers
    (each keeps what its compiles leave within its share of a budget: jit/collector.py)."""
    return 1 + workers * (2 if _worker_helpers(workers, cores) else 1)


@contextlib.contextmanager
def _sharing(processes: int):
    """This process (and the compile helper it starts) told how many processes compile side
    by side, while the block runs."""
    from ..jit.collector import PROCESSES_ENV

    before = os.environ.get(PROCESSES_ENV)
    os.environ[PROCESSES_ENV] = str(processes)
    try:
        yield
    finally:
        if before is None:
            os.environ.pop(PROCESSES_ENV, None)
        else:
            os.environ[PROCESSES_ENV] = before


def _start_workers(queue: _Queue, procs: list[subprocess.Popen], workers: int,
                   cores: int) -> list[threading.Thread]:
    """The threads that feed ``workers`` worker processes from the queue (their Popen
    objects put in ``procs``), started; each worker process starts once the queue lets it
    (:meth:`_Queue.open_to`)."""
    helper = _worker_helpers(workers, cores)
    processes = _compiling_processes(workers, cores)
    threads = [threading.Thread(target=_work, args=(queue, procs, helper, i, processes),
                                daemon=True, name=f"whitted-warm-{i}") for i in range(workers)]
    for thread in threads:
        thread.start()
    return threads


def _wait_workers(threads: list[threading.Thread], stop=lambda: False) -> None:
    """Wait for the workers' threads; KeyboardInterrupt once ``stop()`` says a signal came
    (its own KeyboardInterrupt may have been swallowed where it landed)."""
    for thread in threads:
        while thread.is_alive():
            if stop():
                raise KeyboardInterrupt
            thread.join(0.2)  # a timeout: Ctrl-C reaches this thread


@app.command()
def warm(
    jobs: Annotated[int, typer.Option(
        "--jobs", "-j", help="Processes compiling at once (0: one per core)")] = 0,
    variants: Annotated[list[str] | None, typer.Option(
        "--variant", hidden=True, help="Only these (a process of the command's own)")] = None,
    serve: Annotated[bool, typer.Option(
        "--serve", hidden=True, help="A worker of the command: names on stdin")] = False,
) -> None:
    """Compile every kernel variant (CSG and tori, mesh instances, caustics, AOVs, the Stefan
    solver, the OBJ reader; adaptive anti-aliasing is part of the render kernel) into the
    kernel cache, so that no later command waits for a first compile."""
    if serve:
        _serve()
        return
    if variants:
        known = set(_all_names()) | {"plain/render"}
        unknown = [v for v in variants if v not in known]
        if unknown:
            raise fail(f"--variant: unknown variant {unknown[0]!r}")
        _warm_here(variants)
        return
    from ..render.api import available_threads
    from ..render.warm_up import kernels_cached, warm_up_kernels

    if jobs < 0 or jobs > 1024:
        raise fail(f"--jobs: must be 0 (one per core) to 1024 (got {jobs})")
    jobs = jobs or available_threads()
    cores = available_threads()
    start = time.perf_counter()
    names = _all_names()
    workers = min(jobs, len(names))
    queue = _Queue(names)
    procs: list[subprocess.Popen] = []
    # Ctrl-C or SIGTERM stops the compiles at once (the workers with it); every kernel
    # compiled so far stays in the cache, whose files are whole or not there (jit/cache.py)
    guard = InterruptGuard(at_once=True)
    try:
        with guard, _sharing(_compiling_processes(workers, cores)):
            err.echo("loading the default scene's kernels (compiled before)" if kernels_cached()
                     else "compiling the default scene's kernels (the first time)")
            threads = _start_workers(queue, procs, workers, cores)
            # once the default scene's compile helper has finished, this process compiles
            # the render kernel's own module on one core: workers start on the others
            early = min(workers, max(1, cores - 1))
            queue.finish("plain/render", warm_up_kernels(
                on_helper_end=lambda: queue.open_to(early)))
            if names:
                err.echo(f"{len(names)} more variant{'s' * (len(names) > 1)} in {workers} "
                         f"process{'es' * (workers > 1)}, "
                         "each compiled unless the cache has it")
            queue.open_to(workers)
            _wait_workers(threads, guard.is_set)
    except KeyboardInterrupt:
        done = len(queue.times)
        raise guard.exit(f"{done} of {len(names) + 1} kinds of kernels were compiled and are "
                         "kept in the cache; whitted warm again compiles the rest") from None
    finally:
        queue.close()  # no worker starts after this: every one started is in procs
        for proc in list(procs):
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    for name in ["plain/render", *names]:
        if name in queue.times:
            out.echo(f"{name:28} {queue.times[name]:7.2f} s")
    total = time.perf_counter() - start
    if queue.failed:
        reason = queue.errors[0] if queue.errors else sorted(queue.failed)[0]
        raise fail(f"a compile failed: {reason}")
    out.echo(f"every kernel is in the cache: {total:.1f} s")
