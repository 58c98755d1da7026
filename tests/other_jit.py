"""Run a test script in a fresh process with the kernels in the other JIT mode (compiled
when this process runs them as plain Python, ``NUMBA_DISABLE_JIT=1``, and the other way
round), and read back the arrays it saved."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
JIT_OFF = os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0")


def in_other_jit_mode(script: str, out: Path) -> dict[str, np.ndarray]:
    """``tests/<script>`` run with the output file ``out`` (an .npz) as its argument."""
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"),
               NUMBA_DISABLE_JIT="0" if JIT_OFF else "1")
    subprocess.run([sys.executable, str(ROOT / "tests" / script), str(out)], env=env,
                   check=True, timeout=600)
    with np.load(out) as other:
        return {k: other[k] for k in other.files}
