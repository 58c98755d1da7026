"""``whitted stefan run``: compute the melt of a case and write what it produced.

Output folder::

    case.toml              the case, as given (a resume refuses a different one)
    fields/state_0003.npz  the state at each saved time (compressed NumPy): enthalpy H
                           (float64, exact, for resuming), cell kind, liquid fraction
                           (float32), temperature (float32, NaN in air), time and totals
    surfaces/outer_0003.ply, inner_0003.ply   ice/air and ice/water surfaces
    scenes/frame_0003.toml a whitted scene rendering that saved time
    series.csv             time series: ice, cavity and water volume, minimum shell,
                           breach time (empty until the shell opens), energy imbalance,
                           heat in, heat drained with the meltwater (J), water condensed
                           from the air (cm³)
    series.png             the same as plots
    summary.json           breach time, end time, energy balance

Every file is written atomically; an interrupted run keeps every saved time and ``run``
again continues from the last one.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
import time as wallclock
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .case import Case, CaseError, case_digest
from .geometry import GridFrame, grid_frame, initial_state
from .measures import measure
from .scene import puddle_radius, still_life_scene, void_bubble, write_scene
from .solver import EnthalpySolver
from .surfaces import extract_surfaces, write_ply

_STATE_NAME = re.compile(r"state_(\d+)\.npz")
SERIES_COLUMNS = ("time_s", "ice_volume_cm3", "cavity_volume_cm3", "water_volume_cm3",
                  "min_shell_mm", "breached", "breach_time_s", "energy_imbalance_J",
                  "heat_in_J", "heat_drained_J", "condensed_cm3")


@dataclass
class RunResult:
    out_dir: Path
    saved: list[float] = field(default_factory=list)  # times saved in this call
    last_saved: float | None = None  # the latest saved time (a resume starts there)
    resumed_from: float | None = None
    end_time: float = 0.0
    breach_time: float | None = None
    finished: bool = False
    interrupted: bool = False
    solve_seconds: float = 0.0
    surface_seconds: list[float] = field(default_factory=list)
    cells: tuple[int, int, int] = (0, 0, 0)
    steps: int = 0


def _atomic_bytes(path: Path, data: bytes) -> None:
    tmp = path.with_name(path.name + ".part")
    tmp.write_bytes(data)
    tmp.replace(path)


def _save_state(path: Path, solver: EnthalpySolver, digest: str, index: int,
                initial_cavity: float) -> None:
    buf = io.BytesIO()
    f = solver.liquid_fraction().astype(np.float32)
    np.savez_compressed(
        buf, H=solver.H, kind=solver.kind, liquid_fraction=f,
        temperature=solver.temperature().astype(np.float32), time=solver.time,
        steps=solver.steps, totals=solver.totals, dx=solver.dx, digest=digest, index=index,
        breached=solver.breached,
        breach_time=np.nan if solver.breach_time is None else solver.breach_time,
        initial_enthalpy=solver.initial_enthalpy, initial_cavity=initial_cavity,
        **({} if solver.flow is None else solver.flow.state()))
    _atomic_bytes(path, buf.getvalue())


def state_files(fields: Path) -> list[Path]:
    """``state_NNNN.npz`` files by their number (numeric: state_10000 comes after state_9999)."""
    found = []
    for path in Path(fields).glob("state_*.npz"):
        m = _STATE_NAME.fullmatch(path.name)
        if m is not None and path.is_file():
            found.append((int(m.group(1)), path))
    return [p for _, p in sorted(found)]


def _latest_state(fields: Path, digest: str) -> Path | None:
    for path in reversed(state_files(fields)):
        try:
            with np.load(path) as z:
                if str(z["digest"]) == digest:
                    return path
        except (OSError, ValueError, KeyError):
            continue  # a damaged file: try the one before
    return None


def _write_series(path: Path, rows: list[dict]) -> None:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=SERIES_COLUMNS, lineterminator="\n")
    w.writeheader()
    for row in rows:
        w.writerow({k: row.get(k) for k in SERIES_COLUMNS})  # (older series lack the last)
    _atomic_bytes(path, buf.getvalue().encode())


def _read_series(path: Path) -> list[dict]:
    if not path.exists():
        return []
    with path.open(newline="") as fh:
        return [{k: (v if k == "breached" else None if v == "" else float(v))
                 for k, v in row.items()} for row in csv.DictReader(fh)]


def plot_series(rows: list[dict], path: Path, breach_time: float | None) -> None:
    """Ice, cavity and water volumes and the minimum shell thickness against time (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = np.array([r["time_s"] for r in rows]) / 60.0
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.4), dpi=110)
    a.plot(t, [r["ice_volume_cm3"] for r in rows], label="ice")
    a.plot(t, [r["cavity_volume_cm3"] for r in rows], label="cavity")
    a.plot(t, [r["water_volume_cm3"] for r in rows], "--", label="cavity water")
    a.set_xlabel("time (min)")
    a.set_ylabel("volume (cm³)")
    a.legend()
    b.plot(t, [r["min_shell_mm"] for r in rows], color="C3")
    b.set_xlabel("time (min)")
    b.set_ylabel("thinnest shell (mm)")
    for ax in (a, b):
        ax.grid(alpha=0.3)
        if breach_time is not None:
            ax.axvline(breach_time / 60.0, color="k", lw=0.8, ls=":")
    fig.suptitle("hollow ice piece" + (f": breach at {breach_time / 60:.1f} min"
                                       if breach_time is not None else ""))
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    _atomic_bytes(path, buf.getvalue())


