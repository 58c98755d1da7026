"""A SIGTERM that reaches ``whitted`` while Python shuts down (the command done, its files
closed, the modules being freed) ends nothing early: the process exits with the command's
own status, never by the signal (Python puts back the default action of a signal with a
Python handler for the last part of its shutdown; an ignored one stays ignored)."""

from __future__ import annotations

import subprocess
import sys

# an object freed with the modules, after every exit hook, that sends SIGTERM to its process
SCRIPT = """
import os, signal, sys, time
from whitted.cli import interrupt

class Late:
    def __del__(self):
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(0.05)

interrupt.install_process_handlers()
holder = type(sys)("late_holder")
holder.late = Late()
sys.modules["late_holder"] = holder
sys.exit(int(sys.argv[1]))
"""


def test_a_signal_during_the_interpreter_shutdown_changes_nothing():
    for status in (0, 2):
        done = subprocess.run([sys.executable, "-c", SCRIPT, str(status)],
                              capture_output=True, text=True, timeout=60)
        assert done.returncode == status, (done.returncode, done.stderr)
        assert "Traceback" not in done.stderr
