"""The case's initial state on the grid, and where each cell sits in the world.

World axes: y up, the table is the plane y = 0, the block's centre is above the origin. The
grid is the block's bounding box with one air cell on the four sides and two above; its
bottom face is the table. Cells are cubes of side ``case.dx``; a cell is ice (or water) when
its centre is inside the rounded block (or the cavity): a staircase of cells, as the
enthalpy method on a fixed grid has it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .case import Case

PAD_SIDE = 1
PAD_TOP = 2


@dataclass(frozen=True)
class GridFrame:
    """Shape of the cell grid, cell side and the world position of cell (0, 0, 0)'s corner."""

    shape: tuple[int, int, int]
    dx: float
    origin: tuple[float, float, float]

    def centres(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """World coordinates of the cell centres along x, y, z (1-D arrays)."""
        return tuple(self.origin[a] + (np.arange(self.shape[a]) + 0.5) * self.dx
                     for a in range(3))  # type: ignore[return-value]

    def to_world(self, index_points: np.ndarray) -> np.ndarray:
        """Points in cell-index units (cell centres at integers) -> world metres."""
        return np.asarray(self.origin) + (np.asarray(index_points) + 0.5) * self.dx


def grid_frame(case: Case) -> GridFrame:
    dx = case.dx
    n = [int(np.ceil(s / dx - 1e-9)) for s in case.block.size]
    shape = (n[0] + 2 * PAD_SIDE, n[1] + PAD_TOP, n[2] + 2 * PAD_SIDE)
    origin = (-0.5 * shape[0] * dx, 0.0, -0.5 * shape[2] * dx)
    return GridFrame(shape, dx, origin)


def rounded_box_distance(p: np.ndarray, half: np.ndarray, radius: float) -> np.ndarray:
    """Signed distance from points (..., 3) to a box of half sizes ``half`` centred at the
    origin with edges rounded by ``radius`` (negative inside)."""
    q = np.abs(p) - (half - radius)
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=-1)
    inside = np.minimum(np.max(q, axis=-1), 0.0)
    return outside + inside - radius


def initial_state(case: Case) -> tuple[np.ndarray, np.ndarray, np.ndarray, GridFrame]:
    """Enthalpy per volume H, cell kind (1 body, 0 air) and the cavity mask at t = 0."""
    frame = grid_frame(case)
    props = case.properties
    x, y, z = frame.centres()
    X, Y, Z = np.meshgrid(x, y, z, indexing="ij")
    p = np.stack([X, Y, Z], axis=-1)
    half = 0.5 * np.asarray(case.block.size)
    centre = np.array([0.0, half[1], 0.0])
    body = rounded_box_distance(p - centre, half, case.block.edge_radius) <= 0.0
    cav = case.cavity
    c = centre + np.asarray(cav.center)
    if cav.shape == "sphere":
        cavity = np.linalg.norm(p - c, axis=-1) <= cav.radius
    else:
        cavity = np.all(np.abs(p - c) <= 0.5 * np.asarray(cav.size), axis=-1)
    cavity &= body
    H = np.zeros(frame.shape)
    H[body] = props.enthalpy(case.block.temperature, liquid=False)
    H[cavity] = props.enthalpy(case.cavity.temperature, liquid=True)
    return H, body.astype(np.uint8), cavity, frame
