"""The farm from the command line: ``whitted render --cluster local:N`` writes the image a
local render writes; bad farm options and a missing dask.distributed are one error line."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from whitted import load_scene
from whitted.cli.main import app
from whitted.render.api import RenderJob

pytest.importorskip("distributed")


def whitted(*args: object, cwd: Path, prelude: str = "") -> subprocess.CompletedProcess:
    code = (f"{prelude}import sys; from whitted.cli.main import main; "
            "sys.argv[0] = 'whitted'; main()")
    return subprocess.run([sys.executable, "-c", code, *map(str, args)], cwd=cwd,
                          env=dict(os.environ), capture_output=True, text=True, timeout=300)


def test_render_on_a_local_cluster_writes_the_local_image(tmp_path, examples_dir):
    scene_path = examples_dir / "textured.toml"
    result = whitted("render", scene_path, "-W", 80, "-H", 45, "-s", 2, "-o",
                     tmp_path / "farm.png", "--cluster", "local:2", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "farm: 2 workers at tcp://127.0.0.1:" in result.stderr
    assert "on 2 workers" in result.stdout
    scene = load_scene(scene_path).with_settings(width=80, height=45, samples=2)
    RenderJob(scene).run().save(tmp_path / "local.png")
    farm = np.asarray(Image.open(tmp_path / "farm.png"))
    local = np.asarray(Image.open(tmp_path / "local.png"))
    assert farm.shape == (45, 80, 3) and np.array_equal(farm, local)


@pytest.mark.parametrize(("options", "message"), [
    (["--cluster", "pool:4"], "error: --cluster: unknown cluster 'pool:4' (use local:N, or "
                              "--scheduler tcp://HOST:PORT for a running one)"),
    (["--cluster", "local:0"], "error: --cluster: 'local:0': N must be a whole number of "
                               "workers, 1 or more"),
    (["--cluster", "local:2", "--scheduler", "tcp://127.0.0.1:9"],
     "error: give one of --cluster local:N and --scheduler tcp://HOST:PORT"),
])
def test_bad_farm_options_are_one_line(tmp_path, options, message):
    result = CliRunner().invoke(app, ["render", "-W", "8", "-H", "8", "-o",
                                      str(tmp_path / "x.png"), *options])
    assert result.exit_code == 2
    assert result.stderr.strip() == message
    assert not (tmp_path / "x.png").exists()


def test_without_dask_the_farm_says_what_to_install(tmp_path):
    hide_dask = "import sys; sys.modules['distributed'] = None; "  # as if not installed
    result = whitted("render", "-W", 8, "-H", 8, "-o", tmp_path / "x.png", "--cluster",
                     "local:2", cwd=tmp_path, prelude=hide_dask)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.stderr
    assert lines[0].startswith("error: the render farm needs dask.distributed: "
                               "pip install 'whitted[farm]'")
