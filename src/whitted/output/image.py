"""The :class:`Image` wrapper around a linear float32 framebuffer."""

from __future__ import annotations

import io
import os
import pathlib
from typing import Any

import numpy as np

from whitted.output import colour, formats


class Image:
    """A rendered picture: linear float32 RGB pixels plus how to display them.

    ``pixels`` is a float32 C-contiguous (H, W, 3) array of linear radiance, row 0 at the top
    (an input that already is one is kept without a copy). ``transfer`` ("srgb" or "linear")
    and ``tonemap`` ("clamp", "reinhard" or "aces") are the defaults used when the image is
    turned into 8/16-bit values (:meth:`save` to .png/.jpg, :meth:`to_srgb8`, Jupyter display);
    HDR files (.exr, .pfm, .npy) always receive the raw linear data. ``meta`` is a free-form
    dict (render statistics and the like).
    """

    def __init__(
        self,
        pixels: np.ndarray,
        *,
        transfer: str = "srgb",
        tonemap: str = "clamp",
        meta: dict | None = None,
    ) -> None:
        self._pixels = colour.check_pixels(pixels)
        self.transfer = colour.check_transfer(transfer)
        self.tonemap = colour.check_tonemap(tonemap)
        self.meta: dict = {} if meta is None else dict(meta)

    # ---------------------------------------------------------------- properties

    @property
    def pixels(self) -> np.ndarray:
        """The linear float32 (H, W, 3) C-contiguous pixel array."""
        return self._pixels

    @pixels.setter
    def pixels(self, value: np.ndarray) -> None:
        self._pixels = colour.check_pixels(value)

    @property
    def width(self) -> int:
        return int(self._pixels.shape[1])

    @property
    def height(self) -> int:
        return int(self._pixels.shape[0])

    # ---------------------------------------------------------------- conversions

    def to_srgb8(self) -> np.ndarray:
        """uint8 (H, W, 3) display values: this image's tonemap, then its transfer."""
        return colour.encode_ldr(self._pixels, bits=8, transfer=self.transfer, tonemap=self.tonemap)

    def to_uint16(self) -> np.ndarray:
        """uint16 (H, W, 3) display values: this image's tonemap, then its transfer."""
        return colour.encode_ldr(
            self._pixels, bits=16, transfer=self.transfer, tonemap=self.tonemap
        )

    def _repr_png_(self) -> bytes:
        """8-bit PNG bytes, for Jupyter's rich display."""
        from PIL import Image as PILImage

        buf = io.BytesIO()
        PILImage.fromarray(self.to_srgb8()).save(buf, format="PNG")
        return buf.getvalue()

    def __array__(self, dtype: Any = None, copy: bool | None = None) -> np.ndarray:
        if dtype is None or np.dtype(dtype) == self._pixels.dtype:
            return self._pixels.copy() if copy else self._pixels
        if copy is False:
            raise ValueError(f"cannot convert Image pixels to {np.dtype(dtype)} without a copy")
        return self._pixels.astype(dtype)

    def __repr__(self) -> str:
        return f"<Image {self.width}x{self.height} linear {self._pixels.dtype}>"

    # ---------------------------------------------------------------- files

    def save(
        self,
        path: str | os.PathLike[str],
        *,
        bit_depth: int = 8,
        transfer: str | None = None,
        tonemap: str | None = None,
        alpha: np.ndarray | None = None,
        quality: int | None = None,
    ) -> pathlib.Path:
        """Write the image atomically; the format comes from the extension of ``path``.

        ``.png`` (``bit_depth`` 8 or 16), ``.jpg``/``.jpeg`` (8-bit, quality 95): tonemap ->
        transfer -> quantize, using this image's ``transfer`` / ``tonemap`` unless overridden.
        ``.tif``/``.tiff``, ``.webp``: 8-bit, as .png (WebP lossless, or lossy at
        ``quality``). ``.exr``, ``.pfm``, ``.npy``: raw linear float32. ``alpha``: an (H, W)
        coverage plane for .png, .tif, .webp (straight) and .exr, .npy (premultiplied)
        (:func:`whitted.output.formats.write_image`). ValueError for an unknown extension,
        transfer or tonemap, or a bit depth other than 8 (16 is accepted for .png only).
        Returns the path written.
        """
        return formats.write_image(
            path,
            self._pixels,
            bit_depth=bit_depth,
            transfer=self.transfer if transfer is None else transfer,
            tonemap=self.tonemap if tonemap is None else tonemap,
            alpha=alpha,
            quality=quality,
        )

    @classmethod
    def load(cls, path: str | os.PathLike[str], *, transfer: str = "srgb") -> Image:
        """Read an image file (see :func:`whitted.output.formats.read_image`).

        LDR files are decoded with ``transfer``, which also becomes the image's transfer.
        """
        return cls(formats.read_image(path, transfer=transfer), transfer=transfer)
