"""A 2D game framework on esper, built around a fast, numerically sound collision pipeline.

Importing it (and running scenes without a renderer) never imports pyglet's GL modules.
"""

from typing import TYPE_CHECKING, Any

from .components import Body, Hitbox, MassData, Parts, Transform, Velocity, Visual, body_mass_data
from .shapes import AABB, Capsule, Chain, ChainSegment, Circle, Polygon, Segment, Shape
from .text import Text
from .validation import InvalidValue

if TYPE_CHECKING:  # the names loaded on first use (see __getattr__), as type checkers see them
    from .character import CharacterController
    from .collision import Contact, Impact, RayHit, Vec2, collide
    from .events import CollisionEvent
    from .input import Input
    from .joints import DistanceJoint, MotorJoint, MouseJoint, PrismaticJoint, RevoluteJoint, WeldJoint, WheelJoint
    from .render import Camera, Renderer, run, screenshot
    from .scene import STAGES, Scene, SceneClosed, SceneHit

__all__ = [
    "AABB", "Body", "Camera", "Capsule", "Chain", "ChainSegment", "CharacterController", "Circle", "CollisionEvent",
    "Contact", "DistanceJoint",
    "Hitbox", "Impact", "Input", "InvalidValue", "MassData", "MotorJoint", "MouseJoint", "Parts", "Polygon",
    "PrismaticJoint",
    "RayHit",
    "Renderer", "RevoluteJoint", "Segment",
    "STAGES", "Scene", "SceneClosed", "SceneHit", "Shape", "Text", "Transform", "Vec2", "Velocity", "Visual",
    "WeldJoint", "WheelJoint", "body_mass_data", "collide", "run", "screenshot",
]
__version__ = "0.2.0"

_LAZY = {
    "Contact": "collision", "Impact": "collision", "RayHit": "collision", "Vec2": "collision",
    "collide": "collision", "CollisionEvent": "events", "STAGES": "scene", "Scene": "scene",
    "SceneClosed": "scene", "SceneHit": "scene", "CharacterController": "character", "Input": "input",
    "DistanceJoint": "joints", "MotorJoint": "joints", "MouseJoint": "joints", "PrismaticJoint": "joints",
    "RevoluteJoint": "joints", "WeldJoint": "joints", "WheelJoint": "joints",
    # the render entry points (pyglet loads with them, on first use)
    "Camera": "render", "Renderer": "render", "run": "render", "screenshot": "render",
}


def __getattr__(name: str) -> Any:
    # The scene and the queries load on first use, so `import framework` stays light.
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module 'framework' has no attribute {name!r}")
