"""Issue 25, the animation, sweep and file-reading items (6-10, 15, 16): limits that keep a
hostile but fair input from running away, and one clean line for every mistake."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from test_reliability import SCENE, one_line_error, run_main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
GiB = 1 << 30


# ----------------------------------------------------------- item 10: an address-space limit


def run_limited(args: list[str], cwd: Path, address_space: int = 2 * GiB
                ) -> subprocess.CompletedProcess:
    """``whitted ARGS`` in a child process whose address space is limited (as ``ulimit -v``)."""
    code = textwrap.dedent(f"""
        import resource, runpy, sys
        resource.setrlimit(resource.RLIMIT_AS, ({address_space}, {address_space}))
        sys.argv = ["whitted", *{args!r}]
        runpy.run_module("whitted", run_name="__main__", alter_sys=True)
    """)
    return subprocess.run([sys.executable, "-c", code], cwd=cwd, capture_output=True,
                          text=True, timeout=300, env=os.environ.copy())


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS as on Linux")
def test_every_example_reads_under_a_2_gb_address_space(tmp_path: Path):
    """The OBJ reader used to ask for 8 GiB + 1 bytes up front: every scene with a model
    failed with "out of memory" under ``ulimit -v 4000000``."""
    for scene in sorted(EXAMPLES.glob("*.toml")):
        result = run_limited(["info", str(scene)], tmp_path)
        assert result.returncode == 0, (scene.name, result.stderr)
        assert "bvh:" in result.stdout
    # and a render of a scene with an OBJ model and its MTL file (the teapot)
    result = run_limited(["render", str(EXAMPLES / "teapot_glass.toml"), "-W", "8", "-H", "6",
                          "-q", "-o", "t.png"], tmp_path)
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "t.png").stat().st_size > 0


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS as on Linux")
def test_a_file_too_big_for_the_address_space_is_one_clear_line(tmp_path: Path):
    big = tmp_path / "big.obj"
    with big.open("wb") as f:  # 3 GiB, sparse: a valid start, then holes
        f.write(b"v 0 0 0\n" * 10_000)  # more than the head the reader checks
        f.truncate(3 * GiB)
    result = run_limited(["info", "big.obj"], tmp_path)
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.stderr
    assert lines[0] == ("error: big.obj: OBJ file too large for the memory this process may "
                        "use: 3.0 GiB could not be read (a memory or address-space limit such "
                        "as ulimit -v)")


def test_reading_a_small_file_asks_for_its_size_not_the_limit(tmp_path: Path, monkeypatch):
    """The read is sized by the file (plus one byte to notice growth), never by the limit."""
    from whitted.assets import files

    path = tmp_path / "a.mtl"
    path.write_bytes(b"newmtl a\nKd 1 0 0\n")
    asked: list[int] = []
    real_fdopen = os.fdopen

    class Spy:
        def __init__(self, f):
            self.f = f

        def read(self, n=-1):
            asked.append(n)
            return self.f.read(n)

        def fileno(self):
            return self.f.fileno()

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.f.close()

    monkeypatch.setattr(files.os, "fdopen", lambda *a, **k: Spy(real_fdopen(*a, **k)))
    assert files.read_limited(path, 8 * GiB) == b"newmtl a\nKd 1 0 0\n"
    assert asked == [19]
    with pytest.raises(files.SceneError, match=r"too large: 18 bytes \(the limit is 10 bytes\)"):
        files.read_limited(path, 10)
