"""Reading model and image files into NumPy data.

The loaders are imported on first use (PEP 562): a scene without textures never imports
Pillow and pypng (10 ms of a render's start-up), one without models never the OBJ reader."""

from __future__ import annotations

import importlib

_HOMES = {"load_image": ".images", "MeshData": ".mesh", "clear_mesh_cache": ".mesh",
          "load_mesh": ".mesh"}

__all__ = ["MeshData", "clear_mesh_cache", "load_image", "load_mesh"]


def __getattr__(name: str):
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(home, __name__), name)


def __dir__() -> list[str]:
    return sorted([*globals(), *_HOMES])
