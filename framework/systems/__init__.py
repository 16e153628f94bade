"""The pipeline's stages, one module each, each an esper processor: movement, characters, continuous detection,
broad phase, narrow phase (contacts and their events), response, sleeping and render. Each reads
the step's frame that the stages before it wrote (see :mod:`framework.frame`)."""

from __future__ import annotations

from .broad_phase import BroadPhase
from .ccd import ContinuousDetection
from .character import CharacterStage
from .movement import Movement
from .narrow_phase import NarrowPhase
from .render import Render
from .response import Response
from .sleeping import Sleeping
from .soft_step import SoftStep
from .stage import STAGES, Pipeline, Stage

__all__ = ["BroadPhase", "CharacterStage", "ContinuousDetection", "Movement", "NarrowPhase", "Pipeline", "Render",
           "Response",
           "STAGES", "Sleeping", "SoftStep", "Stage", "pipeline_stages"]

_ORDER: tuple[type[Stage], ...] = (
    Movement, CharacterStage, ContinuousDetection, BroadPhase, NarrowPhase, Response, Sleeping, Render)


def pipeline_stages(pipeline: Pipeline) -> list[Stage]:
    """One instance of every stage, in pipeline order, sharing ``pipeline``, with the soft step
    where it runs (at the response's place: it stands for movement, detection and response when the
    scene's solver is soft)."""
    stages = [cls(pipeline) for cls in _ORDER]
    assert tuple(s.name for s in stages) == STAGES
    at = STAGES.index("response") + 1
    return [*stages[:at], SoftStep(pipeline), *stages[at:]]
