"""The scene: one esper world, its bodies and the pipeline that steps them.

``Scene`` is a facade. The pipeline's stages are esper processors in the scene's world
(:mod:`framework.systems`): movement -> continuous detection (only for ``ccd`` bodies) -> broad
phase -> narrow phase (contacts and events) -> response -> sleeping -> render (only with a
renderer attached). Each reads and writes the step's frame (:class:`~framework.frame.StepFrame`).
Game code adds its own systems (``system(scene, dt)``) or esper processors before or after any
stage; collision handlers run after the last stage. Spatial queries live in
:mod:`framework.queries`, handler dispatch in :mod:`framework.events`.
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Callable, Iterable
from contextlib import nullcontext
from numbers import Integral
from typing import Any, cast

import esper
import numpy as np
from numpy.typing import NDArray

from .bodies import Bodies
from .character import CharacterController
from .collision.broad_phase import SpatialHash
from .collision.distance import Distance
from .collision.results import Vec2
from .compile_notice import FIRST_STEP_NOTICE, notice_if_slow
from .components import Hitbox, MassData, Parts, Transform, Velocity, Visual, body_mass_data
from .effects import DEFAULT_EFFECTS, EFFECTS, resolve_effects
from .entities import MissingComponent, check_added_component, spawn_components
from .events import CollisionEvent, CollisionHandlers, PairTracker, StepContacts, pair_parts
from .frame import StepFrame, add_counters
from .geometry import Geometry
from .input import Input
from .joints import Joint, JointBroken, JointReaction, breakable, check_joints, joint_components, remove_joints_of
from .limits import MAX_COORD, check_motion, motion_within
from .queries import ALL_LAYERS, Nearest, NearestMany, PointHits, RayHits, SceneHit, ShapeHit, SpatialQueries
from .rollback import StepRollback
from .shapes import Shape
from .snapshot import Snapshot
from .snapshot import restore as restore_snapshot
from .snapshot import take as take_snapshot
from .store import BodyStore
from .systems import pipeline_stages
from .systems.character import CharacterStage
from .systems.narrow_phase import NarrowPhase
from .systems.sleeping import SLEEP_SPEED, SLEEP_STEPS
from .systems.soft_step import SoftStep
from .systems.stage import STAGES, Pipeline, SystemProcessor, place, unregister
from .validation import InvalidValue, positive, vector2

__all__ = ["DEFAULT_EFFECTS", "EFFECTS", "SLEEP_SPEED", "SLEEP_STEPS", "SOLVERS", "STAGES", "MissingComponent", "Scene",
           "SceneClosed", "SceneHit", "ShapeHit", "resolve_effects"]

_scene_ids = itertools.count(1)
_STEPPED = False  # whether a scene in this process has stepped (the first step compiles: see step())
# Called with each new scene (the test plugin, framework.testing.plugin, follows the scenes a test
# makes, to picture them when it fails).
SCENE_CREATED: list[Callable[[Scene], None]] = []

System = Callable[["Scene", float], Any]
#: The contact solvers a scene can run (see ``Scene(solver=...)``).
SOLVERS = ("exact", "soft")


def _count(name: str, value: Any) -> int:
    """``value`` if it is an int >= 1 (not a bool), else ``ValueError`` naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise InvalidValue(f"Scene {name} must be an int >= 1, got {value!r}")
    return value


class SceneClosed(RuntimeError, ValueError):
    """The scene was closed; it can no longer be stepped or changed."""


