"""Measures the editor (not a test: run it by hand, offscreen or on a display):

    QT_QPA_PLATFORM=offscreen .venv/bin/python tests/gui_measure.py

- edit -> updated preview on the default scene: median of 10 colour edits, from the edit to
  the preview frame reaching the viewport;
- time to first pixels of a full render (Render -> the first tiles in the viewport);
- event-loop lateness while rendering: a 10 ms QTimer measures how late it fires.
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QSettings, QTimer  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

import whitted  # noqa: E402
from whitted.gui.main_window import MainWindow  # noqa: E402


def main(app: QApplication) -> None:
    folder = Path(tempfile.mkdtemp())
    window = MainWindow(whitted.default_scene(), None, autosave_folder=folder,
                        settings=QSettings(str(folder / "s.ini"), QSettings.Format.IniFormat))
    window.ask_unsaved = lambda: "discard"
    window.show()
    frames: list[tuple[float, str]] = []
    window.controller.frame.connect(lambda image, kind: frames.append((time.perf_counter(),
                                                                       kind)))

    def wait(predicate, timeout=300.0) -> None:
        end = time.perf_counter() + timeout
        while not predicate():
            if time.perf_counter() > end:
                raise TimeoutError
            app.processEvents()
            time.sleep(0.001)

    t0 = time.perf_counter()
    wait(lambda: window.controller.previews_done > 0)
    print(f"first preview after start: {time.perf_counter() - t0:.2f} s (kernels loaded/compiled)")
    for _ in range(3):  # let the preview size settle
        n = window.controller.previews_done
        window.select(("objects", 1))
        window.properties.row("material", "color").editor.choose("#10ff10")
        window.properties.row("material", "color").editor.choose("#ff1010")
        wait(lambda n=n: window.controller.previews_done > n)

    latencies = []
    for i in range(10):
        n = window.controller.previews_done
        frames.clear()
        colour = "#%02x40c0" % (20 * i + 30)
        start = time.perf_counter()
        window.properties.row("material", "color").editor.choose(colour)
        wait(lambda n=n: window.controller.previews_done > n)
        stamp = next(t for t, kind in frames if kind == "preview")
        latencies.append(stamp - start)
    prev = window.controller.last_preview
    print(f"edit -> preview ({prev.width}x{prev.height}, depth 2): median "
          f"{statistics.median(latencies) * 1000:.0f} ms, max {max(latencies) * 1000:.0f} ms "
          f"over {len(latencies)} edits")

    # a full render that lasts a few seconds: the default scene at 4 samples per pixel, twice
    # (the first in a process may still load a kernel variant the previews did not need)
    window.controller.preview_enabled = False
    scene = window.doc.scene.with_settings(samples=4)
    window.doc.apply(scene, "more samples")
    for attempt in ("first", "second"):
        lateness: list[float] = []
        timer = QTimer()
        timer.setInterval(10)
        last = [time.perf_counter()]

        def tick(lateness=lateness, last=last) -> None:
            now = time.perf_counter()
            lateness.append(now - last[0] - 0.010)
            last[0] = now

        frames.clear()
        start = time.perf_counter()
        window.start_render()
        last[0] = time.perf_counter()
        timer.timeout.connect(tick)
        timer.start()
        wait(lambda: not window.controller.rendering)
        timer.stop()
        total = time.perf_counter() - start
        first = next(t for t, kind in frames if kind == "render") - start
        stats = window.controller.last_image.meta["stats"]
        print(f"{attempt} full render {stats.width}x{stats.height}, {stats.samples} spp, "
              f"{stats.threads} threads: first pixels after {first * 1000:.0f} ms, done in "
              f"{total:.2f} s")
        print(f"  event loop during it: {len(lateness)} ticks of 10 ms, lateness median "
              f"{statistics.median(lateness) * 1000:.1f} ms, 99th percentile "
              f"{sorted(lateness)[int(0.99 * len(lateness))] * 1000:.1f} ms, "
              f"max {max(lateness) * 1000:.1f} ms")
    window.doc.undo_stack.setClean()
    window.close()


if __name__ == "__main__":
    application = QApplication(sys.argv[:1])  # outlives every widget of main()
    main(application)
