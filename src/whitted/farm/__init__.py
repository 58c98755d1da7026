"""The render farm: films and big stills on a Dask cluster (``pip install 'whitted[farm]'``).

A thin client of the render API: it schedules render-API calls on dask.distributed and writes
what comes back. In a notebook, pass your own client::

    from dask.distributed import Client
    from whitted import farm, load_scene

    client = Client("tcp://scheduler:8786")
    client.register_plugin(farm.WhittedWorker(threads=1))   # kernels warm, 1 thread a task
    image = farm.render_still(client, load_scene("poster.toml"))
    image.save("poster.png")

The command line does the same with ``whitted render SCENE --cluster local:N`` or
``--scheduler tcp://HOST:PORT``. See docs/farm.md.
"""

from __future__ import annotations

from ._dask import INSTALL_HINT
from .assets import AssetManifest, collect_assets, scene_file_names
from .cluster import check_farm_options, farm_client, local_cluster, parse_cluster
from .errors import ClusterLost, FarmError
from .film import FilmPlan, FilmResult, FrameFailed, chunk_size, plan_film, render_film
from .still import band_ranges, render_still
from .transfer import Shipment, ship_assets
from .watch import Watch
from .worker import WhittedWorker

__all__ = [
    "INSTALL_HINT",
    "AssetManifest",
    "ClusterLost",
    "FarmError",
    "FilmPlan",
    "FilmResult",
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
    "plan_film",
    "render_film",
    "render_still",
    "scene_file_names",
    "ship_assets",
]
