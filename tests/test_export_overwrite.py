"""``whitted export`` replaces only files whitted exported: a hand-written ``scene.pov`` in
the way is kept (exit 2, one line) unless ``--force``."""

from __future__ import annotations

import pytest

from cli_run import one_line_error, run_main
from whitted.errors import OutputError
from whitted.export.pov import WHITTED_HEADER, export_pov, foreign_file
from whitted.scene import load_scene

SCENE = "[render]\nwidth = 8\nheight = 6\n"
HAND = "// my own scene, tuned by hand\n#version 3.7;\nsphere { 0, 1 }\n"


def test_export_without_o_keeps_a_hand_written_file_of_the_same_name(tmp_path):
    (tmp_path / "scene.toml").write_text(SCENE, encoding="utf-8")
    (tmp_path / "scene.pov").write_text(HAND, encoding="utf-8")
    one_line_error(run_main("export", "scene.toml", cwd=tmp_path),
                   "scene.pov: exists and was not written by whitted", "--force")
    assert (tmp_path / "scene.pov").read_text(encoding="utf-8") == HAND
    one_line_error(run_main("export", "scene.toml", "-o", "scene.pov", cwd=tmp_path))
    assert (tmp_path / "scene.pov").read_text(encoding="utf-8") == HAND
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.pov", "scene.toml"]

    code, out, err = run_main("export", "scene.toml", "--force", cwd=tmp_path)
    assert code == 0, err
    assert (tmp_path / "scene.pov").read_text(encoding="utf-8").startswith(WHITTED_HEADER)


def test_a_whitted_export_is_replaced_and_written_in_the_current_folder(tmp_path):
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    (scenes / "scene.toml").write_text(SCENE, encoding="utf-8")
    work = tmp_path / "work"
    work.mkdir()
    assert run_main("export", "../scenes/scene.toml", cwd=work)[0] == 0
    first = (work / "scene.pov").read_text(encoding="utf-8")
    assert "+W8 +H6" in first and not (scenes / "scene.pov").exists()
    code, _, err = run_main("export", "../scenes/scene.toml", "-W", "16", cwd=work)
    assert code == 0, err  # its own earlier export: replaced without --force
    assert "+W16 +H6" in (work / "scene.pov").read_text(encoding="utf-8")


def test_the_python_api_keeps_foreign_files_too(tmp_path):
    (tmp_path / "scene.toml").write_text(SCENE, encoding="utf-8")
    scene = load_scene(tmp_path / "scene.toml")
    target = tmp_path / "mine.pov"
    target.write_text(HAND, encoding="utf-8")
    assert foreign_file(target) and not foreign_file(tmp_path / "absent.pov")
    assert not foreign_file(tmp_path)  # a folder is left to the output checks
    with pytest.raises(OutputError, match="not a file whitted exported"):
        export_pov(scene, target)
    assert target.read_text(encoding="utf-8") == HAND
    export_pov(scene, target, force=True)
    assert not foreign_file(target)
    empty = tmp_path / "empty.pov"
    empty.write_bytes(b"")
    with pytest.raises(OutputError):  # an empty file is someone's too
        export_pov(scene, empty)


def test_samples_beside_antialias_names_samples_not_the_size(tmp_path):
    (tmp_path / "aa.toml").write_text(SCENE + "[render.antialias]\nthreshold = 0.3\n",
                                      encoding="utf-8")
    line = one_line_error(run_main("render", "aa.toml", "-s", "4", "-o", "x.png",
                                   cwd=tmp_path), "--samples: samples = 4 beside "
                          "[render.antialias]")
    assert "--width" not in line and "RenderSettings" not in line
    line = one_line_error(run_main("animate", "aa.toml", "-W", "100000", "-H", "100000",
                                   "-o", "x.mp4", cwd=tmp_path),
                          "--width/--height: 100000x100000 is over 100 megapixels")
    assert "RenderSettings" not in line
