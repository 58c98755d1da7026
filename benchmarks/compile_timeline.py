"""A timeline of the default scene's first compile as a user meets it: ``whitted render`` on
an empty cache folder, the process and its compile helper (``python -m
whitted.render.warm_up``) side by side. Which function each process compiles when, how long
the render process waits for the helper (for one of its callees, or at the end), and the
wall and CPU seconds of both.

    PYTHONPATH=src python benchmarks/compile_timeline.py [--runs 1] [--keep DIR]
        [--cache-from DIR] [-- ARGS...]

Each run starts ``python -m whitted render -q -o OUT.png`` (ARGS replace the default
arguments: another scene) with an empty cache folder (or a copy of ``--cache-from``: the
general kernels' first compile on a cache holding the plain ones), and a ``sitecustomize``
module on ``PYTHONPATH`` that both processes import: it records Numba's documented compile
events (``numba.core.event``, ``"numba:compile"``) with the system-wide monotonic clock and
each process's CPU clock, and the moments the render process waits (``wait_for_helper``,
``_finish_helper``) or starts the helper, into one file per process. Nothing of whitted's is
changed. The CPU figure is the render process's and every child's it waited for (the
operating system's accounting).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TRACER = r'''
import atexit, json, os, sys, threading, time

_out = os.environ.get("WHITTED_TIMELINE_DIR")
_rows = []
_pid = os.getpid()
_t = time.monotonic


def _note(kind, name="", depth=0):
    _rows.append((_t(), time.process_time(), kind, name, depth))


def _dump():
    _note("exit")
    role = "helper" if os.environ.get("WHITTED_KERNEL_CACHE_HELPER") else "main"
    if "whitted.render.warm_up" in " ".join(sys.argv) or sys.argv[0].endswith("warm_up.py"):
        role = "helper"
    with open(os.path.join(_out, f"{role}-{_pid}.json"), "w") as f:
        json.dump({"pid": _pid, "argv": sys.argv, "rows": _rows}, f)


def _wrap(module, attr, label):
    fn = getattr(module, attr, None)
    if fn is None or getattr(fn, "_timeline", False):
        return fn is not None

    def wrapped(*a, **k):
        _note("begin", label)
        try:
            return fn(*a, **k)
        finally:
            _note("end", label)

    wrapped._timeline = True
    setattr(module, attr, wrapped)
    return True


def _watch():
    registered = False
    wrapped = set()
    targets = [("whitted.render.warm_up", "_start_helper", "start helper"),
               ("whitted.render.warm_up", "_finish_helper", "wait: helper's end"),
               ("whitted.render.warm_up", "compile_builders", "builders"),
               ("whitted.render.warm_up", "_compile_light_buffers", "light buffers"),
               ("whitted.render.warm_up", "_compile_render_kernels", "render kernels"),
               ("whitted.render.warm_up", "_delegated", "delegated list"),
               ("whitted.render.warm_up", "stand_in_scene", "stand-in scene"),
               ("whitted.render.api", "compile_scene", "scene compiled"),
               ("__main__", "precompile_for_render", "helper's work"),
               ("__main__", "compile_builders", "builders"),
               ("__main__", "_compile_light_buffers", "light buffers")]
    deadline = _t() + 120
    while _t() < deadline:
        if not registered and "numba.core.event" in sys.modules:
            from numba.core import event

            depth = [0]

            class L(event.Listener):
                def on_start(self, ev):
                    f = ev.data["dispatcher"].py_func
                    _note("cstart", f.__module__ + "." + f.__qualname__, depth[0])
                    depth[0] += 1

                def on_end(self, ev):
                    depth[0] -= 1
                    f = ev.data["dispatcher"].py_func
                    _note("cend", f.__module__ + "." + f.__qualname__, depth[0])

            event.register("numba:compile", L())
            registered = True
        wu = sys.modules.get("whitted.render.warm_up")
        if wu is not None and "wait" not in wrapped:
            cc = getattr(wu, "_CompileCount", None)
            if cc is not None:
                fn = cc.wait_for_helper

                def w(self, name, _fn=fn):
                    _note("begin", "wait: " + name)
                    try:
                        return _fn(self, name)
                    finally:
                        _note("end", "wait: " + name)

                cc.wait_for_helper = w
                wrapped.add("wait")
        for mod, attr, label in targets:
            m = sys.modules.get(mod)
            if (mod, attr) not in wrapped and m is not None and _wrap(m, attr, label):
                wrapped.add((mod, attr))
        time.sleep(0.002)


if _out:
    _note("start")
    atexit.register(_dump)
    _os_exit = os._exit

    def _exit_now(code):  # whitted render ends with os._exit: write the log first
        _dump()
        _os_exit(code)

    os._exit = _exit_now
    threading.Thread(target=_watch, daemon=True).start()
'''


def children_cpu() -> float:
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def one_run(args, src: Path, keep: Path | None) -> dict:
    work = Path(tempfile.mkdtemp(prefix="whitted-timeline-"))
    try:
        (work / "tracer").mkdir()
        (work / "tracer" / "sitecustomize.py").write_text(TRACER)
        (work / "log").mkdir()
        if args.cache_from is not None:  # kernels compiled before (the plain variant)
            shutil.copytree(args.cache_from, work / "cache")
        env = dict(os.environ, WHITTED_CACHE_DIR=str(work / "cache"),
                   WHITTED_TIMELINE_DIR=str(work / "log"),
                   PYTHONPATH=os.pathsep.join([str(work / "tracer"), str(src)]))
        command = [sys.executable, "-m", "whitted", "render", *(
            args.args or ["-q", "-o", str(work / "out.png")])]
        cpu0 = children_cpu()
        t0 = time.monotonic()
        proc = subprocess.run(command, env=env, capture_output=True, text=True)
        wall = time.monotonic() - t0
        cpu = children_cpu() - cpu0
        if proc.returncode != 0:
            raise SystemExit(f"whitted render failed ({proc.returncode}):\n{proc.stderr}")
        logs = {}
        for f in (work / "log").glob("*.json"):
            data = json.loads(f.read_text())
            logs[f.name.split("-")[0]] = data
        if keep is not None:
            keep.mkdir(parents=True, exist_ok=True)
            for f in (work / "log").glob("*.json"):
                shutil.copy(f, keep / f"{len(list(keep.iterdir())):03d}-{f.name}")
        return {"wall": wall, "cpu": cpu, "logs": logs, "t0": t0}
    finally:
        shutil.rmtree(work, ignore_errors=True)


def _close(stack: list, label: str, ts: float, cpu: float, t0: float) -> None:
    """Print the span that ``label`` opened last (popped from ``stack``), ended at (ts, cpu)."""
    for i in range(len(stack) - 1, -1, -1):
        if stack[i][2] == label:
            bts, bcpu, _ = stack.pop(i)
            print(f"    {bts - t0:7.2f} {ts - t0:7.2f}  {ts - bts:6.2f} s wall "
                  f"{cpu - bcpu:6.2f} s CPU  {label}")
            return


def summarise(run: dict, detail: bool) -> None:
    t0 = run["t0"]
    print(f"\nprocess: {run['wall']:.2f} s wall, {run['cpu']:.2f} s CPU (both processes)")
    for role in ("main", "helper"):
        log = run["logs"].get(role)
        if log is None:
            print(f"  {role}: no log")
            continue
        rows = log["rows"]
        start, end = rows[0], rows[-1]
        compiles = [r for r in rows if r[2] == "cend"]
        first_c = next((r for r in rows if r[2] == "cstart"), None)
        last_c = compiles[-1] if compiles else None
        print(f"  {role} (pid {log['pid']}): {start[0] - t0:6.2f} .. {end[0] - t0:6.2f} s, "
              f"CPU {end[1]:.2f} s, {len(compiles)} compiles"
              + (f" from {first_c[0] - t0:.2f} to {last_c[0] - t0:.2f} s" if last_c else ""))
        stack = []
        for ts, cpu, kind, name, depth in rows:
            if kind == "begin":
                stack.append((ts, cpu, name))
            elif kind == "end":
                _close(stack, name, ts, cpu, t0)
            elif kind == "cstart" and depth <= (2 if detail else 0):
                stack.append((ts, cpu, "compile " + "  " * depth + name))
            elif kind == "cend" and depth <= (2 if detail else 0):
                _close(stack, "compile " + "  " * depth + name, ts, cpu, t0)
    main, helper = run["logs"].get("main"), run["logs"].get("helper")
    if main and helper:
        names_m = {r[3] for r in main["rows"] if r[2] == "cend"}
        names_h = {r[3] for r in helper["rows"] if r[2] == "cend"}
        both = sorted(names_m & names_h)
        print(f"  compiled in both processes ({len(both)}): {', '.join(both)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=1)
    parser.add_argument("--detail", action="store_true", help="callees two deep too")
    parser.add_argument("--keep", type=Path, help="copy the event logs here")
    parser.add_argument("--src", type=Path, default=Path(__file__).resolve().parents[1] / "src")
    parser.add_argument("--vs", type=Path, help="a second source tree (its src folder): "
                        "runs alternate, this tree's first, and each pair's ratio is printed")
    parser.add_argument("--quiet", action="store_true", help="figures only, no timeline")
    parser.add_argument("--cache-from", type=Path, help="a cache folder each run starts "
                        "with a copy of (e.g. where `whitted warm --variant plain/render` "
                        "ran, to time the general kernels' first compile alone; with --vs, "
                        "where each tree's ran: the folder inside is named by a hash of "
                        "the kernel sources)")
    parser.add_argument("args", nargs="*", help="whitted render's arguments")
    args = parser.parse_args()
    trees = [args.src] + ([args.vs] if args.vs else [])
    figures: dict = {tree: [] for tree in trees}
    for k in range(args.runs):
        for tree in trees:
            run = one_run(args, tree, args.keep)
            figures[tree].append((run["wall"], run["cpu"]))
            print(f"run {k + 1} {tree}: {run['wall']:.2f} s wall, {run['cpu']:.2f} s CPU",
                  flush=True)
            if not args.quiet:
                summarise(run, args.detail)
    for tree in trees:
        walls = sorted(w for w, _ in figures[tree])
        cpus = sorted(c for _, c in figures[tree])
        print(f"{tree}: wall median {statistics.median(walls):.2f} ({walls[0]:.2f}-"
              f"{walls[-1]:.2f}), CPU median {statistics.median(cpus):.2f} ({cpus[0]:.2f}-"
              f"{cpus[-1]:.2f})")
    if args.vs:
        for i, name in ((0, "wall"), (1, "CPU")):
            pairs = zip(figures[args.src], figures[args.vs], strict=True)
            ratios = sorted(a[i] / b[i] for a, b in pairs)
            print(f"{name} A/B pair by pair: median {statistics.median(ratios):.3f} "
                  f"({ratios[0]:.3f}-{ratios[-1]:.3f})")


if __name__ == "__main__":
    main()
