"""Pure collision geometry, no ECS: pairwise queries, rays, sweeps and batch kernels.

The public contract (see ``docs/collision.md``): world units, y up, radians counter-clockwise;
touching is not a collision; normals point from A toward B; grazing rays and sweeps miss.
"""

from .collide import collide
from .distance import Distance, distance
from .manifold import manifold
from .ray import raycast
from .results import Contact, Impact, Manifold, ManifoldPoint, RayHit, Vec2
from .sweep import time_of_impact

__all__ = ["Contact", "Distance", "Impact", "Manifold", "ManifoldPoint", "RayHit", "Vec2", "collide", "distance",
           "manifold", "raycast", "time_of_impact"]
