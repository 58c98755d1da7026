"""Tests of the output layer: encoding curves, file formats, atomic writes, Image."""

from __future__ import annotations

import os
import pathlib

import numpy as np
import png
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from PIL import Image as PILImage

from whitted.output import (
    Image,
    atomic_write,
    linear_to_srgb,
    read_image,
    srgb_to_linear,
)
from whitted.output.colour import encode_ldr, quantize, tonemap

RNG = np.random.default_rng(1234)


def ramp_image(h: int = 6, w: int = 7) -> np.ndarray:
    """A deterministic (h, w, 3) image in [0, 1] whose rows and columns all differ."""
    return RNG.random((h, w, 3), dtype=np.float32)


unit_floats = st.floats(0.0, 1.0, width=32, allow_nan=False)


# ------------------------------------------------------------------------------- sRGB curve


def test_srgb_hand_values():
    x = np.array([0.0, 1.0, 0.5, 0.214041], dtype=np.float32)
    y = linear_to_srgb(x)
    assert y.dtype == np.float32
    assert y[0] == 0.0
    assert y[1] == 1.0
    assert y[2] == pytest.approx(0.735357, abs=1e-6)
    assert y[3] == pytest.approx(0.5, abs=1e-6)
    assert srgb_to_linear(np.float32(0.5)) == pytest.approx(0.214041, abs=1e-6)
    assert srgb_to_linear(np.float32(1.0)) == 1.0
    assert srgb_to_linear(np.float32(0.0)) == 0.0


def test_srgb_continuity_at_breakpoint():
    c = 0.0031308
    below = linear_to_srgb(np.nextafter(np.float32(c), np.float32(0)))
    at = linear_to_srgb(np.float32(c))
    assert at == pytest.approx(12.92 * c, abs=1e-6)
    assert abs(float(at) - float(below)) < 1e-6
    assert srgb_to_linear(np.float32(0.04045)) == pytest.approx(0.04045 / 12.92, abs=1e-7)
    above = srgb_to_linear(np.nextafter(np.float32(0.04045), np.float32(1)))
    assert abs(float(above) - 0.04045 / 12.92) < 1e-7


def test_srgb_clamps_and_nan():
    x = np.array([-1.0, np.nan, 2.0, np.inf, -np.inf], dtype=np.float32)
    np.testing.assert_array_equal(linear_to_srgb(x), [0.0, 0.0, 1.0, 1.0, 0.0])
    np.testing.assert_array_equal(srgb_to_linear(x), [0.0, 0.0, 1.0, 1.0, 0.0])


def test_srgb_monotonic():
    x = np.linspace(0, 1, 100_001, dtype=np.float32)
    assert np.all(np.diff(linear_to_srgb(x)) >= 0)
    assert np.all(np.diff(srgb_to_linear(x)) >= 0)


@settings(max_examples=200, deadline=None)
@given(hnp.arrays(np.float32, st.integers(1, 64), elements=unit_floats))
def test_srgb_round_trip(x):
    back = srgb_to_linear(linear_to_srgb(x))
    assert back.shape == x.shape
    np.testing.assert_allclose(back, x, rtol=1e-5, atol=1e-6)


# ------------------------------------------------------------------------- tonemap/quantize


def grey(x: np.ndarray) -> np.ndarray:
    return np.repeat(np.asarray(x, dtype=np.float32)[:, None], 3, axis=1)


@pytest.mark.parametrize("mode", ["reinhard", "aces"])
@settings(max_examples=100, deadline=None)
@given(values=hnp.arrays(np.float32, st.integers(1, 64), elements=st.floats(0.0, 1e6, width=32)))
def test_tonemap_range_and_monotonic(mode, values):
    x = np.sort(values)
    y = tonemap(grey(x), mode)
    assert y.dtype == np.float32
    assert np.all(y >= 0.0) and np.all(y <= 1.0)
    assert np.all(np.diff(y[:, 0]) >= 0)  # monotonic
    assert np.all(y[:, 0] == y[:, 1]) and np.all(y[:, 1] == y[:, 2])  # grey stays grey
    if mode == "reinhard":
        assert np.all(y < 1.0)  # [0, inf) -> [0, 1)
    else:
        # The Narkowicz ACES fit reaches 1 (and is clipped there) at x ~ 7.24.
        assert np.all(y[x < 7.0] < 1.0)


