"""whitted against POV-Ray 3.7, pixel by pixel, for the scenes of benchmarks/povray_checks/
(CSG, merge of glass, torus at grazing angles, focal blur, adaptive anti-aliasing): a
measurement, not a test.

    python benchmarks/povray_compare.py [--out /tmp/povray_compare] [--threads 2]

Each scene is rendered by whitted and, exported with ``whitted export``'s writer, by POV-Ray
at the same size (its anti-aliasing options from the scene: ``-A``, or ``+A +AM2 +R`` for
``[render.antialias]``). Prints the share of pixels whose every channel is within 2/255,
the mean absolute difference (8-bit units) and both trace times, and writes side-by-side
PNGs (whitted | POV-Ray | difference x4) into ``--out``.
"""

from __future__ import annotations

import argparse
import subprocess
import time
from pathlib import Path

import numpy as np
from PIL import Image as PILImage

import whitted
from whitted.bench.povray import parse_povray_statistics, povray_executable
from whitted.export.pov import export_pov, povray_antialias_options

CHECKS = Path(__file__).parent / "povray_checks"


def compare(name: str, scene_file: Path, out: Path, threads: int) -> dict:
    scene = whitted.load_scene(scene_file)
    start = time.perf_counter()
    image = whitted.render(scene, threads=threads)
    ours_s = image.meta["stats"].render_seconds
    ours = image.to_srgb8()
    del start
    pov_file = export_pov(scene, out / f"{name}.pov")
    pov_png = out / f"{name}.povray.png"
    command = [povray_executable(), f"+I{pov_file}", f"+O{pov_png}",
               f"+W{scene.render.width}", f"+H{scene.render.height}",
               *povray_antialias_options(scene).split(), "-D", "-P", "+FN", f"+WT{threads}",
               "-V"]
    run = subprocess.run(command, capture_output=True, text=True, cwd=out, timeout=3600)
    if run.returncode != 0:
        raise SystemExit(f"povray failed on {name}: {run.stderr[-500:]}")
    stats = parse_povray_statistics(run.stderr)
    theirs = np.asarray(PILImage.open(pov_png).convert("RGB"))
    diff = np.abs(ours.astype(int) - theirs.astype(int))
    within = float(np.mean(diff.max(axis=2) <= 2))
    side = np.concatenate([ours, theirs, np.clip(diff * 4, 0, 255).astype(np.uint8)], axis=1)
    PILImage.fromarray(side).save(out / f"{name}.side_by_side.png")
    return {"scene": name, "within_2": within, "mean_abs": float(diff.mean()),
            "whitted_s": ours_s, "povray_trace_s": float(stats["trace_s"])}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", type=Path, default=Path("/tmp/povray_compare"))
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--only", default=None)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    print("| scene | pixels within 2/255 | mean abs diff (8-bit) | whitted render s | "
          "POV-Ray trace s |")
    print("| --- | --- | --- | --- | --- |")
    for scene_file in sorted(CHECKS.glob("*.toml")):
        if args.only and args.only not in scene_file.stem:
            continue
        row = compare(scene_file.stem, scene_file, args.out, args.threads)
        print(f"| {row['scene']} | {100 * row['within_2']:.2f} % | {row['mean_abs']:.2f} | "
              f"{row['whitted_s']:.2f} | {row['povray_trace_s']:.2f} |", flush=True)


if __name__ == "__main__":
    main()
