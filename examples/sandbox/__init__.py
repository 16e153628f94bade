"""A physics sandbox: drag bodies with the mouse, drive a car up a slope (joints, soft solver).

``python -m examples.sandbox`` opens it in a window; ``--headless --demo`` runs a scripted drive and
drag without one. Installed, it is ``framework.examples.sandbox``. See docs/joints.md.
"""

from .controls import DRAG_STRENGTH, drag_to, drive, drive_system, grab, joint_count, release
from .world import CAR, GRAVITY, SLOPE, ZOOM, CarSpec, Sandbox, make_sandbox, slope_height

__all__ = [
    "CAR", "DRAG_STRENGTH", "GRAVITY", "SLOPE", "ZOOM", "CarSpec", "Sandbox", "drag_to", "drive", "drive_system",
    "grab", "joint_count", "make_sandbox", "release", "slope_height",
]
