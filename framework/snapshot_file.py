"""Snapshot files safe to load from strangers: a save game, a rollback peer's state, a bug report.

``save_snapshot(scene, path)`` writes the state :meth:`Scene.snapshot` holds (see
:mod:`framework.snapshot`) without pickle: one ``.npz`` file (a zip) holding every numpy array of
the state, read back with ``allow_pickle=False``, and a versioned JSON description of the rest.
``load_snapshot(scene, path)`` puts a scene back in that state; restored, it steps
bit-identically to the scene that was saved.

Loading never runs code from the file. The description names classes, but only these are made:
the framework's own (from modules already imported: a name never imports anything), the classes of
the components and resources the scene being restored already has (the game built it, so it
knows them), and any class passed in ``allow``. Objects are made with ``cls.__new__`` and their
attributes set directly: no ``__init__``, ``__setstate__`` or ``__reduce__`` of the file's
choosing runs. A file from another version of the format or of the framework, of another scene
shape (other systems or handlers), naming a class that is not allowed, malformed in any way, or
larger than ``max_bytes`` (the zip's members summed, checked before anything is inflated) is an
:class:`~framework.validation.InvalidValue` naming the file, and the scene is unchanged.

In-process copies (:meth:`Scene.snapshot`) and Ray keep using pickle, which is faster and takes
any picklable component; these files are for what crosses a trust boundary.
"""

from __future__ import annotations

import base64
import enum
import json
import sys
import zipfile
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from . import snapshot as snap
from .validation import InvalidValue

__all__ = ["FILE_FORMAT", "FILE_VERSION", "MAX_BYTES", "load_snapshot", "save_snapshot"]

FILE_FORMAT = "framework-snapshot"
FILE_VERSION = 1
MAX_BYTES = 512 * 1024 * 1024  # the members of a snapshot file, summed (load_snapshot(max_bytes=...))
_META = "__meta__"


def _cname(cls: type) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


def _allowed(scene: Any, allow: Iterable[type]) -> dict[str, type]:
    """The classes a file may name: the scene's component and resource classes, ``allow``."""
    import esper

    scene._activate()
    out: dict[str, type] = {}
    for comps in esper._entities.values():
        for kind in comps:
            out[_cname(kind)] = kind
    for key, value in scene.resources.items():
        for cls in (key, type(value)):
            if isinstance(cls, type):
                out[_cname(cls)] = cls
    for cls in allow:
        if not isinstance(cls, type):
            raise InvalidValue(f"allow takes classes, got {cls!r}")
        out[_cname(cls)] = cls
    return out


def _framework_class(name: str) -> type | None:
    """A class of the framework named ``module:qualname``, from a module already imported."""
    module, _, qual = name.partition(":")
    if not (module == "framework" or module.startswith("framework.")) or module not in sys.modules:
        return None
    obj: Any = sys.modules[module]
    for part in qual.split("."):
        if part.startswith("<") or not part.isidentifier():
            return None
        obj = getattr(obj, part, None)
    return obj if isinstance(obj, type) else None