@pytest.mark.parametrize("mode", ["reinhard", "aces"])
def test_tonemap_dense_monotonic(mode):
    x = np.concatenate([np.linspace(0, 20, 20_001), np.geomspace(20, 1e7, 1000)])
    y = tonemap(grey(x), mode)[:, 0]
    assert y[0] == 0.0
    assert np.all(np.diff(y) >= 0)
    assert np.all((y >= 0) & (y <= 1))
    if mode == "reinhard":
        assert np.all(y < 1.0)


def test_tonemap_values():
    one = grey([1.0])
    assert tonemap(one, "reinhard")[0, 0] == pytest.approx(0.5)
    assert tonemap(one, "aces")[0, 0] == pytest.approx(2.54 / 3.16, abs=1e-6)
    np.testing.assert_array_equal(tonemap(grey([-1.0, 0.5, 3.0]), "clamp")[:, 0], [0, 0.5, 1])
    # Reinhard keeps hue: a colour is scaled by 1 / (1 + L).
    c = np.array([[0.6, 0.3, 0.1]], dtype=np.float32)
    lum = 0.2126 * 0.6 + 0.7152 * 0.3 + 0.0722 * 0.1
    np.testing.assert_allclose(tonemap(c, "reinhard"), c / (1 + lum), rtol=1e-6)
    # Special values: NaN -> 0, +inf saturates to 1, -inf -> 0.
    special = grey([np.nan, np.inf, -np.inf])
    for mode in ("clamp", "reinhard", "aces"):
        np.testing.assert_array_equal(tonemap(special, mode)[:, 0], [0.0, 1.0, 0.0])
    with pytest.raises(ValueError, match="reinhard"):
        tonemap(one, "filmic")


def test_quantize_round_half_up():
    x = np.array([0.0, 0.5, 10 / 255, 1.0, 1.5, -0.2, np.nan, 0.5 / 255, 0.49 / 255])
    q8 = quantize(x, 8)
    assert q8.dtype == np.uint8
    np.testing.assert_array_equal(q8, [0, 128, 10, 255, 255, 0, 0, 1, 0])
    q16 = quantize(x, 16)
    assert q16.dtype == np.uint16
    np.testing.assert_array_equal(q16[:4], [0, 32768, 2570, 65535])
    with pytest.raises(ValueError, match="8 or 16"):
        quantize(x, 12)


def test_encode_ldr_pipeline():
    px = np.array([[[0.5, 0.2, 2.0]]], dtype=np.float32)
    # linear: 127.5 -> 128, 51 -> 51; sRGB: 0.735357 -> 187.99 -> 188, 0.484529 -> 124
    np.testing.assert_array_equal(encode_ldr(px, transfer="linear"), [[[128, 51, 255]]])
    np.testing.assert_array_equal(encode_ldr(px), [[[188, 124, 255]]])
    # reinhard on grey 1.0 gives 0.5, written linearly as 128
    one = np.ones((1, 1, 3), dtype=np.float32)
    np.testing.assert_array_equal(encode_ldr(one, transfer="linear", tonemap="reinhard"), 128)


# ------------------------------------------------------------------------------ file formats


@pytest.mark.parametrize("name", ["a.png", "a.PNG"])
def test_png8_round_trip(tmp_path, name):
    px = ramp_image()
    path = Image(px).save(tmp_path / name)
    assert path == tmp_path / name
    with PILImage.open(path) as im:
        assert im.mode == "RGB" and im.size == (7, 6)
    back = read_image(path)
    assert back.dtype == np.float32 and back.shape == px.shape
    # within one 8-bit quantisation step, measured in the encoded (sRGB) domain
    np.testing.assert_allclose(linear_to_srgb(back), linear_to_srgb(px), atol=1 / 255)
    np.testing.assert_allclose(linear_to_srgb(back), linear_to_srgb(px), atol=0.5 / 255 + 1e-6)


