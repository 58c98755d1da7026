"""output/formats.py's readers on files they must refuse or adapt: PFM headers and data cut
short or wrong, EXR files of one grey channel or none usable, arrays of text or of a shape
that is no image, and paths that are not regular files; each refusal is one line naming the
file."""

from __future__ import annotations

import numpy as np
import pytest

from whitted.errors import ArgumentError
from whitted.output.formats import read_image


@pytest.mark.parametrize(("content", "problem"), [
    (b"PF\n2 1\n", "truncated PFM header"),
    (b"P6\n2 1\n-1.0\n" + bytes(24), "not a PFM file (magic b'P6')"),
    (b"PF\ntwo 1\n-1.0\n" + bytes(24), "bad PFM header b'PF two 1 -1.0'"),
    (b"PF\n0 1\n-1.0\n", "bad PFM header b'PF 0 1 -1.0'"),
    (b"PF\n2 1\n0\n" + bytes(24), "bad PFM header b'PF 2 1 0'"),
    (b"PF\n2 1\n-1.0\n" + bytes(23), "truncated PFM data"),
])
def test_bad_pfm_files(tmp_path, content, problem):
    path = tmp_path / "x.pfm"
    path.write_bytes(content)
    with pytest.raises(ValueError) as info:
        read_image(path)
    assert str(info.value) == f"{path}: {problem}"


def test_exr_grey_single_and_unusable_channels(tmp_path):
    import OpenEXR

    grey = np.array([[0.25, 2.0]], np.float32)
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    OpenEXR.File(header, {"Y": grey}).write(str(tmp_path / "y.exr"))
    np.testing.assert_array_equal(read_image(tmp_path / "y.exr"),
                                  np.repeat(grey[:, :, None], 3, axis=2))
    OpenEXR.File(header, {"Z": grey * 3}).write(str(tmp_path / "z.exr"))
    np.testing.assert_array_equal(read_image(tmp_path / "z.exr")[0, :, 1], [0.75, 6.0])
    OpenEXR.File(header, {"A": grey, "Z": grey}).write(str(tmp_path / "az.exr"))
    with pytest.raises(ValueError) as info:
        read_image(tmp_path / "az.exr")
    assert str(info.value) == (f"{tmp_path / 'az.exr'}: no R, G, B or Y channels in EXR "
                               "(has ['A', 'Z'])")


def test_npy_arrays_that_are_no_image(tmp_path):
    np.save(tmp_path / "text.npy", np.array([["a", "b"]]))
    with pytest.raises(ValueError) as info:
        read_image(tmp_path / "text.npy")
    assert str(info.value) == f"{tmp_path / 'text.npy'}: not a numeric array (dtype <U1)"
    np.save(tmp_path / "five.npy", np.zeros((2, 2, 5), np.float32))
    with pytest.raises(ValueError) as info:
        read_image(tmp_path / "five.npy")
    assert str(info.value) == (f"{tmp_path / 'five.npy'}: cannot use image data of shape "
                               "(2, 2, 5) as RGB")
    np.save(tmp_path / "grey_alpha.npy", np.array([[[0.5, 1.0], [2, 0]]], np.float64))
    assert read_image(tmp_path / "grey_alpha.npy").tolist() == [[[0.5] * 3, [2.0] * 3]]
    np.save(tmp_path / "ints.npy", np.array([[7, 9]], np.int16))
    out = read_image(tmp_path / "ints.npy")
    assert out.dtype == np.float32 and out.tolist() == [[[7.0] * 3, [9.0] * 3]]


def test_only_regular_files_are_read(tmp_path):
    with pytest.raises(ArgumentError) as info:
        read_image(tmp_path / "missing.png")
    assert str(info.value) == f"{tmp_path / 'missing.png'}: no such file"
    (tmp_path / "folder.exr").mkdir()
    with pytest.raises(ArgumentError) as info:
        read_image(tmp_path / "folder.exr")
    assert str(info.value) == f"{tmp_path / 'folder.exr'}: is a directory, not a regular file"
