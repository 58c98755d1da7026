"""Before any work: what a case will cost (memory, steps, disk) and whether to refuse it.

The estimate comes from the case alone (no array is allocated): the grid's cell count, the
time step the solver will take (``cfl`` times the stability limit, or ``time.dt``), the number
of saved times and what each one writes. A case over a **hard** limit (the machine's memory,
the free space where the run writes) is refused; one over a **soft** limit (``SOFT_LIMITS``:
sane bounds for an interactive tool) is refused unless the caller allows it (``whitted stefan
run --allow-large``). The refusal is one line naming the key, the estimate and the limit.
"""

from __future__ import annotations

import math
import os
import shutil
from dataclasses import dataclass
from pathlib import Path

from .case import Case, CaseError

#: Bytes of memory per grid cell at the peak (the initial state's coordinates, the solver's two
#: enthalpy buffers, kinds and surface lists, and a save's fields, distance transform and
#: marching cubes), measured at 32-96 cells (docs/stefan.md) and rounded up; plus the process.
BYTES_PER_CELL = 220
BASE_BYTES = 400 * 2**20
#: Bytes a saved time writes per grid cell at most: the state (float64 H, uint8 kind, float32
#: liquid fraction and temperature, before compression) and both surfaces (bounded by cells).
DISK_PER_CELL = 17 + 8
DISK_PER_SAVE = 16 * 2**10  # the scene file, a row of the series
#: Cell updates per second the documentation's figures assume (2 cores); for the time estimate.
CELL_UPDATES_PER_SECOND = 50e6

#: A flow box cell's cost in enthalpy cell updates (``cavity.convection = "flow"``): each
#: part of the predictor (three components) and, once a step, the projection with what goes
#: with it (the multigrid-preconditioned pressure, the divergence and correction, the carried
#: heat, the fields). Measured on the default case at 48 cells (docs/stefan.md: one thread,
#: CPU seconds per phase over 200 steps): 2.1 and 19.5 with 13 700 fluid cells in the 41³
#: box, rounded up for the cavity's growth. The projection's cost is spread over the
#: ``FLOW_EVERY`` enthalpy steps of a flow step.
FLOW_PREDICT_COST = 2.5
FLOW_PROJECT_COST = 24.0

SOFT_LIMITS = {
    "cell_updates": 1.0e12,  # about 5.5 h at 50 M cell updates/s
    "steps": 1.0e8,
    "saves": 100_000,
    "disk_bytes": 50 * 2**30,
}


@dataclass(frozen=True)
class Estimate:
    cells: int  # grid cells
    shape: tuple[int, int, int]
    dt: float  # s
    steps: int
    saves: int
    memory_bytes: int
    disk_bytes: int
    #: with ``cavity.convection = "flow"``: the flow box's cells, its predictor's parts a
    #: flow step (one projection each) and the enthalpy steps a flow step spans
    flow_cells: int = 0
    flow_substeps: int = 0
    flow_every: int = 1

    @property
    def cell_updates(self) -> float:
        """Enthalpy cell updates, the flow's counted in them (``FLOW_PREDICT_COST`` a box
        cell and predictor part, ``FLOW_PROJECT_COST`` a box cell and step)."""
        flow = (self.flow_cells * (FLOW_PREDICT_COST * self.flow_substeps + FLOW_PROJECT_COST)
                / max(1, self.flow_every))
        return (float(self.cells) + (flow if self.flow_cells else 0.0)) * self.steps

    @property
    def seconds(self) -> float:
        return self.cell_updates / CELL_UPDATES_PER_SECOND


def grid_shape(case: Case) -> tuple[int, int, int]:
    from .geometry import PAD_SIDE, PAD_TOP

    n = [int(math.ceil(s / case.dx - 1e-9)) for s in case.block.size]
    return (n[0] + 2 * PAD_SIDE, n[1] + PAD_TOP, n[2] + 2 * PAD_SIDE)


def time_step(case: Case) -> float:
    from .solver import stability_limit

    if case.time.dt is not None:
        return case.time.dt
    limit = stability_limit(case.solver_properties(), case.dx, 3, case.solver_faces(),
                            case.solver_air())
    return case.time.cfl * limit


def estimate(case: Case) -> Estimate:
    """What solving ``case`` will cost, from the case alone."""
    shape = grid_shape(case)
    cells = shape[0] * shape[1] * shape[2]
    dt = time_step(case)
    steps = math.ceil(case.time.end / dt) if dt > 0 else math.inf
    saves = math.ceil(case.time.end / case.time.save_every) + 1
    memory = BASE_BYTES + BYTES_PER_CELL * cells
    disk = saves * (DISK_PER_CELL * cells + DISK_PER_SAVE)
    flow_cells = substeps = 0
    every = 1
    if case.cavity.model == "flow":  # the box around the cavity (Case.solver_flow), at rest
        from .convection import water_density, water_viscosity

        half = [0.5 * s for s in case.block.size]
        ext = case.cavity.half_extent()
        shell = min(half[a] - (abs(case.cavity.center[a]) + ext[a]) for a in range(3))
        margin = 2 + int(math.ceil(0.5 * shell / case.dx))
        flow_cells = 1
        for a in range(3):
            flow_cells *= min(shape[a], int(math.ceil(2 * ext[a] / case.dx)) + 2 * margin)
        from .flow import FLOW_EVERY

        every = FLOW_EVERY
        nu = water_viscosity(2.0) / water_density(2.0)
        substeps = (max(1, math.ceil(every * dt / (0.9 * case.dx ** 2 / (6.0 * nu))))
                    if dt > 0 else 1)
        memory += 200 * flow_cells  # 3 velocities and their copies, scratch, the levels
    return Estimate(cells, shape, dt, int(min(steps, 2**62)), int(saves), int(memory), int(disk),
                    flow_cells, substeps, every)


