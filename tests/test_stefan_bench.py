"""``whitted stefan bench``: the throughput table on tiny grids, and its bad options refused in
one line."""

from __future__ import annotations

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from whitted.cli.main import app


def test_the_bench_measures_both_solvers_at_each_thread_count(tmp_path):
    from whitted.stefan.bench import measure

    rows = measure(cells=12, flow_cells=8, threads=(1, 2), runs=2, steps=3, flow_steps=2)
    assert [(r.solver.split()[0], r.threads) for r in rows] == [
        ("enthalpy", 1), ("enthalpy", 2), ("flow", 1), ("flow", 2)]
    for r in rows:
        assert len(r.runs) == 2 and all(v > 0.0 for v in r.runs)
        assert r.best >= r.median and r.per_thread == r.median / r.threads
    assert rows[2].cells == 8 ** 3
    out = tmp_path / "bench.json"
    result = CliRunner().invoke(app, ["stefan", "bench", "--cells", "12", "--flow-cells", "8",
                                      "--runs", "1", "--steps", "2", "-t", "1",
                                      "--json", str(out)])
    assert result.exit_code == 0, result.output
    assert "CPU:" in result.output and "enthalpy step" in result.output
    data = json.loads(out.read_text())
    assert data["cpu"] and {r["threads"] for r in data["rows"]} == {1}


@pytest.mark.parametrize("args, word", [
    (["-t", "two"], "--threads"), (["-t", "0"], "--threads"), (["-t", ""], "--threads"),
    (["--cells", "0"], "--cells"), (["--cells", "100000"], "--cells"),
    (["--flow-cells", "-3"], "--flow-cells"), (["--runs", "0"], "--runs"),
    (["--steps", "0"], "--steps")])
def test_bad_bench_options_are_one_line(args, word):
    result = CliRunner().invoke(app, ["stefan", "bench", *args])
    assert result.exit_code == 2
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and word in lines[0], result.output


def test_the_bench_json_is_not_written_into_a_missing_folder(tmp_path):
    result = CliRunner().invoke(app, ["stefan", "bench", "--json",
                                      str(tmp_path / "nope" / "b.json")])
    assert result.exit_code == 2 and "--json" in result.output


def test_the_bench_json_is_not_written_over_a_folder(tmp_path):
    result = CliRunner().invoke(app, ["stefan", "bench", "--json", str(tmp_path)])
    assert result.exit_code == 2 and "--json" in result.output
    assert list(tmp_path.iterdir()) == []


@settings(max_examples=60, deadline=None)
@given(st.text(max_size=12))
def test_any_thread_list_is_read_or_refused_in_one_line(text):
    import typer

    from whitted.cli.stefan import _thread_counts

    try:
        counts = _thread_counts(text)
    except typer.Exit as exc:
        assert exc.exit_code == 2
        return
    assert counts and all(1 <= c <= 1024 for c in counts)
    assert counts == tuple(int(t) for t in text.split(",") if t.strip())
