"""``whitted render`` without -o writes render.png in the current folder, and replaces only a
render.png whitted wrote (its PNG text 'Software: whitted'): a file of the user's at that
name is kept, in one line, as ``whitted export`` keeps a hand-written ``.pov``."""

from __future__ import annotations

from PIL import Image as PILImage

from cli_run import one_line_error, run_main
from whitted.output.png import written_by_whitted

TINY = ("-W", "8", "-H", "6", "-q")


def test_the_default_picture_replaces_only_its_own(tmp_path):
    picture = tmp_path / "render.png"
    code, _, err = run_main("render", *TINY, cwd=tmp_path)
    assert code == 0, err
    assert written_by_whitted(picture) and PILImage.open(picture).size == (8, 6)
    code, _, err = run_main("render", "-W", "10", "-H", "6", "-q", cwd=tmp_path)
    assert code == 0, err  # whitted's own: replaced
    assert PILImage.open(picture).size == (10, 6)

    PILImage.new("RGB", (3, 2), "red").save(picture)  # the user's own picture
    mine = picture.read_bytes()
    one_line_error(run_main("render", *TINY, cwd=tmp_path),
                   "render.png: a file not marked as whitted's is there (someone else's, or "
                   "an older whitted's); it is kept",
                   "-o render.png")
    assert picture.read_bytes() == mine
    picture.write_text("my notes")
    one_line_error(run_main("render", *TINY, cwd=tmp_path), "render.png")
    assert picture.read_text() == "my notes"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["render.png"]  # nothing else

    code, _, err = run_main("render", *TINY, "-o", "render.png", cwd=tmp_path)
    assert code == 0, err  # named: the user asked for it
    assert written_by_whitted(picture)


def test_a_frame_as_the_default_picture_is_whitted_s_too(tmp_path, examples_dir):
    """A film's frame rendered as a still (written as a film frame, with its record) carries
    the same text: the next `whitted render` replaces it."""
    scene = examples_dir / "camera_orbit.toml"
    code, _, err = run_main("render", scene, "--frame", "3", *TINY, cwd=tmp_path)
    assert code == 0, err
    assert written_by_whitted(tmp_path / "render.png")
    code, _, err = run_main("render", scene, *TINY, cwd=tmp_path)
    assert code == 0, err


def test_the_default_sheet_of_a_sweep_replaces_only_its_own(tmp_path):
    sweep = ("sweep", "--set", "render.max_depth=1,2", "-W", "8", "-H", "6", "-q")
    code, _, err = run_main(*sweep, cwd=tmp_path)
    assert code == 0, err
    sheet = tmp_path / "sheet.png"
    assert written_by_whitted(sheet)
    assert all(written_by_whitted(p) for p in (tmp_path / "sheet_cells").iterdir())
    code, _, err = run_main(*sweep, cwd=tmp_path)
    assert code == 0, err  # its own sheet: replaced
    PILImage.new("RGB", (3, 2)).save(sheet)
    mine = sheet.read_bytes()
    one_line_error(run_main(*sweep, cwd=tmp_path), "sheet.png: a file not marked as whitted's")
    assert sheet.read_bytes() == mine
    code, _, err = run_main(*sweep, "-o", "sheet.png", cwd=tmp_path)
    assert code == 0, err
    assert written_by_whitted(sheet)
