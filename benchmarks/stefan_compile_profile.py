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
import collections
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from compile_profile import compile_times, cpu_seconds, llvm_passes  # noqa: E402


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
    rows = compile_times(rec.buffer)
    by_name = collections.defaultdict(list)
    for name, sig, inc, exc in rows:
        by_name[name].append((sig, inc, exc))
    print(f"compiles: {len(rows)} ({len(by_name)} functions); exclusive total "
          f"{sum(r[3] for r in rows):.1f} s; {wall:.1f} s wall, {cpu:.1f} s CPU")
    print(f"\n{'exclusive s':>11} {'inclusive s':>11}  function")
    for name, _sig, inc, exc in sorted(rows, key=lambda r: -r[3])[:args.top]:
        print(f"{exc:11.2f} {inc:11.2f}  {name}")
    dups = {n: v for n, v in by_name.items() if len(v) > 1}
    print(f"\nfunctions compiled for more than one signature: {len(dups)}")
    for name, variants in sorted(dups.items(), key=lambda kv: -sum(v[2] for v in kv[1])):
        print(f"  {name}: {len(variants)} variants, {sum(v[2] for v in variants):.2f} s")
        for sig, _inc, exc in variants:
            print(f"      {exc:6.2f} s  {sig[:160]}")
    llvm_passes(rec.buffer, args.top)


if __name__ == "__main__":
    main()
