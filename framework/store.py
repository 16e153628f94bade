"""The columnar store: one row per entity with a Transform, hot fields in numpy columns.

The pipeline reads and writes whole columns; :class:`~framework.components.Transform` and
:class:`~framework.components.Velocity` objects are views of a row, so game code's ``t.x += 1``
and the systems see the same number without any gathering or writing back.

Rows are packed: despawning moves the last row into the hole. Components find their row through
their entity id, so nothing needs rebinding. A value that is not a real number (``None``, a
string) cannot live in a float column: it is kept aside, the column holds NaN, and the next step
reports it (with its repr) before changing anything.
"""

from __future__ import annotations

import math
from numbers import Real
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .collision.kinds import KIND_AABB, KIND_CAPSULE, KIND_CIRCLE, KIND_NONE, KIND_POLYGON, KIND_SEGMENT
from .compiled import kernel
from .components import _HITBOX_FIELDS as _HITBOX_FIELD_NAMES
from .components import (
    Body,
    Hitbox,
    Parts,
    Transform,
    Velocity,
    Visual,
    check_component,
    check_hitbox_field,
    check_mass_and_density,
)
from .limits import MAX_COORD, check_hitbox_limits, check_position, rows_sound
from .shapes import AABB, Capsule, Circle, Segment
from .validation import InvalidValue

__all__ = ["ROW_STATE", "ROW_STRUCTURE", "BodyStore", "KIND_AABB", "KIND_CAPSULE", "KIND_CIRCLE", "KIND_POLYGON",
           "KIND_NONE", "KIND_SEGMENT", "as_selector"]

BODY_CODES = {Body.DYNAMIC: 0, Body.KINEMATIC: 1, Body.STATIC: 2}
DYNAMIC, KINEMATIC, STATIC = 0, 1, 2
NO_FRICTION = -1.0  # the friction column of a hitbox that gives no coefficient (Hitbox(friction=None))

_FLOATS = (
    "x", "y", "rot", "vx", "vy", "w",  # transform and velocity (component views)
    "ox", "oy", "hw", "hh", "radius", "bound", "inv_mass", "restitution",  # hitbox, derived
    "friction",  # the hitbox's friction coefficient; NO_FRICTION where it gives none
    "inv_inertia",  # 1 / moment of inertia of a body contacts turn (dynamic, centred, a circle, box or polygon),
    # else 0
)
_INTS = {
    "kind": np.int8, "body": np.int8, "layer": np.int64, "mask": np.int64, "entity": np.int64,
    "still": np.int32,  # consecutive steps the body has been at rest (sleeping)
    "look": np.int64,  # stamp of the row's last change a renderer must look at (Visual, hitbox shape, new row)
}
_BOOLS = ("has_vel", "sensor", "ccd", "one_way", "asleep")
#: What a step may change in a row (framework.rollback keeps it): the row's structure (entity, shape
#: kind, body kind, whether it has a Velocity; compared, not put back), then its pose, velocity and
#: rest (put back). Every value of them is exact in a float.
ROW_STRUCTURE = ("entity", "kind", "body", "has_vel")
ROW_STATE = ROW_STRUCTURE + ("x", "y", "rot", "vx", "vy", "w", "still", "asleep")
_FIELD_NAMES = {
    "x": "Transform.x", "y": "Transform.y", "rot": "Transform.rotation",
    "vx": "Velocity.x", "vy": "Velocity.y", "w": "Velocity.angular",
}


@kernel
def _pair_friction(friction, ra, rb):  # pragma: no cover - compiled
    """:meth:`BodyStore.pair_friction` in one pass (numpy's answers: where both are given, neither
    is NaN and ``max(f, 0) = f``, -0.0 included)."""
    out = np.empty(ra.size)
    for i in range(ra.size):
        fa, fb = friction[ra[i]], friction[rb[i]]
        if fa >= 0.0 and fb >= 0.0:
            out[i] = np.sqrt(fa * fb)
        elif fa >= 0.0:
            out[i] = fa
        elif fb >= 0.0:
            out[i] = fb
        else:
            out[i] = 0.0
    return out


