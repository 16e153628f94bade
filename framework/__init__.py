"""A 2D game framework on esper, built around a fast, numerically sound collision pipeline."""

from .components import Transform
from .shapes import AABB, Circle, Polygon

__all__ = ["AABB", "Circle", "Polygon", "Transform"]
__version__ = "0.1.0"
