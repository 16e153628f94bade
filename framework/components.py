"""Components: small, validated data that systems process.

Constructors refuse NaN, inf and wrong types at once. Attributes stay plain and mutable
(``t.x += 1`` in game code). A bad value written later is kept as written and reported by the
scene's next ``step`` (a ``ValueError`` naming the entity and the field), which then changes
nothing.

Inside a scene, the hot fields of :class:`Transform` and :class:`Velocity` live in the scene's
columnar store (numpy arrays) and the component objects are views of one row: the pipeline works
on whole columns and never gathers from, or writes back to, thousands of Python objects. Outside
a scene, a component keeps its own values.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Iterator
from enum import Enum
from typing import TYPE_CHECKING, Any, NamedTuple, Protocol

from .shapes import AABB, Capsule, Circle, Polygon, Segment, Shape
from .sprites import Animation, Frame
from .validation import InvalidValue, finite, vector2

if TYPE_CHECKING:
    from .store import BodyStore

__all__ = ["MAX_PARTS", "Body", "Hitbox", "MassData", "Parts", "Transform", "Velocity", "Visual", "body_mass_data"]


class _Columns:
    """Base of components whose float fields may be views of a row of a :class:`BodyStore`."""

    __slots__ = ("_own", "_store", "_entity")
    _fields: tuple[str, ...] = ()
    _columns: tuple[str, ...] = ()  # the store column of each field

    def __init__(self, *values: object) -> None:
        self._store: BodyStore | None = None
        self._entity = -1
        # (a value written later is kept as written and checked at the next step: any object)
        self._own: list[object] = [finite(f"{type(self).__name__} {name}", v) for name, v in zip(self._fields, values)]

    def _get(self, i: int) -> Any:
        store = self._store
        if store is None:
            return self._own[i]
        return store.read(self._entity, self._columns[i])

    def _set(self, i: int, value: object) -> None:
        store = self._store
        if store is None:
            self._own[i] = value
        else:
            store.write(self._entity, self._columns[i], value)

    def _values(self) -> tuple[Any, ...]:
        return tuple(self._get(i) for i in range(len(self._fields)))

    def __repr__(self) -> str:
        inner = ", ".join(f"{n}={v!r}" for n, v in zip(self._fields, self._values()))
        return f"{type(self).__name__}({inner})"

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return self._values() == other._values()

    __hash__ = None  # type: ignore[assignment]  # mutable


if TYPE_CHECKING:
    class _FloatField(Protocol):
        """What a :func:`_field` property is to a type checker: a float to read and to write."""

        def __get__(self, obj: Any, owner: type | None = None, /) -> float: ...
        def __set__(self, obj: Any, value: float, /) -> None: ...


def _field(i: int, doc: str) -> _FloatField:
    return property(lambda self: self._get(i), lambda self, v: self._set(i, v), doc=doc)


class Transform(_Columns):
    """Where an entity is: position ``(x, y)`` in world units (y up) and ``rotation`` in radians,
    counter-clockwise. A hitbox's shape rotates about its hitbox origin."""

    __slots__ = ()
    _fields = ("x", "y", "rotation")
    _columns = ("x", "y", "rot")

    def __init__(self, x: float = 0.0, y: float = 0.0, rotation: float = 0.0) -> None:
        super().__init__(x, y, rotation)

    x = _field(0, "World x of the entity's origin.")
    y = _field(1, "World y of the entity's origin (y up).")
    rotation = _field(2, "Rotation in radians, counter-clockwise.")


class Velocity(_Columns):
    """Linear velocity ``(x, y)`` in world units per second and ``angular`` in radians per second.

    Only entities with a Velocity are integrated by the movement system."""

    __slots__ = ()
    _fields = ("x", "y", "angular")
    _columns = ("vx", "vy", "w")

    def __init__(self, x: float = 0.0, y: float = 0.0, angular: float = 0.0) -> None:
        super().__init__(x, y, angular)

    x = _field(0, "Velocity along x, world units per second.")
    y = _field(1, "Velocity along y, world units per second.")
    angular = _field(2, "Angular velocity, radians per second (counter-clockwise).")


