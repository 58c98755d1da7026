"""Running POV-Ray on an exported scene and reading its own timing and ray statistics.

POV-Ray 3.7 is Debian's ``povray`` package (``apt-get install povray``); it is only needed for
``whitted bench --compare povray``. It renders with anti-aliasing off (``-A``: one ray per
pixel, as whitted with one sample), ``+WT<threads>`` render threads, no display, PNG output.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

from .timing import timed_process


class PovrayError(RuntimeError):
    pass


def povray_executable() -> str | None:
    return shutil.which("povray")


def povray_version() -> str:
    exe = povray_executable()
    if exe is None:
        return "not installed"
    run = subprocess.run([exe, "--version"], capture_output=True, text=True, timeout=30)
    m = re.search(r"POV-Ray\s+(\S+)", run.stdout + run.stderr)
    return m.group(1) if m else "unknown version"


@dataclass
class PovrayRun:
    trace_s: float  # POV-Ray's own "Trace Time" (the render proper)
    parse_s: float  # "Parse Time" (reading the scene file)
    bounding_s: float  # "Bounding Time" (building its bounding hierarchy)
    wall_s: float  # the whole process, measured from outside
    peak_mib: float  # peak resident memory of the process
    rays: dict[str, int] = field(default_factory=dict)


_TIME = r"{}:\s+.*?\(([\d.]+) seconds\)"
_COUNTS = {
    "pixels": r"Pixels:\s+(\d+)",
    "rays": r"\bRays:\s+(\d+)",
    "shadow": r"Shadow Ray Tests:\s+(\d+)",
    "reflected": r"Reflected Rays:\s+(\d+)",
    "refracted": r"Refracted Rays:\s+(\d+)",
    "transmitted": r"Transmitted Rays:\s+(\d+)",
}


def parse_povray_statistics(text: str) -> dict[str, float | int]:
    """Times (seconds) and ray counts from POV-Ray's statistics output (its stderr)."""
    values: dict[str, float | int] = {}
    for key, label in (("trace_s", "Trace Time"), ("parse_s", "Parse Time"),
                       ("bounding_s", "Bounding Time")):
        m = re.search(_TIME.format(label), text)
        values[key] = float(m.group(1)) if m else 0.0
    for key, pattern in _COUNTS.items():
        m = re.search(pattern, text)
        values[key] = int(m.group(1)) if m else 0
    return values


def povray_rays(stats: dict[str, float | int]) -> dict[str, int]:
    """POV-Ray's counts under whitted's four ray kinds: its camera rays are the pixels (one
    each with -A); refraction counts both refracted rays (through an ior) and transmitted ones
    (straight through a filter)."""
    return {
        "primary": int(stats["pixels"]),
        "shadow": int(stats["shadow"]),
        "reflection": int(stats["reflected"]),
        "refraction": int(stats["refracted"]) + int(stats["transmitted"]),
    }


def run_povray(pov_file: Path, output: Path, width: int, height: int, threads: int,
               linear: bool = False) -> PovrayRun:
    exe = povray_executable()
    if exe is None:
        raise PovrayError("povray is not installed (Debian: apt-get install povray)")
    command = [exe, f"+I{pov_file}", f"+O{output}", f"+W{width}", f"+H{height}", "-A", "-D",
               "-P", "+FN", f"+WT{threads}", "-V"]
    if linear:
        command.append("File_Gamma=1.0")
    result = timed_process(command, cwd=pov_file.parent)
    if result.returncode != 0 or "Render Statistics" not in result.stderr:
        tail = " | ".join(result.stderr.strip().splitlines()[-4:])
        raise PovrayError(f"povray failed on {pov_file.name} (exit {result.returncode}): {tail}")
    stats = parse_povray_statistics(result.stderr)
    return PovrayRun(trace_s=float(stats["trace_s"]), parse_s=float(stats["parse_s"]),
                     bounding_s=float(stats["bounding_s"]), wall_s=result.wall_s,
                     peak_mib=result.peak_mib, rays=povray_rays(stats))
