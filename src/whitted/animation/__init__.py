"""Time: animated scenes, per-frame stills, command-line overrides and sweeps.

Pure data and functions (no kernels): an animated :class:`~whitted.Scene` becomes one plain
still per frame (:func:`scene_at_frame`, ``scene.at_frame(k)``), which the render API
renders like any other scene. :func:`render_frame` (in :mod:`whitted.animation.frames`)
renders one frame to a PNG that records what it is a picture of, so a film can resume.
"""

from ..scene.animation import Animation, Track
from ..scene.paths import PathError, get_value, parse_path, resolve_path, set_value
from ..scene.timeline import frame_count, frame_seed, scene_at_frame, sequence_file
from .overrides import apply_overrides, parse_assignment, parse_value, parse_values

__all__ = [
    "Animation", "PathError", "Track", "apply_overrides", "frame_count", "frame_seed",
    "get_value", "parse_assignment", "parse_path", "parse_value", "parse_values", "resolve_path",
    "scene_at_frame", "sequence_file", "set_value",
]
