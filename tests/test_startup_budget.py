"""``whitted bench --startup``: the budget of one whole ``whitted render`` process, from the
moments the process notes (whitted/marks.py) and the launch and exit timed outside it."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from whitted import marks
from whitted.bench.startup import PHASES, StartupBudget, StartupError, phases

ROOT = Path(__file__).resolve().parents[1]


def test_phases_from_marks_worked_numbers():
    got = phases({"interpreter": 10.05, "command": 10.30, "job": 10.45, "rendered": 10.95,
                  "written": 11.00, "build:seconds": 0.04, "kernels:seconds": 0.10,
                  "render:seconds": 0.30}, launched=10.0, ended=11.02)
    want = {"interpreter": 0.05, "imports": 0.25, "scene": 0.15 + 0.04, "kernels": 0.10,
            "render": 0.30, "other work": 0.50 - 0.04 - 0.10 - 0.30, "encoding": 0.05,
            "exit": 0.02, "whole process": 1.02}
    assert got.keys() == want.keys()
    for key, value in want.items():
        assert got[key] == pytest.approx(value, abs=1e-9), key
    # the phases add up to the whole process
    assert sum(got[p] for p in PHASES) == pytest.approx(got["whole process"], abs=1e-9)


def test_a_process_that_noted_nothing_is_one_clear_error():
    with pytest.raises(StartupError, match="noted no interpreter"):
        phases({}, 0.0, 1.0)


def test_the_budget_table_holds_medians_and_the_ratio():
    budget = StartupBudget("x", runs=[dict.fromkeys([*PHASES, "whole process"], v)
                                      for v in (1.0, 3.0, 2.0)], povray_wall=[4.0, 4.0, 5.0])
    data = budget.as_dict()
    assert data["median"]["render"] == 2.0 and data["median"]["whole process"] == 2.0
    assert data["ratio_wall"] == 0.5


def test_marks_cost_nothing_unless_asked(tmp_path, monkeypatch):
    monkeypatch.delenv(marks.ENV, raising=False)
    marks.mark("x")
    marks.write()
    assert not marks.enabled()
    target = tmp_path / "marks.jsonl"
    monkeypatch.setenv(marks.ENV, str(target))
    marks.mark("a", at=1.5)
    marks.note("render", 0.25)
    marks.write()
    lines = [json.loads(line) for line in target.read_text().splitlines()]
    assert lines == [{"name": "a", "value": 1.5}, {"name": "render:seconds", "value": 0.25}]


def test_bench_startup_times_a_real_render_process(tmp_path):
    scene = tmp_path / "tiny.toml"
    scene.write_text("[render]\nwidth = 16\nheight = 12\n\n[[objects]]\ntype = \"sphere\"\n"
                     "radius = 1.0\n\n[[lights]]\ntype = \"point\"\nposition = [0, 5, 5]\n")
    out = tmp_path / "budget.json"
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    result = subprocess.run([sys.executable, "-m", "whitted", "bench", "--startup", "--scene",
                             str(scene), "--runs", "1", "--json", str(out)],
                            capture_output=True, text=True, timeout=900, env=env)
    assert result.returncode == 0, result.stderr
    assert "whole process" in result.stdout and "interpreter" in result.stdout
    data = json.loads(out.read_text())[0]
    median = data["median"]
    assert all(median[p] >= 0 for p in PHASES)
    assert sum(median[p] for p in PHASES) == pytest.approx(median["whole process"], rel=1e-6)


def test_bench_startup_refuses_what_is_no_scene(tmp_path):
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    result = subprocess.run([sys.executable, "-m", "whitted", "bench", "--startup", "--scene",
                             str(tmp_path / "missing.toml")],
                            capture_output=True, text=True, timeout=300, env=env)
    assert result.returncode == 2
    assert result.stderr.strip().count("\n") == 0
    assert "neither a benchmark scene nor a scene file" in result.stderr


def test_numba_s_import_counts_with_the_imports():
    """Numba comes in with the first kernel (in the job, before the kernels' own figure):
    the budget moves that time from the job's other work to the imports."""
    base = {"interpreter": 10.05, "command": 10.30, "job": 10.45, "rendered": 10.95,
            "written": 11.00, "build:seconds": 0.04, "kernels:seconds": 0.10,
            "render:seconds": 0.30}
    got = phases({**base, "numba:start": 10.46, "numba:end": 10.51}, 10.0, 11.02)
    assert got["imports"] == pytest.approx(0.30)
    assert got["other work"] == pytest.approx(0.01)
    assert got["kernels"] == pytest.approx(0.10)
    assert sum(got[p] for p in PHASES) == pytest.approx(got["whole process"])
    early = phases({**base, "numba:start": 10.35, "numba:end": 10.40}, 10.0, 11.02)
    assert early["imports"] == pytest.approx(0.30) and early["scene"] == pytest.approx(0.14)