class Body(Enum):
    """How the response treats a body.

    - ``DYNAMIC``: moved by its velocity and pushed by contacts.
    - ``KINEMATIC``: moved by its velocity or by game code; pushes dynamic bodies, is never pushed.
    - ``STATIC``: never moves (no Velocity); hashed once; static-static pairs are never tested.
    """

    DYNAMIC = "dynamic"
    KINEMATIC = "kinematic"
    STATIC = "static"


class MassData(NamedTuple):
    """A body's mass properties (:attr:`Hitbox.mass_data`), as Box2D's ``b2MassData``: its
    ``mass``, its centre of mass ``center`` in the entity's frame (the hitbox offset plus the
    shape's centroid, turning with the transform), and ``inertia``, its moment of inertia about
    that centre."""

    mass: float
    center: tuple[float, float]
    inertia: float


_HITBOX_FIELDS = (
    "shape", "offset", "layer", "mask", "sensor", "body", "mass", "restitution", "ccd", "one_way", "friction",
    "inertia", "density",
)
_ALL_BITS = 0xFFFFFFFF


class Hitbox:
    """The collision shape of an entity and how it takes part in collisions.

    - ``shape``: an :class:`~framework.shapes.AABB`, :class:`~framework.shapes.Circle`,
      :class:`~framework.shapes.Polygon`, :class:`~framework.shapes.Capsule` or
      :class:`~framework.shapes.Segment` (terrain: a segment has no area, so only a static or
      kinematic body takes one; a dynamic one is refused).
    - ``offset``: the hitbox origin relative to the entity's Transform; it turns with the
      transform's rotation (an AABB's box itself never turns).
    - ``layer`` / ``mask``: 32-bit collision filter. A pair is tested only when each one's layer
      meets the other's mask (``a.layer & b.mask and b.layer & a.mask``).
    - ``sensor``: reports collision events but never takes part in the response.
    - ``body``: :class:`Body` kind (or its name: ``"dynamic"``, ``"kinematic"``, ``"static"``).
    - ``mass``: > 0, used to split push-outs and impulses between two dynamic bodies;
      ``math.inf`` makes a dynamic body immovable by contacts. With a ``density``, leave it at its
      default: the mass is then the density times the shape's area (reading ``mass`` gives that).
    - ``density``: > 0, or None (the default); a mass other than 1 and a density is an error.
    - ``restitution``: 0 (slide) to 1 (elastic bounce); a pair uses the larger of the two.
    - ``friction``: Coulomb coefficient (>= 0), or None (the default: no material of its own).
      A pair where both hitboxes give one uses ``sqrt(f1 * f2)`` (Box2D's rule); where one does,
      that one (a crate given 0.5 slides with 0.5 on a plain floor); where neither does, none.
      Needs the ``"friction"`` effect (on by default); see docs/physics.md.
    - ``inertia``: moment of inertia about the body's centre of mass (> 0), or None (the default:
      from the shape and ``mass`` about its centroid, a solid disk's ``m r^2 / 2``, a box's
      ``m (w^2 + h^2) / 12``); ``math.inf`` keeps the body from turning (a player that must never
      tip). Contacts turn dynamic circles, boxes and polygons: boxes tip and tumble, circles roll
      (through friction). In the soft solver (``Scene(solver="soft")``) a body turns about its
      centre of mass (:attr:`mass_data`), wherever the hitbox offset and the outline put it. The
      exact solver turns only bodies without an offset, about their entity's position, with the
      inertia given or the shape's about that point: there, give an outline whose centroid is at
      the origin. An ``AABB`` never turns. Needs the ``"rotation"`` effect (on by default).
    - ``ccd``: continuous detection. The body is swept along its motion each step so it cannot
      pass through thin walls; bodies without it pay nothing for it.
    - ``one_way``: a platform that is solid only from above (its local +y, turning with its
      transform): a body that comes down onto it this step lands; one moving up through it, or
      sideways into it, passes. Events are reported either way (they are about overlap).
    """

    __slots__ = ("_store", "_entity") + tuple("_" + f for f in _HITBOX_FIELDS)

    if TYPE_CHECKING:
        # The fields as type checkers see them (__getattr__ and __setattr__ serve them at run time;
        # a field set to a bad value is kept as written and reported by the scene's next step).
        shape: Shape
        offset: tuple[float, float]
        layer: int
        mask: int
        sensor: bool

        @property
        def body(self) -> Body: ...
        @body.setter
        def body(self, value: Body | str) -> None: ...

        mass: float
        restitution: float
        ccd: bool
        one_way: bool
        friction: float | None
        inertia: float | None
        density: float | None
        # the slots behind them
        _store: BodyStore | None
        _entity: int
        _shape: Shape
        _offset: tuple[float, float]
        _layer: int
        _mask: int
        _sensor: bool
        _body: Body
        _mass: float
        _restitution: float
        _ccd: bool
        _one_way: bool
        _friction: float | None
        _inertia: float | None
        _density: float | None

    def __init__(
        self,
        shape: Shape,
        offset: tuple[float, float] = (0.0, 0.0),
        *,
        layer: int = 1,
        mask: int = _ALL_BITS,
        sensor: bool = False,
        body: Body | str = Body.DYNAMIC,
        mass: float = 1.0,
        restitution: float = 0.0,
        ccd: bool = False,
        one_way: bool = False,
        friction: float | None = None,
        inertia: float | None = None,
        density: float | None = None,
    ) -> None:
        object.__setattr__(self, "_store", None)
        object.__setattr__(self, "_entity", -1)
        for name, value in zip(
            _HITBOX_FIELDS, (shape, offset, layer, mask, sensor, body, mass, restitution, ccd, one_way, friction,
                             inertia, density)
        ):
            object.__setattr__(self, "_" + name, check_hitbox_field(name, value))
        check_mass_and_density(self)
        check_body_shape(self)

    def __getattr__(self, name: str) -> Any:
        if name == "mass":
            return self.effective_mass
        if name in _HITBOX_FIELDS:
            return object.__getattribute__(self, "_" + name)
        raise AttributeError(f"Hitbox has no attribute {name!r}")

    def __setattr__(self, name: str, value: Any) -> None:
        if name not in _HITBOX_FIELDS:
            raise AttributeError(f"Hitbox has no attribute {name!r}")
        # Kept as given; checked when the scene next steps (or at once outside a scene).
        if self._store is None:
            value = check_hitbox_field(name, value)
            if name in ("mass", "density"):  # a mass and a density: refused, as the scene's step does
                mass = value if name == "mass" else object.__getattribute__(self, "_mass")
                density = value if name == "density" else object.__getattribute__(self, "_density")
                try:
                    _check_mass_and_density(mass, density)
                except InvalidValue as exc:
                    fix = "set its mass back to 1.0 first" if name == "density" else "set its density to None first"
                    raise InvalidValue(f"{exc}; to change from one to the other, {fix}") from None
            if name in ("shape", "body"):  # a segment on a dynamic body: refused, as the scene's step does
                _check_body_shape(value if name == "shape" else object.__getattribute__(self, "_shape"),
                                  value if name == "body" else object.__getattribute__(self, "_body"))
        else:
            self._store.hitbox_changed(self._entity)
        object.__setattr__(self, "_" + name, value)

    def __getstate__(self) -> dict[str, Any]:  # pickling (snapshots): every slot, as it is
        return {name: object.__getattribute__(self, name) for name in Hitbox.__slots__}

    def __setstate__(self, state: dict[str, Any]) -> None:
        for name, value in state.items():
            object.__setattr__(self, name, value)

    @property
    def effective_mass(self) -> float:
        """The mass given, else ``density`` times the shape's area, else 1."""
        if self._density is not None:
            return self._density * self._shape.area
        return self._mass

    @property
    def mass_data(self) -> MassData:
        """The body's mass properties (:class:`MassData`): its mass (:attr:`effective_mass`), its
        centre of mass in the entity's frame (the ``offset`` plus the shape's centroid: (0, 0) for
        a centred shape) and its moment of inertia about that centre: the ``inertia`` given, else
        the mass times the shape's :attr:`~framework.shapes.Shape.central_moment` (the moment about
        the hitbox origin, less ``m d^2`` for a centroid ``d`` from it: the parallel-axis theorem).
        What the soft solver turns a dynamic body with; the fields as they are now (outside a scene,
        checked; inside one, a field written since the last step is read as written)."""
        shape = self._shape
        mass = self.effective_mass
        cx, cy = shape.centroid
        ox, oy = self._offset
        inertia = self._inertia if self._inertia is not None else mass * shape.central_moment
        return MassData(mass, (ox + cx, oy + cy), inertia)

    @property
    def inverse_mass(self) -> float:
        return 0.0 if self._body is not Body.DYNAMIC else 1.0 / self.effective_mass

    def __repr__(self) -> str:
        inner = ", ".join(f"{f}={object.__getattribute__(self, '_' + f)!r}" for f in _HITBOX_FIELDS)
        return f"Hitbox({inner})"


