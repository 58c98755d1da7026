"""Work kept between the frames of a film: what a frame shares with the one before it is not
compiled again.

* Only the camera, background or render settings changed (a camera move): the whole
  compiled scene (geometry, BVHs, materials, lights and light buffers) is reused.
* The lights changed too, the objects and materials did not: geometry, BVHs and the material
  table are reused; the light table is rebuilt, and the light buffers too if a point light
  moved (they depend on where the lights are, not on their colour or intensity).
* Objects or materials changed: the scene is compiled again, but every BVH whose primitives
  did not move is reused (:class:`~whitted.compile.reuse.BvhMemo`): a moving object
  rebuilds the scene BVH, never the BVHs of meshes that did not change.

Every reuse gives exactly what a fresh compile gives (the compiler is deterministic), so
frames are the same whether rendered in one run or one by one.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..compile.scene import CompiledScene
    from ..scene.scene import Scene

__all__ = ["CompileCache", "ReuseStats"]

REUSE_ALL = "all"  # nothing compiled
REUSE_LIGHT_BUFFERS = "light buffers"  # light values changed, not where the lights are
REUSE_GEOMETRY = "geometry"  # lights rebuilt
REUSE_BVH = "bvh"  # compiled again, BVHs from the memo where unchanged
REUSE_NONE = "none"


@dataclass
class ReuseStats:
    """What a film's compiles reused (frames by level; BVHs and their primitives)."""

    frames: dict[str, int] = field(default_factory=dict)
    bvh_built: int = 0
    bvh_reused: int = 0
    primitives_built: int = 0
    primitives_reused: int = 0
    compile_seconds: float = 0.0

    def summary(self) -> str:
        """One line in words: how many frames' scenes were compiled in full, or reused the
        frame before's in part or whole; the BVHs reused; the time the compiles took."""
        levels = ", ".join(f"{self.frames[k]} {LEVEL_WORDS.get(k, k)}"
                           for k in sorted(self.frames, key=_level_order))
        total_bvh = self.bvh_built + self.bvh_reused
        prims = self.primitives_built + self.primitives_reused
        share = self.primitives_reused / prims if prims else 1.0
        return (f"scene compiles: {levels or 'none'}; BVHs: {self.bvh_reused} of {total_bvh} "
                f"reused ({share:.0%} of their primitives); {self.compile_seconds:.3f} s")


#: each level of reuse in words, for :meth:`ReuseStats.summary` (in this order)
LEVEL_WORDS = {
    REUSE_NONE: "compiled in full",
    REUSE_BVH: "compiled again keeping unchanged BVHs",
    REUSE_GEOMETRY: "kept the geometry (new lights)",
    REUSE_LIGHT_BUFFERS: "kept all but the lights' values",
    REUSE_ALL: "reused the frame before's whole",
}


def _level_order(level: str) -> int:
    order = list(LEVEL_WORDS)
    return order.index(level) if level in order else len(order)


def _geometry_part(scene: Scene) -> tuple:
    return (scene.objects, scene.materials, str(scene.base_dir))


def _light_part(scene: Scene) -> tuple:
    return (scene.lights, scene.render.shadow_samples)


def _same_buffers(previous, table):
    """The previous lights with ``table``'s values when every light has the same type and
    position as before (a light buffer depends on the geometry, the materials and where the
    point lights are, not on their colour or intensity); else None."""
    import numpy as np

    from ..kernels.layout import LIGHT_BUFFER, LIGHT_BUFFER_SIDE, LIGHT_POSITION, LIGHT_TYPE

    old = previous.table
    if old.shape != table.shape:
        return None
    where = [LIGHT_TYPE, LIGHT_POSITION, LIGHT_POSITION + 1, LIGHT_POSITION + 2]
    if not np.array_equal(old[:, where], table[:, where]):
        return None
    new = table.copy()
    new[:, LIGHT_BUFFER] = old[:, LIGHT_BUFFER]
    new[:, LIGHT_BUFFER_SIDE] = old[:, LIGHT_BUFFER_SIDE]
    return previous._replace(table=new)


class CompileCache:
    """Compiles the stills of consecutive frames, reusing what the previous one shares."""

    def __init__(self) -> None:
        from ..compile.reuse import BvhMemo

        self.memo = BvhMemo()
        self.stats = ReuseStats()
        self._previous: tuple[Scene, CompiledScene] | None = None

    def compile(self, still: Scene, threads: int = 1) -> tuple[CompiledScene, str]:
        """The compiled scene of ``still`` and how much was reused (``all``,
        ``light buffers``, ``geometry``, ``bvh`` or ``none``). ``threads`` may build the
        light buffers (the same arrays on any number)."""
        start = time.perf_counter()
        compiled, level = self._compile(still, threads)
        self.stats.compile_seconds += time.perf_counter() - start
        self.stats.frames[level] = self.stats.frames.get(level, 0) + 1
        self._previous = (still, compiled)
        return compiled, level

    def _compile(self, still: Scene, threads: int) -> tuple[CompiledScene, str]:
        from ..compile.light_buffers import build_light_buffers
        from ..compile.lights import light_rows
        from ..compile.scene import compile_scene

        if self._previous is not None:
            before, compiled = self._previous
            if _geometry_part(before) == _geometry_part(still):
                geo = compiled.geometry
                self.stats.bvh_reused += 2 + len(geo.mesh_info)
                self.stats.primitives_reused += (len(geo.node_prims) + len(geo.inst_prims)
                                                 + len(geo.mesh_faces))
                if _light_part(before) == _light_part(still):
                    return compiled, REUSE_ALL
                table, ambient = light_rows(still)
                kept = _same_buffers(compiled.lights, table)
                if kept is not None:  # only colours or intensities changed
                    return dataclasses.replace(compiled, lights=kept, ambient=ambient,
                                               build_seconds=0.0), REUSE_LIGHT_BUFFERS
                lights = build_light_buffers(geo, compiled.materials, table, threads=threads)
                return dataclasses.replace(compiled, lights=lights, ambient=ambient,
                                           build_seconds=0.0), REUSE_GEOMETRY
        built, reused = self.memo.built, self.memo.reused
        prims_built, prims_reused = self.memo.primitives_built, self.memo.primitives_reused
        with self.memo:
            compiled = compile_scene(still, threads=threads)
        self.stats.bvh_built += self.memo.built - built
        self.stats.bvh_reused += self.memo.reused - reused
        self.stats.primitives_built += self.memo.primitives_built - prims_built
        self.stats.primitives_reused += self.memo.primitives_reused - prims_reused
        return compiled, REUSE_BVH if self.memo.reused > reused else REUSE_NONE
