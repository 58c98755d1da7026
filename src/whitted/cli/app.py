"""The ``whitted`` command line's typer app and what its commands share: the one-line error
of a user mistake (:func:`fail`), the scene argument, ``--set``, and the state one run of the
program keeps (what main() does when the command returns). The commands live in their own
modules (render, info, export, bench, animate, sweep, stefan), which register on :data:`app`;
:mod:`.main` imports them all and is the entry point."""

from __future__ import annotations

import gc
import os
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from ..errors import SceneError, WhittedError, shorten
from .console import Text, err, out

if TYPE_CHECKING:
    import numpy as np
    from pydantic import ValidationError

    from ..scene import Scene

# NumPy, pydantic, rich, the scene models and the renderer are imported inside the commands
# that use them: `whitted --help` and the import of the command line stay far under 0.2 s
# (tests/test_startup.py).

app = typer.Typer(
    add_completion=False,
    no_args_is_help=False,
    help="whitted: a fast Whitted ray tracer. Render scene files (TOML/JSON) to images.",
    pretty_exceptions_enable=False,
)

#: The optional scene-file argument of render, export, animate and sweep.
SceneArgument = Annotated[
    Path | None, typer.Argument(
        metavar="[SCENE]", help="Scene file (.toml, .json), model file (.obj, .ply, .stl, .off, "
        ".glb, .gltf) or example name (glass_cube); default: the built-in scene")
]

EXIT_USER_ERROR = 2
#: set by render: its job's thread was abandoned after an interrupt during the first compile,
#: or the render is local and done; either way main() may end the process at once (main.py)
abandoned: list[bool] = []
ends_at_once: list[bool] = []  # set by a local render: the process may skip the teardown
#: The longest error line printed (a file may hold a huge key or value: it is cut, not echoed).
MESSAGE_LIMIT = 400


def one_line(message: str) -> str:
    """``message`` as one line of at most :data:`MESSAGE_LIMIT` characters."""
    return shorten(" ".join(str(message).split()), MESSAGE_LIMIT)


def fail(message: str) -> typer.Exit:
    """One line on stderr, exit status 2: the way every user mistake ends. The message is
    printed literally (no rich markup, no emoji codes)."""
    err.print(Text.assemble(("error:", "bold red"), " ", one_line(message)), soft_wrap=True)
    return typer.Exit(EXIT_USER_ERROR)


def note(message: str) -> None:
    err.print(Text(one_line(message)), soft_wrap=True)


def _version(value: bool) -> None:
    if value:
        from ..fingerprint import whitted_version

        out.print(f"whitted {whitted_version()}")
        raise typer.Exit()


@app.callback()
def main_options(
    version: Annotated[
        bool, typer.Option("--version", callback=_version, is_eager=True, help="Show the version.")
    ] = False,
) -> None:
    """whitted: a fast Whitted ray tracer."""


def load_scene_argument(scene_path: Path | None, *, width: int | None = None,
                        height: int | None = None,
                        turntable: int | None = None) -> tuple[Scene, str]:
    """The scene the SCENE argument names: a scene file; a model file (OBJ, PLY, STL, OFF,
    glTF), shown on a lit ground by a framed camera (for a picture ``width`` x ``height``);
    an example's short name (``glass_cube``); nothing: the built-in default scene. With
    ``turntable``, a film of that many frames with the camera going once around."""
    from ..files.shipped import example_path
    from ..scene import load_scene
    from ..scene.default import default_scene
    from ..studio import is_model_file, model_scene
    from ..studio import turntable as turntable_of

    if scene_path is None:
        scene, name = default_scene(), "<default scene>"
    elif is_model_file(scene_path):
        size = {k: v for k, v in (("width", width), ("height", height)) if v is not None}
        if "width" not in size and "height" in size:  # keep the default picture's shape
            size["width"] = max(1, round(size["height"] * 4 / 3))
        elif "height" not in size and "width" in size:
            size["height"] = max(1, round(size["width"] * 3 / 4))
        scene = model_scene(scene_path, **size, all_around=turntable is not None)
        name = str(scene_path)
    else:
        example = None if _exists(scene_path) else example_path(str(scene_path))
        if example is None and _bare_name(scene_path):
            raise SceneError(no_such_example(str(scene_path)), file=str(scene_path))
        scene = load_scene(example or scene_path)
        name = str(example or scene_path)
    if turntable is not None:
        scene = turntable_of(scene, turntable)
    return scene, name


def _bare_name(path: Path) -> bool:
    """A name with no folder and no suffix that is not a file here: meant as an example."""
    text = str(path)
    return bool(text) and "/" not in text and os.sep not in text and not path.suffix \
        and not _exists(path)


