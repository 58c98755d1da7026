"""Checks made before a render starts, so that its result can be written when it ends: the
output place is writable, no output is one of the job's inputs, and the memory the image and
its encoder need is there."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterable
from pathlib import Path

from ..errors import OutputError
from ..files import kind_of, same_file
from ..files.memory import memory_room

#: Bytes per pixel held while rendering (the float32 RGB framebuffer).
FRAMEBUFFER_BYTES = 12
#: Bytes per pixel the encoders add on top of the framebuffer (see formats.write_image;
#: measured 4.4 for 8-bit PNG and JPEG at 25 megapixels).
ENCODER_BYTES = {"png": 5, "jpeg": 5, "exr": 12, "pfm": 0, "npy": 0}


def check_output_place(path: str | os.PathLike[str]) -> None:
    """:class:`OutputError` (one line) unless a file can be written at ``path``: its folder
    exists and takes new files, and ``path`` is not a folder, a device or a pipe."""
    target = Path(path)
    name = os.fspath(path)
    try:
        status = os.stat(target)
    except FileNotFoundError:
        status = None
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the name
        raise OutputError(f"{name}: cannot write: "
                          f"{getattr(exc, 'strerror', None) or exc}") from None
    if status is not None:
        kind = kind_of(status.st_mode)
        if kind is not None:
            raise OutputError(f"{name}: is {kind}, not a file that can be written")
    folder = target.parent
    if not folder.exists():
        raise OutputError(f"{name}: the folder {folder} does not exist")
    if not folder.is_dir():
        raise OutputError(f"{name}: {folder} is not a folder")
    try:  # the real test: the atomic writer makes a temporary file right there
        fd, probe = tempfile.mkstemp(prefix=f".{target.name[:64]}.", suffix=".probe", dir=folder)
    except OSError as exc:
        raise OutputError(f"{name}: cannot write in {folder}: {exc.strerror or exc}") from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(probe)
    if len(os.fsencode(target.name)) > 255:
        raise OutputError(f"{name}: file name too long (over 255 bytes)")


def input_files(scene: object, scene_path: str | os.PathLike[str] | None) -> list[Path]:
    """Every file a render of ``scene`` reads that the scene names: the scene file, its models
    and texture images."""
    from ..assets.mesh import load_mesh
    from ..errors import WhittedError
    from ..scene.writing import named_files

    files: list[Path] = []
    if scene_path is not None:
        files.append(Path(scene_path))
    for keys, named in named_files(scene):
        try:
            path = scene.resolve_path(named)  # type: ignore[attr-defined]
        except (OSError, RuntimeError, ValueError):
            continue
        files.append(path)
        if len(keys) >= 3 and keys[-1] == "file" and keys[-3] == "objects":
            # a model's own material libraries and textures (loaded once, cached for the
            # render; a model that cannot be loaded is reported by the render itself)
            try:
                mesh = load_mesh(path)
            except (WhittedError, OSError):
                continue
            files += [Path(f) for f in (*mesh.library_files, *mesh.texture_files)]
    return files


def check_outputs(outputs: Iterable[str | os.PathLike[str]], scene: object = None,
                  scene_path: str | os.PathLike[str] | None = None, *,
                  inputs: Iterable[str | os.PathLike[str]] | None = None) -> None:
    """Every output can be written and none is a file the job reads (:class:`OutputError`):
    ``inputs``, or those of ``scene`` (:func:`input_files`) when not given."""
    if inputs is None:
        inputs = input_files(scene, scene_path) if scene is not None else (
            [Path(scene_path)] if scene_path is not None else [])
    inputs = list(inputs)
    for output in outputs:
        for source in inputs:
            if same_file(output, source):
                raise OutputError(f"{output}: is an input of this job ({source}): "
                                  "choose another output name")
        check_output_place(output)


def available_memory() -> int | None:
    """Bytes of memory this process may still allocate: the machine's free memory or the
    process's own limit (``ulimit -v``, RLIMIT_AS), the tighter; None when unknown."""
    room = memory_room()
    return None if room is None else room.bytes


def memory_need(width: int, height: int, fmt: str) -> int:
    """Bytes a render of ``width`` x ``height`` written as ``fmt`` holds at its peak."""
    return width * height * (FRAMEBUFFER_BYTES + ENCODER_BYTES.get(fmt, 12))


def check_memory(width: int, height: int, fmt: str, bit_depth: int = 8) -> None:
    """:class:`OutputError` before the work starts when the image cannot be held and written."""
    need = memory_need(width, height, fmt)
    room = memory_room()
    if room is not None and need > room.bytes:
        raise OutputError(
            f"a {width}x{height} render to .{fmt} needs about {need / 2**30:.1f} GiB of memory; "
            f"{room.describe()}")
