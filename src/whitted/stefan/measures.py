"""What the time series reports: ice volume, cavity volume, water volume, minimum shell
thickness, from a state (H, kind) on the grid.

The two regions a fixed grid does not tell apart by itself, sorted once (``regions``):

* the **cavity**: the cells at least half liquid without a face to the air (above the
  table's layer), the half-liquid cells next to them, and the partly melted cells around
  those (their melt came from the cavity's side). A cell next to the cavity stays the
  cavity's when the outer surface reaches it (the last cell of the shell), so the cavity's
  volume changes by melting and freezing, not by how cells are classified as the outer
  surface moves in.
* the **solid**: every body cell, at its ice fraction outside the cavity, full in it.

The cavity's volume is the liquid in the cavity's cells. The shell's thickness is the
distance between the two surfaces measured in ice: the least ice a path from the cavity's
water to the air crosses (``shell_thickness``), so it follows the cells' melting continuously
(the old measure counted whole cells by class and jumped: 0.52 mm at 2400 s, 1.25 mm at
2520 s at 32 cells). The table is not air.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from .properties import Properties

_FACES = ndimage.generate_binary_structure(3, 1)


def outer_cells(kind: np.ndarray) -> np.ndarray:
    """Body cells with a face to air (the outer surface's cells; their meltwater drains).
    Outside the grid counts as air on the four sides and the top, not the table (y-)."""
    air = np.pad(kind == 0, 1, constant_values=True)
    air[:, 0, :] = False  # the table
    near = ndimage.binary_dilation(air, structure=_FACES)[1:-1, 1:-1, 1:-1]
    return (kind == 1) & near


def regions(H: np.ndarray, kind: np.ndarray, props: Properties):
    """(liquid fraction f, cavity cells mask): see the module docstring."""
    body = kind == 1
    f = np.where(body, props.liquid_fraction(H), 0.0)
    wet = body & (f >= 0.5)
    seeds = wet & ~outer_cells(kind)
    seeds[:, 0, :] = False  # the table's layer melts from the table (a conducting one)
    core = seeds | (wet & ndimage.binary_dilation(seeds, structure=_FACES))
    rim = ndimage.binary_dilation(core, structure=_FACES) & body & (f > 0.0) & ~core
    return f, core | rim


@dataclass
class Measures:
    time: float
    ice_volume: float  # m³
    cavity_volume: float  # m³: the space inside the inner surface
    water_volume: float  # m³: the cavity's water (its mass / rho_w)
    min_shell: float  # m: thinnest ice between cavity water and air (0 once breached)
    breached: bool


def shell_thickness(f: np.ndarray, kind: np.ndarray, dx: float) -> float:
    """The thinnest ice between the cavity's water and the air (m): the least ice a path from
    the air to a cell of the cavity's water (all liquid, no face to the air, above the
    table's layer) crosses, each cell counting its ice fraction 1 - f: a geodesic over the 26
    neighbours, steps of length 1, sqrt 2, sqrt 3 weighted by the mean ice of the two cells
    (scikit-image's ``MCP_Geometric``), so a straight path through cells of ice fractions
    c_1..c_n measures c_1 + ... + c_n cells. It changes continuously as the cells melt (a
    cell draining or turning all liquid has no ice left). 0 when there is no such water or
    no air."""
    from skimage.graph import MCP_Geometric

    body = kind == 1
    air = ~body
    water = body & (f >= 1.0) & ~outer_cells(kind)
    water[:, 0, :] = False
    if not water.any() or not air.any():
        return 0.0
    cost = np.where(body, 1.0 - f, 0.0)
    mcp = MCP_Geometric(cost, fully_connected=True)
    cumulative, _ = mcp.find_costs(np.argwhere(air), np.argwhere(water), find_all_ends=False)
    best = float(cumulative[water].min())
    return best * dx if np.isfinite(best) else 0.0


def measure(H: np.ndarray, kind: np.ndarray, dx: float, props: Properties, time: float,
            initial_cavity_volume: float, breached: bool) -> Measures:
    f, cavity = regions(H, kind, props)
    body = kind == 1
    cell = dx ** 3
    ice = float(((1.0 - f) * body).sum()) * cell
    cavity_volume = float(f[cavity].sum()) * cell
    melted_inside = cavity_volume - initial_cavity_volume  # volume of ice that melted into it
    water = initial_cavity_volume + props.ice.rho / props.water.rho * melted_inside
    if breached or not cavity.any():
        shell = 0.0
    else:
        shell = shell_thickness(f, kind, dx)
    return Measures(time, ice, cavity_volume,
                    min(water, cavity_volume) if cavity_volume > 0 else 0.0, shell, breached)
