"""Adaptive anti-aliasing against uniform sampling at equal render time (a measurement, not
a test).

    python benchmarks/antialias_study.py [--width 200 --height 150] [--reference 256]

For the default scene and the soft-shadow benchmark (benchmarks/softshadow.toml, its disk
light at 16 shadow rays), renders a reference at ``--reference`` stratified samples per
pixel, then uniform sampling at 1, 4, 9 and 16 samples and adaptive anti-aliasing at a few
thresholds and sample caps, each on one thread, timing the render's CPU time (the median of
three) and measuring the RMS error of the 8-bit sRGB pixels against the reference. Prints a
markdown table sorted by time, and for each adaptive setting the uniform error at the same
time (interpolated in log time between the two nearest uniform renders).
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

import whitted
from whitted.scene.default import default_scene

UNIFORM = (1, 4, 9, 16)
ADAPTIVE = ((0.3, 81), (0.1, 25), (0.1, 81), (0.05, 81), (0.02, 289))


def _render(scene, repeats=3):
    times = []
    image = None
    for _ in range(repeats):
        start = time.process_time()
        image = whitted.render(scene, threads=1)
        times.append(time.process_time() - start)
    return image, statistics.median(times)


def _display(image) -> np.ndarray:
    return image.to_srgb8().astype(np.float64)


def study(name: str, scene, reference_samples: int) -> None:
    whitted.render(scene.with_settings(width=8, height=8))  # kernels loaded, not timed
    reference, ref_time = _render(scene.with_settings(samples=reference_samples), repeats=1)
    ref = _display(reference)
    rows = []
    for n in UNIFORM:
        image, t = _render(scene.with_settings(samples=n))
        rows.append(("uniform", f"{n} spp", t, _rms(_display(image), ref),
                     image.meta["stats"].rays["primary"]))
    for threshold, cap in ADAPTIVE:
        image, t = _render(scene.with_settings(
            samples=1, antialias={"threshold": threshold, "max_samples": cap}))
        rows.append(("adaptive", f"+A{threshold} cap {cap}", t, _rms(_display(image), ref),
                     image.meta["stats"].rays["primary"]))
    uniform = sorted((r[2], r[3]) for r in rows if r[0] == "uniform")
    print(f"\n### {name} ({scene.render.width}x{scene.render.height}, reference "
          f"{reference_samples} spp in {ref_time:.1f} s)\n")
    print("| sampling | setting | CPU s | primary rays | RMS error (8-bit) | uniform at "
          "equal time |")
    print("| --- | --- | --- | --- | --- | --- |")
    for kind, setting, t, err, rays in sorted(rows, key=lambda r: r[2]):
        same = _at_time(uniform, t) if kind == "adaptive" else None
        same_text = "" if same is None else f"{same:.3f}"
        print(f"| {kind} | {setting} | {t:.3f} | {rays:,} | {err:.3f} | {same_text} |")


def _rms(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((a - b) ** 2)))


def _at_time(uniform, t):
    """The uniform error interpolated at time t (log-log between neighbours)."""
    if t <= uniform[0][0]:
        return uniform[0][1]
    for (t0, e0), (t1, e1) in zip(uniform, uniform[1:], strict=False):
        if t0 <= t <= t1:
            w = (math.log(t) - math.log(t0)) / (math.log(t1) - math.log(t0))
            return math.exp(math.log(e0) + w * (math.log(e1) - math.log(e0)))
    return None  # slower than every uniform render


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--width", type=int, default=200)
    parser.add_argument("--height", type=int, default=150)
    parser.add_argument("--reference", type=int, default=256)
    args = parser.parse_args()
    size = {"width": args.width, "height": args.height}
    study("default scene", default_scene().with_settings(**size), args.reference)
    soft = whitted.load_scene("benchmarks/softshadow.toml").with_settings(
        shadow_samples=16, **size)
    study("soft shadows", soft, args.reference)


if __name__ == "__main__":
    main()