#: The most parts a :class:`Parts` holds (a body's shapes are numbered 0, its Hitbox, to 63).
MAX_PARTS = 63


class Parts:
    """More shapes of an entity's body, beside its :class:`Hitbox`: a body of several shapes (a
    character with a head circle and a body box, an L-shaped crate, a car's chassis).

    ``Parts([Hitbox(Circle(0.5), offset=(0, 1)), Hitbox(Polygon.box(0.5, 2), offset=(0.75, 0.75))])``:
    each part is a Hitbox of its own, with its own shape, ``offset`` (in the entity's frame, turning
    with it), material (``friction``, ``restitution``), ``mass`` or ``density``, ``inertia`` (about its
    own centre of mass), ``layer``, ``mask``, ``sensor`` and ``one_way``. Its ``body`` must be the
    entity's Hitbox's (a static compound body gives every part ``body="static"``). The entity's shapes
    are numbered: 0 its Hitbox, 1, 2, ... these parts in order; collision events name them
    (``CollisionEvent.part_a``, ``part_b``). Shapes of one body never collide with each other.

    The body's mass is the sum of its shapes' masses, its centre of mass theirs together, its
    moment of inertia about that centre the sum of each shape's about its own centre plus
    ``m d^2`` for the distance ``d`` between the two (the parallel-axis theorem):
    :func:`body_mass_data`, ``scene.mass_data(entity)``. A compound body turns when all its shapes
    are circles or polygons and none has ``inertia=math.inf`` (an AABB never turns, a capsule is
    turned only by the game).

    Only the soft solver (``Scene(solver="soft")``) takes compound bodies: the exact solver and the
    character controller refuse them (an :class:`InvalidValue` naming the entity, at the step's
    checks, before anything changes). The parts are fixed when the Parts is made (a tuple); a part's
    fields may be edited in a scene, as a Hitbox's (checked at the next step)."""

    __slots__ = ("hitboxes", "_store", "_entity")
    hitboxes: tuple[Hitbox, ...]
    _store: BodyStore | None
    _entity: int

    def __init__(self, hitboxes: Iterable[Hitbox]) -> None:
        if isinstance(hitboxes, Hitbox):
            raise InvalidValue("Parts takes a list of Hitboxes, got one Hitbox: write Parts([hitbox])")
        try:
            items = tuple(hitboxes)
        except TypeError:
            raise InvalidValue(f"Parts takes a list of Hitboxes, got {hitboxes!r}") from None
        if not 1 <= len(items) <= MAX_PARTS:
            raise InvalidValue(f"Parts takes 1 to {MAX_PARTS} Hitboxes, got {len(items)}")
        for i, hb in enumerate(items):
            if not isinstance(hb, Hitbox):
                raise InvalidValue(f"Parts: part {i + 1} must be a Hitbox, got {hb!r}")
        if len({id(hb) for hb in items}) != len(items):
            raise InvalidValue("Parts: the same Hitbox object is given twice; give each part its own")
        object.__setattr__(self, "hitboxes", items)
        object.__setattr__(self, "_store", None)
        object.__setattr__(self, "_entity", -1)

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("Parts is fixed when made: replace the component (scene.add_component) to change "
                             "the shapes, or edit a part's fields")

    def __len__(self) -> int:
        return len(self.hitboxes)

    def __iter__(self) -> Iterator[Hitbox]:
        return iter(self.hitboxes)

    def __getitem__(self, i: int) -> Hitbox:
        return self.hitboxes[i]

    def __getstate__(self) -> dict[str, Any]:  # pickling (snapshots)
        return {name: object.__getattribute__(self, name) for name in Parts.__slots__}

    def __setstate__(self, state: dict[str, Any]) -> None:
        for name, value in state.items():
            object.__setattr__(self, name, value)

    def mass_data(self, hitbox: Hitbox) -> MassData:
        """The mass data of the body made of ``hitbox`` (the entity's) and these parts:
        :func:`body_mass_data`."""
        return body_mass_data(hitbox, self)

    def __repr__(self) -> str:
        return f"Parts({list(self.hitboxes)!r})"


