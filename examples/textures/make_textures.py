"""Write the example texture images next to this script (deterministic: run it again, same files).

- ``earth.png``: 256x128 equirectangular map of a made-up planet (oceans, continents, deserts,
  mountains, ice caps). The terrain is a smooth function of the 3-D point on the sphere, so the
  map has no seam at longitude 180° and no pinching at the poles.
- ``tiles.png``: 128x128 UV test grid, 8x8 coloured tiles labelled A1..H8: the letter counts
  tiles along u (A at u = 0), the digit along v (1 at the bottom, v = 0), so a wrongly flipped
  or rotated mapping is visible at once.

Usage: ``python examples/textures/make_textures.py``
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

HERE = Path(__file__).resolve().parent


def sphere_points(width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors (H, W, 3) at the pixel centres of an equirectangular map, and latitudes."""
    longitude = (np.arange(width) + 0.5) / width * 2.0 * np.pi - np.pi
    latitude = np.pi / 2.0 - (np.arange(height) + 0.5) / height * np.pi  # row 0 = north
    lon, lat = np.meshgrid(longitude, latitude)
    points = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], -1)
    return points, lat


def smooth_field(points: np.ndarray, rng: np.random.Generator, octaves: int = 5) -> np.ndarray:
    """A sum of random plane waves over the sphere, finer and weaker each octave; zero mean,
    unit standard deviation."""
    field = np.zeros(points.shape[:2])
    for octave in range(octaves):
        frequency = 4.0 * 1.9**octave
        amplitude = 0.55**octave
        for _ in range(10):
            direction = rng.normal(size=3)
            direction /= np.linalg.norm(direction)
            phase = rng.uniform(0.0, 2.0 * np.pi)
            field += amplitude * np.cos(frequency * (points @ direction) + phase)
    return (field - field.mean()) / field.std()


def blend(colour_a, colour_b, t: np.ndarray) -> np.ndarray:
    t = np.clip(t, 0.0, 1.0)[..., None]
    return np.asarray(colour_a) * (1.0 - t) + np.asarray(colour_b) * t


def make_earth(width: int = 256, height: int = 128) -> Image.Image:
    rng = np.random.default_rng(2024)
    points, latitude = sphere_points(width, height)
    elevation = smooth_field(points, rng)
    moisture = smooth_field(points, rng, octaves=4)
    polar = np.abs(latitude) / (np.pi / 2.0)  # 0 at the equator, 1 at the poles

    sea_level = np.quantile(elevation, 0.62)  # about 38 % land
    height_above = (elevation - sea_level) / (elevation.max() - sea_level)  # 0..1 on land
    depth = (sea_level - elevation) / (sea_level - elevation.min())  # 0..1 at sea

    ocean = blend((38, 96, 158), (10, 26, 74), depth / 0.5)
    land = blend((58, 118, 48), (112, 100, 64), height_above / 0.5)
    dry = (polar + 0.15 * moisture < 0.4) & (moisture < -0.9)  # deserts in the warm belt
    land = np.where(dry[..., None], blend((206, 180, 120), (160, 128, 84), height_above / 0.5),
                    land)
    land = np.where(
        (height_above > 0.6)[..., None],
        blend((120, 112, 104), (238, 238, 242), (height_above - 0.6) / 0.25),
        land,
    )
    land = np.where((height_above < 0.025)[..., None], (200, 186, 138), land)  # beaches
    colour = np.where((height_above > 0.0)[..., None], land, ocean)
    ice = polar + 0.2 * smooth_field(points, rng, octaves=3) > 0.9
    colour = np.where(ice[..., None], (236, 242, 248), colour)

    codes = np.clip(np.round(colour), 0, 255).astype(np.uint8)
    # a 64-colour palette keeps the file small; median cut is deterministic
    return Image.fromarray(codes).quantize(64, method=Image.Quantize.MEDIANCUT, dither=0)


# 3x5 bitmap glyphs: A-H for columns, 1-8 for rows
GLYPHS = {
    "A": ("010", "101", "111", "101", "101"),
    "B": ("110", "101", "110", "101", "110"),
    "C": ("011", "100", "100", "100", "011"),
    "D": ("110", "101", "101", "101", "110"),
    "E": ("111", "100", "110", "100", "111"),
    "F": ("111", "100", "110", "100", "100"),
    "G": ("011", "100", "101", "101", "011"),
    "H": ("101", "101", "111", "101", "101"),
    "1": ("010", "110", "010", "010", "111"),
    "2": ("110", "001", "010", "100", "111"),
    "3": ("110", "001", "010", "001", "110"),
    "4": ("101", "101", "111", "001", "001"),
    "5": ("111", "100", "110", "001", "110"),
    "6": ("011", "100", "110", "101", "010"),
    "7": ("111", "001", "010", "010", "010"),
    "8": ("111", "101", "111", "101", "111"),
}


def draw_text(codes: np.ndarray, text: str, top: int, left: int, colour, scale: int = 1) -> None:
    for index, char in enumerate(text):
        for row, bits in enumerate(GLYPHS[char]):
            for col, bit in enumerate(bits):
                if bit == "1":
                    y = top + row * scale
                    x = left + (index * 4 + col) * scale
                    codes[y : y + scale, x : x + scale] = colour


def make_tiles(size: int = 128, tiles: int = 8) -> Image.Image:
    tile = size // tiles
    codes = np.zeros((size, size, 3), dtype=np.uint8)
    for i in range(tiles):  # along u (columns, left to right)
        for j in range(tiles):  # along v (rows, bottom to top)
            hue = i / tiles
            rgb = 0.5 + 0.5 * np.cos(2.0 * np.pi * (hue + np.array([0.0, 1.0, 2.0]) / 3.0))
            light = 0.45 + 0.5 * j / (tiles - 1)
            if (i + j) % 2:
                light *= 0.8
            top = size - (j + 1) * tile  # v = 0 is the bottom row of the image
            codes[top : top + tile, i * tile : (i + 1) * tile] = np.round(255 * rgb * light)
            label = "ABCDEFGH"[i] + str(j + 1)
            ink = (0, 0, 0) if light * rgb.mean() > 0.4 else (255, 255, 255)
            draw_text(codes, label, top + 5, i * tile + 4, ink)
    codes[::tile, :] = (30, 30, 30)  # grid lines
    codes[:, ::tile] = (30, 30, 30)
    codes[-1, :] = (30, 30, 30)
    codes[:, -1] = (30, 30, 30)
    return Image.fromarray(codes)


def main() -> None:
    for name, image in (("earth.png", make_earth()), ("tiles.png", make_tiles())):
        path = HERE / name
        image.save(path, optimize=True)
        print(f"{path}: {image.width}x{image.height}, {path.stat().st_size} bytes")


if __name__ == "__main__":
    main()
