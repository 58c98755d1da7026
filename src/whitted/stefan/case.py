"""The case file: a hollow piece of ice in warm air, every parameter, validated (pydantic).

A mistake is one line naming the file, the line and the key (``CaseError``, a SceneError:
exit status 2 in the CLI). Lengths are metres, temperatures °C, times seconds.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from ..errors import SceneError
from .properties import ICE, LATENT_HEAT, WATER, Phase, Properties

# Strict types, as scene files have: a number is a TOML integer or float, never a string or a
# boolean (``h = true``, ``rho = "917"`` and ``cells = "16"`` are refused); a count is an integer.


def _num(**bounds: float):
    return Annotated[float, Field(strict=True, allow_inf_nan=False, **bounds)]


def _count(**bounds: int):
    return Annotated[int, Field(strict=True, **bounds)]


Positive = _num(gt=0.0)
Finite = _num()
Vec3 = tuple[Finite, Finite, Finite]
Length = _num(ge=1.0e-3, le=1.0)  # a block's side: 1 mm to 1 m
Size3 = tuple[Length, Length, Length]
CavitySize3 = tuple[Positive, Positive, Positive]

# Physical properties: documented ranges (docs/stefan.md), wide enough for ice from -80 °C to
# 0 °C and water from 0 to 100 °C with room for sensitivity studies, narrow enough that no value
# makes the method meaningless (1e-300 or 1e308 used to run and end at t = 0 or in overflow).
RANGES = {
    "ice.rho": (800.0, 1000.0), "ice.c": (1000.0, 4000.0), "ice.k": (1.0, 5.0),
    "water.rho": (900.0, 1100.0), "water.c": (3500.0, 5000.0), "water.k": (0.3, 1.0),
    "latent_heat": (2.5e5, 4.0e5),
}


class CaseError(SceneError):
    """A case file that cannot be used (one line: file, line, key, problem)."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class PhaseProperties(_Strict):
    """Density (kg/m³), specific heat capacity (J/kgK), thermal conductivity (W/mK), each in
    its documented range (``RANGES``; checked by the case, which knows which phase it is)."""

    rho: Positive
    c: Positive
    k: Positive

    def phase(self) -> Phase:
        return Phase(self.rho, self.c, self.k)


class Block(_Strict):
    """The piece of ice: a box of ``size`` (x, y, z; y is up) with edges rounded by
    ``edge_radius``, standing on the table, at ``temperature`` (<= 0 °C)."""

    size: Size3 = (0.04, 0.04, 0.04)
    edge_radius: _num(ge=0.0) = 0.004
    temperature: _num(ge=-80.0, le=0.0) = -5.0

    @model_validator(mode="after")
    def _radius_fits(self) -> Block:
        if self.edge_radius > 0.5 * min(self.size):
            raise ValueError(f"edge_radius {self.edge_radius:g} m is over half the block's "
                             f"smallest side ({0.5 * min(self.size):g} m)")
        return self


class Cavity(_Strict):
    """The closed cavity full of water: a sphere of ``radius`` or a box of ``size``, its
    centre ``center`` relative to the block's centre (off centre allowed). ``convection``:
    the water's natural convection, ``"effective"`` (or true: an effective conductivity from
    Catton's enclosure correlation and Kell's density with its 4 °C maximum,
    :mod:`whitted.stefan.convection`; fast), ``"flow"`` (the water's flow computed,
    Navier-Stokes with Kell's buoyancy coupled to the melt: :mod:`whitted.stefan.flow`), or
    ``"off"`` (or false: conduction only)."""

    shape: Literal["sphere", "box"] = "sphere"
    radius: Positive = 0.012
    size: CavitySize3 = (0.02, 0.02, 0.02)
    center: Vec3 = (0.0, 0.0, 0.0)
    temperature: _num(ge=0.0, le=100.0) = 20.0
    convection: Annotated[bool, Field(strict=True)] | Literal["effective", "flow", "off"] = True

    @property
    def model(self) -> str:
        """``"effective"``, ``"flow"`` or ``"off"`` (true and false name the first and last)."""
        if isinstance(self.convection, bool):
            return "effective" if self.convection else "off"
        return self.convection

    def half_extent(self) -> tuple[float, float, float]:
        if self.shape == "sphere":
            return (self.radius,) * 3
        return tuple(0.5 * s for s in self.size)  # type: ignore[return-value]


