"""Snapshot files safe to load from strangers: a save game, a rollback peer's state, a bug report.

``save_snapshot(scene, path)`` writes the state :meth:`Scene.snapshot` holds (see
:mod:`framework.snapshot`) without pickle: one ``.npz`` file (a zip) holding every numpy array of
the state and a versioned JSON description of the rest. ``load_snapshot(scene, path)`` puts a
scene back in that state; restored, it steps bit-identically to the scene that was saved.

Loading runs no code of the file's choosing, and no constructor or hook of any class:

- A class is named ``module:qualname``. The name resolves only to a class defined under exactly
  that name in a module of the framework that is already imported (looked up in the module's
  namespace, then in classes' own namespaces: never through another module or a module's
  ``__getattr__``, and a name never imports anything), or to exactly one of the component and
  resource classes the scene being restored already has (the game built it, so it knows them),
  or to a class passed in ``allow``.
- Objects are made with ``object.__new__`` and their attributes written straight into their
  ``__dict__`` or slots: no ``__init__``, ``__new__``, ``__setattr__``, property setter,
  ``__setstate__`` or ``__reduce__`` runs. A class with its own ``__new__`` (or built on a builtin
  or numpy type) or with a ``__del__`` cannot be made from a file. An enum member is looked up by
  value among its class's members (the class must be an ``enum.Enum``); a named tuple must be of
  a real ``namedtuple`` class and is made with ``tuple.__new__``, one value per field.
- Set members and dict keys must be plain values (``None``, bools, numbers, text, bytes,
  classes, enum members, numpy scalars, tuples and frozensets of these, or objects hashed by
  identity), so that building a set or a dict runs no class's ``__hash__`` or ``__eq__``, and at
  most :data:`MAX_SHARED_HASH` of one set or dict may share a hash (keys made to collide would
  otherwise take minutes to insert).
- Arrays are read from the ``.npy`` members without pickle; a member whose header declares more
  data than it holds, an object array or a member that is not an array is refused before
  anything is allocated for it.

Everything is checked before anything changes: the format and framework versions, the scene's
shape (its systems, processors, collision handlers and substeps), the limits below, every class
name, and the state's structure, so that applying it cannot fail halfway: its parts, stage names
and the fields of the bodies, the pipeline, every stage and the scene (frame, time) are exactly
the scene's, each of the type the scene holds there (``None`` on either side only for a private
field, a cache named with ``_`` that the framework rebuilds);
entity ids, the next id, dead and pending entities are consistent; the body store's row count,
capacity, columns (names, dtypes, lengths) and its rows' entities agree with each other and with
the entities that have a ``Transform``; every resource is named by its class and holds what its
header says. A file that fails any of it is an :class:`~framework.validation.InvalidValue`
naming the file and the place, and the scene is unchanged.

What is not checked is whether the rest describes a sensible simulation: the contents of the
derived structures (spatial hashes, geometry, contact caches) and the values inside components
are taken as the file gives them, so a hostile file can still describe a scene whose next step
raises or behaves oddly, and the text it holds (a ``Visual``'s image path, say) is used as the
game would use it. Treat what a stranger's save puts in your scene as you would their level.

Limits: :data:`MAX_BYTES` (64 MiB) for the zip members summed, checked from the zip's directory
before anything is inflated (``max_bytes=``); :data:`MAX_DESCRIPTION_BYTES` (8 MiB, about 5,000
entities like the platformer's) for the JSON description, which costs up to about 40 bytes of
memory per byte while it is parsed and turned into objects: at the default, at most about 300 MiB
and a few seconds (``max_description_bytes=``); both can be raised. :data:`MAX_MEMBERS` (65,535)
arrays in a file is fixed (a zip without ZIP64 records), and ``save_snapshot`` keeps to it.

In-process copies (:meth:`Scene.snapshot`) and Ray keep using pickle, which is faster and takes
any picklable component; these files are for what crosses a trust boundary.
"""

from __future__ import annotations

import base64
import enum
import json
import math
import os
import re
import sys
import types
import zipfile
from collections import Counter
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import IO, Any

import numpy as np

from . import snapshot as snap
from .validation import InvalidValue

__all__ = ["FILE_FORMAT", "FILE_VERSION", "MAX_BYTES", "MAX_DESCRIPTION_BYTES", "MAX_MEMBERS", "MAX_SHARED_HASH",
           "load_snapshot", "save_snapshot"]