def body_mass_data(hitbox: Hitbox, parts: Parts | Iterable[Hitbox] | None = None) -> MassData:
    """The mass data (:class:`MassData`) of a body made of ``hitbox`` and ``parts`` (none: the
    hitbox's own, :attr:`Hitbox.mass_data`). Mass: the sum of the shapes' masses; centre: the
    mass-weighted mean of their centres (in the entity's frame); inertia about that centre: each
    shape's inertia about its own centre plus its mass times its centre's squared distance from the
    body's (the parallel-axis theorem). A shape of infinite mass makes the body immovable: mass and
    inertia ``math.inf``, centre the mean of the infinite shapes' centres; a shape with
    ``inertia=math.inf`` keeps the body from turning (inertia ``math.inf``)."""
    if parts is None:
        return hitbox.mass_data
    datas = [hitbox.mass_data] + [hb.mass_data for hb in parts]
    infinite = [d for d in datas if math.isinf(d.mass)]
    if infinite:
        k = len(infinite)
        cx = sum(d.center[0] for d in infinite) / k
        cy = sum(d.center[1] for d in infinite) / k
        return MassData(math.inf, (cx, cy), math.inf)
    mass = math.fsum(d.mass for d in datas)
    cx = math.fsum(d.mass * d.center[0] for d in datas) / mass
    cy = math.fsum(d.mass * d.center[1] for d in datas) / mass
    if any(math.isinf(d.inertia) for d in datas):
        return MassData(mass, (cx, cy), math.inf)
    inertia = math.fsum(d.inertia + d.mass * ((d.center[0] - cx) ** 2 + (d.center[1] - cy) ** 2) for d in datas)
    return MassData(mass, (cx, cy), inertia)


