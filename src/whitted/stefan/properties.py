"""Material properties of ice and liquid water near 0 °C (SI units), with their sources.

The defaults are the values the two-phase validation uses:

========================  ==========  ====================================================
quantity                  value       source
========================  ==========  ====================================================
ice density               917 kg/m³   Engineering ToolBox, "Ice - Thermal Properties"
                                      (0 °C); CRC Handbook of Chemistry and Physics
ice heat capacity         2100 J/kgK  Engineering ToolBox (2.09 kJ/kgK at 0 °C, rounded)
ice conductivity          2.14 W/mK   Engineering ToolBox, "Ice - Thermal Properties"
                                      (2.22 at 0 °C; 2.14 is the value commonly quoted)
water density             1000 kg/m³  CRC Handbook (999.8 kg/m³ at 0 °C)
water heat capacity       4220 J/kgK  CRC Handbook (4.219 kJ/kgK at 0 °C)
water conductivity        0.56 W/mK   CRC Handbook (0.561 W/mK at 0 °C)
latent heat of fusion     333.6 kJ/kg CRC Handbook (333.55 kJ/kg)
melting temperature       0 °C        pure water at 1 atm
========================  ==========  ====================================================
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

LATENT_HEAT = 333.6e3  # J/kg
MELTING_POINT = 0.0  # °C; the solver's temperatures are Celsius, the melting point is 0


@dataclass(frozen=True)
class Phase:
    """One phase: density (kg/m³), specific heat capacity (J/kgK), conductivity (W/mK)."""

    rho: float
    c: float
    k: float

    @property
    def capacity(self) -> float:
        """Volumetric heat capacity rho*c (J/m³K)."""
        return self.rho * self.c

    @property
    def diffusivity(self) -> float:
        """Thermal diffusivity k/(rho*c) (m²/s)."""
        return self.k / (self.rho * self.c)


ICE = Phase(rho=917.0, c=2100.0, k=2.14)
WATER = Phase(rho=1000.0, c=4220.0, k=0.56)


@dataclass(frozen=True)
class Properties:
    """Ice, water and the latent heat: everything the enthalpy method needs.

    Enthalpy is per unit volume of the fixed grid and counted from ice at 0 °C:
    ``H = rho_i c_i T`` (T < 0), ``0..rho_i L`` at 0 °C (liquid fraction ``H / (rho_i L)``),
    ``rho_i L + rho_w c_w T`` above. See ``docs/stefan.md`` for why the latent heat is per
    volume of ice.
    """

    ice: Phase = ICE
    water: Phase = WATER
    latent_heat: float = LATENT_HEAT

    @property
    def latent_per_volume(self) -> float:
        """rho_i * L (J/m³): the enthalpy that melts one cubic metre of ice at 0 °C."""
        return self.ice.rho * self.latent_heat

    def as_array(self) -> np.ndarray:
        """The kernels' property vector: rho_i c_i, k_i, rho_w c_w, k_w, rho_i L."""
        return np.array([self.ice.capacity, self.ice.k, self.water.capacity, self.water.k,
                         self.latent_per_volume], dtype=np.float64)

    def enthalpy(self, temperature: float, liquid: bool) -> float:
        """The enthalpy per volume of a cell of ice (``liquid=False``) or water at a temperature."""
        if liquid:
            return self.latent_per_volume + self.water.capacity * max(temperature, 0.0)
        return self.ice.capacity * min(temperature, 0.0)

    def temperature(self, enthalpy: np.ndarray) -> np.ndarray:
        """Temperature (°C) from enthalpy per volume (vectorised, for analysis and tests), the
        kernels' arithmetic to the last bit (a product by the reciprocal capacity)."""
        h = np.asarray(enthalpy, dtype=np.float64)
        hl = self.latent_per_volume
        return np.where(h < 0.0, h * (1.0 / self.ice.capacity),
                        np.where(h > hl, (h - hl) * (1.0 / self.water.capacity), 0.0))

    def liquid_fraction(self, enthalpy: np.ndarray) -> np.ndarray:
        return np.clip(np.asarray(enthalpy, dtype=np.float64) / self.latent_per_volume, 0.0, 1.0)
