"""Files at names the user did not give (a default film, the AOVs beside a picture) are
replaced only when whitted wrote them: its films carry a mark (an MP4's metadata comment, a
GIF's comment), an NPY whitted wrote is recorded (output/ownership.py). Anything else there is
kept byte for byte, and the command ends in one line with status 2 before any work."""

from __future__ import annotations

import shutil

import imageio_ffmpeg
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PIL import Image as PILImage

from cli_run import one_line_error, run_main
from whitted.output import ownership
from whitted.output.ownership import record_written, recorded_by_whitted, written_by_whitted
from whitted.output.video import encode_film, film_written_by_whitted

TINY = ("-W", "8", "-H", "6", "-q")
FOREIGN = "a file not marked as whitted's is there (someone else's, or an older whitted's); " \
          "it is kept"


@pytest.fixture(autouse=True)
def _own_records(tmp_path, monkeypatch):
    """The records of the files whitted wrote kept beside the test's folder (the kernel
    cache, and so the cache folder, stays the one the tests share)."""
    records = tmp_path.with_name(tmp_path.name + "-records")
    monkeypatch.setattr(ownership, "_records", lambda: records)


def _frames(n: int = 2) -> list[np.ndarray]:
    return [np.full((6, 8, 3), 40 * k, np.uint8) for k in range(n)]


def _foreign_mp4(path) -> bytes:
    """An MP4 someone else encoded (imageio-ffmpeg's own writer, no whitted comment)."""
    writer = imageio_ffmpeg.write_frames(str(path), (8, 6), fps=10, quality=5,
                                         macro_block_size=2, ffmpeg_log_level="error")
    writer.send(None)
    for frame in _frames():
        writer.send(frame)
    writer.close()
    return path.read_bytes()


def test_whitted_s_films_carry_the_mark_and_others_do_not(tmp_path):
    mp4 = encode_film(_frames(), tmp_path / "a.mp4", fps=10)
    gif = encode_film(_frames(), tmp_path / "a.gif", fps=10)
    assert film_written_by_whitted(mp4) and film_written_by_whitted(gif)
    assert written_by_whitted(mp4) and written_by_whitted(gif)
    with PILImage.open(gif) as im:
        assert im.info["comment"] == b"whitted"
    _foreign_mp4(tmp_path / "b.mp4")
    PILImage.fromarray(_frames()[1]).save(tmp_path / "b.gif")
    (tmp_path / "c.mp4").write_bytes(mp4.read_bytes()[:200])  # cut short: unreadable
    (tmp_path / "d.mp4").write_bytes(b"\0\0\0\x18ftypisom" + bytes(100))
    for name in ("b.mp4", "b.gif", "c.mp4", "d.mp4", "missing.mp4"):
        assert not film_written_by_whitted(tmp_path / name), name
    (tmp_path / "dir.mp4").mkdir()
    assert not written_by_whitted(tmp_path / "dir.mp4")


def test_a_user_s_remux_or_copy_of_whitted_s_film_is_theirs(tmp_path):
    """The mark survives a remux (ffmpeg ``-c copy``, which keeps the metadata) and a copy;
    only the very bytes whitted wrote at that place are whitted's."""
    import subprocess

    from whitted.output.video import ffmpeg_exe

    film = encode_film(_frames(), tmp_path / "film.mp4", fps=10)
    cut = tmp_path / "cut.mp4"
    subprocess.run([ffmpeg_exe(), "-nostdin", "-loglevel", "error", "-i", str(film),
                    "-c", "copy", "-t", "0.1", str(cut)], check=True)
    assert film_written_by_whitted(film) and not film_written_by_whitted(cut)
    cut.replace(film)  # the user's cut saved over whitted's film
    assert not film_written_by_whitted(film) and not written_by_whitted(film)
    copy = tmp_path / "copy.gif"
    gif = encode_film(_frames(), tmp_path / "a.gif", fps=10)
    copy.write_bytes(gif.read_bytes())  # whitted's bytes, but not written there by whitted
    assert film_written_by_whitted(gif) and not film_written_by_whitted(copy)


