"""Where a cold compile of a scene's render kernel goes: every function Numba compiles, its
inclusive and exclusive compile time (Numba's documented compile events,
``numba.core.event.install_recorder("numba:compile")``), the functions compiled for more than
one signature, and the size of the render kernel's optimised LLVM module.

Run it on an empty cache folder and without the compile helper, so that everything is
compiled in this one process:

    rm -rf /tmp/cp; WHITTED_CACHE_DIR=/tmp/cp WHITTED_COMPILE_HELPER=0 \\
        PYTHONPATH=src python benchmarks/compile_profile.py [SCENE.toml] [--top 25]

The process's CPU seconds (user + system) for the whole compile are printed too. With
Numba's ``NUMBA_LLVM_PASS_TIMINGS=1`` (documented), LLVM's function passes (each function's
own IR) and module passes (its final module, every callee's module linked in and optimised
again) are summed, and the functions whose module passes took longest listed with the size of
their optimised module: how much of the compile is callees optimised once more per level.
"""

from __future__ import annotations

import argparse
import collections
import resource
import time


def cpu_seconds() -> float:
    ru = resource.getrusage(resource.RUSAGE_SELF)
    return ru.ru_utime + ru.ru_stime


def compile_times(buffer) -> list[tuple[str, str, float, float]]:
    """(function, signature, inclusive s, exclusive s) of each compile in a recorder's buffer
    of ``"numba:compile"`` events, in the order the compiles ended. Events nest: a callee is
    compiled inside its caller's compile, and its time is the caller's inclusive time, not
    its exclusive time."""
    stack: list[list] = []
    rows = []
    for ts, ev in buffer:
        if ev.is_start:
            stack.append([ev.data["dispatcher"], ev.data["args"], ts, 0.0])
        else:
            disp, sig, start, children = stack.pop()
            inclusive = ts - start
            rows.append((disp.py_func.__module__ + "." + disp.py_func.__qualname__, str(sig),
                         inclusive, inclusive - children))
            if stack:
                stack[-1][3] += inclusive
    return rows


def llvm_passes(buffer, top: int) -> None:
    """LLVM's pass times per compile (``NUMBA_LLVM_PASS_TIMINGS=1``): function passes and
    module passes, in all and for the ``top`` functions whose module passes took longest."""
    from numba.core import config

    if not config.LLVM_PASS_TIMINGS:
        return
    rows = []
    seen = set()
    for _ts, ev in buffer:
        if ev.is_start:
            continue
        disp = ev.data["dispatcher"]
        for sig, cres in disp.overloads.items():
            if (id(disp), sig) in seen:
                continue
            seen.add((id(disp), sig))
            timings = (cres.metadata or {}).get("llvm_pass_timings")
            if timings is None:
                continue
            function = module = 0.0
            for record in timings:
                secs = record.timings.get_total_time()
                if record.name.startswith("Function passes"):
                    function += secs
                else:
                    module += secs
            name = disp.py_func.__module__ + "." + disp.py_func.__qualname__
            rows.append((module, function, name, disp, sig))
    print(f"\nLLVM passes: function {sum(r[1] for r in rows):.2f} s, module "
          f"{sum(r[0] for r in rows):.2f} s ({len(rows)} compiles)")
    print(f"{'module s':>8} {'function s':>10} {'IR lines':>9}  function")
    for module, function, name, disp, sig in sorted(rows, key=lambda r: -r[0])[:top]:
        lines = disp.inspect_llvm(sig).count("\n")
        print(f"{module:8.2f} {function:10.2f} {lines:9d}  {name}")


