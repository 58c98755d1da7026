"""PNG files encoded on several threads.

A PNG's pixels are one zlib stream, which Pillow and pypng deflate on one thread. This writer
cuts the image into units of about :data:`DEFLATE_UNIT_BYTES` of filtered rows, and each
unit is encoded (tone map, transfer, quantise), filtered and deflated on a thread of its own
(NumPy and zlib release the GIL): a unit ends with a full flush, the next starts a fresh
dictionary, and the pieces concatenate into one valid deflate stream (as pigz does). The
units depend only on the image's size, so the file's bytes are the same on any number of
threads. The stream's Adler-32 is combined from the units' own (zlib's
``adler32_combine``); units are written as IDAT chunks in order as they finish, so memory
holds a few units, never the whole encoded image.

Every row uses PNG's "Up" filter (each byte minus the byte above it). On renders it gives
files as small as Pillow's per-row adaptive choice at the same zlib level, for a fraction of
the work (seed000, 809x817, level 4: 222 KB against Pillow's 227 KB; 9.7 ms on two threads
and 14.9 ms on one against Pillow's 35 ms, AMD EPYC).
"""

from __future__ import annotations

import os
import struct
import zlib
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import BinaryIO

import numpy as np

SIGNATURE = b"\x89PNG\r\n\x1a\n"
COLOR_TYPE_RGB = 2
FILTER_UP = 2
#: filtered bytes deflated as one unit (one thread's piece of work, one IDAT chunk)
DEFLATE_UNIT_BYTES = 1 << 20
ADLER_BASE = 65521
ZLIB_HEADER = b"\x78\x9c"  # deflate, 32 KiB window, default level (decoders ignore the level)


def adler32_combine(adler1: int, adler2: int, length2: int) -> int:
    """The Adler-32 of two byte strings one after the other, from each one's Adler-32 and the
    second's length (zlib's ``adler32_combine``, which Python's zlib does not expose)."""
    rem = length2 % ADLER_BASE
    sum1 = adler1 & 0xFFFF
    sum2 = (rem * sum1) % ADLER_BASE
    sum1 = (sum1 + (adler2 & 0xFFFF) + ADLER_BASE - 1) % ADLER_BASE
    sum2 = (sum2 + ((adler1 >> 16) & 0xFFFF) + ((adler2 >> 16) & 0xFFFF) + ADLER_BASE
            - rem) % ADLER_BASE
    return (sum2 << 16) | sum1


def _chunk(kind: bytes, data: bytes) -> bytes:
    return (struct.pack(">I", len(data)) + kind + data
            + struct.pack(">I", zlib.crc32(data, zlib.crc32(kind)) & 0xFFFFFFFF))


#: PNG's standard "Software" text: what wrote the file. A PNG whitted wrote carries it, and a
#: command may replace such a file at a name the user did not give (``whitted render``'s
#: render.png); any other file there is kept (:func:`written_by_whitted`).
SOFTWARE = b"whitted"


def software_chunk() -> bytes:
    """The tEXt chunk ``Software: whitted``, written after the IHDR of every PNG whitted
    writes."""
    return _chunk(b"tEXt", b"Software\0" + SOFTWARE)


def software_text():
    """The same text for a PNG Pillow writes: its ``pnginfo``."""
    from PIL.PngImagePlugin import PngInfo

    info = PngInfo()
    info.add_text("Software", SOFTWARE.decode())
    return info


def written_by_whitted(path) -> bool:
    """Whether ``path`` is a PNG file whose ``Software`` text (before its pixels) says whitted
    wrote it. False for anything else, a file that cannot be read included."""
    try:
        with open(path, "rb") as f:
            if f.read(len(SIGNATURE)) != SIGNATURE:
                return False
            for _ in range(64):  # the chunks before the first IDAT
                head = f.read(8)
                if len(head) < 8:
                    return False
                length, kind = struct.unpack(">I4s", head)
                if kind in (b"IDAT", b"IEND") or length > 1 << 20:
                    return False
                data = f.read(length)
                f.read(4)  # the CRC
                if kind == b"tEXt" and data.partition(b"\0")[::2] == (b"Software", SOFTWARE):
                    return True
    except OSError:
        return False
    return False


