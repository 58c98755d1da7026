"""The live view costs a render at most a few per cent (interleaved A/B; speed-dependent, so
run apart: make test-timing)."""

from __future__ import annotations

import time

import pytest

pytest.importorskip("ipywidgets")

import whitted  # noqa: E402


@pytest.mark.timing
def test_live_view_slows_a_render_by_under_5_percent(monkeypatch):
    import IPython.display

    monkeypatch.setattr(IPython.display, "display", lambda *objs, **_: None)
    scene = whitted.default_scene().with_settings(width=640, height=360, threads=2)
    whitted.render(scene, live=False, width=32, height=18)  # kernels loaded
    plain, live = [], []
    for _ in range(5):  # alternating, so both see the same machine
        start = time.perf_counter()
        whitted.render(scene, live=False)
        plain.append(time.perf_counter() - start)
        start = time.perf_counter()
        whitted.render(scene, live=True)
        live.append(time.perf_counter() - start)
    assert min(live) <= 1.05 * min(plain) + 0.01, (plain, live)