def print_compiles(rows, wall: float, cpu: float, top: int, signature_width=None) -> None:
    """The compiles' totals, the ``top`` longest by exclusive time, and the functions
    compiled for more than one signature (each signature cut to ``signature_width``)."""
    by_name = collections.defaultdict(list)
    for name, sig, inc, exc in rows:
        by_name[name].append((sig, inc, exc))
    total_exc = sum(r[3] for r in rows)
    print(f"compiles: {len(rows)} ({len(by_name)} functions); exclusive total {total_exc:.1f} s;"
          f" job {wall:.1f} s wall, {cpu:.1f} s CPU")
    print(f"\n{'exclusive s':>11} {'inclusive s':>11}  function")
    for name, _sig, inc, exc in sorted(rows, key=lambda r: -r[3])[:top]:
        print(f"{exc:11.2f} {inc:11.2f}  {name}")
    dups = {n: v for n, v in by_name.items() if len(v) > 1}
    print(f"\nfunctions compiled for more than one signature: {len(dups)}")
    for name, variants in sorted(dups.items(), key=lambda kv: -sum(v[2] for v in kv[1])):
        print(f"  {name}: {len(variants)} variants, {sum(v[2] for v in variants):.2f} s")
        for sig, _inc, exc in variants:
            print(f"      {exc:6.2f} s  {str(sig)[:signature_width]}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", nargs="?", help="a scene file (default: the default scene)")
    parser.add_argument("--top", type=int, default=25, help="functions listed")
    parser.add_argument("--width", type=int, default=64, help="image width rendered")
    args = parser.parse_args()

    from numba.core import event

    from whitted.render.api import RenderJob
    from whitted.scene.default import default_scene
    from whitted.scene.io import load_scene

    scene = load_scene(args.scene) if args.scene else default_scene()
    scene = scene.model_copy(update={"render": scene.render.model_copy(
        update={"width": args.width, "height": args.width})})
    cpu0 = cpu_seconds()
    wall0 = time.perf_counter()
    with event.install_recorder("numba:compile") as rec, \
            event.install_recorder("numba:run_pass") as passes:
        RenderJob(scene, threads=1).run()
    cpu = cpu_seconds() - cpu0
    wall = time.perf_counter() - wall0

    rows = compile_times(rec.buffer)
    print_compiles(rows, wall, cpu, args.top)

    # exclusive time per compiler pass, over all compiles, and inside the top function
    events = sorted([(ts, 0, ev) for ts, ev in rec.buffer]
                    + [(ts, 1, ev) for ts, ev in passes.buffer], key=lambda e: e[0])
    per_pass: dict = collections.defaultdict(float)
    per_pass_top: dict = collections.defaultdict(float)
    top_name = max(rows, key=lambda r: r[3])[0]
    frames: list[list] = []  # [kind, name, start, children]
    for ts, kind, ev in events:
        if ev.is_start:
            if kind == 0:
                f = ev.data["dispatcher"].py_func
                name = f.__module__ + "." + f.__qualname__
            else:
                name = ev.data["name"].split(" [")[0]
            frames.append([kind, name, ts, 0.0])
            continue
        k, name, start, children = frames.pop()
        inclusive = ts - start
        if frames:
            frames[-1][3] += inclusive
        if k == 1:
            exclusive = inclusive - children
            per_pass[name] += exclusive
            owner = next((f[1] for f in reversed(frames) if f[0] == 0), None)
            if owner == top_name:
                per_pass_top[name] += exclusive
    print("\ncompiler passes, exclusive s: all compiles | " + top_name)
    for name, secs in sorted(per_pass.items(), key=lambda kv: -kv[1])[:12]:
        print(f"{secs:8.2f} {per_pass_top.get(name, 0.0):8.2f}  {name}")

    llvm_passes(rec.buffer, args.top)

    from whitted.kernels.tiles import render_tiles

    for sig in render_tiles.signatures:
        ir = render_tiles.inspect_llvm(sig)
        asm = render_tiles.inspect_asm(sig)
        print(f"\nrender_tiles: optimised LLVM IR {len(ir) / 1e6:.2f} MB, "
              f"{ir.count(chr(10))} lines; {asm.count(chr(10))} lines of assembly")


if __name__ == "__main__":
    main()
