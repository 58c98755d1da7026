"""Image files of a framebuffer: the writers and readers of each format.

The renderer hands over a float32 *linear* HDR framebuffer of shape (H, W, 3), row 0 at the
top of the picture. This module turns it into files:

* HDR formats (``.exr``, ``.pfm``, ``.npy``) always store the raw linear float32 data: no tone
  mapping, no transfer curve, NaN and infinities kept as they are.
* LDR formats (``.png``, ``.jpg``/``.jpeg``, ``.tif``/``.tiff``, ``.webp``) go through
  tonemap -> transfer -> quantize.
* An alpha channel (a coverage plane, 0 where the primary rays missed everything) goes into
  PNG, TIFF and WebP as straight (unassociated) alpha, and into EXR and NPY with the colour
  premultiplied, as those formats expect; JPEG and PFM have none.

Every file is written atomically (see :func:`atomic_write`): a reader never sees a partial file.
"""

from __future__ import annotations

import io
import os
import pathlib

import numpy as np

from ..errors import ArgumentError
from ..files import atomic_write, path_problem
from .colour import (
    TONEMAPS,
    TRANSFERS,
    check_bit_depth,
    check_pixels,
    check_tonemap,
    check_transfer,
    encode_ldr,
    linear_to_srgb,
    quantize,
    srgb_to_linear,
    tonemap,
)

_apply_tonemap = tonemap  # the name ``tonemap`` is shadowed by keyword parameters below

__all__ = [
    "ALPHA_FORMATS",
    "FORMATS",
    "HDR_FORMATS",
    "LDR_FORMATS",
    "TONEMAPS",
    "TRANSFERS",
    "atomic_write",
    "check_bit_depth",
    "check_pixels",
    "check_tonemap",
    "check_image_options",
    "check_transfer",
    "encode_ldr",
    "image_format",
    "linear_to_srgb",
    "quantize",
    "read_image",
    "srgb_to_linear",
    "tonemap",
    "write_image",
]

PathLike = str | os.PathLike[str]

FORMATS: dict[str, str] = {
    ".png": "png",
    ".jpg": "jpeg",
    ".jpeg": "jpeg",
    ".tif": "tiff",
    ".tiff": "tiff",
    ".webp": "webp",
    ".exr": "exr",
    ".pfm": "pfm",
    ".npy": "npy",
}
HDR_FORMATS: frozenset[str] = frozenset({"exr", "pfm", "npy"})
LDR_FORMATS: frozenset[str] = frozenset({"png", "jpeg", "tiff", "webp"})
#: formats that hold an alpha channel
ALPHA_FORMATS: frozenset[str] = frozenset({"png", "tiff", "webp", "exr", "npy"})
#: formats whose encoder takes a quality (1..100; WebP without one is lossless)
QUALITY_FORMATS: frozenset[str] = frozenset({"jpeg", "webp"})

JPEG_QUALITY = 95  # written with 4:4:4 chroma (no subsampling): renders have sharp colour edges
#: zlib level of PNG stills (output/png.py). Measured on renders (809x817 seed000, 800x300,
#: 400x300, with Pillow): level 4 writes in about half the time of the default 6 (34 vs 86 ms,
#: 6.9 vs 14.9 ms, 4.2 vs 11.5 ms) for files 6-25 % larger, and is both faster and smaller
#: than 3. With output/png.py's Up filter, seed000: 14.9 ms against 43.8 ms at 6 on one
#: thread, 222 KB against 205 KB. The pixels are the same at every level (zlib is lossless).
PNG_COMPRESS_LEVEL = 4


# --------------------------------------------------------------------------------------------
# validation helpers


def image_format(path: PathLike) -> str:
    """Format name ("png", "jpeg", "exr", "pfm", "npy") chosen by the (case-insensitive)
    extension of ``path``; ValueError for any other extension."""
    suffix = pathlib.Path(path).suffix
    try:
        return FORMATS[suffix.lower()]
    except KeyError:
        raise ArgumentError(
            f"unsupported image format '{suffix}' (use .png, .jpg, .tif, .webp, .exr, .pfm "
            "or .npy)"
        ) from None