FILE_FORMAT = "framework-snapshot"
FILE_VERSION = 1
MAX_BYTES = 64 * 1024 * 1024  # the members of a snapshot file, summed (load_snapshot(max_bytes=...))
MAX_DESCRIPTION_BYTES = 8 * 1024 * 1024  # its JSON description (load_snapshot(max_description_bytes=...))
MAX_MEMBERS = 65_535  # arrays in one file (and the description): a zip without ZIP64 records
MAX_SHARED_HASH = 32  # members of one set (or keys of one dict) in a file that may share a hash
_META = "__meta__"
_META_KEYS = frozenset({"format", "version", "framework", "shape", "frame", "skipped", "state", "resource_headers",
                        "resources"})
_MEMBER = re.compile(r"(a(?:0|[1-9][0-9]{0,8})|__meta__)\.npy")
_SCALARS = (type(None), bool, int, float, str, bytes)
_NUMPY_SCALARS = (np.number, np.bool_, np.str_, np.bytes_, np.datetime64, np.timedelta64)
_ABSENT = object()


def _cname(cls: type) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


def _allowed(scene: Any, allow: Iterable[type]) -> dict[str, type]:
    """The classes a file may name besides the framework's: the scene's component and resource
    classes, ``allow``."""
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
    """The class of the framework whose own name is ``module:qualname``, from a module already
    imported: the walk goes through the module's namespace and then classes' own namespaces only
    (never into another module, never through a module's ``__getattr__``), and the class found
    must have been defined under that very name."""
    module, sep, qual = name.partition(":")
    if not sep or not (module == "framework" or module.startswith("framework.")):
        return None
    obj: Any = sys.modules.get(module)
    if not isinstance(obj, types.ModuleType):
        return None
    for part in qual.split("."):
        if not part.isidentifier():
            return None
        obj = vars(obj).get(part)
        if not isinstance(obj, type):
            return None
    if vars(obj).get("__module__") != module or obj.__qualname__ != qual:
        return None  # (a class imported into the module from elsewhere, or an alias)
    return obj


def _has_del(cls: type) -> bool:
    return any("__del__" in vars(klass) for klass in cls.__mro__)


def _why_not_made(cls: type) -> str | None:
    """Why objects of ``cls`` cannot be made from a file with ``object.__new__`` (None: they can)."""
    if cls.__new__ is not object.__new__:
        return "it has its own __new__, or is built on a builtin or numpy type"
    if _has_del(cls):
        return "it has a __del__, which would run on what the file holds"
    return None


def _is_named_tuple(cls: type) -> bool:
    fields = getattr(cls, "_fields", None)
    return (tuple in cls.__mro__ and type(fields) is tuple and all(type(f) is str for f in fields)
            and callable(getattr(cls, "_make", None)) and not _has_del(cls))


def _key_like(v: Any) -> bool:
    """Whether ``v`` may be a set member or a dict key in a file: hashing it runs no class's
    ``__hash__`` on what the file holds (see the module docstring)."""
    t = type(v)
    if t in _SCALARS:
        return True
    if t is tuple or t is frozenset:
        return all(_key_like(x) for x in v)
    if isinstance(v, type):
        return t.__hash__ is type.__hash__
    if isinstance(v, enum.Enum):
        return t._member_map_.get(v._name_) is v  # a member of its class: its hash is the code's
    if isinstance(v, _NUMPY_SCALARS):
        return True
    if tuple in t.__mro__ and t.__hash__ is tuple.__hash__ and _is_named_tuple(t):
        return all(_key_like(x) for x in v)
    return t.__hash__ is object.__hash__  # hashed by identity


def _check_keys(keys: list[Any], what: str) -> None:
    for k in keys:
        if not _key_like(k):
            raise ValueError(f"a {what} of class {type(k).__qualname__} (only plain values may be set members or "
                             "dict keys in a snapshot file)")
    if len(keys) > MAX_SHARED_HASH:
        shared = Counter(map(hash, keys)).most_common(1)[0][1]
        if shared > MAX_SHARED_HASH:
            raise ValueError(f"{shared} {what}s of one collection share a hash (at most {MAX_SHARED_HASH} may): a file "
                             "made to be slow to load")


def _attribute_name(k: Any) -> bool:
    return type(k) is str and k.isidentifier() and not (k.startswith("__") and k.endswith("__"))