def check_hitbox_field(name: str, value: object) -> Any:
    """Validate one Hitbox field; return its normalised value or raise :class:`InvalidValue`."""
    if name == "shape":
        if not isinstance(value, (AABB, Circle, Polygon, Capsule, Segment)):
            raise InvalidValue(f"Hitbox shape must be an AABB, Circle, Polygon, Capsule or Segment, got {value!r}")
        return value
    if name == "offset":
        return vector2("Hitbox offset", value)
    if name in ("layer", "mask"):
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= int(value) <= _ALL_BITS:
            raise InvalidValue(f"Hitbox {name} must be an int in [0, 2**32), got {value!r}")
        return int(value)
    if name in ("sensor", "ccd", "one_way"):
        if not isinstance(value, bool):
            raise InvalidValue(f"Hitbox {name} must be True or False, got {value!r}")
        return value
    if name == "body":
        try:
            return Body(value.value if isinstance(value, Body) else value)
        except ValueError:
            raise InvalidValue(
                f"Hitbox body must be 'dynamic', 'kinematic' or 'static', got {value!r}"
            ) from None
    if name == "density":
        if value is None:
            return None
        d = finite("Hitbox density", value)
        if not d > 0.0:
            raise InvalidValue(f"Hitbox density must be > 0 (or None), got {value!r}")
        return d
    if name == "mass":
        if isinstance(value, bool) or not isinstance(value, (int, float)) and not hasattr(value, "__float__"):
            raise InvalidValue(f"Hitbox mass must be a number > 0, got {value!r}")
        m = float(value)
        if not (m > 0.0):  # inf allowed: immovable
            raise InvalidValue(f"Hitbox mass must be > 0 (math.inf for immovable), got {value!r}")
        return m
    if name == "restitution":
        r = finite("Hitbox restitution", value)
        if not 0.0 <= r <= 1.0:
            raise InvalidValue(f"Hitbox restitution must be in [0, 1], got {value!r}")
        return r
    if name == "inertia":
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, (int, float)) and not hasattr(value, "__float__"):
            raise InvalidValue(f"Hitbox inertia must be a number > 0 (or None), got {value!r}")
        i = float(value)
        if not (i > 0.0):  # inf allowed: never turns
            raise InvalidValue(f"Hitbox inertia must be > 0 (math.inf: never turns; None: from the shape), "
                               f"got {value!r}")
        return i
    if name == "friction":
        if value is None:
            return None
        f = finite("Hitbox friction", value)
        if not f >= 0.0:
            raise InvalidValue(f"Hitbox friction must be >= 0 (or None), got {value!r}")
        return f
    raise AttributeError(name)


