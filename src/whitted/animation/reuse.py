"""Compiled scenes kept between the frames of a film."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ..scene.scene import Scene


class CompileCache:
    """Compiles the still of each frame."""

    def compile(self, still: Scene) -> tuple[Any, bool]:
        from ..compile.scene import compile_scene

        return compile_scene(still), False
