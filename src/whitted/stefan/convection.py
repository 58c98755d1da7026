"""Natural convection: the air's h per face of the block (``air.h = "auto"``) and the cavity
water's effective conductivity (``cavity.convection``), from published correlations.

Air (Incropera, DeWitt, Bergman & Lavine, *Fundamentals of Heat and Mass Transfer*, 7th ed.,
2011, section 9.6), properties at the film temperature (T_s + T_air)/2 from Table A.4, β = 1/T_f
(ideal gas), Ra_L = g β |T_s − T_air| L³ / (ν α):

* vertical faces, L = the block's height: Churchill & Chu (1975), Int. J. Heat Mass Transfer
  18, 1323 (Incropera eq. 9.26), all Ra_L:
  Nu = {0.825 + 0.387 Ra^(1/6) / [1 + (0.492/Pr)^(9/16)]^(8/27)}²;
* horizontal faces, L = area / perimeter: a face whose buoyant flow rises from it (the upper
  face of a hot plate, the lower face of a cold one) Nu = 0.54 Ra^(1/4) (10⁴-10⁷) and
  0.15 Ra^(1/3) (10⁷-10¹¹) (Lloyd & Moran 1974, ASME 74-WA/HT-66; Incropera eqs. 9.30, 9.31);
  the stable side (the upper face of a cold plate: the ice's top in warm air) Nu = 0.52 Ra^(1/5)
  (10⁴-10⁹, Pr ≥ 0.7; Radziemska & Lewandowski 2001; Incropera eq. 9.32).

Water in the cavity: a closed enclosure with a cold wall (0 °C) around warmer water; its
effective conductivity makes the bulk-to-wall coefficient of a sphere of conducting water,
(2π²/3) k_eff / D, the 2 Nu k / D of Catton's (1978) enclosure correlation (Proc. 6th Int.
Heat Transfer Conf., Toronto, vol. 6, 13; Incropera eq. 9.51 with H/L = 1):
Nu = 0.18 (Pr/(0.2 + Pr) Ra_L)^0.29, 10³ < Ra_L Pr/(0.2 + Pr), 10⁻³ < Pr < 10⁵, 1 ≤ H/L ≤ 2,
(Nu = 1 below: conduction), so k_eff = k max(1, 3 Nu / π²). The buoyancy is the largest
density difference present between the wall (0 °C) and the bulk water, from Kell's (1975)
equation of state (J. Chem. Eng. Data 20, 97), which has the density maximum at 3.98 °C:
Ra = g (Δρ/ρ) L³ / (ν α). Viscosity: the Vogel equation
μ = A exp(B / (T − C)), A = 0.02939 mPa s, B = 507.88 K, C = 149.3 K (Viswanath & Natarajan,
*Data Book on the Viscosity of Liquids*, 1989; 1.003 mPa s at 20 °C against the CRC's 1.002).
Sources and ranges of validity in docs/stefan.md.
"""

from __future__ import annotations

import math

G = 9.80665  # m/s², standard gravity
T0 = 273.15

# Incropera Table A.4, air at 1 atm: T (K), nu (m²/s), k (W/mK), alpha (m²/s), Pr
AIR_TABLE = (
    (200.0, 7.590e-6, 18.1e-3, 10.3e-6, 0.737),
    (250.0, 11.44e-6, 22.3e-3, 15.9e-6, 0.720),
    (300.0, 15.89e-6, 26.3e-3, 22.5e-6, 0.707),
    (350.0, 20.92e-6, 30.0e-3, 29.9e-6, 0.700),
    (400.0, 26.41e-6, 33.8e-3, 38.3e-6, 0.690),
    (450.0, 32.39e-6, 37.3e-3, 47.2e-6, 0.686),
    (500.0, 38.79e-6, 40.7e-3, 56.7e-6, 0.684),
)


def air_properties(t_film_c: float) -> tuple[float, float, float, float]:
    """(nu, k, alpha, Pr) of air at t_film_c °C: linear in Incropera's Table A.4."""
    t = min(max(t_film_c + T0, AIR_TABLE[0][0]), AIR_TABLE[-1][0])
    for lo, hi in zip(AIR_TABLE, AIR_TABLE[1:], strict=False):
        if t <= hi[0]:
            w = (t - lo[0]) / (hi[0] - lo[0])
            return tuple(a + w * (b - a) for a, b in zip(lo[1:], hi[1:], strict=True))  # type: ignore
    return AIR_TABLE[-1][1:]  # pragma: no cover


