"""What the time series reports: ice volume, cavity volume, water volume, minimum shell
thickness, from a state (H, kind) on the grid."""

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


@dataclass
class Measures:
    time: float
    ice_volume: float  # m³
    cavity_volume: float  # m³: the space inside the inner surface
    water_volume: float  # m³: the cavity's water (its mass / rho_w)
    min_shell: float  # m: thinnest ice between cavity water and air (0 once breached)
    breached: bool


def measure(H: np.ndarray, kind: np.ndarray, dx: float, props: Properties, time: float,
            initial_cavity_volume: float, breached: bool) -> Measures:
    f = np.where(kind == 1, props.liquid_fraction(H), 0.0)
    body = kind == 1
    outer = outer_cells(kind)
    cell = dx ** 3
    ice = float(((1.0 - f) * body).sum()) * cell
    inner = body & ~outer
    cavity = float(f[inner].sum()) * cell
    melted_inside = cavity - initial_cavity_volume  # volume of ice that melted into it
    water = initial_cavity_volume + props.ice.rho / props.water.rho * melted_inside
    liquid = inner & (f >= 0.5)
    if breached or not liquid.any():
        shell = 0.0
    else:
        not_air = np.pad(kind == 1, 1, constant_values=False)
        not_air[:, 0, :] = True  # the table is not air
        dist = ndimage.distance_transform_edt(not_air)[1:-1, 1:-1, 1:-1]
        shell = max(0.0, float(dist[liquid].min()) - 1.0) * dx
    return Measures(time, ice, cavity, min(water, cavity) if cavity > 0 else 0.0, shell,
                    breached)