class _Encoder:
    """Turns the state into JSON-able nodes plus numpy arrays (see :func:`save_snapshot`)."""

    def __init__(self, refs: dict[int, str], allowed: dict[str, type]) -> None:
        self.refs, self.allowed = refs, allowed
        self.arrays: list[np.ndarray] = []
        self.seen: dict[int, int] = {}
        self.keep: list[Any] = []  # keeps encoded objects alive, so their ids stay theirs

    def cls(self, cls: type) -> str:
        name = _cname(cls)
        if self.allowed.get(name) is not cls and _framework_class(name) is not cls:
            raise InvalidValue(f"a {cls.__qualname__} ({cls.__module__}) cannot be saved in a snapshot file: it is "
                               "not a component or resource class of the scene, nor passed in allow=")
        return name

    def node(self, v: Any) -> Any:  # noqa: C901 - one case per kind of value
        if v is None or isinstance(v, (bool, str)):
            return v
        if type(v) is int:
            return v if abs(v) < 2**53 else {"I": str(v)}
        if type(v) is float:
            return {"F": v.hex()}
        ref = self.refs.get(id(v))
        if ref is not None:
            return {"P": ref}
        if isinstance(v, np.ndarray):
            if v.dtype.hasobject:
                raise InvalidValue("an array of Python objects cannot be saved in a snapshot file")
            self.arrays.append(v)
            return {"A": len(self.arrays) - 1}
        if isinstance(v, np.generic):
            self.arrays.append(np.asarray(v))
            return {"NS": len(self.arrays) - 1}
        if isinstance(v, type):
            return {"C": self.cls(v)}
        if isinstance(v, enum.Enum):
            return {"E": [self.cls(type(v)), self.node(v.value)]}
        if isinstance(v, bytes):
            return {"B": base64.b64encode(v).decode()}
        if type(v) is slice:
            return {"SL": [self.node(v.start), self.node(v.stop), self.node(v.step)]}
        if isinstance(v, np.dtype):
            return {"DT": v.str}
        if type(v) is tuple:
            return {"T": [self.node(x) for x in v]}
        if isinstance(v, tuple) and hasattr(v, "_fields"):  # a NamedTuple
            return {"NT": [self.cls(type(v)), [self.node(x) for x in v]]}
        key = id(v)
        if key in self.seen:
            return {"R": self.seen[key]}
        self.seen[key] = n = len(self.seen)
        self.keep.append(v)
        if type(v) is list:
            return {"L": [n, [self.node(x) for x in v]]}
        if type(v) is dict:
            return {"D": [n, [[self.node(k), self.node(x)] for k, x in v.items()]]}
        if type(v) in (set, frozenset):
            return {"S" if type(v) is set else "FS": [n, [self.node(x) for x in sorted(v, key=repr)]]}
        cls = type(v)
        name = self.cls(cls)
        state: dict[str, Any] = {}
        for klass in cls.__mro__:
            for slot in getattr(klass, "__slots__", ()):
                if slot not in ("__dict__", "__weakref__") and hasattr(v, slot):
                    state[slot] = object.__getattribute__(v, slot)
        if hasattr(v, "__dict__"):
            state.update(v.__dict__)
        return {"O": [n, name, [[k, self.node(x)] for k, x in state.items()]]}


class _Decoder:
    """Builds the state back from a file's nodes, making only allowed classes."""

    def __init__(self, arrays: dict[str, np.ndarray], objects: dict[str, Any], allowed: dict[str, type]) -> None:
        self.arrays, self.objects, self.allowed = arrays, objects, allowed
        self.made: dict[int, Any] = {}

    def cls(self, name: Any) -> type:
        if not isinstance(name, str):
            raise ValueError(f"a class name must be text, got {name!r:.60}")
        cls = self.allowed.get(name) or _framework_class(name)
        if cls is None:
            raise ValueError(f"class {name!r} is not allowed here (not the framework's, nor a component or resource "
                             "class of this scene, nor passed in allow=)")
        return cls

    def node(self, v: Any) -> Any:  # noqa: C901 - one case per kind of value
        if v is None or isinstance(v, (bool, str, int)):
            return v
        if not isinstance(v, dict) or len(v) != 1:
            raise ValueError(f"unexpected value {v!r:.60}")
        (tag, body), = v.items()
        if tag == "I":
            return int(body)
        if tag == "F":
            return float.fromhex(body)
        if tag == "P":
            if body not in self.objects:
                raise ValueError(f"a reference to {body!r:.40}, which this scene does not have")
            return self.objects[body]
        if tag in ("A", "NS"):
            arr = self.arrays.get(f"a{body}")
            if arr is None:
                raise ValueError(f"array {body!r:.20} is missing")
            return arr if tag == "A" else arr[()]
        if tag == "C":
            return self.cls(body)
        if tag == "E":
            return self.cls(body[0])(self.node(body[1]))
        if tag == "B":
            return base64.b64decode(body, validate=True)
        if tag == "SL":
            start, stop, step = (self.node(x) for x in body)
            if not all(x is None or type(x) is int for x in (start, stop, step)):
                raise ValueError("a slice of something other than integers")
            return slice(start, stop, step)
        if tag == "DT":
            dt = np.dtype(body)
            if dt.hasobject:
                raise ValueError("an object dtype")
            return dt
        if tag == "T":
            return tuple(self.node(x) for x in body)
        if tag == "NT":
            cls = self.cls(body[0])
            if not (issubclass(cls, tuple) and hasattr(cls, "_fields")):
                raise ValueError(f"{body[0]!r} is not a named tuple")
            return cls(*[self.node(x) for x in body[1]])
        if tag == "R":
            if body not in self.made:
                raise ValueError(f"a reference to object {body!r:.20} before it is made")
            return self.made[body]
        if tag not in ("L", "D", "S", "FS", "O") or not isinstance(body, list) or not body:
            raise ValueError(f"unknown tag {tag!r:.20}")
        n, rest = body[0], body[1:]
        if not isinstance(n, int) or n in self.made:
            raise ValueError(f"object number {n!r:.20} is not new")
        if tag == "L":
            out: Any = []
            self.made[n] = out
            out.extend(self.node(x) for x in rest[0])
            return out
        if tag == "D":
            out = {}
            self.made[n] = out
            for k, x in rest[0]:
                out[self.node(k)] = self.node(x)
            return out
        if tag in ("S", "FS"):
            items = [self.node(x) for x in rest[0]]
            out = set(items) if tag == "S" else frozenset(items)
            self.made[n] = out
            return out
        if tag == "O":
            cls = self.cls(rest[0])
            obj = cls.__new__(cls)  # type: ignore[call-overload]  # (no __init__ of the file's choosing)
            self.made[n] = obj
            for k, x in rest[1]:
                if not isinstance(k, str) or not k.isidentifier():
                    raise ValueError(f"attribute name {k!r:.40} of a {cls.__qualname__}")
                object.__setattr__(obj, k, self.node(x))
            return obj
        raise ValueError(f"unknown tag {tag!r:.20}")  # (not reached)


