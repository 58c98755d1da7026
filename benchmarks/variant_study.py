"""What a specialised kernel variant saves: the render time of a bench scene with the kernels
it runs against the same scene run by a more general variant, in one process, the variants
alternating (A B A B ...) so that the machine's drift cancels pair by pair.

The variants are the kinds of GeometryArrays the kernels are specialised on
(kernels/features.py): ``plain`` (float32 inst_box, int32 unbounded), ``instances`` (float64
inst_box), ``extras`` (int64 unbounded) and ``general`` (both). A scene's arrays are cast to
the variant's types; the kernels of each are compiled (or loaded) before the timed runs.
The first variant named is the reference of the ratios. Every variant must give the same
image (checked).

    PYTHONPATH=src python benchmarks/variant_study.py seed000 11 plain general
    PYTHONPATH=src python benchmarks/variant_study.py csg 15 general
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics

import numpy as np

from whitted.bench.scenes import load_bench_scene
from whitted.compile.scene import compile_scene
from whitted.render.api import RenderJob

VARIANTS = {"plain": (False, False), "instances": (True, False), "extras": (False, True),
            "general": (True, True)}


def as_variant(compiled, name: str):
    """``compiled`` with its geometry cast to the types of variant ``name``."""
    instances, extras = VARIANTS[name]
    geo = compiled.geometry
    geo = geo._replace(inst_box=geo.inst_box.astype(np.float64 if instances else np.float32),
                       unbounded=geo.unbounded.astype(np.int64 if extras else np.int32))
    return dataclasses.replace(compiled, geometry=geo)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", help="a bench scene (seed000, csg, instances100, ...)")
    parser.add_argument("runs", type=int, help="timed runs of each variant")
    parser.add_argument("variants", nargs="+", choices=list(VARIANTS))
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()
    scene = load_bench_scene(args.scene)
    compiled = compile_scene(scene)
    cases = {name: as_variant(compiled, name) for name in args.variants}
    images = {name: RenderJob(scene, compiled=c, threads=args.threads).run().pixels
              for name, c in cases.items()}  # compiled or loaded: not timed
    times: dict[str, list[float]] = {name: [] for name in cases}
    for _ in range(args.runs):
        for name, c in cases.items():
            job = RenderJob(scene, compiled=c, threads=args.threads)
            job.run()
            times[name].append(job.stats.render_seconds)
    base = args.variants[0]
    for name in cases:
        ratios = [a / b for a, b in zip(times[name], times[base], strict=True)]
        same = np.array_equal(images[name], images[base])
        print(f"{args.scene:12} {name:9} render median {statistics.median(times[name]):.4f} s"
              f"  /{base}: median {statistics.median(ratios):.3f} (min {min(ratios):.3f}, "
              f"max {max(ratios):.3f}), {args.runs} pairs, same image: {same}")


if __name__ == "__main__":
    main()