def check_image_options(fmt: str, *, alpha: bool = False, quality: int | None = None) -> None:
    """ArgumentError (one line) when ``fmt`` cannot take an alpha channel or a quality."""
    if alpha and fmt not in ALPHA_FORMATS:
        raise ArgumentError(f"{fmt.upper()} has no alpha channel (use .png, .tif, .webp, .exr "
                            "or .npy)")
    if quality is not None:
        if isinstance(quality, bool) or not isinstance(quality, int) \
                or not 1 <= quality <= 100:
            raise ArgumentError(f"quality must be a whole number from 1 to 100, got "
                                f"{quality!r}")
        if fmt not in QUALITY_FORMATS:
            raise ArgumentError(f"a quality is for .jpg and .webp, not {fmt.upper()} "
                                "(lossless)")



# --------------------------------------------------------------------------------------------
# writers (each takes the temporary path and already-encoded data)


#: Rows encoded at a time: the tonemap/transfer/quantize steps work in float64, so they run
#: on strips of rows and an 8-bit image costs a few bytes per pixel beyond its framebuffer.
STRIP_PIXELS = 1 << 16


def _strips(height: int, width: int):
    rows = max(1, STRIP_PIXELS // max(1, width))
    for y in range(0, height, rows):
        yield y, min(height, y + rows)


def _encoded_strips(pixels: np.ndarray, bits: int, transfer: str, tonemap: str):
    """(first row, encoded uint8/uint16 rows) for consecutive strips of ``pixels``."""
    for y0, y1 in _strips(pixels.shape[0], pixels.shape[1]):
        yield y0, encode_ldr(pixels[y0:y1], bits=bits, transfer=transfer, tonemap=tonemap)


def _pil_rgb(pixels: np.ndarray, transfer: str, tonemap: str):
    """A Pillow RGB image filled strip by strip (no full-size float64 or uint8 copy)."""
    from PIL import Image as PILImage

    h, w, _ = pixels.shape
    image = PILImage.new("RGB", (w, h))
    for y0, strip in _encoded_strips(pixels, 8, transfer, tonemap):
        image.paste(PILImage.fromarray(strip), (0, y0))
    return image


def _write_png(tmp: str, pixels: np.ndarray, transfer: str, tonemap: str, bits: int) -> None:
    from .png import write_png

    h, w, _ = pixels.shape

    def encode_rows(y0: int, y1: int) -> np.ndarray:  # in strips: no whole-unit float64
        rows = np.empty((y1 - y0, w, 3), np.uint8 if bits == 8 else np.uint16)
        for a, b in _strips(y1 - y0, w):
            rows[a:b] = encode_ldr(pixels[y0 + a:y0 + b], bits=bits, transfer=transfer,
                                   tonemap=tonemap)
        return rows

    with open(tmp, "wb") as f:
        write_png(f, h, w, bits, encode_rows, PNG_COMPRESS_LEVEL)


def _write_jpeg(tmp: str, pixels: np.ndarray, transfer: str, tonemap: str,
                quality: int | None = None) -> None:
    _pil_rgb(pixels, transfer, tonemap).save(tmp, format="JPEG",
                                             quality=quality or JPEG_QUALITY, subsampling=0)


def _with_alpha(image, alpha: np.ndarray | None):
    """The Pillow RGB image with ``alpha`` (0..1, straight) as its A channel (RGBA)."""
    if alpha is None:
        return image
    from PIL import Image as PILImage

    image.putalpha(PILImage.fromarray(quantize(np.clip(alpha, 0.0, 1.0), 8)))
    return image


def _write_pillow(tmp: str, fmt: str, pixels: np.ndarray, transfer: str, tonemap: str,
                  alpha: np.ndarray | None, quality: int | None) -> None:
    """TIFF (deflate) or WebP (lossless, or lossy at ``quality``), through Pillow."""
    image = _with_alpha(_pil_rgb(pixels, transfer, tonemap), alpha)
    if fmt == "tiff":
        image.save(tmp, format="TIFF", compression="tiff_adobe_deflate")
    elif quality is None:
        image.save(tmp, format="WEBP", lossless=True, quality=100, method=4)
    else:
        image.save(tmp, format="WEBP", quality=quality, method=4)


def _write_exr(tmp: str, data: np.ndarray, alpha: np.ndarray | None = None) -> None:
    import OpenEXR

    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    if alpha is None:
        OpenEXR.File(header, {"RGB": data}).write(tmp)
        return
    rgba = np.concatenate([data, alpha[..., None].astype(np.float32)], axis=2)
    OpenEXR.File(header, {"RGBA": np.ascontiguousarray(rgba)}).write(tmp)


def _write_pfm(tmp: str, data: np.ndarray) -> None:
    h, w, _ = data.shape
    with open(tmp, "wb") as f:
        f.write(f"PF\n{w} {h}\n-1.0\n".encode("ascii"))
        # PFM stores scanlines bottom-to-top; a negative scale means little-endian.
        for y0, y1 in _strips(h, w):  # bottom strip first, each flipped: no full-size copy
            f.write(np.ascontiguousarray(data[h - y1:h - y0][::-1], dtype="<f4").tobytes())


def _write_npy(tmp: str, data: np.ndarray) -> None:
    # A file object, not a path: np.save would append ".npy" to a path ending in ".NPY".
    with open(tmp, "wb") as f:
        np.save(f, data, allow_pickle=False)


def write_image(
    path: PathLike,
    pixels: np.ndarray,
    *,
    bit_depth: int = 8,
    transfer: str = "srgb",
    tonemap: str = "clamp",
    alpha: np.ndarray | None = None,
    quality: int | None = None,
) -> pathlib.Path:
    """Write linear float pixels (H, W, 3) to ``path`` atomically, format by extension.

    ``.exr`` / ``.pfm`` / ``.npy`` get the raw linear float32 data (``transfer`` and
    ``tonemap`` are ignored); ``.png`` (8 or 16-bit, encoded on threads: output/png.py),
    ``.jpg``/``.jpeg`` (8-bit, ``quality`` 95 unless given), ``.tif``/``.tiff`` (8-bit,
    deflate) and ``.webp`` (lossless, or lossy at ``quality``) get tonemap -> transfer ->
    quantize. ``alpha``: an (H, W) coverage plane in 0..1 for the formats that hold one, with
    ``pixels`` straight (not premultiplied): LDR files store it so, EXR and NPY store the
    colour premultiplied by it (RGBA). Everything is validated before the disk is touched.
    Returns ``path`` as a :class:`pathlib.Path`.
    """
    fmt = image_format(path)
    check_transfer(transfer)
    check_tonemap(tonemap)
    check_bit_depth(bit_depth, fmt)
    check_image_options(fmt, alpha=alpha is not None, quality=quality)
    data = check_pixels(pixels)
    if alpha is not None:
        alpha = np.asarray(alpha, dtype=np.float32)
        if alpha.shape != data.shape[:2]:
            raise ArgumentError(f"alpha must be (height, width) = {data.shape[:2]}, got "
                                f"{alpha.shape}")

    if fmt in HDR_FORMATS:
        if alpha is not None:  # premultiplied, as EXR readers expect
            premultiplied = data * alpha[..., None]
            if fmt == "exr":
                return atomic_write(path, lambda tmp: _write_exr(tmp, premultiplied, alpha))
            rgba = np.concatenate([premultiplied, alpha[..., None]], axis=2)
            return atomic_write(path, lambda tmp: _write_npy(tmp, rgba))
        writer = {"exr": _write_exr, "pfm": _write_pfm, "npy": _write_npy}[fmt]
        return atomic_write(path, lambda tmp: writer(tmp, data))
    if fmt == "jpeg":
        return atomic_write(path, lambda tmp: _write_jpeg(tmp, data, transfer, tonemap,
                                                          quality))
    if fmt in ("tiff", "webp"):
        return atomic_write(path, lambda tmp: _write_pillow(tmp, fmt, data, transfer, tonemap,
                                                            alpha, quality))
    if alpha is not None:
        return atomic_write(path, lambda tmp: _write_png_alpha(tmp, data, alpha, transfer,
                                                               tonemap, bit_depth))
    return atomic_write(path, lambda tmp: _write_png(tmp, data, transfer, tonemap, bit_depth))


def _write_png_alpha(tmp: str, pixels: np.ndarray, alpha: np.ndarray, transfer: str,
                     tonemap: str, bits: int) -> None:
    """An RGBA PNG (8 or 16-bit) through Pillow (output/png.py writes RGB only)."""
    from PIL import Image as PILImage

    rgb = encode_ldr(pixels, bits=bits, transfer=transfer, tonemap=tonemap)
    a = quantize(np.clip(alpha, 0.0, 1.0), bits)
    rgba = np.concatenate([rgb, a[..., None]], axis=2)
    from .png import software_chunk, software_text

    if bits == 8:
        PILImage.fromarray(rgba, "RGBA").save(tmp, format="PNG", pnginfo=software_text(),
                                             compress_level=PNG_COMPRESS_LEVEL)
        return
    import png as pypng  # 16-bit RGBA: Pillow has no such mode

    encoded = io.BytesIO()
    writer = pypng.Writer(pixels.shape[1], pixels.shape[0], bitdepth=16, greyscale=False,
                          alpha=True)
    writer.write(encoded, rgba.reshape(pixels.shape[0], -1))
    data = encoded.getvalue()
    ihdr_end = 8 + 8 + 13 + 4  # the signature, then IHDR: length, type, 13 bytes, CRC
    with open(tmp, "wb") as f:
        f.write(data[:ihdr_end] + software_chunk() + data[ihdr_end:])


# --------------------------------------------------------------------------------------------
# readers


def _to_rgb(arr: np.ndarray, source: object) -> np.ndarray:
    """(H, W), (H, W, 1), (H, W, 2) grey+alpha, (H, W, 3) or (H, W, 4) -> (H, W, 3)."""
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if arr.ndim != 3 or arr.shape[2] not in (1, 2, 3, 4):
        raise ValueError(f"{source}: cannot use image data of shape {arr.shape} as RGB")
    if arr.shape[2] in (1, 2):
        arr = np.repeat(arr[:, :, :1], 3, axis=2)
    return np.ascontiguousarray(arr[:, :, :3], dtype=np.float32)


def _read_exr(path: str) -> np.ndarray:
    import OpenEXR

    f = OpenEXR.File(path, separate_channels=True)
    channels = {name: np.asarray(ch.pixels) for name, ch in f.channels().items()}
    if all(c in channels for c in "RGB"):
        arr = np.stack([channels["R"], channels["G"], channels["B"]], axis=-1)
    elif "Y" in channels:
        arr = channels["Y"]
    elif len(channels) == 1:
        arr = next(iter(channels.values()))
    else:
        raise ValueError(f"{path}: no R, G, B or Y channels in EXR (has {sorted(channels)})")
    return _to_rgb(arr.astype(np.float32), path)


def _read_pfm(path: str) -> np.ndarray:
    with open(path, "rb") as f:
        raw = f.read()
    tokens: list[bytes] = []
    pos = 0
    while len(tokens) < 4:
        while pos < len(raw) and raw[pos : pos + 1].isspace():
            pos += 1
        start = pos
        while pos < len(raw) and not raw[pos : pos + 1].isspace():
            pos += 1
        if start == pos:
            raise ValueError(f"{path}: truncated PFM header")
        tokens.append(raw[start:pos])
    pos += 1  # exactly one whitespace character ends the header
    magic = tokens[0]
    if magic not in (b"PF", b"Pf"):
        raise ValueError(f"{path}: not a PFM file (magic {magic!r})")
    try:
        width, height, scale = int(tokens[1]), int(tokens[2]), float(tokens[3])
    except ValueError:
        raise ValueError(f"{path}: bad PFM header {b' '.join(tokens)!r}") from None
    if width <= 0 or height <= 0 or scale == 0.0:
        raise ValueError(f"{path}: bad PFM header {b' '.join(tokens)!r}")
    nchan = 3 if magic == b"PF" else 1
    count = width * height * nchan
    dtype = "<f4" if scale < 0 else ">f4"
    if len(raw) - pos < count * 4:
        raise ValueError(f"{path}: truncated PFM data")
    arr = np.frombuffer(raw, dtype=dtype, count=count, offset=pos)
    arr = arr.reshape(height, width, nchan)[::-1]  # stored bottom-to-top
    return _to_rgb(arr.astype(np.float32), path)


def _read_npy(path: str) -> np.ndarray:
    arr = np.load(path, allow_pickle=False)
    if not (np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)):
        raise ValueError(f"{path}: not a numeric array (dtype {arr.dtype})")
    return _to_rgb(arr, path)