def test_an_npy_is_whitted_s_while_it_holds_the_bytes_recorded(tmp_path):
    path = tmp_path / "x.depth.npy"
    np.save(path, np.arange(6, dtype=np.float32))
    assert not recorded_by_whitted(path)  # written, never recorded
    record_written(path)
    assert recorded_by_whitted(path) and written_by_whitted(path)
    copy = tmp_path / "copy.npy"
    shutil.copy(path, copy)
    assert not recorded_by_whitted(copy)  # the record is of the path
    np.save(path, np.arange(6, dtype=np.float32) + 1)  # changed since: someone else's
    assert not recorded_by_whitted(path)
    record_written(path)
    assert recorded_by_whitted(path)
    record = ownership._records() / f"{ownership._key(path)}.json"
    record.write_text("{damaged")
    assert not recorded_by_whitted(path)


def test_the_default_film_replaces_only_whitted_s_own(tmp_path, examples_dir):
    scene = tmp_path / "orbit.toml"
    shutil.copy(examples_dir / "glass_cube.toml", scene)
    film = tmp_path / "film.mp4"
    animate = ("animate", scene, "--turntable", "2", *TINY)
    code, _, err = run_main(*animate, cwd=tmp_path)
    assert code == 0, err
    assert film_written_by_whitted(film)
    first = film.read_bytes()
    code, _, err = run_main(*animate[:3], "3", *TINY, cwd=tmp_path)
    assert code == 0, err  # whitted's own film: replaced (three frames now)
    assert film.read_bytes() != first and film_written_by_whitted(film)

    mine = _foreign_mp4(film)
    frames_before = sorted(p.name for p in (tmp_path / "film_frames").iterdir())
    one_line_error(run_main(*animate, cwd=tmp_path), f"film.mp4: {FOREIGN}", "-o film.mp4")
    assert film.read_bytes() == mine
    assert sorted(p.name for p in (tmp_path / "film_frames").iterdir()) == frames_before
    film.write_text("my notes")
    one_line_error(run_main(*animate, cwd=tmp_path), "film.mp4")
    assert film.read_text() == "my notes"

    text = scene.read_text()
    one_line_error(run_main("animate", scene, "-o", scene, *TINY, cwd=tmp_path), "orbit.toml")
    assert scene.read_text() == text  # an input named as the output: refused

    code, _, err = run_main(*animate, "-o", "film.mp4", cwd=tmp_path)
    assert code == 0, err  # named: the user's to replace
    assert film_written_by_whitted(film)


def test_the_default_turntable_film_replaces_only_whitted_s_own(tmp_path, examples_dir):
    scene = tmp_path / "cube.toml"
    shutil.copy(examples_dir / "glass_cube.toml", scene)
    film = tmp_path / "cube_turntable.mp4"
    mine = _foreign_mp4(film)
    one_line_error(run_main("render", scene, "--turntable", "2", *TINY, cwd=tmp_path),
                   f"cube_turntable.mp4: {FOREIGN}")
    assert film.read_bytes() == mine
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cube.toml", "cube_turntable.mp4"]
    film.unlink()
    code, _, err = run_main("render", scene, "--turntable", "2", *TINY, cwd=tmp_path)
    assert code == 0, err
    assert film_written_by_whitted(film)
    code, _, err = run_main("render", scene, "--turntable", "2", *TINY, cwd=tmp_path)
    assert code == 0, err  # whitted's own: replaced


def test_the_aovs_beside_a_picture_replace_only_whitted_s_own(tmp_path):
    depth, normal = tmp_path / "shot.depth.npy", tmp_path / "shot.normal.npy"
    render = ("render", *TINY, "-o", "shot.png", "--aov", "depth,normal")
    code, _, err = run_main(*render, cwd=tmp_path)
    assert code == 0, err
    assert np.load(depth).shape == (6, 8) and recorded_by_whitted(normal)
    code, _, err = run_main(*render[:-1], "depth", "-W", "10", cwd=tmp_path)
    assert code == 0, err  # whitted's own: replaced
    assert np.load(depth).shape == (6, 10)

    np.save(normal, np.ones(3))  # the user's own array at a name the user did not give
    mine, picture = normal.read_bytes(), (tmp_path / "shot.png").read_bytes()
    one_line_error(run_main(*render, cwd=tmp_path), f"shot.normal.npy: {FOREIGN}",
                   "move it, or give -o another name")
    assert normal.read_bytes() == mine
    assert (tmp_path / "shot.png").read_bytes() == picture  # nothing written
    assert np.load(depth).shape == (6, 10)


