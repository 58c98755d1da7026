"""A first compile is never silent (jit/progress.py): the Python API logs it, shows a bar where
one can be seen, and keeps how long it took, so the next estimate is this machine's."""

from __future__ import annotations

import json
import logging

import pytest

from whitted.jit import progress


@pytest.fixture
def cache_root(tmp_path, monkeypatch):
    monkeypatch.setenv("WHITTED_CACHE_DIR", str(tmp_path))
    return tmp_path


class _Clock:
    """time.monotonic() as a compile of 12.5 s sees it."""

    def __init__(self) -> None:
        self.values = iter([100.0, 112.5])

    def monotonic(self) -> float:
        return next(self.values)


def test_a_compile_is_logged_and_its_time_kept(cache_root, caplog, monkeypatch):
    monkeypatch.setattr(progress, "_bar", False)
    monkeypatch.setattr(progress, "time", _Clock())
    assert progress.expected_seconds("the kernels") == progress.DEFAULT_SECONDS["the kernels"]
    with caplog.at_level(logging.INFO, logger="whitted"), \
            progress.CompileReport("the kernels", lambda: 0.5) as report:
        assert report.expected == progress.DEFAULT_SECONDS["the kernels"]
    messages = [r.getMessage() for r in caplog.records if r.name == "whitted"]
    assert messages[0].startswith("compiling the kernels (first run only; about 20 s)")
    assert messages[1].startswith("compiled the kernels in 12.5 s")
    kept = json.loads((cache_root / progress.TIMES).read_text())
    assert list(kept.values()) == [12.5]
    assert progress.expected_seconds("the kernels") == 12.5  # this machine's figure now


def test_a_stopped_compile_keeps_no_time(cache_root, caplog, monkeypatch):
    monkeypatch.setattr(progress, "_bar", False)
    with caplog.at_level(logging.INFO, logger="whitted"), pytest.raises(KeyboardInterrupt), \
            progress.CompileReport("the kernels", lambda: 0.1):
        raise KeyboardInterrupt
    assert not (cache_root / progress.TIMES).exists()
    assert any("stopped" in r.getMessage() for r in caplog.records)


def test_a_damaged_times_file_is_a_default_estimate(cache_root):
    (cache_root / progress.TIMES).write_text("{not json")
    assert progress.expected_seconds("the caustics kernels") == 25.0
    progress.record_seconds("the caustics kernels", 12.345)
    assert progress.expected_seconds("the caustics kernels") == 12.35


def test_the_bar_is_drawn_while_compiling(cache_root, monkeypatch):
    """Forced on (a notebook or terminal picks it by itself), the bar runs on a thread of
    its own until the compile ends."""
    monkeypatch.setattr(progress, "_bar", True)
    seen = []
    with progress.CompileReport("the kernels", lambda: seen.append(1) or 0.25) as report:
        assert report._thread is not None and report._thread.is_alive()
    assert not report._thread.is_alive()


def test_the_command_line_turns_the_bar_off(monkeypatch):
    monkeypatch.setattr(progress, "_bar", "auto")
    progress.show_compile_bar(False)
    assert progress._bar_wanted() is False
    progress.show_compile_bar("auto")


def test_bench_says_up_front_how_long_its_compiles_take(cache_root, monkeypatch):
    from rich.console import Console

    from whitted.bench import command
    from whitted.bench.runner import BenchOptions
    from whitted.render import warm_up

    progress.record_seconds("the kernels", 14.0)
    progress.record_seconds("the caustics kernels", 9.0)
    console = Console(record=True, width=200)
    monkeypatch.setattr(warm_up, "kernels_cached", lambda instances=False: False)
    command._say_compile_time(BenchOptions(scenes=["seed000", "caustics"], quick=True), console)
    assert "about 23 s" in console.export_text()
    monkeypatch.setattr(warm_up, "kernels_cached", lambda instances=False: True)
    quiet = Console(record=True, width=200)
    command._say_compile_time(BenchOptions(scenes=["seed000"], quick=True), quiet)
    assert quiet.export_text() == ""