def _set_attribute(obj: Any, cls: type, name: Any, value: Any) -> None:
    """Write an attribute of an object being made: into its slot or its ``__dict__``, running no
    ``__setattr__`` and no property setter."""
    if not _attribute_name(name):
        raise ValueError(f"attribute name {_label(name)} of a {cls.__qualname__}")
    found: Any = _ABSENT
    for klass in cls.__mro__:
        found = vars(klass).get(name, _ABSENT)
        if found is not _ABSENT:
            break
    if isinstance(found, types.MemberDescriptorType) and found.__objclass__ is klass:  # a slot
        found.__set__(obj, value)
        return
    if found is not _ABSENT and hasattr(type(found), "__set__"):
        raise ValueError(f"{cls.__qualname__}.{name} is not a plain attribute (a property or other descriptor)")
    where = _instance_dict(obj, cls)
    if where is None:
        raise ValueError(f"a {cls.__qualname__} has no attribute {name!r}")
    where[name] = value


def _instance_dict(obj: Any, cls: type) -> dict[str, Any] | None:
    for klass in cls.__mro__:
        slot = vars(klass).get("__dict__")
        if slot is not None:
            return slot.__get__(obj, cls) if isinstance(slot, types.GetSetDescriptorType) else None
    return None


def _label(v: Any) -> str:
    """A short, cheap description of a value read from a file (never its whole repr)."""
    if type(v) in (str, int, float, bool, type(None)):
        return repr(v)[:60]
    return f"a {type(v).__name__}"


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

    def key(self, k: Any, what: str) -> Any:
        if not _key_like(k):
            raise InvalidValue(f"a {what} of class {type(k).__qualname__} cannot be saved in a snapshot file (set "
                               "members and dict keys must be plain values: numbers, text, classes, enum members, "
                               "tuples of these, or objects hashed by identity)")
        return self.node(k)

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
            return {"A": self.array(v)}
        if isinstance(v, np.generic):
            return {"NS": self.array(np.asarray(v))}
        if isinstance(v, type):
            return {"C": self.cls(v)}
        if isinstance(v, enum.Enum):
            cls = type(v)
            if cls._value2member_map_.get(v.value) is not v if _key_like(v.value) else True:
                raise InvalidValue(f"{cls.__qualname__}.{v._name_} cannot be saved in a snapshot file (an enum member "
                                   "is saved by its value, which must be a plain value naming that one member)")
            return {"E": [self.cls(cls), self.node(v.value)]}
        if isinstance(v, bytes):
            return {"B": base64.b64encode(v).decode()}
        if type(v) is slice:
            return {"SL": [self.node(v.start), self.node(v.stop), self.node(v.step)]}
        if isinstance(v, np.dtype):
            return {"DT": v.str}
        if type(v) is tuple:
            return {"T": [self.node(x) for x in v]}
        if isinstance(v, tuple) and _is_named_tuple(type(v)):
            return {"NT": [self.cls(type(v)), [self.node(x) for x in v]]}
        key = id(v)
        if key in self.seen:
            return {"R": self.seen[key]}
        self.seen[key] = n = len(self.seen)
        self.keep.append(v)
        if type(v) is list:
            return {"L": [n, [self.node(x) for x in v]]}
        if type(v) is dict:
            return {"D": [n, [[self.key(k, "dict key"), self.node(x)] for k, x in v.items()]]}
        if type(v) in (set, frozenset):
            return {"S" if type(v) is set else "FS": [n, [self.key(x, "set member")
                                                          for x in sorted(v, key=repr)]]}
        cls = type(v)
        name = self.cls(cls)
        why = _why_not_made(cls)
        if why:
            raise InvalidValue(f"a {cls.__qualname__} cannot be saved in a snapshot file: {why}")
        state: dict[str, Any] = {}
        for klass in cls.__mro__:
            slots = vars(klass).get("__slots__", ())
            for slot in (slots,) if isinstance(slots, str) else slots:
                if slot.startswith("__") and not slot.endswith("__"):
                    slot = f"_{klass.__name__.lstrip('_')}{slot}"  # a private slot's real name
                if slot not in ("__dict__", "__weakref__") and hasattr(v, slot):
                    state[slot] = object.__getattribute__(v, slot)
        if hasattr(v, "__dict__"):
            state.update(v.__dict__)
        return {"O": [n, name, [[k, self.node(x)] for k, x in state.items()]]}

    def array(self, a: np.ndarray) -> int:
        if len(self.arrays) + 1 >= MAX_MEMBERS:
            raise InvalidValue(f"the state holds more than {MAX_MEMBERS - 1} arrays, more than a snapshot file may")
        self.arrays.append(a)
        return len(self.arrays) - 1


