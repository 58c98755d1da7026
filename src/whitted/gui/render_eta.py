"""The time left of a render, from the measured cost of its tiles rather than their count.

Tiles cost very different amounts (sky is one ray a pixel, glass dozens), so "35 % of the
tiles in 3 s" says little about the rest. The preview of the same scene has already traced
every part of the picture: :class:`CostMap` keeps, per preview pixel, the rays that its tiles
cost (each tile its own count, whichever batch of finished tiles it came in). The full
render's finished tiles then say which share of the whole *cost* is done, and

    time left = elapsed × (cost of the tiles not yet done) / (cost of the tiles done)

No Qt: plain NumPy, fed from the render threads' progress reports."""

from __future__ import annotations

import numpy as np


class CostMap:
    """Rays per pixel of a ``width`` x ``height`` preview, learnt batch by batch."""

    def __init__(self, width: int, height: int) -> None:
        self.width, self.height = width, height
        self.density = np.zeros((height, width), np.float64)
        self.covered = np.zeros((height, width), bool)
        self._rays = 0

    def learn(self, tiles: np.ndarray, rays: int, tile_rays: np.ndarray | None = None) -> None:
        """A batch of finished ``tiles`` (rows of x0, y0, x1, y1) and the rays traced in all
        so far. With ``tile_rays`` (each tile's own rays) every tile gets its own cost; without,
        the rays since the last batch are spread over these tiles' pixels."""
        new, self._rays = max(rays - self._rays, 0), max(rays, self._rays)
        if tile_rays is not None and len(tile_rays) == len(tiles) and len(tiles):
            for (x0, y0, x1, y1), count in zip(tiles, tile_rays, strict=True):
                area = int((x1 - x0) * (y1 - y0))
                if area > 0:
                    self.density[y0:y1, x0:x1] = float(count) / area
                    self.covered[y0:y1, x0:x1] = True
            return
        area = sum(int((x1 - x0) * (y1 - y0)) for x0, y0, x1, y1 in tiles)
        if area <= 0:
            return
        for x0, y0, x1, y1 in tiles:
            self.density[y0:y1, x0:x1] = new / area
            self.covered[y0:y1, x0:x1] = True

    @property
    def complete(self) -> bool:
        return bool(self.covered.all()) and float(self.density.sum()) > 0

    def scaled(self, width: int, height: int) -> np.ndarray:
        """The cost of each pixel of a ``width`` x ``height`` render of the same view (the
        preview's pixel that covers it; a share of the whole, summing to 1)."""
        ys = np.arange(height) * self.height // height
        xs = np.arange(width) * self.width // width
        full = self.density[ys][:, xs]
        return full / full.sum()


class CostClock:
    """The time left of one render: ``done(tiles)`` as tiles finish, ``eta(elapsed)``."""

    def __init__(self, costs: np.ndarray) -> None:
        self.costs = costs  # a share of the whole per render pixel (sums to 1)
        self.fraction = 0.0

    def done(self, tiles: np.ndarray) -> None:
        for x0, y0, x1, y1 in tiles:
            self.fraction += float(self.costs[y0:y1, x0:x1].sum())

    def eta(self, elapsed: float) -> float | None:
        """Seconds left; None until something measurable is done."""
        if self.fraction <= 1e-9:
            return None
        return max(elapsed * (1.0 - min(self.fraction, 1.0)) / self.fraction, 0.0)


__all__ = ["CostClock", "CostMap"]
