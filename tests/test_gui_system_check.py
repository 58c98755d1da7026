"""``whitted gui`` on a Linux desktop without Qt's X11 libraries: one line naming what to
install, before Qt starts; without a display, one line naming what to set."""

from __future__ import annotations

import subprocess
import sys

from whitted.gui.system_check import XCB_LIBRARIES, display_problem, uses_xcb


def cache_without(*missing: str) -> str:
    lines = [f"\t{lib} (libc6,x86-64) => /usr/lib/x86_64-linux-gnu/{lib}"
             for lib in XCB_LIBRARIES if lib not in missing]
    return f"{len(lines)} libs found in cache `/etc/ld.so.cache'\n" + "\n".join(lines)


def test_which_platform_needs_the_check():
    assert uses_xcb({"DISPLAY": ":0"}, "linux")
    assert not uses_xcb({"DISPLAY": ":0", "QT_QPA_PLATFORM": "offscreen"}, "linux")
    assert uses_xcb({"QT_QPA_PLATFORM": "xcb"}, "linux")
    assert not uses_xcb({"WAYLAND_DISPLAY": "wayland-0"}, "linux")
    assert not uses_xcb({"DISPLAY": ":0"}, "darwin")


def test_one_line_names_the_packages():
    env = {"DISPLAY": ":0"}
    assert display_problem(env, "linux", cache_without()) is None
    line = display_problem(env, "linux", cache_without("libxcb-cursor.so.0",
                                                       "libxkbcommon-x11.so.0"))
    assert "\n" not in line
    assert "sudo apt-get install libxcb-cursor0 libxkbcommon-x11-0" in line
    assert "libxcb-cursor.so.0" in line


def test_the_command_stops_before_qt(tmp_path):
    """In a fresh process with the library list emptied of libxcb-cursor: exit 2, one line,
    and Qt never imported."""
    code = (
        "import sys\n"
        "from whitted.gui import system_check as c\n"
        f"c.library_cache = lambda: {cache_without('libxcb-cursor.so.0')!r}\n"
        "from typer.testing import CliRunner\n"
        "from whitted.program import app\n"
        "r = CliRunner().invoke(app, ['gui'])\n"
        "print(repr(r.output)); print(r.exit_code)\n"
        "print(any(m.startswith('PySide6.QtWidgets') for m in sys.modules))\n"
    )
    env = {"DISPLAY": ":99", "PATH": "/usr/bin:/bin"}
    import os

    env.update({k: v for k, v in os.environ.items() if k in ("PYTHONPATH", "WHITTED_CACHE_DIR",
                                                              "HOME")})
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, timeout=120).stdout.splitlines()
    output, status, qt = eval(out[0]), out[1], out[2]  # noqa: S307 - our own repr
    assert status == "2" and qt == "False"
    assert output.count("\n") == 1 and "libxcb-cursor0" in output



def test_no_display_is_one_line():
    from whitted.gui.system_check import no_display

    line = no_display({}, "linux")
    assert line is not None and "\n" not in line and "DISPLAY" in line and "xvfb" in line
    assert display_problem({}, "linux", cache_without()) == line
    assert no_display({"QT_QPA_PLATFORM": "xcb"}, "linux") == line
    assert no_display({"QT_QPA_PLATFORM": "wayland", "DISPLAY": ":0"}, "linux") == line
    assert no_display({"DISPLAY": ":0"}, "linux") is None
    assert no_display({"WAYLAND_DISPLAY": "wayland-0"}, "linux") is None
    assert no_display({"QT_QPA_PLATFORM": "offscreen"}, "linux") is None
    assert no_display({}, "darwin") is None and no_display({}, "win32") is None


def test_the_command_without_a_display_exits_2_before_qt():
    """The real command in a fresh process with no display: exit 2, one line on stderr, no
    Qt abort (SIGABRT, exit 134)."""
    import os

    env = {k: v for k, v in os.environ.items()
           if k not in ("DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM")}
    done = subprocess.run([sys.executable, "-m", "whitted", "gui"], capture_output=True,
                          text=True, env=env, timeout=120)
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and "DISPLAY" in done.stderr
    assert "xvfb" in done.stderr and done.stdout == ""