def save_snapshot(scene: Any, path: str | Path, *, allow: Iterable[type] = ()) -> tuple[str, ...]:
    """Write the scene's state (between steps) to ``path`` (an ``.npz`` file); return the
    resources left out (by name: those holding something a file cannot hold, such as a generator
    or an object of a class not allowed). A component that cannot be saved is an
    :class:`InvalidValue` naming the entity."""
    from . import __version__

    state, refs = snap.collect_state(scene)
    allowed = _allowed(scene, allow)
    enc = _Encoder(refs, allowed)
    try:
        state_node = enc.node(state)
    except (InvalidValue, TypeError, ValueError) as exc:
        _name_component(state["esper"]["entities"], refs, allowed)
        raise InvalidValue(f"the scene's state cannot be saved in a snapshot file: {exc}") from None
    headers, payloads, skipped = [], [], []
    for name, key, cls, in_place, payload in snap.resource_parts(scene):
        trial = _Encoder(refs, allowed)
        trial.arrays, trial.seen, trial.keep = enc.arrays, dict(enc.seen), enc.keep
        try:
            header = [name, trial.node(key), trial.cls(cls), in_place]
            body = trial.node(payload)
        except (InvalidValue, TypeError, ValueError):
            del enc.arrays[len(enc.arrays):]  # (arrays appended by the failed try stay unused)
            skipped.append(name)
            continue
        enc.seen = trial.seen
        headers.append(header)
        payloads.append([name, body])
    meta = {"format": FILE_FORMAT, "version": FILE_VERSION, "framework": __version__,
            "shape": json.loads(json.dumps(snap.scene_shape(scene), default=str)), "frame": scene.frame,
            "skipped": sorted(skipped), "state": state_node, "resource_headers": headers, "resources": payloads}
    arrays = {f"a{i}": a for i, a in enumerate(enc.arrays)}
    arrays[_META] = np.frombuffer(json.dumps(meta, allow_nan=False).encode(), dtype=np.uint8)
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "wb") as f:
        np.savez(f, **arrays)  # type: ignore[arg-type]  # (numpy's stub reads **kwds as allow_pickle)
    tmp.replace(path)
    return tuple(sorted(skipped))


def _name_component(entities: dict[int, dict[type, Any]], refs: dict[int, str], allowed: dict[str, type]) -> None:
    for e in sorted(entities):
        for kind, comp in entities[e].items():
            try:
                _Encoder(refs, allowed).node(comp)
            except (InvalidValue, TypeError, ValueError) as exc:
                raise InvalidValue(f"entity {e}: its {kind.__name__} component cannot be saved in a snapshot file "
                                   f"({exc})") from None