def _save_surfaces(out: Path, index: int, solver: EnthalpySolver, case: Case,
                   frame: GridFrame) -> tuple[str | None, str | None, float]:
    t0 = wallclock.perf_counter()
    outer, inner = extract_surfaces(solver.H, solver.kind, case.properties, frame,
                                    smoothing=case.surfaces.smoothing, keep=case.surfaces.keep)
    names: list[str | None] = []
    for label, mesh in (("outer", outer), ("inner", inner)):
        if mesh is None or len(mesh.faces) == 0:
            names.append(None)
            continue
        name = f"surfaces/{label}_{index:04d}.ply"
        write_ply(mesh, out / name)
        names.append(name)
    return names[0], names[1], wallclock.perf_counter() - t0


def run_case(case: Case, case_text: str, out: Path, *, resume: bool = True,
             progress: Callable[[float, float, str], None] | None = None,
             should_stop: Callable[[], bool] | None = None, scene_size: tuple[int, int] =
             (480, 360), allow_large: bool = False, case_path: Path | None = None,
             on_estimate: Callable[[str], None] | None = None,
             on_row: Callable[[dict], None] | None = None) -> RunResult:
    """Solve ``case`` into the folder ``out`` (see the module docstring).

    Before any work the cost is estimated (:func:`whitted.stefan.budget.check`: refused over
    the machine's memory or free disk, or over a soft limit unless ``allow_large``), and
    ``out`` must be a folder whitted made (:func:`whitted.stefan.folder.prepare`): ``resume``
    False (``--fresh``) removes the files whitted wrote there and nothing else.
    ``case_path``: the case file read, which the run must not write over. ``on_estimate``
    is given the estimate's line (:func:`whitted.stefan.budget.describe`) once the checks
    pass, before the solving starts. ``on_row`` is given every row of ``series.csv`` (those
    of a resumed run first), as it is saved (:class:`whitted.stefan.eta.TimeLeft` reads the
    thinnest shell's thinning from them)."""
    from . import budget, folder

    out = Path(out)
    digest = case_digest(case)
    case_file = out / "case.toml"
    if case_path is not None and Path(case_path).resolve() == case_file.resolve():
        raise CaseError("the run would write its case.toml over the case file it reads: use "
                        "another output folder", file=str(case_path))
    existing = 0
    if resume and folder.is_marked(out) and (out / "fields").is_dir():
        existing = len(state_files(out / "fields"))
    cost = budget.check(case, out, allow_large=allow_large, existing_saves=existing,
                        file=None if case_path is None else str(case_path))
    folder.prepare(out, fresh=not resume, digest=digest)
    if resume and _latest_state(out / "fields", digest) is None and state_files(out / "fields"):
        raise CaseError("holds a run of a different case (use a new folder or --fresh)",
                        file=str(out))
    _atomic_bytes(case_file, case_text.encode())
    if on_estimate is not None:  # every check passed: the run starts
        on_estimate(budget.describe(cost, case))
    frame = grid_frame(case)
    result = RunResult(out, cells=frame.shape)
    air = case.solver_air()
    latest = _latest_state(out / "fields", digest) if resume else None
    rows: list[dict]
    if latest is not None:
        with np.load(latest) as z:
            solver = EnthalpySolver(z["H"], z["kind"], float(z["dx"]), case.solver_properties(),
                                    faces=case.solver_faces(), air=air, dt=case.time.dt,
                                    cfl=case.time.cfl, convection=case.solver_convection(),
                                    flow=case.solver_flow(z["H"], z["kind"]),
                                    stop_on_breach=case.breach.action == "stop",
                                    time=float(z["time"]))
            solver.steps = int(z["steps"])
            if solver.flow is not None:
                solver.flow.restore(z)
            solver.totals[:] = z["totals"]
            solver.initial_enthalpy = float(z["initial_enthalpy"])
            solver.breached = bool(z["breached"])
            bt = float(z["breach_time"])
            solver.breach_time = None if math.isnan(bt) else bt
            index = int(z["index"])
            initial_cavity = float(z["initial_cavity"])
        rows = [r for r in _read_series(out / "series.csv") if r["time_s"] <= solver.time + 1e-9]
        result.resumed_from = solver.time
    else:
        H, kind, cavity, _ = initial_state(case)
        solver = EnthalpySolver(H, kind, case.dx, case.solver_properties(),
                                faces=case.solver_faces(), air=air, dt=case.time.dt,
                                cfl=case.time.cfl, convection=case.solver_convection(),
                                flow=case.solver_flow(H, kind),
                                stop_on_breach=case.breach.action == "stop")
        initial_cavity = float(cavity.sum()) * case.dx ** 3
        if solver.flow is not None:
            solver.flow.seed_tracers(solver._Hp, solver._kindp)
        index = 0
        rows = []
        _record(out, solver, case, frame, digest, index, initial_cavity, rows, result,
                scene_size)
    if on_row is not None:
        for r in rows:
            on_row(r)
    end = case.time.end
    every = case.time.save_every
    t_solve = wallclock.perf_counter()
    while solver.time < end - 1e-9 and not result.finished:
        if solver.breached and case.breach.action == "stop":
            result.finished = True
            break
        target = min(end, (index + 1) * every)
        stopped = not solver.advance(target, should_stop=should_stop,
                                     on_chunk=None if progress is None else
                                     lambda: progress(solver.time / end, solver.time, "solve"))
        if stopped:
            result.interrupted = True
            break
        index += 1
        _record(out, solver, case, frame, digest, index, initial_cavity, rows, result,
                scene_size)
        if on_row is not None:
            on_row(rows[-1])
        if progress is not None:
            progress(solver.time / end, solver.time, "saved")
        if not (solver.kind == 1).any() or rows[-1]["ice_volume_cm3"] <= 0.0:
            result.finished = True  # all melted
    result.solve_seconds = wallclock.perf_counter() - t_solve
    if not result.interrupted and solver.time >= end - 1e-9:
        result.finished = True
    if solver.breached and case.breach.action == "stop":
        result.finished = True
    result.end_time = solver.time
    result.last_saved = rows[-1]["time_s"] if rows else None
    result.breach_time = solver.breach_time
    result.steps = solver.steps
    plot_series(rows, out / "series.png", solver.breach_time)
    summary = {"case_digest": digest, "end_time_s": solver.time, "steps": solver.steps,
               "dt_s": solver.dt, "dt_limit_s": solver.dt_limit, "cells": list(frame.shape),
               "dx_m": solver.dx, "breach_time_s": solver.breach_time,
               "breach_action": case.breach.action, "finished": result.finished,
               "heat_in_J": solver.heat_in, "drained_J": solver.drained,
               "energy_imbalance_J": solver.energy_error(), "saved_times": len(rows),
               "solve_seconds": result.solve_seconds,
               "surface_seconds_per_save": (float(np.mean(result.surface_seconds))
                                            if result.surface_seconds else None)}
    _atomic_bytes(out / "summary.json", json.dumps(summary, indent=2).encode())
    return result


