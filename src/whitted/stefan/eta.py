"""The time a run has left, honestly: against the case's end, and, when the breach stops the
run, against the breach as the thinnest shell's thinning foretells it.

The wall clock's pace (simulated seconds per wall second) is measured over the last
``window`` wall seconds of progress. The breach is foretold from the saved rows: a straight
line through the thinnest shell of the last ``fit`` saves (least squares) reaches
``opens_at`` at the foretold breach; none while the shell is not thinning (then the end
bounds the time left: "until the end at most").

The grid opens before the measured shell reaches zero: the solver calls it a breach when an
outer cell has drained (no ice left) next to a cavity cell at least half liquid, so the
thinnest shell then measures between 0 and half a cell; ``whitted stefan run`` foretells the
middle, a quarter of a cell (``opens_at``).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass


@dataclass(frozen=True)
class Estimate:
    to_end: float | None  # wall seconds until time.end at the present pace (None: no pace yet)
    to_breach: float | None  # wall seconds until the foretold breach (None: none foretold)
    breach_at: float | None  # simulated time of the foretold breach (s)


def _clock(seconds: float) -> str:
    s = int(round(seconds))
    h, rest = divmod(s, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


class TimeLeft:
    """Feed it progress (:meth:`tick`: simulated time at a wall time) and the saved rows
    (:meth:`row`: the time and the thinnest shell); :meth:`estimate` and :meth:`text` say
    what is left. ``end``: the case's ``time.end``; ``stops_at_breach``: the case stops
    there (``breach.action = "stop"``); ``opens_at``: the thinnest shell (mm) at which the
    breach is foretold."""

    def __init__(self, end: float, stops_at_breach: bool, window: float = 60.0,
                 fit: int = 4, opens_at: float = 0.0) -> None:
        self.end = float(end)
        self.stops_at_breach = bool(stops_at_breach)
        self.opens_at = max(0.0, float(opens_at))
        self.window = float(window)
        self.fit = max(2, int(fit))
        self._ticks: deque[tuple[float, float]] = deque()
        self._rows: deque[tuple[float, float]] = deque(maxlen=self.fit)

    def tick(self, wall: float, t: float) -> None:
        if self._ticks and t < self._ticks[-1][1]:
            self._ticks.clear()  # time went back (a resumed run): start the pace afresh
        self._ticks.append((float(wall), float(t)))
        while len(self._ticks) > 2 and wall - self._ticks[1][0] >= self.window:
            self._ticks.popleft()

    def row(self, t: float, shell_mm: float) -> None:
        """A saved row: the simulated time (s) and the thinnest shell (mm; 0 once open)."""
        if self._rows and t <= self._rows[-1][0]:
            while self._rows and self._rows[-1][0] >= t:
                self._rows.pop()
        if math.isfinite(shell_mm):
            self._rows.append((float(t), float(shell_mm)))

    def pace(self) -> float | None:
        """Simulated seconds per wall second over the window (None: not yet measurable)."""
        if len(self._ticks) < 2:
            return None
        (w0, t0), (w1, t1) = self._ticks[0], self._ticks[-1]
        if w1 - w0 <= 0.0 or t1 <= t0:
            return None
        return (t1 - t0) / (w1 - w0)

    def breach_at(self) -> float | None:
        """The simulated time the thinnest shell reaches ``opens_at`` on the straight line
        through the last saves (None: fewer than two, or not thinning)."""
        if not self.stops_at_breach or len(self._rows) < 2:
            return None
        ts = [r[0] for r in self._rows]
        ss = [r[1] for r in self._rows]
        if ss[-1] <= self.opens_at:
            return ts[-1]
        mt = sum(ts) / len(ts)
        ms = sum(ss) / len(ss)
        var = sum((t - mt) ** 2 for t in ts)
        if var <= 0.0:
            return None
        slope = sum((t - mt) * (s - ms) for t, s in zip(ts, ss, strict=True)) / var
        if slope >= 0.0:
            return None
        # from the last save: its shell, thinning at the fitted rate
        return ts[-1] + (ss[-1] - self.opens_at) / -slope

    def estimate(self, t: float) -> Estimate:
        pace = self.pace()
        to_end = None if pace is None else max(0.0, self.end - t) / pace
        at = self.breach_at()
        if at is not None and at >= self.end:
            at = None  # foretold after the end: the end comes first
        to_breach = None if pace is None or at is None else max(0.0, at - t) / pace
        return Estimate(to_end, to_breach, at)

    def text(self, t: float) -> str:
        e = self.estimate(t)
        if e.to_end is None:
            return "time left: -"
        end = _clock(e.to_end)
        if e.to_breach is not None:
            return f"~{_clock(e.to_breach)} to the breach ({end} to the end at most)"
        if self.stops_at_breach:
            return f"{end} until the end at most"
        return f"{end} left"


__all__ = ["Estimate", "TimeLeft"]