def rayleigh_air(t_surface: float, t_air: float, length: float) -> tuple[float, float, float]:
    """(Ra_L, Pr, k) of air over a surface at t_surface °C, properties at the film
    temperature, β = 1 / T_film."""
    film = 0.5 * (t_surface + t_air)
    nu, k, alpha, pr = air_properties(film)
    ra = G / (film + T0) * abs(t_surface - t_air) * length ** 3 / (nu * alpha)
    return ra, pr, k


def nusselt_vertical(ra: float, pr: float) -> float:
    """Churchill & Chu (1975), a vertical plate, every Ra_L (Incropera eq. 9.26)."""
    psi = (1.0 + (0.492 / pr) ** (9.0 / 16.0)) ** (8.0 / 27.0)
    return (0.825 + 0.387 * ra ** (1.0 / 6.0) / psi) ** 2


def nusselt_horizontal(ra: float, rising: bool) -> float:
    """A horizontal plate: ``rising`` (the buoyant flow leaves the face: a hot plate's upper
    face, a cold plate's lower face) Lloyd & Moran (1974), else the stable side, Nu =
    0.52 Ra^(1/5) (Incropera eqs. 9.30-9.32)."""
    if not rising:
        return 0.52 * ra ** 0.2
    return 0.54 * ra ** 0.25 if ra <= 1.0e7 else 0.15 * ra ** (1.0 / 3.0)


def face_coefficients(size: tuple[float, float, float], t_air: float,
                      t_surface: float = 0.0) -> tuple[float, ...]:
    """h (W/m²K) of the block's six faces (x-, x+, y-, y+, z-, z+; y is up) in still air at
    t_air for a surface at t_surface (0 °C: the melting ice): Churchill & Chu on the vertical
    faces (L = the height), the horizontal plate correlations on the top and the bottom
    (L = area / perimeter; the bottom stands on the table, whose own contact is ``table``:
    this h is for air under overhangs). Zero where the surface is at the air's temperature."""
    if t_surface == t_air:
        return (0.0,) * 6
    sx, sy, sz = size
    ra, pr, k = rayleigh_air(t_surface, t_air, sy)
    h_side = nusselt_vertical(ra, pr) * k / sy
    length = sx * sz / (2.0 * (sx + sz))
    ra_h, _, k_h = rayleigh_air(t_surface, t_air, length)
    cold = t_surface < t_air  # a cold plate: its lower face is the rising (unstable) side
    h_top = nusselt_horizontal(ra_h, rising=not cold) * k_h / length
    h_bottom = nusselt_horizontal(ra_h, rising=cold) * k_h / length
    return (h_side, h_side, h_bottom, h_top, h_side, h_side)


# --- water -------------------------------------------------------------------------------

def water_density(t_c: float) -> float:
    """Density of air-free water at 1 atm (kg/m³), Kell (1975) eq. 16, 0-150 °C."""
    num = (999.83952 + 16.945176 * t_c - 7.9870401e-3 * t_c ** 2 - 46.170461e-6 * t_c ** 3
           + 105.56302e-9 * t_c ** 4 - 280.54253e-12 * t_c ** 5)
    return num / (1.0 + 16.879850e-3 * t_c)


def water_viscosity(t_c: float) -> float:
    """Dynamic viscosity of water (Pa s): the Vogel equation (constants above)."""
    return 0.02939e-3 * math.exp(507.88 / (t_c + T0 - 149.3))


TEMPERATURE_OF_MAXIMUM_DENSITY = 3.983  # °C: the maximum of Kell's equation (999.972 kg/m³)


def density_span(t_a: float, t_b: float) -> float:
    """The largest density difference (kg/m³) between two water temperatures in [t_a, t_b]
    (Kell): the densest water present (3.98 °C when the range holds it) against the
    lightest. Between a 0 °C wall and 8.14 °C bulk, where ρ(0) = ρ(bulk), it is the 4 °C water
    of the boundary layer against both (0.13 kg/m³), never the false zero of
    |ρ(wall) − ρ(bulk)|."""
    lo, hi = min(t_a, t_b), max(t_a, t_b)
    values = [water_density(lo), water_density(hi)]
    if lo < TEMPERATURE_OF_MAXIMUM_DENSITY < hi:
        values.append(water_density(TEMPERATURE_OF_MAXIMUM_DENSITY))
    return max(values) - min(values)