def test_png16_round_trip(tmp_path):
    px = ramp_image()
    path = Image(px).save(tmp_path / "a.png", bit_depth=16)
    with open(path, "rb") as f:
        info = png.Reader(file=f).read()[3]
    assert info["bitdepth"] == 16 and info["planes"] == 3
    back = read_image(path)
    assert back.dtype == np.float32 and back.shape == px.shape
    np.testing.assert_allclose(linear_to_srgb(back), linear_to_srgb(px), atol=1 / 65535)
    # linear transfer: the stored values are the linear values themselves
    Image(px).save(tmp_path / "b.png", bit_depth=16, transfer="linear")
    np.testing.assert_allclose(
        read_image(tmp_path / "b.png", transfer="linear"), px, atol=0.5 / 65535 + 1e-7
    )


@settings(max_examples=60, deadline=None)
@given(st.binary(max_size=300), st.binary(max_size=300), st.binary(max_size=70000))
def test_adler32_combine_equals_zlib_over_the_joined_bytes(a, b, c):
    import zlib

    from whitted.output.png import adler32_combine

    ab = adler32_combine(zlib.adler32(a), zlib.adler32(b), len(b))
    assert ab == zlib.adler32(a + b)
    assert adler32_combine(ab, zlib.adler32(c), len(c)) == zlib.adler32(a + b + c)


