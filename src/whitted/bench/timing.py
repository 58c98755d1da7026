"""Timing a child process from outside: wall-clock time and its own peak memory."""

from __future__ import annotations

import os
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path


@dataclass
class ProcessResult:
    returncode: int
    stdout: str
    stderr: str
    wall_s: float  # launch to exit
    peak_mib: float  # the child's peak resident set (its own, from wait4)


def timed_process(command: list[str], cwd: Path | None = None,
                  env: dict[str, str] | None = None) -> ProcessResult:
    """Run ``command`` to the end; its output goes through files so that no pipe can stall it,
    and ``os.wait4`` reaps it to read that one child's resource usage."""
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        start = time.perf_counter()
        proc = subprocess.Popen(command, stdout=out, stderr=err, cwd=cwd, env=env)
        try:
            _, status, usage = os.wait4(proc.pid, 0)
        except BaseException:
            proc.kill()
            proc.wait()
            raise
        wall = time.perf_counter() - start
        proc.returncode = os.waitstatus_to_exitcode(status)  # reaped: tell Popen
        out.seek(0)
        err.seek(0)
        return ProcessResult(
            returncode=proc.returncode,
            stdout=out.read().decode("utf-8", "replace"),
            stderr=err.read().decode("utf-8", "replace"),
            wall_s=wall,
            peak_mib=usage.ru_maxrss / 1024.0,  # Linux reports KiB
        )
