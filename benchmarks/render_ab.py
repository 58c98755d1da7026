"""Render time of two builds of the kernels side by side: processes A and B alternate
(A B A B ...), each renders a bench scene once untimed (loading or compiling its kernels)
then ``--runs`` times, and the ratio B / A of their best render times is taken pair by pair,
so a machine whose speed drifts weighs on both alike. The float32 framebuffers of A and B
must be bitwise equal (their SHA-256 is compared).

With ``--cpu`` the figure compared is the render's CPU seconds (the process's user + system
time over the render calls, summed over all of the process's threads: the work of the
render, whatever else the machine runs) instead of the render's wall time. With ``--threads``
above 1 it adds the threads' spinning and waiting too: compare CPU at one thread.

A and B differ by environment settings (``--a``, ``--b``: ``NAME=VALUE`` words) and by
``PYTHONPATH`` (two checkouts) or cache folders (``WHITTED_CACHE_DIR``):

    python benchmarks/render_ab.py seed000 7 --a "WHITTED_CACHE_DIR=/tmp/a" \\
        --b "WHITTED_CACHE_DIR=/tmp/b NUMBA_OPT=2"
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import resource
import shlex
import statistics
import subprocess
import sys


def worker(scene_name: str, runs: int, threads: int) -> None:
    from whitted.bench.scenes import load_bench_scene
    from whitted.compile.scene import compile_scene
    from whitted.render.api import RenderJob

    scene = load_bench_scene(scene_name)
    compiled = compile_scene(scene)
    job = RenderJob(scene, compiled=compiled, threads=threads)
    job.run()
    digest = hashlib.sha256(job.framebuffer.tobytes()).hexdigest()
    times, cpu = [], []
    for _ in range(runs):
        job = RenderJob(scene, compiled=compiled, threads=threads)
        before = cpu_seconds()
        job.run()
        cpu.append(cpu_seconds() - before)
        times.append(job.stats.render_seconds)
        if hashlib.sha256(job.framebuffer.tobytes()).hexdigest() != digest:
            raise SystemExit("the image changed between runs")
    print(json.dumps({"render_s": times, "render_cpu_s": cpu, "sha256": digest}))


def cpu_seconds() -> float:
    ru = resource.getrusage(resource.RUSAGE_SELF)
    return ru.ru_utime + ru.ru_stime


def launch(env_words: str, scene: str, runs: int, threads: int) -> dict:
    env = dict(os.environ)
    for word in shlex.split(env_words):
        name, _, value = word.partition("=")
        env[name] = value
    out = subprocess.run([sys.executable, __file__, "--worker", scene, str(runs),
                          "--threads", str(threads)], env=env, capture_output=True, text=True,
                         check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene")
    parser.add_argument("pairs", type=int)
    parser.add_argument("--a", default="", help="A's environment settings")
    parser.add_argument("--b", default="", help="B's environment settings")
    parser.add_argument("--runs", type=int, default=3, help="timed renders in each process")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--cpu", action="store_true",
                        help="compare the renders' CPU seconds, not their wall time")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args.scene, args.pairs, args.threads)
        return
    ratios, best_a, best_b, digests = [], [], [], set()
    figure = "render_cpu_s" if args.cpu else "render_s"
    for _ in range(args.pairs):
        a = launch(args.a, args.scene, args.runs, args.threads)
        b = launch(args.b, args.scene, args.runs, args.threads)
        best_a.append(min(a[figure]))
        best_b.append(min(b[figure]))
        ratios.append(best_b[-1] / best_a[-1])
        digests |= {a["sha256"], b["sha256"]}
    kind = "CPU" if args.cpu else "wall"
    print(f"{args.scene} ({kind}): A {statistics.median(best_a):.3f} s, B "
          f"{statistics.median(best_b):.3f} s (medians of each process's best of {args.runs}); "
          f"B / A pair by pair: median "
          f"{statistics.median(ratios):.3f} ({min(ratios):.3f}-{max(ratios):.3f}), "
          f"{args.pairs} pairs; framebuffers {'identical' if len(digests) == 1 else 'DIFFER'}")


if __name__ == "__main__":
    main()
