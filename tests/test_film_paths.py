"""animation/film.py: frames folders and files that cannot be used, each named in one line,
and paths that cannot even be looked at (a NUL byte, a link loop)."""

from __future__ import annotations

from pathlib import Path

import pytest

from whitted.animation.film import check_frame_files, film_paths
from whitted.errors import OutputError


def test_a_frames_folder_whose_name_cannot_be_used():
    with pytest.raises(OutputError) as info:
        check_frame_files(Path("bad\0name"), [])
    # (Path.exists says False for it; the place check then named it, where os.stat raised
    # ValueError through every caller before)
    assert str(info.value) == "bad\0name: cannot write: embedded null byte"
    assert film_paths("bad\0film.mp4").frames == Path("bad\0film_frames")


def test_a_file_where_the_frames_folder_goes(tmp_path):
    (tmp_path / "f_frames").write_text("")
    with pytest.raises(OutputError) as info:
        check_frame_files(tmp_path / "f_frames", [tmp_path / "f_frames" / "0.png"])
    assert str(info.value) == (f"{tmp_path / 'f_frames'}: is a file, not a folder for the "
                               "frames: move it or choose another output name")


def test_inputs_in_the_frames_folder_and_files_in_the_way(tmp_path):
    frames = tmp_path / "frames"
    frames.mkdir()
    (frames / "0.png").write_bytes(b"\x89PNG\r\n\x1a\n")  # a PNG, but not a frame whitted wrote
    (frames / "tex.png").write_bytes(b"")
    loop = frames / "loop.png"
    loop.symlink_to(loop)  # cannot be resolved: kept as an input to compare with
    with pytest.raises(OutputError) as info:
        check_frame_files(frames, [frames / "tex.png"], inputs=[frames / "tex.png", loop])
    assert str(info.value) == (f"{frames / 'tex.png'}: is an input of this job "
                               f"({frames / 'tex.png'}): choose another output name")
    with pytest.raises(OutputError) as info:
        check_frame_files(frames, [frames / "0.png"], inputs=[loop])
    assert str(info.value) == (f"{frames / '0.png'}: is in the way and whitted did not write "
                               "it (it has no frame record): move it or choose another "
                               "output name")
    check_frame_files(frames, [frames / "1.png"], inputs=[tmp_path / "scene.toml"])  # fine
