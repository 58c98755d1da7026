"""One kernel cache for every way whitted is started: two copies of whitted in different
places (a checkout and an installed package, say), with other modification times, share the
per-user cache folder (jit/cache.py, jit/locator.py): a kernel the first compiled, the second
loads without compiling."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "whitted"

PROBE = '''"""A kernel for the cache-sharing test."""
from ..jit import builder


@builder
def twice_plus(x, y):
    return 2 * x + y
'''

RUN = '''
import json, sys
from numba.core import event
import whitted.kernels.probe_kernel as probe
from whitted.jit.cache import prepare

compiled = []

class Seen(event.Listener):
    def on_start(self, ev):
        pass

    def on_end(self, ev):
        compiled.append(1)

event.register("numba:compile", Seen())
value = probe.twice_plus(20, 2)
print(json.dumps({"value": value, "compiled": len(compiled), "folder": prepare().folder}))
'''


def _install(place: Path, mtime: int) -> Path:
    package = place / "whitted"
    shutil.copytree(SRC, package, ignore=shutil.ignore_patterns("__pycache__"))
    (package / "kernels" / "probe_kernel.py").write_text(PROBE)
    for root, _, files in os.walk(package):
        for name in files:
            os.utime(os.path.join(root, name), (mtime, mtime))
    return place


def _run(place: Path, cache: Path, with_stderr: bool = False):
    env = {k: v for k, v in os.environ.items()
           if k not in ("NUMBA_CACHE_DIR", "NUMBA_CACHE_LOCATOR_CLASSES", "PYTHONPATH")}
    env.update(PYTHONPATH=str(place), WHITTED_CACHE_DIR=str(cache), WHITTED_COMPILE_HELPER="0")
    result = subprocess.run([sys.executable, "-c", RUN], env=env, capture_output=True,
                            text=True, timeout=600, cwd=place)
    assert result.returncode == 0, result.stderr
    found = json.loads(result.stdout.strip().splitlines()[-1])
    if with_stderr:
        return found, [line for line in result.stderr.splitlines() if line.strip()]
    return found


def test_two_installs_in_different_places_share_one_cache(tmp_path):
    cache = tmp_path / "user-cache"
    first = _run(_install(tmp_path / "checkout", 1_600_000_000), cache)
    second = _run(_install(tmp_path / "site-packages" / "deeper", 1_700_000_000), cache)
    assert first["value"] == second["value"] == 42
    assert first["compiled"] >= 1
    assert second["compiled"] == 0  # loaded from what the other copy compiled
    assert first["folder"] == second["folder"]
    assert Path(first["folder"]).parent == cache
    # filed by the folder inside whitted, not by either install path
    assert (Path(first["folder"]) / "kernels").is_dir()
    names = {p.name for p in Path(first["folder"]).iterdir() if p.is_dir()}
    assert names == {"kernels"}, names


def test_a_damaged_kernel_file_is_found_when_its_kernel_is_looked_up(tmp_path):
    """Each process hashes only the cache files of the kernels it looks up (jit/locator.py):
    a flipped bit in one of them is still found, deleted and compiled again, with one
    warning; the next process loads the new file without a word."""
    cache = tmp_path / "user-cache"
    place = _install(tmp_path / "checkout", 1_600_000_000)
    first = _run(place, cache)
    folder = Path(first["folder"])
    [machine_code] = sorted((folder / "kernels").glob("probe_kernel.twice_plus-*.nbc"))
    data = bytearray(machine_code.read_bytes())
    data[len(data) // 2] ^= 0x10
    machine_code.write_bytes(data)  # in place: the inode the list records
    second, warnings = _run(place, cache, with_stderr=True)
    assert second["value"] == 42 and second["compiled"] == 1
    assert warnings == ["warning: 1 damaged kernel cache file in "
                        f"{folder} deleted; compiling it again"]
    third, warnings = _run(place, cache, with_stderr=True)
    assert third["compiled"] == 0 and warnings == []