def check_mass_and_density(hb: Hitbox) -> None:
    """:class:`InvalidValue` if a hitbox gives both a mass (other than the default 1) and a density."""
    _check_mass_and_density(object.__getattribute__(hb, "_mass"), object.__getattribute__(hb, "_density"))


def _check_mass_and_density(mass: float, density: float | None) -> None:
    if density is not None and mass != 1.0:
        raise InvalidValue(f"Hitbox mass and density are both given ({mass!r} and {density!r}): give one "
                           "(the mass of a body with a density is the density times its area)")


def check_body_shape(hb: Hitbox) -> None:
    """:class:`InvalidValue` if a hitbox puts a shape without area (a segment) on a dynamic body (its
    fields as written: a body written in place may still be its name)."""
    _check_body_shape(object.__getattribute__(hb, "_shape"),
                      check_hitbox_field("body", object.__getattribute__(hb, "_body")))


def _check_body_shape(shape: object, body: object) -> None:
    if isinstance(shape, Segment) and body is Body.DYNAMIC:
        raise InvalidValue(f"Hitbox shape {shape!r} has no area, so it cannot be a dynamic body's shape (it "
                           "would have no mass): give the hitbox body='static' or body='kinematic'")


def check_component(comp: object) -> None:
    """Raise :class:`InvalidValue` if ``comp``, about to join an entity, holds a bad value (one
    written after it was made, or while it belonged to another entity). Normalises a Hitbox's
    fields in place, as its constructor would; changes nothing on error."""
    if isinstance(comp, _Columns):
        for name, value in zip(comp._fields, comp._values()):
            finite(f"{type(comp).__name__}.{name}", value)
    elif isinstance(comp, Hitbox):
        fields = [check_hitbox_field(f, object.__getattribute__(comp, "_" + f)) for f in _HITBOX_FIELDS]
        _check_mass_and_density(fields[_HITBOX_FIELDS.index("mass")], fields[_HITBOX_FIELDS.index("density")])
        _check_body_shape(fields[_HITBOX_FIELDS.index("shape")], fields[_HITBOX_FIELDS.index("body")])
        for name, value in zip(_HITBOX_FIELDS, fields):
            object.__setattr__(comp, "_" + name, value)


def _rgba(color: Any) -> tuple[int, int, int, int]:
    """A Visual's colour as RGBA (alpha 255 when RGB is given); anything else is an InvalidValue."""
    if not isinstance(color, tuple) or len(color) not in (3, 4) or not all(
        isinstance(c, int) and not isinstance(c, bool) and 0 <= c <= 255 for c in color
    ):
        raise InvalidValue(f"Visual color must be an (r, g, b[, a]) tuple of ints 0-255, got {color!r}")
    return (color[0], color[1], color[2], color[3] if len(color) == 4 else 255)


def _check_image(image: Any) -> None:
    """A Visual's image: None or the path of an existing file (a missing one is named at once, not
    when a frame is drawn)."""
    if image is None:
        return
    if not isinstance(image, str):
        raise InvalidValue(f"Visual image must be a file path or None, got {image!r}")
    if not os.path.isfile(image):
        raise InvalidValue(f"Visual image {image!r}: no such file")