@kernel
def _move_rows(rows, x, y, rot, vx, vy, w, dt):  # pragma: no cover - compiled
    """:meth:`BodyStore.move_by_velocity`'s arithmetic, row by row (a rotation only where ``w``
    is not 0: adding 0 would turn a rotation of -0.0 into 0.0)."""
    for i in range(rows.size):
        r = rows[i]
        x[r] += vx[r] * dt
        y[r] += vy[r] * dt
        if w[r] != 0.0:
            rot[r] += w[r] * dt


def as_selector(rows: NDArray[np.intp]) -> slice | NDArray[np.intp]:
    """Sorted distinct ``rows`` as a slice when they are one contiguous run, else as they are."""
    if rows.size and int(rows[-1]) - int(rows[0]) + 1 == rows.size:
        return slice(int(rows[0]), int(rows[-1]) + 1)
    return rows


class BodyStore:
    """Columns of every entity that has a Transform (and optionally Velocity and Hitbox)."""

    if TYPE_CHECKING:  # the live rows of the columns (``cols[name][:n]``), properties (_live_rows)
        x: NDArray[np.float64]
        y: NDArray[np.float64]
        rot: NDArray[np.float64]
        vx: NDArray[np.float64]
        vy: NDArray[np.float64]
        w: NDArray[np.float64]
        ox: NDArray[np.float64]
        oy: NDArray[np.float64]
        hw: NDArray[np.float64]
        hh: NDArray[np.float64]
        radius: NDArray[np.float64]
        bound: NDArray[np.float64]
        inv_mass: NDArray[np.float64]
        restitution: NDArray[np.float64]
        friction: NDArray[np.float64]
        inv_inertia: NDArray[np.float64]
        kind: NDArray[np.int8]
        body: NDArray[np.int8]
        layer: NDArray[np.int64]
        mask: NDArray[np.int64]
        entity: NDArray[np.int64]
        still: NDArray[np.int32]
        has_vel: NDArray[np.bool_]
        sensor: NDArray[np.bool_]
        ccd: NDArray[np.bool_]
        one_way: NDArray[np.bool_]
        asleep: NDArray[np.bool_]

    def __init__(self, capacity: int = 64) -> None:
        self.n = 0
        self.cap = capacity
        # (columns of several dtypes: float64, int8 / int32 / int64 and bool; see the declarations above)
        self.cols: dict[str, NDArray[Any]] = {}
        for name in _FLOATS:
            self.cols[name] = np.zeros(capacity)
        for name, dt in _INTS.items():
            self.cols[name] = np.zeros(capacity, dtype=dt)
        for name in _BOOLS:
            self.cols[name] = np.zeros(capacity, dtype=bool)
        self.row_of: dict[int, int] = {}
        self.hitboxes: list[Hitbox | None] = []
        # The shape each row's columns were derived from: a hitbox's shape edited by game code
        # takes effect at the next step, and until then geometry must not mix the two.
        self.shapes: list[Any] = []
        self.bad: dict[tuple[int, str], object] = {}
        self.dirty_hitboxes: set[int] = set()
        # The other shapes of compound bodies (framework.components.Parts), by entity: the soft step
        # poses them from their entity's row (framework.systems.soft_step.kernel_tables).
        self.parts: dict[int, Parts] = {}
        self.static_epoch = 0  # bumped whenever static_dirty is set
        self.sleep_epoch = 0  # bumped whenever sleep_dirty is set
        self.static_dirty = True  # the static set or a static body changed: re-hash the statics
        self.sleep_dirty = False  # a body fell asleep or woke: re-hash the sleepers
        self.written: set[int] = set()  # entities game code wrote to since the last check
        self._active_key: tuple[int, int, int] | None = None
        self._active: tuple[NDArray[np.intp], NDArray[np.intp], NDArray[np.intp]]
        self._active_sel: tuple[slice | NDArray[np.intp], ...]
        self._layers_key = -1
        self._kinds_key = -1
        self._kinds: frozenset[int] = frozenset()
        self._layers_open = False
        self.version = 0  # bumped on every structural change (rows, kinds, body types)
        self._friction_seen = (-1, False)  # (version, whether a hitbox gives friction then)
        self.wakes = 0  # bumped whenever a sleeping row wakes
        self.writes = 0  # bumped by every write from game code to a pose (Transform views; velocities move no bound)
        self.motion = 0  # bumped by every move the pipeline makes (move_by_velocity, place)
        self.looks = 0  # the last stamp given to a row's ``look`` column
        self._lookup = np.full(1, -1, dtype=np.int64)  # entity id -> row (rows_of)
        self._lookup_version = -1
        # A step that may be undone (framework.rollback) keeps every row that is not static; a
        # static row is saved here before its first change during the step (rows below _undo_n).
        self._undo: dict[int, NDArray[np.float64]] | None = None
        self._undo_n = 0

    # --- change flags and the rows that can move ---------------------------------------------

    @property
    def static_dirty(self) -> bool:
        return self._static_dirty

    @static_dirty.setter
    def static_dirty(self, value: bool) -> None:
        self._static_dirty = value
        if value:
            self.static_epoch += 1

    @property
    def sleep_dirty(self) -> bool:
        return self._sleep_dirty

    @sleep_dirty.setter
    def sleep_dirty(self, value: bool) -> None:
        self._sleep_dirty = value
        if value:
            self.sleep_epoch += 1

    def active(self) -> tuple[NDArray[np.intp], NDArray[np.intp], NDArray[np.intp]]:
        """``(movers, awake_bodies, nonstatic)`` rows, cached until rows, kinds or sleep change:
        movers have a Velocity and are neither static nor asleep; awake bodies have a hitbox and
        are neither static nor asleep. Per-step work walks these, never the static level."""
        key = (self.version, self.sleep_epoch, self.n)
        if key != self._active_key:
            n = self.n
            c = self.cols
            nonstatic = c["body"][:n] != STATIC
            awake = nonstatic & ~c["asleep"][:n]
            self._active = (
                np.flatnonzero(awake & c["has_vel"][:n]),
                np.flatnonzero(awake & (c["kind"][:n] >= 0)),
                np.flatnonzero(nonstatic),
            )
            self._active_sel = tuple(as_selector(rows) for rows in self._active)
            self._active_key = key
        return self._active

    def layers_all_meet(self) -> bool:
        """Whether every two hitboxes' layers and masks let them meet (the default: one layer, all
        masks open), so the broad phase need not filter pairs; cached until a structural change
        (layers and masks are hitbox fields: editing one is one)."""
        if self._layers_key != self.version:
            n = self.n
            has = self.cols["kind"][:n] >= 0
            layer, mask = self.cols["layer"][:n][has], self.cols["mask"][:n][has]
            common = np.bitwise_and.reduce(mask) if mask.size else 0
            self._layers_open = bool(mask.size == 0 or ((layer & common) != 0).all())
            self._layers_key = self.version
        return self._layers_open

    def kinds_present(self) -> frozenset[int]:
        """The shape kinds of the hitboxes (``KIND_AABB`` ...), cached until a structural change:
        a scene of boxes alone skips sorting its pairs by kind."""
        if self._kinds_key != self.version:
            kind = self.cols["kind"][: self.n]
            self._kinds = frozenset(int(k) for k in (KIND_AABB, KIND_CIRCLE, KIND_POLYGON, KIND_CAPSULE, KIND_SEGMENT)
                                    if (kind == k).any())
            self._kinds_key = self.version
        return self._kinds

    def active_sel(self) -> tuple[slice | NDArray[np.intp], ...]:
        """:meth:`active` as selectors: a slice where the rows are one contiguous run (the usual
        case: movers spawned together), so the per-step column reads are views, not gathers."""
        self.active()
        return self._active_sel

    def rows_of(self, entities: NDArray[np.intp] | list[int]) -> NDArray[np.int64]:
        """Rows of ``entities`` (-1 for an id without a row), through a table rebuilt after each
        structural change: the one entity -> row lookup of the pipeline, the queries and the renderer."""
        lut = self.row_table()
        ents = np.asarray(entities, dtype=np.int64)
        out = np.full(ents.size, -1, dtype=np.int64)
        ok = ents < lut.size
        out[ok] = lut[ents[ok]]
        return out

    def row_table(self) -> NDArray[np.int64]:
        """The table behind :meth:`rows_of`: the row of each entity id below its size (-1: none),
        built again only after a structural change (for compiled passes that look rows up)."""
        if self._lookup_version != self.version:  # (every spawn and despawn bumps the version)
            size = (int(self.entity.max()) + 1) if self.n else 1
            lut = np.full(size, -1, dtype=np.int64)
            lut[self.entity] = np.arange(self.n)
            self._lookup, self._lookup_version = lut, self.version
        return self._lookup

    def has_friction(self) -> bool:
        """Whether any hitbox gives a friction coefficient above 0 (looked at again only after a
        structural change: a scene without friction pays one comparison per step for it)."""
        if self._friction_seen[0] != self.version:
            self._friction_seen = (self.version, bool((self.friction > 0.0).any()))
        return self._friction_seen[1]

    def pair_friction(self, ra: NDArray[np.intp], rb: NDArray[np.intp]) -> NDArray[np.float64]:
        """The friction coefficient of each pair ``(ra, rb)``: ``sqrt(f_a * f_b)`` where both
        hitboxes give one, the one given where one does, 0 where neither does."""
        mu: NDArray[np.float64] = _pair_friction(self.cols["friction"], ra, rb)
        return mu

    def movable(self, rows: NDArray[np.intp]) -> NDArray[np.bool_]:
        """Mask of ``rows`` the response may move: a finite mass (``inv_mass > 0``), and awake."""
        return (self.inv_mass[rows] > 0.0) & ~self.asleep[rows]

    # --- moves: the only ways the pipeline changes positions -----------------------------------
    # Each bumps ``motion``, so whatever is derived from positions (hitbox bounds) knows it is stale
    # without the mover having to say so.

    def move_by_velocity(self, rows: NDArray[np.intp], sel: slice | NDArray[np.intp], dt: float) -> None:
        """``x += vx dt``, ``y += vy dt`` and ``rot += w dt`` over ``rows`` (``sel``: the same rows,
        as a slice where they are one run, so the column reads are views, not gathers)."""
        c = self.cols
        _move_rows(rows, c["x"], c["y"], c["rot"], c["vx"], c["vy"], c["w"], dt)
        self.motion += 1

    def place(
        self, rows: NDArray[np.intp] | int, x: NDArray[np.float64] | float, y: NDArray[np.float64] | float,
    ) -> None:
        """Put ``rows`` at ``(x, y)``."""
        self.cols["x"][rows] = x
        self.cols["y"][rows] = y
        self.motion += 1

    # --- columns ---------------------------------------------------------------------------

    def _grow(self) -> None:
        self.cap *= 2
        for name, col in self.cols.items():
            new = np.zeros(self.cap, dtype=col.dtype)
            new[: self.n] = col[: self.n]
            self.cols[name] = new

    # --- rows ------------------------------------------------------------------------------

    def add(self, entity: int, transform: Transform, velocity: Velocity | None, hitbox: Hitbox | None) -> None:
        if self.n == self.cap:
            self._grow()
        row = self.n
        c = self.cols
        c["entity"][row] = entity
        c["asleep"][row] = False
        c["still"][row] = 0
        c["x"][row], c["y"][row], c["rot"][row] = transform._own
        if velocity is not None:
            c["vx"][row], c["vy"][row], c["w"][row] = velocity._own
            c["has_vel"][row] = True
        else:
            c["vx"][row] = c["vy"][row] = c["w"][row] = 0.0
            c["has_vel"][row] = False
        self.n += 1
        self.row_of[entity] = row
        self.hitboxes.append(None)
        self.shapes.append(None)
        self._set_hitbox_row(row, hitbox)
        self.looks += 1
        c["look"][row] = self.looks
        if hitbox is not None and hitbox._body is Body.STATIC:
            self.static_dirty = True
        for comp in (transform, velocity, hitbox):
            if comp is not None:
                object.__setattr__(comp, "_store", self)
                object.__setattr__(comp, "_entity", entity)
        self.version += 1

    def remove(self, entity: int, components: tuple[Any, ...]) -> None:
        row = self.row_of[entity]
        last = self.n - 1
        if self._undo is not None:
            self._before_change(row)
            self._before_change(last)
        if self.cols["body"][row] == STATIC and self.cols["kind"][row] >= 0:
            self.static_dirty = True
        if self.cols["asleep"][row]:
            self.sleep_dirty = True
        for comp in components:
            self.unbind(entity, comp)
        if entity in self.parts:
            self.unbind(entity, self.parts.pop(entity))
        del self.row_of[entity]
        for key in [k for k in self.bad if k[0] == entity]:
            del self.bad[key]
        self.dirty_hitboxes.discard(entity)
        if row != last:
            for col in self.cols.values():
                col[row] = col[last]
            self.hitboxes[row] = self.hitboxes[last]
            self.shapes[row] = self.shapes[last]
            self.row_of[int(self.cols["entity"][row])] = row
        self.hitboxes.pop()
        self.shapes.pop()
        self.n -= 1
        self.version += 1

    def unbind(self, entity: int, comp: object) -> None:
        """Detach a component from its row: it keeps the values it had (bad ones included), as its
        own, and no longer writes to the row (which may soon hold another entity or component)."""
        if isinstance(comp, (Transform, Velocity)) and comp._store is self:
            comp._own = [self.read(entity, col) for col in comp._columns]
            comp._store = None
        elif isinstance(comp, (Hitbox, Visual)) and comp._store is self:
            object.__setattr__(comp, "_store", None)
        elif isinstance(comp, Parts) and comp._store is self:
            object.__setattr__(comp, "_store", None)
            for hb in comp.hitboxes:
                object.__setattr__(hb, "_store", None)

    def visual_changed(self, entity: int) -> None:
        """Stamp ``entity``'s row (if it has one) as changed for renderers: its Visual was edited,
        added or removed. A renderer compares each row's ``look`` with the stamp it last drew, so it
        visits only what changed, never every entity every frame."""
        row = self.row_of.get(entity)
        if row is not None:
            self.looks += 1
            self.cols["look"][row] = self.looks

    def set_velocity(self, entity: int, velocity: Velocity | None) -> None:
        """Give the row ``velocity``'s values (or none); unbind the old Velocity first."""
        row = self.row_of[entity]
        if self._undo is not None:
            self._before_change(row)
        c = self.cols
        for col in ("vx", "vy", "w"):  # values the old Velocity held, reported no more
            self.bad.pop((entity, col), None)
        if velocity is None:
            c["has_vel"][row] = False
            c["vx"][row] = c["vy"][row] = c["w"][row] = 0.0
        else:
            c["vx"][row], c["vy"][row], c["w"][row] = velocity._own
            c["has_vel"][row] = True
            velocity._store, velocity._entity = self, entity
        self.wake(row)
        self.version += 1

    def set_hitbox(self, entity: int, hitbox: Hitbox | None) -> None:
        row = self.row_of[entity]
        if self._undo is not None:
            self._before_change(row)
        old = self.hitboxes[row]
        if old is not None and old is not hitbox:
            self.unbind(entity, old)
        self.dirty_hitboxes.discard(entity)  # edits of the old hitbox no longer matter
        self.static_dirty = True
        self.wake(row)
        self._set_hitbox_row(row, hitbox)
        if hitbox is not None:
            object.__setattr__(hitbox, "_store", self)
            object.__setattr__(hitbox, "_entity", entity)
        self.version += 1

    def set_parts(self, entity: int, parts: Parts | None) -> None:
        """Give ``entity`` (a row) the other shapes ``parts`` of a compound body, or none; the old
        ones are unbound. Their hitboxes are bound to the entity: an edit of a part's field is
        checked and applied at the next step, as the entity's Hitbox's."""
        row = self.row_of[entity]
        if self._undo is not None:
            self._before_change(row)
        old = self.parts.pop(entity, None)
        if old is not None and old is not parts:
            self.unbind(entity, old)
        if parts is not None:
            self.parts[entity] = parts
            object.__setattr__(parts, "_store", self)
            object.__setattr__(parts, "_entity", entity)
            for hb in parts.hitboxes:
                object.__setattr__(hb, "_store", self)
                object.__setattr__(hb, "_entity", entity)
        self.static_dirty = True
        self.wake(row)
        self.looks += 1  # (renderers draw every part: look again)
        self.cols["look"][row] = self.looks
        self.version += 1

    def _set_hitbox_row(self, row: int, hb: Hitbox | None) -> None:
        c = self.cols
        self.hitboxes[row] = hb
        shape = None if hb is None else hb._shape
        if shape is not self.shapes[row]:  # a filled hitbox is drawn from its shape: renderers look again
            self.looks += 1
            c["look"][row] = self.looks
        self.shapes[row] = shape
        if hb is None:
            c["kind"][row] = KIND_NONE
            c["body"][row] = DYNAMIC
            c["sensor"][row] = c["ccd"][row] = c["one_way"][row] = False
            c["layer"][row] = c["mask"][row] = 0
            for name in ("ox", "oy", "hw", "hh", "radius", "bound", "inv_mass", "restitution"):
                c[name][row] = 0.0
            c["friction"][row] = NO_FRICTION
            c["inv_inertia"][row] = 0.0
            return
        shape = hb._shape
        if isinstance(shape, AABB):
            c["kind"][row] = KIND_AABB
            c["hw"][row], c["hh"][row] = shape.width * 0.5, shape.height * 0.5
            c["radius"][row] = 0.0
        elif isinstance(shape, Circle):
            c["kind"][row] = KIND_CIRCLE
            c["hw"][row] = c["hh"][row] = c["radius"][row] = shape.radius
        elif isinstance(shape, Capsule):
            # hw, hh: the half extents upright (the geometry turns them); radius: the capsule's
            c["kind"][row] = KIND_CAPSULE
            c["hw"][row] = c["radius"][row] = shape.radius
            c["hh"][row] = shape.half_length + shape.radius
        elif isinstance(shape, Segment):
            # (its outline of two points is in the geometry, as a polygon's)
            c["kind"][row] = KIND_SEGMENT
            c["hw"][row] = c["hh"][row] = c["radius"][row] = 0.0
        else:
            c["kind"][row] = KIND_POLYGON
            c["hw"][row] = c["hh"][row] = c["radius"][row] = 0.0
        c["bound"][row] = shape.bounding_radius
        c["ox"][row], c["oy"][row] = hb._offset
        c["layer"][row], c["mask"][row] = hb._layer, hb._mask
        c["sensor"][row], c["ccd"][row], c["one_way"][row] = hb._sensor, hb._ccd, hb._one_way
        c["body"][row] = BODY_CODES[hb._body]
        c["inv_mass"][row] = hb.inverse_mass
        c["restitution"][row] = hb._restitution
        c["friction"][row] = NO_FRICTION if hb._friction is None else hb._friction
        c["inv_inertia"][row] = _inverse_inertia(hb)

    # --- a step that may be undone (framework.rollback) --------------------------------------

    def begin_undo(self) -> None:
        """From now on, save each static row (of the rows there are now) before its first change:
        the rollback of a step keeps the rows that are not static whole, and a static row changes
        only when game code writes it or the scene's structure changes (the pipeline never moves
        one), so a level of 100,000 tiles costs nothing to keep."""
        self._undo, self._undo_n = {}, self.n

    def end_undo(self) -> dict[int, NDArray[np.float64]]:
        """Stop saving; the static rows saved, each as its :data:`ROW_STATE` values."""
        saved, self._undo = self._undo or {}, None
        return saved

    def _before_change(self, row: int) -> None:
        undo = self._undo
        if undo is not None and row < self._undo_n and row not in undo and self.cols["body"][row] == STATIC:
            c = self.cols
            undo[row] = np.array([c[name][row] for name in ROW_STATE], dtype=np.float64)

    # --- component views -------------------------------------------------------------------

    def read(self, entity: int, col: str) -> Any:
        bad = self.bad.get((entity, col), _MISSING) if self.bad else _MISSING
        if bad is not _MISSING:
            return bad
        return float(self.cols[col][self.row_of[entity]])

    def wake(self, rows: NDArray[np.intp] | int) -> None:
        """Wake sleeping rows (game code moved them, or something touched them)."""
        asleep = self.cols["asleep"]
        rows = np.atleast_1d(rows)
        if asleep[rows].any():
            asleep[rows] = False
            self.sleep_dirty = True
            self.wakes += 1
        self.cols["still"][rows] = 0

    def write(self, entity: int, col: str, value: object) -> None:
        row = self.row_of[entity]
        if self._undo is not None:
            self._before_change(row)
        if col in ("x", "y", "rot"):
            self.writes += 1
        self.written.add(entity)
        if self.cols["asleep"][row] or self.cols["still"][row]:
            self.wake(row)
        try:
            number = float(value) if isinstance(value, Real) and not isinstance(value, bool) else None
        except (OverflowError, ValueError):  # an int beyond float64 (10**400): not a finite float
            number = None
        if number is not None:
            self.cols[col][row] = number
            if self.bad:
                self.bad.pop((entity, col), None)
        else:
            self.bad[(entity, col)] = value
            self.cols[col][row] = math.nan
        if col in ("x", "y", "rot") and self.cols["body"][row] == STATIC and self.cols["kind"][row] >= 0:
            self.static_dirty = True

    def hitbox_changed(self, entity: int) -> None:
        self.dirty_hitboxes.add(entity)

    # --- checks at the start of a step -----------------------------------------------------

    def check(self) -> None:
        """Raise :class:`InvalidValue` naming the entity and field of the first bad value.

        Changes nothing, so a failed step leaves the scene exactly as it was."""
        # Static rows change only through game code's writes: check those and the rows that move.
        rows = self.active()[2]
        extra = np.array([self.row_of[e] for e in self.written if e in self.row_of], dtype=np.int64) \
            if self.written else None
        if not self.bad and not self.dirty_hitboxes:
            c = self.cols  # (the columns whole: the pass reads only the rows asked, all below n)
            xs, ys, rot, vx, vy, w = c["x"], c["y"], c["rot"], c["vx"], c["vy"], c["w"]
            if rows_sound(xs, ys, rot, vx, vy, w, rows, MAX_COORD) and (
                    extra is None or rows_sound(xs, ys, rot, vx, vy, w, extra, MAX_COORD)):
                self.written.clear()
                return
        sel = self.active_sel()[2]
        if extra is not None:  # (a row found wrong below is named once, in row order)
            rows = sel = np.union1d(rows, extra)
        problems: list[tuple[int, str, object]] = [(e, col, v) for (e, col), v in self.bad.items()]
        cols = ("x", "y", "rot", "vx", "vy", "w")
        # First all six at once: the sum of finite values is finite unless it overflows, which
        # only sends us to the column-by-column look below.
        with np.errstate(over="ignore", invalid="ignore"):
            total = self.cols["x"][sel] + self.cols["y"][sel]
            for col in cols[2:]:
                total += self.cols[col][sel]
        all_finite = bool(np.isfinite(total).all())
        for col in () if all_finite else cols:
            values = self.cols[col][sel]
            ok = np.isfinite(values)
            if not ok.all():
                for row in rows[~ok]:
                    e = int(self.cols["entity"][row])
                    if (e, col) not in self.bad:
                        problems.append((e, col, float(self.cols[col][row])))
        for e in sorted(self.dirty_hitboxes):
            hb = self.hitboxes[self.row_of[e]]
            if hb is None:  # (a part of a body without a Hitbox: the scene's checks refuse it)
                continue
            for name in _HITBOX_FIELD_NAMES:
                try:
                    value = check_hitbox_field(name, object.__getattribute__(hb, "_" + name))
                except InvalidValue as exc:
                    raise InvalidValue(f"entity {e}: {exc}") from None
                if name == "body" and value is Body.STATIC and self.cols["has_vel"][self.row_of[e]]:
                    raise InvalidValue(f"entity {e}: Hitbox body is static, but a static body never moves: "
                                       "remove its Velocity first (or make it kinematic)")
            try:
                check_mass_and_density(hb)
                check_hitbox_limits(hb)
            except InvalidValue as exc:
                raise InvalidValue(f"entity {e}: {exc}") from None
            parts = self.parts.get(e)
            for i, part in enumerate(parts.hitboxes if parts is not None else ()):
                try:
                    for name in _HITBOX_FIELD_NAMES:
                        check_hitbox_field(name, object.__getattribute__(part, "_" + name))
                    check_mass_and_density(part)
                    check_hitbox_limits(part)
                except InvalidValue as exc:
                    raise InvalidValue(f"entity {e}: part {i + 1}: {exc}") from None
        if problems:
            e, col, v = min(problems, key=lambda p: (p[0], p[1]))
            raise InvalidValue(f"entity {e}: {_FIELD_NAMES[col]} must be a finite number, got {v!r}")
        # positions within the scene's range (framework.limits)
        with np.errstate(invalid="ignore"):
            far = np.maximum(np.abs(self.cols["x"][sel]), np.abs(self.cols["y"][sel])) > MAX_COORD
        if far.any():
            row = int(np.atleast_1d(rows)[np.flatnonzero(far)[0]])
            e = int(self.cols["entity"][row])
            check_position(float(self.cols["x"][row]), float(self.cols["y"][row]), f"entity {e}: Transform")
        self.written.clear()

    def apply_hitbox_changes(self) -> set[int]:
        """Re-derive the rows of hitboxes that game code edited; return those entities."""
        changed = self.dirty_hitboxes
        for e in changed:
            row = self.row_of[e]
            if self._undo is not None:
                self._before_change(row)
            hb = self.hitboxes[row]
            if hb is None:  # (a part edited on an entity whose Hitbox was removed: refused by the scene's checks)
                continue
            try:
                for name in ("offset", "layer", "mask", "body", "mass", "restitution", "friction", "inertia",
                             "density"):
                    value = check_hitbox_field(name, object.__getattribute__(hb, "_" + name))
                    object.__setattr__(hb, "_" + name, value)
                check_mass_and_density(hb)
            except InvalidValue as err:
                raise InvalidValue(f"entity {e}: {err}") from None
            parts = self.parts.get(e)
            for part in parts.hitboxes if parts is not None else ():
                check_component(part)  # (checked above: normalises its fields in place)
            self._set_hitbox_row(row, hb)
        self.dirty_hitboxes = set()
        if changed:
            self.wake(np.array([self.row_of[e] for e in changed], dtype=np.int64))
            self.version += 1
            self.static_dirty = True
        return changed


