"""The scene: one esper world, its columnar store and the collision pipeline that steps it.

A step runs, in this order: movement (integrate Velocity, optional gravity) -> continuous
detection (only for ``ccd`` bodies) -> broad phase -> narrow phase (contacts and events) ->
response -> render (only with a renderer attached). Game code adds its own systems before or after
any stage with :meth:`Scene.add_system`.
"""

from __future__ import annotations

import inspect
import itertools
import math
import time
from collections.abc import Callable, Iterable
from numbers import Integral
from typing import Any, NamedTuple

import esper
import numpy as np

from .arrays import distinct
from .collision import batch
from .collision.broad_phase import SpatialHash
from .collision.grid import auto_cell_size
from .collision.placement import check_shape
from .collision.ray import raycast as _raycast
from .collision.results import Vec2
from .components import Body, Hitbox, Transform, Velocity, check_component
from .events import CollisionEvent, PairTracker, StepContacts, pair_keys, sorted_member, to_events
from .input import Input
from .shapes import AABB, Circle
from .store import STATIC, BodyStore
from .systems.ccd import sweep_ccd_bodies
from .systems.geometry import Geometry
from .systems.internal_faces import InternalFaces
from .systems.movement import integrate, integrate_rows
from .systems.narrow_phase import filter_layers, pair_contacts
from .systems.response import resolve
from .validation import InvalidValue, finite, positive, vector2

__all__ = ["DEFAULT_EFFECTS", "EFFECTS", "Scene", "SceneClosed", "SceneHit", "STAGES", "resolve_effects"]

STAGES = ("movement", "ccd", "broad_phase", "narrow_phase", "response", "render")

# Effects a scene can declare, each with the effects it needs. A scene assembles only the stages
# its effects call for (see docs/effects.md).
EFFECTS: dict[str, tuple[str, ...]] = {
    "movement": (),                          # integrate Velocity
    "gravity": ("movement",),                # accelerate dynamic bodies by Scene.gravity
    "detection": (),                         # broad + narrow phase: which hitboxes overlap
    "events": ("detection",),                # every pair's started / ongoing / ended events
    "response": ("detection",),              # push bodies apart, slide, bounce
    "continuous": ("movement", "detection"),  # sweep Hitbox(ccd=True) bodies
    "rendering": (),                         # the render stage (a renderer must be attached)
    "debug_overlay": ("rendering",),         # hitboxes, contacts, cells, rays on screen
    "sleeping": (),                          # bodies at rest sleep: no work until woken
}
DEFAULT_EFFECTS = frozenset(
    {"movement", "gravity", "detection", "events", "response", "continuous", "sleeping"}
)
# A dynamic body sleeps after this many steps at rest: moving less than SLEEP_SPEED (relative to
# 1 + its size, per second) with a speed below that. Game code writing its Transform or Velocity,
# a contact with an awake body, a change to the static level or a despawn nearby wake it.
SLEEP_STEPS = 30
SLEEP_SPEED = 1e-3


def resolve_effects(effects: Iterable[str] | None) -> frozenset[str]:
    """The declared effects plus everything they need; ``ValueError`` for an unknown one."""
    if effects is None:
        return DEFAULT_EFFECTS
    if isinstance(effects, str):
        raise InvalidValue(f"effects must be a collection of names, got the string {effects!r}")
    wanted = list(effects)
    out: set[str] = set()
    while wanted:
        name = wanted.pop()
        if name not in EFFECTS:
            raise InvalidValue(f"unknown effect {name!r}; known effects are {sorted(EFFECTS)}")
        if name not in out:
            out.add(name)
            wanted.extend(EFFECTS[name])
    return frozenset(out)
_ALL_BITS = 0xFFFFFFFF
_scene_ids = itertools.count(1)
_NO_SUPPORT = (np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(0))
_NO_RESOLVED = (*_NO_SUPPORT, np.zeros(0))

System = Callable[["Scene", float], Any]


def _takes_one_argument(fn: Callable[..., Any]) -> bool:
    try:
        params = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return False
    if any(p.kind == p.VAR_POSITIONAL for p in params):
        return False
    return sum(p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD) for p in params) == 1


def _add_counters(total: dict[str, Any], step: dict[str, Any]) -> None:
    """Sum one sub-step's counters into ``total`` (lists of systems: in order, once)."""
    for key, value in step.items():
        if isinstance(value, dict):
            _add_counters(total.setdefault(key, {}), value)
        elif isinstance(value, list):
            seen = total.setdefault(key, [])
            seen.extend(v for v in value if v not in seen)
        else:
            total[key] = total.get(key, 0) + value


class SceneClosed(RuntimeError, ValueError):
    """The scene was closed; it can no longer be stepped or changed."""


class SceneHit(NamedTuple):
    """A scene raycast hit: the entity, and where and how the ray entered its hitbox."""

    entity: int
    distance: float
    point: Vec2
    normal: Vec2


