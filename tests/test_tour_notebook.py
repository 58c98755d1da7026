"""docs/tour.ipynb runs on a real Jupyter kernel (ipykernel, driven by nbclient) as a new user
would run it, and its outputs are what the tour promises: pictures, a live render's bar that
reached 100 %, a film that plays as an HTML5 <video>, a contact sheet, a viewer, and a
Stefan run's plot."""

from __future__ import annotations

import base64
import importlib.util
import io
import os
import time
from pathlib import Path

import numpy as np
import pytest

nbclient = pytest.importorskip("nbclient")
nbformat = pytest.importorskip("nbformat")
if importlib.util.find_spec("ipykernel") is None:  # the kernel runs in its own process;
    pytest.skip("ipykernel is not installed", allow_module_level=True)  # not imported here
pytest.importorskip("ipywidgets")

DOCS = Path(__file__).resolve().parents[1] / "docs"


def _png(data: str) -> np.ndarray:
    from PIL import Image as PILImage

    return np.asarray(PILImage.open(io.BytesIO(base64.b64decode(data))).convert("RGB"))


def _cell(nb, start: str):
    for cell in nb.cells:
        if cell.cell_type == "code" and start in cell.source:
            return cell
    raise AssertionError(f"no cell with {start!r}")


def _data(cell, mime: str) -> list:
    return [o["data"][mime] for o in cell.outputs if mime in o.get("data", {})]


@pytest.fixture(scope="module")
def tour(tmp_path_factory):
    """The tour, executed once (its temporary folders under a folder of the test's)."""
    tmp = tmp_path_factory.mktemp("tour")
    nb = nbformat.read(DOCS / "tour.ipynb", as_version=4)
    old = os.environ.get("TMPDIR")
    os.environ["TMPDIR"] = str(tmp)  # the kernel inherits it: film and run folders go there
    try:
        started = time.perf_counter()
        client = nbclient.NotebookClient(nb, timeout=600, startup_timeout=180,
                                         kernel_name="python3",
                                         resources={"metadata": {"path": str(DOCS)}})
        client.execute()
        nb.metadata["seconds"] = time.perf_counter() - started
    finally:
        if old is None:
            os.environ.pop("TMPDIR", None)
        else:
            os.environ["TMPDIR"] = old
    return nb


def test_tour_runs_without_an_error(tour):
    for cell in tour.cells:
        if cell.cell_type == "code":
            assert not [o for o in cell.outputs if o["output_type"] == "error"], cell.source


def test_tour_shows_the_default_scene(tour):
    cell = _cell(tour, "scene = whitted.default_scene()")
    (png,) = _data(cell, "image/png")
    picture = _png(png)
    assert picture.shape == (108, 192, 3)
    assert picture.std() > 10  # a picture, not a flat colour
    views = _data(cell, "application/vnd.jupyter.widget-view+json")
    assert len(views) == 1  # the live view, then the Image returned


def test_tour_live_render_reached_100_percent(tour):
    state = tour.metadata["widgets"]["application/vnd.jupyter.widget-state+json"]["state"]
    cell = _cell(tour, "scene = whitted.default_scene()")
    (view,) = _data(cell, "application/vnd.jupyter.widget-view+json")
    box = state[view["model_id"]]["state"]
    bar_row = state[box["children"][0].removeprefix("IPY_MODEL_")]["state"]
    bar = state[bar_row["children"][0].removeprefix("IPY_MODEL_")]
    assert bar["model_name"] == "FloatProgressModel"
    assert bar["state"]["value"] == 100.0 and bar["state"]["bar_style"] == "success"
    label = state[box["children"][1].removeprefix("IPY_MODEL_")]["state"]["value"]
    assert label.startswith("192x108") and "rays" in label


def test_tour_film_plays_as_html5_video(tour):
    cell = _cell(tour, "film = whitted.render_film(")
    (html,) = _data(cell, "text/html")
    assert "<video" in html and "data:video/mp4;base64," in html
    assert "12 frames at 6 fps, 96x54" in _data(cell, "text/plain")[-1]
    frames = _cell(tour, "whitted.film_from_frames(")
    assert "<video" in _data(frames, "text/html")[0]


def test_tour_sweep_and_models_are_pictures(tour):
    sheet = _png(_data(_cell(tour, "whitted.sweep("), "image/png")[0])
    assert sheet.shape[1] > 4 * 96  # four cells side by side
    teapot = _png(_data(_cell(tour, "teapot_glass.toml"), "image/png")[0])
    assert teapot.shape == (100, 160, 3) and teapot.std() > 10
    caustics = _png(_data(_cell(tour, "caustics="), "image/png")[0])
    assert caustics.shape == (108, 192, 3)


def test_tour_viewer_and_its_one_line_error(tour):
    cell = _cell(tour, "viewer = whitted.viewer(")
    assert _data(cell, "application/vnd.jupyter.widget-view+json")
    error = _cell(tour, "viewer.set(")
    text = "".join(o.get("text", "") for o in error.outputs if o["output_type"] == "stream")
    assert "ior" in text and text.count("\n") == 1 and "Traceback" not in text


def test_tour_stefan_run_plots(tour):
    cell = _cell(tour, "whitted.run_stefan(")
    plot = _png(_data(cell, "image/png")[0])
    assert plot.shape[1] > 2 * plot.shape[0]  # melt fraction, shell, heat budget
    assert "melted" in _data(cell, "text/plain")[-1]


def test_tour_awaited_render_has_a_stop_button(tour):
    state = tour.metadata["widgets"]["application/vnd.jupyter.widget-state+json"]["state"]
    cell = _cell(tour, "await whitted.render_async(")
    (view,) = _data(cell, "application/vnd.jupyter.widget-view+json")
    box = state[view["model_id"]]["state"]
    row = state[box["children"][0].removeprefix("IPY_MODEL_")]["state"]
    kinds = [state[c.removeprefix("IPY_MODEL_")] for c in row["children"]]
    assert [k["model_name"] for k in kinds] == ["FloatProgressModel", "ButtonModel"]
    assert kinds[1]["state"]["description"] == "Stop"
    assert kinds[0]["state"]["value"] == 100.0
    assert "192x108" in _data(cell, "text/plain")[-1]
