"""Wavefront MTL material libraries -> whitted :class:`Material` objects.

The mapping (colours in MTL files are linear floats):

========================  =================================================================
``Kd``                    ``color`` (clipped to 0..1)
``Ka``                    ``ambient_color`` when given and not black
``Ks``                    ``ks = max(Ks)``, ``specular_color = Ks / max(Ks)``
``Ns``                    ``shininess`` (clipped to 0..100000)
``Ni``                    ``ior`` when > 0 (clipped to 10)
``d`` / ``Tr``            ``kt = 1 - d`` (``Tr`` is ``1 - d``; ``d`` wins when both are given)
``illum 3``               mirror-like: ``kr = max(Ks)``
``illum 4, 6, 7``         glass-like: ``kt`` from ``1 - d`` or else ``Tf``/``Kt``, ``kr`` from
                          ``Ks``, ``fresnel = true``
``map_Kd``                ``texture = ImageTexture(file=<absolute path>)``; ``-o``, ``-s`` and
                          ``-clamp on`` become its ``offset``, ``scale`` and ``wrap``
========================  =================================================================

Where a surface transmits (``kt > 0``) its diffuse weight is scaled by ``1 - kt``. ``Ke``
(emission) and the other maps are read past silently; a ``map_Kd`` whose image is missing is
a warning and the plain ``Kd`` colour is used. Texture-map options (``-clamp on``, ``-o u v``,
``-bm 1.5``, ...) are recognised wherever they appear on the line, before or after the file
name, so they are never taken for the name.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from ..scene.materials import Material
from ..scene.textures import ImageTexture

# Texture-map options and how many arguments each takes (min, max); the -o/-s/-t triples take
# 1 to 3 numbers.
MAP_OPTIONS: dict[str, tuple[int, int]] = {
    "-blendu": (1, 1), "-blendv": (1, 1), "-bm": (1, 1), "-boost": (1, 1), "-cc": (1, 1),
    "-clamp": (1, 1), "-imfchan": (1, 1), "-mm": (1, 2), "-o": (1, 3), "-s": (1, 3),
    "-t": (1, 3), "-texres": (1, 1), "-type": (1, 1), "-colorspace": (1, 1),
}
_NUMERIC_OPTIONS = {"-o", "-s", "-t", "-mm", "-bm", "-boost", "-texres"}


@dataclass
class TextureMap:
    """A parsed ``map_*`` statement: the file name and its options."""

    file: str
    options: dict[str, list[str]] = field(default_factory=dict)


@dataclass
class MtlRecord:
    """The statements of one ``newmtl`` block, as read (before conversion)."""

    name: str
    line: int
    colours: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    scalars: dict[str, float] = field(default_factory=dict)
    illum: int | None = None
    diffuse_map: TextureMap | None = None
    diffuse_map_line: int = 0


def decode_text(data: bytes) -> str:
    """Text of a small text file: UTF-16/UTF-8 by BOM, else UTF-8, else Latin-1 (never fails)."""
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        try:
            return data.decode("utf-16")
        except UnicodeDecodeError:
            pass
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def strip_comment(text: str) -> str:
    """The text before a ``#`` that starts the line or follows a blank."""
    for k, char in enumerate(text):
        if char == "#" and (k == 0 or text[k - 1] in " \t"):
            return text[:k]
    return text


def split_escaped(text: str) -> list[str]:
    """Split at blanks, keeping backslash-escaped blanks (``my\\ file.mtl``) inside names."""
    parts: list[str] = []
    current: list[str] = []
    k = 0
    while k < len(text):
        char = text[k]
        if char == "\\" and k + 1 < len(text) and text[k + 1] in " \t":
            current.append(text[k + 1])
            k += 2
            continue
        if char in " \t":
            if current:
                parts.append("".join(current))
                current = []
        else:
            current.append(char)
        k += 1
    if current:
        parts.append("".join(current))
    return parts


def _is_number(token: str) -> bool:
    try:
        return math.isfinite(float(token))
    except ValueError:
        return False