def _read_png(path: str) -> np.ndarray:
    with open(path, "rb") as f:
        head = f.read(26)
    # IHDR is the first chunk: signature (8), length (4), "IHDR" (4), width, height, bit depth.
    if len(head) < 26 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        raise ValueError(f"{path}: not a PNG file")
    if head[24] == 16:
        # Pillow cannot give 16-bit RGB, so 16-bit files go through pypng.
        import png

        with open(path, "rb") as f:
            width, height, rows, info = png.Reader(file=f).asDirect()
            arr = np.vstack([np.asarray(row, dtype=np.float32) for row in rows])
        arr = arr.reshape(height, width, info["planes"]) / np.float32(65535.0)
        return _to_rgb(arr, path)
    return _read_pillow(path)


def _read_pillow(path: str) -> np.ndarray:
    """8-bit (or lower) PNG or JPEG of any colour type, as float32 RGB in [0, 1]."""
    from PIL import Image as PILImage

    with PILImage.open(path) as im:
        arr = np.asarray(im.convert("RGB"), dtype=np.float32) / np.float32(255.0)
    return _to_rgb(arr, path)


def read_image(path: PathLike, *, transfer: str = "srgb") -> np.ndarray:
    """Read an image file as a float32 (H, W, 3) linear array, row 0 at the top.

    ``.exr``, ``.pfm`` and ``.npy`` are returned as stored. ``.png`` (8- or 16-bit, any colour
    type), ``.jpg``/``.jpeg``, ``.tif``/``.tiff`` and ``.webp`` are normalised to [0, 1] and
    decoded with ``transfer``: the sRGB curve by default, or ``"linear"`` for files holding
    linear data (e.g. written with ``transfer="linear"``). Grey images are expanded to RGB
    and alpha is dropped.
    """
    check_transfer(transfer)
    fmt = image_format(path)
    p = os.fspath(path)
    problem = path_problem(p)
    if problem is not None:  # only regular files: a pipe or a device would hang or never end
        raise ArgumentError(f"{p}: {problem}")
    if fmt == "exr":
        return _read_exr(p)
    if fmt == "pfm":
        return _read_pfm(p)
    if fmt == "npy":
        return _read_npy(p)
    arr = _read_png(p) if fmt == "png" else _read_pillow(p)
    if transfer == "srgb":
        arr = srgb_to_linear(arr)
    return arr
