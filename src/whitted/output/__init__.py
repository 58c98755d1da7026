"""Output layer: turn the renderer's linear float32 framebuffer into image files.

LDR formats (.png 8/16-bit, .jpg) are tone mapped, encoded with a transfer curve (sRGB by
default) and quantized; HDR formats (.exr, .pfm, .npy) store the raw linear floats. All files
are written atomically.
"""

from whitted.files import atomic_write
from whitted.output.colour import linear_to_srgb, quantize, srgb_to_linear, tonemap
from whitted.output.formats import read_image, write_image
from whitted.output.image import Image

__all__ = [
    "Image",
    "atomic_write",
    "linear_to_srgb",
    "quantize",
    "read_image",
    "srgb_to_linear",
    "tonemap",
    "write_image",
]