class Air(_Strict):
    """The room: air temperature (°C) and the convective heat transfer coefficient h (W/m²K:
    about 5-10 still air, 10-25 a gentle draught; ``"auto"``: still air, h per face from
    natural-convection correlations, :func:`whitted.stefan.convection.face_coefficients`);
    radiation with surroundings at
    ``surroundings`` °C (default: the air's) for ice of ``emissivity`` (0 turns it off); and
    condensation of the air's vapour at ``relative_humidity`` (0-1; 0 turns it off). See
    :mod:`whitted.stefan.room` and docs/stefan.md."""

    temperature: _num(ge=-80.0, le=200.0) = 25.0
    h: _num(gt=0.0, le=1.0e4) | Literal["auto"] = 20.0
    surroundings: _num(ge=-80.0, le=200.0) | None = None
    emissivity: _num(ge=0.0, le=1.0) = 0.97
    relative_humidity: _num(ge=0.0, le=1.0) = 0.3

    @field_validator("h", mode="before")
    @classmethod
    def _h_word(cls, value):
        if isinstance(value, str) and value != "auto":
            raise ValueError(f'{value!r}: use a number (W/m²K) or "auto"')
        return value


class Table(_Strict):
    """The bottom face: ``adiabatic`` (an insulating table) or ``conducting`` (a contact
    conductance ``h`` to a table at ``temperature``; meltwater there drains)."""

    contact: Literal["adiabatic", "conducting"] = "adiabatic"
    temperature: _num(ge=-80.0, le=200.0) = 20.0
    h: _num(gt=0.0, le=1.0e5) = 100.0


class Grid(_Strict):
    """``cells`` along the block's longest side (cubic cells)."""

    cells: _count(ge=8, le=100_000) = 64


class Time(_Strict):
    """Simulated time to ``end`` (s), a saved state every ``save_every`` s; the time step is
    ``cfl`` times the stability limit unless ``dt`` is given (it must be under the limit)."""

    end: _num(gt=0.0, le=1.0e7) = 3600.0
    save_every: Positive = 120.0
    dt: Positive | None = None
    cfl: _num(gt=0.0, le=1.0) = 0.9


class Breach(_Strict):
    """What happens when the shell opens: ``stop`` (report the time) or ``drain`` (the cavity
    water runs out through the hole and the melt goes on)."""

    action: Literal["stop", "drain"] = "stop"


class Surfaces(_Strict):
    """Surface extraction: Taubin smoothing passes, and the fraction of faces to keep (1: no
    decimation)."""

    smoothing: _count(ge=0, le=200) = 10
    keep: _num(gt=0.0, le=1.0) = 1.0