def test_a_foreign_file_at_the_tile_state_name_is_not_taken_for_whitted_s(tmp_path):
    """The state an interrupted render keeps (``NAME.whitted-tiles``): a zip of someone else's
    that happens to hold a member called magic.npy is still someone else's."""
    import io
    import zipfile

    from whitted.cli.tile_state import foreign

    path = tmp_path / "shot.png.whitted-tiles"
    with zipfile.ZipFile(path, "w") as z:
        buffer = io.BytesIO()
        np.save(buffer, np.array("not whitted"))
        z.writestr("magic.npy", buffer.getvalue())
    assert foreign(path)


def test_the_default_study_plot_replaces_only_whitted_s_own(tmp_path):
    """``whitted bench --study`` without --plot writes bench-study-KIND.png here: a file of
    someone else's there stops it in one line before the (long) study runs."""
    from whitted.bench.studies import plot_study

    plot = tmp_path / "bench-study-threads.png"
    PILImage.new("RGB", (3, 2)).save(plot)
    mine = plot.read_bytes()
    one_line_error(run_main("bench", "--study", "threads", "--quick", cwd=tmp_path),
                   f"bench-study-threads.png: {FOREIGN}")
    assert plot.read_bytes() == mine
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bench-study-threads.png"]
    rows = [{"scene": "seed000", "width": 8, "height": 8, "threads": t, "render_s": 1.0 / t,
             "wall_s": 1.2 / t, "mrays_per_s": 1.0} for t in (1, 2)]
    plot_study("threads", rows, plot, with_seed=False)  # the plot the study writes
    assert written_by_whitted(plot)


def test_two_bench_results_never_go_to_one_file(tmp_path):
    one_line_error(run_main("bench", "--quick", "--json", "out.txt", "--markdown", "out.txt",
                            cwd=tmp_path), "--markdown: out.txt is the file --json names too")
    assert not any(tmp_path.iterdir())
    (tmp_path / "loop").symlink_to("loop")  # a link to itself: one line too, no traceback
    code, _, err = run_main("bench", "--quick", "--json", "loop", "--markdown", "out.md",
                            cwd=tmp_path)
    assert code == 2 and err.strip().count("\n") == 0 and "loop" in err, err


def test_the_default_melt_film_replaces_only_whitted_s_own(tmp_path, examples_dir):
    """``whitted stefan film`` without -o writes melt.mp4 here: someone else's melt.mp4
    stops it in one line before the solve, and nothing is written."""
    case = examples_dir / "stefan" / "hollow_ice.toml"
    film = tmp_path / "melt.mp4"
    mine = _foreign_mp4(film)
    one_line_error(run_main("stefan", "film", case, "-W", "8", "-H", "6", cwd=tmp_path),
                   f"melt.mp4: {FOREIGN}")
    assert film.read_bytes() == mine
    assert sorted(p.name for p in tmp_path.iterdir()) == ["melt.mp4"]


@settings(max_examples=30, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(head=st.sampled_from([b"", b"GIF89a", b"\0\0\0\x18ftypisom", b"\x89PNG\r\n\x1a\n"]),
       body=st.binary(max_size=400))
def test_no_bytes_at_a_default_name_pass_for_whitted_s(tmp_path, head, body):
    """Whatever someone else's file holds (a film's or a PNG's first bytes, then anything), it
    is never taken for whitted's, and reading it never raises."""
    path = tmp_path / "film.mp4"
    path.write_bytes(head + body)
    assert not written_by_whitted(path)
    record = ownership._records() / f"{ownership._key(path)}.json"
    if not record.exists():  # a damaged record is no record
        record.parent.mkdir(parents=True, exist_ok=True)
        record.write_bytes(body)
        try:
            assert not recorded_by_whitted(path)
        finally:
            record.unlink()


def test_records_of_files_gone_are_swept_past_the_limit(tmp_path, monkeypatch):
    monkeypatch.setattr(ownership, "RECORDS_KEPT", 3)
    files = [tmp_path / f"{k}.npy" for k in range(4)]
    for path in files:
        np.save(path, np.zeros(2))
        record_written(path)
    files[0].unlink()
    files[1].write_bytes(b"changed")
    np.save(files[2], np.ones(2))  # the same size: kept, yet no longer whitted's
    kept = tmp_path / "4.npy"
    np.save(kept, np.zeros(2))
    record_written(kept)
    assert len(list(ownership._records().iterdir())) == 3
    assert recorded_by_whitted(kept) and recorded_by_whitted(files[3])
    assert not recorded_by_whitted(files[2])
