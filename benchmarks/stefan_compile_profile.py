"""Where a cold compile of the Stefan solver's kernels goes (``whitted warm``'s Stefan variant,
``stefan/warm.py``): every compile with its inclusive and exclusive seconds, the functions
compiled for more than one signature, and (``NUMBA_LLVM_PASS_TIMINGS=1``) LLVM's share; the
same tables as ``compile_profile.py``, whose helpers it uses. On an empty cache folder, no
compile helper:

    rm -rf /tmp/sp; WHITTED_CACHE_DIR=/tmp/sp WHITTED_COMPILE_HELPER=0 \\
        PYTHONPATH=src python benchmarks/stefan_compile_profile.py [--top 40]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from compile_profile import (  # noqa: E402
    compile_times,
    cpu_seconds,
    llvm_passes,
    print_compiles,
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--top", type=int, default=40, help="compiles listed")
    args = parser.parse_args()

    from numba.core import event

    from whitted.stefan.warm import warm_stefan_kernels

    cpu0, wall0 = cpu_seconds(), time.perf_counter()
    with event.install_recorder("numba:compile") as rec:
        warm_stefan_kernels()
    cpu, wall = cpu_seconds() - cpu0, time.perf_counter() - wall0
    print_compiles(compile_times(rec.buffer), wall, cpu, args.top, signature_width=160)
    llvm_passes(rec.buffer, args.top)


if __name__ == "__main__":
    main()