class Case(_Strict):
    """A Stefan case: everything the solver and the surfaces need."""

    ice: PhaseProperties = PhaseProperties(rho=ICE.rho, c=ICE.c, k=ICE.k)
    water: PhaseProperties = PhaseProperties(rho=WATER.rho, c=WATER.c, k=WATER.k)
    latent_heat: Positive = LATENT_HEAT
    block: Block = Block()
    cavity: Cavity = Cavity()
    air: Air = Air()
    table: Table = Table()
    grid: Grid = Grid()
    time: Time = Time()
    breach: Breach = Breach()
    surfaces: Surfaces = Surfaces()

    @property
    def properties(self) -> Properties:
        return Properties(self.ice.phase(), self.water.phase(), self.latent_heat)

    @property
    def dx(self) -> float:
        return max(self.block.size) / self.grid.cells

    def check(self) -> list[tuple[str, str]]:
        """Physical checks beyond single values: (key, problem) pairs, empty when fine."""
        problems: list[tuple[str, str]] = []
        for key, (low, high) in RANGES.items():
            value = self.latent_heat if key == "latent_heat" else getattr(
                getattr(self, key.split(".")[0]), key.split(".")[1])
            if not low <= value <= high:
                problems.append((key, f"{value:g} is outside the documented range {low:g} to "
                                 f"{high:g} (docs/stefan.md)"))
        if problems:
            return problems
        b, cav = self.block, self.cavity
        dx = self.dx
        half = [0.5 * s for s in b.size]
        ext = cav.half_extent()
        # the block's centre is at half its height; the cavity must sit inside with a shell
        shell = min(half[a] - (abs(cav.center[a]) + ext[a]) for a in range(3))
        if shell <= 0.0:
            where = "cavity.center" if any(cav.center) else (
                "cavity.radius" if cav.shape == "sphere" else "cavity.size")
            problems.append((where, f"the cavity reaches outside the block (shell "
                             f"{shell * 1e3:.3g} mm)"))
        elif shell < 2.0 * dx:
            problems.append(("grid.cells", f"{self.grid.cells} cells make {dx * 1e3:.3g} mm "
                             f"cells: too coarse for the {shell * 1e3:.3g} mm shell (needs 2 "
                             "cells across it)"))
        if (self.air.temperature <= 0.0 and cav.temperature <= 0.0
                and (self.table.contact == "adiabatic" or self.table.temperature <= 0.0)):
            problems.append(("air.temperature", "nothing melts: the air, the cavity water and "
                             "the table are all at or below 0 °C"))
        if self.time.dt is not None:
            from .solver import stability_limit

            limit = stability_limit(self.solver_properties(), dx, 3, self.solver_faces(),
                                    self.solver_air())
            if self.time.dt > limit:
                problems.append(("time.dt", f"{self.time.dt:g} s is over the stability limit "
                                 f"{limit:.4g} s of {dx * 1e3:.3g} mm cells"))
        if self.time.save_every > self.time.end:
            problems.append(("time.save_every", f"{self.time.save_every:g} s is longer than "
                             f"time.end ({self.time.end:g} s)"))
        return problems

    def solver_air(self):
        """The solver's air: convection, radiation and condensation as one effective film
        (:func:`whitted.stefan.room.outer_film`)."""
        from .room import outer_film
        from .solver import Air as SolverAir

        a = self.air
        if a.h == "auto":  # natural convection per face, for the melting surface at 0 °C
            from .convection import face_coefficients

            films = [outer_film(a.temperature, h, t_sur=a.surroundings,
                                emissivity=a.emissivity, relative_humidity=a.relative_humidity)
                     for h in face_coefficients(self.block.size, a.temperature)]
            return SolverAir(a.temperature, max(f.h for f in films),
                             tuple((f.h, f.temperature) for f in films))
        film = outer_film(a.temperature, a.h, t_sur=a.surroundings, emissivity=a.emissivity,
                          relative_humidity=a.relative_humidity)
        return SolverAir(film.temperature, film.h)

    def condensation_share(self) -> float:
        """The share of the heat into the melting (0 °C) outer surface that the condensing
        vapour brings (0 without humidity): per face direction with ``air.h = "auto"``,
        weighted by the block's face areas in air (its four sides and top)."""
        from .room import outer_film

        a = self.air
        if a.h == "auto":
            from .convection import face_coefficients

            hs = face_coefficients(self.block.size, a.temperature)
            sx, sy, sz = self.block.size
            areas = (sy * sz, sy * sz, 0.0, sx * sz, sx * sy, sx * sy)  # y- is the table
        else:
            hs, areas = (a.h,), (1.0,)
        cond = total = 0.0
        for h, area in zip(hs, areas, strict=True):
            f = outer_film(a.temperature, h, t_sur=a.surroundings, emissivity=a.emissivity,
                           relative_humidity=a.relative_humidity)
            cond += area * f.condensation
            total += area * (f.convection + f.radiation + f.condensation)
        return cond / total if total > 0.0 and cond > 0.0 else 0.0

    def cavity_length(self) -> float:
        """The cavity's equivalent diameter (6 V / π)^(1/3) (m): Catton's L."""
        import math

        cav = self.cavity
        volume = (4.0 / 3.0 * math.pi * cav.radius ** 3 if cav.shape == "sphere"
                  else cav.size[0] * cav.size[1] * cav.size[2])
        return (6.0 * volume / math.pi) ** (1.0 / 3.0)

    def solver_properties(self) -> Properties:
        """The properties the solver steps with: with ``cavity.convection`` the water's
        conductivity is the largest k_eff the cavity can reach (the time step's bound; the
        solver refreshes the actual one, :meth:`solver_convection`)."""
        props = self.properties
        if self.cavity.model != "effective":
            return props
        from .convection import largest_conductivity

        w = props.water
        k_max = largest_conductivity(self.cavity.temperature, self.cavity_length(), w.k,
                                     w.capacity)
        return Properties(props.ice, Phase(w.rho, w.c, max(w.k, k_max)), props.latent_heat)

    def solver_convection(self):
        """The solver's effective cavity convection (None unless ``cavity.convection`` is
        ``"effective"``)."""
        if self.cavity.model != "effective":
            return None
        from .convection import CavityConvection

        w = self.properties.water
        return CavityConvection(w.k, w.capacity, self.solver_properties().water.k)

    def solver_flow(self, H, kind):
        """The cavity water's flow (:class:`whitted.stefan.flow.MeltFlow`) when
        ``cavity.convection`` is ``"flow"``, else None: solved in the box of the liquid cells
        of ``H`` (unpadded) widened by half the shell and two cells each way."""
        if self.cavity.model != "flow":
            return None
        import math

        import numpy as np

        from .flow import MeltFlow, cavity_box

        props = self.properties
        liquid = (np.asarray(kind) == 1) & (np.asarray(H) >= props.latent_per_volume)
        half = [0.5 * s for s in self.block.size]
        ext = self.cavity.half_extent()
        shell = min(half[a] - (abs(self.cavity.center[a]) + ext[a]) for a in range(3))
        margin = 2 + int(math.ceil(0.5 * shell / self.dx))
        return MeltFlow(cavity_box(liquid, margin), self.dx, props)

    def solver_faces(self):
        from .solver import Faces

        faces = Faces.adiabatic()
        if self.table.contact == "conducting":
            faces.set("y-", self.table.h, self.table.temperature, drain=True)
        return faces


