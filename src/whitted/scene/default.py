"""The built-in default scene: the coursework's glass sphere in front of a group of spheres."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from .io import parse_scene_text, scene_from_dict
from .scene import Scene

DEFAULT_SCENE_NAME = "default.toml"


def default_scene_text() -> str:
    return resources.files("whitted.scene").joinpath("data", DEFAULT_SCENE_NAME).read_text()


def default_scene() -> Scene:
    """A fresh copy of the default scene (what ``whitted render`` shows with no scene file);
    its model files are packaged beside it."""
    scene = scene_from_dict(parse_scene_text(default_scene_text(), ".toml", "<default scene>"))
    return scene.with_base_dir(Path(str(resources.files("whitted.scene").joinpath("data"))))