@dataclass(frozen=True)
class FilmFrame:
    """One saved time of a run as a film frame: its index, time and surfaces (relative to the
    run folder; ``inner`` None when the cavity is gone: after a breach in drain mode)."""

    index: int
    time: float
    outer: str
    inner: str | None


def inner_top(path: Path) -> tuple[float, float, float]:
    """The highest vertex of a cavity surface (PLY, metres): where the void's bubble sits."""
    import trimesh

    verts = trimesh.load(path, process=False).vertices
    top = verts[int(verts[:, 1].argmax())]
    return float(top[0]), float(top[1]), float(top[2])


def film_bubbles(out: Path, frames: list[FilmFrame]) -> list:
    """The void's bubble of each frame (:func:`whitted.stefan.scene.void_bubble`): the
    series' cavity volume less its water's, under the top of that frame's cavity."""
    rows = _read_series(Path(out) / "series.csv")
    return [void_bubble(inner_top(Path(out) / f.inner),
                        1e-6 * (float(rows[f.index]["cavity_volume_cm3"])
                                - float(rows[f.index]["water_volume_cm3"])))
            for f in frames if f.inner is not None]


def meltwater(case: Case, first: tuple[float, float], now: tuple[float, float],
              condensed: float = 0.0) -> float:
    """The water that left the block (m³): the ice and cavity water of the start less those
    of now, in water's volume, (rho_i / rho_w) (V_ice,0 - V_ice) - (V_w - V_w,0), and the
    water the air condensed on it (``condensed``, m³: it runs off with the melt)."""
    ratio = case.ice.rho / case.water.rho
    return max(0.0, ratio * (first[0] - now[0]) - (now[1] - first[1])) + max(0.0, condensed)


