"""The tiles an interrupted ``whitted render`` kept, for ``--continue``.

When a still is interrupted after some tiles, beside the picture (which shows them) a state
file ``OUTPUT.whitted-tiles`` keeps what finishing it needs: the linear framebuffer, which
tiles are done, and a digest of everything the pixels depend on (the scene with its model
and texture files, the settings, the frame, the region, the tile size and the renderer's
kernels). ``--continue`` renders only the other tiles; as a pixel depends on nothing but the
scene and its place, the result is byte for byte the picture an uninterrupted render makes.
The file is written atomically, removed once the picture is whole, and read defensively: a
damaged one, or one of another scene, is named in one line and never trusted.
"""

from __future__ import annotations

import hashlib
import io
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import WhittedError
from ..files import atomic_write

__all__ = ["TileState", "foreign", "job_digest", "load_state", "remove_state", "save_state",
           "state_path"]

SUFFIX = ".whitted-tiles"
MAGIC = "whitted tile state 1"


def state_path(output: Path) -> Path:
    return output.with_name(output.name + SUFFIX)


def job_digest(scene, frame: int, region, tile_size: int) -> str:
    """What the pixels of this job depend on (animation/frames.py ``frame_digest``: scene,
    files, settings but the thread count, the kernels), with its region and tile size."""
    from ..animation.frames import frame_digest

    h = hashlib.sha256(frame_digest(scene, frame).encode())
    h.update(f"|region={region}|tile={tile_size}".encode())
    return h.hexdigest()


@dataclass
class TileState:
    digest: str
    finished: np.ndarray  # bool per tile
    framebuffer: np.ndarray  # float32 (H, W, 3)


def save_state(path: Path, state: TileState) -> None:
    """Write the state atomically (a temporary file renamed over the old one)."""
    def write(tmp: str) -> None:
        with open(tmp, "wb") as f:
            np.savez(f, magic=np.array(MAGIC), digest=np.array(state.digest),
                     finished=state.finished.astype(bool),
                     framebuffer=state.framebuffer.astype(np.float32))

    atomic_write(path, write)


class StateError(ValueError):
    """A state file that cannot be used (damaged, or not whitted's)."""


def load_state(path: Path, max_bytes: int) -> TileState | None:
    """The state at ``path``; None when there is none. :class:`StateError` (a sentence)
    when it is damaged or not a tile state (its zip members' CRCs are checked)."""
    from ..files import path_problem, read_limited

    if not path.exists() and not path.is_symlink():
        return None
    problem = path_problem(path)
    if problem is not None:
        raise StateError(problem)
    try:
        raw = read_limited(path, max_bytes, "tile state")
        with np.load(io.BytesIO(raw), allow_pickle=False) as data:
            if str(data["magic"]) != MAGIC:
                raise StateError("not a whitted tile state")
            state = TileState(str(data["digest"]), np.asarray(data["finished"], bool),
                              np.asarray(data["framebuffer"], np.float32))
    except StateError:
        raise
    except WhittedError as exc:  # too big, unreadable
        raise StateError(str(exc)) from None
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
        raise StateError(f"damaged ({type(exc).__name__}: {exc})") from None
    except Exception as exc:  # noqa: BLE001 - the zip and npy readers raise many kinds
        raise StateError(f"damaged ({type(exc).__name__})") from None
    if state.framebuffer.ndim != 3 or state.framebuffer.shape[2] != 3 \
            or state.finished.ndim != 1:
        raise StateError("damaged (its arrays are not a framebuffer and tiles)")
    return state


def foreign(path: Path) -> bool:
    """Whether something other than a tile state of whitted's is at ``path`` (a file of
    someone else's that whitted neither writes over nor removes)."""
    if not path.exists() and not path.is_symlink():
        return False
    try:
        with open(path, "rb") as f:
            head = f.read(4096)
    except OSError:
        return True
    # a zip (np.savez, stored) whose first member is the magic string's array (UTF-32)
    return not (head.startswith(b"PK") and b"magic.npy" in head
                and MAGIC.encode("utf-32-le") in head)


def remove_state(path: Path) -> None:
    """Remove the state file, when it is one of whitted's."""
    import contextlib

    if foreign(path):
        return
    with contextlib.suppress(FileNotFoundError, IsADirectoryError, PermissionError):
        path.unlink()