def rayleigh_water(t_bulk: float, length: float, k: float, rho_c: float,
                   t_wall: float = 0.0) -> tuple[float, float]:
    """(Ra_L, Pr) of water at t_bulk °C in an enclosure of size ``length`` with walls at
    t_wall: buoyancy from the largest density difference present between the wall and the
    bulk (:func:`density_span`, Kell's equation, the 3.98 °C maximum included), ν and Pr at
    the mean of the two, α = k / (ρ c) of the case."""
    mean = 0.5 * (t_bulk + t_wall)
    rho = water_density(mean)
    drho = density_span(t_wall, t_bulk) / rho
    nu = water_viscosity(mean) / rho
    alpha = k / rho_c
    return G * drho * length ** 3 / (nu * alpha), nu / alpha


def nusselt_enclosure(ra: float, pr: float) -> float:
    """Catton (1978), an enclosure of aspect ratio 1-2 (Incropera eq. 9.51); 1 (conduction)
    below its range (Ra Pr / (0.2 + Pr) < 10³)."""
    x = pr / (0.2 + pr) * ra
    if x < 1.0e3:
        return 1.0
    return max(1.0, 0.18 * x ** 0.29)


SPHERE_MODE = math.pi ** 2 / 3.0  # (2π²/3) k / D: a conducting sphere's bulk-to-wall h, × D / 2k


def wall_coefficient(t_bulk: float, length: float, k: float, rho_c: float) -> float:
    """The bulk-to-wall heat transfer coefficient (W/m²K) Catton's correlation implies: its Nu
    is the wall-to-wall flux over k ΔT / L, and the bulk sits halfway (ΔT / 2 from each wall),
    so h = 2 Nu k / L."""
    ra, pr = rayleigh_water(t_bulk, length, k, rho_c)
    return 2.0 * nusselt_enclosure(ra, pr) * k / length


def water_conductivity(t_bulk: float, length: float, k: float, rho_c: float) -> float:
    """k_eff of the cavity's water at a mean t_bulk °C inside walls at 0 °C, for a sphere of
    diameter ``length`` cooled all round: a conducting sphere's slowest mode gives a
    bulk-to-wall coefficient (2π²/3) k_eff / D, which k_eff = k · 3 Nu / π² makes the
    correlation's 2 Nu k / D (:func:`wall_coefficient`); never below k (conduction)."""
    ra, pr = rayleigh_water(t_bulk, length, k, rho_c)
    return k * max(1.0, nusselt_enclosure(ra, pr) / SPHERE_MODE)


class CavityConvection:
    """The cavity water's effective conductivity, refreshed every ``interval`` seconds of
    simulated time (a whole number of steps, ``every``) from the field: the largest body of
    all-liquid cells, its mean temperature and its equivalent diameter (6 V / π)^(1/3) as
    Catton's L, k_eff = k max(1, 3 Nu / π²) (:func:`water_conductivity`), at most ``k_max``
    (the value the time step was chosen for).
    The kernels have one water conductivity: every all-liquid cell takes the cavity's k_eff
    (open meltwater drains at once, so in practice the cavity is the only liquid region)."""

    def __init__(self, k: float, rho_c: float, k_max: float, interval: float = 2.0) -> None:
        self.k = float(k)
        self.rho_c = float(rho_c)
        self.k_max = float(k_max)
        self.interval = float(interval)  # s: the solver refreshes k_eff every this often
        self.every = 1  # steps (set by the solver from its time step)
        self.last = (float("nan"), float("nan"), float(k))  # mean T, L, k_eff

    def conductivity(self, H, kind, dx: float, props) -> float:
        import numpy as np
        from scipy import ndimage

        wet = (kind == 1) & (props.latent_per_volume <= H)
        labels, n = ndimage.label(wet)
        if n == 0:
            return self.k
        sizes = np.bincount(labels.ravel())[1:]
        region = labels == 1 + int(np.argmax(sizes))
        t_mean = float(props.temperature(H[region]).mean())
        length = (6.0 * float(sizes.max()) * dx ** 3 / math.pi) ** (1.0 / 3.0)
        k_eff = min(self.k_max, water_conductivity(t_mean, length, self.k, self.rho_c))
        self.last = (t_mean, length, k_eff)
        return k_eff


def largest_conductivity(t_cavity: float, length: float, k: float, rho_c: float) -> float:
    """The largest k_eff of water between 0 °C and t_cavity (the time step's bound)."""
    return max(water_conductivity(t_cavity * q / 200.0, length, k, rho_c) for q in range(201))


__all__ = ["CavityConvection", "TEMPERATURE_OF_MAXIMUM_DENSITY", "air_properties",
           "density_span", "wall_coefficient", "face_coefficients", "largest_conductivity",
           "nusselt_enclosure", "nusselt_horizontal", "nusselt_vertical", "rayleigh_air",
           "rayleigh_water", "water_conductivity", "water_density", "water_viscosity"]
