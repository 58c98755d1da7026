"""Before Qt starts: can it open a window here? There must be a display (an X11 or Wayland
server), and on Linux Qt's xcb platform needs a few system libraries that a desktop may lack;
without either, Qt aborts the process with a long message of its own. This finds what is
missing (like ``scripts/install-qt-deps.sh --check --desktop``) and says in one line what to
set or install. No Qt import here."""

from __future__ import annotations

import os
import subprocess
import sys

#: shared library -> Debian/Ubuntu package, for Qt 6's xcb platform (a real window)
XCB_LIBRARIES = {
    "libGL.so.1": "libgl1",
    "libEGL.so.1": "libegl1",
    "libxkbcommon.so.0": "libxkbcommon0",
    "libfontconfig.so.1": "libfontconfig1",
    "libdbus-1.so.3": "libdbus-1-3",
    "libX11.so.6": "libx11-6",
    "libX11-xcb.so.1": "libx11-xcb1",
    "libxcb.so.1": "libxcb1",
    "libxcb-cursor.so.0": "libxcb-cursor0",
    "libxcb-icccm.so.4": "libxcb-icccm4",
    "libxcb-keysyms.so.1": "libxcb-keysyms1",
    "libxcb-image.so.0": "libxcb-image0",
    "libxcb-randr.so.0": "libxcb-randr0",
    "libxcb-render-util.so.0": "libxcb-render-util0",
    "libxcb-shape.so.0": "libxcb-shape0",
    "libxcb-xkb.so.1": "libxcb-xkb1",
    "libxkbcommon-x11.so.0": "libxkbcommon-x11-0",
}


def uses_xcb(environ=os.environ, platform: str = sys.platform) -> bool:
    """Whether Qt will try the xcb (X11) platform: Linux, and neither an explicit other
    platform (offscreen, wayland...) nor a Wayland session without an X display."""
    if not platform.startswith("linux"):
        return False
    chosen = environ.get("QT_QPA_PLATFORM", "")
    if chosen:
        return chosen.split(";")[0].split(":")[0] == "xcb"
    return not (environ.get("WAYLAND_DISPLAY") and not environ.get("DISPLAY"))


def library_cache() -> str | None:
    """``ldconfig -p``'s list of the system's shared libraries (None if unavailable)."""
    for exe in ("ldconfig", "/sbin/ldconfig", "/usr/sbin/ldconfig"):
        try:
            return subprocess.run([exe, "-p"], capture_output=True, text=True, timeout=10,
                                  check=False).stdout
        except (OSError, subprocess.SubprocessError):
            continue
    return None


def missing_libraries(cache: str) -> list[str]:
    present = {line.strip().split(" ", 1)[0] for line in cache.splitlines()}
    return [lib for lib in XCB_LIBRARIES if lib not in present]


def no_display(environ=os.environ, platform: str = sys.platform) -> str | None:
    """One line saying what to set when Qt has no display to open a window on (Linux and the
    BSDs: no ``DISPLAY`` for X11, no ``WAYLAND_DISPLAY`` for Wayland), or None. Qt itself
    would abort the process (SIGABRT) with a message of several lines."""
    if platform.startswith(("darwin", "win", "cygwin")):
        return None
    chosen = environ.get("QT_QPA_PLATFORM", "").split(";")[0].split(":")[0]
    if chosen and chosen not in ("xcb", "wayland", "wayland-egl"):
        return None  # offscreen, vnc, eglfs, linuxfb...: no display server needed
    if chosen == "xcb" and environ.get("DISPLAY"):
        return None
    if chosen.startswith("wayland") and environ.get("WAYLAND_DISPLAY"):
        return None
    if not chosen and (environ.get("DISPLAY") or environ.get("WAYLAND_DISPLAY")):
        return None
    return ("the editor needs a display and there is none here (DISPLAY and WAYLAND_DISPLAY "
            "are unset): run it on a desktop, over `ssh -X`, or under a virtual display "
            "(`sudo apt-get install xvfb`, then `xvfb-run whitted gui`)")


def display_problem(environ=os.environ, platform: str = sys.platform,
                    cache: str | None = None) -> str | None:
    """One line saying what to set or install for Qt to open a window here, or None when
    nothing is missing (or it cannot be told)."""
    problem = no_display(environ, platform)
    if problem is not None:
        return problem
    if not uses_xcb(environ, platform):
        return None
    cache = library_cache() if cache is None else cache
    if not cache:
        return None
    missing = missing_libraries(cache)
    if not missing:
        return None
    packages = " ".join(dict.fromkeys(XCB_LIBRARIES[lib] for lib in missing))
    return (f"the editor cannot open a window: Qt's X11 (xcb) platform needs "
            f"{', '.join(missing)}; install them with `sudo apt-get install {packages}` "
            "(or run scripts/install-qt-deps.sh --desktop)")