def _text(v: Any, tag: str) -> str:
    if type(v) is not str:
        raise ValueError(f"a {tag} node holds {_label(v)}, not text")
    return v


def _list(v: Any, tag: str, size: int | None = None) -> list[Any]:
    if type(v) is not list or (size is not None and len(v) != size):
        raise ValueError(f"a {tag} node holds {_label(v)}, not a list" + (f" of {size}" if size is not None else ""))
    return v


class _Decoder:
    """Builds the state back from a file's nodes, making only allowed classes, and only with
    ``object.__new__`` and direct attribute writes (see the module docstring)."""

    def __init__(self, arrays: dict[str, np.ndarray], objects: dict[str, Any], allowed: dict[str, type]) -> None:
        self.arrays, self.objects, self.allowed = arrays, objects, allowed
        self.made: dict[int, Any] = {}

    def cls(self, name: Any) -> type:
        if type(name) is not str:
            raise ValueError(f"a class name must be text, got {_label(name)}")
        cls = self.allowed.get(name) or _framework_class(name)
        if cls is None:
            raise ValueError(f"class {name[:100]!r} is not allowed here (not a class of the framework, nor a component "
                             "or resource class of this scene, nor passed in allow=)")
        return cls

    def node(self, v: Any) -> Any:  # noqa: C901 - one case per kind of value
        if v is None or type(v) in (bool, str, int):
            return v
        if type(v) is not dict or len(v) != 1:
            raise ValueError(f"unexpected value {_label(v)}")
        (tag, body), = v.items()
        if tag == "I":
            return int(_text(body, tag))
        if tag == "F":
            return float.fromhex(_text(body, tag))
        if tag == "P":
            if _text(body, tag) not in self.objects:
                raise ValueError(f"a reference to {body[:40]!r}, which this scene does not have")
            return self.objects[body]
        if tag in ("A", "NS"):
            arr = self.arrays.get(f"a{body}") if type(body) is int else None
            if arr is None:
                raise ValueError(f"array {_label(body)} is missing")
            if tag == "NS":
                if arr.ndim != 0:
                    raise ValueError(f"array {body} is not a scalar")
                return arr[()]
            return arr
        if tag == "C":
            return self.cls(body)
        if tag == "E":
            return self.member(_list(body, tag, 2))
        if tag == "B":
            return base64.b64decode(_text(body, tag), validate=True)
        if tag == "SL":
            start, stop, step = (self.node(x) for x in _list(body, tag, 3))
            if not all(x is None or type(x) is int for x in (start, stop, step)):
                raise ValueError("a slice of something other than integers")
            return slice(start, stop, step)
        if tag == "DT":
            dt = np.dtype(_text(body, tag))
            if dt.hasobject or dt.str != body:
                raise ValueError(f"dtype {body[:40]!r} is not one a snapshot file holds")
            return dt
        if tag == "T":
            return tuple([self.node(x) for x in _list(body, tag)])
        if tag == "NT":
            return self.named_tuple(_list(body, tag, 2))
        if tag == "R":
            if type(body) is not int or body not in self.made:
                raise ValueError(f"a reference to object {_label(body)} before it is made")
            return self.made[body]
        if tag not in ("L", "D", "S", "FS", "O"):
            raise ValueError(f"unknown tag {_label(tag)}")
        body = _list(body, tag, 3 if tag == "O" else 2)
        n = body[0]
        if type(n) is not int or n in self.made:
            raise ValueError(f"object number {_label(n)} is not new")
        if tag == "L":
            out: Any = []
            self.made[n] = out
            out.extend([self.node(x) for x in _list(body[1], tag)])
            return out
        if tag == "D":
            out = {}
            self.made[n] = out
            pairs = [(self.node(k), self.node(x)) for k, x in (_list(p, tag, 2) for p in _list(body[1], tag))]
            _check_keys([k for k, _ in pairs], "dict key")
            out.update(pairs)
            return out
        if tag in ("S", "FS"):
            items = [self.node(x) for x in _list(body[1], tag)]
            _check_keys(items, "set member")
            if n in self.made:
                raise ValueError(f"object number {n} is not new")
            out = set(items) if tag == "S" else frozenset(items)
            self.made[n] = out
            return out
        cls = self.cls(body[1])
        why = _why_not_made(cls)
        if why:
            raise ValueError(f"a {cls.__qualname__} cannot be made from a file: {why}")
        obj: Any = object.__new__(cls)
        self.made[n] = obj
        for k, x in (_list(p, tag, 2) for p in _list(body[2], tag)):
            _set_attribute(obj, cls, k, self.node(x))
        return obj

    def member(self, body: list[Any]) -> Any:
        """An enum member, looked up by value (no constructor, no ``_missing_``)."""
        cls = self.cls(body[0])
        if enum.Enum not in cls.__mro__:
            raise ValueError(f"class {body[0][:100]!r} is not an enum")
        value = self.node(body[1])
        if not _key_like(value):
            raise ValueError(f"an enum value of class {type(value).__qualname__}")
        member = cls._value2member_map_.get(value)  # type: ignore[attr-defined]
        if member is None:
            raise ValueError(f"{cls.__qualname__} has no member of value {_label(value)}")
        return member

    def named_tuple(self, body: list[Any]) -> Any:
        cls = self.cls(body[0])
        if not _is_named_tuple(cls):
            raise ValueError(f"class {body[0][:100]!r} is not a named tuple")
        items = [self.node(x) for x in _list(body[1], "NT")]
        fields: tuple[str, ...] = cls._fields  # type: ignore[attr-defined]  # (checked by _is_named_tuple)
        if len(items) != len(fields):
            raise ValueError(f"a {cls.__qualname__} of {len(items)} values, not {len(fields)}")
        return tuple.__new__(cls, items)  # (not the class's __new__)


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
        trial.arrays, trial.seen, trial.keep = list(enc.arrays), dict(enc.seen), enc.keep
        try:
            header = [name, trial.node(key), trial.cls(cls), in_place]
            body = trial.node(payload)
        except (InvalidValue, TypeError, ValueError):
            skipped.append(name)  # (the arrays the failed try appended stay out)
            continue
        enc.arrays, enc.seen = trial.arrays, trial.seen
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


