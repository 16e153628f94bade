"""Scene snapshots: save a scene's state between steps, restore it later, replay bit for bit.

A :class:`Snapshot` holds everything a later step depends on: the entities and their components
(the game's own included), the body store and what the pipeline derives from it (geometry, spatial
hashes), the step's frame (contacts, events, the solver's warm-start data), each stage's own state
(pair tracking, sleeping, caches), the step counter and clock, and the scene's resources. What it
does not hold is the scene's *shape*, the code: its systems, processors and collision handlers,
which a scene gets by being built (``Game()``, say). So a snapshot restores into the scene it came
from, or into another scene built the same way, in this process or another one: a snapshot
pickles (its state is one ``bytes`` inside). Restoring into a scene of another shape, or from
another version of the framework, is an :class:`~framework.validation.InvalidValue` and changes
nothing.

Resources are restored in place: a resource object gets back the attributes it had (so
``game.state`` and ``scene.resources[GameState]`` stay one object, in the scene restored into), and
a reference to a resource, from a component or another resource, stays a reference to that
scene's resource. A resource that cannot be pickled (one holding a generator, say) is left out of
the snapshot and keeps its current value on restore (``Snapshot.skipped`` names them). A
component that cannot be pickled is an error naming the entity and the component. Component
objects are new after a restore: fetch them again (``scene.get``).

Snapshots use :mod:`pickle`: fine between the processes of one program; never restore one from
a file a stranger gave you (unpickling runs code). For that, :mod:`framework.snapshot_file` writes
and reads the same state without pickle.
"""

from __future__ import annotations

import io
import itertools
import pickle
import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import esper

from .validation import InvalidValue

if TYPE_CHECKING:
    from .scene import Scene

__all__ = ["SNAPSHOT_VERSION", "Snapshot", "restore", "take"]

SNAPSHOT_VERSION = 1
# Pipeline fields that belong to the scene object, not its state.
_PIPELINE_OWN = ("bodies", "renderer", "view", "wanted_pairs")
_STAGE_OWN = ("pipeline", "bodies", "priority", "wanted_for")
_SCENE_FIELDS = ("frame", "time", "_totals")


@dataclass(frozen=True)
class Snapshot:
    """A scene's state at the end of step ``frame`` (see the module docstring). ``shape``: the
    systems, processors and handlers of the scene it came from; ``skipped``: the resources that
    could not be saved (by type name)."""

    version: int
    framework: str
    shape: tuple[Any, ...]
    frame: int
    data: bytes = field(repr=False)
    skipped: tuple[str, ...] = ()

    @property
    def size(self) -> int:
        """Bytes of saved state."""
        return len(self.data)


def _name(obj: Any) -> str:
    return f"{getattr(obj, '__module__', '?')}.{getattr(obj, '__qualname__', type(obj).__qualname__)}"


def scene_shape(scene: Scene) -> tuple[Any, ...]:
    """What a scene is built of (its code, not its state): the processors of its esper world in
    order (stages by name, game systems by function), and its collision handlers' types and kinds."""
    from .systems.stage import Stage, SystemProcessor

    scene._activate()
    procs: list[tuple[Any, ...]] = []
    for p in esper._processors:
        if isinstance(p, Stage):
            procs.append(("stage", p.name, p.priority))
        elif isinstance(p, SystemProcessor):
            procs.append(("system", _name(p.system), p.stage, p.priority))
        else:
            procs.append(("processor", _name(type(p)), p.priority))
    handlers = tuple((_name(a), _name(b), tuple(sorted(kinds))) for a, b, _h, kinds in scene.handlers._handlers)
    return (tuple(procs), handlers, scene.substeps)


class _Pickler(pickle.Pickler):
    """Pickles a scene's state; the scene's own objects (the scene, its pipeline, bodies, renderer,
    stages) are written as references that :class:`_Unpickler` resolves to the target scene's."""

    def __init__(self, buf: io.BytesIO, refs: dict[int, str]) -> None:
        super().__init__(buf, protocol=pickle.HIGHEST_PROTOCOL)
        self.refs = refs

    def persistent_id(self, obj: Any) -> str | None:
        return self.refs.get(id(obj))


class _Unpickler(pickle.Unpickler):
    def __init__(self, buf: io.BytesIO, objects: dict[str, Any]) -> None:
        super().__init__(buf)
        self.objects = objects

    def persistent_load(self, pid: Any) -> Any:
        return self.objects[pid]


