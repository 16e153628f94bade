"""The render stage: hands the scene to its renderer, on the last sub-step of a step."""

from __future__ import annotations

from ..frame import StepFrame
from .stage import Stage

__all__ = ["Render"]


class Render(Stage):
    """Call ``renderer.draw(view)`` (the renderer attached to the scene)."""

    name = "render"
    needs = frozenset({"rendering"})

    def run(self, frame: StepFrame) -> bool:
        renderer = self.pipeline.renderer
        if renderer is None or not frame.render:
            return False
        renderer.draw(self.pipeline.view)
        return True
