"""The studio: framing a camera on a scene's objects (``whitted.framed``), a turntable film
around them, and a ready-lit scene for a quick look at a model file
(``whitted.model_scene``, what ``whitted render model.obj`` shows)."""

from __future__ import annotations

from .framing import framed, turntable
from .model import MODEL_SUFFIXES, is_model_file, model_scene, studio_lights

__all__ = ["MODEL_SUFFIXES", "framed", "is_model_file", "model_scene", "studio_lights",
           "turntable"]
