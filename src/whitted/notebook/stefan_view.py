"""``whitted.run_stefan``: a Stefan run from Python or a notebook, with its progress shown
(in a notebook) and its results returned as :class:`~whitted.stefan.results.StefanResults`,
which plot inline (melt fraction, thinnest shell, heat budget against time)."""

from __future__ import annotations

import os
import tempfile
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .detect import live_view

if TYPE_CHECKING:
    from ..stefan.case import Case
    from ..stefan.results import StefanResults

__all__ = ["run_stefan"]


def _merge(base: dict, changes: Mapping[str, Any]) -> dict:
    out = dict(base)
    for key, value in changes.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = value
    return out


def _case(case: Case | str | os.PathLike[str] | Mapping, changes: Mapping[str, Any]):
    """(the case, the text written as the run's case.toml, the case file read or None)."""
    import tomlkit

    from ..stefan.case import Case, CaseError, case_from_dict, load_case

    path = None
    if isinstance(case, str | os.PathLike):
        path = Path(case)
        loaded = load_case(path)  # one-line CaseError for a missing or bad file
        if not changes:
            return loaded, path.read_text(encoding="utf-8"), path
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    elif isinstance(case, Case):
        data = case.model_dump(mode="json", exclude_none=True)
    elif isinstance(case, Mapping):
        data = dict(case)
    else:
        raise CaseError(f"a case is a Case, a case file or a dict, got {type(case).__name__}")
    data = _merge(data, changes)
    text = tomlkit.dumps(data)
    return case_from_dict(data, file=None if path is None else str(path), text=text), text, path


def run_stefan(
    case: Case | str | os.PathLike[str] | Mapping,
    out: str | os.PathLike[str] | None = None,
    *,
    resume: bool = True,
    allow_large: bool = False,
    live: bool | None = None,
    **changes: Any,
) -> StefanResults:
    """Solve a Stefan case (a :class:`~whitted.stefan.Case`, a case file or a dict) into the
    folder ``out`` (None: a folder named after the case file in a new temporary folder), as
    ``whitted stefan run`` does (resumes when ``resume``), and return its results, which plot
    inline in a notebook (titled with the folder's name). Keyword
    ``changes`` replace tables of the case: ``grid={"cells": 16}``, ``time={"end": 600}``.
    In a notebook a bar shows the simulated time; the interrupt stops at the next step and
    keeps every saved time (run it again to resume). One-line :class:`CaseError` for a case
    that cannot be used, before any work."""
    from ..render.api import CancelToken
    from ..stefan.results import load_results
    from ..stefan.run import run_case

    the_case, text, path = _case(case, changes)
    if out is None:  # named after the case: the folder's name titles the results' plot
        out = Path(tempfile.mkdtemp(prefix="whitted-stefan-")) / (
            path.stem if path is not None else "stefan")
    out = Path(out)
    cancel = CancelToken()
    live = live_view(live)
    view = None
    progress = None
    if live:
        from IPython.display import display

        from .task import TaskView

        view = TaskView("melting")
        end = the_case.time.end

        def progress(fraction: float, t: float, what: str) -> None:
            view.fraction = fraction
            view.text = f"t = {t:.0f} s of {end:.0f} s" + (" (saved)" if what == "saved" else "")

        display(view.widget)

    def work():
        return run_case(the_case, text, out, resume=resume, progress=progress,
                        should_stop=lambda: cancel.cancelled, allow_large=allow_large,
                        case_path=path)

    from .task import run_in_view

    result = run_in_view(work, view, cancel)
    results = load_results(out)
    results.run = result
    if view is not None:
        if result is None or result.interrupted:
            view.end(f"stopped at t = {results.time_s[-1]:.0f} s: every saved time is in "
                     f"{out} (run it again to resume)", "warning")
        else:
            view.end(repr(results).strip("<>"), "success", 1.0)
    return results
