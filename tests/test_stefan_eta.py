"""The run's time left: against time.end, and against the breach foretold from the thinnest
shell's thinning when the breach stops the run."""

from __future__ import annotations

import math

import pytest

from whitted.stefan.eta import TimeLeft


def _drive(left: TimeLeft, pace: float, shell0: float, rate: float, t_stop: float,
           save_every: float = 120.0) -> None:
    """Progress at ``pace`` simulated seconds per wall second, a save every ``save_every``
    s with a shell thinning from ``shell0`` mm at ``rate`` mm/s, up to ``t_stop``."""
    t = 0.0
    while t <= t_stop + 1e-9:
        left.tick(t / pace, t)
        if t % save_every == 0.0:
            left.row(t, max(0.0, shell0 - rate * t))
        t += 10.0


def test_the_breach_is_foretold_from_the_shell_thinning():
    # a 2 h case whose 6 mm shell thins at 0.004 mm/s: it opens at 1500 s. At 600 s, with 4
    # simulated seconds a wall second, 900 s are left to the breach (225 wall s), 6600 s to
    # the end (1650 wall s), which bounds it
    left = TimeLeft(end=7200.0, stops_at_breach=True)
    _drive(left, pace=4.0, shell0=6.0, rate=0.004, t_stop=600.0)
    assert left.pace() == pytest.approx(4.0)
    assert left.breach_at() == pytest.approx(1500.0)
    e = left.estimate(600.0)
    assert e.to_breach == pytest.approx(225.0)
    assert e.to_end == pytest.approx(1650.0)
    assert left.text(600.0) == "~3:45 to the breach (27:30 to the end at most)"


def test_the_thinning_is_fitted_over_the_last_saves():
    # the shell thinned slowly at first (the ice warming) and faster now: the last saves
    # set the rate, not the first
    left = TimeLeft(end=7200.0, stops_at_breach=True, fit=3)
    for t, s in ((0, 6.0), (120, 5.99), (240, 5.9), (360, 5.42), (480, 4.94), (600, 4.46)):
        left.tick(t / 2.0, float(t))
        left.row(float(t), s)
    assert left.breach_at() == pytest.approx(600.0 + 4.46 / 0.004)


def test_no_breach_foretold_says_until_the_end_at_most():
    left = TimeLeft(end=3600.0, stops_at_breach=True)
    _drive(left, pace=2.0, shell0=6.0, rate=0.0, t_stop=600.0)  # not thinning
    assert left.breach_at() is None
    assert left.text(600.0) == "25:00 until the end at most"
    # thinning too slowly to open before the end: the end comes first
    late = TimeLeft(end=3600.0, stops_at_breach=True)
    _drive(late, pace=2.0, shell0=6.0, rate=0.001, t_stop=600.0)
    assert late.breach_at() == pytest.approx(6000.0)
    assert late.estimate(600.0).to_breach is None
    assert late.text(600.0) == "25:00 until the end at most"


def test_a_run_that_drains_goes_to_the_end():
    left = TimeLeft(end=3600.0, stops_at_breach=False)
    _drive(left, pace=2.0, shell0=6.0, rate=0.004, t_stop=600.0)
    assert left.breach_at() is None  # the breach does not stop it
    assert left.text(600.0) == "25:00 left"


def test_an_open_shell_and_early_or_odd_input():
    left = TimeLeft(end=3600.0, stops_at_breach=True)
    assert left.text(0.0) == "time left: -"  # no pace yet
    left.tick(0.0, 0.0)
    left.row(0.0, 6.0)
    assert left.breach_at() is None  # one save: no rate
    left.tick(10.0, 100.0)
    left.row(100.0, 0.0)  # opened
    assert left.breach_at() == 100.0
    assert left.estimate(100.0).to_breach == 0.0
    left.row(50.0, math.nan)  # a resumed run's earlier row replaces the later ones; NaN ignored
    assert left.breach_at() is None
    # the pace is measured over the window only: a slow start does not weigh on it
    w = TimeLeft(end=3600.0, stops_at_breach=False, window=60.0)
    w.tick(0.0, 0.0)
    w.tick(100.0, 10.0)  # 0.1 s/s while compiling
    for k in range(1, 13):
        w.tick(100.0 + 10.0 * k, 10.0 + 20.0 * k)  # then 2 s/s
    assert w.pace() == pytest.approx(2.0)


def test_the_run_shows_the_time_left_on_a_terminal_and_ends_cleanly(tmp_path):
    # `whitted stefan run` on a terminal (TTY_COMPATIBLE=1): the bar says the time left to the
    # breach, bounded by the end, and the bar's ending (rich's Live writing its last line)
    # goes through a real console: exit 0, no internal error
    import os
    import subprocess
    import sys
    from pathlib import Path

    case = tmp_path / "small.toml"
    case.write_text("[grid]\ncells = 16\n[time]\nsave_every = 120.0\n")
    env = {**os.environ, "TTY_COMPATIBLE": "1", "COLUMNS": "160",
           "PYTHONPATH": str(Path(__file__).resolve().parents[1] / "src")}
    env.pop("FORCE_COLOR", None)
    done = subprocess.run([sys.executable, "-m", "whitted", "stefan", "run", str(case), "-o",
                           str(tmp_path / "out")], env=env, capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "internal error" not in done.stderr
    assert "to the breach (" in done.stderr and "to the end at most)" in done.stderr
    assert "breach: the shell opened" in done.stdout


def test_the_breach_is_foretold_where_the_grid_opens():
    # the grid opens with some ice still measured (an outer cell drained next to a cavity
    # cell half liquid: 0 to half a cell); foretold at a quarter of a 2 mm cell, 0.5 mm: the
    # 6 mm shell thinning at 0.004 mm/s reaches it at 1375 s, not 1500 s
    left = TimeLeft(end=7200.0, stops_at_breach=True, opens_at=0.5)
    _drive(left, pace=4.0, shell0=6.0, rate=0.004, t_stop=600.0)
    assert left.breach_at() == pytest.approx(1375.0)
    left.row(1380.0, 0.45)  # already below it, not yet open: imminent
    assert left.breach_at() == 1380.0
