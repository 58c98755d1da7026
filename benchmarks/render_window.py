"""Where a bench render's wall time goes, thread by thread: fresh processes render a bench
scene once, as ``whitted bench`` times it (a ``whitted render`` process: start, read the scene,
build, load the kernels, render, write), and the render's window is taken apart from the
kernel's own accounting of every thread of the process (Linux ``/proc/self/task/*/schedstat``):

- ``on_cpu``: the render threads' time running (all lanes together);
- ``waiting``: their time runnable but waiting for a CPU (other processes, other threads);
- ``blocked``: the rest of the lanes' wall time (sleeping on a lock, the GIL, a page from disk);
- ``others``: CPU time of the process's other threads in the window (Embree's TBB workers,
  helpers);
- minor / major page faults and voluntary / involuntary switches of the process.

On a loaded machine ``waiting`` takes up what the others run; ``on_cpu`` is the work of the
render whatever the load. Threads alternate run by run (1, 2, 1, 2, ...):

    python benchmarks/render_window.py bunny1m --threads 1,2 --runs 5 [--size 640x360]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

CHILD = r"""
import importlib, json, os, resource, runpy, sys, threading, time
api = importlib.import_module("whitted.render.api")


def tasks():
    out = {}
    for t in os.listdir("/proc/self/task"):
        try:
            f = open(f"/proc/self/task/{t}/schedstat").read().split()
        except FileNotFoundError:
            continue
        out[t] = (int(f[0]) / 1e9, int(f[1]) / 1e9)
    return out


run_lanes = api.run_lanes


def timed_lanes(fn, lanes, pool):
    lane_ids = set()

    def lane(k, n):
        lane_ids.add(str(threading.get_native_id()))
        return fn(k, n)

    a, r0, t0 = tasks(), resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
    run_lanes(lane, lanes, pool)
    wall, b, r1 = time.perf_counter() - t0, tasks(), resource.getrusage(resource.RUSAGE_SELF)
    cpu = {k: b[k][0] - a.get(k, (0.0, 0.0))[0] for k in b}
    wait = {k: b[k][1] - a.get(k, (0.0, 0.0))[1] for k in b}
    on = sum(cpu[k] for k in lane_ids)
    waiting = sum(wait[k] for k in lane_ids)
    window = dict(wall=wall, on_cpu=on, waiting=waiting,
                  blocked=max(0.0, lanes * wall - on - waiting),
                  others=sum(v for k, v in cpu.items() if k not in lane_ids),
                  minflt=r1.ru_minflt - r0.ru_minflt, majflt=r1.ru_majflt - r0.ru_majflt,
                  nvcsw=r1.ru_nvcsw - r0.ru_nvcsw, nivcsw=r1.ru_nivcsw - r0.ru_nivcsw)
    with open(os.environ["WHITTED_RENDER_WINDOW"], "w") as out:  # before the command's exit
        out.write(json.dumps(window))


api.run_lanes = timed_lanes
sys.argv = ["whitted", "render", *sys.argv[1:]]
runpy.run_module("whitted", run_name="__main__", alter_sys=True)
"""

FIGURES = ("render_s", "on_cpu", "waiting", "blocked", "others", "minflt", "majflt", "nvcsw",
           "nivcsw")


def cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", help="a bench scene's name (bunny1m, mesh1m, ...)")
    parser.add_argument("--threads", default="1,2", help="thread counts, alternated")
    parser.add_argument("--runs", type=int, default=3, help="processes per thread count")
    parser.add_argument("--size", help="WxH instead of the scene's own image size")
    args = parser.parse_args()
    try:
        threads = [int(t) for t in args.threads.split(",")]
        size = [] if args.size is None else [int(v) for v in args.size.lower().split("x")]
    except ValueError:
        parser.error("--threads takes whole numbers (1,2) and --size WxH (640x360)")
    if args.runs < 1 or any(t < 1 for t in threads) or len(size) not in (0, 2) or \
            any(v < 1 for v in size):
        parser.error("--runs, every thread count and both sides of --size must be at least 1")
    extra = [] if not size else ["--width", str(size[0]), "--height", str(size[1])]
    from whitted.bench.scenes import load_bench_scene
    from whitted.bench.startup import read_marks
    from whitted.marks import ENV as MARKS_ENV

    rows: dict[int, list[dict]] = {t: [] for t in threads}
    with tempfile.TemporaryDirectory(prefix="whitted-render-window-") as tmp:
        scene_file = Path(tmp) / "scene.json"
        load_bench_scene(args.scene).save(scene_file)
        for _ in range(args.runs):
            for t in threads:
                window, marks = Path(tmp) / "window.json", Path(tmp) / "marks.jsonl"
                marks.unlink(missing_ok=True)
                env = dict(os.environ, WHITTED_RENDER_WINDOW=str(window),
                           **{MARKS_ENV: str(marks)})
                subprocess.run([sys.executable, "-c", CHILD, str(scene_file), "-q", "-o",
                                str(Path(tmp) / "out.png"), "--threads", str(t), *extra],
                               capture_output=True, text=True, check=True, env=env)
                row = json.loads(window.read_text())
                row["render_s"] = read_marks(marks)["render:seconds"]
                rows[t].append(row)
    print(f"{args.scene}, {cpu_name()}, {os.cpu_count()} CPUs; medians of {args.runs} "
          "processes (s, counts)")
    print("threads  " + "  ".join(f"{f:>9}" for f in FIGURES))
    for t in threads:
        med = [statistics.median(r[f] for r in rows[t]) for f in FIGURES]
        print(f"{t:>7}  " + "  ".join(f"{v:9.4f}" if isinstance(v, float) and i < 5
                                      else f"{v:9.0f}" for i, v in enumerate(med)))


if __name__ == "__main__":
    main()
