"""The OBJ scanner (assets/obj_scan.py) on the statements the other mesh tests leave out, and
every OBJ test run again with the scanner in the other JIT mode (plain Python when this run is
compiled): the same values and the same one-line errors either way."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from whitted.assets.mesh import load_obj_bytes
from whitted.errors import SceneError

ROOT = Path(__file__).resolve().parents[1]
JIT_OFF = os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0")
TRIANGLE = b"v 0 0 0\nv 1 0 0\nv 0 1 0\n"


def _load(data: bytes):
    return load_obj_bytes(data, "x.obj", ROOT)


@pytest.mark.parametrize(
    ("data", "message"),
    [
        # a backslash then a lone CR continues the line; the CR-only lines are counted
        (b"v 0 0 \\\r0\rv 1 x 0\r", "x.obj:3: invalid number 'x' in vertex position"),
        # a backslash before anything but a line end is part of the token
        (b"v 1 2 3\\x\n", "x.obj:1: invalid number '3\\\\x' in vertex position"),
        (TRIANGLE + b"f 1 2 -\n",
         "x.obj:4: invalid face corner '-' (expected v, v/vt, v//vn or v/vt/vn)"),
        (b"f 1 2 +\n", "x.obj:1: vertex index 1 out of range (0 defined so far) in '1'"),
        # a continued unknown statement counts its lines
        (b"g a \\\n b\nv 1 x 0\n", "x.obj:3: invalid number 'x' in vertex position"),
        (b"o thing\ns 1 \\\r\n \x01\n", "x.obj:3: binary data (byte 0x01): not an OBJ text file"),
    ],
)
def test_scanner_errors(data, message):
    with pytest.raises(SceneError) as caught:
        _load(data)
    assert str(caught.value) == message


def test_a_continuation_right_after_a_token_ends_it():
    mesh = _load(b"v 1 2\\\n3\nv 0 0 0\nv 1 1 1\nf 1 2 3\n")
    assert mesh.vertices.tolist() == [[1, 2, 3], [0, 0, 0], [1, 1, 1]]
    assert mesh.faces.tolist() == [[0, 1, 2]]


def test_blanks_at_the_end_of_the_file_and_an_empty_usemtl():
    mesh = _load(b"usemtl\n" + TRIANGLE + b"f 1 2 3\n   \t")
    assert mesh.faces.tolist() == [[0, 1, 2]] and mesh.triangle_records == 1


def test_a_one_value_texture_coordinate_has_v_zero():
    mesh = _load(TRIANGLE + b"vt 0.25\nvt 0.5 0.75\nf 1/1 2/2 3/1\n")
    assert mesh.uvs.tolist() == [[0.25, 0.0], [0.5, 0.75], [0.25, 0.0]]


def test_a_position_used_with_three_texture_coordinates_gets_two_copies():
    mesh = _load(TRIANGLE + b"vt 0 0\nvt 1 0\nvt 0 1\n"
                 b"f 1/1 2/1 3/1\nf 1/2 2/1 3/1\nf 1/3 2/1 3/1\nf 1/2 2/1 3/1\n")
    # vertex 1 with vt 1 keeps its index; with vt 2 and vt 3 it is copied (3, 4); the last
    # face finds the vt 2 copy along the chain of copies
    assert mesh.faces.tolist() == [[0, 1, 2], [3, 1, 2], [4, 1, 2], [3, 1, 2]]
    assert np.array_equal(mesh.vertices[3], mesh.vertices[0])
    assert np.array_equal(mesh.vertices[4], mesh.vertices[0])
    assert mesh.uvs.tolist() == [[0, 0], [0, 0], [0, 0], [1, 0], [0, 1]]


@pytest.mark.skipif(bool(os.environ.get("WHITTED_NESTED_OBJ_RUN")), reason="the nested run")
def test_every_obj_test_passes_with_the_scanner_in_the_other_jit_mode():
    """tests/test_mesh_loading.py and this file again, in a fresh process with the other JIT
    mode (the Stanford bunny, 2.4 MB, only compiled: as plain Python it takes minutes)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), WHITTED_NESTED_OBJ_RUN="1",
               NUMBA_DISABLE_JIT="0" if JIT_OFF else "1")
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
         "tests/test_mesh_loading.py", "tests/test_cov_obj_scan.py", "-k", "not bunny"],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]
    summary = done.stdout.strip().splitlines()[-1]
    passed = re.search(r"(\d+) passed", summary)
    assert passed and int(passed.group(1)) >= 80, summary
    assert "failed" not in summary and "error" not in summary, summary