def load_snapshot(scene: Any, path: str | Path, *, allow: Iterable[type] = (), max_bytes: int = MAX_BYTES,
                  max_description_bytes: int = MAX_DESCRIPTION_BYTES) -> None:
    """Put ``scene`` in the state saved in the file at ``path`` (see the module docstring): the
    scene is unchanged if the file cannot be restored into it. ``allow``: classes besides the
    framework's and the scene's component and resource classes that the file may make;
    ``max_bytes``, ``max_description_bytes``: the limits (see :data:`MAX_BYTES`)."""
    from . import __version__

    name = str(path)

    def bad(message: str) -> InvalidValue:
        return InvalidValue(f"{name}: {message}")

    for label, limit in (("max_bytes", max_bytes), ("max_description_bytes", max_description_bytes)):
        if isinstance(limit, bool) or not isinstance(limit, int) or limit <= 0:
            raise InvalidValue(f"{label} must be an int > 0, got {limit!r}")
    scene._activate()
    if scene._stepping:
        raise InvalidValue("load_snapshot() was called from inside a step (a system or a collision handler)")
    try:
        arrays = _read_members(path, bad, max_bytes, max_description_bytes)
    except (InvalidValue, FileNotFoundError):
        raise
    except Exception as exc:  # whatever a damaged zip or .npy makes zipfile or numpy raise
        raise bad(f"not a snapshot file ({type(exc).__name__}: {exc})") from None
    meta = _read_description(arrays.pop(_META, None), bad)
    if not isinstance(meta, dict) or meta.get("format") != FILE_FORMAT:
        raise bad("not a snapshot file")
    if meta.get("version") != FILE_VERSION or meta.get("framework") != __version__:
        raise bad(f"a snapshot file from another version (format {_label(meta.get('version'))}, framework "
                  f"{_label(meta.get('framework'))}; this is format {FILE_VERSION}, framework {__version__!r})")
    if set(meta) != _META_KEYS:
        raise bad(f"not a snapshot file (its description's parts are {sorted(meta)!r:.200})")
    shape = json.loads(json.dumps(snap.scene_shape(scene), default=str))
    if meta["shape"] != shape:
        raise bad("the snapshot is from a scene of another shape (other systems, processors, collision handlers or "
                  "substeps)")
    objects = snap._own_objects(scene)
    dec = _Decoder(arrays, objects, _allowed(scene, allow))
    try:
        headers = _resource_headers(scene, dec, meta["resource_headers"])
        targets = snap.resource_targets(scene, headers, objects)  # (registers the resources for references)
        state = dec.node(meta["state"])
        payloads = _resource_payloads(dec, meta["resources"], headers)
        _check_state(scene, state, meta["frame"])
    except RecursionError:
        raise bad("not a snapshot file (nested too deeply)") from None
    except (ValueError, TypeError, KeyError, IndexError, AttributeError, OverflowError) as exc:
        raise bad(f"not a snapshot file this scene can take ({type(exc).__name__}: {exc})") from None
    snap.apply_state(scene, state, targets, payloads)


