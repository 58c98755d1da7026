"""Measure the farm on this machine (the numbers behind docs/farm.md's scaling model)::

    python -m whitted.farm.measure [SCENE] [--frames 24] [--width 480 --height 270]
        [--workers 1x1,1x2,2x1] [--rounds 3] [--hd] [--cold] [--json out.json]

A film of ``--frames`` frames (the scene's own animation, or a camera turn added to a still
scene) rendered locally in one process with 2 render threads (what ``whitted animate`` does),
and on LocalClusters given as ``PROCESSESxTHREADS``: 1x2 is one worker process with 2 Dask
threads, 2x1 two processes of one (``--cluster local:2``); every task renders with 1 thread.
Also: the time to start a cluster and warm a fresh worker (kernels loaded from the cache; with
``--cold`` compiled into an empty cache), the per-task overhead of Dask on this machine (empty
tasks: the round trip of one, and the throughput of many), the bytes that travel (the scene,
its files, a frame's PNG), and with ``--hd`` one 1920x1080 frame's render time and PNG size.
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import statistics
import tempfile
import time
from pathlib import Path

from ..machine import cpu_name


def _noop(x: int) -> int:
    return x


def film_scene(path: str | None, frames: int):
    from ..scene import load_scene
    from ..scene.default import default_scene

    scene = load_scene(path) if path else default_scene()
    if scene.is_animated:
        return scene
    cam = scene.camera
    eye = [float(v) for v in cam.position]
    target = [float(v) for v in cam.look_at]
    dx, dz = eye[0] - target[0], eye[2] - target[2]
    keys = []
    for k, turn in ((0, 0.0), (frames - 1, 0.5)):  # a quarter... half a radian round
        import math

        c, s = math.cos(turn), math.sin(turn)
        keys.append([k, [target[0] + c * dx + s * dz, eye[1], target[2] - s * dx + c * dz]])
    from ..scene.animation import Track

    return scene.with_animation(frames, 24.0, [Track("camera.position", keys)])


def measure_local(scene, folder: Path, threads: int = 2) -> dict:
    from ..animation.frames import FrameRenderer
    from ..render.warm_up import warm_up_kernels

    warm_up_kernels()
    renderer = FrameRenderer(threads)
    start = time.perf_counter()
    cpu = time.process_time()
    for k in range(scene.frame_count):
        renderer.render(scene.at_frame(k), k, folder / f"{k:04d}.png", force=True)
    wall = time.perf_counter() - start
    cpu = time.process_time() - cpu
    n = scene.frame_count
    return {"threads": threads, "wall_s": wall, "cpu_s": cpu, "per_frame_s": wall / n,
            "per_frame_cpu_s": cpu / n}


def measure_cluster(scene, workers: int, folder: Path, overhead: bool,
                    dask_threads: int = 1) -> dict:
    from ..animation.film import render_film
    from ._dask import Client
    from .cluster import local_cluster
    from .film import DaskFrames
    from .worker import WhittedWorker, warm_seconds

    row: dict = {"workers": workers, "threads_per_worker": dask_threads}
    start = time.perf_counter()
    cluster = local_cluster(workers, 1, dask_threads)
    client = Client(cluster)
    row["cluster_start_s"] = time.perf_counter() - start
    try:
        start = time.perf_counter()
        client.register_plugin(WhittedWorker(threads=1))
        row["plugin_warm_s"] = time.perf_counter() - start
        row["worker_warm_s"] = sorted(client.run(warm_seconds).values())
        start = time.perf_counter()
        result = render_film(scene, folder, force=True, executor=DaskFrames(client))
        report = result.report
        row["wall_s"] = time.perf_counter() - start
        row["per_frame_worker_s"] = result.render_seconds / max(1, len(result.rendered))
        row["per_frame_worker_cpu_s"] = report.render_cpu_seconds / max(1, len(result.rendered))
        row["tasks"] = report.tasks
        row["chunk"] = report.chunk
        sizes = [p.stat().st_size for p in result.files]
        row["png_bytes_mean"] = statistics.mean(sizes)
        row["asset_bytes"] = report.asset_bytes
        if overhead:
            trips = []
            for i in range(30):
                t = time.perf_counter()
                client.submit(_noop, i, pure=False).result()
                trips.append(time.perf_counter() - t)
            row["task_round_trip_ms"] = 1000 * statistics.median(trips)
            n = 1000
            t = time.perf_counter()
            client.gather(client.map(_noop, range(n), pure=False))
            row["task_throughput_per_s"] = n / (time.perf_counter() - t)
    finally:
        client.close()
        cluster.close()
    return row


def measure_hd(scene, folder: Path) -> dict:
    from ..animation.frames import render_frame

    start = time.perf_counter()
    render_frame(scene, 0, folder / "hd.png", width=1920, height=1080, threads=1, force=True)
    return {"width": 1920, "height": 1080, "threads": 1,
            "frame_s": time.perf_counter() - start,
            "png_bytes": (folder / "hd.png").stat().st_size}


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?")
    parser.add_argument("--frames", type=int, default=24)
    parser.add_argument("--width", type=int, default=480)
    parser.add_argument("--height", type=int, default=270)
    parser.add_argument("--workers", default="1x1,2x1",
                        help="cluster layouts PROCESSESxTHREADS, comma-separated (2 = 2x1)")
    parser.add_argument("--hd", action="store_true")
    parser.add_argument("--cold", action="store_true")
    parser.add_argument("--rounds", type=int, default=1,
                        help="interleaved rounds of local / 1 / 2 workers (medians reported)")
    parser.add_argument("--json")
    args = parser.parse_args(argv)

    scene = film_scene(args.scene, args.frames).with_settings(width=args.width,
                                                               height=args.height)
    report: dict = {"cpu": cpu_name(), "load_before": os.getloadavg(), "frames": scene.frame_count,
                    "size": [args.width, args.height], "scene": args.scene or "<default>",
                    "scene_pickle_bytes": len(pickle.dumps(scene))}
    with tempfile.TemporaryDirectory(prefix="whitted-measure-") as tmp:
        root = Path(tmp)
        layouts = [_layout(text) for text in args.workers.split(",")]
        counts = [f"{p}x{t}" for p, t in layouts]
        local_rows, cluster_rows = [], {n: [] for n in counts}
        for round_ in range(args.rounds):  # interleaved: the machine's load hits all alike
            local_rows.append(measure_local(scene, _fresh(root / "local")))
            print(f"round {round_} local:", local_rows[-1], flush=True)
            for n, (processes, threads) in zip(counts, layouts, strict=True):
                row = measure_cluster(scene, processes, _fresh(root / f"farm{n}"),
                                      overhead=n == counts[-1], dask_threads=threads)
                cluster_rows[n].append(row)
                print(f"round {round_} {n} worker(s):", row, flush=True)
        report["local"] = _medians(local_rows)
        report["cluster"] = []
        for n in counts:
            row = _medians(cluster_rows[n])
            row["speedup_vs_local"] = report["local"]["wall_s"] / row["wall_s"]
            report["cluster"].append(row)
        report["rounds"] = {"local": local_rows, "cluster": cluster_rows}
        if args.cold:
            os.environ["WHITTED_CACHE_DIR"] = str(root / "cold-cache")
            os.environ.pop("NUMBA_CACHE_DIR", None)
            row = measure_cluster(scene.with_animation(2, 24.0), 1, _fresh(root / "cold"),
                                  overhead=False)
            report["cold_worker"] = {k: row[k] for k in ("cluster_start_s", "plugin_warm_s",
                                                         "worker_warm_s")}
            print("cold worker:", report["cold_worker"], flush=True)
        if args.hd:
            report["hd"] = measure_hd(scene, root)
            print("1080p frame:", report["hd"], flush=True)
    report["load_after"] = os.getloadavg()
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2) + "\n")
    return report


def _layout(text: str) -> tuple[int, int]:
    processes, _, threads = text.partition("x")
    return int(processes), int(threads or 1)


def _medians(rows: list[dict]) -> dict:
    """Each numeric field's median over the rounds (other fields from the first round)."""
    out = dict(rows[0])
    for key, value in rows[0].items():
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            out[key] = statistics.median(r[key] for r in rows)
    return out


def _fresh(folder: Path) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    return folder




if __name__ == "__main__":
    main()
