"""One timed render in a fresh process, as ``whitted render`` does it: start Python, import
whitted, read the scene, load (or compile) the kernels, build the BVH, render, write the PNG.
Prints one JSON line with the render statistics.

    python -m whitted.bench.worker SCENE OUT.png --threads N [--width W --height H]
"""

from __future__ import annotations

import argparse
import json
import time


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m whitted.bench.worker")
    parser.add_argument("scene")
    parser.add_argument("output")
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--width", type=int)
    parser.add_argument("--height", type=int)
    args = parser.parse_args(argv)

    from ..render.api import RenderJob
    from ..scene.io import load_scene

    start = time.perf_counter()
    scene = load_scene(args.scene).with_settings(width=args.width, height=args.height)
    loaded = time.perf_counter()
    job = RenderJob(scene, threads=args.threads or None)
    image = job.run()
    rendered = time.perf_counter()
    image.save(args.output)
    written = time.perf_counter()
    stats = job.stats
    print(json.dumps({
        "width": stats.width, "height": stats.height, "threads": stats.threads,
        "rays": stats.rays, "load_s": loaded - start, "compile_s": stats.compile_seconds,
        "build_s": stats.build_seconds, "render_s": stats.render_seconds,
        "job_s": rendered - loaded, "output_s": written - rendered,
        "photon_s": stats.photons.seconds if stats.photons is not None else 0.0,
    }))


if __name__ == "__main__":
    main()