class Scene:
    """An isolated world of entities and the systems that step it.

    ``gravity``: acceleration of dynamic bodies (world units per second squared, y up).
    ``cell_size``: the spatial hash's cell; ``None`` chooses it from the hitbox sizes.
    ``response_iterations``: passes of the response over bodies in several contacts (accuracy
    knob: more passes settle stacks and corners better).
    ``substeps``: pipeline runs per :meth:`step` (accuracy knob: smaller steps tunnel and
    sink less, at a proportional cost).
    ``effects``: what the scene simulates (see :data:`EFFECTS`); the default,
    :data:`DEFAULT_EFFECTS`, is a typical game's: movement, gravity, detection, events, response
    and continuous detection. Rendering is added when a renderer is attached.
    """

    def __init__(
        self,
        *,
        gravity: tuple[float, float] = (0.0, 0.0),
        cell_size: float | None = None,
        response_iterations: int = 4,
        substeps: int = 1,
        effects: Iterable[str] | None = None,
    ) -> None:
        self.effects = resolve_effects(effects)
        self.gravity = vector2("Scene gravity", gravity)
        if cell_size is not None:
            cell_size = positive("Scene cell_size", cell_size)
        if isinstance(response_iterations, bool) or not isinstance(response_iterations, int) \
                or response_iterations < 1:
            raise InvalidValue(f"Scene response_iterations must be an int >= 1, got {response_iterations!r}")
        self.response_iterations = response_iterations
        if isinstance(substeps, bool) or not isinstance(substeps, int) or substeps < 1:
            raise InvalidValue(f"Scene substeps must be an int >= 1, got {substeps!r}")
        self.substeps = substeps
        self.world = f"framework.scene.{next(_scene_ids)}"
        self.store = BodyStore()
        self.geometry = Geometry()
        self.hash = SpatialHash(cell_size)
        self.sleep_hash = SpatialHash(cell_size)  # the sleeping bodies, entered when they change
        self.tracker = PairTracker()
        self._renderer: Any = None
        self.resources: dict[type, Any] = {Input: Input()}
        # For the debug overlay: this step's rays (origin, end, first hit or None) and the swept
        # paths of continuous-detection bodies ((x0, y0), (x1, y1)).
        self.ray_log: list[tuple[tuple[float, float], tuple[float, float], SceneHit | None]] = []
        self.swept_paths: list[tuple[tuple[float, float], tuple[float, float]]] = []
        self.closed = False
        self.frame = 0
        self.time = 0.0
        self.counters: dict[str, Any] = {}
        self.stage_ms: dict[str, float] = {}
        self._systems: dict[tuple[str, str], list[System]] = {}
        self._handlers: list[tuple[type, type, Callable[..., Any], frozenset[str]]] = []
        self._stepping = False
        self._pending_despawn: list[int] = []
        self._ghosts: dict[int, set[type]] = {}
        self._contacts = StepContacts.empty()
        self._started = np.zeros(0, dtype=bool)
        self._ended = StepContacts.empty()
        self._events: list[CollisionEvent] | None = []
        self._support = _NO_SUPPORT
        self._resolved = _NO_RESOLVED
        self._n_static = 0
        self._internal_faces = InternalFaces()
        self._row_lookup = np.zeros(1, dtype=np.int64)
        self._moved = 0  # bumped whenever a stage moves bodies (see ensure_geometry)
        self._start_key: tuple[int, ...] | None = None
        self._start_buf = (np.zeros(0), np.zeros(0))
        self._geometry_stamp: tuple[int, ...] | None = None
        self._lookup_version = -1
        esper.switch_world(self.world)

    # --- entities ----------------------------------------------------------------------------

    def _activate(self) -> None:
        if self.closed:
            raise SceneClosed(f"scene {self.world!r} is closed")
        if esper.current_world != self.world:
            esper.switch_world(self.world)

    def spawn(self, *components: Any) -> int:
        """Create an entity with ``components``; return its id.

        A Hitbox needs a Transform; a static body has no Velocity. Nothing changes on error."""
        self._activate()
        kinds: dict[type, Any] = {}
        for comp in components:
            if comp is None or isinstance(comp, type):
                raise InvalidValue(f"spawn takes component instances, got {comp!r}")
            check_component(comp)
            if type(comp) in kinds:
                raise InvalidValue(f"spawn got two {type(comp).__name__} components: {components!r}")
            kinds[type(comp)] = comp
        t, v, h = kinds.get(Transform), kinds.get(Velocity), kinds.get(Hitbox)
        for comp in (t, v, h):
            if comp is not None and comp._store is not None:
                raise InvalidValue(f"{comp!r} already belongs to an entity; give each entity its own")
        if h is not None and t is None:
            raise InvalidValue("an entity with a Hitbox needs a Transform")
        if h is not None and h.body is Body.STATIC and v is not None:
            raise InvalidValue("a static body never moves: give it no Velocity (or make it kinematic)")
        if v is not None and t is None:
            raise InvalidValue("an entity with a Velocity needs a Transform")
        entity = esper.create_entity(*components)
        if t is not None:
            self.store.add(entity, t, v, h)
        return entity

    def despawn(self, entity: int) -> None:
        """Remove ``entity``; its pairs end (``ended`` events) in the next step's events.

        During a step (from a system or a handler) the removal waits until the step ends."""
        self._activate()
        if not self.exists(entity):
            raise InvalidValue(f"entity {entity!r} does not exist (despawned already?)")
        if self._stepping:
            self._pending_despawn.append(entity)
        else:
            self._remove(entity)

    def _remove(self, entity: int) -> None:
        comps = esper.components_for_entity(entity)
        self._ghosts[entity] = {type(c) for c in comps}
        store = self.store
        if entity in store.row_of:
            row = store.row_of[entity]
            if store.asleep.any() and store.kind[row] >= 0:
                # Whatever slept on or against it wakes.
                r = 1.1 * float(store.bound[row])
                x, y = float(store.x[row]), float(store.y[row])
                self.ensure_geometry()
                g = self.geometry
                near = (g.minx < x + r) & (g.maxx > x - r) & (g.miny < y + r) & (g.maxy > y - r)
                store.wake(np.flatnonzero(near & store.asleep))
            store.remove(entity, comps)
        esper.delete_entity(entity, immediate=True)

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
        if component is None or isinstance(component, type):
            raise InvalidValue(f"add_component takes a component instance, got {component!r}")
        store = self.store
        has_t = entity in store.row_of
        if isinstance(component, Transform):
            raise InvalidValue("a Transform is given at spawn and edited in place; it cannot be replaced")
        try:
            check_component(component)
        except InvalidValue as exc:
            raise InvalidValue(f"entity {entity}: {exc}") from None
        if isinstance(component, (Velocity, Hitbox)):
            if not has_t:
                raise InvalidValue(f"entity {entity} has no Transform")
            if component._store is not None:
                raise InvalidValue(f"{component!r} already belongs to an entity")
            hb = component if isinstance(component, Hitbox) else esper.try_component(entity, Hitbox)
            has_v = isinstance(component, Velocity) or esper.has_component(entity, Velocity)
            if hb is not None and hb.body is Body.STATIC and has_v:
                raise InvalidValue("a static body never moves: give it no Velocity")
        old = esper.try_component(entity, type(component))
        esper.add_component(entity, component)
        if isinstance(component, Velocity):
            if old is not None:
                store.unbind(entity, old)  # the replaced Velocity no longer writes to the row
            store.set_velocity(entity, component)
        elif isinstance(component, Hitbox):
            store.set_hitbox(entity, component)

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
        comp = esper.remove_component(entity, component_type)
        if component_type is Velocity and entity in self.store.row_of:
            self.store.unbind(entity, comp)  # before the row forgets its values
            self.store.set_velocity(entity, None)
        elif component_type is Hitbox and entity in self.store.row_of:
            self.store.set_hitbox(entity, None)
        return comp

    def get(self, entity: int, component_type: type) -> Any:
        """The ``component_type`` component of ``entity`` (KeyError if it has none)."""
        self._activate()
        return esper.component_for_entity(entity, component_type)

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

    # --- systems and handlers ----------------------------------------------------------------

    def add_system(self, system: System, *, before: str | None = None, after: str | None = None) -> None:
        """Run ``system(scene, dt)`` every step, before or after a stage (default: after response)."""
        if before is not None and after is not None:
            raise InvalidValue("give either before= or after=, not both")
        where = ("after", "response") if before is None and after is None else (
            ("before", before) if before is not None else ("after", after))
        if where[1] not in STAGES:
            raise InvalidValue(f"unknown stage {where[1]!r}; stages are {STAGES}")
        if not callable(system):
            raise InvalidValue(f"system must be callable as system(scene, dt), got {system!r}")
        self._systems.setdefault(where, []).append(system)

    def remove_system(self, system: System) -> None:
        for lst in self._systems.values():
            if system in lst:
                lst.remove(system)
                return
        raise InvalidValue(f"system {system!r} is not in this scene")

    def on_collision(
        self, type_a: type, type_b: type, handler: Callable[[Scene, CollisionEvent], Any],
        kinds: Iterable[str] = ("started",),
    ) -> None:
        """Call ``handler(scene, event)`` for collision events between an entity with a ``type_a``
        component and one with a ``type_b`` component. The event is turned so that ``event.a``
        is the ``type_a`` entity (its normal then points from it toward the ``type_b`` one).
        A handler that takes a single argument is called as ``handler(event)``. ``kinds`` may be
        one kind name or several."""
        ks = frozenset([kinds] if isinstance(kinds, str) else kinds)
        if not ks <= {"started", "ongoing", "ended"}:
            raise InvalidValue(f"kinds must be among 'started', 'ongoing', 'ended', got {sorted(ks)!r}")
        if not callable(handler):
            raise InvalidValue(f"handler must be callable, got {handler!r}")
        if _takes_one_argument(handler):
            one = handler
            handler = lambda scene, event: one(event)  # noqa: E731
        self._handlers.append((type_a, type_b, handler, ks))

    # --- stepping ----------------------------------------------------------------------------

    def step(self, dt: float) -> None:
        """Advance the scene by ``dt`` seconds (finite, > 0), in ``substeps`` equal sub-steps.

        A component holding NaN, inf or a non-number makes this raise ``ValueError`` naming the
        entity and the field, before anything changes. One that game code spoils during the step
        (from a system or a handler), or that overflows, is reported at the end of the step (which
        is then complete: frame, time and events included). With several sub-steps, each runs the whole
        pipeline (game systems and handlers included; rendering only after the last), the events
        of all sub-steps are reported in order, and the counters add up."""
        self._activate()
        if self._stepping:
            raise InvalidValue("step() was called from inside a step (a system or a collision handler)")
        dt = positive("dt", dt)
        self.store.check()
        n = self.substeps
        if n == 1:
            self._substep(dt, render=True, checked=True)
        else:
            frame_events: list[CollisionEvent] = []
            total: dict[str, Any] = {}
            for k in range(n):
                self._substep(dt / n, render=k == n - 1, checked=k == 0)
                frame_events.extend(self.events)
                _add_counters(total, self.counters)
            self._events = frame_events
            self.counters = total
        self.frame += 1
        self.time += dt
        inp = self.resources.get(Input)
        if inp is not None:
            inp.end_step()
        try:
            # A bad value written by game code during the step (a system or a handler), or a
            # motion that overflowed: reported now, by the step that made it.
            self.store.check()
        except InvalidValue as exc:
            raise InvalidValue(f"{exc} (at the end of step {self.frame}: written by a system or a collision "
                               "handler during the step, or an overflow)") from None

    def _substep(self, dt: float, render: bool, checked: bool = False) -> None:
        """One pass of the pipeline (``checked``: the store was just checked, nothing ran since)."""
        store = self.store
        self._stepping = True
        self.counters = counters = {"systems": [], "integrated": 0, "rehashed": 0, "candidate_pairs": 0,
                                    "narrow_tests": {}, "contacts": 0, "events": 0, "resolved": 0,
                                    "late_contacts": 0, "ccd_stopped": 0, "asleep": 0}
        self.stage_ms = {}
        self.ray_log = []
        self.swept_paths = []
        self._start_x = self._start_y = np.zeros(0)  # set by movement
        try:
            if not checked:
                store.check()
            store.apply_hitbox_changes()
            for stage in STAGES if render else STAGES[:-1]:
                self._run_hooks("before", stage, dt)
                t0 = time.perf_counter()
                ran = getattr(self, "_stage_" + stage)(dt)
                if ran:
                    counters["systems"].append(stage)
                    self.stage_ms[stage] = (time.perf_counter() - t0) * 1e3
                self._run_hooks("after", stage, dt)
            if "sleeping" in self.effects:
                self._update_sleep(dt)
            self._dispatch()
        finally:
            self._stepping = False
            pending, self._pending_despawn = self._pending_despawn, []
            for e in pending:
                if esper.entity_exists(e):
                    self._remove(e)

    def _run_hooks(self, when: str, stage: str, dt: float) -> None:
        for system in self._systems.get((when, stage), ()):
            system(self, dt)

    @property
    def renderer(self) -> Any:
        """The object whose ``draw(scene)`` is the render stage; attaching one declares rendering."""
        return self._renderer

    @renderer.setter
    def renderer(self, renderer: Any) -> None:
        self._renderer = renderer
        if renderer is not None:
            self.effects = resolve_effects(self.effects | {"rendering"})
        if renderer is not None and "debug_overlay" in self.effects and hasattr(renderer, "debug"):
            renderer.debug = True

    def _gravity(self) -> tuple[float, float]:
        return self.gravity if "gravity" in self.effects else (0.0, 0.0)

    def _stage_movement(self, dt: float) -> bool:
        if "movement" not in self.effects:
            return False
        store = self.store
        # Where every row starts the step (for one-way platforms and sleeping); static rows are
        # copied again only when the static set changed.
        key = (store.version, store.static_epoch, store.n)
        if key != self._start_key:
            self._start_buf = (store.x.copy(), store.y.copy())
            self._start_key = key
        else:
            sel = store.active_sel()[2]
            self._start_buf[0][sel], self._start_buf[1][sel] = store.x[sel], store.y[sel]
        self._start_x, self._start_y = self._start_buf
        movers = store.active()[0]
        ccd = movers[store.ccd[store.active_sel()[0]]]
        self._ccd_rows = ccd
        self._ccd_start = (store.x[ccd].copy(), store.y[ccd].copy())
        rows = integrate(store, dt, self._gravity())
        self._moved += 1
        self.counters["integrated"] = int(rows.size)
        return True

    def _stage_ccd(self, dt: float) -> bool:
        if "continuous" not in self.effects or "movement" not in self.effects:
            return False
        rows = self._ccd_rows
        store, geom = self.store, self.geometry
        if rows.size == 0 or rows.max() >= store.n:
            return False
        self.ensure_geometry()
        self._sync_static()
        stopped = sweep_ccd_bodies(
            store, geom, rows, *self._ccd_start, self._static_entities_in_box, self.counters
        )
        self.counters["ccd_stopped"] = stopped
        if stopped:
            self._moved += 1
        x0, y0 = self._ccd_start
        self.swept_paths = list(zip(zip(x0.tolist(), y0.tolist()),
                                    zip(store.x[rows].tolist(), store.y[rows].tolist())))
        return True

    def ensure_geometry(self) -> None:
        """Bring ``scene.geometry`` (hitbox origins and bounds) up to date, if anything moved.

        Queries, the renderer and the stages call this; it recomputes only after the pipeline or
        game code moved something (or the entities changed) since the last time."""
        store = self.store
        stamp = (self._moved, store.writes, store.version, store.n)
        if stamp != self._geometry_stamp:
            self.geometry.update(store)
            self._geometry_stamp = stamp

    def _static_entities_in_box(self, minx: float, miny: float, maxx: float, maxy: float) -> list[int]:
        ids = self.hash.query_box(minx, miny, maxx, maxy)
        rows = self._rows_of(ids)
        rows = rows[rows >= 0]
        return rows[self.store.body[rows] == STATIC].tolist()

    def _rows_of(self, entities: np.ndarray) -> np.ndarray:
        store = self.store
        if self._lookup_version != store.version:  # (every spawn and despawn bumps the version)
            size = (int(store.entity.max()) + 1) if store.n else 1
            lut = np.full(size, -1, dtype=np.int64)
            lut[store.entity] = np.arange(store.n)
            self._row_lookup, self._lookup_version = lut, store.version
        entities = np.asarray(entities, dtype=np.int64)
        out = np.full(entities.size, -1, dtype=np.int64)
        ok = entities < self._row_lookup.size
        out[ok] = self._row_lookup[entities[ok]]
        return out

    def _choose_cell_size(self, static_rows: np.ndarray) -> None:
        """The automatic cell: about twice the median extent of the moving bodies or of the static
        ones, whichever is larger, so small tiles do not make every mover span dozens of cells
        and small movers do not cut large tiles into many."""
        store, geom = self.store, self.geometry
        moving = np.flatnonzero((store.kind >= 0) & (store.body != STATIC))
        sizes = []
        for rows in (moving, static_rows):
            if rows.size:
                c = auto_cell_size(geom.minx[rows], geom.miny[rows], geom.maxx[rows], geom.maxy[rows])
                if c is not None:
                    sizes.append(c)
        if sizes:
            self.hash.set_cell_size(max(sizes))
            self.sleep_hash.set_cell_size(max(sizes))

    def _sync_static(self) -> None:
        store, geom = self.store, self.geometry
        if not store.static_dirty:
            return
        if store.asleep.any():  # the level changed under the sleepers
            store.wake(np.flatnonzero(store.asleep))
        rows = np.flatnonzero((store.kind >= 0) & (store.body == STATIC))
        if self.hash.cell_size is None:
            self._choose_cell_size(rows)
        self.hash.set_static(geom.minx[rows], geom.miny[rows], geom.maxx[rows], geom.maxy[rows],
                             store.entity[rows])
        self._n_static = int(rows.size)
        self.counters["rehashed"] = self.counters.get("rehashed", 0) + int(rows.size)
        store.static_dirty = False
        store.moved_static.clear()

    def _stage_broad_phase(self, dt: float) -> bool:
        if "detection" not in self.effects:
            return False
        store, geom = self.store, self.geometry
        self.ensure_geometry()
        self._sync_static()
        moving = store.active_sel()[1]  # a slice where the bodies are one run of rows: views, no gathers
        bounds = (geom.minx[moving], geom.miny[moving], geom.maxx[moving], geom.maxy[moving])
        ea, eb = self.hash.pairs(*bounds, store.entity[moving])
        self.counters["rehashed"] += int(store.active()[1].size)
        if store.sleep_dirty:
            sleepers = np.flatnonzero(store.asleep)
            self.sleep_hash.set_static(geom.minx[sleepers], geom.miny[sleepers], geom.maxx[sleepers],
                                       geom.maxy[sleepers], store.entity[sleepers])
            self.counters["rehashed"] += int(sleepers.size)
            store.sleep_dirty = False
        self.counters["asleep"] = n_asleep = int(np.count_nonzero(store.asleep[store.active_sel()[2]]))
        if n_asleep:
            sa, sb = self.sleep_hash.pairs(*bounds, store.entity[moving], moving_pairs=False)
            if sa.size:
                keys = np.concatenate([pair_keys(ea, eb), pair_keys(sa, sb)])
                keys.sort()
                ea, eb = keys >> 32, keys & 0xFFFFFFFF
        ra, rb = self._rows_of(ea), self._rows_of(eb)
        keep = filter_layers(store, ra, rb)
        if "events" not in self.effects:
            keep &= self._someone_reads(ra, rb)
        self._pairs = (ea[keep], eb[keep], ra[keep], rb[keep])
        self.counters["candidate_pairs"] = int(keep.sum())
        return True

    def _someone_reads(self, ra: np.ndarray, rb: np.ndarray) -> np.ndarray:
        """Without the events effect, only pairs the response or a handler reads are tested."""
        store = self.store
        need = np.zeros(ra.size, dtype=bool)
        if "response" in self.effects:
            need |= ~(store.sensor[ra] | store.sensor[rb]) & ((store.inv_mass[ra] > 0) | (store.inv_mass[rb] > 0))
        for ta, tb, _handler, _kinds in self._handlers:
            has_a, has_b = self._has_type(ta), self._has_type(tb)
            need |= (has_a[ra] & has_b[rb]) | (has_a[rb] & has_b[ra])
        return need

    def _has_type(self, component_type: type) -> np.ndarray:
        """Per row: whether the entity has a ``component_type`` component."""
        mask = np.zeros(self.store.n, dtype=bool)
        ents = [e for e, _ in esper.get_component(component_type)]
        if ents:
            rows = self._rows_of(np.array(ents, dtype=np.int64))
            mask[rows[rows >= 0]] = True
        return mask

    def _stage_narrow_phase(self, dt: float) -> bool:
        if "detection" not in self.effects:
            return False
        ea, eb, ra, rb = self._pairs
        if self.geometry.version != self.store.version:
            # A system changed hitboxes after the broad phase: measure the pairs as they are now.
            live = (self.store.kind[ra] >= 0) & (self.store.kind[rb] >= 0)
            ea, eb, ra, rb = ea[live], eb[live], ra[live], rb[live]
            self.geometry.update(self.store)
        res = pair_contacts(self.store, self.geometry, ra, rb, self.counters["narrow_tests"])
        h = np.flatnonzero(res.hit)
        contacts = StepContacts(ea[h], eb[h], res.nx[h], res.ny[h], res.depth[h], res.px[h], res.py[h])
        crows = (ra[h], rb[h])
        store = self.store
        if self.counters["asleep"]:
            # Pairs of sleeping (or sleeping and static) bodies are not tested: they keep the
            # contact they had, so their events stay "ongoing" while they sleep.
            prev = self.tracker.active
            pa, pb = self._rows_of(prev.a), self._rows_of(prev.b)
            ok = (pa >= 0) & (pb >= 0)
            idle = store.asleep | (store.body == STATIC)
            frozen = np.flatnonzero(ok & idle[np.maximum(pa, 0)] & idle[np.maximum(pb, 0)])
            if frozen.size:
                merged = [np.concatenate([x, y[frozen]]) for x, y in zip(contacts, prev)]
                order = np.lexsort((merged[1], merged[0]))
                contacts = StepContacts(*(m[order] for m in merged))
                crows = (np.concatenate([crows[0], pa[frozen]])[order],
                         np.concatenate([crows[1], pb[frozen]])[order])
            # A touch by an awake, solid body wakes a sleeper.
            a_, b_ = crows
            solid = ~(store.sensor[a_] | store.sensor[b_])
            wake_b = solid & store.asleep[b_] & ~store.asleep[a_] & (store.body[a_] != STATIC)
            wake_a = solid & store.asleep[a_] & ~store.asleep[b_] & (store.body[b_] != STATIC)
            woken = distinct(np.concatenate([b_[wake_b], a_[wake_a]]))
            if woken.size:
                store.wake(woken)
                contacts, crows = self._catch_up_woken(woken, dt, contacts, crows)
        self._contacts = contacts
        self._contact_rows = crows
        self._started, _ongoing, self._ended = self.tracker.update(self._contacts)

        self._events = None
        self.counters["contacts"] = int(self._contacts.a.size)
        self.counters["events"] = int(h.size + self._ended.a.size)
        return True

    def _catch_up_woken(self, woken: np.ndarray, dt: float, contacts: StepContacts,
                        crows: tuple[np.ndarray, np.ndarray]):
        """Bodies woken by a touch in this narrow phase slept through the movement stage: move them
        now as it would have (a body resting on the floor sinks into it by gravity's step, as an
        awake one does, and the response pushes it out), then measure their contacts again: those
        kept from last step are as the narrow phase found them before that step's response moved
        the body. A contact now apart is dropped. So a woken body's contacts are real ones, and a
        resting body bumped awake keeps its floor contact (``ongoing``) rather than ending it."""
        store = self.store
        if "movement" in self.effects:
            integrate_rows(store, woken, dt, self._gravity())
            self._moved += 1
            self.geometry.update_rows(store, woken)
        flag = np.zeros(store.n, dtype=bool)
        flag[woken] = True
        stale = np.flatnonzero(flag[crows[0]] | flag[crows[1]])
        if stale.size == 0:
            return contacts, crows
        r = pair_contacts(store, self.geometry, crows[0][stale], crows[1][stale])
        cols = [c.copy() for c in contacts]
        for col, new in zip(cols[2:], (r.nx, r.ny, r.depth, r.px, r.py)):
            col[stale] = new
        keep = np.ones(contacts.a.size, dtype=bool)
        keep[stale[~r.hit]] = False
        return StepContacts(*(c[keep] for c in cols)), (crows[0][keep], crows[1][keep])

    def _stage_response(self, dt: float) -> bool:
        if "response" not in self.effects:
            return False
        store = self.store
        c = self._contacts
        # This step's contacts, plus the pairs the response resolved last step that no longer
        # overlap: bodies resting on each other fall by the same amount and merely touch, and
        # overlap again once the body below is pushed up (see response.resolve).
        sa, sb, snx, sny = self._support
        old = ~sorted_member(pair_keys(sa, sb), pair_keys(c.a, c.b))
        sra, srb = self._rows_of(sa[old]), self._rows_of(sb[old])
        live = (sra >= 0) & (srb >= 0)
        ok = np.flatnonzero(live)  # ...and both still have hitboxes whose layers meet
        live[ok] = (store.kind[sra[ok]] >= 0) & (store.kind[srb[ok]] >= 0) & filter_layers(store, sra[ok], srb[ok])
        ra = np.concatenate([self._contact_rows[0], sra[live]])
        rb = np.concatenate([self._contact_rows[1], srb[live]])
        ents_a = np.concatenate([c.a, sa[old][live]])
        ents_b = np.concatenate([c.b, sb[old][live]])
        nx, ny = np.concatenate([c.nx, snx[old][live]]), np.concatenate([c.ny, sny[old][live]])
        depth = np.concatenate([c.depth, self._support_gaps(sra[live], srb[live], snx[old][live], sny[old][live])])
        alive0 = np.arange(ra.size) < c.a.size
        self._support = _NO_SUPPORT
        self._resolved = _NO_RESOLVED
        if ra.size and ra.max() >= store.n:  # rows spawned mid-step are not in this step
            return False
        inv, asleep = store.inv_mass, store.asleep  # sleeping bodies keep still
        movable_a, movable_b = (inv[ra] > 0) & ~asleep[ra], (inv[rb] > 0) & ~asleep[rb]
        solid = ~(store.sensor[ra] | store.sensor[rb]) & (movable_a | movable_b)
        solid &= (store.kind[ra] >= 0) & (store.kind[rb] >= 0)  # a system may have removed a hitbox
        one_way = store.one_way[ra] | store.one_way[rb]
        if one_way.any():
            solid &= ~one_way | self._lands_on_one_way(ra, rb, nx, ny, depth, alive0)
        idx = np.flatnonzero(solid)
        if idx.size == 0:
            return True
        every = idx.size == ra.size  # (then the columns are used as they are, not gathered)
        pa, pb = (ra, rb) if every else (ra[idx], rb[idx])
        geom = self.geometry

        # Push-outs avoid the internal faces of tiles (only looked at when a static is touched).
        faces = self._n_static > 0 and bool(((store.body[pa] == STATIC) | (store.body[pb] == STATIC)).any())

        def recompute(a: np.ndarray, b: np.ndarray):
            if geom.version != store.version:
                geom.update(store)
            elif geom.has_offset:  # hitbox origins of just these rows
                geom.update_rows(store, np.concatenate([a, b]))
            else:  # origins are the positions
                geom.hx, geom.hy = store.x, store.y
            r = pair_contacts(store, geom, a, b, remeasure=True)
            rank = r.depth.copy()
            if faces:
                self._internal_faces.redirect(store, geom, self.hash, self._rows_of, a, b, r.nx, r.ny, r.depth, r.hit,
                                              rank)
            return r.hit, r.nx, r.ny, r.depth, rank

        self._moved += 1
        if not every:
            nx, ny, depth, alive0 = nx[idx], ny[idx], depth[idx], alive0[idx]
        rank = None
        if faces:
            rank = depth.copy()
            self._internal_faces.redirect(store, geom, self.hash, self._rows_of, pa, pb, nx, ny, depth, alive0, rank)
        done, anx, any_, pushed = resolve(store, pa, pb, nx, ny, depth, self._gravity(),
                                          self.response_iterations, recompute, alive0, dt, rank)
        snx, sny = nx, ny
        if done.all():
            ea, eb = (ents_a, ents_b) if every else (ents_a[idx], ents_b[idx])
        else:
            ea, eb = ents_a[idx[done]], ents_b[idx[done]]
            snx, sny = nx[done], ny[done]
            anx, any_, pushed = anx[done], any_[done], pushed[done]
        # Bodies pushed by other dynamic bodies may have been shoved into static geometry they did
        # not touch when the step's contacts were found (a pile spawned on one spot): find those
        # contacts now and push them out, so no body ends the step inside a static it can fall
        # through. Pushes out of statics themselves need no such look (they move away from them).
        if self._n_static:
            dd = idx[done]
            dd = dd[(store.inv_mass[ra[dd]] > 0) & (store.inv_mass[rb[dd]] > 0)]
            pushed_rows = distinct(np.concatenate([ra[dd], rb[dd]]))  # (not a flag per row: 100k tiles)
        else:
            pushed_rows = idx[:0]
        for _ in range(max(1, self.response_iterations)):
            if pushed_rows.size == 0 or self._n_static == 0:
                break
            extra = self._new_static_contacts(pushed_rows, ea, eb)
            if extra is None:
                break
            xa, xb, xra, xrb, xr = extra
            xrank = xr.depth.copy()
            self._internal_faces.redirect(store, geom, self.hash, self._rows_of, xra, xrb, xr.nx, xr.ny, xr.depth,
                                          xr.hit, xrank)
            xdone, xanx, xany, xpushed = resolve(store, xra, xrb, xr.nx, xr.ny, xr.depth, self._gravity(),
                                                 self.response_iterations, recompute, xr.hit, dt, xrank)
            ea, eb = np.concatenate([ea, xa[xdone]]), np.concatenate([eb, xb[xdone]])
            snx, sny = np.concatenate([snx, xr.nx[xdone]]), np.concatenate([sny, xr.ny[xdone]])
            anx, any_ = np.concatenate([anx, xanx[xdone]]), np.concatenate([any_, xany[xdone]])
            pushed = np.concatenate([pushed, xpushed[xdone]])
            pushed_rows = distinct(np.where(store.inv_mass[xra] > 0, xra, xrb)[xdone])
            self.counters["late_contacts"] += int(xdone.sum())
        self._moved += 1
        keys = pair_keys(ea, eb)
        if keys.size > 1 and not (keys[1:] > keys[:-1]).all():  # late contacts were appended
            order = np.argsort(keys, kind="stable")
            ea, eb, snx, sny, anx, any_, pushed = (v[order] for v in (ea, eb, snx, sny, anx, any_, pushed))
        self._resolved = (ea, eb, anx, any_, pushed)
        # Kept for the next step: the pairs that rest one on the other (normal within 60 degrees of
        # the vertical), which gravity presses together again; none without gravity.
        gx, gy = self._gravity()
        g = math.hypot(gx, gy)
        if g > 0.0:
            keep = np.flatnonzero(np.abs(snx * gx + sny * gy) > 0.5 * g)
            self._support = (ea[keep], eb[keep], snx[keep], sny[keep])
        else:
            self._support = _NO_SUPPORT
        self.counters["resolved"] = int(ea.size)
        return True

    def _support_gaps(self, ra: np.ndarray, rb: np.ndarray, nx: np.ndarray, ny: np.ndarray) -> np.ndarray:
        """The depth (<= 0) of last step's resting pairs that no longer overlap: how far apart the
        step's movement took them along their normal. They touched when it began; a pair that
        fell together stays at 0 (and is resolved again if a push below makes them overlap),
        one flying apart starts this far from touching, so a small push below does not count
        as an overlap (a box bouncing off a base kept being pushed by it, a little every step)."""
        sx, sy, store = self._start_x, self._start_y, self.store
        if ra.size == 0 or sx.size <= max(int(ra.max()), int(rb.max())):
            return np.zeros(ra.size)
        gap = (((store.x[rb] - sx[rb]) - (store.x[ra] - sx[ra])) * nx
               + ((store.y[rb] - sy[rb]) - (store.y[ra] - sy[ra])) * ny)
        return np.minimum(-gap, 0.0)

    def _new_static_contacts(self, rows: np.ndarray, known_a: np.ndarray, known_b: np.ndarray):
        """Overlaps of ``rows`` (dynamic, just moved) with static bodies, other than the pairs
        ``(known_a, known_b)`` (entities, either order): ``(ents_a, ents_b, rows_a, rows_b, contacts)``
        or None."""
        store, geom = self.store, self.geometry
        # First a cheap look with bounds that hold the hitbox at any rotation (its bounding circle
        # about the body's position): most bodies have no static in their cells, and their exact
        # bounds are not needed; nor are any when all of them lie outside the statics' extent.
        reach = store.bound[rows] + np.hypot(store.ox[rows], store.oy[rows]) if geom.has_offset else store.bound[rows]
        x, y = store.x[rows], store.y[rows]
        box = (np.nextafter(x - reach, -np.inf), np.nextafter(y - reach, -np.inf),
               np.nextafter(x + reach, np.inf), np.nextafter(y + reach, np.inf))
        if self.hash.outside_statics(*(f(v) for f, v in zip((np.min, np.min, np.max, np.max), box))):
            return None
        near = self.hash.near_statics(*box) & (store.kind[rows] >= 0) & ~store.asleep[rows] & ~store.sensor[rows]
        rows = rows[near]
        if rows.size == 0:
            return None
        geom.update_rows(store, rows)
        ea, eb = self.hash.static_pairs(geom.minx[rows], geom.miny[rows], geom.maxx[rows], geom.maxy[rows],
                                        store.entity[rows])
        if ea.size == 0:
            return None
        ra, rb = self._rows_of(ea), self._rows_of(eb)
        keep = filter_layers(store, ra, rb) & ~(store.sensor[ra] | store.sensor[rb])
        keep &= ~(store.one_way[ra] | store.one_way[rb])  # a platform is passed through from below
        keep &= ~np.isin(pair_keys(ea, eb), np.concatenate([pair_keys(known_a, known_b), pair_keys(known_b, known_a)]))
        if not keep.any():
            return None
        ea, eb, ra, rb = ea[keep], eb[keep], ra[keep], rb[keep]
        r = pair_contacts(store, geom, ra, rb, remeasure=True)
        if not r.hit.any():
            return None
        h = np.flatnonzero(r.hit)
        return ea[h], eb[h], ra[h], rb[h], batch.ContactArrays(*(v[h] for v in r))

    def _update_sleep(self, dt: float) -> None:
        """Count the steps each awake dynamic body has been at rest; put the restful to sleep."""
        store = self.store
        n0 = self._start_x.size
        if n0 == 0:
            return
        c = store.cols
        rows = np.flatnonzero((store.body[:n0] == 0) & (store.kind[:n0] >= 0) & ~store.asleep[:n0])
        if rows.size == 0:
            return
        tol = SLEEP_SPEED * (1.0 + store.bound[rows])
        moved = np.abs(store.x[rows] - self._start_x[rows]) + np.abs(store.y[rows] - self._start_y[rows])
        speed = np.abs(store.vx[rows]) + np.abs(store.vy[rows]) + np.abs(store.w[rows]) * store.bound[rows]
        rest = (moved <= tol * dt) & (speed <= tol)
        still = c["still"]
        still[rows] = np.where(rest, still[rows] + 1, 0)
        sleepy = rows[still[rows] >= SLEEP_STEPS]
        if sleepy.size:
            sleepy = self._whole_islands(sleepy)
        if sleepy.size:
            c["asleep"][sleepy] = True
            c["vx"][sleepy] = c["vy"][sleepy] = c["w"][sleepy] = 0.0
            store.sleep_dirty = True

    def _whole_islands(self, ready_rows: np.ndarray) -> np.ndarray:
        """The ready rows whose whole group of touching dynamic bodies is ready (or asleep).

        A stack sleeps as one: a body touching an awake, restless dynamic body stays awake, and
        so, in turn, does whatever touches it."""
        store = self.store
        ready = np.zeros(store.n, dtype=bool)
        ready[ready_rows] = True
        ra, rb = self._contact_rows
        sa, sb = self._rows_of(self._support[0]), self._rows_of(self._support[1])
        ea = np.concatenate([ra, sa])
        eb = np.concatenate([rb, sb])
        ok = (ea >= 0) & (eb >= 0) & (ea < store.n) & (eb < store.n)
        ea, eb = ea[ok], eb[ok]
        restless = (store.body == 0) & ~store.asleep
        for _ in range(store.n):
            blocked_a = ready[ea] & restless[eb] & ~ready[eb]
            blocked_b = ready[eb] & restless[ea] & ~ready[ea]
            if not (blocked_a.any() or blocked_b.any()):
                break
            ready[ea[blocked_a]] = False
            ready[eb[blocked_b]] = False
        return ready_rows[ready[ready_rows]]

    def _lands_on_one_way(self, ra, rb, nx, ny, depth, alive0) -> np.ndarray:
        """Mask of contacts a one-way platform takes: the other body comes from above (the
        normal within 45 degrees of the platform's up) and sank in only by this step's motion."""
        store = self.store
        plat_is_a = store.one_way[ra]
        plat = np.where(plat_is_a, ra, rb)
        other = np.where(plat_is_a, rb, ra)
        rot = store.rot[plat]
        ux, uy = -np.sin(rot), np.cos(rot)
        toward_other = np.where(plat_is_a, 1.0, -1.0)
        from_above = (nx * ux + ny * uy) * toward_other > 0.7071
        # Where each body started the step (rows spawned during the step: where they are).
        x0, y0 = store.x.copy(), store.y.copy()
        n0 = self._start_x.size
        x0[:n0], y0[:n0] = self._start_x, self._start_y
        dx = (store.x[other] - x0[other]) - (store.x[plat] - x0[plat])
        dy = (store.y[other] - y0[other]) - (store.y[plat] - y0[plat])
        sank = -(dx * ux + dy * uy)
        tol = 1e-9 * (1.0 + store.bound[other])
        came_down = depth <= np.maximum(sank, 0.0) + tol
        return from_above & (came_down | ~alive0)

    def _stage_render(self, dt: float) -> bool:
        if self._renderer is None or "rendering" not in self.effects:
            return False
        self.renderer.draw(self)
        return True

    # --- events ------------------------------------------------------------------------------

    @property
    def events(self) -> list[CollisionEvent]:
        """This step's collision events, sorted by pair (a, b): ended, then started or ongoing."""
        if self._events is None:
            self._events = to_events(self._contacts, self._started, ~self._started, self._ended)
        return self._events

    @property
    def resolved(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The contacts the response actually applied this step, as arrays ``(a, b, nx, ny,
        pushed)`` (entity ids a < b, the normal from a to b it pushed along, the total push-out),
        sorted by pair. A contact the response discarded (the sliver of a tile under a body
        pushed into a wall, once the wall's push freed it) is not here: a game asking "am I
        standing on something?" should look here, not at every contact."""
        return self._resolved

    @property
    def contacts(self) -> StepContacts:
        """This step's overlapping pairs as arrays (entity ids a < b, normal from a to b)."""
        return self._contacts

    def _dispatch(self) -> None:
        if not self._handlers:
            self._ghosts.clear()
            return
        events = self.events
        if not events:
            self._ghosts.clear()
            return
        ghosts = self._ghosts

        def has(e: int, t: type) -> bool:
            if e in ghosts:
                return t in ghosts[e]
            return esper.has_component(e, t)

        for ev in events:
            for ta, tb, handler, ks in self._handlers:
                if ev.kind not in ks:
                    continue
                if has(ev.a, ta) and has(ev.b, tb):
                    handler(self, ev)
                elif has(ev.b, ta) and has(ev.a, tb):
                    handler(self, ev.flipped())
        self._ghosts = {}

    # --- queries -----------------------------------------------------------------------------

    def _candidate_rows(self, minx: float, miny: float, maxx: float, maxy: float) -> np.ndarray:
        """Rows whose current bounds strictly meet the box: statics via the hash, moving bodies by
        one vectorised test over their current bounds."""
        store, geom = self.store, self.geometry
        self.ensure_geometry()
        self._sync_static()
        st = self._rows_of(self.hash.query_box(minx, miny, maxx, maxy))
        st = st[(st >= 0)]
        st = st[store.body[st] == STATIC]
        mv = np.flatnonzero((store.kind >= 0) & (store.body != STATIC))
        hit = (geom.minx[mv] < maxx) & (geom.maxx[mv] > minx) & (geom.miny[mv] < maxy) & (geom.maxy[mv] > miny)
        return np.concatenate([st, mv[hit]])

    def _mask_ok(self, rows: np.ndarray, mask: int) -> np.ndarray:
        return rows[(self.store.layer[rows] & mask) != 0]

    def raycast_all(
        self, origin: tuple[float, float], direction: tuple[float, float], max_distance: float = math.inf,
        mask: int = _ALL_BITS,
    ) -> list[SceneHit]:
        """Every hitbox the ray enters within ``max_distance``, nearest first (ties by entity)."""
        self._activate()
        ox, oy = vector2("origin", origin)
        dx, dy = vector2("direction", direction)
        if dx == 0.0 and dy == 0.0:
            raise InvalidValue(f"direction must not be zero, got {direction!r}")
        md = float(max_distance) if not isinstance(max_distance, bool) else math.nan
        if not md >= 0.0:
            raise InvalidValue(f"max_distance must be >= 0, got {max_distance!r}")
        ln = math.hypot(dx, dy)
        reach = md if math.isfinite(md) else self._world_extent(ox, oy)
        ex, ey = ox + dx / ln * reach, oy + dy / ln * reach
        rows = self._candidate_rows(min(ox, ex) - 1e-9, min(oy, ey) - 1e-9, max(ox, ex) + 1e-9,
                                    max(oy, ey) + 1e-9)
        rows = self._mask_ok(rows, mask)
        hits = []
        geom, store = self.geometry, self.store
        for r in rows.tolist():
            hb = store.hitboxes[r]
            hit = _raycast(hb.shape, (float(geom.hx[r]), float(geom.hy[r]), float(store.rot[r])),
                           (ox, oy), (dx, dy), md)
            if hit is not None:
                hits.append(SceneHit(int(store.entity[r]), *hit))
        hits.sort(key=lambda h: (h.distance, h.entity))
        self.ray_log.append(((ox, oy), (ex, ey), hits[0] if hits else None))
        return hits

    def raycast(self, origin: tuple[float, float], direction: tuple[float, float],
                max_distance: float = math.inf, mask: int = _ALL_BITS) -> SceneHit | None:
        """The first hitbox the ray enters within ``max_distance``, or ``None``."""
        hits = self.raycast_all(origin, direction, max_distance, mask)
        return hits[0] if hits else None

    def _world_extent(self, ox: float, oy: float) -> float:
        g = self.geometry
        self.ensure_geometry()
        if self.store.n == 0:
            return 1.0
        far = max(abs(float(g.minx.min()) - ox), abs(float(g.maxx.max()) - ox),
                  abs(float(g.miny.min()) - oy), abs(float(g.maxy.max()) - oy))
        return 2.0 * far + 1.0

    def query_box(self, minx: float, miny: float, maxx: float, maxy: float, mask: int = _ALL_BITS) -> list[int]:
        """Entities whose hitbox interiors overlap the box's interior, sorted."""
        self._activate()
        x0, y0, x1, y1 = (finite(n, v) for n, v in zip(("minx", "miny", "maxx", "maxy"), (minx, miny, maxx, maxy)))
        if not (x1 > x0 and y1 > y0):
            raise InvalidValue(f"query_box needs maxx > minx and maxy > miny, got {(minx, miny, maxx, maxy)!r}")
        box = AABB(x1 - x0, y1 - y0)
        return self._overlapping(box, ((x0 + x1) * 0.5, (y0 + y1) * 0.5), mask, (x0, y0, x1, y1))

    def query_point(self, x: float, y: float, mask: int = _ALL_BITS) -> list[int]:
        """Entities whose hitbox contains the point (closed: a point on the boundary counts)."""
        self._activate()
        px, py = finite("x", x), finite("y", y)
        rows = self._mask_ok(self._candidate_rows(px - 1e-9, py - 1e-9, px + 1e-9, py + 1e-9), mask)
        out = []
        for r in rows.tolist():
            if self._contains(r, px, py):
                out.append(int(self.store.entity[r]))
        return sorted(out)

    def _contains(self, r: int, px: float, py: float) -> bool:
        store, geom = self.store, self.geometry
        hb = store.hitboxes[r]
        dx, dy = px - float(geom.hx[r]), py - float(geom.hy[r])
        shape = hb.shape
        if isinstance(shape, Circle):
            return dx * dx + dy * dy <= shape.radius * shape.radius
        verts, count = geom.outlines(store, np.array([r]))
        pts = verts[0, : int(count[0])]
        for i in range(len(pts)):
            x0, y0 = pts[i]
            x1, y1 = pts[(i + 1) % len(pts)]
            if (x1 - x0) * (dy - y0) - (y1 - y0) * (dx - x0) < 0.0:
                return False
        return True

    def _overlapping(self, shape: Any, center: tuple[float, float], mask: int, box: tuple) -> list[int]:
        rows = self._mask_ok(self._candidate_rows(*box), mask)
        store, geom = self.store, self.geometry
        check_shape("shape", shape)
        if rows.size == 0:
            return []
        shapes_b = [store.hitboxes[r].shape for r in rows.tolist()]
        poses_b = list(zip(geom.hx[rows].tolist(), geom.hy[rows].tolist(), store.rot[rows].tolist()))
        res = batch.collide_many([shape] * rows.size, [center] * rows.size, shapes_b, poses_b)
        return sorted(int(e) for e in store.entity[rows[res.hit]])

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
