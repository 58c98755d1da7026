"""benchmarks/render_window.py: a bench render's wall time taken apart per thread. The parts
must add up: a lane's wall time is its time on a CPU, waiting for one, or blocked."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "render_window.py"


def _run(*args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(SCRIPT.parents[1] / "src"),
                                         env.get("PYTHONPATH", "")])
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True,
                          timeout=900, env=env)


def test_the_render_window_adds_up():
    out = _run("seed000", "--threads", "1,2", "--runs", "1", "--size", "48x27")
    assert out.returncode == 0, out.stderr
    lines = out.stdout.strip().splitlines()
    assert lines[0].startswith("seed000, ")
    heads = lines[1].split()
    rows = {int(line.split()[0]): dict(zip(heads[1:], map(float, line.split()[1:]), strict=True))
            for line in lines[2:]}
    assert sorted(rows) == [1, 2]
    for threads, row in rows.items():
        assert row["render_s"] > 0.0 and row["on_cpu"] > 0.0
        assert row["majflt"] >= 0 and row["minflt"] >= 0
        # the lanes' wall time is on a CPU + waiting for one + blocked (the lanes run inside
        # the render's timer: at most its wall time each)
        parts = row["on_cpu"] + row["waiting"] + row["blocked"]
        assert parts <= threads * row["render_s"] + 0.01
        assert row["on_cpu"] <= threads * row["render_s"] + 0.01
    # one lane: nothing else of the process runs while it renders
    assert rows[1]["others"] < 0.5 * rows[1]["on_cpu"] + 0.005


def test_bad_arguments_are_one_line_and_exit_2():
    for args in (["seed000", "--runs", "0"], ["seed000", "--threads", "0"],
                 ["seed000", "--size", "48x"], ["seed000", "--threads", "one"]):
        out = _run(*args)
        assert out.returncode == 2
        assert out.stderr.strip().splitlines()[-1].startswith("render_window.py: error:")
