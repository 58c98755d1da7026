"""Takes the screenshots of docs/editor.md (not a test; run by hand, best under Xvfb with a
1366x768 screen, the smallest the window is meant for):

    xvfb-run -s "-screen 0 1366x768x24" .venv/bin/python tests/gui_screenshots.py docs/images
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from PIL import Image as PILImage
from PySide6.QtCore import QSettings
from PySide6.QtWidgets import QApplication

import whitted
from whitted.gui.main_window import MainWindow


def save(widget, path: Path, colours: int = 256) -> None:
    """A small PNG of ``widget``: grabbed, then reduced to a palette."""
    raw = path.with_suffix(".raw.png")
    widget.grab().save(str(raw))
    image = PILImage.open(raw).convert("RGB")
    image.quantize(colors=colours, method=PILImage.Quantize.MEDIANCUT, dither=PILImage.Dither.NONE
                   ).save(path, optimize=True)
    raw.unlink()
    print(f"{path}: {image.width}x{image.height}, {path.stat().st_size // 1024} KiB")


def main(app: QApplication, out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    folder = Path(tempfile.mkdtemp())
    scene = whitted.load_scene(Path(__file__).parents[1] / "examples" / "transparent_sphere.toml")
    scene = scene.with_settings(width=640, height=640)
    window = MainWindow(scene, None, autosave_folder=folder,
                        settings=QSettings(str(folder / "s.ini"), QSettings.Format.IniFormat))
    window.ask_unsaved = lambda: "discard"
    window.show()

    def wait(predicate, timeout=300.0, settle=0.3) -> None:
        end = time.perf_counter() + timeout
        while not predicate():
            if time.perf_counter() > end:
                raise TimeoutError
            app.processEvents()
            time.sleep(0.005)
        end = time.perf_counter() + settle
        while time.perf_counter() < end:
            app.processEvents()
            time.sleep(0.005)

    wait(lambda: window.controller.previews_done > 0)
    # 1. a render in progress, the glass sphere selected
    glass = next(i for i, o in enumerate(window.doc.scene.objects) if o.type == "sphere"
                 and o.material == "glass")
    window.select(("objects", glass))
    wait(lambda: window.viewport.outline is not None)
    window.doc.apply(window.doc.scene.with_settings(samples=4), "4 samples")
    wait(lambda: window.viewport.outline is not None and window.controller.preview is None)
    window.start_render()
    wait(lambda: window.controller.full is None or (
        window.controller.full.latest is not None
        and window.controller.full.latest.fraction > 0.4), settle=0.1)
    save(window, out / "editor-rendering.png")
    window.stop_render()
    wait(lambda: not window.controller.rendering)
    # 2. the finished render
    window.start_render()
    wait(lambda: not window.controller.rendering, settle=0.5)
    save(window, out / "editor.png")
    # 3. an invalid value refused at its field
    window.properties.row("radius").editor.line.setText("-1")
    window.properties.row("radius").editor.line.editingFinished.emit()
    wait(lambda: True, settle=0.3)
    save(window.properties, out / "editor-invalid.png", colours=64)
    window.doc.undo_stack.setClean()
    window.close()


if __name__ == "__main__":
    application = QApplication(sys.argv[:1])
    main(application, Path(sys.argv[1] if len(sys.argv) > 1 else "docs/images"))
