"""``whitted bench --startup``: where the time of one whole ``whitted render`` process goes.

Each run starts ``python -m whitted render SCENE -q`` as a user would, with
``WHITTED_STARTUP_MARKS`` naming a file: the process notes its moments there (whitted/marks.py)
on the system-wide monotonic clock, and the job's own figures, and this process times the
launch and the exit from outside. The budget, each phase the median of the runs:

- **interpreter**: from the launch to whitted's first line (Python's start, site packages);
- **imports**: to the command's first line (whitted, typer, the command modules; the command
  line parsed), and Numba's import wherever the first kernel needs it;
- **scene**: the scene file read and validated, the output checks, the scene compiled to
  arrays and BVHs (``build``);
- **kernels**: the kernels loaded from the cache (or compiled: the first run);
- **render**: the tiles (and the photons of a scene with caustics);
- **other work**: the rest of the job (its thread, the render parameters, the framebuffer);
- **encoding**: the image encoded and written;
- **exit**: from the file written to the process gone.

With ``--compare povray`` POV-Ray renders the same scene (exported once) between whitted's
runs, and the whole processes are compared side by side.
"""

from __future__ import annotations

import json
import os
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import WhittedError
from ..machine import cpu_name
from ..marks import ENV

PHASES = ("interpreter", "imports", "scene", "kernels", "render", "other work", "encoding",
          "exit")


class StartupError(WhittedError):
    """A run of the budget failed (one line)."""


@dataclass
class StartupBudget:
    scene: str
    runs: list[dict[str, float]] = field(default_factory=list)
    povray_wall: list[float] = field(default_factory=list)

    def median(self, phase: str) -> float:
        return statistics.median(run[phase] for run in self.runs)

    @property
    def whole(self) -> float:
        return statistics.median(run["whole process"] for run in self.runs)

    def rows(self) -> list[tuple[str, float, float]]:
        """(phase, median seconds, share of the whole process's median)."""
        whole = self.whole
        rows = [(phase, self.median(phase), self.median(phase) / whole if whole else 0.0)
                for phase in PHASES]
        rows.append(("whole process", whole, 1.0))
        return rows

    def as_dict(self) -> dict:
        data = {"scene": self.scene, "cpu": cpu_name(), "runs": self.runs,
                "median": {phase: seconds for phase, seconds, _ in self.rows()}}
        if self.povray_wall:
            pov = statistics.median(self.povray_wall)
            data["povray_wall_s"] = pov
            data["ratio_wall"] = self.whole / pov if pov > 0 else float("inf")
        return data


def phases(marks: dict[str, float], launched: float, ended: float) -> dict[str, float]:
    """The budget of one run from its marks (whitted/marks.py) and the launch and end times
    measured outside it (``time.monotonic()``)."""
    needed = ("interpreter", "command", "job", "rendered", "written", "build:seconds",
              "kernels:seconds", "render:seconds")
    missing = [name for name in needed if name not in marks]
    if missing:
        raise StartupError(f"the render process noted no {', '.join(missing)}")
    build, kernels, render = (marks["build:seconds"], marks["kernels:seconds"],
                              marks["render:seconds"])
    job = marks["rendered"] - marks["job"]
    scene = marks["job"] - marks["command"]
    other = max(0.0, job - build - kernels - render)
    # Numba's import, wherever it fell (the first kernel a scene needs), is an import
    numba = 0.0
    if "numba:start" in marks and "numba:end" in marks:
        numba = marks["numba:end"] - marks["numba:start"]
        if marks["numba:start"] < marks["job"]:
            scene -= numba
        else:  # in the job, before its first kernel: not in the kernels' own figure
            taken = min(other, numba)
            other -= taken
            kernels -= numba - taken
    return {
        "interpreter": marks["interpreter"] - launched,
        "imports": marks["command"] - marks["interpreter"] + numba,
        "scene": scene + build,
        "kernels": kernels,
        "render": render,
        "other work": other,
        "encoding": marks["written"] - marks["rendered"],
        "exit": ended - marks["written"],
        "whole process": ended - launched,
    }