def _read_members(path: str | Path, bad: Callable[[str], InvalidValue], max_bytes: int,
                  max_description_bytes: int) -> dict[str, np.ndarray]:
    """The file's arrays by name, each read only after its header was checked against its size."""
    with open(path, "rb") as f:
        _check_directory(f, bad)
        with zipfile.ZipFile(f) as zf:
            members = zf.infolist()
            names = [m.filename for m in members]
            if (len(members) > MAX_MEMBERS or len(set(names)) != len(names)
                    or not all(_MEMBER.fullmatch(n) for n in names)):
                raise bad("not a snapshot file (unexpected members)")
            total = sum(m.file_size for m in members)
            if total > max_bytes:
                raise bad(f"the snapshot file holds {total} bytes, more than the limit of {max_bytes} (max_bytes)")
            arrays = {}
            for m in members:
                key = m.filename[:-4]
                arrays[key] = _read_array(zf, m, bad, max_description_bytes if key == _META else None)
    return arrays


def _check_directory(f: IO[bytes], bad: Callable[[str], InvalidValue]) -> None:
    """The zip's end record, as ``numpy.savez`` writes it (no comment, no ZIP64), and a central
    directory no larger than :data:`MAX_MEMBERS` entries need: ``zipfile`` makes an object per
    entry before any size can be checked."""
    f.seek(0, os.SEEK_END)
    size = f.tell()
    if size < 22:
        raise bad("not a snapshot file (not a zip)")
    f.seek(size - 22)
    end = f.read(22)
    if end[:4] != b"PK\x05\x06" or end[20:] != b"\x00\x00":
        raise bad("not a snapshot file (no zip end record where numpy writes it)")
    if size >= 42:
        f.seek(size - 42)
        if f.read(4) == b"PK\x06\x07":
            raise bad("not a snapshot file (a ZIP64 archive: more members or bytes than a snapshot file holds)")
    entries, directory = int.from_bytes(end[10:12], "little"), int.from_bytes(end[12:16], "little")
    if entries > MAX_MEMBERS or directory > 128 * MAX_MEMBERS:
        raise bad(f"not a snapshot file (a zip directory of {entries} entries, {directory} bytes)")
    f.seek(0)


def _read_array(zf: zipfile.ZipFile, member: zipfile.ZipInfo, bad: Callable[[str], InvalidValue],
                limit: int | None) -> np.ndarray:
    """One ``.npy`` member, without pickle; its header's shape and dtype checked against the
    bytes the member holds before anything is allocated."""
    where = f"member {member.filename}"
    fp: Any
    with zf.open(member) as fp:
        version = np.lib.format.read_magic(fp)
        if version == (1, 0):
            shape, fortran, dtype = np.lib.format.read_array_header_1_0(fp)
        elif version == (2, 0):
            shape, fortran, dtype = np.lib.format.read_array_header_2_0(fp)
        else:
            raise bad(f"not a snapshot file ({where}: .npy format {version}, which numpy.savez does not write here)")
        if dtype.hasobject or dtype.itemsize == 0 or any(d < 0 for d in shape):
            raise bad(f"not a snapshot file ({where}: an array of {dtype} {shape}, which a snapshot file never holds)")
        count = math.prod(shape)
        size = count * dtype.itemsize
        if limit is not None and size > limit:
            raise bad(f"the snapshot file's description is {size} bytes, more than the limit of {limit} "
                      "(max_description_bytes)")
        if size > member.file_size:
            raise bad(f"not a snapshot file ({where}: its header declares {size} bytes of data, the member holds "
                      f"{member.file_size})")
        flat = np.empty(count, dtype=dtype)  # (an array owning its data, as numpy.load gives)
        view, got = flat.view(np.uint8).data, 0
        while got < size:
            n = fp.readinto(view[got:])
            if not n:
                break
            got += n
        if got != size or fp.read(1):
            raise bad(f"not a snapshot file ({where}: its data is not the {size} bytes its header declares)")
    return flat.reshape(shape, order="F" if fortran else "C")