def unit_rows(height: int, width: int, bits: int) -> list[tuple[int, int]]:
    """The row ranges deflated as units: about DEFLATE_UNIT_BYTES of filtered rows each."""
    row_bytes = 1 + width * 3 * bits // 8
    rows = max(1, DEFLATE_UNIT_BYTES // row_bytes)
    return [(y, min(height, y + rows)) for y in range(0, height, rows)]


def _filtered_up(rows: np.ndarray, above: np.ndarray | None) -> np.ndarray:
    """``rows`` (n, row bytes) as PNG scanlines with the Up filter; ``above`` is the row
    before them (None at the top of the image: zeros)."""
    n, width = rows.shape
    out = np.empty((n, width + 1), np.uint8)
    out[:, 0] = FILTER_UP
    if above is None:
        out[0, 1:] = rows[0]
    else:
        np.subtract(rows[0], above, out=out[0, 1:])
    np.subtract(rows[1:], rows[:-1], out=out[1:, 1:])
    return out


def write_png(file: BinaryIO, height: int, width: int, bits: int,
              encode_rows: Callable[[int, int], np.ndarray], level: int,
              threads: int | None = None) -> None:
    """Write an RGB PNG of ``bits`` (8 or 16) per channel to ``file``. ``encode_rows(y0, y1)``
    returns rows ``y0`` to ``y1 - 1`` as (rows, width, 3) uint8 or uint16 display values;
    it is called from several threads at once, for at most a unit's rows and one more.
    ``threads`` defaults to the CPUs this process may use; the bytes written do not depend
    on it."""
    if bits not in (8, 16):
        raise ValueError(f"PNG bit depth must be 8 or 16, not {bits}")
    dtype = np.dtype(np.uint8) if bits == 8 else np.dtype(">u2")
    units = unit_rows(height, width, bits)

    def unit(k: int) -> tuple[bytes, int, int]:
        y0, y1 = units[k]
        first = max(0, y0 - 1)  # the row above the unit, for the Up filter of its first row
        rows = np.ascontiguousarray(encode_rows(first, y1), dtype=dtype)
        rows = rows.reshape(y1 - first, -1).view(np.uint8)
        raw = memoryview(_filtered_up(rows[y0 - first:], rows[0] if y0 > 0 else None))
        deflate = zlib.compressobj(level, zlib.DEFLATED, -15)
        last = k == len(units) - 1
        data = deflate.compress(raw) + deflate.flush(zlib.Z_FINISH if last else
                                                     zlib.Z_FULL_FLUSH)
        return data, zlib.adler32(raw), raw.nbytes

    file.write(SIGNATURE)
    file.write(_chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, bits, COLOR_TYPE_RGB,
                                           0, 0, 0)))
    file.write(software_chunk())
    if threads is None:
        threads = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (
            os.cpu_count() or 1)
    threads = max(1, min(threads, len(units)))
    checksum = 1  # Adler-32 of nothing
    prefix = ZLIB_HEADER
    with ThreadPoolExecutor(threads) if threads > 1 else _InThisThread() as pool:
        for data, adler, length in pool.map(unit, range(len(units))):
            checksum = adler32_combine(checksum, adler, length)
            file.write(_chunk(b"IDAT", prefix + data))
            prefix = b""
    file.write(_chunk(b"IDAT", struct.pack(">I", checksum)))
    file.write(_chunk(b"IEND", b""))


class _InThisThread:
    """``map`` in the calling thread, one item at a time (a pool of one, without a thread)."""

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        return None

    @staticmethod
    def map(fn, items):
        return (fn(item) for item in items)