def read_marks(path: Path) -> dict[str, float]:
    found: dict[str, float] = {}
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError:
        return found
    for line in lines:
        entry = json.loads(line)
        found[entry["name"]] = float(entry["value"])
    return found


def run_once(scene_file: Path, folder: Path, threads: int | None, index: int) -> dict:
    """One ``whitted render`` process, timed from outside and by its own marks."""
    marks_file = folder / f"marks-{index}.jsonl"
    command = [sys.executable, "-m", "whitted", "render", str(scene_file), "-q",
               "-o", str(folder / "whitted.png")]
    if threads is not None:
        command += ["--threads", str(threads)]
    env = dict(os.environ, **{ENV: str(marks_file)})
    import subprocess

    launched = time.monotonic()
    result = subprocess.run(command, env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    ended = time.monotonic()
    if result.returncode != 0:
        tail = " | ".join(result.stderr.strip().splitlines()[-2:])
        raise StartupError(f"whitted render {scene_file} failed (exit {result.returncode}): "
                           f"{tail}")
    return phases(read_marks(marks_file), launched, ended)


def scene_file_of(name: str) -> Path:
    """A benchmark scene's file (``seed000``) or a scene file's path."""
    from .scenes import SCENES, benchmarks_dir

    if name in SCENES:
        return benchmarks_dir() / SCENES[name].file
    path = Path(name)
    if not path.is_file():
        raise StartupError(f"--startup: {name}: neither a benchmark scene nor a scene file")
    return path


def startup_budget(name: str, runs: int = 5, threads: int | None = None,
                   povray: bool = False, warm_runs: int = 1,
                   log=lambda line: None) -> StartupBudget:
    """The budget of ``whitted render`` on scene ``name`` (median of ``runs`` runs, after
    ``warm_runs`` untimed ones that fill the kernel cache), beside POV-Ray when ``povray``."""
    scene_file = scene_file_of(name)
    budget = StartupBudget(name)
    with tempfile.TemporaryDirectory(prefix="whitted-startup-") as tmp:
        folder = Path(tmp)
        pov_once = _povray_once(scene_file, folder, threads) if povray else None
        for index in range(warm_runs):
            log(f"  warming the kernel cache ({name})")
            run_once(scene_file, folder, threads, -1 - index)
            if pov_once is not None:
                pov_once()
        for index in range(runs):
            budget.runs.append(run_once(scene_file, folder, threads, index))
            if pov_once is not None:
                budget.povray_wall.append(pov_once())
            log(f"  run {index + 1}/{runs}: {budget.runs[-1]['whole process']:.3f} s")
    return budget


def _povray_once(scene_file: Path, folder: Path, threads: int | None):
    from ..export.pov import export_pov
    from ..render.api import available_threads
    from ..scene import load_scene
    from .povray import PovrayError, run_povray

    scene = load_scene(scene_file)
    pov_file = folder / "scene.pov"
    export_pov(scene, pov_file, source=str(scene_file))
    count = threads or scene.render.threads or available_threads()

    def once() -> float:
        try:
            return run_povray(pov_file, folder / "povray.png", scene.render.width,
                              scene.render.height, count,
                              scene.render.transfer == "linear").wall_s
        except PovrayError as exc:
            raise StartupError(str(exc)) from None

    return once


def budget_table(budget: StartupBudget):
    """The budget as a rich table."""
    from rich.table import Table

    table = Table(title=f"whitted render {budget.scene}: the whole process "
                        f"(median of {len(budget.runs)})")
    table.add_column("phase")
    table.add_column("seconds", justify="right")
    table.add_column("share", justify="right")
    for phase, seconds, share in budget.rows():
        table.add_row(phase, f"{seconds:.3f}", f"{100 * share:.0f} %")
    data = budget.as_dict()
    if "povray_wall_s" in data:
        table.add_row("POV-Ray, whole process", f"{data['povray_wall_s']:.3f}", "")
        table.add_row("ratio (whitted / POV-Ray)", f"{data['ratio_wall']:.2f}", "")
    return table