def _read_description(raw: np.ndarray | None, bad: Callable[[str], InvalidValue]) -> Any:
    if raw is None or raw.dtype != np.uint8 or raw.ndim != 1:
        raise bad("not a snapshot file (no description)")
    if raw.size and int(raw.max()) > 127:  # (save_snapshot writes ASCII: one byte a character in memory too)
        raise bad("not a snapshot file (its description is not ASCII JSON)")
    try:
        return json.loads(str(memoryview(raw), "ascii"), parse_constant=_no_constant)  # type: ignore[arg-type]
    except (ValueError, RecursionError) as exc:
        raise bad(f"not a snapshot file (its description is not JSON: {type(exc).__name__})") from None


def _resource_headers(scene: Any, dec: _Decoder, raw: Any) -> list[tuple[str, Any, type, bool]]:
    """Each resource's ``(name, key, class, in place)``: the key a class named by the name, and a
    class that can be made wherever the scene has no object of it to restore into."""
    current = {snap._name(key): value for key, value in scene.resources.items()}
    out: list[tuple[str, Any, type, bool]] = []
    for header in _list(raw, "resource headers"):
        rname, key_node, cname, in_place = _list(header, "resource header", 4)
        if type(rname) is not str or any(rname == h[0] for h in out):
            raise ValueError(f"resource name {_label(rname)} is not text, or given twice")
        key, cls = dec.node(key_node), dec.cls(cname)
        if not isinstance(key, type) or snap._name(key) != rname or type(in_place) is not bool:
            raise ValueError(f"resource {rname[:80]!r}: its header is not [its class's name, its class, the class "
                             "of its value, whether it is restored in place]")
        obj = current.get(rname)
        if in_place and (obj is None or type(obj) is not cls or not hasattr(obj, "__dict__")):
            why = _why_not_made(cls)  # (a new one is made: resource_targets)
            if why:
                raise ValueError(f"resource {rname[:80]!r}: a {cls.__qualname__} cannot be made from a file: {why}")
        out.append((rname, key, cls, in_place))
    return out


