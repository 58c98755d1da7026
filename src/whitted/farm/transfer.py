"""Sending scenes and their files to the workers through Dask.

Each file's bytes become the result of a task under the key ``whitted-asset-<sha256>`` (the
same file asked for twice, by two frames or two runs on one client, is one piece of data):
a task's result, not scattered data, so that when every worker that held it is lost Dask
computes it again (from the bytes the task was submitted with) instead of failing the tasks
that need it. A task that needs files takes their futures
as arguments: Dask brings each blob to each worker once (from whichever worker has it, not
from the client), and :func:`~whitted.farm.assets.materialise` writes it into that worker's
disk cache.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

from ..scene.scene import Scene
from ._dask import Client, Future
from .assets import (
    ASSET_KEY_PREFIX,
    AssetManifest,
    collect_assets,
    file_stamps,
    files_visible,
)

AssetMode = Literal["auto", "ship", "shared"]
ASSET_MODES = ("auto", "ship", "shared")


@dataclass
class Shipment:
    """The files of some scenes on their way to the workers (``manifest`` None: the workers
    read the client's files where they are)."""

    manifest: AssetManifest | None = None
    blobs: dict[str, Future] = field(default_factory=dict)  # by digest
    needs: list[list[str]] = field(default_factory=list)  # tree paths, per scene

    @property
    def shipped(self) -> bool:
        return self.manifest is not None

    @property
    def bytes(self) -> int:
        return self.manifest.total_bytes if self.manifest is not None else 0

    def for_scenes(self, indices: Sequence[int]) -> tuple[AssetManifest | None,
                                                           dict[str, Future]]:
        """The manifest and blob futures a task rendering these scenes takes."""
        if self.manifest is None:
            return None, {}
        paths = {p for i in indices for p in self.needs[i]}
        part = self.manifest.subset(paths)
        return part, {digest: self.blobs[digest] for digest in set(part.files.values())}


def workers_see(client: Client, stamps: dict[str, tuple[int, int]]) -> bool:
    """Whether every ready worker (at least one) sees every file as the client does (``stamps``:
    size and modification time by absolute path, from :func:`file_stamps`)."""
    from .watch import ready_workers

    if not stamps:
        return True
    workers = ready_workers(client.scheduler_info(n_workers=-1))
    if not workers:
        return False
    answers = client.run(files_visible, stamps, workers=workers)
    return bool(answers) and all(answers.values())


def ship_assets(client: Client, scenes: Sequence[Scene], mode: AssetMode = "auto") -> Shipment:
    """Make the files of ``scenes`` (one base folder) reachable by every worker: "shared"
    trusts a shared file system, "ship" always sends them, "auto" sends them unless every
    worker already sees them."""
    if mode not in ASSET_MODES:
        raise ValueError(f"assets: unknown mode {mode!r} (use {', '.join(ASSET_MODES)})")
    if mode == "shared":
        return Shipment()
    stamped = file_stamps(scenes)  # sizes and times only: no file is read yet
    if not stamped[0] or (mode == "auto" and workers_see(client, stamped[0])):
        return Shipment()
    manifest, paths, needs = collect_assets(scenes, stamped)
    from .worker import TASK_RESOURCES, hold

    blobs = {}
    with warnings.catch_warnings():  # big files make a "large graph": meant, and said above
        warnings.simplefilter("ignore", UserWarning)
        for digest, path in paths.items():
            blobs[digest] = client.submit(hold, path.read_bytes(),
                                          key=ASSET_KEY_PREFIX + digest,
                                          resources=TASK_RESOURCES)
    return Shipment(manifest, blobs, needs)