@pytest.mark.parametrize("bits", [8, 16])
def test_png_written_in_units_on_threads_is_exact_and_the_same_bytes(tmp_path, monkeypatch,
                                                                      bits):
    """output/png.py: an image of several deflate units (made small here) reads back with
    exactly the codes encode_ldr gives, through Pillow or pypng and zlib's own checks (CRCs,
    Adler-32), and its bytes do not depend on the number of threads."""
    import zlib

    from whitted.output import png as png_writer

    monkeypatch.setattr(png_writer, "DEFLATE_UNIT_BYTES", 700)  # 23 units of 5-6 rows
    px = RNG.random((125, 41, 3), dtype=np.float32) * 1.2  # some above 1: clipped
    px[7:30, 3:20] = 0.25  # flat runs: Up filters to zeros
    codes = encode_ldr(px, bits=bits)
    files = {}
    for threads in (1, 2, 5):
        path = tmp_path / f"t{threads}.png"
        with open(path, "wb") as f:
            png_writer.write_png(f, 125, 41, bits, lambda y0, y1: encode_ldr(px[y0:y1],
                                                                             bits=bits),
                                 4, threads=threads)
        files[threads] = path.read_bytes()
    assert files[1] == files[2] == files[5]
    assert len(png_writer.unit_rows(125, 41, bits)) > 10
    with open(tmp_path / "t2.png", "rb") as f:
        w, h, rows, info = png.Reader(file=f).read()  # checks every chunk's CRC
        back = np.array(list(rows), dtype=np.uint16).reshape(h, w, 3)
    assert (w, h, info["bitdepth"]) == (41, 125, bits)
    assert np.array_equal(back, codes)
    if bits == 8:
        with PILImage.open(tmp_path / "t2.png") as im:
            assert np.array_equal(np.asarray(im), codes)
    # the IDAT stream is one zlib stream, its Adler-32 included
    data, at = files[2], 8
    stream = b""
    while at < len(data):
        (length,) = np.frombuffer(data[at:at + 4], ">u4")
        if data[at + 4:at + 8] == b"IDAT":
            stream += data[at + 8:at + 8 + int(length)]
        at += 12 + int(length)
    assert len(zlib.decompress(stream)) == 125 * (1 + 41 * 3 * bits // 8)


def test_png_of_one_row_and_of_one_pixel(tmp_path):
    for shape in ((1, 9, 3), (1, 1, 3), (9, 1, 3)):
        px = RNG.random(shape, dtype=np.float32)
        path = Image(px).save(tmp_path / "x.png")
        with PILImage.open(path) as im:
            assert np.array_equal(np.asarray(im), encode_ldr(px, bits=8))


def test_linear_transfer_writes_exact_values(tmp_path):
    px = np.zeros((2, 3, 3), dtype=np.float32)
    px[0, 0] = 0.5
    px[0, 1] = 10 / 255
    px[0, 2] = [1.0, 2.0, -1.0]
    px[1, 0] = [64 / 255, 200 / 255, 254.6 / 255]
    Image(px, transfer="linear").save(tmp_path / "lin.png")
    with PILImage.open(tmp_path / "lin.png") as im:
        raw = np.asarray(im)
    assert raw.dtype == np.uint8
    np.testing.assert_array_equal(raw[0, 0], [128, 128, 128])
    np.testing.assert_array_equal(raw[0, 1], [10, 10, 10])
    np.testing.assert_array_equal(raw[0, 2], [255, 255, 0])
    np.testing.assert_array_equal(raw[1, 0], [64, 200, 255])
    np.testing.assert_array_equal(raw[1, 1], [0, 0, 0])
    # the per-call override beats the image default
    Image(px).save(tmp_path / "lin2.png", transfer="linear")
    with PILImage.open(tmp_path / "lin2.png") as im:
        np.testing.assert_array_equal(np.asarray(im), raw)


@pytest.mark.parametrize("ext", [".exr", ".pfm", ".npy", ".EXR", ".PFM", ".NPY"])
def test_hdr_round_trip_exact(tmp_path, ext):
    px = (RNG.standard_normal((5, 8, 3)) * 10).astype(np.float32)  # negatives, > 1
    px[0, 0] = [1e-30, 65504.5, 3e38]
    path = Image(px, tonemap="aces", transfer="linear").save(tmp_path / f"hdr{ext}")
    back = read_image(path)
    assert back.dtype == np.float32 and back.shape == px.shape
    np.testing.assert_array_equal(back, px)
    assert sorted(os.listdir(tmp_path)) == [f"hdr{ext}"]


@pytest.mark.parametrize("ext", [".exr", ".pfm", ".npy"])
def test_hdr_keeps_special_values(tmp_path, ext):
    px = np.ones((2, 2, 3), dtype=np.float32)
    px[0, 0] = [np.nan, np.inf, -np.inf]
    back = read_image(Image(px).save(tmp_path / f"s{ext}"))
    np.testing.assert_array_equal(back, px)  # assert_array_equal treats NaN == NaN


def test_pfm_layout_and_orientation(tmp_path):
    px = np.zeros((2, 3, 3), dtype=np.float32)
    px[0] = [1.0, 0.0, 0.0]  # top row red
    px[1] = [0.0, 0.0, 1.0]  # bottom row blue
    path = Image(px).save(tmp_path / "o.pfm")
    raw = path.read_bytes()
    header = b"PF\n3 2\n-1.0\n"
    assert raw.startswith(header)
    data = np.frombuffer(raw[len(header) :], dtype="<f4").reshape(2, 3, 3)
    np.testing.assert_array_equal(data[0], px[1])  # file stores bottom row first
    back = read_image(path)
    np.testing.assert_array_equal(back[0, 0], [1.0, 0.0, 0.0])  # top row stays top
    np.testing.assert_array_equal(back, px)


def test_pfm_reads_big_endian_and_greyscale(tmp_path):
    g = np.arange(6, dtype=np.float32).reshape(2, 3)
    p = tmp_path / "g.pfm"
    p.write_bytes(b"Pf\n3 2\n1.0\n" + np.ascontiguousarray(g[::-1], dtype=">f4").tobytes())
    back = read_image(p)
    np.testing.assert_array_equal(back, np.repeat(g[:, :, None], 3, axis=2))
    p.write_bytes(b"PF\n3 2\n-1.0\n" + b"\0" * 10)
    with pytest.raises(ValueError, match="truncated"):
        read_image(p)


def test_exr_is_float32_rgb(tmp_path):
    import OpenEXR

    px = ramp_image() * 100
    path = Image(px).save(tmp_path / "f.exr")
    f = OpenEXR.File(str(path), separate_channels=True)
    channels = f.channels()
    assert sorted(channels) == ["B", "G", "R"]
    assert channels["R"].pixels.dtype == np.float32
    np.testing.assert_array_equal(channels["R"].pixels, px[:, :, 0])


@pytest.mark.parametrize("name", ["j.jpg", "j.jpeg", "j.JPG"])
def test_jpeg_round_trip(tmp_path, name):
    px = np.zeros((16, 16, 3), dtype=np.float32)
    px[:] = [0.8, 0.2, 0.05]
    path = Image(px).save(tmp_path / name)
    with PILImage.open(path) as im:
        assert im.format == "JPEG" and im.size == (16, 16)
    back = read_image(path)
    np.testing.assert_allclose(linear_to_srgb(back), linear_to_srgb(px), atol=3 / 255)


def test_read_png_greyscale_and_alpha(tmp_path):
    p = tmp_path / "ga.png"
    PILImage.fromarray(np.array([[[0, 10], [255, 200]]], dtype=np.uint8), mode="LA").save(p)
    back = read_image(p, transfer="linear")
    assert back.shape == (1, 2, 3)
    np.testing.assert_allclose(back[0, :, 0], [0.0, 1.0])
    np.testing.assert_array_equal(back[..., 0], back[..., 2])


def test_read_png_grey16_palette_and_garbage(tmp_path):
    g16 = np.array([[0, 65535, 32768]], dtype=np.uint16)
    p = tmp_path / "g16.png"
    with open(p, "wb") as f:
        png.Writer(width=3, height=1, greyscale=True, bitdepth=16).write(f, g16)
    back = read_image(p, transfer="linear")
    assert back.shape == (1, 3, 3)
    np.testing.assert_allclose(back[0, :, 1], g16[0] / 65535.0, rtol=1e-6)
    pal = PILImage.new("P", (2, 1))
    pal.putpalette([255, 0, 0, 0, 0, 255] + [0] * 762)
    pal.putpixel((1, 0), 1)
    pal.save(tmp_path / "pal.png")
    np.testing.assert_array_equal(
        read_image(tmp_path / "pal.png"), [[[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]]
    )
    (tmp_path / "bad.png").write_bytes(b"not a png at all, really not")
    with pytest.raises(ValueError, match="not a PNG"):
        read_image(tmp_path / "bad.png")


# ---------------------------------------------------------------------------- atomic writes


def test_atomic_write_success(tmp_path):
    target = tmp_path / "out.png"
    seen = []

    def writer(tmp):
        seen.append(tmp)
        assert tmp.endswith(".png")
        assert pathlib.Path(tmp).parent == tmp_path
        pathlib.Path(tmp).write_bytes(b"new")

    assert atomic_write(target, writer) == target
    assert target.read_bytes() == b"new"
    assert not os.path.exists(seen[0])
    assert os.listdir(tmp_path) == ["out.png"]


@pytest.mark.skipif(os.name == "nt", reason="POSIX permissions")
def test_atomic_write_permissions(tmp_path):
    mask = os.umask(0o022)
    os.umask(mask)
    new = atomic_write(tmp_path / "new.bin", lambda t: pathlib.Path(t).write_bytes(b"x"))
    assert new.stat().st_mode & 0o777 == 0o666 & ~mask
    old = tmp_path / "old.bin"
    old.write_bytes(b"old")
    old.chmod(0o640)
    atomic_write(old, lambda t: pathlib.Path(t).write_bytes(b"y"))
    assert old.stat().st_mode & 0o777 == 0o640


def test_atomic_write_failure_keeps_old_file(tmp_path):
    target = tmp_path / "out.png"
    target.write_bytes(b"old content")

    def failing(tmp):
        with open(tmp, "wb") as f:
            f.write(b"partial")
        raise RuntimeError("disk on fire")

    with pytest.raises(RuntimeError, match="disk on fire"):
        atomic_write(target, failing)
    assert target.read_bytes() == b"old content"
    assert os.listdir(tmp_path) == ["out.png"]


def test_atomic_write_failure_creates_nothing(tmp_path):
    def failing(tmp):
        raise OSError("nope")

    with pytest.raises(OSError, match="nope"):
        atomic_write(tmp_path / "x.exr", failing)
    assert os.listdir(tmp_path) == []


def test_save_validation_touches_nothing(tmp_path):
    target = tmp_path / "keep.png"
    target.write_bytes(b"old")
    img = Image(ramp_image())
    with pytest.raises(ValueError):
        img.save(target, bit_depth=12)
    with pytest.raises(ValueError):
        img.save(target, tonemap="nope")
    assert target.read_bytes() == b"old"
    assert os.listdir(tmp_path) == ["keep.png"]


def test_save_overwrites_atomically(tmp_path):
    target = tmp_path / "a.png"
    Image(np.zeros((2, 2, 3))).save(target)
    Image(np.ones((2, 2, 3))).save(target)
    np.testing.assert_array_equal(read_image(target), np.ones((2, 2, 3)))
    assert os.listdir(tmp_path) == ["a.png"]


# ------------------------------------------------------------------------------------ Image


def test_image_basics():
    px64 = np.arange(2 * 3 * 3, dtype=np.float64).reshape(2, 3, 3) / 20
    img = Image(px64, meta={"samples": 4})
    assert img.pixels.dtype == np.float32 and img.pixels.flags.c_contiguous
    assert (img.width, img.height) == (3, 2)
    assert repr(img) == "<Image 3x2 linear float32>"
    assert img.meta == {"samples": 4}
    assert Image(px64).meta == {}
    assert np.asarray(img) is img.pixels
    assert np.asarray(img, dtype=np.float64).dtype == np.float64
    assert np.array(img) is not img.pixels
    np.testing.assert_array_equal(np.asarray(img), px64.astype(np.float32))
    # no copy for an array that already fits
    px32 = np.zeros((2, 3, 3), dtype=np.float32)
    assert Image(px32).pixels is px32
    # non-contiguous input is made contiguous
    assert Image(np.zeros((3, 4, 3))[:, ::2]).pixels.flags.c_contiguous
    assert Image(np.zeros((2, 2, 3), dtype=np.uint8)).pixels.dtype == np.float32


def test_image_encodings():
    px = np.array([[[0.5, 0.2, 4.0], [0.0, 1.0, np.nan]]], dtype=np.float32)
    img = Image(px)
    s8 = img.to_srgb8()
    assert s8.dtype == np.uint8 and s8.shape == (1, 2, 3)
    np.testing.assert_array_equal(s8, [[[188, 124, 255], [0, 255, 0]]])
    s16 = img.to_uint16()
    assert s16.dtype == np.uint16 and s16.shape == (1, 2, 3)
    expected16 = np.floor(linear_to_srgb(np.clip(np.nan_to_num(px), 0, 1)) * 65535.0 + 0.5)
    np.testing.assert_array_equal(s16, expected16)
    # the image's own tonemap and transfer are used
    grey_img = Image(np.ones((1, 1, 3)), transfer="linear", tonemap="reinhard")
    np.testing.assert_array_equal(grey_img.to_srgb8(), 128)
    np.testing.assert_array_equal(grey_img.to_uint16(), 32768)
    png_bytes = img._repr_png_()
    assert png_bytes.startswith(b"\x89PNG\r\n\x1a\n")


def test_image_load(tmp_path):
    px = ramp_image() * 5
    Image(px).save(tmp_path / "l.exr")
    loaded = Image.load(tmp_path / "l.exr")
    np.testing.assert_array_equal(loaded.pixels, px)
    Image(ramp_image(), transfer="linear").save(tmp_path / "l.png")
    assert Image.load(tmp_path / "l.png", transfer="linear").transfer == "linear"


# ------------------------------------------------------------------------------ bad inputs


@pytest.mark.parametrize(
    "bad",
    [
        np.zeros((4, 4)),
        np.zeros((4, 4, 4)),
        np.zeros((4, 4, 3, 1)),
        np.zeros((0, 4, 3)),
        np.zeros(3),
        np.array([[["a", "b", "c"]]]),
        np.zeros((2, 2, 3), dtype=bool),
        [[1, 2, 3], [4, 5]],
    ],
)
def test_bad_pixels(bad):
    with pytest.raises(ValueError, match="pixels"):
        Image(bad)


def test_bad_extension(tmp_path):
    img = Image(ramp_image())
    with pytest.raises(ValueError) as exc:
        img.save(tmp_path / "a.xyz")
    assert str(exc.value) == (
        "unsupported image format '.xyz' (use .png, .jpg, .tif, .webp, .exr, .pfm or .npy)"
    )
    with pytest.raises(ValueError, match="unsupported image format"):
        img.save(tmp_path / "noext")
    with pytest.raises(ValueError, match="unsupported image format"):
        read_image(tmp_path / "a.xyz")
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize(
    ("name", "depth"),
    [("a.png", 12), ("a.png", 0), ("a.png", 32), ("a.jpg", 16), ("a.exr", 16), ("a.png", True)],
)
def test_bad_bit_depth(tmp_path, name, depth):
    with pytest.raises(ValueError, match="bit_depth"):
        Image(ramp_image()).save(tmp_path / name, bit_depth=depth)
    assert os.listdir(tmp_path) == []


def test_bad_transfer_and_tonemap(tmp_path):
    with pytest.raises(ValueError, match="'srgb' or 'linear'"):
        Image(ramp_image(), transfer="gamma22")
    with pytest.raises(ValueError, match="'clamp', 'reinhard' or 'aces'"):
        Image(ramp_image(), tonemap="filmic")
    img = Image(ramp_image())
    with pytest.raises(ValueError, match="transfer"):
        img.save(tmp_path / "a.png", transfer="rec709")
    with pytest.raises(ValueError, match="transfer"):
        read_image(tmp_path / "a.png", transfer="rec709")


def test_8bit_srgb_table_gives_the_exact_curves_codes():
    """encode_ldr's 8-bit sRGB table look-up equals the float64 curve then rounding, at every
    step of the table (and three float32 values either side), on a million float32 values
    spread over [0, 1], on values outside it, and after every tone map."""
    from whitted.output import colour as e

    def reference(v, tonemap="clamp"):
        return e.quantize(e.linear_to_srgb(e.tonemap(v, tonemap)), 8)

    _code, step = e._srgb8_table()
    edges = step[np.isfinite(step)]
    assert len(edges) == 255  # one step per code
    bits = edges.view(np.uint32).astype(np.int64)
    near = np.concatenate([bits + d for d in range(-3, 4)]).astype(np.uint32).view(np.float32)
    spread = np.arange(0, int(np.float32(1).view(np.uint32)) + 1, 1021,
                       dtype=np.int64).astype(np.uint32).view(np.float32)
    odd = np.array([np.nan, np.inf, -np.inf, -1e-30, -2.0, 1.0, 1.0000001, 3e38, 0.0, 5e-45],
                   np.float32)
    for values in (near, spread, odd):
        assert np.array_equal(e.encode_ldr(values, bits=8), reference(values))
    rng = np.random.default_rng(7)
    hdr = (rng.random((64, 48, 3)) * 9).astype(np.float32)
    for mode in ("clamp", "reinhard", "aces"):
        assert np.array_equal(e.encode_ldr(hdr, bits=8, tonemap=mode), reference(hdr, mode))


@pytest.mark.parametrize("bits, with_alpha", [(8, False), (16, False), (8, True), (16, True)])
def test_every_png_whitted_writes_says_so(tmp_path, bits, with_alpha):
    """Each PNG writer (whitted's own RGB one, Pillow's RGBA, pypng's 16-bit RGBA) adds the
    text 'Software: whitted', which written_by_whitted finds; the pixels are unchanged."""
    from whitted.output.png import written_by_whitted

    pixels = ramp_image()
    alpha = np.linspace(0, 1, 42, dtype=np.float32).reshape(6, 7) if with_alpha else None
    path = Image(pixels).save(tmp_path / "a.png", bit_depth=bits, alpha=alpha)
    assert written_by_whitted(path)
    _w, _h, rows, info = png.Reader(filename=str(path)).read()  # a valid PNG (CRCs checked)
    got = np.array(list(rows), dtype=np.int64).reshape(6, 7, 4 if with_alpha else 3)
    assert info["bitdepth"] == bits
    np.testing.assert_array_equal(got[..., :3], encode_ldr(pixels, bits=bits))
    if with_alpha:
        np.testing.assert_array_equal(got[..., 3], quantize(alpha, bits))
    assert dict(png.Reader(filename=str(path)).chunks()).get(b"tEXt") == b"Software\0whitted"


def test_other_files_are_not_whitted_s(tmp_path):
    from whitted.output.png import written_by_whitted

    PILImage.new("RGB", (4, 3)).save(tmp_path / "theirs.png")
    (tmp_path / "notes.png").write_text("not a picture")
    (tmp_path / "short.png").write_bytes(b"\x89PNG\r\n\x1a\n\0\0")
    other = PILImage.new("RGB", (4, 3))
    from PIL.PngImagePlugin import PngInfo

    info = PngInfo()
    info.add_text("Software", "whitted-like")
    other.save(tmp_path / "like.png", pnginfo=info)
    for name in ("theirs.png", "notes.png", "short.png", "like.png", "missing.png", "."):
        assert not written_by_whitted(tmp_path / name), name
