"""One still image split into bands of rows across the workers, assembled on the client.

A pixel's value depends only on the scene, the seed and its coordinates, so a band rendered
anywhere holds exactly the values of the same rows of a local render: the assembled image is
bit-identical to it, with no seams. Bands are whole tile rows (16 pixels), about four per
render thread of the cluster (every worker's Dask threads counted) so that a slow band does
not leave the others idle at the end. Stopped part way (``cancel``), the image holds the
bands that arrived and black elsewhere, as a local render stopped part way does.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

import numpy as np

from ..output.image import Image
from ..render.api import DEFAULT_TILE, RenderStats
from ..scene.scene import Scene
from ._dask import Client
from .transfer import AssetMode, Shipment, ship_assets
from .worker import render_band

BANDS_PER_THREAD = 4
RETRIES = 2


def band_ranges(height: int, bands: int, tile: int = DEFAULT_TILE) -> list[tuple[int, int]]:
    """``bands`` (at most one per tile row) ranges of whole tile rows covering the image."""
    tile_rows = -(-height // tile)
    bands = max(1, min(bands, tile_rows))
    cuts = [k * tile_rows // bands * tile for k in range(bands + 1)]
    return [(a, min(b, height)) for a, b in zip(cuts, cuts[1:], strict=False) if a < b]


def render_still(
    client: Client,
    scene: Scene,
    *,
    bands: int | None = None,
    assets: AssetMode | Shipment = "auto",
    progress: Callable[[int, int], None] | None = None,
    retries: int = RETRIES,
    cancel: threading.Event | None = None,
    note: Callable[[str], None] | None = None,
    stall_floor: float | None = None,
) -> Image:
    """Render ``scene`` on the cluster behind ``client`` and return the whole
    :class:`~whitted.output.Image`, bit-identical to :func:`whitted.render.api.render`.
    ``assets``: how the scene's files reach the workers ("auto", "ship", "shared": see
    :func:`~whitted.farm.transfer.ship_assets`), or a :class:`Shipment` made earlier for this
    scene. ``progress(bands_done, bands_total)`` is called as bands arrive. ``cancel``: set
    it to stop; the image then holds the bands that arrived (``stats.cancelled``,
    ``stats.tiles_done`` bands of ``stats.tiles_total``). ``note``, ``stall_floor``: as
    :func:`~whitted.farm.film.render_film`'s. Raises
    :class:`~whitted.farm.watch.ClusterLost` when the cluster cannot go on."""
    from ..compile.embree import with_concrete_mesh_tracer
    from .watch import STALL_FLOOR, Watch, cancel_quietly, run_tasks
    from .worker import TASK_RESOURCES, scene_argument

    start = time.perf_counter()
    if scene.is_animated:  # as the render API does: an animated scene renders its frame 0
        scene = scene.at_frame(0)
    s = scene.render
    info = client.scheduler_info(n_workers=-1)
    workers = info.get("workers", {})
    threads = max(1, sum(w.get("nthreads", 1) for w in workers.values()))
    ranges = band_ranges(s.height, bands or BANDS_PER_THREAD * threads)
    framebuffer = np.zeros((s.height, s.width, 3), np.float32)
    stats = RenderStats(width=s.width, height=s.height, threads=0, samples=s.samples,
                        max_depth=s.max_depth, tiles_total=len(ranges))
    watch = Watch(client, note, stall_floor=STALL_FLOOR if stall_floor is None
                  else stall_floor)
    tasks: dict = {}
    shipment = Shipment()
    try:
        shipment = (assets if isinstance(assets, Shipment)
                    else ship_assets(client, [scene], assets))
        manifest, blobs = shipment.for_scenes([0])
        scene_future = scene_argument(client, with_concrete_mesh_tracer(scene))

        def submit(band: tuple[int, int], workers: list[str] | None = None):
            return client.submit(render_band, scene_future, band[0], band[1], manifest, blobs,
                                 pure=False, retries=retries, resources=TASK_RESOURCES,
                                 workers=workers, allow_other_workers=False)

        for band in ranges:
            tasks[submit(band)] = band

        def on_done(future, band: tuple[int, int]) -> None:
            if future.status == "cancelled":
                raise watch.lost()
            row, rows, band_stats = watch.result(future)  # a failed band raises its error
            framebuffer[row:row + len(rows)] = rows
            watch.record([band_stats.render_seconds])
            for kind, count in band_stats.rays.items():
                stats.rays[kind] = stats.rays.get(kind, 0) + count
            stats.threads = max(stats.threads, band_stats.threads)
            stats.compile_seconds = max(stats.compile_seconds, band_stats.compile_seconds)
            stats.warnings.extend(w for w in band_stats.warnings if w not in stats.warnings)
            stats.tiles_done += 1
            if progress is not None:
                progress(stats.tiles_done, len(ranges))

        stats.cancelled = not run_tasks(watch, tasks, submit, on_done, cancel=cancel)
    finally:
        watch.close()
        cancel_quietly(client, tasks)
    stats.wall_seconds = stats.render_seconds = time.perf_counter() - start
    return Image(framebuffer, transfer=s.transfer, tonemap=s.tonemap,
                 meta={"stats": stats, "workers": len(workers), "threads": threads,
                       "bands": len(ranges), "asset_bytes": shipment.bytes})