def describe(e: Estimate, case: Case) -> str:
    """One line: the steps, the cells and the time the run should take (to ``time.end``; a
    breach that stops the run comes sooner)."""
    flow = (f" and a flow box of {e.flow_cells:,} cells (a flow step every {e.flow_every} "
            f"step(s), its predictor in {e.flow_substeps} part(s))") if e.flow_cells else ""
    stop = " or the breach" if case.breach.action == "stop" else ""
    return (f"estimate: {e.steps:,} steps of {e.dt:.3g} s on {e.cells:,} cells{flow}, about "
            f"{_hours(e.seconds)} on 2 cores to t = {case.time.end:g} s{stop}")


def machine_memory() -> int | None:
    """Physical memory (bytes), or the address-space limit when lower; None if unknown."""
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        total = None
    try:
        import resource

        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft != resource.RLIM_INFINITY and (total is None or soft < total):
            total = soft
    except (ImportError, ValueError, OSError):
        pass
    return total


def free_disk(where: Path) -> int | None:
    """Free bytes on the file system that holds ``where`` (its nearest existing folder)."""
    place = Path(where).absolute()
    while not place.exists() and place != place.parent:
        place = place.parent
    try:
        return shutil.disk_usage(place).free
    except OSError:
        return None


def _size(n: float) -> str:
    for unit, scale in (("TB", 2**40), ("GB", 2**30), ("MB", 2**20)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n / 2**10:.3g} kB"


def _hours(seconds: float) -> str:
    return f"{seconds / 3600:.3g} h" if seconds >= 3600 else f"{seconds / 60:.3g} min"


def check(case: Case, out: Path | None = None, *, allow_large: bool = False,
          file: str | None = None, existing_saves: int = 0) -> Estimate:
    """The estimate, or :class:`CaseError` (one line: key, estimate, limit) when the case is
    over a hard limit, or over a soft one and ``allow_large`` is False. ``existing_saves``:
    saved times a resumed run already holds (their disk is already spent)."""
    e = estimate(case)
    more = " (--allow-large to go beyond)"
    memory = machine_memory()
    if memory is not None and e.memory_bytes > memory:
        raise CaseError(f"{case.grid.cells} cells make a {'x'.join(map(str, e.shape))} grid "
                        f"that needs about {_size(e.memory_bytes)} of memory, over the limit of "
                        f"this machine's {_size(memory)}", file=file, where="grid.cells")
    step_key = "time.dt" if case.time.dt is not None else "time.end"
    if not allow_large:
        if e.steps > SOFT_LIMITS["steps"]:
            raise CaseError(f"{e.steps:.3g} steps of {e.dt:.3g} s to reach {case.time.end:g} s "
                            f"is over the limit of {SOFT_LIMITS['steps']:.3g} steps{more}",
                            file=file, where=step_key)
        if e.cell_updates > SOFT_LIMITS["cell_updates"]:
            key = "grid.cells" if case.grid.cells > 64 else step_key
            raise CaseError(f"{e.steps:.3g} steps on {e.cells:,} cells is {e.cell_updates:.3g} "
                            f"cell updates (about {_hours(e.seconds)}), over the limit of "
                            f"{SOFT_LIMITS['cell_updates']:.3g}{more}", file=file, where=key)
        if e.saves > SOFT_LIMITS["saves"]:
            raise CaseError(f"{e.saves:,} saved times is over the limit of "
                            f"{SOFT_LIMITS['saves']:,}{more}", file=file,
                            where="time.save_every")
        if e.disk_bytes > SOFT_LIMITS["disk_bytes"]:
            raise CaseError(f"{e.saves:,} saved times write about {_size(e.disk_bytes)}, over "
                            f"the limit of {_size(SOFT_LIMITS['disk_bytes'])}{more}",
                            file=file, where="time.save_every")
    if out is not None:
        free = free_disk(out)
        need = max(0, e.saves - existing_saves) * (DISK_PER_CELL * e.cells + DISK_PER_SAVE)
        if free is not None and need > free:
            raise CaseError(f"{e.saves:,} saved times write about {_size(need)}; {out} has "
                            f"{_size(free)} free", file=file, where="time.save_every")
    return e


__all__ = ["SOFT_LIMITS", "Estimate", "check", "describe", "estimate"]
