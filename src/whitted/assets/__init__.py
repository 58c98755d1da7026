"""Reading model and image files into NumPy data."""

from .images import load_image
from .mesh import MeshData, clear_mesh_cache, load_mesh

__all__ = ["MeshData", "clear_mesh_cache", "load_image", "load_mesh"]