class Visual:
    """How the render system draws an entity; entities without a Visual are not drawn (the debug
    overlay still outlines hitboxes).

    What it shows, the first given of: ``animation`` (an :class:`~framework.sprites.Animation`,
    its frame chosen by the scene's clock), ``frame`` (a :class:`~framework.sprites.Frame`: part
    of an image, e.g. of a :class:`~framework.sprites.SpriteSheet`), ``image`` (a file path: the
    whole image); else the entity's hitbox filled in ``color``. Images are centred on the entity,
    one pixel per world unit, tinted by ``color`` (white: none) and mirrored left-right with
    ``flip_x``. ``color`` is RGB or RGBA (0-255); higher ``z`` draws on top; ``visible=False``
    hides it. Every field may change at any time.

    ``started``: the scene time the animation started at (``None``: when the entity is spawned,
    or the Visual added). :meth:`play` switches animations; :meth:`frame_at` says which frame
    shows at a scene time, the one the renderer draws."""

    __slots__ = ("color", "z", "image", "visible", "frame", "animation", "flip_x", "started", "_store", "_entity")
    _TRACKED = frozenset(("color", "z", "image", "visible", "frame", "animation", "flip_x", "started"))
    color: tuple[int, int, int, int]
    z: int
    image: str | None
    visible: bool
    frame: Frame | None
    animation: Animation | None
    flip_x: bool
    started: float | None
    _store: BodyStore | None
    _entity: int

    def __init__(
        self, color: tuple[int, ...] = (255, 255, 255), z: int = 0, image: str | None = None,
        visible: bool = True, *, frame: Frame | None = None, animation: Animation | None = None,
        flip_x: bool = False, started: float | None = None,
    ) -> None:
        color = _rgba(color)
        if isinstance(z, bool) or not isinstance(z, int):
            raise InvalidValue(f"Visual z must be an int, got {z!r}")
        _check_image(image)
        if frame is not None and not isinstance(frame, Frame):
            raise InvalidValue(f"Visual frame must be a Frame (framework.sprites) or None, got {frame!r}")
        if animation is not None and not isinstance(animation, Animation):
            raise InvalidValue(f"Visual animation must be an Animation (framework.sprites) or None, got {animation!r}")
        if started is not None:
            started = finite("Visual started", started)
        set_ = object.__setattr__
        set_(self, "_store", None)
        set_(self, "_entity", -1)
        set_(self, "color", color)
        set_(self, "z", z)
        set_(self, "image", image)
        set_(self, "visible", bool(visible))
        set_(self, "frame", frame)
        set_(self, "animation", animation)
        set_(self, "flip_x", bool(flip_x))
        set_(self, "started", started)

    def __setattr__(self, name: str, value: Any) -> None:
        if name == "color":
            value = _rgba(value)
        elif name == "image":
            _check_image(value)
        object.__setattr__(self, name, value)
        if name in Visual._TRACKED and self._store is not None:
            self._store.visual_changed(self._entity)  # the renderer looks at this entity again

    def play(self, animation: Animation, at: float, *, restart: bool = False) -> None:
        """Show ``animation`` from scene time ``at`` (a game system passes ``scene.time``). Playing
        the animation already shown changes nothing unless ``restart``."""
        if not isinstance(animation, Animation):
            raise InvalidValue(f"Visual.play takes an Animation, got {animation!r}")
        at = finite("Visual.play at", at)
        if restart or animation != self.animation:
            self.animation = animation
            self.started = at

    def frame_at(self, time: float) -> Frame | None:
        """The frame shown at scene time ``time`` (``None`` for a filled hitbox)."""
        if self.animation is not None:
            return self.animation.frame_at(time - (self.started or 0.0))
        if self.frame is not None:
            return self.frame
        return None if self.image is None else Frame.whole(self.image)

    def _bind(self, store: BodyStore | None, entity: int, time: float) -> None:
        """Tie to the scene's ``store`` (edits then tell the renderer) and start a pending animation."""
        object.__setattr__(self, "_store", store)
        object.__setattr__(self, "_entity", entity)
        if self.animation is not None and self.started is None:
            object.__setattr__(self, "started", float(time))

    def __getstate__(self) -> dict[str, Any]:
        return {name: getattr(self, name) for name in self.__slots__}

    def __setstate__(self, state: dict[str, Any]) -> None:
        for name, value in state.items():
            object.__setattr__(self, name, value)

    def __repr__(self) -> str:
        shown = (f"animation={self.animation!r}, " if self.animation is not None else
                 f"frame={self.frame!r}, " if self.frame is not None else "")
        return (f"Visual(color={self.color!r}, z={self.z!r}, image={self.image!r}, visible={self.visible!r}, "
                f"{shown}flip_x={self.flip_x!r})")
