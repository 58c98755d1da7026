"""A Stefan run's results as time series, and their plot: melt fraction, thinnest shell and
heat budget against time, read from a run folder (``whitted stefan run``'s, or
:func:`~whitted.stefan.run_case`'s). :class:`StefanResults` shows itself as that plot in a
notebook.

The heat budget of each saved time: the heat that came in through the surfaces, the
enthalpy drained away with meltwater, and what the block holds more than at the start
(``stored = heat in - drained + imbalance``, the imbalance being the solver's energy error,
zero to round-off): read from ``series.csv`` (from the saved states' totals for a run
written before the series had those columns).
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .case import CaseError

__all__ = ["StefanResults", "load_results"]


@dataclass
class StefanResults:
    """The time series of a run (NumPy arrays, one value per saved time)."""

    folder: Path
    time_s: np.ndarray
    ice_volume_cm3: np.ndarray
    cavity_volume_cm3: np.ndarray
    water_volume_cm3: np.ndarray
    min_shell_mm: np.ndarray
    heat_in_J: np.ndarray
    drained_J: np.ndarray
    imbalance_J: np.ndarray
    breach_time_s: float | None = None
    finished: bool = False
    summary: dict = field(default_factory=dict, repr=False)
    #: what the run did (:class:`~whitted.stefan.run.RunResult`), when this call ran it
    run: object = field(default=None, repr=False)

    @property
    def melt_fraction(self) -> np.ndarray:
        """The part of the ice melted since the start, 0..1."""
        first = self.ice_volume_cm3[0] if len(self.ice_volume_cm3) else 0.0
        if first <= 0:
            return np.zeros_like(self.ice_volume_cm3)
        return np.clip(1.0 - self.ice_volume_cm3 / first, 0.0, 1.0)

    @property
    def stored_J(self) -> np.ndarray:
        """What the block holds more than at the start (J)."""
        return self.heat_in_J - self.drained_J + self.imbalance_J

    def figure(self):
        """A matplotlib Figure: melt fraction, thinnest shell, heat budget against time."""
        from matplotlib.figure import Figure

        t = self.time_s / 60.0
        fig = Figure(figsize=(11, 3.3), dpi=100, layout="constrained")
        a, b, c = fig.subplots(1, 3)
        a.plot(t, 100 * self.melt_fraction, color="C0")
        a.set_ylabel("ice melted (%)")
        a.set_ylim(bottom=0)
        b.plot(t, self.min_shell_mm, color="C3")
        b.set_ylabel("thinnest shell (mm)")
        b.set_ylim(bottom=0)
        c.plot(t, self.heat_in_J / 1e3, label="heat in")
        c.plot(t, self.stored_J / 1e3, label="stored")
        c.plot(t, self.drained_J / 1e3, label="drained")
        c.plot(t, self.imbalance_J / 1e3, ":", color="k", label="imbalance")
        c.set_ylabel("energy (kJ)")
        c.legend(fontsize=8)
        for ax in (a, b, c):
            ax.set_xlabel("time (min)")
            ax.grid(alpha=0.3)
            if self.breach_time_s is not None:
                ax.axvline(self.breach_time_s / 60.0, color="k", lw=0.8, ls="--")
        breach = (f": breach at {self.breach_time_s / 60:.1f} min"
                  if self.breach_time_s is not None else "")
        fig.suptitle(f"{self.folder.name}{breach}")
        return fig

    def _repr_png_(self) -> bytes:
        buf = io.BytesIO()
        self.figure().savefig(buf, format="png")
        return buf.getvalue()

    def __repr__(self) -> str:
        if not len(self.time_s):
            return f"<StefanResults {self.folder}: no saved time>"
        end = self.time_s[-1] / 60.0
        breach = (f", breach at {self.breach_time_s / 60:.1f} min"
                  if self.breach_time_s is not None else "")
        return (f"<StefanResults {self.folder}: {len(self.time_s)} saved times to "
                f"{end:.1f} min, {100 * self.melt_fraction[-1]:.1f} % melted, thinnest shell "
                f"{self.min_shell_mm[-1]:.2f} mm{breach}>")


def _number(text: str | None) -> float:
    return float("nan") if text in (None, "") else float(text)


def load_results(folder: str | os.PathLike[str]) -> StefanResults:
    """The results of the run in ``folder``. One-line :class:`CaseError` when it holds no
    run (no ``series.csv``) or a damaged one."""
    from .run import state_files

    folder = Path(folder)
    series = folder / "series.csv"
    try:
        with series.open(newline="") as fh:
            rows = list(csv.DictReader(fh))
    except FileNotFoundError:
        raise CaseError("holds no Stefan run (no series.csv)", file=str(folder)) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise CaseError(f"cannot read series.csv: {getattr(exc, 'strerror', None) or exc}",
                        file=str(folder)) from None
    try:
        columns = {key: np.array([_number(r.get(key)) for r in rows]) for key in (
            "time_s", "ice_volume_cm3", "cavity_volume_cm3", "water_volume_cm3",
            "min_shell_mm", "energy_imbalance_J")}
    except (TypeError, ValueError) as exc:
        raise CaseError(f"series.csv is damaged: {exc}", file=str(folder)) from None
    n = len(rows)
    try:  # series.csv has the budget's columns (runs before them: the saved states' totals)
        heat_in = np.array([_number(r.get("heat_in_J")) for r in rows])
        drained = np.array([_number(r.get("heat_drained_J")) for r in rows])
    except (TypeError, ValueError) as exc:
        raise CaseError(f"series.csv is damaged: {exc}", file=str(folder)) from None
    if n and not (np.isnan(heat_in).any() or np.isnan(drained).any()):
        return _results(folder, columns, heat_in, drained)
    for path in state_files(folder / "fields"):
        try:
            with np.load(path) as z:
                index = int(z["index"])
                if 0 <= index < n:
                    dx = float(z["dx"])
                    totals = z["totals"]
                    heat_in[index] = float(totals[0]) * dx ** 2
                    drained[index] = float(totals[1]) * dx ** 3
        except (OSError, ValueError, KeyError):
            continue  # a damaged state: that time's budget stays unknown (NaN)
    return _results(folder, columns, heat_in, drained)


def _results(folder: Path, columns: dict, heat_in: np.ndarray,
             drained: np.ndarray) -> StefanResults:
    summary = {}
    with contextlib.suppress(OSError, ValueError):
        summary = json.loads((folder / "summary.json").read_text())
    breach = summary.get("breach_time_s")
    return StefanResults(folder, columns["time_s"], columns["ice_volume_cm3"],
                         columns["cavity_volume_cm3"], columns["water_volume_cm3"],
                         columns["min_shell_mm"], heat_in, drained,
                         columns["energy_imbalance_J"],
                         None if breach is None else float(breach),
                         bool(summary.get("finished", False)), summary)