def condensed_volume(case: Case, heat_in: float) -> float:
    """The water (m³) the air's vapour condensed on the block while ``heat_in`` J entered it:
    the condensation's share of the heat into a surface at 0 °C
    (:meth:`~whitted.stefan.case.Case.condensation_share`) over the latent heat of
    vaporisation, in water's volume."""
    from .room import L_VAPORISATION

    return max(0.0, heat_in) * case.condensation_share() / (L_VAPORISATION * case.water.rho)


def film_puddles(out: Path, frames: list[FilmFrame], case: Case) -> list[float]:
    """The meltwater's disc radius of each frame (:func:`whitted.stefan.scene.puddle_radius`)."""
    rows = _read_series(Path(out) / "series.csv")

    def volumes(row: dict) -> tuple[float, float]:
        return 1e-6 * float(row["ice_volume_cm3"]), 1e-6 * float(row["water_volume_cm3"])

    def condensed(row: dict) -> float:
        return 1e-6 * float(row.get("condensed_cm3") or 0.0)

    return [puddle_radius(meltwater(case, volumes(rows[0]), volumes(rows[f.index]),
                                    condensed(rows[f.index])), case.block.size)
            for f in frames]


def tracer_points(solver: EnthalpySolver, frame: GridFrame) -> list[tuple[float, ...]]:
    """The flow's tracer particles now, in scene centimetres (none without the flow)."""
    if solver.flow is None or len(solver.flow.tracers) == 0:
        return []
    world = frame.to_world(solver.flow.tracer_points())
    return [tuple(100.0 * c for c in p) for p in world]