def _own_objects(scene: Scene) -> dict[str, Any]:
    """The scene's own objects, by reference name: kept by a restore, never copied."""
    pipeline = scene._pipeline
    objects: dict[str, Any] = {"scene": scene, "pipeline": pipeline, "bodies": scene.bodies,
                               "handlers": scene.handlers, "queries": scene._queries}
    if pipeline.renderer is not None:
        objects["renderer"] = pipeline.renderer
    for name, stage in scene._stages.items():
        objects[f"stage:{name}"] = stage
    for i, proc in enumerate(scene._systems):
        objects[f"system:{i}"] = proc
    return objects


def _dumps(value: Any, refs: dict[int, str]) -> bytes:
    buf = io.BytesIO()
    _Pickler(buf, refs).dump(value)
    return buf.getvalue()


def collect_state(scene: Scene) -> tuple[dict[str, Any], dict[int, str]]:
    """The scene's state (see the module docstring) and the references to its own objects and
    resources (``id(object) -> name``) that a saved copy writes by name."""
    scene._activate()
    if scene._stepping:
        raise InvalidValue("snapshot() was called from inside a step (a system or a collision handler)")
    objects = _own_objects(scene)
    refs = {id(obj): name for name, obj in objects.items()}
    for key, value in scene.resources.items():  # a reference to a resource stays one to the resource
        refs.setdefault(id(value), f"resource:{_name(key)}")
    entities = {e: dict(comps) for e, comps in esper._entities.items()}
    count = int(re.fullmatch(r"count\((-?\d+)\)", repr(esper._entity_count)).group(1))  # type: ignore[union-attr]
    state: dict[str, Any] = {
        "esper": {"entities": entities, "next": count, "dead": set(esper._dead_entities)},
        "bodies": dict(scene.bodies.__dict__),
        "pipeline": {k: v for k, v in scene._pipeline.__dict__.items() if k not in _PIPELINE_OWN},
        "stages": {name: {k: v for k, v in stage.__dict__.items() if k not in _STAGE_OWN}
                   for name, stage in scene._stages.items()},
        "scene": {k: getattr(scene, k) for k in _SCENE_FIELDS},
        "pending": list(scene._pending_despawn),
    }
    return state, refs


def resource_parts(scene: Scene) -> list[tuple[str, Any, type, bool, Any]]:
    """Each resource as ``(name, key, type, in place, payload)``: its attributes where it has
    them (restored into the very object the game holds), else its value."""
    out = []
    for key, value in scene.resources.items():
        in_place = hasattr(value, "__dict__")
        out.append((_name(key), key, type(value), in_place, dict(value.__dict__) if in_place else value))
    return out


def take(scene: Scene) -> Snapshot:
    """The state of ``scene`` now (between steps); see :meth:`framework.scene.Scene.snapshot`."""
    from . import __version__

    state, refs = collect_state(scene)
    try:
        data = _dumps(state, refs)
    except Exception as exc:
        _name_unpicklable(state["esper"]["entities"], refs)
        raise InvalidValue(f"the scene's state cannot be saved: {exc}") from exc
    headers, payloads, skipped = [], {}, []
    for name, key, cls, in_place, payload in resource_parts(scene):
        try:
            _dumps((key, cls, payload), refs)
        except Exception:
            skipped.append(name)  # one that cannot be pickled is left out
            continue
        headers.append((name, key, cls, in_place))
        payloads[name] = payload
    blob = pickle.dumps((data, _dumps(headers, {}), _dumps(payloads, refs)), protocol=pickle.HIGHEST_PROTOCOL)
    return Snapshot(SNAPSHOT_VERSION, __version__, scene_shape(scene), scene.frame, blob, tuple(sorted(skipped)))


def _name_unpicklable(entities: dict[int, dict[type, Any]], refs: dict[int, str]) -> None:
    """Raise :class:`InvalidValue` naming the first entity and component that cannot be pickled."""
    for e in sorted(entities):
        for kind, comp in entities[e].items():
            try:
                _dumps(comp, refs)
            except Exception as exc:
                raise InvalidValue(f"entity {e}: its {kind.__name__} component cannot be saved in a snapshot "
                                   f"({exc}); components must be picklable") from exc