def parse_texture_map(arguments: str) -> TextureMap | None:
    """The file name and options of a ``map_*`` line's arguments (None when no name)."""
    tokens = split_escaped(arguments)
    options: dict[str, list[str]] = {}
    name_parts: list[str] = []
    k = 0
    while k < len(tokens):
        token = tokens[k]
        option = token.lower()
        if option in MAP_OPTIONS or (token.startswith("-") and len(token) > 1
                                     and not _is_number(token)):
            low, high = MAP_OPTIONS.get(option, (0, 1))
            k += 1
            values: list[str] = []
            while k < len(tokens) and len(values) < high:
                # numeric options take numbers only; the others one word each
                if option in _NUMERIC_OPTIONS or option not in MAP_OPTIONS:
                    if not _is_number(tokens[k]):
                        break
                elif len(values) >= low:
                    break
                values.append(tokens[k])
                k += 1
            options[option] = values
            continue
        name_parts.append(token)
        k += 1
    if not name_parts:
        return None
    return TextureMap(file=" ".join(name_parts), options=options)


def parse_mtl(text: str, source: str, warnings: list[str]) -> dict[str, MtlRecord]:
    """The materials of an MTL file by (trimmed) name; problems are appended to warnings."""
    records: dict[str, MtlRecord] = {}
    current: MtlRecord | None = None
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.replace("\x00", "").strip()
        if not line or line.startswith("#"):
            continue
        keyword, _, rest = line.replace("\t", " ").partition(" ")  # "Kd\t1 0 0" too
        keyword = keyword.lower()
        rest = rest.strip()
        if keyword == "newmtl":
            name = rest.strip()
            current = MtlRecord(name=name, line=number)
            records[name] = current
            continue
        if current is None:
            continue
        if keyword in ("kd", "ka", "ks", "tf", "kt"):
            values = strip_comment(rest).split()
            if values and values[0].lower() in ("spectral", "xyz"):
                warnings.append(f"{source}:{number}: {keyword.capitalize()} {values[0]} colours "
                                "are not supported (ignored)")
                continue
            try:
                numbers = [float(v) for v in values[:3]]
            except ValueError:
                numbers = []
            if not numbers or not all(math.isfinite(v) for v in numbers):
                warnings.append(f"{source}:{number}: bad colour {rest!r} (ignored)")
                continue
            while len(numbers) < 3:
                numbers.append(numbers[0])
            current.colours[keyword] = (numbers[0], numbers[1], numbers[2])
        elif keyword in ("ns", "ni", "d", "tr"):
            values = strip_comment(rest).split()
            if values and values[0] == "-halo":
                values = values[1:]
            try:
                value = float(values[0])
            except (ValueError, IndexError):
                value = math.nan
            if not math.isfinite(value):
                warnings.append(f"{source}:{number}: bad number {rest!r} (ignored)")
                continue
            current.scalars[keyword] = value
        elif keyword == "illum":
            values = strip_comment(rest).split()
            try:
                current.illum = int(float(values[0]))
            except (ValueError, IndexError, OverflowError):
                warnings.append(f"{source}:{number}: bad illum {rest!r} (ignored)")
        elif keyword == "map_kd":
            texture_map = parse_texture_map(strip_comment(rest))
            if texture_map is None:
                warnings.append(f"{source}:{number}: map_Kd without a file name (ignored)")
                continue
            current.diffuse_map = texture_map
            current.diffuse_map_line = number
        # Ke, the other maps, PBR extensions, ...: not used by the renderer
    return records


def find_texture(name: str, folder: Path) -> Path | None:
    """The image file a map names, relative to the MTL's folder (Windows separators allowed)."""
    candidates = [name, name.replace("\\", "/")]
    for candidate in candidates:
        path = Path(candidate)
        if not path.is_absolute():
            path = folder / path
        if path.is_file():
            return path.resolve()
    base = Path(name.replace("\\", "/")).name
    if base and (folder / base).is_file():
        return (folder / base).resolve()
    return None


def _clip01(values: tuple[float, float, float]) -> tuple[float, float, float]:
    r, g, b = (min(max(v, 0.0), 1.0) for v in values)
    return (r, g, b)


