"""The base of the pipeline's stages, and what they share.

A stage is an :class:`esper.Processor` registered in the scene's esper world at a fixed priority,
so ``esper.process(dt)`` (which the scene calls once per sub-step) runs the stages in pipeline
order, with any processor a game adds placed before or after any of them. Each stage declares the
effects it needs; it runs only when the scene has them all. It reads and writes the frame of the
step under way (:class:`~framework.frame.StepFrame`) and the bodies, and reaches nothing else.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, ClassVar

import esper

from ..bodies import Bodies
from ..frame import StepFrame
from ..validation import InvalidValue

__all__ = ["PRIORITY", "STAGES", "Pipeline", "Stage", "SystemProcessor", "place", "unregister"]

STAGES = ("movement", "character", "ccd", "broad_phase", "narrow_phase", "response", "sleeping", "render")
# esper runs higher priorities first; a game's processor goes 300 above ("before") or below
# ("after") a stage, so "after A" comes before "before B" for consecutive stages A and B. A
# processor added with esper's default priority 0 runs after the whole pipeline.
PRIORITY = {name: 1000 * (len(STAGES) - i) for i, name in enumerate(STAGES)}


@dataclass(eq=False)
class Pipeline:
    """What the stages share: the bodies, the scene's settings and the frame of the step under way.

    ``effects``: what the scene simulates; ``gravity``: acceleration of dynamic bodies (used only
    with the gravity effect); ``response_iterations``: passes of the response; ``renderer``: the
    render stage's renderer; ``view``: what the renderer is handed to draw (the scene);
    ``wanted_pairs``: without the events effect, which pairs some handler reads (rows a, rows b ->
    mask; see :meth:`framework.events.CollisionHandlers.wanted`); ``solver``: ``"exact"`` (the
    stages one by one) or ``"soft"`` (movement, detection and response as one compiled call, see
    :mod:`framework.systems.soft_step`); ``length_unit``: world units per metre, which scales the
    soft solver's tolerances."""

    bodies: Bodies
    effects: frozenset[str]
    gravity: tuple[float, float] = (0.0, 0.0)
    response_iterations: int = 4
    renderer: Any = None
    view: Any = None
    wanted_pairs: Any = None
    frame: StepFrame = field(default_factory=StepFrame)
    solver: str = "exact"
    length_unit: float = 1.0

    def active_gravity(self) -> tuple[float, float]:
        """Gravity as the stages apply it: none unless the scene declared the gravity effect."""
        return self.gravity if "gravity" in self.effects else (0.0, 0.0)


class Stage(esper.Processor):
    """One stage of the pipeline: ``run(frame)`` does its work and returns whether it did any (a
    stage that ran is listed in ``counters["systems"]`` and timed in ``stage_ms``)."""

    name: ClassVar[str]
    needs: ClassVar[frozenset[str]] = frozenset()
    solver: ClassVar[str | None] = None  # the solver mode the stage belongs to (None: both)

    def __init__(self, pipeline: Pipeline) -> None:
        self.pipeline = pipeline
        self.bodies = pipeline.bodies
        self.priority = PRIORITY.get(self.name, 0)
        self.wanted_for: tuple[Any, Any, bool] = (None, None, False)  # (effects, solver, wanted()) last seen

    def wanted(self) -> bool:
        """Whether the scene's effects (and its solver mode) call for this stage. (It may depend on
        nothing else: :meth:`process` asks again only when the effects or the solver change.)"""
        return self.needs <= self.pipeline.effects and self.solver in (None, self.pipeline.solver)

    def process(self, dt: float) -> None:  # esper's entry point
        pipe = self.pipeline
        frame = pipe.frame
        effects, solver, wanted = self.wanted_for
        if effects is not pipe.effects or solver is not pipe.solver:  # (most stages of a scene are idle)
            wanted = self.wanted()
            self.wanted_for = (pipe.effects, pipe.solver, wanted)
        if not wanted:
            return
        t0 = time.perf_counter()
        if self.run(frame):
            frame.counters["systems"].append(self.name)
            frame.stage_ms[self.name] = (time.perf_counter() - t0) * 1e3

    def run(self, frame: StepFrame) -> bool:
        raise NotImplementedError


def place(before: str | None, after: str | None) -> tuple[str, int]:
    """``(stage, priority)`` of a game processor placed ``before`` or ``after`` a stage (default:
    after the response); ``ValueError`` for both or an unknown stage."""
    if before is not None and after is not None:
        raise InvalidValue("give either before= or after=, not both")
    stage = after if before is None else before
    stage = "response" if stage is None else stage
    if stage not in STAGES:
        raise InvalidValue(f"unknown stage {stage!r}; stages are {STAGES}")
    return stage, PRIORITY[stage] + (300 if before is not None else -300)


class SystemProcessor(esper.Processor):
    """A plain ``system(scene, dt)`` function as a processor of the scene's world. One placed
    around the render stage runs only when it does (the last sub-step of a step)."""

    def __init__(self, system: Any, scene: Any, stage: str) -> None:
        self.system, self.scene, self.stage = system, scene, stage

    def process(self, dt: float) -> None:
        if self.stage == "render" and not self.scene.step_frame.render:
            return
        self.system(self.scene, dt)


def unregister(processor: esper.Processor) -> None:
    """Take one processor instance out of the current esper world (``esper.remove_processor``
    removes by type, and a scene may hold several processors of one type)."""
    esper._processors.remove(processor)
    if esper._processors_dict.get(type(processor)) is processor:
        del esper._processors_dict[type(processor)]
