"""What a room does to the ice's outer surface besides convection: radiation exchange with the
surroundings and condensation of the air's water vapour (heat-mass transfer analogy).

Both enter the solver as one effective film: ``h_eff = h + h_rad`` toward
``T_eff = (h T_air + h_rad T_sur + q_cond) / h_eff``. For a surface at the melting point
(0 °C: the outer surface while it melts) this carries exactly

    q = h (T_air - 0) + eps sigma (T_sur^4 - T_0^4) + h_m L_v (rho_v,air - rho_v,sat(0 °C))

with h_rad = eps sigma (T_sur^4 - T_0^4) / (T_sur - T_0) (the secant at 0 °C; absolute
temperatures) and h_m = h / (rho_a c_p,a Le^(2/3)) (Chilton-Colburn analogy: Incropera et al.,
*Fundamentals of Heat and Mass Transfer*, 6th ed., eq. 6.92). A colder surface (the block
before it starts to melt) gets the same film linearised about 0 °C. Sources in docs/stefan.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

SIGMA = 5.670374419e-8  # W/m²K⁴, Stefan-Boltzmann constant (CODATA 2018)
T0 = 273.15  # K
EMISSIVITY_ICE = 0.97  # Incropera et al., Table A.11 (ice: 0.95-0.98)
R_VAPOUR = 461.5  # J/kgK, water vapour
R_AIR = 287.05  # J/kgK, dry air
CP_AIR = 1007.0  # J/kgK at 300 K (Incropera Table A.4)
LEWIS = 0.87  # alpha_air / D_H2O-air: 22.5e-6 / 0.26e-4 m²/s at 298 K (Incropera A.4, A.8)
L_VAPORISATION = 2.501e6  # J/kg at 0 °C (condensing to water on a melting surface)
PRESSURE = 101325.0  # Pa


def saturation_pressure(t_c: float) -> float:
    """Saturation vapour pressure over water (Pa) at t_c °C: Buck (1981), J. Appl. Meteor. 20,
    1527, 'ew1' (0.05 % from -40 to 50 °C)."""
    return 611.21 * math.exp((18.678 - t_c / 234.5) * (t_c / (257.14 + t_c)))


def vapour_density(t_c: float, relative_humidity: float) -> float:
    """Water vapour density (kg/m³) of air at t_c °C and a relative humidity (0-1)."""
    return relative_humidity * saturation_pressure(t_c) / (R_VAPOUR * (t_c + T0))


def radiation_coefficient(t_sur: float, emissivity: float) -> float:
    """h_rad (W/m²K): the secant of eps sigma (T^4 - T_0^4) between 0 °C and t_sur °C."""
    ts = t_sur + T0
    if abs(t_sur) < 1e-9:
        return 4.0 * emissivity * SIGMA * T0 ** 3
    return emissivity * SIGMA * (ts ** 4 - T0 ** 4) / t_sur


def condensation_flux(h: float, t_air: float, relative_humidity: float) -> float:
    """Latent heat (W/m²) released by vapour condensing on a surface at 0 °C (negative:
    evaporation/sublimation into dry air)."""
    film = 0.5 * t_air  # film temperature, °C
    rho_air = PRESSURE / (R_AIR * (film + T0))
    h_m = h / (rho_air * CP_AIR * LEWIS ** (2.0 / 3.0))
    return h_m * L_VAPORISATION * (vapour_density(t_air, relative_humidity)
                                   - vapour_density(0.0, 1.0))


@dataclass(frozen=True)
class Film:
    """The outer surface's effective film: coefficient (W/m²K) and far temperature (°C), and
    the three parts of the flux into a surface at 0 °C (W/m²)."""

    h: float
    temperature: float
    convection: float
    radiation: float
    condensation: float


def outer_film(t_air: float, h: float, *, t_sur: float | None = None,
               emissivity: float = EMISSIVITY_ICE, relative_humidity: float = 0.0) -> Film:
    t_sur = t_air if t_sur is None else t_sur
    h_rad = radiation_coefficient(t_sur, emissivity) if emissivity > 0 else 0.0
    q_cond = condensation_flux(h, t_air, relative_humidity) if relative_humidity > 0 else 0.0
    h_eff = h + h_rad
    if h_eff == 0.0:  # no film at all ("auto" in air at 0 °C, no radiation)
        return Film(0.0, t_air, 0.0, 0.0, q_cond)
    return Film(h_eff, (h * t_air + h_rad * t_sur + q_cond) / h_eff, h * t_air, h_rad * t_sur,
                q_cond)


__all__ = ["Film", "condensation_flux", "outer_film", "radiation_coefficient",
           "saturation_pressure", "vapour_density"]
