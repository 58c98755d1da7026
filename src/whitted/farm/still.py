"""One still image split into bands of rows across the workers, assembled on the client.

A pixel's value depends only on the scene, the seed and its coordinates, so a band rendered
anywhere holds exactly the values of the same rows of a local render: the assembled image is
bit-identical to it, with no seams. Bands are whole tile rows (16 pixels), about four per
worker so that a slow band does not leave the others idle at the end.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from ..output.image import Image
from ..render.api import DEFAULT_TILE, RenderStats
from ..scene.scene import Scene
from ._dask import Client, as_completed
from .transfer import AssetMode, Shipment, ship_assets
from .worker import render_band

BANDS_PER_WORKER = 4
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
) -> Image:
    """Render ``scene`` on the cluster behind ``client`` and return the whole
    :class:`~whitted.output.Image`, bit-identical to :func:`whitted.render.api.render`.
    ``assets``: how the scene's files reach the workers ("auto", "ship", "shared": see
    :func:`~whitted.farm.transfer.ship_assets`), or a :class:`Shipment` made earlier for this
    scene. ``progress(bands_done, bands_total)`` is called as bands arrive."""
    start = time.perf_counter()
    if scene.is_animated:  # as the render API does: an animated scene renders its frame 0
        scene = scene.at_frame(0)
    s = scene.render
    n_workers = max(1, len(client.scheduler_info().get("workers", {})))
    ranges = band_ranges(s.height, bands or BANDS_PER_WORKER * n_workers)
    shipment = assets if isinstance(assets, Shipment) else ship_assets(client, [scene], assets)
    manifest, blobs = shipment.for_scenes([0])
    from ..compile.embree import with_concrete_mesh_tracer

    [scene_future] = client.scatter([with_concrete_mesh_tracer(scene)], broadcast=True,
                                    hash=False)
    futures = [client.submit(render_band, scene_future, a, b, manifest, blobs, pure=False,
                             retries=retries) for a, b in ranges]
    framebuffer = np.zeros((s.height, s.width, 3), np.float32)
    stats = RenderStats(width=s.width, height=s.height, threads=0, samples=s.samples,
                        max_depth=s.max_depth, tiles_total=len(ranges))
    try:
        for done, future in enumerate(as_completed(futures), start=1):
            row, rows, band = future.result()
            framebuffer[row:row + len(rows)] = rows
            for kind, count in band.rays.items():
                stats.rays[kind] = stats.rays.get(kind, 0) + count
            stats.threads = max(stats.threads, band.threads)
            stats.compile_seconds = max(stats.compile_seconds, band.compile_seconds)
            stats.warnings.extend(w for w in band.warnings if w not in stats.warnings)
            stats.tiles_done = done
            if progress is not None:
                progress(done, len(futures))
    finally:
        client.cancel(futures)
    stats.wall_seconds = stats.render_seconds = time.perf_counter() - start
    return Image(framebuffer, transfer=s.transfer, tonemap=s.tonemap,
                 meta={"stats": stats, "workers": n_workers, "bands": len(ranges),
                       "asset_bytes": shipment.bytes})