def film_tracers(out: Path, frames: list[FilmFrame]) -> list[list[tuple[float, ...]]] | None:
    """The tracers of each frame (scene centimetres) from the saved states; None when the
    run has none (no flow)."""
    from .geometry import grid_frame

    fields = Path(out) / "fields"
    found = []
    frame = None
    for f in frames:
        with np.load(fields / f"state_{f.index:04d}.npz") as z:
            if "flow_tracers" not in z:
                return None
            if frame is None:
                from .case import load_case

                frame = grid_frame(load_case(Path(out) / "case.toml"))
            pts = np.array(z["flow_tracers"]).reshape(-1, 3)
            box = np.array(z["flow_box"])
        world = frame.to_world(pts + box[:, 0] - 0.5)
        found.append([tuple(100.0 * c for c in p) for p in world])
    return found


def film_frames(out: Path) -> list[FilmFrame]:
    """The saved times of the run in ``out`` that a film shows, from t = 0 to the end of the
    run: every saved time with an outer surface (in ``drain`` mode the frames after the
    breach have the outer surface alone); it stops at the first saved time without one."""
    out = Path(out)
    frames: list[FilmFrame] = []
    for k, row in enumerate(_read_series(out / "series.csv")):
        outer = f"surfaces/outer_{k:04d}.ply"
        if not (out / outer).is_file():
            break
        inner = f"surfaces/inner_{k:04d}.ply"
        frames.append(FilmFrame(k, float(row["time_s"]), outer,
                                inner if (out / inner).is_file() else None))
    return frames


def _record(out: Path, solver: EnthalpySolver, case: Case, frame: GridFrame, digest: str,
            index: int, initial_cavity: float, rows: list[dict], result: RunResult,
            scene_size: tuple[int, int]) -> None:
    """Surfaces, scene, series row and (last, so a resume never skips the others) the state
    of one saved time."""
    outer, inner, seconds = _save_surfaces(out, index, solver, case, frame)
    result.surface_seconds.append(seconds)
    m = measure(solver.H, solver.kind, solver.dx, case.properties, solver.time, initial_cavity,
                solver.breached)
    bubble = None if inner is None else [void_bubble(inner_top(out / inner),
                                                     m.cavity_volume - m.water_volume)]
    first = (m.ice_volume, m.water_volume) if not rows else (
        1e-6 * float(rows[0]["ice_volume_cm3"]), 1e-6 * float(rows[0]["water_volume_cm3"]))
    condensed = condensed_volume(case, solver.heat_in)
    puddle = puddle_radius(meltwater(case, first, (m.ice_volume, m.water_volume), condensed),
                           case.block.size)
    text = still_life_scene(None if outer is None else "../" + outer,
                            None if inner is None else "../" + inner, solver.time,
                            width=scene_size[0], height=scene_size[1],
                            size_cm=100 * max(case.block.size), bubbles=bubble,
                            puddles=[puddle], tracers=None if inner is None else
                            [tracer_points(solver, frame)])
    write_scene(out / "scenes" / f"frame_{index:04d}.toml", text)
    rows[:] = [r for r in rows if r["time_s"] < solver.time - 1e-9]
    rows.append({"time_s": solver.time, "ice_volume_cm3": m.ice_volume * 1e6,
                 "cavity_volume_cm3": m.cavity_volume * 1e6,
                 "water_volume_cm3": m.water_volume * 1e6, "min_shell_mm": m.min_shell * 1e3,
                 "breached": int(m.breached), "breach_time_s": solver.breach_time,
                 "energy_imbalance_J": solver.energy_error(), "heat_in_J": solver.heat_in,
                 "heat_drained_J": solver.drained, "condensed_cm3": condensed * 1e6})
    _write_series(out / "series.csv", rows)
    _save_state(out / "fields" / f"state_{index:04d}.npz", solver, digest, index,
                initial_cavity)
    result.saved.append(solver.time)


__all__ = ["FilmFrame", "RunResult", "asdict", "film_bubbles", "film_frames", "film_puddles",
           "condensed_volume", "film_tracers", "inner_top", "meltwater", "run_case", "state_files"]