def _error_from_validation(exc: ValidationError, file: str | None, text: str | None) -> CaseError:
    from ..scene.messages import clean_loc, clean_message, format_path, toml_line

    best = max(exc.errors(), key=lambda e: len(e["loc"]))
    keys = clean_loc(best["loc"])
    message = "unknown key" if best["type"] == "extra_forbidden" else clean_message(best)
    line = toml_line(text, keys) if text and keys else None
    return CaseError(message, file=file, where=format_path(keys) or None, line=line)


def case_from_dict(data: dict, *, file: str | None = None, text: str | None = None) -> Case:
    """Validate a case; raises :class:`CaseError` on the first problem."""
    from ..scene.messages import parse_path, toml_line

    try:
        case = Case.model_validate(data)
    except ValidationError as exc:
        raise _error_from_validation(exc, file, text) from None
    problems = case.check()
    if problems:
        where, message = problems[0]
        line = toml_line(text, parse_path(where)) if text else None
        raise CaseError(message, file=file, where=where, line=line)
    return case


def load_case(path: str | Path) -> Case:
    """Read and validate a case file (TOML)."""
    path = Path(path)
    name = str(path)
    if not path.exists():
        raise CaseError("no such file", file=name)
    if path.suffix.lower() != ".toml":
        raise CaseError(f"unknown case format {path.suffix!r} (use .toml)", file=name)
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise CaseError("not UTF-8 text", file=name) from None
    except OSError as exc:
        raise CaseError(f"cannot read: {exc.strerror}", file=name) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        line = getattr(exc, "lineno", None)
        msg = str(exc).split(" (at line")[0]
        raise CaseError(f"not valid TOML: {msg}", file=name, line=line) from None
    return case_from_dict(data, file=name, text=text)


def case_digest(case: Case) -> str:
    """A short hash of everything that changes the solution (to refuse a resume that would
    mix two cases)."""
    import hashlib

    return hashlib.sha256(case.model_dump_json().encode()).hexdigest()[:16]


__all__ = ["Case", "CaseError", "case_digest", "case_from_dict", "load_case"]