def load_snapshot(scene: Any, path: str | Path, *, allow: Iterable[type] = (), max_bytes: int = MAX_BYTES) -> None:
    """Put ``scene`` in the state saved in the file at ``path`` (see the module docstring); the
    scene is unchanged if the file cannot be restored into it."""
    from . import __version__

    name = str(path)

    def bad(message: str) -> InvalidValue:
        return InvalidValue(f"{name}: {message}")

    scene._activate()
    if scene._stepping:
        raise InvalidValue("load_snapshot() was called from inside a step (a system or a collision handler)")
    try:
        with zipfile.ZipFile(path) as zf:
            members = zf.infolist()
            total = sum(m.file_size for m in members)
            if total > max_bytes:
                raise bad(f"the snapshot file holds {total} bytes, more than the limit of {max_bytes} (max_bytes)")
            if not all(m.filename.endswith(".npy") for m in members) or len(members) > 1_000_000:
                raise bad("not a snapshot file (unexpected members)")
        with np.load(path, allow_pickle=False) as npz:
            arrays = {k: npz[k] for k in npz.files}
    except (InvalidValue, FileNotFoundError):
        raise
    except Exception as exc:  # whatever a damaged zip or .npy makes zipfile or numpy raise
        raise bad(f"not a snapshot file ({type(exc).__name__}: {exc})") from None
    raw = arrays.pop(_META, None)
    if raw is None or raw.dtype != np.uint8 or raw.ndim != 1:
        raise bad("not a snapshot file (no description)")
    try:
        meta = json.loads(raw.tobytes().decode("utf-8"), parse_constant=_no_constant)
    except (ValueError, RecursionError) as exc:
        raise bad(f"not a snapshot file (its description is not JSON: {type(exc).__name__})") from None
    if not isinstance(meta, dict) or meta.get("format") != FILE_FORMAT:
        raise bad("not a snapshot file")
    if meta.get("version") != FILE_VERSION or meta.get("framework") != __version__:
        raise bad(f"a snapshot file from another version (format {meta.get('version')!r}, framework "
                  f"{meta.get('framework')!r}; this is format {FILE_VERSION}, framework {__version__!r})")
    shape = json.loads(json.dumps(snap.scene_shape(scene), default=str))
    if meta.get("shape") != shape:
        raise bad("the snapshot is from a scene of another shape (other systems, processors, collision handlers or "
                  "substeps)")
    allowed = _allowed(scene, allow)
    objects = snap._own_objects(scene)
    dec = _Decoder(arrays, objects, allowed)
    try:
        headers = []
        for header in meta["resource_headers"]:
            rname, key, cname, in_place = header
            headers.append((rname, dec.node(key), dec.cls(cname), bool(in_place)))
        targets = snap.resource_targets(scene, headers, objects)
        state = dec.node(meta["state"])
        payloads = {rname: dec.node(body) for rname, body in meta["resources"]}
        _check_state(state, targets, payloads)
    except RecursionError:
        raise bad("not a snapshot file (nested too deeply)") from None
    except (ValueError, TypeError, KeyError, IndexError, AttributeError, OverflowError) as exc:
        raise bad(f"not a snapshot file this scene can take ({type(exc).__name__}: {exc})") from None
    snap.apply_state(scene, state, targets, payloads)


def _check_state(state: Any, targets: dict[str, Any], payloads: dict[str, Any]) -> None:
    """The shape :func:`framework.snapshot.apply_state` needs, so that applying cannot fail halfway."""
    if not isinstance(state, dict) or set(state) != {"esper", "bodies", "pipeline", "stages", "scene", "pending"}:
        raise ValueError("the state's parts are not a scene's")
    world = state["esper"]
    if not (isinstance(world, dict) and isinstance(world.get("entities"), dict) and isinstance(world.get("next"), int)
            and isinstance(world.get("dead"), set)):
        raise ValueError("the entities are not a scene's")
    for e, comps in world["entities"].items():
        if not isinstance(e, int) or not isinstance(comps, dict) or not all(isinstance(k, type) for k in comps):
            raise ValueError(f"entity {e!r:.20} is not an entity")
    for part in ("bodies", "pipeline", "scene"):
        if not isinstance(state[part], dict) or not all(isinstance(k, str) for k in state[part]):
            raise ValueError(f"the {part} part is not a scene's")
    if not isinstance(state["stages"], dict) or not all(isinstance(v, dict) for v in state["stages"].values()):
        raise ValueError("the stages part is not a scene's")
    if not isinstance(state["pending"], list):
        raise ValueError("the pending part is not a scene's")
    for rname, (_key, obj) in targets.items():
        if rname not in payloads or (obj is not None and not isinstance(payloads[rname], dict)):
            raise ValueError(f"resource {rname!r:.60} has no state")


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not JSON")



