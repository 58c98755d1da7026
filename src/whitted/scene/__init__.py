"""The scene description: pure, validated data (no rendering code)."""

from .camera import Camera
from .io import load_scene
from .lights import AmbientLight, DirectionalLight, DiskLight, PointLight
from .materials import PRESETS, Material
from .scene import RenderSettings, Scene
from .shapes import CSG, Box, Cone, Cylinder, Disk, Mesh, Plane, Rectangle, Sphere, Torus, Triangle
from .textures import CheckerTexture, GradientTexture, ImageTexture
from .types import AxisAngle, Background, Gradient, Transform
from .writing import save_scene

__all__ = [
    "CSG", "PRESETS", "AmbientLight", "AxisAngle", "Background", "Box", "Camera", "CheckerTexture",
    "Cone", "Cylinder", "DirectionalLight", "Disk", "DiskLight", "Gradient", "GradientTexture",
    "ImageTexture", "Material", "Mesh", "Plane", "PointLight",
    "Rectangle", "RenderSettings", "Scene", "Sphere", "Torus", "Transform", "Triangle",
    "load_scene",
    "save_scene",
]
