"""``whitted warm``: every kernel a command can reach compiled into the per-user kernel cache
ahead of use (``make demo`` runs it), so no later render, film or Stefan run stops for a first
compile.

The default scene's kernels (with the scene builders and the OBJ reader) come first, in this
process and its compile helper (both cores); then the other variants (render/variants.py) and
the Stefan solver's kernels are shared among ``--jobs`` processes (one per core), each
compiling its share into the same cache (jit/cache.py keeps them consistent). A variant
already in the cache loads in a fraction of a second, so a second ``whitted warm`` is quick.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from typing import Annotated

import typer

from .app import app, fail
from .console import err, out

STEFAN = "stefan"


def _all_names() -> list[str]:
    from ..render.variants import variant_names

    return [n for n in variant_names() if n != "plain/render"] + [STEFAN]


def _warm_here(names: list[str]) -> None:
    """Warm ``names`` in this process, one JSON line per name on stdout."""
    from ..render.variants import warm_variant

    for name in names:
        if name == STEFAN:
            from ..stefan.warm import warm_stefan_kernels

            seconds = warm_stefan_kernels()
        else:
            seconds = warm_variant(name)
        print(json.dumps({"name": name, "seconds": seconds}), flush=True)


@app.command()
def warm(
    jobs: Annotated[int, typer.Option(
        "--jobs", "-j", help="Processes compiling at once (0: one per core)")] = 0,
    variants: Annotated[list[str] | None, typer.Option(
        "--variant", hidden=True, help="Only these (a process of the command's own)")] = None,
) -> None:
    """Compile every kernel variant (CSG and tori, mesh instances, caustics, adaptive
    anti-aliasing, AOVs, the Stefan solver, the OBJ reader) into the kernel cache, so that
    no later command waits for a first compile."""
    if variants:
        known = set(_all_names()) | {"plain/render"}
        unknown = [v for v in variants if v not in known]
        if unknown:
            raise fail(f"--variant: unknown variant {unknown[0]!r}")
        _warm_here(variants)
        return
    from ..render.api import available_threads
    from ..render.warm_up import warm_up_kernels

    if jobs < 0 or jobs > 1024:
        raise fail(f"--jobs: must be 0 (one per core) to 1024 (got {jobs})")
    jobs = jobs or available_threads()
    start = time.perf_counter()
    err.line("compiling the default scene's kernels (the first time: both cores)")
    times = {"plain/render": warm_up_kernels()}
    names = _all_names()
    shares = [names[i::jobs] for i in range(min(jobs, len(names)))]
    err.line(f"compiling {len(names)} more variants in {len(shares)} process"
             f"{'es' * (len(shares) > 1)}")
    procs = [subprocess.Popen(
        [sys.executable, "-m", "whitted", "warm", *sum((["--variant", n] for n in share), [])],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for share in shares]
    failed = []
    try:
        for proc in procs:
            stdout, stderr = proc.communicate()
            for line in stdout.splitlines():
                try:
                    entry = json.loads(line)
                except ValueError:
                    continue
                times[entry["name"]] = entry["seconds"]
            if proc.returncode != 0:
                failed.append(stderr.strip().splitlines()[-1] if stderr.strip() else
                              f"exit status {proc.returncode}")
    finally:
        for proc in procs:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    for name in ["plain/render", *names]:
        if name in times:
            out.line(f"{name:28} {times[name]:7.2f} s")
    total = time.perf_counter() - start
    if failed:
        raise fail(f"a compile failed: {failed[0]}")
    out.line(f"every kernel is in the cache: {total:.1f} s")