def _live_rows(name: str) -> property:
    """The live rows of one column, ``cols[name][:n]``, as a property: found by the class's own
    lookup (a ``__getattr__`` served them before, after a failed lookup had raised: 0.76 us a
    read against 0.26 us; the exact step reads a hundred to three hundred of them)."""

    def rows(self: BodyStore) -> NDArray[Any]:
        return self.cols[name][: self.n]

    return property(rows, doc=f"The live rows of the ``{name}`` column.")


if not TYPE_CHECKING:  # (mypy reads the declarations in the class)
    for _name in (*_FLOATS, *_INTS, *_BOOLS):
        setattr(BodyStore, _name, _live_rows(_name))


_MISSING = object()


def _inverse_inertia(hb: Hitbox) -> float:
    """1 / the moment of inertia of a body that contacts turn (with the ``rotation`` effect), else
    0: a dynamic circle, box or polygon centred on its entity (it turns about its entity's
    position), of finite mass and inertia; the inertia given, or the mass times the shape's second
    moment about that point (a solid disk's ``m r^2 / 2``, a box's ``m (w^2 + h^2) / 12``). An
    ``AABB`` never turns, and neither does a ``Capsule`` (contacts push it like an AABB; its
    rotation is the game's to set). This is the exact solver's column: the soft step turns a body
    whose centre of mass is off its origin about that centre, with its inertia about it
    (:func:`~framework.systems.soft_step.kernel_tables`)."""
    shape = hb._shape
    if hb._body is not Body.DYNAMIC or isinstance(shape, (AABB, Capsule)) or hb._offset != (0.0, 0.0):
        return 0.0
    inertia = hb._inertia if hb._inertia is not None else hb.effective_mass * shape.second_moment
    return 0.0 if math.isinf(inertia) else 1.0 / inertia
