"""The film of a Stefan run (whitted.stefan.film) through the film pipeline: after a breach in
drain mode each saved time is its own still life; its frames record what they show, so a
second film renders none of them again, and every frame is stamped with its time."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from whitted.animation.film import FilmProgress
from whitted.fingerprint import FINGERPRINT_KEY, renderer_fingerprint
from whitted.stefan.case import Case
from whitted.stefan.film import render_melt_film
from whitted.stefan.run import film_frames, run_case


@pytest.fixture(scope="module")
def drained(tmp_path_factory) -> tuple[Path, Case]:
    """A 2-cell shell that opens early and drains: frames after the breach have no cavity."""
    case = Case.model_validate({"grid": {"cells": 12}, "cavity": {"radius": 0.0135,
                               "temperature": 60.0}, "air": {"h": 30.0, "temperature": 30.0},
                               "time": {"end": 1800.0, "save_every": 600.0},
                               "breach": {"action": "drain"}, "surfaces": {"smoothing": 2}})
    out = tmp_path_factory.mktemp("stefan") / "drain"
    run_case(case, "", out, scene_size=(32, 24))
    return out, case


def test_a_drained_run_films_each_saved_time_and_resumes(drained, tmp_path):
    import imageio.v3 as iio

    out, case = drained
    shown = film_frames(out)
    assert any(f.inner is None for f in shown)  # the drain branch
    events: list[FilmProgress] = []
    film = tmp_path / "melt.gif"
    made = render_melt_film(out, case, [film], width=32, height=24, fps=4,
                            progress=events.append)
    assert not made.cancelled and made.films == [film] and made.count == len(shown)
    assert [p.name for p in made.frames] == [f"{k:04d}.png" for k in range(len(shown))]
    assert sorted(e.frame for e in events if e.event == "done") == list(range(len(shown)))
    for path in made.frames:  # frames that say what they are: resumable
        from PIL import Image

        with Image.open(path) as im:
            assert im.text[FINGERPRINT_KEY] == renderer_fingerprint()
    frames = iio.imread(film, index=None)
    assert frames.shape[:3] == (len(shown), 24, 32)
    raw = iio.imread(made.frames[0])
    stamped = np.abs(frames[0][..., :3].astype(int) - raw[..., :3].astype(int)).sum(axis=2)
    assert stamped[:12, :].max() > 150  # the time, in white, at the top

    again: list[FilmProgress] = []
    second = render_melt_film(out, case, [tmp_path / "again.gif"], width=32, height=24, fps=4,
                              progress=again.append)
    assert not [e for e in again if e.event == "done"]  # every frame kept
    assert second.frames == made.frames
    assert (tmp_path / "again.gif").read_bytes() == film.read_bytes()


def test_a_run_with_nothing_to_film_is_one_line(tmp_path):
    from whitted.errors import WhittedError

    (tmp_path / "series.csv").write_text("time_s\n0.0\n")
    with pytest.raises(WhittedError, match=r"no saved time has a surface to film$"):
        render_melt_film(tmp_path, None, [tmp_path / "x.gif"], width=8, height=8, fps=4)
