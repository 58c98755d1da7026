"""``whitted bench --rays``: where a scene's render time goes, by kind of ray.

The render kernel keeps no clock per ray (a clock read per ray would cost more than many of
the rays), so the time of each kind is measured by difference, on three variants of the scene
rendered alternately with the scene itself (``full``, ``dark``, ``primary``, ``full``, ...,
so a machine whose speed drifts weighs on all alike; medians over the runs):

- ``full``: the scene as it is;
- ``dark``: the same without its lights other than ambient (no shadow ray, no direct light,
  no photon); every other ray is traced as in ``full`` (a ray's weight does not depend on
  the lights), so its reflection and refraction counts are ``full``'s;
- ``primary``: ``dark`` at max depth 0: the camera rays alone.

Then ``primary_s`` is ``primary``'s render time; ``shadow_s`` (the direct light: shadow rays
and the shading around them) is ``full − photon − dark``; the secondary rays' time is
``dark − primary``, shared between ``reflection_s`` and ``refraction_s`` in proportion to
their counts (one variant cannot trace one of the two kinds alone without changing what the
other traces); ``photon_s`` is the render's own clock on shooting photons (caustics). The five
add up to the median render time of ``full`` except where noise makes a difference negative:
that kind is then 0 and ``noise_s`` holds the difference.
"""

from __future__ import annotations

import statistics
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..scene.scene import Scene

KINDS = ("primary", "shadow", "reflection", "refraction", "photon")
VARIANTS = ("full", "dark", "primary")


def variants(scene: Scene) -> dict[str, Scene]:
    """The scene and its two reduced copies (see the module's text)."""
    dark = scene.model_copy(update={"lights": [light for light in scene.lights
                                               if light.type == "ambient"]})
    return {"full": scene, "dark": dark, "primary": dark.with_settings(max_depth=0)}


def time_by_kind(scene: Scene, threads: int, runs: int, folder: Path,
                 measure: Callable[[Scene, int, Path], dict[str, Any]]) -> dict[str, Any]:
    """Render the three variants alternately ``runs`` times each (after one warm-up of each)
    with ``measure`` (the bench's fresh-process or in-process run); the seconds per kind."""
    scenes = variants(scene)
    folders = {}
    for name in VARIANTS:
        folders[name] = folder / f"rays-{name}"
        folders[name].mkdir(exist_ok=True)
        measure(scenes[name], threads, folders[name])  # warm-up: kernels, files
    results: dict[str, list[dict[str, Any]]] = {name: [] for name in VARIANTS}
    for _ in range(runs):
        for name in VARIANTS:
            results[name].append(measure(scenes[name], threads, folders[name]))
    render = {name: statistics.median(r["render_s"] for r in results[name])
              for name in VARIANTS}
    photon = statistics.median(r.get("photon_s", 0.0) for r in results["full"])
    rays = {name: dict(results[name][0]["rays"]) for name in VARIANTS}
    return split_time(render, photon, rays)


def split_time(render: dict[str, float], photon: float,
               rays: dict[str, dict[str, int]]) -> dict[str, Any]:
    """The seconds per kind from the variants' median render times and ray counts."""
    raw = {
        "primary": render["primary"],
        "shadow": render["full"] - photon - render["dark"],
        "secondary": render["dark"] - render["primary"],
    }
    noise = sum(-v for v in raw.values() if v < 0)
    raw = {k: max(0.0, v) for k, v in raw.items()}
    full = rays["full"]
    secondary = full.get("reflection", 0) + full.get("refraction", 0)
    share = full.get("reflection", 0) / secondary if secondary else 0.0
    seconds = {
        "primary": raw["primary"], "shadow": raw["shadow"],
        "reflection": raw["secondary"] * share,
        "refraction": raw["secondary"] * (1.0 - share),
        "photon": photon,
    }
    return {
        "seconds": seconds,
        "render_s": render["full"],
        "noise_s": noise,
        "variant_render_s": dict(render),
        "variant_rays": rays,
    }


def breakdown_rows(rows: list[dict[str, Any]]) -> tuple[list[str], list[list[str]]]:
    """Column headings and text cells of the time-by-kind table (rows that have one)."""
    columns = ["scene", "threads", "render s"]
    columns += [f"{kind} s" for kind in KINDS] + [f"{kind} %" for kind in KINDS]
    columns += ["noise s"]
    cells = []
    for r in rows:
        b = r.get("time_by_kind")
        if b is None:
            continue
        total = b["render_s"]
        line = [r["scene"], str(r["threads"]), f"{total:.3f}"]
        line += [f"{b['seconds'][k]:.3f}" for k in KINDS]
        line += [f"{100 * b['seconds'][k] / total:.0f}" if total > 0 else "" for k in KINDS]
        line += [f"{b['noise_s']:.3f}"]
        cells.append(line)
    return columns, cells


def breakdown_table(rows: list[dict[str, Any]]):
    from rich.table import Table

    columns, cells = breakdown_rows(rows)
    table = Table(title="render time by kind of ray", header_style="bold", pad_edge=False)
    for i, name in enumerate(columns):
        table.add_column(name, justify="left" if i == 0 else "right", no_wrap=True)
    for line in cells:
        table.add_row(*line)
    return table
