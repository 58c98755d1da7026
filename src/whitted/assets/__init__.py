"""Reading model and image files into NumPy data."""

from .images import load_image

__all__ = ["load_image"]
