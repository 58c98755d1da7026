"""whitted in a notebook, without a kernel: the live render view (progress, picture, Stop,
the interrupt), films inline, sweeps as contact sheets, the viewer, Stefan results. The
widgets are real ipywidgets objects; ``IPython.display.display`` is replaced by a list."""

from __future__ import annotations

import asyncio
import base64
import io
import os
import signal
import time

import numpy as np
import pytest

pytest.importorskip("ipywidgets")

import whitted  # noqa: E402
from whitted.errors import OutputError, SceneError  # noqa: E402
from whitted.notebook import detect, live  # noqa: E402


@pytest.fixture(autouse=True)
def kernel_interrupt():
    """Ctrl-C as a Jupyter kernel has it (Python's own handler: KeyboardInterrupt in the main
    thread), whatever handler an earlier test of the whitted program left installed."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


@pytest.fixture
def shown(monkeypatch):
    """What the code under test displayed."""
    import IPython.display

    items = []
    monkeypatch.setattr(IPython.display, "display", lambda *objs, **_: items.extend(objs))
    return items


@pytest.fixture(scope="module")
def scene():
    return whitted.default_scene().with_settings(width=64, height=40, threads=2)


def _until(condition, seconds: float = 30.0) -> None:
    """Wait (on the render's thread) until the watcher has acted."""
    end = time.monotonic() + seconds
    while not condition() and time.monotonic() < end:
        time.sleep(0.005)


def _png(data: bytes) -> np.ndarray:
    from PIL import Image as PILImage

    return np.asarray(PILImage.open(io.BytesIO(data)).convert("RGB"))


# ------------------------------------------------------------------ detection
def test_detection_outside_a_kernel(monkeypatch):
    monkeypatch.delenv("WHITTED_NOTEBOOK", raising=False)
    assert not detect.in_notebook()  # pytest is no notebook
    monkeypatch.setenv("WHITTED_NOTEBOOK", "1")
    assert detect.in_notebook()
    monkeypatch.setenv("WHITTED_NOTEBOOK", "0")
    assert not detect.in_notebook()
    monkeypatch.setenv("WHITTED_NOTEBOOK", "1")
    monkeypatch.setattr(detect, "widgets_installed", lambda: False)
    assert not detect.in_notebook()  # forced on, but no extra: the plain path
    assert not detect.live_view(None)
    with pytest.raises(whitted.WhittedError, match=r"whitted\[notebook\]"):
        detect.live_view(True)  # asked for by name: one line naming the extra


def test_plain_render_outside_a_notebook_shows_nothing(scene, shown):
    image = whitted.render(scene)
    assert shown == []
    reference = whitted.render(scene, live=False)
    np.testing.assert_array_equal(image.pixels, reference.pixels)


# ------------------------------------------------------------------ live render
def test_live_render_fills_in_and_ends_at_100_percent(scene, shown):
    image = whitted.render(scene, live=True, width=96, height=64)
    assert len(shown) == 1
    box = shown[0]
    view = box.view
    assert view.bar.value == 100.0 and view.bar.bar_style == "success"
    assert "96x64" in view.status.value and "rays" in view.status.value
    assert len(box.children) == 2  # the picture went: the Image returned shows itself
    # the same picture as a render without the view (pixels do not depend on watching)
    np.testing.assert_array_equal(image.pixels,
                                  whitted.render(scene, live=False, width=96,
                                                 height=64).pixels)
    # the view's own work stays within its budget (the last update may take it over)
    wall = time.perf_counter() - view.started
    assert view.view_seconds <= live.BUDGET * wall + view.longest_update + 1e-3
    assert "whitted render" in repr(box)


def test_live_picture_shows_the_tiles_finished(scene):
    from whitted.render import RenderJob

    job = RenderJob(scene.with_settings(width=48, height=32), tile_size=8)
    view = live.LiveRender(job, picture=True)
    image = live.watch(job, view, keep_picture=True)
    assert view.picture.format == "png"
    np.testing.assert_array_equal(_png(view.picture.value), image.to_srgb8())


def test_live_preview_of_a_wide_render_is_every_nth_pixel(scene):
    from whitted.render import RenderJob

    job = RenderJob(scene.with_settings(width=1100, height=24), tile_size=16)
    view = live.LiveRender(job, picture=True)
    assert view.step == 3 and view._display.shape == (8, 367, 3)
    image = live.watch(job, view)
    view._paint()  # the rows finished after the last update
    np.testing.assert_array_equal(view._display, image.to_srgb8()[::3, ::3])


def test_interrupt_stops_and_returns_the_picture_so_far(scene, shown):
    interrupted = []

    def interrupt_once(progress):
        if not interrupted:
            interrupted.append(progress.tiles_done)
            os.kill(os.getpid(), signal.SIGINT)  # as the notebook's ■ does
            _until(lambda: shown and shown[0].view.stop_requested)

    big = scene.with_settings(width=160, height=120, threads=1)
    image = whitted.render(big, live=True, progress=interrupt_once)
    stats = image.meta["stats"]
    assert stats.cancelled and 0 < stats.tiles_done < stats.tiles_total
    view = shown[0].view
    assert view.bar.bar_style == "warning" and "stopped at" in view.status.value
    assert view.job.cancelled
    np.testing.assert_array_equal(image.to_srgb8(), view.job.srgb())


def test_stop_button_of_an_awaited_render(scene, shown):
    clicked = []

    def click_stop(progress):
        if not clicked and shown:
            clicked.append(1)
            hbox = shown[0].children[0]
            hbox.children[1].click()  # the Stop button, as a user's click arrives

    big = scene.with_settings(width=160, height=120, threads=1)
    image = asyncio.run(whitted.render_async(big, live=True, progress=click_stop))
    assert clicked
    view = shown[0].view
    assert view.stop_requested and view.job.cancelled
    assert image.meta["stats"].cancelled
    assert view.bar.description == "stopped"


def test_failed_live_render_says_why(scene, shown):
    def broken(_progress):
        raise RuntimeError("broken callback")

    with pytest.raises(RuntimeError, match="broken callback"):
        whitted.render(scene, live=True, progress=broken)
    view = shown[0].view
    assert view.bar.bar_style == "danger" and "broken callback" in view.status.value


def test_bad_settings_raise_one_line_before_any_view(scene, shown):
    with pytest.raises(whitted.WhittedError) as info:
        whitted.render(scene, live=True, width=-3)
    assert "\n" not in str(info.value)
    assert shown == []


# ------------------------------------------------------------------ films
def _frames(folder, n=3, size=(9, 6)):
    from PIL import Image as PILImage

    folder.mkdir()
    for k in range(n):
        pixels = np.full((size[1], size[0], 3), 40 * k, np.uint8)
        PILImage.fromarray(pixels).save(folder / f"{k:04d}.png")
    return folder


def test_film_from_frames_plays_as_html5_video(tmp_path):
    film = whitted.film_from_frames(_frames(tmp_path / "frames"), fps=12)
    assert film.kind == "mp4" and film.frames == 3 and film.fps == 12.0
    assert film.size == (10, 6)  # H.264 wants even sides: one column more
    assert repr(film) == "<Film in memory, MP4: 3 frames at 12 fps, 10x6, 0.2 s>"
    html = film._repr_html_()
    assert "<video" in html and 'src="data:video/mp4;base64,' in html
    data = base64.b64decode(html.split("base64,")[1].split('"')[0])
    assert data[4:8] == b"ftyp" and data == film.data
    saved = film.save(tmp_path / "film.mp4")
    assert saved.read_bytes() == film.data
    with pytest.raises(OutputError, match="use a .mp4 name"):
        film.save(tmp_path / "film.gif")


def test_film_is_a_gif_without_an_encoder(tmp_path, monkeypatch):
    from whitted.output import inline_film

    monkeypatch.setattr(inline_film, "mp4_encoder", lambda: False)
    film = whitted.Film.from_frames(_frames(tmp_path / "frames", n=2), fps=5)
    assert film.kind == "gif" and film.size == (9, 6) and film.data[:4] == b"GIF8"
    assert "<img" in film._repr_html_() and "image/gif" in film._repr_html_()


@pytest.mark.parametrize("case", ["missing", "file", "empty", "foreign"])
def test_film_from_frames_bad_folders_are_one_line(tmp_path, case):
    folder = tmp_path / "frames"
    if case == "file":
        folder.write_text("not a folder")
    elif case == "empty":
        folder.mkdir()
    elif case == "foreign":
        folder.mkdir()
        (folder / "notes.txt").write_text("x")
    with pytest.raises(OutputError) as info:
        whitted.film_from_frames(folder)
    assert "\n" not in str(info.value) and str(folder) in str(info.value)


def test_frames_of_different_sizes_are_refused(tmp_path):
    from PIL import Image as PILImage

    folder = _frames(tmp_path / "frames", n=2)
    PILImage.new("RGB", (4, 4)).save(folder / "0002.png")
    with pytest.raises(OutputError, match="cannot make a film"):
        whitted.film_from_frames(folder)


def test_render_film_returns_a_film_that_plays(tmp_path, shown, examples_dir):
    film = whitted.render_film(examples_dir / "camera_orbit.toml", tmp_path / "orbit.mp4",
                               frames=range(0, 48, 24), width=32, height=18, fps=4,
                               live=True)
    assert film.path == tmp_path / "orbit.mp4" and film.path.is_file()
    assert (film.frames, film.fps, film.size) == (2, 4.0, (32, 18))
    assert "<video" in film._repr_html_()
    assert film.result.rendered == [0, 24]
    assert film.frames_folder == tmp_path / "orbit_frames"
    view = shown[0]
    assert "2 rendered" in view.children[1].value
    # again: every frame is kept (resume), the film encoded again
    again = whitted.render_film(examples_dir / "camera_orbit.toml", tmp_path / "orbit.mp4",
                                frames=range(0, 48, 24), width=32, height=18, fps=4)
    assert again.result.kept == [0, 24] and again.result.rendered == []


# ------------------------------------------------------------------ sweeps
def test_sweep_returns_a_contact_sheet_of_real_renders(scene, shown):
    path = "objects[glass sphere].material.ior"
    sheet = whitted.sweep(scene, {path: [1.0, 1.5]}, width=32, height=20, live=True)
    assert sheet.complete and sheet.labels == ["ior = 1", "ior = 1.5"]
    reference = whitted.render(scene.with_settings(width=32, height=20), live=False)
    # ior 1.5 is the default scene's own value: that cell is the scene's render
    np.testing.assert_array_equal(sheet.images[1].pixels, reference.pixels)
    assert _png(sheet._repr_png_()).shape == sheet.pixels.shape
    assert "ContactSheet" in repr(sheet) and "(2)" in repr(sheet)
    assert shown[0].children[0].value == 100.0


def test_sweep_bad_path_is_one_line_before_rendering(scene):
    with pytest.raises(SceneError) as info:
        whitted.sweep(scene, {"objects[no such].radius": [1, 2]}, live=False)
    assert "\n" not in str(info.value) and "no such" in str(info.value)


# ------------------------------------------------------------------ viewer
def test_viewer_renders_coarse_then_full_and_shows_bad_values(scene):
    path = "objects[glass sphere].material.ior"
    v = whitted.viewer(scene, {path: (1.0, 2.5), "camera.aperture": (0.0, 0.3)},
                       width=48, height=32)
    try:
        assert v.wait(120)
        assert v.renders == 2  # a quarter size, then the full picture
        plain = whitted.render(scene, live=False, width=48, height=32)
        np.testing.assert_array_equal(v.image.pixels, plain.pixels)
        np.testing.assert_array_equal(_png(v.picture.value), plain.to_srgb8())
        v.set(path, -1.0)  # refused by the scene: one line, no render, no exception
        assert v.wait(60)
        assert v.error is not None and "\n" not in v.error and "ior" in v.error
        assert v.status.value.startswith("⚠") and v.renders == 2
        v.sliders[path].value = 1.0  # as a user drags the slider
        assert v.wait(120)
        assert v.error is None and v.renders == 4
        expected = whitted.render(scene.with_settings(width=48, height=32).model_copy(),
                                  live=False)
        assert not np.array_equal(v.image.pixels, expected.pixels)  # ior 1: a different image
    finally:
        v.close()


def test_viewer_bad_slider_is_one_line(scene):
    with pytest.raises(whitted.WhittedError, match="min < max"):
        whitted.viewer(scene, {"camera.aperture": (0.3, 0.0)})
    with pytest.raises(whitted.WhittedError, match="nothing|unknown|no "):
        whitted.viewer(scene, {"camera.no_such": (0.0, 1.0)})


# ------------------------------------------------------------------ Stefan
def test_stefan_run_without_a_folder_is_titled_with_the_case(tmp_path, monkeypatch,
                                                              examples_dir):
    """No output folder: a temporary one, named after the case file, which titles the plot
    (not the temporary folder's random name)."""
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    results = whitted.run_stefan(examples_dir / "stefan" / "hollow_ice.toml",
                                 grid={"cells": 16}, time={"end": 60.0, "save_every": 60.0},
                                 live=False)
    assert results.folder.name == "hollow_ice"
    assert results.folder.parent.parent == tmp_path
    assert list(results.time_s) == [0.0, 60.0]
    assert results.figure().get_suptitle() == "hollow_ice"


def test_stefan_results_plot_and_balance(tmp_path, shown, examples_dir):
    results = whitted.run_stefan(examples_dir / "stefan" / "hollow_ice.toml",
                                 tmp_path / "melt", grid={"cells": 16},
                                 time={"end": 240.0, "save_every": 120.0}, live=True)
    assert list(results.time_s) == [0.0, 120.0, 240.0]
    melt = results.melt_fraction
    assert melt[0] == 0.0 and np.all(np.diff(melt) > 0) and melt[-1] < 1
    assert np.all(results.heat_in_J[1:] > 0) and results.heat_in_J[0] == 0.0
    # the budget closes: stored = heat in - drained + the solver's imbalance (round-off)
    assert np.all(np.abs(results.imbalance_J) < 1e-6 * np.maximum(1.0, results.heat_in_J))
    assert results.min_shell_mm[-1] < results.min_shell_mm[0]
    picture = _png(results._repr_png_())
    assert picture.shape[1] > 2 * picture.shape[0]  # three panels side by side
    assert shown[0].children[0].value == 100.0
    assert "melted" in repr(results)
    from whitted.stefan.results import load_results

    again = load_results(tmp_path / "melt")
    np.testing.assert_array_equal(again.heat_in_J, results.heat_in_J)
    # a run written before series.csv had the budget's columns: from the saved states
    import csv

    series = tmp_path / "melt" / "series.csv"
    rows = list(csv.DictReader(io.StringIO(series.read_text())))
    older = [c for c in rows[0] if c not in ("heat_in_J", "heat_drained_J", "condensed_cm3")]
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=older, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    series.write_text(out.getvalue())
    from_states = load_results(tmp_path / "melt")
    np.testing.assert_allclose(from_states.heat_in_J, results.heat_in_J, rtol=1e-12)
    np.testing.assert_allclose(from_states.drained_J, results.drained_J, rtol=0, atol=1e-9)
    # a damaged saved state: that time's budget is unknown (NaN), the rest stands
    (tmp_path / "melt" / "fields" / "state_0001.npz").write_bytes(b"not a state")
    damaged = load_results(tmp_path / "melt")
    assert np.isnan(damaged.heat_in_J[1]) and damaged.heat_in_J[2] == results.heat_in_J[2]
    assert _png(damaged._repr_png_()).size
    # a damaged series: one line naming the folder
    from whitted.stefan.case import CaseError

    (tmp_path / "melt" / "series.csv").write_text("time_s,ice_volume_cm3\nzero,1\n")
    with pytest.raises(CaseError) as info:
        load_results(tmp_path / "melt")
    assert "\n" not in str(info.value) and "series.csv" in str(info.value)


def test_stefan_results_of_a_folder_without_a_run(tmp_path):
    from whitted.stefan.case import CaseError
    from whitted.stefan.results import load_results

    with pytest.raises(CaseError, match="no series.csv"):
        load_results(tmp_path)


# ------------------------------------------------------------------ probes
@pytest.mark.parametrize("fps", [0, -1, float("nan"), float("inf"), 1e300])
def test_film_from_frames_bad_rates_are_one_line(tmp_path, fps):
    with pytest.raises(OutputError) as info:
        whitted.film_from_frames(_frames(tmp_path / "frames", n=2), fps=fps)
    assert "\n" not in str(info.value) and "fps" in str(info.value).lower()


def test_film_save_into_a_place_that_cannot_take_it(tmp_path):
    film = whitted.film_from_frames(_frames(tmp_path / "frames", n=2), kind="gif")
    with pytest.raises(OutputError, match="cannot write"):
        film.save(tmp_path / "missing" / "film.gif")
    (tmp_path / "taken.gif").mkdir()
    with pytest.raises(OutputError, match="cannot write"):
        film.save(tmp_path / "taken.gif")
    assert (tmp_path / "taken.gif").is_dir()


def test_render_film_keeps_files_it_did_not_write(tmp_path, examples_dir):
    from PIL import Image as PILImage

    folder = tmp_path / "orbit_frames"
    folder.mkdir()
    PILImage.new("RGB", (4, 4)).save(folder / "0000.png")  # someone else's
    before = (folder / "0000.png").read_bytes()
    with pytest.raises(whitted.WhittedError, match="whitted did not write it"):
        whitted.render_film(examples_dir / "camera_orbit.toml", tmp_path / "orbit.mp4",
                            frames=[0], width=16, height=10, live=False)
    assert (folder / "0000.png").read_bytes() == before
    with pytest.raises(whitted.WhittedError):
        whitted.render_film(examples_dir / "camera_orbit.toml", examples_dir / "die.toml",
                            frames=[0], width=16, height=10, live=False)


def test_sheet_save_refuses_other_formats_and_bad_places(tmp_path, scene):
    sheet = whitted.sweep(scene, {"camera.aperture": [0.0, 0.1]}, width=16, height=10,
                          live=False)
    with pytest.raises(OutputError, match="PNG"):
        sheet.save(tmp_path / "sheet.jpg")
    with pytest.raises(OutputError, match="cannot write"):
        sheet.save(tmp_path / "no" / "sheet.png")
    assert _png(sheet.save(tmp_path / "sheet.png").read_bytes()).shape == sheet.pixels.shape


def test_viewer_render_errors_are_one_line(scene):
    v = whitted.viewer(scene, {"render.width": (8, 64)}, width=16, height=10)
    try:
        assert v.wait(60)
        v.set("render.width", 10 ** 9)  # refused by the render settings
        assert v.wait(60)
        assert v.error is not None and "\n" not in v.error and "width" in v.error
        assert v.error.startswith("render.width: ")  # the path, no command-line option
        v.set("render.width", 32)
        v.set("render.samples", "many")  # text is parsed as --set parses it: refused
        assert "samples" in v.error
        v.set("render.samples", 1)
        assert v.wait(60) and v.error is None and v.image.width == 32
    finally:
        v.close()


def test_stefan_into_a_file_is_one_line(tmp_path, examples_dir):
    from whitted.stefan.case import CaseError

    target = tmp_path / "taken"
    target.write_text("mine")
    with pytest.raises(CaseError) as info:
        whitted.run_stefan(examples_dir / "stefan" / "hollow_ice.toml", target,
                           grid={"cells": 16}, time={"end": 120.0, "save_every": 120.0},
                           live=False)
    assert "\n" not in str(info.value)
    assert target.read_text() == "mine"
    with pytest.raises(CaseError, match="cells"):
        whitted.run_stefan(examples_dir / "stefan" / "hollow_ice.toml", tmp_path / "x",
                           grid={"cells": 2}, live=False)


from hypothesis import given  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

_numbers = st.one_of(st.integers(-10**6, 10**6), st.floats(allow_nan=True, allow_infinity=True),
                     st.booleans(), st.text(max_size=3), st.none())


@given(st.one_of(st.tuples(_numbers, _numbers), st.tuples(_numbers, _numbers, _numbers),
                 st.lists(_numbers, max_size=4), _numbers,
                 st.dictionaries(st.sampled_from(["min", "max", "step", "x"]), _numbers)))
def test_slider_specs_make_a_slider_or_one_line(spec):
    from whitted.notebook.viewer import _slider

    try:
        slider = _slider("camera.aperture", spec, 0.1)
    except whitted.WhittedError as exc:
        assert "\n" not in str(exc)
    else:
        assert slider.description


def test_viewer_slider_of_values(scene):
    path = "objects[glass sphere].material.ior"
    v = whitted.viewer(scene, {path: [1.0, 1.5, None]}, width=16, height=10)
    try:
        assert v.wait(60) and v.values[path] == 1.5  # the scene's own value is among them
        slider = v.sliders[path]
        assert slider.value == 1 and slider.label == "1.5"
        slider.value = 0  # as a user moves it: the value is 1.0
        assert v.wait(60) and v.values[path] == 1.0 and v.error is None
        slider.value = 2  # None: refused by the material, one line
        assert v.wait(60) and v.values[path] is None and "ior" in v.error
        v.set(path, 1.5)
        assert slider.value == 1 and v.wait(60) and v.error is None
    finally:
        v.close()


def test_interrupted_sweep_returns_the_cells_finished(scene, shown, monkeypatch):
    token = whitted.CancelToken()
    sent = []

    def interrupt_in_second_cell(progress):
        if progress.done == 1 and progress.tiles is not None and not sent:
            sent.append(1)
            os.kill(os.getpid(), signal.SIGINT)
            _until(lambda: token.cancelled)

    from whitted.animation import sheet as sheet_module

    original = sheet_module.render_sweep

    def with_probe(*args, **kwargs):
        user = kwargs["progress"]

        def both(p):
            user(p)
            interrupt_in_second_cell(p)

        kwargs["progress"] = both
        return original(*args, **kwargs)

    monkeypatch.setattr(sheet_module, "render_sweep", with_probe)  # sweep() imports it
    sheet = whitted.sweep(scene, {"camera.aperture": [0.0, 0.1, 0.2]}, width=64, height=48,
                          threads=1, cancel=token, live=True)
    assert sent and not sheet.complete and len(sheet.images) == 1
    assert "stopped: 1 of 3 images" in shown[0].children[1].value


def test_render_film_into_a_folder_makes_the_film_in_memory(tmp_path, examples_dir):
    film = whitted.render_film(examples_dir / "camera_orbit.toml", tmp_path / "frames",
                               frames=[0, 1], width=16, height=10, fps=2, live=False)
    assert film.path is None and film.frames == 2 and film.kind in ("mp4", "gif")
    assert film.frames_folder == tmp_path / "frames"
    assert sorted(p.name for p in (tmp_path / "frames").iterdir()) == ["0000.png", "0001.png"]


def test_a_script_never_imports_the_widgets():
    import subprocess
    import sys

    code = ("import sys, whitted\n"
            "image = whitted.render(whitted.Scene(), width=4, height=4, threads=1)\n"
            "print(image.width, 'ipywidgets' in sys.modules, 'IPython' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=600, env={**os.environ, "WHITTED_NOTEBOOK": ""})
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["4", "False", "False"]
    assert out.stderr == ""


def test_a_big_film_is_linked_not_embedded(tmp_path, monkeypatch):
    from whitted.output import inline_film

    film = whitted.film_from_frames(_frames(tmp_path / "frames", n=2), kind="gif")
    path = film.save(tmp_path / "film.gif")
    on_disk = whitted.Film(path, frames=2, fps=24, size=(9, 6))
    monkeypatch.setattr(inline_film, "EMBED_LIMIT", 10)
    html = on_disk._repr_html_()
    assert f'src="{path.as_posix()}"' in html and "base64" not in html
    assert repr(on_disk) == "<Film film.gif: 2 frames at 24 fps, 9x6, 0.1 s>"


def test_the_first_compile_shows_in_the_bar(scene, monkeypatch):
    from whitted.render import RenderJob, warm_up

    job = RenderJob(scene)
    view = live.LiveRender(job, stop=False)
    monkeypatch.setattr(warm_up, "compile_progress", lambda: 0.4)
    view.update()
    assert view.bar.description == "compiling" and view.bar.value == 40.0
    assert "compiling the kernels" in view.status.value
    monkeypatch.setattr(warm_up, "compile_progress", lambda: None)
    view._next = 0.0
    view.update()
    assert "preparing the scene" in view.status.value


def test_render_async_outside_a_notebook_is_the_plain_render(scene, shown):
    image = asyncio.run(whitted.render_async(scene, live=False))
    assert shown == []
    np.testing.assert_array_equal(image.pixels, whitted.render(scene, live=False).pixels)


def test_the_view_turns_the_compile_bar_off_while_it_runs(scene, shown):
    from whitted.jit.progress import compile_bar_setting

    before = compile_bar_setting()
    during = []
    whitted.render(scene, live=True, progress=lambda p: during.append(compile_bar_setting()))
    assert during and set(during) == {False}  # the view shows a first compile itself
    assert compile_bar_setting() == before
    whitted.render(scene, live=False, progress=lambda p: during.append(compile_bar_setting()))
    assert during[-1] == before