class Scene:
    """An isolated world of entities and the systems that step it.

    ``gravity``: acceleration of dynamic bodies (world units per second squared, y up).
    ``cell_size``: the spatial hash's cell; ``None`` chooses it from the hitbox sizes.
    ``response_iterations``: passes of the response over bodies in several contacts (accuracy
    knob: more passes settle stacks and corners better).
    ``substeps``: pipeline runs per :meth:`step` (accuracy knob: smaller steps tunnel and
    sink less, at a proportional cost; the soft solver's joints get ``N`` times as many hertz).
    ``effects``: what the scene simulates (see :data:`EFFECTS`); the default,
    :data:`DEFAULT_EFFECTS`, is a typical game's: movement, gravity, detection, events, response,
    continuous detection and sleeping. Rendering is added when a renderer is attached.
    ``solver``: ``"exact"`` (the default: bodies rest at their exact heights, touching decided
    exactly) or ``"soft"`` (Box2D v3's soft step as one compiled call: several times faster, bodies
    rest within a fraction of the linear slop, see docs/physics.md); settable between steps (see
    :attr:`solver`).
    ``length_unit``: world units per metre; scales the soft solver's tolerances (its linear slop is
    0.005 metres, as Box2D's), so a game in pixels with 32 pixels a metre passes 32.
    """

    def __init__(
        self,
        *,
        gravity: tuple[float, float] = (0.0, 0.0),
        cell_size: float | None = None,
        response_iterations: int = 4,
        substeps: int = 1,
        effects: Iterable[str] | None = None,
        solver: str = "exact",
        length_unit: float = 1.0,
    ) -> None:
        effects = resolve_effects(effects)
        if solver not in SOLVERS:
            raise InvalidValue(f"Scene solver must be one of {SOLVERS}, got {solver!r}")
        length_unit = positive("Scene length_unit", length_unit)
        gravity = vector2("Scene gravity", gravity)
        if cell_size is not None:
            cell_size = positive("Scene cell_size", cell_size)
        iterations = _count("response_iterations", response_iterations)
        self.substeps = _count("substeps", substeps)
        self.world = f"framework.scene.{next(_scene_ids)}"
        self.bodies = Bodies(cell_size)
        self.handlers = CollisionHandlers(self.bodies.rows_of)
        self._pipeline = Pipeline(self.bodies, effects, gravity, iterations, view=self,
                                  frame=StepFrame(counters={}), solver=solver, length_unit=length_unit)
        self._queries = SpatialQueries(self._pipeline)
        self.resources: dict[type, Any] = {Input: Input()}
        self.closed = False
        self.frame = 0
        self.time = 0.0
        #: the joints that broke at the end of the last step (see JointBroken, Joint.break_force)
        self.broken_joints: list[JointBroken] = []
        self._totals: tuple[list[CollisionEvent], dict[str, Any]] | None = None  # a step of several sub-steps
        self._systems: list[SystemProcessor] = []
        self._stepping = False
        self._dispatching = False  # collision handlers are running
        self._pending_despawn: list[int] = []
        self._after_step: list[Callable[[Scene], Any]] = []  # called when the step under way ends
        esper.switch_world(self.world)
        self._stages = {stage.name: stage for stage in pipeline_stages(self._pipeline)}
        for stage in self._stages.values():
            if stage.solver in (None, solver):  # (the other solver's stages never run here)
                esper.add_processor(stage, stage.priority)
        for hook in SCENE_CREATED:
            hook(self)

    # --- settings and what the last step computed ----------------------------------------------

    @property
    def effects(self) -> frozenset[str]:
        """What the scene simulates (see :data:`EFFECTS`)."""
        return self._pipeline.effects

    @effects.setter
    def effects(self, effects: Iterable[str]) -> None:
        self._pipeline.effects = resolve_effects(effects)

    @property
    def solver(self) -> str:
        """The contact solver: ``"exact"`` or ``"soft"`` (see :class:`Scene`).

        Settable between steps (a game whose levels need different solvers: a level with joints
        the soft one, another the exact one's resting heights). Switching puts the scene's
        pipeline in the state a new scene of that solver starts from, keeping the bodies (poses,
        velocities), entities, components, systems, handlers, resources, clock and step counter:
        the other solver's stages replace this one's, each solver's own state is dropped (the
        exact solver's pair tracking and warm starts, the soft step's candidate pairs, contact and
        joint impulses), the last step's frame is forgotten (``scene.events`` and
        ``scene.contacts`` read empty until the next step) and every body is woken. So pairs that
        touch across the switch are reported ``started`` again by the next step, and no ``ended``
        for pairs the old solver was tracking: switch with nothing touching for unbroken events.
        Setting the solver it has already changes nothing. Refused with :class:`InvalidValue`
        (the scene unchanged) for an unknown solver, and during a step (from a system or a
        collision handler: use :meth:`after_step` to switch when the step ends)."""
        return self._pipeline.solver

    @solver.setter
    def solver(self, solver: str) -> None:
        self._activate()
        if self._stepping:
            raise InvalidValue(f"Scene solver cannot change during a step (asked for {solver!r} from a system or a "
                               "collision handler): set it between steps, or from scene.after_step(...)")
        if not isinstance(solver, str) or solver not in SOLVERS:
            raise InvalidValue(f"Scene solver must be one of {SOLVERS}, got {solver!r}")
        pipeline = self._pipeline
        if solver == pipeline.solver:
            return
        for stage in self._stages.values():
            if stage in esper._processors:
                unregister(stage)
        pipeline.solver = solver
        pipeline.frame = StepFrame(counters={})
        self._totals = None
        # Fresh stages, as a new scene's: the solvers' own (and the sleeping stage, whose links the
        # solver made); the character and render stages keep theirs (the controllers' state is
        # the components', the renderer the scene's).
        fresh = {stage.name: stage for stage in pipeline_stages(pipeline)}
        for name in list(self._stages):
            if self._stages[name].solver is not None or name == "sleeping":
                self._stages[name] = fresh[name]
        store = self.bodies.store
        if store.n:
            store.wake(np.arange(store.n))
        for stage in self._stages.values():
            if stage.solver in (None, solver):
                esper.add_processor(stage, stage.priority)

    def after_step(self, call: Callable[[Scene], Any]) -> None:
        """Call ``call(scene)`` when the step under way ends (after its sub-steps, handlers and
        despawns; the step counter and clock moved on), between steps: for what only between
        steps may be done, such as setting :attr:`solver` from a system. Calls run in the order
        asked for; one that raises stops the rest, and the step (complete) raises its exception
        with a note. A step that fails (and is undone) drops them. Outside a step, ``call(scene)``
        runs now."""
        if not callable(call):
            raise InvalidValue(f"after_step takes a callable as call(scene), got {call!r}")
        self._activate()
        if self._stepping:
            self._after_step.append(call)
        else:
            call(self)

    @property
    def gravity(self) -> tuple[float, float]:
        """Acceleration of dynamic bodies (with the gravity effect)."""
        return self._pipeline.gravity

    @gravity.setter
    def gravity(self, value: tuple[float, float]) -> None:
        self._pipeline.gravity = vector2("Scene gravity", value)

    @property
    def response_iterations(self) -> int:
        return self._pipeline.response_iterations

    @response_iterations.setter
    def response_iterations(self, value: int) -> None:
        self._pipeline.response_iterations = _count("response_iterations", value)

    @property
    def step_frame(self) -> StepFrame:
        """The frame of the step under way, or of the last step between steps (read-only: what the
        stages computed; see :mod:`framework.frame`)."""
        return self._pipeline.frame

    @property
    def events(self) -> list[CollisionEvent]:
        """This step's collision events, sorted by pair (a, b): ended, then started or ongoing."""
        return self._totals[0] if self._totals is not None else self._pipeline.frame.events

    @property
    def counters(self) -> dict[str, Any]:
        """What the last step did: the stages that ran (``systems``), bodies integrated, pairs,
        contacts, events, contacts resolved, bodies asleep... (summed over sub-steps)."""
        return self._totals[1] if self._totals is not None else self._pipeline.frame.counters

    @property
    def stage_ms(self) -> dict[str, float]:
        """Milliseconds each stage took in the last sub-step."""
        return self._pipeline.frame.stage_ms

    @property
    def contacts(self) -> StepContacts:
        """This step's overlapping pairs as arrays (entity ids a < b, normal from a to b)."""
        return self._pipeline.frame.contacts

    @property
    def resolved(
        self,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """The contacts the response actually applied this step, as arrays ``(a, b, nx, ny,
        pushed)`` (entity ids a < b, the normal from a to b it pushed along, the total push-out),
        sorted by pair. A contact the response discarded (the sliver of a tile under a body
        pushed into a wall, once the wall's push freed it) is not here: a game asking "am I
        standing on something?" should look here, not at every contact."""
        return self._pipeline.frame.resolved

    @property
    def contact_points(
        self,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64],
               NDArray[np.float64]]:
        """Where boxes and polygons turn (the ``rotation`` effect): the points the response pushed
        at this step, as arrays ``(a, b, x, y, push, impulse)`` (entity ids a < b; each point's
        push-out and normal impulse), sorted by pair; two where a face rests on a face (see
        docs/physics.md). Empty in a step where no such body was in a contact."""
        keys, _slot, push, impulse, _tpush, _timpulse, x, y = self._pipeline.frame.points
        a, b = pair_parts(keys)
        return a, b, x, y, push, impulse

    @property
    def ray_log(self) -> list[tuple[tuple[float, float], tuple[float, float], SceneHit | None]]:
        """This step's rays (origin, end, first hit or None), for the debug overlay."""
        return self._pipeline.frame.ray_log

    @property
    def swept_paths(self) -> list[tuple[tuple[float, float], tuple[float, float]]]:
        """This step's swept paths of continuous-detection bodies ((x0, y0), (x1, y1))."""
        return self._pipeline.frame.swept_paths

    # Read-only views of the pipeline's data, for tools, tests and the renderer.
    @property
    def store(self) -> BodyStore:
        """The columnar store (see framework.store)."""
        return self.bodies.store

    @property
    def geometry(self) -> Geometry:
        """Hitbox origins and bounds (current after ensure_geometry)."""
        return self.bodies.geometry

    @property
    def hash(self) -> SpatialHash:
        """The spatial hash of the static bodies."""
        return self.bodies.hash

    @property
    def tracker(self) -> PairTracker:
        """The narrow phase's pair tracker."""
        return cast(NarrowPhase, self._stages["narrow_phase"]).tracker

    def ensure_geometry(self) -> None:
        """Bring ``scene.geometry`` (hitbox origins and bounds) up to date, if anything moved."""
        self.bodies.ensure_geometry()

    # --- entities ----------------------------------------------------------------------------

    def _activate(self) -> None:
        if self.closed:
            raise SceneClosed(f"scene {self.world!r} is closed")
        if esper.current_world != self.world:
            esper.switch_world(self.world)

    def spawn(self, *components: Any) -> int:
        """Create an entity with ``components``; return its id.

        A Hitbox needs a Transform; a static body has no Velocity; a joint's bodies are bodies of
        the scene (see :mod:`framework.joints`). Nothing changes on error."""
        self._activate()
        t, v, h = spawn_components(components)
        for comp in components:
            if isinstance(comp, Joint):
                comp.attach(self.bodies.store)
        entity = esper.create_entity(*components)
        if t is not None:
            self.bodies.store.add(entity, t, v, h)
        for comp in components:
            if isinstance(comp, Parts):
                self.bodies.store.set_parts(entity, comp)
            elif isinstance(comp, CharacterController):
                comp.bind(entity)
            elif isinstance(comp, Visual):
                comp._bind(self.bodies.store if t is not None else None, entity, self.time)
        return entity

    def despawn(self, entity: int) -> None:
        """Remove ``entity``; its pairs end (``ended`` events) in the next step's events.

        During a step (from a system or a handler) the removal waits until the step ends.
        Despawning an entity that is gone already (despawned, or waiting to be) is refused, except
        from a collision handler, where it does nothing: two events of one step may well name the
        same bullet. An id that never named an entity of this scene is always refused."""
        self._activate()
        if not self.exists(entity):
            if self._dispatching and self._was_entity(entity):
                return
            raise InvalidValue(f"entity {entity!r} does not exist (despawned already?)")
        if self._stepping:
            self._pending_despawn.append(entity)
        else:
            self._remove(entity)

    def _remove(self, entity: int) -> None:
        comps: tuple[Any, ...] = esper.components_for_entity(entity)
        self.handlers.remember(entity, {type(c) for c in comps})
        store = self.bodies.store
        row = store.row_of.get(entity)
        self._wake_joined(comps)  # a joint that goes: its bodies
        if row is not None:
            if store.asleep.any():
                if store.kind[row] >= 0:
                    self.bodies.wake_near(row)
                self._wake_joined(j for _e, j in joint_components() if entity in j.bodies())
            store.remove(entity, comps)
        esper.delete_entity(entity, immediate=True)
        if row is not None:  # a body: its joints go with it (and the entities they leave empty)
            for e in remove_joints_of(entity):
                self._remove(e)

    def _wake_joined(self, joints: Iterable[Any]) -> None:
        """Wake the bodies of the joints (of the components) given, which are going: a body asleep
        while a joint held it (a crate a mouse joint held up) must not hang there once let go."""
        store = self.bodies.store
        if not store.asleep.any():
            return
        rows = [store.row_of[e] for j in joints if isinstance(j, Joint) for e in j.bodies() if e in store.row_of]
        if rows:
            store.wake(np.asarray(rows, dtype=np.intp))

    def _was_entity(self, entity: Any) -> bool:
        """Whether ``entity`` is an id this scene gave out (esper never gives one out twice): one
        that does not exist any more was despawned."""
        if isinstance(entity, bool) or not isinstance(entity, Integral):
            return False
        return 1 <= int(entity) < self._next_entity()

    def _next_entity(self) -> int:
        """The next id esper gives out in this scene's world."""
        text = repr(esper._entity_count)  # ("count(7)": esper's itertools.count; read, not advanced)
        if text.startswith("count(") and text[6:-1].isdigit():
            return int(text[6:-1])
        count = re.fullmatch(r"count\((-?\d+)\)", text)
        return int(count.group(1)) if count is not None else 0

    def exists(self, entity: int) -> bool:
        """Whether ``entity`` is an entity of this scene (not despawned, nor waiting to be)."""
        self._activate()
        if isinstance(entity, bool) or not isinstance(entity, Integral):  # True is not entity 1
            return False
        return esper.entity_exists(int(entity)) and entity not in self._pending_despawn

    def add_component(self, entity: int, component: Any) -> None:
        """Add (or replace) a component of ``entity``, keeping the pipeline's view in step."""
        self._activate()
        if not self.exists(entity):
            raise InvalidValue(f"entity {entity!r} does not exist")
        store = self.bodies.store
        check_added_component(store, entity, component)
        if isinstance(component, Joint):
            component.attach(store)
        old = esper.try_component(entity, type(component))
        esper.add_component(entity, component)
        if isinstance(component, CharacterController):
            component.bind(entity)
        if isinstance(component, Visual):
            if isinstance(old, Visual):
                store.unbind(entity, old)
            component._bind(store if entity in store.row_of else None, entity, self.time)
            store.visual_changed(entity)
        if isinstance(component, Velocity):
            if old is not None:
                store.unbind(entity, old)  # the replaced Velocity no longer writes to the row
            store.set_velocity(entity, component)
        elif isinstance(component, Hitbox):
            store.set_hitbox(entity, component)
        elif isinstance(component, Parts):
            store.set_parts(entity, component)

    def remove_component(self, entity: int, component_type: type) -> Any:
        """Remove and return ``entity``'s ``component_type`` component; it keeps its values."""
        self._activate()
        if component_type is Transform:
            raise InvalidValue("remove the entity instead of its Transform")
        if not self.exists(entity):
            raise InvalidValue(f"entity {entity!r} does not exist")
        if not esper.has_component(entity, component_type):
            name = getattr(component_type, "__name__", repr(component_type))
            raise InvalidValue(f"entity {entity} has no {name} component")
        comp: Any = esper.remove_component(entity, component_type)
        self._wake_joined((comp,))
        store = self.bodies.store
        if component_type is Velocity and entity in store.row_of:
            store.unbind(entity, comp)  # before the row forgets its values
            store.set_velocity(entity, None)
        elif component_type is Hitbox and entity in store.row_of:
            store.set_hitbox(entity, None)
        elif component_type is Parts and entity in store.row_of:
            store.set_parts(entity, None)
        elif component_type is Visual:
            store.unbind(entity, comp)
            store.visual_changed(entity)
        return comp

    def get(self, entity: int, component_type: type) -> Any:
        """The ``component_type`` component of ``entity``; :class:`MissingComponent` (a
        ``KeyError``) naming the entity and the type if it has none or does not exist."""
        self._activate()
        try:
            return esper.component_for_entity(entity, component_type)
        except KeyError:
            pass
        name = getattr(component_type, "__name__", repr(component_type))
        if esper.entity_exists(entity):
            comps: tuple[Any, ...] = esper.components_for_entity(entity)
            has = ", ".join(sorted(type(c).__name__ for c in comps)) or "nothing"
            msg = f"entity {entity} has no {name} component (it has {has})"
        elif self._was_entity(entity):
            msg = f"entity {entity} was despawned, so it has no {name} component"
        else:
            msg = f"entity {entity!r} does not exist (no entity of this scene has that id), so it has no {name}"
        raise MissingComponent(msg, entity, component_type)

    def try_get(self, entity: int, component_type: type) -> Any:
        self._activate()
        return esper.try_component(entity, component_type)

    def query(self, *component_types: type) -> list[tuple[int, Any]]:
        """``esper.get_components`` in this scene's world, sorted by entity id."""
        self._activate()
        if len(component_types) == 1:
            return sorted(esper.get_component(component_types[0]), key=lambda ec: ec[0])
        return sorted(esper.get_components(*component_types), key=lambda ec: ec[0])

    @property
    def entities(self) -> list[int]:
        self._activate()
        return sorted(esper.get_entities())

    # --- systems, processors and handlers ------------------------------------------------------

    def add_system(self, system: System, *, before: str | None = None, after: str | None = None) -> None:
        """Run ``system(scene, dt)`` every step, before or after a stage (default: after response)."""
        stage, priority = place(before, after)
        if not callable(system):
            raise InvalidValue(f"system must be callable as system(scene, dt), got {system!r}")
        self._activate()
        proc = SystemProcessor(system, self, stage)
        self._systems.append(proc)
        esper.add_processor(proc, priority)

    def remove_system(self, system: System) -> None:
        for proc in self._systems:
            if proc.system == system:
                self._activate()
                self._systems.remove(proc)
                unregister(proc)
                return
        raise InvalidValue(f"system {system!r} is not in this scene")

    def add_processor(self, processor: esper.Processor, *, before: str | None = None,
                      after: str | None = None) -> None:
        """Add an esper processor to the scene's world, before or after a stage (default: after
        the response). ``esper.process`` passes it ``dt``: ``processor.process(dt)``."""
        _stage, priority = place(before, after)
        if not callable(getattr(processor, "process", None)):
            raise InvalidValue(f"processor must have a process(dt) method, got {processor!r}")
        self._activate()
        esper.add_processor(processor, priority)

    def remove_processor(self, processor: esper.Processor) -> None:
        """Take a processor added with :meth:`add_processor` out of the scene."""
        self._activate()
        if processor not in esper._processors or processor in self._stages.values():
            raise InvalidValue(f"processor {processor!r} is not a game processor of this scene")
        unregister(processor)

    def on_collision(
        self, type_a: type, type_b: type, handler: Callable[[Scene, CollisionEvent], Any],
        kinds: Iterable[str] = ("started",),
    ) -> None:
        """Call ``handler(scene, event)`` for collision events between an entity with a ``type_a``
        component and one with a ``type_b`` component. The event is turned so that ``event.a``
        is the ``type_a`` entity (its normal then points from it toward the ``type_b`` one).
        A handler that takes a single argument is called as ``handler(event)``. ``kinds`` may be
        one kind name or several. ``type_a`` and ``type_b`` must be classes (``Bullet``, not
        ``Bullet()`` or ``"Bullet"``): anything else is an :class:`InvalidValue`."""
        self.handlers.add(type_a, type_b, handler, kinds)
        self._pipeline.wanted_pairs = self.handlers.wanted

    # --- stepping ----------------------------------------------------------------------------

    def step(self, dt: float) -> None:
        """Advance the scene by ``dt`` seconds (finite, > 0), in ``substeps`` equal sub-steps.

        A component holding NaN, inf or a non-number, a body beyond the scene's coordinates or a
        hitbox beyond its sizes and masses (:mod:`framework.limits`), or a ``dt`` that could carry a
        body beyond those coordinates, makes this raise ``ValueError`` naming the entity and the
        field, before anything changes. A step that fails (a stage, system or processor raises,
        or one writes a bad value into a body, or a motion overflows) is undone before the
        exception propagates: the scene is exactly as it was before the step (see
        :mod:`framework.rollback`), with a note on the exception saying so. With several
        sub-steps, each runs the whole pipeline (game systems and handlers included; rendering
        only after the last), the events of all sub-steps are reported in order, and the counters
        add up.

        A collision handler that raises does not cut the step short: the other handlers still run
        (every sub-step too), the step completes (frame, time, events, despawns), and then the
        first handler's exception is raised, unchanged in type, with a note naming the handler,
        the event's kind and entities, and the step (and a note listing any other handler that
        raised). A bad value a handler writes is reported at the end of the step (which is then
        complete), and the next step refuses to start until it is mended."""
        self._activate()
        if self._stepping:
            raise InvalidValue("step() was called from inside a step (a system or a collision handler)")
        dt = positive("dt", dt)
        store = self.bodies.store
        store.check()
        if store.parts:
            self._check_compound()
        joints = joint_components()
        if joints:
            check_joints(joints, store, self.solver)
        characters = self._stages["character"]
        if isinstance(characters, CharacterStage) and characters.wanted():
            characters.check()
        movers = store.active()[0]
        c = store.cols  # (the columns whole: the pass reads only the movers' rows)
        gx, gy = self._pipeline.active_gravity()
        if motion_within(c["x"], c["y"], c["vx"], c["vy"], movers, dt, gx, gy, MAX_COORD) >= 0:
            check_motion(store.entity[movers], store.x[movers], store.y[movers], store.vx[movers], store.vy[movers],
                         dt, (gx, gy))
        before = StepRollback(self)
        n = self.substeps
        errors: list[Exception] = []  # raised by collision handlers, raised once the step is complete
        # The process's first step compiles the kernels it uses (after installing): say so if slow.
        # (A soft scene's kernel says its own.)
        global _STEPPED
        compiling, _STEPPED = not _STEPPED and self._pipeline.solver == "exact", True
        with notice_if_slow(FIRST_STEP_NOTICE) if compiling else nullcontext():
            try:
                self._totals = None
                if n == 1:
                    self._substep(dt, render=True, checked=True, errors=errors, where=f", in step {self.frame + 1}")
                else:
                    events: list[CollisionEvent] = []
                    total: dict[str, Any] = {}
                    for k in range(n):
                        self._substep(dt / n, render=k == n - 1, checked=k == 0, errors=errors,
                                      where=f", in step {self.frame + 1} (sub-step {k + 1} of {n})")
                        events.extend(self.events)
                        add_counters(total, self.counters)
                    self._totals = (events, total)
            except Exception as exc:
                self._after_step = []  # (the step is undone: what it asked for with it)
                if before.restore(self):
                    exc.add_note(f"step {self.frame + 1} failed and was undone: the scene is as it was before it")
                else:
                    exc.add_note(f"step {self.frame + 1} failed after a system changed the scene's structure (a Hitbox "
                                 "or Velocity added or removed): the scene is left as the failure found it")
                raise
        store.end_undo()  # (the step stands: the static rows need no saving any more)
        self.broken_joints = self._break_joints()
        self.frame += 1
        self.time += dt
        inp = self.resources.get(Input)
        if inp is not None:
            inp.end_step()
        calls, self._after_step = self._after_step, []
        for call in calls:
            try:
                call(self)
            except Exception as exc:
                exc.add_note(f"raised by {call!r}, called by scene.after_step at the end of step {self.frame} (the "
                             "step is complete; later after_step calls were not made)")
                raise
        try:
            # A bad value written by a collision handler (after the step's physics was done, and
            # kept): reported now, by the step that made it. (The pipeline's own values were
            # checked before the handlers ran; only what game code wrote since needs a look.)
            if store.written or store.bad or store.dirty_hitboxes:
                store.check()
        except InvalidValue as exc:
            bad = InvalidValue(f"{exc} (at the end of step {self.frame}: written by a collision handler during "
                               "the step)")
            if not errors:
                raise bad from None
            errors[0].add_note(f"and at the end of step {self.frame}: {bad}")
        if errors:
            first = errors[0]
            if len(errors) > 1:
                others = "; ".join(f"{type(e).__name__}: {e} ({e.__notes__[-1]})" for e in errors[1:4])
                more = f"; and {len(errors) - 4} more" if len(errors) > 4 else ""
                first.add_note(f"{len(errors) - 1} other collision handler call(s) raised in step {self.frame} "
                               f"too: {others}{more}")
            raise first

    def _check_compound(self) -> None:
        """Refuse to step a scene whose compound bodies (entities with :class:`Parts`) it cannot
        take: only the soft solver does, not for a character (the controller moves one shape), and
        a body's shapes need its Hitbox and are of its kind. Changes nothing."""
        from .systems.soft_step import MAX_COMPOUND_ENTITY

        store = self.bodies.store
        characters = esper.get_component(CharacterController) if "character" in self.effects else []
        for e in sorted(store.parts):
            parts = store.parts[e]
            hb = store.hitboxes[store.row_of[e]]
            if self.solver != "soft":
                raise InvalidValue(f"entity {e} is a body of several shapes (Parts): the {self.solver} solver does not "
                                   "take them; use Scene(solver='soft'), or remove its Parts")
            if hb is None:
                raise InvalidValue(f"entity {e} has Parts but no Hitbox: its Hitbox is its part 0 (give it one, or "
                                   "remove its Parts)")
            for i, part in enumerate(parts.hitboxes, start=1):
                if part.body is not hb.body:
                    raise InvalidValue(f"entity {e}: Parts: part {i} is body={part.body!r}, its Hitbox "
                                       f"body={hb.body!r}: the shapes of one body are of one kind")
            if esper.has_component(e, CharacterController):
                raise InvalidValue(f"entity {e} is a character (CharacterController) with Parts: the character "
                                   "controller moves bodies of one shape; remove its Parts")
            if characters and any(not part.sensor for part in parts.hitboxes):
                raise InvalidValue(f"entity {e} is a body of several shapes (Parts) in a scene with characters "
                                   f"(entity {characters[0][0]}): the character controller does not see the parts of "
                                   "compound bodies yet (it would walk through them); make its parts sensors, or the "
                                   "body one shape")
            if e >= MAX_COMPOUND_ENTITY:
                raise InvalidValue(f"entity {e} has Parts: compound bodies take entity ids below "
                                   f"{MAX_COMPOUND_ENTITY} (2**24)")

    def mass_data(self, entity: int) -> MassData:
        """The mass data of ``entity``'s body (:class:`MassData`: mass, centre of mass in the
        entity's frame, moment of inertia about it): its Hitbox's, or with its :class:`Parts`, the
        whole body's (:func:`~framework.components.body_mass_data`). :class:`MissingComponent` if it
        has no Hitbox."""
        hb = self.get(entity, Hitbox)
        return body_mass_data(hb, self.try_get(entity, Parts))

    def _substep(self, dt: float, render: bool, checked: bool, errors: list[Exception], where: str) -> None:
        """One pass of the pipeline (``checked``: the store was just checked, nothing ran since).
        Exceptions raised by collision handlers are appended to ``errors`` (each with a note ending
        in ``where``), not raised."""
        store = self.bodies.store
        self._stepping = True
        frame = self._pipeline.frame = self._pipeline.frame.next(dt, render)
        done = False
        try:
            if not checked:
                store.check()
            store.apply_hitbox_changes()
            esper.process(dt)
            try:  # a bad value a system wrote, or a motion that overflowed: the step failed
                store.check()
            except InvalidValue as exc:
                raise InvalidValue(f"{exc} (written during step {self.frame + 1} by a system or processor, or "
                                   "an overflow)") from None
            self._dispatching = True
            self.handlers.dispatch(self, lambda: frame.events, errors, where)
            done = True
        finally:
            self._stepping = self._dispatching = False
            pending, self._pending_despawn = self._pending_despawn, []
            for e in pending if done else ():  # (a failed step drops them: it is undone)
                if esper.entity_exists(e):
                    self._remove(e)

    @property
    def renderer(self) -> Any:
        """The object whose ``draw(scene)`` is the render stage; attaching one declares rendering."""
        return self._pipeline.renderer

    @renderer.setter
    def renderer(self, renderer: Any) -> None:
        self._pipeline.renderer = renderer
        if renderer is not None:
            self.effects = self.effects | {"rendering"}
        if renderer is not None and "debug_overlay" in self.effects and hasattr(renderer, "debug"):
            renderer.debug = True

    # --- queries (see framework.queries) -------------------------------------------------------

    def raycast_all(self, origin: tuple[float, float], direction: tuple[float, float],
                    max_distance: float = math.inf, mask: int = ALL_LAYERS) -> list[SceneHit]:
        """Every hitbox the ray enters within ``max_distance``, nearest first (ties by entity)."""
        self._activate()
        return self._queries.raycast_all(origin, direction, max_distance, mask)

    def raycast(self, origin: tuple[float, float], direction: tuple[float, float],
                max_distance: float = math.inf, mask: int = ALL_LAYERS) -> SceneHit | None:
        """The first hitbox the ray enters within ``max_distance``, or ``None``."""
        hits = self.raycast_all(origin, direction, max_distance, mask)
        return hits[0] if hits else None

    def shape_cast(self, shape: Shape, start: tuple[float, float], end: tuple[float, float], *,
                   rotation: float = 0.0, mask: int = ALL_LAYERS, ignore: Iterable[int] = ()) -> ShapeHit | None:
        """The first hitbox ``shape`` would enter moving from ``start`` to ``end`` (positions of
        its hitbox origin, turned by ``rotation``): a :class:`~framework.casting.ShapeHit` (entity,
        fraction of the way, touching point, surface normal facing the shape), or ``None``.
        Grazing is a miss; overlapping at ``start`` is a hit at fraction 0. Sensors and the
        ``ignore``-d entities (the caster's own, say) are passed through."""
        self._activate()
        return self._queries.shape_cast(shape, start, end, rotation, mask, ignore)

    def query_box(self, minx: float, miny: float, maxx: float, maxy: float, mask: int = ALL_LAYERS) -> list[int]:
        """Entities whose hitbox interiors overlap the box's interior, sorted."""
        self._activate()
        return self._queries.query_box(minx, miny, maxx, maxy, mask)

    def query_point(self, x: float, y: float, mask: int = ALL_LAYERS) -> list[int]:
        """Entities whose hitbox contains the point (closed: a point on the boundary counts)."""
        self._activate()
        return self._queries.query_point(x, y, mask)

    def query_shape(self, shape: Shape, position: tuple[float, float], *, rotation: float = 0.0,
                    mask: int = ALL_LAYERS) -> list[int]:
        """Entities whose hitbox interiors overlap ``shape``'s placed at ``position`` (its hitbox
        origin) and turned by ``rotation``, sorted: an explosion's reach, a sword's swing, whether a
        spawn point is free. Touching does not count."""
        self._activate()
        return self._queries.query_shape(shape, position, rotation, mask)

    def nearest(self, point: tuple[float, float], *, max_distance: float = math.inf,
                mask: int = ALL_LAYERS) -> Nearest | None:
        """The hitbox nearest ``point`` within ``max_distance``: a :class:`~framework.queries.Nearest`
        (entity, distance, its nearest point; distance 0 if the point is inside), or None. Ties go to
        the lower entity id."""
        self._activate()
        return self._queries.nearest(point, max_distance, mask)

    def distance(self, entity_a: int, entity_b: int) -> Distance:
        """How far apart two entities' hitboxes are (0 where they overlap or touch) and their
        closest points: a :class:`~framework.collision.distance.Distance`."""
        self._activate()
        return self._queries.distance(entity_a, entity_b)

    def query_points(self, points: Any, *, mask: int = ALL_LAYERS) -> PointHits:
        """:meth:`query_point` of many points (an ``(n, 2)`` array) in one compiled pass: a
        :class:`~framework.queries.PointHits`; point ``i``'s entities, sorted, are
        ``hits.entities[hits.offsets[i]:hits.offsets[i + 1]]`` (``hits.of(i)``)."""
        self._activate()
        return self._queries.query_points(points, mask)

    def nearest_many(self, points: Any, *, max_distance: float = math.inf, mask: int = ALL_LAYERS) -> NearestMany:
        """:meth:`nearest` of many points (an ``(n, 2)`` array) in one compiled pass: a
        :class:`~framework.queries.NearestMany` of arrays ``entity`` (-1 where no hitbox is within
        ``max_distance``), ``distance`` (``inf`` there) and ``point``; the same floats as
        ``nearest`` point by point."""
        self._activate()
        return self._queries.nearest_many(points, max_distance, mask)

    def raycast_many(self, origins: Any, directions: Any, *, max_distance: float = math.inf,
                     mask: int = ALL_LAYERS) -> RayHits:
        """:meth:`raycast` of many rays (``(n, 2)`` arrays of origins and directions) in one
        compiled pass: a :class:`~framework.queries.RayHits` of arrays ``entity`` (-1 for a miss),
        ``distance`` (``inf`` for a miss), ``point`` and ``normal``; the same floats as
        ``raycast`` ray by ray. Batched rays are not drawn by the debug overlay."""
        self._activate()
        return self._queries.raycast_many(origins, directions, max_distance, mask)

    def _break_joints(self) -> list[JointBroken]:
        """Remove the joints whose force or torque this step was above their ``break_force`` or
        ``break_torque`` (and their entities, if that was all they held); what broke, by entity."""
        stage = self._stages.get("soft_step")
        joints = joint_components()
        if not joints or not isinstance(stage, SoftStep):
            return []
        broken = []
        for e, j in breakable(joints):
            fx, fy, torque = stage.reaction(e, j)
            if math.hypot(fx, fy) > j.break_force or abs(torque) > j.break_torque:
                broken.append(JointBroken(e, j.a, j.b, j, Vec2(float(fx), float(fy)), float(torque)))
        for b in broken:
            esper.remove_component(b.entity, type(b.joint))
            if not esper.components_for_entity(b.entity):
                self._remove(b.entity)
        return broken

    def joint_reaction(self, joint: int) -> JointReaction:
        """What the joint on entity ``joint`` did to its body ``a`` in the last step: a
        :class:`~framework.joints.JointReaction` ``(force, torque)`` (Box2D's constraint force
        and torque: the torque is the joint's angular part, a motor's, a limit's or a weld's).
        Zeros before a step has solved it (and in the exact solver, which solves no joints)."""
        self._activate()
        found: list[Joint] = []
        if isinstance(joint, int) and not isinstance(joint, bool) and esper.entity_exists(joint):
            held: tuple[Any, ...] = esper.components_for_entity(joint)
            found = [c for c in held if isinstance(c, Joint)]
        if not found:
            raise InvalidValue(f"joint must be an entity holding a joint component, got {joint!r}")
        stage = self._stages.get("soft_step")
        fx, fy, torque = stage.reaction(joint, found[0]) if isinstance(stage, SoftStep) else (0.0, 0.0, 0.0)
        return JointReaction(Vec2(float(fx), float(fy)), float(torque))

    # --- snapshots ---------------------------------------------------------------------------

    def snapshot(self) -> Snapshot:
        """The scene's state now, between steps: entities and components, the store, contacts and
        events, sleeping, the solver's warm start, the step counter and clock, the resources. A
        restored scene steps bit-identically to this one; the snapshot pickles (see
        :mod:`framework.snapshot`)."""
        return take_snapshot(self)

    def restore(self, snapshot: Snapshot) -> None:
        """Put the scene back in the state of ``snapshot`` (taken from this scene or one built the
        same way). A snapshot from a scene of another shape (other systems or handlers) or another
        version is an ``InvalidValue``, and the scene is unchanged."""
        restore_snapshot(self, snapshot)

    # --- lifetime ----------------------------------------------------------------------------

    def close(self) -> None:
        """Delete the scene's world. Further calls raise :class:`SceneClosed`."""
        if self.closed:
            return
        if esper.current_world == self.world:
            esper.switch_world("default")
        if self.world in esper.list_worlds():
            esper.delete_world(self.world)
        self.closed = True

    def __enter__(self) -> Scene:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:  # pragma: no cover - best effort
        try:
            if not self.closed and self.world in esper.list_worlds() and esper.current_world != self.world:
                esper.delete_world(self.world)
        except Exception:
            pass