def _pair(values: list[str], default: float) -> tuple[float, float] | None:
    try:
        numbers = [float(v) for v in values]
    except ValueError:
        return None
    if not numbers or not all(math.isfinite(v) for v in numbers):
        return None
    return (numbers[0], numbers[1] if len(numbers) > 1 else default)


def _image_texture(
    texture_map: TextureMap, path: Path, source: str, line: int, warnings: list[str]
) -> ImageTexture:
    fields: dict[str, object] = {"file": str(path)}
    offset = texture_map.options.get("-o")
    if offset is not None:
        pair = _pair(offset, 0.0)
        if pair is None:
            warnings.append(f"{source}:{line}: bad -o values {offset} (ignored)")
        else:
            fields["offset"] = pair
    scale = texture_map.options.get("-s")
    if scale is not None:
        pair = _pair(scale, 1.0)
        if pair is None:
            warnings.append(f"{source}:{line}: bad -s values {scale} (ignored)")
        else:
            fields["scale"] = pair
    clamp = texture_map.options.get("-clamp")
    if clamp:
        fields["wrap"] = "clamp" if clamp[0].lower() == "on" else "repeat"
    return ImageTexture.model_validate(fields)


def to_material(
    record: MtlRecord, folder: Path, source: str, warnings: list[str], textures: list[str]
) -> Material:
    """The whitted material for an MTL record (texture paths are appended to textures)."""
    fields: dict[str, object] = {}
    colours = record.colours
    scalars = record.scalars
    if "kd" in colours:
        fields["color"] = _clip01(colours["kd"])
    if "ka" in colours and max(colours["ka"]) > 0.0:
        fields["ambient_color"] = _clip01(colours["ka"])
    specular = max(colours["ks"]) if "ks" in colours else 0.0
    if specular > 0.0:
        ks = colours["ks"]
        fields["ks"] = min(specular, 1.0)
        fields["specular_color"] = _clip01((ks[0] / specular, ks[1] / specular, ks[2] / specular))
    if "ns" in scalars:
        fields["shininess"] = min(max(scalars["ns"], 0.0), 100000.0)
    if scalars.get("ni", 0.0) > 0.0:
        fields["ior"] = min(scalars["ni"], 10.0)
    if "d" in scalars:
        kt = 1.0 - min(max(scalars["d"], 0.0), 1.0)
    elif "tr" in scalars:
        kt = min(max(scalars["tr"], 0.0), 1.0)
    else:
        kt = 0.0
    if record.illum == 3:
        fields["kr"] = min(max(specular, 0.0), 1.0)
    elif record.illum in (4, 6, 7):
        if kt == 0.0:
            filter_colour = colours.get("tf") or colours.get("kt")
            if filter_colour is not None:
                kt = min(max(max(filter_colour), 0.0), 1.0)
        fields["kr"] = min(max(specular, 0.0), 1.0)
        fields["fresnel"] = True
    if kt > 0.0:
        fields["kt"] = kt
        fields["kd"] = Material.model_fields["kd"].default * (1.0 - kt)
    if record.diffuse_map is not None:
        path = find_texture(record.diffuse_map.file, folder)
        if path is None:
            warnings.append(
                f"{source}:{record.diffuse_map_line}: texture image "
                f"'{record.diffuse_map.file}' not found (material '{record.name}' uses its plain "
                "Kd colour)"
            )
        else:
            fields["texture"] = _image_texture(
                record.diffuse_map, path, source, record.diffuse_map_line, warnings
            )
            if str(path) not in textures:
                textures.append(str(path))
    return Material.model_validate(fields)


def read_mtl_file(path: Path, warnings: list[str]) -> dict[str, MtlRecord] | None:
    """The records of an MTL file, or None when it cannot be read."""
    from ..errors import SceneError
    from ..files import read_limited

    try:
        data = read_limited(path, MAX_MTL_BYTES, "material library")
    except SceneError as error:
        warnings.append(str(error))
        return None
    return parse_mtl(decode_text(data), os.fspath(path), warnings)


#: Largest MTL file read (material libraries are small text files).
MAX_MTL_BYTES = 64 << 20
