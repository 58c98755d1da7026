"""The render farm: films and big stills on a Dask cluster (``pip install 'whitted[farm]'``).

A thin client of the render API: it schedules render-API calls on dask.distributed and writes
what comes back. In a notebook, pass your own client::

    from dask.distributed import Client
    from whitted import farm, load_scene
    from whitted.animation.film import render_film

    client = Client("tls://scheduler:8786")                 # Dask's TLS settings
    farm.ready_cluster(client, farm.WhittedWorker(threads=1), print)  # kernels warm
    image = farm.render_still(client, load_scene("poster.toml"))
    image.save("poster.png")
    render_film(load_scene("film.toml"), "film.mp4", executor=farm.DaskFrames(client))

The command line does the same with ``whitted render SCENE --cluster local:N`` or
``--scheduler tcp://HOST:PORT``. See docs/farm.md.
"""

from __future__ import annotations

from ._dask import INSTALL_HINT
from .assets import AssetManifest, collect_assets, scene_file_names
from .cluster import (
    check_farm_options,
    farm_client,
    local_cluster,
    parse_cluster,
    ready_cluster,
)
from .errors import ClusterLost, FarmError
from .film import DaskFrames, FarmReport, FrameFailed, chunk_size
from .still import band_ranges, render_still
from .transfer import Shipment, ship_assets
from .watch import Watch
from .worker import WhittedWorker

__all__ = [
    "INSTALL_HINT",
    "AssetManifest",
    "ClusterLost",
    "DaskFrames",
    "FarmError",
    "FarmReport",
    "FrameFailed",
    "Shipment",
    "Watch",
    "WhittedWorker",
    "band_ranges",
    "check_farm_options",
    "chunk_size",
    "collect_assets",
    "farm_client",
    "local_cluster",
    "parse_cluster",
    "ready_cluster",
    "render_still",
    "scene_file_names",
    "ship_assets",
]
