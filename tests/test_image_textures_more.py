"""assets/images.py beyond the common PNGs: float and 32-bit integer images, sizes refused
from the header, unknown colour spaces, files that cannot even be looked at, and the cache's
bound on how many images it keeps."""

from __future__ import annotations

import struct
import zlib

import numpy as np
import pytest
from PIL import Image

from whitted.assets import images
from whitted.assets.images import clear_image_cache, load_image
from whitted.errors import ArgumentError, SceneError


def _png_header(width: int, height: int) -> bytes:
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + struct.pack(">I", 13) + b"IHDR" + ihdr
            + struct.pack(">I", zlib.crc32(b"IHDR" + ihdr)))


def test_float_images_are_taken_as_scaled(tmp_path):
    values = np.array([[0.0, 0.5], [2.0, np.nan]], np.float32)
    Image.fromarray(values, mode="F").save(tmp_path / "f.tif")
    linear = load_image(tmp_path / "f.tif", colorspace="linear")
    # grey made RGB; NaN counts as 0 (the value stays 2.0: float data is not clipped)
    assert linear[:, :, 0].tolist() == [[0.0, 0.5], [2.0, 0.0]]
    assert (linear[:, :, 0] == linear[:, :, 2]).all()
    srgb = load_image(tmp_path / "f.tif")
    assert srgb[0, 1, 1] == pytest.approx(((0.5 + 0.055) / 1.055) ** 2.4, rel=1e-6)


def test_32_bit_integer_grey_is_clipped_to_16_bits(tmp_path):
    values = np.array([[0, 65535, 100000]], np.int32)
    Image.fromarray(values, mode="I").save(tmp_path / "i.tif")
    pixels = load_image(tmp_path / "i.tif", colorspace="linear")
    assert pixels[0, :, 1].tolist() == [0.0, 1.0, 1.0]


def test_16_bit_grey_from_pillow(tmp_path):
    values = np.array([[0, 32768, 65535]], np.uint16)
    Image.fromarray(values).save(tmp_path / "g.tif")
    pixels = load_image(tmp_path / "g.tif", colorspace="linear")
    np.testing.assert_allclose(pixels[0, :, 0], [0.0, 32768 / 65535, 1.0], rtol=1e-7)


def test_a_huge_image_is_refused_from_its_header(tmp_path):
    path = tmp_path / "huge.png"
    path.write_bytes(_png_header(9000, 8000))
    with pytest.raises(SceneError) as info:
        load_image(path)
    assert str(info.value) == (f"{path}: image too large: 9000x8000 pixels (the limit is "
                               "67,108,864 pixels, 8192x8192)")
    bmp = tmp_path / "huge.bmp"  # checked by Pillow's header for other formats
    bmp.write_bytes(b"BM" + struct.pack("<IHHI", 0, 0, 0, 54) + struct.pack(
        "<iiiHHIIiiII", 40, 10000, 10000, 1, 24, 0, 0, 0, 0, 0, 0))
    with pytest.raises(SceneError) as info:
        load_image(bmp)
    assert str(info.value) == (f"{bmp}: image too large: 10000x10000 pixels (the limit is "
                               "67,108,864 pixels, 8192x8192)")


def test_pillows_own_bomb_limit_is_one_line(tmp_path, monkeypatch):
    Image.fromarray(np.zeros((4, 4, 3), np.uint8)).save(tmp_path / "small.png")

    def bomb(data, name="image"):
        raise Image.DecompressionBombError("Image size (16 pixels) exceeds limit")

    monkeypatch.setattr(images, "_read_with_pillow", bomb)
    with pytest.raises(SceneError) as info:
        load_image(tmp_path / "small.png")
    assert str(info.value) == (f"{tmp_path / 'small.png'}: image too large: Image size "
                               "(16 pixels) exceeds limit")


def test_an_image_without_pixels(tmp_path, monkeypatch):
    Image.fromarray(np.zeros((1, 1, 3), np.uint8)).save(tmp_path / "one.png")
    monkeypatch.setattr(images, "_read_with_pillow",
                        lambda data, name="image": (np.zeros((0, 4, 3), np.uint8), 256))
    with pytest.raises(SceneError) as info:
        load_image(tmp_path / "one.png")
    assert str(info.value) == f"{tmp_path / 'one.png'}: image has no pixels"


def test_an_unknown_colour_space_and_an_unreadable_path(tmp_path):
    with pytest.raises(ArgumentError) as info:
        load_image(tmp_path / "x.png", colorspace="rec709")
    assert str(info.value) == "colorspace must be one of ('srgb', 'linear'), not 'rec709'"
    (tmp_path / "file").write_bytes(b"")
    with pytest.raises(SceneError) as info:
        load_image(tmp_path / "file" / "x.png")
    assert str(info.value) == f"{tmp_path / 'file' / 'x.png'}: cannot read image file: " \
        "Not a directory"
    assert images._one_line(OSError()) == "OSError"


def test_the_cache_keeps_the_last_32_images(tmp_path):
    clear_image_cache()
    paths = []
    for k in range(images._CACHE_ENTRIES + 1):
        path = tmp_path / f"{k}.png"
        Image.fromarray(np.full((1, 1, 3), k, np.uint8)).save(path)
        paths.append(path)
    first = [load_image(p, colorspace="linear") for p in paths]
    assert len(images._cache) == images._CACHE_ENTRIES
    assert load_image(paths[-1], colorspace="linear") is first[-1]  # kept
    again = load_image(paths[0], colorspace="linear")  # the oldest was dropped: read again
    assert again is not first[0] and again[0, 0, 0] == 0.0
    assert load_image(paths[5], colorspace="linear")[0, 0, 0] == pytest.approx(5 / 255)
    clear_image_cache()
    assert images._cache == {}
