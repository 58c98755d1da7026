"""Exact similarity solutions of the Stefan problem (Neumann), for validation.

Melting of a half space x > 0 of ice by a wall at x = 0 held at ``T_w`` > 0 °C: the front is
at ``s(t) = 2 lambda sqrt(alpha_w t)``. lambda is the root of a transcendental equation, found
here with SciPy's Brent solver (no tabulated value is used).

One phase (the ice at 0 °C): ``lambda exp(lambda²) erf(lambda) = St / sqrt(pi)`` with the
Stefan number ``St = rho_w c_w (T_w - 0) / (rho_i L)`` (latent heat per volume of ice; with one
density it is the textbook ``c (T_w - T_m) / L``).

Two phases (ice initially at ``T_i`` < 0), energy balance at the front per volume of ice:
``rho_i L ds/dt = -k_w dT_w/dx + k_i dT_i/dx``, which gives

``k_w dT_l exp(-l²) / (erf(l) sqrt(pi alpha_w)) - k_i dT_s exp(-l² nu²) / (erfc(l nu)
sqrt(pi alpha_i)) = rho_i L l sqrt(alpha_w)`` with ``nu = sqrt(alpha_w / alpha_i)``.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq
from scipy.special import erf, erfc

from .properties import Properties


def one_phase_lambda(stefan: float) -> float:
    """lambda of the one-phase Neumann problem for the Stefan number ``stefan`` > 0."""
    if stefan <= 0:
        raise ValueError("the Stefan number must be positive")

    def residual(lam: float) -> float:
        return lam * math.exp(lam * lam) * math.erf(lam) - stefan / math.sqrt(math.pi)

    return brentq(residual, 1e-12, 10.0, xtol=1e-15, rtol=1e-15)


def two_phase_lambda(props: Properties, wall: float, initial: float) -> float:
    """lambda of the two-phase Neumann problem: wall at ``wall`` °C (> 0), ice at ``initial``
    °C (<= 0), front condition with the latent heat per volume of ice."""
    ice, water = props.ice, props.water
    a_w, a_i = water.diffusivity, ice.diffusivity
    nu = math.sqrt(a_w / a_i)
    d_l, d_s = wall, -initial

    def residual(lam: float) -> float:
        liquid = water.k * d_l * math.exp(-lam * lam) / (math.erf(lam) * math.sqrt(math.pi * a_w))
        solid = ice.k * d_s * math.exp(-(lam * nu) ** 2) / (
            math.erfc(lam * nu) * math.sqrt(math.pi * a_i))
        return liquid - solid - props.latent_per_volume * lam * math.sqrt(a_w)

    return brentq(residual, 1e-9, 5.0, xtol=1e-15, rtol=1e-15)


def front(lam: float, props: Properties, t: float | np.ndarray) -> float | np.ndarray:
    """Front position s(t) = 2 lambda sqrt(alpha_w t) (m)."""
    return 2.0 * lam * np.sqrt(props.water.diffusivity * np.asarray(t, dtype=np.float64))


def two_phase_temperature(props: Properties, wall: float, initial: float, x: np.ndarray,
                          t: float) -> np.ndarray:
    """The exact temperature field of the two-phase problem at time t (for the far-field
    check: how far the thermal wave has gone)."""
    lam = two_phase_lambda(props, wall, initial)
    a_w, a_i = props.water.diffusivity, props.ice.diffusivity
    s = float(front(lam, props, t))
    nu = math.sqrt(a_w / a_i)
    liquid = wall - wall * erf(x / (2 * math.sqrt(a_w * t))) / math.erf(lam)
    solid = initial - initial * erfc(x / (2 * math.sqrt(a_i * t))) / math.erfc(lam * nu)
    return np.where(x < s, liquid, solid)


def wave_reach(props: Properties, t: float, tolerance: float = 1e-6) -> float:
    """Distance beyond which the ice's temperature has changed by less than ``tolerance`` of
    the initial difference by time t: ``erfc(x / 2 sqrt(alpha_i t)) = tolerance``."""
    from scipy.special import erfcinv

    return float(2.0 * math.sqrt(props.ice.diffusivity * t) * erfcinv(tolerance))


def stefan_number_wall(props: Properties, stefan: float) -> float:
    """The wall temperature (°C) that gives the one-phase Stefan number ``stefan``."""
    return stefan * props.latent_per_volume / props.water.capacity
