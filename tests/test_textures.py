"""Textures: image decoding (sRGB, bit depths, modes, errors, cache), the compiled texture table
and the ``texture_color`` kernel (orientation, filtering, wrapping, placement, checker, gradient,
robustness for any (u, v))."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import png
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from PIL import Image

from whitted.assets import load_image
from whitted.assets.images import clear_image_cache, srgb_to_linear
from whitted.compile.textures import TextureArrays, compile_textures
from whitted.errors import SceneError
from whitted.kernels.texture import texture_color
from whitted.kernels.texture_layout import (
    N_TEX_PARAMS,
    TEX_HEIGHT,
    TEX_IMAGE,
    TEX_KIND,
    TEX_PIXEL_OFFSET,
    TEX_WIDTH,
)
from whitted.scene.textures import CheckerTexture, GradientTexture, ImageTexture

RED, GREEN, BLUE, WHITE = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 1.0, 1.0)


def srgb_reference(c: float) -> float:
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def write_png(path: Path, codes: np.ndarray) -> Path:
    Image.fromarray(codes).save(path)
    return path


@pytest.fixture()
def quad_png(tmp_path: Path) -> Path:
    """2x2 image: top row red, green; bottom row blue, white."""
    codes = np.array(
        [[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [255, 255, 255]]], dtype=np.uint8
    )
    return write_png(tmp_path / "quad.png", codes)


def compiled(*textures, base: Path | None = None) -> TextureArrays:
    return compile_textures(list(textures), lambda name: (base or Path.cwd()) / name)


def lookup(arrays: TextureArrays, u: float, v: float, k: int = 0) -> tuple[float, float, float]:
    return texture_color(arrays.tex_info, arrays.tex_pixels, k, float(u), float(v))


def quad(quad_png: Path, **fields) -> TextureArrays:
    fields.setdefault("colorspace", "linear")
    return compiled(ImageTexture(file=quad_png.name, **fields), base=quad_png.parent)


# --- sRGB and decoding ---------------------------------------------------------------------


def test_srgb_curve_exact_points():
    assert srgb_to_linear(0.0) == 0.0
    assert srgb_to_linear(1.0) == 1.0
    assert srgb_to_linear(0.5) == pytest.approx(((0.5 + 0.055) / 1.055) ** 2.4, rel=1e-15)
    assert srgb_to_linear(0.5) == pytest.approx(0.21404114, abs=1e-8)
    assert srgb_to_linear(0.04) == pytest.approx(0.04 / 12.92, rel=1e-15)  # linear segment


def test_8bit_srgb_decode(tmp_path: Path):
    codes = np.array([[[0, 10, 188], [255, 128, 1]]], dtype=np.uint8)
    pixels = load_image(write_png(tmp_path / "c.png", codes))
    assert pixels.dtype == np.float32 and pixels.shape == (1, 2, 3)
    assert pixels[0, 0, 2] == pytest.approx(0.50289, abs=1e-5)  # 188 -> 0.5029
    expected = np.vectorize(srgb_reference)(codes / 255.0)
    np.testing.assert_allclose(pixels, expected, rtol=1e-6, atol=1e-9)
    assert pixels[0, 0, 0] == 0.0 and pixels[0, 1, 0] == 1.0


def test_linear_colorspace_only_scales(tmp_path: Path):
    codes = np.array([[[0, 51, 255]]], dtype=np.uint8)
    pixels = load_image(write_png(tmp_path / "l.png", codes), colorspace="linear")
    np.testing.assert_allclose(pixels[0, 0], [0.0, 0.2, 1.0], rtol=1e-6)


def test_row_zero_is_top(quad_png: Path):
    pixels = load_image(quad_png, colorspace="linear")
    assert tuple(pixels[0, 0]) == RED and tuple(pixels[0, 1]) == GREEN
    assert tuple(pixels[1, 0]) == BLUE and tuple(pixels[1, 1]) == WHITE


def test_16bit_rgb_png_keeps_16_bits(tmp_path: Path):
    values = np.array([[0, 32768, 65535, 1, 2, 3]], dtype=np.uint16)  # two RGB pixels
    path = tmp_path / "deep.png"
    with open(path, "wb") as f:
        png.Writer(2, 1, greyscale=False, bitdepth=16).write(f, values.tolist())
    linear = load_image(path, colorspace="linear")
    np.testing.assert_allclose(linear[0, 0], [0.0, 32768 / 65535, 1.0], rtol=1e-7)
    np.testing.assert_allclose(linear[0, 1], np.array([1, 2, 3]) / 65535, rtol=1e-6)
    decoded = load_image(path)
    assert decoded[0, 0, 1] == pytest.approx(srgb_reference(32768 / 65535), rel=1e-6)


def test_16bit_grey_png(tmp_path: Path):
    path = tmp_path / "grey16.png"
    with open(path, "wb") as f:
        png.Writer(2, 1, greyscale=True, bitdepth=16).write(f, [[1000, 65535]])
    pixels = load_image(path, colorspace="linear")
    assert pixels.shape == (1, 2, 3)
    np.testing.assert_allclose(pixels[0, 0], [1000 / 65535] * 3, rtol=1e-6)
    np.testing.assert_allclose(pixels[0, 1], [1.0] * 3)


def test_grey_png_becomes_rgb(tmp_path: Path):
    path = write_png(tmp_path / "grey.png", np.array([[0, 188]], dtype=np.uint8))
    pixels = load_image(path)
    assert pixels.shape == (1, 2, 3)
    np.testing.assert_allclose(pixels[0, 1], [srgb_reference(188 / 255)] * 3, rtol=1e-6)


def test_rgba_and_palette_drop_alpha(tmp_path: Path):
    rgba = np.array([[[255, 0, 0, 0], [0, 0, 255, 128]]], dtype=np.uint8)
    pixels = load_image(write_png(tmp_path / "rgba.png", rgba), colorspace="linear")
    assert pixels.shape == (1, 2, 3)
    np.testing.assert_array_equal(pixels[0], [RED, BLUE])
    palette = Image.fromarray(rgba[:, :, :3]).convert("P", palette=Image.Palette.ADAPTIVE)
    palette.save(tmp_path / "palette.png")
    np.testing.assert_array_equal(
        load_image(tmp_path / "palette.png", colorspace="linear")[0], [RED, BLUE]
    )


def test_other_formats(tmp_path: Path):
    codes = np.array([[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [255, 255, 255]]], np.uint8)
    for suffix in ("bmp", "tga"):
        Image.fromarray(codes).save(tmp_path / f"quad.{suffix}")
        pixels = load_image(tmp_path / f"quad.{suffix}", colorspace="linear")
        np.testing.assert_array_equal(pixels, codes / 255.0, err_msg=suffix)


@pytest.mark.parametrize(
    "content",
    [None, b"", b"hello, not an image\n", b"\x89PNG\r\n\x1a\n" + b"\x00" * 40, "truncated"],
    ids=["missing", "empty", "text", "bad-png", "truncated"],
)
def test_bad_files_are_one_line_scene_errors(tmp_path: Path, quad_png: Path, content):
    path = tmp_path / "broken.png"
    if content == "truncated":
        data = quad_png.read_bytes()
        content = data[: len(data) // 2]
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(SceneError) as info:
        load_image(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(str(path))
    assert info.value.file == str(path)


def test_folder_is_a_scene_error(tmp_path: Path):
    with pytest.raises(SceneError, match="is a directory, not an image file"):
        load_image(tmp_path)


def test_cache_reuses_and_notices_changes(tmp_path: Path):
    clear_image_cache()
    path = write_png(tmp_path / "c.png", np.full((1, 1, 3), 255, np.uint8))
    first = load_image(path, colorspace="linear")
    assert load_image(path, colorspace="linear") is first
    assert not first.flags.writeable
    assert load_image(path) is not first  # another colorspace, another entry
    write_png(path, np.zeros((1, 2, 3), np.uint8))
    stat = path.stat()
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + 10**9))
    changed = load_image(path, colorspace="linear")
    assert changed.shape == (1, 2, 3) and changed.max() == 0.0


# --- compiled table ------------------------------------------------------------------------


def test_empty_list_gives_a_placeholder_row():
    arrays = compile_textures([], lambda name: Path(name))
    assert arrays.tex_info.shape == (1, N_TEX_PARAMS) and arrays.tex_info.dtype == np.float64
    assert arrays.tex_pixels.shape == (3,) and arrays.tex_pixels.dtype == np.float32


def test_images_are_concatenated_once_each(tmp_path: Path, quad_png: Path):
    write_png(tmp_path / "one.png", np.full((1, 1, 3), 255, np.uint8))
    arrays = compiled(
        ImageTexture(file="quad.png"),
        CheckerTexture(),
        ImageTexture(file="one.png", colorspace="linear"),
        ImageTexture(file="quad.png", wrap="clamp"),  # the same pixels as row 0
        base=tmp_path,
    )
    info = arrays.tex_info
    assert info.shape == (4, N_TEX_PARAMS)
    assert list(info[:, TEX_KIND]) == [TEX_IMAGE, 1, TEX_IMAGE, TEX_IMAGE]
    assert arrays.tex_pixels.shape == (2 * 2 * 3 + 3,)
    assert (info[0, TEX_WIDTH], info[0, TEX_HEIGHT]) == (2, 2)
    assert info[0, TEX_PIXEL_OFFSET] == info[3, TEX_PIXEL_OFFSET] == 0
    assert info[2, TEX_PIXEL_OFFSET] == 12
    assert lookup(arrays, 0.5, 0.5, k=2) == WHITE


def test_missing_image_raises_from_compile(tmp_path: Path):
    with pytest.raises(SceneError, match="not found"):
        compiled(ImageTexture(file="nowhere.png"), base=tmp_path)


# --- image lookup --------------------------------------------------------------------------

TEXEL_CENTRES = [((0.25, 0.75), RED), ((0.75, 0.75), GREEN), ((0.25, 0.25), BLUE),
                 ((0.75, 0.25), WHITE)]


@pytest.mark.parametrize("filter_", ["bilinear", "nearest"])
@pytest.mark.parametrize("wrap", ["repeat", "clamp"])
def test_texel_centres_give_exact_colours(quad_png: Path, filter_: str, wrap: str):
    arrays = quad(quad_png, filter=filter_, wrap=wrap)
    for (u, v), colour in TEXEL_CENTRES:
        assert lookup(arrays, u, v) == colour, (u, v)


def test_bilinear_midpoint_is_the_average(quad_png: Path):
    for wrap in ("repeat", "clamp"):
        r, g, b = lookup(quad(quad_png, wrap=wrap), 0.5, 0.5)
        assert (r, g, b) == pytest.approx((0.5, 0.5, 0.5), abs=1e-12)
    # halfway between the two top texels
    assert lookup(quad(quad_png), 0.5, 0.75) == pytest.approx((0.5, 0.5, 0.0), abs=1e-12)


def test_nearest_takes_the_containing_texel(quad_png: Path):
    arrays = quad(quad_png, filter="nearest")
    assert lookup(arrays, 0.49, 0.51) == RED
    assert lookup(arrays, 0.51, 0.51) == GREEN
    assert lookup(arrays, 0.49, 0.49) == BLUE
    assert lookup(arrays, 1.0, 1.0) == RED  # repeat: (1, 1) is (0, 0) ... the top-left texel
    assert lookup(quad(quad_png, filter="nearest", wrap="clamp"), 1.0, 0.0) == WHITE


def test_repeat_versus_clamp(quad_png: Path):
    repeat, clamp = quad(quad_png), quad(quad_png, wrap="clamp")
    assert lookup(repeat, 1.25, 0.75) == RED  # 1.25 repeats to 0.25
    assert lookup(clamp, 1.25, 0.75) == GREEN  # beyond the right edge: the right column
    assert lookup(repeat, -0.25, 0.75) == GREEN  # -0.25 repeats to 0.75
    assert lookup(clamp, -0.25, 0.75) == RED
    assert lookup(repeat, -1.75, -0.75) == BLUE  # negative in both: (0.25, 0.25)
    # at the seam u = 0, repeat blends the left and right columns, clamp keeps the edge
    assert lookup(repeat, 0.0, 0.75) == pytest.approx((0.5, 0.5, 0.0), abs=1e-12)
    assert lookup(clamp, 0.0, 0.75) == RED


def test_rotation_scale_offset_move_the_lookup(quad_png: Path):
    # (u', v') = R(90°)·(u, v) = (-v, u): (0.75, 0.75) -> (-0.75, 0.75) ~ (0.25, 0.75): red
    assert lookup(quad(quad_png, rotation=90.0), 0.75, 0.75) == RED
    assert lookup(quad(quad_png, rotation=90.0), 0.25, 0.75) == BLUE  # (-0.75, 0.25)
    # scale first: (0.125, 0.375) * 2 = (0.25, 0.75)
    assert lookup(quad(quad_png, scale=(2.0, 2.0)), 0.125, 0.375) == RED
    assert lookup(quad(quad_png, offset=(0.5, 0.0)), 0.25, 0.75) == GREEN
    assert lookup(quad(quad_png, offset=(0.0, -0.5)), 0.25, 0.75) == BLUE


def test_placement_formula_matches_numpy():
    rng = np.random.default_rng(7)
    for _ in range(20):
        scale = rng.uniform(-3, 3, size=2)
        rotation = rng.uniform(-400, 400)
        offset = rng.uniform(-1, 1, size=2)
        u, v = rng.uniform(-2, 2, size=2)
        angle = math.radians(rotation)
        rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
        up, vp = rot @ (scale * (u, v)) + offset
        for axis, expected in (("u", up), ("v", vp)):
            texture = GradientTexture(
                axis=axis, scale=tuple(scale), rotation=rotation, offset=tuple(offset)
            )
            r, _, _ = lookup(compiled(texture), u, v)
            assert r == pytest.approx(min(max(expected, 0.0), 1.0), abs=1e-12)


# --- checker and gradient ------------------------------------------------------------------


def test_checker_values():
    c1, c2 = (0.9, 0.8, 0.7), (0.1, 0.2, 0.3)
    arrays = compiled(CheckerTexture(color1=c1, color2=c2, checks=4.0))
    assert lookup(arrays, 0.1, 0.1) == c1
    assert lookup(arrays, 0.3, 0.1) == c2
    assert lookup(arrays, 0.3, 0.3) == c1
    assert lookup(arrays, -0.1, 0.1) == c2  # floor(-0.4) + floor(0.4) = -1: odd
    assert lookup(arrays, -0.1, -0.1) == c1  # -2: even
    assert lookup(arrays, -0.3, 0.1) == c1  # floor(-1.2) = -2
    assert lookup(arrays, 1e300, 0.1) == c1  # huge integers are even
    placed = compiled(CheckerTexture(color1=c1, color2=c2, checks=1.0, offset=(0.5, 0.0)))
    assert lookup(placed, 0.6, 0.5) == c2  # u' = 1.1


def test_gradient_ends_middle_and_clamp():
    arrays = compiled(
        GradientTexture(color1=(0.0, 0.2, 1.0), color2=(1.0, 0.4, 0.0)),
        GradientTexture(color1=(0.0, 0.0, 0.0), color2=(1.0, 1.0, 1.0), axis="v"),
    )
    assert lookup(arrays, 0.0, 0.9) == (0.0, 0.2, 1.0)
    assert lookup(arrays, 1.0, 0.9) == (1.0, 0.4, 0.0)
    assert lookup(arrays, 0.5, 0.9) == pytest.approx((0.5, 0.3, 0.5), abs=1e-15)
    assert lookup(arrays, -3.0, 0.0) == (0.0, 0.2, 1.0)
    assert lookup(arrays, 7.0, 0.0) == (1.0, 0.4, 0.0)
    assert lookup(arrays, 0.9, 0.25, k=1) == (0.25, 0.25, 0.25)


def test_nan_gives_colour1_or_first_texel(quad_png: Path):
    nan = float("nan")
    assert lookup(quad(quad_png), nan, 0.3) == RED
    assert lookup(quad(quad_png, filter="nearest", wrap="clamp"), 0.3, nan) == RED
    assert lookup(compiled(CheckerTexture(color1=GREEN)), nan, nan) == GREEN
    assert lookup(compiled(GradientTexture(color1=BLUE)), nan, 0.5) == BLUE
    # overflow to infinity after placement behaves the same
    assert lookup(compiled(CheckerTexture(color1=GREEN, scale=(1e10, 1.0))), 1e300, 0.5) == GREEN
    assert lookup(quad(quad_png, scale=(1e10, 1.0)), 1e300, 0.5) == RED


# --- any finite (u, v) ---------------------------------------------------------------------

_RANDOM_CODES = np.random.default_rng(3).integers(0, 256, size=(3, 5, 3), dtype=np.uint8)


@pytest.fixture(scope="module")
def random_textures(tmp_path_factory) -> tuple[TextureArrays, np.ndarray]:
    folder = tmp_path_factory.mktemp("random")
    write_png(folder / "random.png", _RANDOM_CODES)
    textures = [
        ImageTexture(file="random.png", wrap=wrap, filter=filter_, scale=(3.0, -2.0),
                     rotation=33.0, offset=(0.1, -0.7))
        for wrap in ("repeat", "clamp") for filter_ in ("bilinear", "nearest")
    ]
    textures += [CheckerTexture(checks=1e6, scale=(1e5, 1.0)), GradientTexture(rotation=10.0)]
    return compiled(*textures, base=folder), load_image(folder / "random.png")


finite = st.floats(allow_nan=False, allow_infinity=False)


@settings(max_examples=300, deadline=None)
@given(u=finite, v=finite)
@example(u=7.3e18, v=0.0)  # beyond int64 after placement
@example(u=-1.7e308, v=1.7e308)  # overflows to infinity after placement
@example(u=-1e-20, v=-5e-324)  # fractional part rounds up to 1.0
@example(u=0.0, v=0.0)
def test_any_finite_uv_gives_a_colour_of_the_texture(random_textures, u: float, v: float):
    arrays, pixels = random_textures
    low, high = pixels.reshape(-1, 3).min(axis=0), pixels.reshape(-1, 3).max(axis=0)
    for k in range(4):
        colour = np.array(lookup(arrays, u, v, k))
        assert np.all(np.isfinite(colour))
        assert np.all(colour >= low - 1e-6) and np.all(colour <= high + 1e-6), (k, colour)
    assert lookup(arrays, u, v, 4) in ((0.9, 0.9, 0.9), (0.1, 0.1, 0.1))
    gradient = np.array(lookup(arrays, u, v, 5))
    assert np.all(gradient >= 0.0) and np.all(gradient <= 1.0)


# --- called from another kernel ------------------------------------------------------------


def test_texture_color_inside_a_kernel_without_allocation(quad_png: Path):
    """The integrator calls texture_color from compiled code built without the Numba runtime."""
    from whitted.jit import kernel

    @kernel(cache=False)
    def shade_all(tex_info, tex_pixels, k, uv, out):
        for i in range(uv.shape[0]):
            r, g, b = texture_color(tex_info, tex_pixels, k, uv[i, 0], uv[i, 1])
            out[i, 0] = r
            out[i, 1] = g
            out[i, 2] = b

    arrays = quad(quad_png)
    uv = np.array([[0.25, 0.75], [0.5, 0.5], [-3.2, 9.1], [np.nan, 0.0]])
    out = np.zeros((len(uv), 3))
    shade_all(arrays.tex_info, arrays.tex_pixels, 0, uv, out)
    for i, (u, v) in enumerate(uv):
        assert tuple(out[i]) == lookup(arrays, u, v)