def check_shape(scene: Scene, shape: Any, what: str = "snapshot") -> None:
    """``InvalidValue`` unless ``shape`` is the scene's (see :func:`scene_shape`)."""
    now = scene_shape(scene)
    if shape != now:
        raise InvalidValue(f"the {what} is from a scene of another shape (other systems, processors, collision "
                           f"handlers or substeps): {_shape_difference(shape, now)}")


def resource_targets(scene: Scene, headers: list[tuple[str, Any, type, bool]],
                     objects: dict[str, Any]) -> dict[str, tuple[Any, Any]]:
    """Where each saved resource goes: ``name -> (key, the object its attributes go into, or
    None to replace the value)``; registers every resource object in ``objects`` by reference name."""
    current = {_name(key): value for key, value in scene.resources.items()}
    for key, value in scene.resources.items():
        objects[f"resource:{_name(key)}"] = value
    targets = {}
    for name, key, cls, in_place in headers:
        obj = current.get(name)
        if in_place and (obj is None or type(obj) is not cls or not hasattr(obj, "__dict__")):
            obj = cls.__new__(cls)  # type: ignore[call-overload]  # a resource the scene lacks: a new one
        objects[f"resource:{name}"] = obj if in_place else objects.get(f"resource:{name}")
        targets[name] = (key, obj if in_place else None)
    return targets


def restore(scene: Scene, snapshot: Snapshot) -> None:
    """Put ``scene`` back in the state ``snapshot`` saved; see :meth:`framework.scene.Scene.restore`."""
    from . import __version__

    scene._activate()
    if scene._stepping:
        raise InvalidValue("restore() was called from inside a step (a system or a collision handler)")
    if not isinstance(snapshot, Snapshot):
        raise InvalidValue(f"restore takes a Snapshot (from scene.snapshot()), got {type(snapshot).__name__}")
    if snapshot.version != SNAPSHOT_VERSION or snapshot.framework != __version__:
        raise InvalidValue(f"the snapshot is from another version (snapshot format {snapshot.version}, framework "
                           f"{snapshot.framework!r}; this is format {SNAPSHOT_VERSION}, framework {__version__!r})")
    check_shape(scene, snapshot.shape)
    objects = _own_objects(scene)
    try:
        data, header_blob, payload_blob = pickle.loads(snapshot.data)
        targets = resource_targets(scene, pickle.loads(header_blob), objects)
        state = _Unpickler(io.BytesIO(data), objects).load()
        payloads = _Unpickler(io.BytesIO(payload_blob), objects).load()
    except Exception as exc:
        raise InvalidValue(f"the snapshot cannot be read: {exc}") from exc
    apply_state(scene, state, targets, payloads)


def apply_state(scene: Scene, state: dict[str, Any], targets: dict[str, tuple[Any, Any]],
                payloads: dict[str, Any]) -> None:
    """Replace the scene's state by ``state`` and its resources by ``payloads`` (everything was
    read and checked before: from here on nothing can fail halfway)."""
    world = state["esper"]
    esper._entities.clear()
    esper._entities.update(world["entities"])
    esper._components.clear()
    for e, comps in world["entities"].items():
        for kind in comps:
            esper._components.setdefault(kind, set()).add(e)
    esper._dead_entities.clear()
    esper._dead_entities.update(world["dead"])
    esper._entity_count = itertools.count(world["next"])
    esper._get_component_cache.clear()
    esper._get_components_cache.clear()
    esper._cache_dirty = True
    scene.bodies.__dict__.clear()
    scene.bodies.__dict__.update(state["bodies"])
    scene._pipeline.__dict__.update(state["pipeline"])
    for name, values in state["stages"].items():
        scene._stages[name].__dict__.update(values)
    for key, value in state["scene"].items():
        setattr(scene, key, value)
    scene._pending_despawn = list(state["pending"])
    for name, (key, obj) in targets.items():
        if obj is None:
            scene.resources[key] = payloads[name]
        else:
            obj.__dict__.clear()
            obj.__dict__.update(payloads[name])
            scene.resources[key] = obj
    renderer = scene._pipeline.renderer
    if renderer is not None:
        renderer.reset()  # its drawables were for the entities as they were


def _shape_difference(saved: tuple[Any, ...], now: tuple[Any, ...]) -> str:
    labels = ("processors", "collision handlers", "substeps")
    for label, a, b in zip(labels, saved, now):
        if a != b:
            return f"{label}: the snapshot's {a!r}, this scene's {b!r}"
    return "?"