def _resource_payloads(dec: _Decoder, raw: Any, headers: list[tuple[str, Any, type, bool]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for item in _list(raw, "resources"):
        rname, body = _list(item, "resource", 2)
        if type(rname) is not str or rname in out:
            raise ValueError(f"resource name {_label(rname)} is not text, or given twice")
        out[rname] = dec.node(body)
    if set(out) != {h[0] for h in headers}:
        raise ValueError("the resources' states are not those of the resources the file names")
    for rname, _key, cls, in_place in headers:
        value = out[rname]
        if in_place and (type(value) is not dict or not all(_attribute_name(k) for k in value)):
            raise ValueError(f"resource {rname[:80]!r}: its state is not a set of attributes")
        if not in_place and type(value) is not cls:
            raise ValueError(f"resource {rname[:80]!r}: holds {_label(value)}, not the {cls.__qualname__} its header "
                             "names")
    return out


def _fits(name: Any, value: Any, now: Any) -> bool:
    """Whether a field read from a file may replace the scene's: the same type; or, for a private
    field (a cache the framework rebuilds, named with ``_``: a fresh scene holds None in some),
    None on either side."""
    if type(value) is type(now):
        return True
    return type(name) is str and name.startswith("_") and (value is None or now is None)


def _same_fields(got: Any, now: Any, where: str) -> None:
    """``got`` has exactly the fields of ``now``, each fitting (see :func:`_fits`)."""
    if type(got) is not dict:
        raise ValueError(f"{where} is not a set of fields")
    if set(got) != set(now):
        missing = sorted(set(now) - set(got))
        unknown = sorted(_label(k) for k in set(got) - set(now))
        parts = ([f"missing {', '.join(missing)}"] if missing else []) + (
            [f"unknown {', '.join(unknown)}"] if unknown else [])
        raise ValueError(f"{where}: " + "; ".join(parts))
    for k, v in got.items():
        if not _fits(k, v, now[k]):
            raise ValueError(f"{where}: {k} is of type {type(v).__name__}, where this scene's is of type "
                             f"{type(now[k]).__name__}")


def _check_state(scene: Any, state: Any, frame: Any) -> None:
    """Everything :func:`framework.snapshot.apply_state` and the next step rely on in the state's
    structure (see the module docstring), so that applying it cannot fail halfway."""
    from .components import Transform

    now, _refs = snap.collect_state(scene)
    _same_fields(state, now, "the state")
    world = state["esper"]
    _same_fields(world, now["esper"], "the entities")
    entities = world["entities"]
    for e, comps in entities.items():
        if type(e) is not int or e < 1:
            raise ValueError(f"entity id {_label(e)} is not an entity id")
        if type(comps) is not dict:
            raise ValueError(f"entity {e}: its components are not a dict")
        for kind, comp in comps.items():
            if not isinstance(kind, type) or kind not in type(comp).__mro__:
                raise ValueError(f"entity {e}: a {type(comp).__name__} kept as a component of type {_label(kind)}")
    if world["next"] <= max(entities, default=0):
        raise ValueError(f"the next entity id, {world['next']}, is one in use")
    for what, ids in (("dead", world["dead"]), ("pending despawn", state["pending"])):
        for e in ids:
            if type(e) is not int or e not in entities:
                raise ValueError(f"a {what} entity {_label(e)} that the state does not have")
    for part in ("bodies", "pipeline", "scene"):
        _same_fields(state[part], now[part], f"the {part} part")
    stages = state["stages"]
    if set(stages) != set(now["stages"]):
        unknown = sorted(_label(k) for k in set(stages) - set(now["stages"]))
        missing = sorted(set(now["stages"]) - set(stages))
        raise ValueError(f"the stages are not this scene's (unknown {', '.join(unknown) or 'none'}; missing "
                         f"{', '.join(missing) or 'none'})")
    for stage in stages:
        _same_fields(stages[stage], now["stages"][stage], f"stage {stage!r}")
    fields = state["scene"]
    if fields["frame"] < 0 or fields["frame"] != frame or not math.isfinite(fields["time"]):
        raise ValueError(f"the scene's frame {fields['frame']} and time {fields['time']} are not a step's")
    totals = fields["_totals"]
    if totals is not None and not (len(totals) == 2 and type(totals[0]) is list and type(totals[1]) is dict):
        raise ValueError("the scene's step totals are not (events, counters)")
    _check_store(state["bodies"]["store"], scene.bodies.store,
                 {e for e, comps in entities.items() if Transform in comps})


def _check_store(store: Any, now: Any, placed: set[int]) -> None:
    """The body store's rows: count, capacity, columns and the entity of each row agree with each
    other and with the entities that have a Transform."""
    got = vars(store)
    for k in ("n", "cap", "cols", "row_of", "hitboxes", "shapes"):
        if k not in got:
            raise ValueError(f"the body store has no {k}")
    current = vars(now)
    for k, v in got.items():
        if k in current and not _fits(k, v, current[k]):
            raise ValueError(f"the body store's {k} is of type {type(v).__name__}, where this scene's is of type "
                             f"{type(current[k]).__name__}")
    n, cap, cols, row_of = got["n"], got["cap"], got["cols"], got["row_of"]
    if not (type(n) is int and type(cap) is int and 0 <= n <= cap):
        raise ValueError(f"the body store's row count {_label(n)} and capacity {_label(cap)} do not fit")
    if set(cols) != set(now.cols):
        raise ValueError("the body store's columns are not this scene's")
    for col, arr in cols.items():
        want = now.cols[col]
        if type(arr) is not np.ndarray or arr.dtype != want.dtype or arr.shape != (cap, *want.shape[1:]):
            raise ValueError(f"the body store's column {col} is not {cap} rows of {want.dtype}")
    if len(row_of) != n or set(row_of.values()) != set(range(n)) or set(row_of) != placed:
        raise ValueError("the body store's rows are not one for each entity with a Transform")
    rows = np.fromiter(row_of.values(), dtype=np.int64, count=n)
    ids = np.fromiter(row_of, dtype=np.int64, count=n)
    if not (cols["entity"][rows] == ids).all():
        raise ValueError("the body store's entity column does not name each row's entity")
    if len(got["hitboxes"]) != n or len(got["shapes"]) != n:
        raise ValueError("the body store's hitboxes and shapes are not one for each row")


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not JSON")