def no_such_example(name: str) -> str:
    """Neither a file nor an example: the examples' names nearest to ``name``."""
    import difflib

    from ..files.shipped import example_names

    names = list(example_names())
    near = difflib.get_close_matches(name, names, n=3, cutoff=0.6)
    hint = f"did you mean {' or '.join(repr(n) for n in near)}? " if near else ""
    return (f"no such file, nor an example of that name ({hint}`whitted examples` lists "
            f"them)" if names else "no such file")


def check_default_output(output: Path) -> None:
    """An output at a default name (no -o) replaces only a file whitted wrote (a PNG, MP4 or
    GIF marked as whitted's, output/ownership.py): a file of the user's at that name is kept,
    and the command ends in one line."""
    from ..output.ownership import check_replaceable

    try:
        check_replaceable(output, f"replace it with -o {output}, or give another name")
    except WhittedError as exc:
        raise fail(str(exc)) from None


def _exists(path: Path) -> bool:
    try:
        return path.exists()
    except (OSError, ValueError):
        return False


def apply_set_options(scene: Scene, set_values: list[str] | None) -> Scene:
    """The scene with every ``--set PATH=VALUE`` applied (SceneError on a bad one)."""
    if not set_values:
        return scene
    from ..animation.overrides import apply_overrides, parse_assignment

    return apply_overrides(scene, [parse_assignment(text) for text in set_values])


def is_dir(path: Path) -> bool:
    try:
        return path.is_dir()
    except (OSError, ValueError):  # a name too long, a NUL byte: reported by the checks later
        return False


def with_scene_key(exc: WhittedError, scene: Scene, name: str) -> str:
    """A model or texture error from the render, with the scene file and key that name it."""
    from ..scene.writing import named_files

    file = getattr(exc, "file", None)
    if not file and getattr(exc, "where", None) and not name.startswith("<"):
        return f"{name}: {exc}"  # a scene key's problem found while compiling
    if not file or file == name:
        return str(exc)
    for keys, named in named_files(scene):
        try:
            target = scene.resolve_path(named)
        except (OSError, RuntimeError, ValueError):
            continue
        from ..files import same_file

        if same_file(target, file) or str(target) == file:
            where = "".join(f"[{k}]" if isinstance(k, int) else f".{k}" for k in keys).lstrip(".")
            return f"{name}: {where}: {exc}"
    return f"{name}: {exc}"


def save_npy(path: Path, array: np.ndarray) -> None:
    """An AOV beside the picture: written atomically, and recorded as whitted's (an NPY
    holds no mark; output/ownership.py) so that the next render may replace it."""
    import numpy as np

    from ..files import atomic_write
    from ..output.ownership import record_written

    atomic_write(path, lambda tmp: np.save(tmp, array))
    record_written(path)


def check_side_files(paths: list[Path]) -> None:
    """Files a command writes beside its output under derived names (the AOVs,
    ``NAME.depth.npy``): each may replace only a file whitted wrote; anything else there
    ends the command in one line before any work."""
    from ..output.ownership import check_replaceable

    for path in paths:
        try:
            check_replaceable(path, "move it, or give -o another name")
        except WhittedError as exc:
            raise fail(str(exc)) from None


def override_error(exc: ValidationError, given: dict[str, object] | None = None) -> str:
    """One line for command-line values the render settings reject. ``given``: the settings
    the options gave (``{"samples": 4}``); a problem of the settings as a whole (the image
    size, samples beside ``[render.antialias]``) is laid on the options that took part."""
    from ..scene.messages import clean_message as _clean_message

    e = exc.errors()[0]
    named = [k for k, v in (given or {}).items() if v is not None]
    if e["loc"]:
        option = "--" + str(e["loc"][0]).replace("_", "-")
    else:  # a check of the settings as a whole: lay it on the options that were given
        message = _clean_message(e)
        involved = [k for k in named if k in message or
                    (k in ("width", "height") and "megapixels" in message)]
        option = "/".join("--" + k.replace("_", "-") for k in (involved or named)) or "render"
    return f"{option}: {_clean_message(e)}"


def with_options(scene: Scene, **given: object) -> Scene:
    """``scene.with_settings(**given)`` (the render options a command was given; None: not
    given), a value the settings reject ending the command with one line that names the
    option (:func:`override_error`), never the settings' class."""
    from pydantic import ValidationError

    try:
        return scene.with_settings(**given)
    except ValidationError as exc:
        raise fail(override_error(exc, given)) from None


#: whether main() paused the cyclic garbage collector for a render's set-up (a list: set once)
collector_paused: list[bool] = []


def resume_collector() -> None:
    """The cyclic garbage collector, paused by main() while ``whitted render`` imports its
    modules and reads its scene (some 90 collections, 10-15 ms of a 0.57 s render, finding
    next to nothing: modules, classes and the scene all live to the end), back on for the job,
    with everything made so far frozen (``gc.freeze``), so later collections never scan it."""
    if collector_paused:
        collector_paused.clear()
        gc.freeze()
        gc.enable()


