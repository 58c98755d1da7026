"""Writing scenes for other renderers (POV-Ray 3.7 scene description language)."""

from .pov import export_pov, scene_to_pov

__all__ = ["export_pov", "scene_to_pov"]
