"""The soft step: movement, detection and response as one compiled call (``Scene(solver="soft")``).

Box2D v3's "soft step" (sub-steps, soft contacts, relax, restitution, warm starting) over every
body in one call of :func:`~framework.systems.soft_kernel.soft_step`, in place of the exact
pipeline's movement, continuous detection, broad phase, narrow phase and response stages. It is
the accuracy knob for speed: bodies at rest sit within a small fraction of the linear slop of their
exact height instead of on it, and contacts are measured in floats (a pair counts as touching from
the first overlap until it is more than the slop apart), where the exact pipeline decides touching
exactly. See docs/physics.md.

What stays outside the call, in Python: the shape tables (rebuilt only after a structural change),
the pair tracking handed to the frame (started, ongoing and ended pairs as arrays; event objects
are made only when asked for), waking the sleepers an awake body touched. The stage runs where the
response does: a game processor placed between the exact pipeline's physics stages runs before it.
"""

from __future__ import annotations

import math
from typing import Any

import esper
import numpy as np

from ..character import CharacterController
from ..compile_notice import notice_if_slow
from ..components import Body, body_mass_data
from ..events import StepContacts
from ..frame import StepFrame
from ..joints import (
    DISTANCE,
    MOTOR,
    MOUSE,
    PRISMATIC,
    REVOLUTE,
    WELD,
    WHEEL,
    DistanceJoint,
    Joint,
    MotorJoint,
    PrismaticJoint,
    RevoluteJoint,
    WeldJoint,
    WheelJoint,
    check_joints,
    joint_components,
    joint_writes,
)
from ..shapes import AABB, Capsule, ChainSegment, Circle, Polygon, Segment
from ..store import DYNAMIC, KIND_AABB, KIND_CAPSULE, KIND_CIRCLE, KIND_POLYGON, KIND_SEGMENT, NO_FRICTION, STATIC
from ..validation import InvalidValue
from .soft_joints import JOINT_F, JOINT_IMP
from .soft_kernel import CHAIN_KIND, PARAMS, SLOT, internal_faces, soft_step
from .stage import PRIORITY, Stage

__all__ = ["COMPILE_NOTICE", "SOFT_SETTINGS", "SoftStep", "kernel_tables"]

#: Box2D v3's defaults, in metres (scaled by ``Scene(length_unit=...)``): linear slop, contact
#: stiffness (hertz) and damping ratio, the fastest push out of an overlap, the slowest approach
#: that bounces, sub-steps per step, how far a moving body's fat bounds reach beyond it (its
#: candidate pairs are found again only when it leaves them), and the joints' stiffness (hertz, at
#: most a quarter of the sub-step rate) and damping ratio.
SOFT_SETTINGS = {"slop": 0.005, "hertz": 30.0, "damping": 10.0, "push_speed": 3.0, "restitution_threshold": 1.0,
                 "substeps": 4, "fat_margin": 0.1, "joint_hertz": 60.0, "joint_damping": 2.0}
# the store's columns the kernel reads (and writes: the pose and velocity), in its argument order
_KERNEL_COLUMNS = ("x", "y", "rot", "vx", "vy", "w", "asleep")
# a scene without joints passes these
_NO_JF = np.zeros((0, len(JOINT_F)))
_NO_IMP = np.zeros((0, len(JOINT_IMP)))
_NO_KEYS = np.zeros(0, dtype=np.int64)
_JF = {name: i for i, name in enumerate(JOINT_F)}


def joint_tables(joints: list[tuple[int, Joint]], row_of: dict[int, int]) -> tuple[np.ndarray, ...]:
    """The kernel's joint tables (:mod:`~framework.systems.soft_joints`) for ``joints`` (checked
    and attached): ``(jint, jf, keys, apart)``; ``keys``: each joint's warm-start key (entity * 8 +
    kind); ``apart``: the sorted pair keys of the bodies that must not collide."""
    m = len(joints)
    jint = np.empty((m, 3), dtype=np.int64)
    jf = np.zeros((m, len(JOINT_F)))
    keys = np.empty(m, dtype=np.int64)
    apart = []
    for i, (e, j) in enumerate(joints):
        frame = j._frame
        assert frame is not None
        ra, rb = row_of[j.a], (-1 if j.b is None else row_of[j.b])
        keys[i] = 8 * e + j.kind
        jint[i] = (j.kind, ra, rb)
        row = jf[i]
        row[0:5] = frame
        if j.kind == DISTANCE:
            assert isinstance(j, DistanceJoint)
            lo, hi = j.limits()
            length = max(j.length or 0.0, lo)
            if hi is not None:
                length = min(length, hi)
            row[_JF["length"]], row[_JF["lo"]] = length, lo
            row[_JF["hi"]], row[_JF["has_hi"]] = (0.0, 0.0) if hi is None else (hi, 1.0)
            row[_JF["hertz"]], row[_JF["damping"]] = j.hertz, j.damping
        elif j.kind == WELD:
            assert isinstance(j, WeldJoint)
            row[_JF["hertz"]], row[_JF["damping"]] = j.hertz, j.damping
        elif j.kind in (REVOLUTE, PRISMATIC, WHEEL):
            # the kernel turns (and slides) its b relative to its a, along its a's axis: a and b swap
            assert isinstance(j, (RevoluteJoint, PrismaticJoint, WheelJoint))
            jint[i] = (j.kind, jint[i, 2], ra)
            row[0:5] = (frame[2], frame[3], frame[0], frame[1], -frame[4])
            if j.lower is not None:
                row[_JF["lower"]], row[_JF["has_lower"]] = j.lower, 1.0
            if j.upper is not None:
                row[_JF["upper"]], row[_JF["has_upper"]] = j.upper, 1.0
            row[_JF["speed"]] = j.motor_speed
            if isinstance(j, PrismaticJoint):  # a motor along the axis
                row[_JF["force"]] = j.max_motor_force
            else:  # a motor turning it
                row[_JF["torque"]] = j.max_motor_torque
            # the wheel's suspension; the revolute's or the prismatic's spring (hertz 0: none)
            row[_JF["hertz"]], row[_JF["damping"]] = j.hertz, j.damping
            if not isinstance(j, RevoluteJoint):
                row[_JF["axis_x"]], row[_JF["axis_y"]] = j._axis_local
        elif j.kind == MOUSE:  # the world's anchor is the target; the body is b to the kernel
            jint[i] = (MOUSE, -1, ra)
            row[0:5] = (*j.target, frame[0], frame[1], 0.0)  # type: ignore[attr-defined]
            row[_JF["hertz"]], row[_JF["damping"]] = j.hertz, j.damping  # type: ignore[attr-defined]
            row[_JF["force"]] = j.max_force  # type: ignore[attr-defined]
        elif j.kind == MOTOR:  # b (the frame of the target) is the kernel's a, the body driven its b
            assert isinstance(j, MotorJoint) and j.linear_offset is not None and j.angular_offset is not None
            jint[i] = (MOTOR, jint[i, 2], ra)
            row[0:5] = (*j.linear_offset, 0.0, 0.0, j.angular_offset)
            row[_JF["force"]], row[_JF["torque"]] = j.max_force, j.max_torque
            row[_JF["correction"]] = j.correction_factor
        if j.b is not None and not j.collide_connected:
            apart.append((min(j.a, j.b) << 32) | max(j.a, j.b))
    return jint, jf, keys, np.array(sorted(set(apart)), dtype=np.int64)


def kernel_tables(store, detection: bool = True) -> tuple[np.ndarray, ...]:
    """What the kernel reads of each row that changes only with the rows (a hitbox's fields and
    shape, its body kind, its entity): ``(fprops, iprops, off, verts)``, see
    :func:`~framework.systems.soft_kernel.soft_step`. Every hitbox is a rounded polygon about its
    hitbox origin (vertex count 0: no hitbox, or ``detection`` off): AABBs do not turn with the
    transform (their offset does); circles are one vertex, capsules their segment, segments their
    two ends with radius 0 (Box2D's segment as a polygon of two points: each side a face); a chain
    segment also its ghost vertices, in the vertex slots after its ends, and the shape kind
    ``CHAIN_KIND``.

    ``off`` rows: the hitbox offset, then the centre of mass the soft step turns the body about
    (:attr:`~framework.components.Hitbox.mass_data`'s ``center``: a dynamic circle's or polygon's
    whose centre is not its entity's origin; (0, 0) for every other row, which turns about its
    origin as before: a kinematic body, as in Box2D; a capsule and an AABB, which contacts do not
    turn). Such a body's inverse inertia (``fprops`` row 1) is about that centre: the store's
    column holds the exact solver's, about the origin.

    ``iprops`` rows 10 to 12: each shape row's owner (the body row that poses it and takes its
    contacts' impulses), its key id (the pairs' keys are made of these: a body's entity for its own
    row) and its part number (0: the entity's Hitbox). A compound body
    (:class:`~framework.components.Parts`) has a shape row for each of its other parts after the
    store's rows (:func:`_part_rows`): its own row takes the whole body's mass, inertia and centre of
    mass. Without compound bodies there are none, and rows 10 to 12 are ``arange(n)``, the
    entities and zeros: the kernel does exactly what it did before they existed."""
    n = store.n
    polys = [store.shapes[r] for r in range(n)]
    kinds = store.kind[:n].tolist()
    compound = [(store.row_of[e], parts) for e, parts in sorted(store.parts.items())
                if store.hitboxes[store.row_of[e]] is not None]
    part_shapes = [hb._shape for _r, parts in compound for hb in parts.hitboxes]
    K = max([4] + [len(s.points) for s, k in zip(polys, kinds) if k == KIND_POLYGON]
            + [len(s.points) for s in part_shapes if isinstance(s, Polygon)])
    off = np.zeros((n, 4))
    off[:, 0], off[:, 1] = store.ox, store.oy
    inv_inertia = store.inv_inertia
    bodies = store.body[:n].tolist()
    for r, k in enumerate(kinds):
        if (k == KIND_CIRCLE or k == KIND_POLYGON) and bodies[r] == DYNAMIC and not (
                compound and int(store.entity[r]) in store.parts):  # (a compound body's: the whole body's, below)
            hb = store.hitboxes[r]
            gx, gy = polys[r].centroid
            cx, cy = float(store.ox[r]) + gx, float(store.oy[r]) + gy
            if hb is None or (cx == 0.0 and cy == 0.0):
                continue
            if inv_inertia is store.inv_inertia:
                inv_inertia = inv_inertia.copy()
            off[r, 2], off[r, 3] = cx, cy
            inertia = hb._inertia if hb._inertia is not None else hb.effective_mass * polys[r].central_moment
            inv_inertia[r] = 0.0 if math.isinf(inertia) else 1.0 / inertia
    verts = np.zeros((n, K, 4))  # local vertices (x, y), then the edges' outward normals
    chain: list[int] = []  # the rows of chain segments
    cnt = np.zeros(n, dtype=np.int64)
    rr = np.zeros(n)
    spin = np.ones(n, dtype=np.int64)
    box_n = ((0.0, -1.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0))
    for r, k in enumerate(kinds):
        if k == KIND_AABB:
            hw, hh = float(store.hw[r]), float(store.hh[r])
            verts[r, :4, 0:2] = ((-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh))
            verts[r, :4, 2:4] = box_n
            cnt[r], spin[r] = 4, 0
        elif k == KIND_CIRCLE:
            cnt[r], rr[r] = 1, float(store.radius[r])
        elif k == KIND_CAPSULE:
            h = polys[r].half_length
            verts[r, :2, 0:2] = ((0.0, -h), (0.0, h))
            verts[r, :2, 2:4] = ((1.0, 0.0), (-1.0, 0.0))
            cnt[r], rr[r] = 2, float(store.radius[r])
        elif k == KIND_POLYGON:
            pts = polys[r].points
            m = len(pts)
            for i in range(m):
                (x1, y1), (x2, y2) = pts[i], pts[(i + 1) % m]
                ex, ey = x2 - x1, y2 - y1
                d = math.hypot(ex, ey)
                verts[r, i] = (x1, y1, ey / d, -ex / d)
            cnt[r] = m
        elif k == KIND_SEGMENT:
            (x1, y1), (x2, y2) = polys[r].a, polys[r].b
            ex, ey = x2 - x1, y2 - y1
            d = math.hypot(ex, ey)
            verts[r, :2] = ((x1, y1, ey / d, -ex / d), (x2, y2, -ey / d, ex / d))
            cnt[r] = 2
            if isinstance(polys[r], ChainSegment):  # its ghosts after its ends (the kernel reads them there)
                verts[r, 2, 0:2], verts[r, 3, 0:2] = polys[r].ghost1, polys[r].ghost2
                chain.append(r)
    if not detection:
        cnt[:] = 0
    fprops = np.stack([store.inv_mass, inv_inertia, store.friction, store.restitution, store.bound, rr])
    kind = store.kind.astype(np.int64)
    kind[chain] = CHAIN_KIND  # (the kernel's code of a chain segment)
    iprops = np.stack([store.body.astype(np.int64), kind, store.layer, store.mask,
                       store.entity, store.sensor.astype(np.int64), store.one_way.astype(np.int64),
                       store.has_vel.astype(np.int64), cnt, spin, np.arange(n, dtype=np.int64),
                       store.entity.astype(np.int64), np.zeros(n, dtype=np.int64)])
    if compound:
        fprops, iprops, off, verts = _part_rows(store, compound, fprops, iprops, off, verts)
        if not detection:
            iprops[8, n:] = 0
    return fprops, iprops, off, verts


#: A part's key id (``kernel_tables``' ``iprops`` row 11): ``PART_BASE + (entity << 6) + part``, above
#: every entity's own (an entity's key id is the entity): the pairs' keys stay unique and sorted.
PART_BASE = 1 << 30
#: Compound bodies take entity ids below this (their parts' key ids must stay below 2**31).
MAX_COMPOUND_ENTITY = 1 << 24


def part_ids(sids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The entities and part numbers of shape rows' key ids (``iprops`` row 11)."""
    sids = np.asarray(sids, dtype=np.int64)
    is_part = sids >= PART_BASE
    rest = sids - PART_BASE
    return np.where(is_part, rest >> 6, sids), np.where(is_part, rest & 63, 0)


def _shape_row(shape: Any, vrow: np.ndarray) -> tuple[int, int, float, int]:
    """A part's shape as the kernel reads it (as ``kernel_tables`` packs a row's): its kind code,
    vertex count, rounding radius and whether it turns with its body; its local vertices and the
    edges' outward normals written into ``vrow``."""
    if isinstance(shape, AABB):
        hw, hh = shape.width * 0.5, shape.height * 0.5
        vrow[:4, 0:2] = ((-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh))
        vrow[:4, 2:4] = ((0.0, -1.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0))
        return KIND_AABB, 4, 0.0, 0
    if isinstance(shape, Circle):
        return KIND_CIRCLE, 1, shape.radius, 1
    if isinstance(shape, Capsule):
        h = shape.half_length
        vrow[:2, 0:2] = ((0.0, -h), (0.0, h))
        vrow[:2, 2:4] = ((1.0, 0.0), (-1.0, 0.0))
        return KIND_CAPSULE, 2, shape.radius, 1
    if isinstance(shape, Segment):
        (x1, y1), (x2, y2) = shape.a, shape.b
        ex, ey = x2 - x1, y2 - y1
        d = math.hypot(ex, ey)
        vrow[:2] = ((x1, y1, ey / d, -ex / d), (x2, y2, -ey / d, ex / d))
        if isinstance(shape, ChainSegment):
            raise InvalidValue("a chain segment cannot be a part of a compound body (spawn_chain spawns a body each)")
        return KIND_SEGMENT, 2, 0.0, 1
    pts = shape.points
    m = len(pts)
    for i in range(m):
        (x1, y1), (x2, y2) = pts[i], pts[(i + 1) % m]
        ex, ey = x2 - x1, y2 - y1
        d = math.hypot(ex, ey)
        vrow[i] = (x1, y1, ey / d, -ex / d)
    return KIND_POLYGON, m, 0.0, 1


def _part_rows(store, compound: list[tuple[int, Any]], fprops: np.ndarray, iprops: np.ndarray, off: np.ndarray,
               verts: np.ndarray) -> tuple[np.ndarray, ...]:
    """``kernel_tables``' tables with a shape row for each part of the ``compound`` bodies (their
    rows, their Parts) appended, and each such body's own row given the whole body's inverse mass,
    inverse inertia about its centre of mass, and that centre (``off`` columns 2, 3)."""
    n = store.n
    m = sum(len(parts) for _r, parts in compound)
    fprops = np.concatenate([fprops, np.zeros((fprops.shape[0], m))], axis=1)
    iprops = np.concatenate([iprops, np.zeros((iprops.shape[0], m), dtype=np.int64)], axis=1)
    off = np.concatenate([off, np.zeros((m, 4))])
    verts = np.concatenate([verts, np.zeros((m, verts.shape[1], 4))])
    q = n
    for r, parts in compound:
        hb = store.hitboxes[r]
        e = int(store.entity[r])
        data = body_mass_data(hb, parts)
        cx, cy = data.center
        dynamic = hb._body is Body.DYNAMIC
        turns = dynamic and all(isinstance(h._shape, (Circle, Polygon)) for h in (hb, *parts.hitboxes))
        fprops[0, r] = 1.0 / data.mass if dynamic else 0.0
        fprops[1, r] = 1.0 / data.inertia if turns and not math.isinf(data.inertia) else 0.0
        off[r, 2], off[r, 3] = (cx, cy) if dynamic else (0.0, 0.0)
        for i, part in enumerate(parts.hitboxes, start=1):
            shape = part._shape
            kind, cnt, radius, spin = _shape_row(shape, verts[q])
            ox, oy = part._offset
            reach = max(math.hypot(ox, oy), math.hypot(ox - off[r, 2], oy - off[r, 3]))
            fprops[2, q] = NO_FRICTION if part._friction is None else part._friction
            fprops[3, q] = part._restitution
            fprops[4, q] = shape.bounding_radius + reach  # (its reach about its body's turning point)
            fprops[5, q] = radius
            iprops[:, q] = (iprops[0, r], kind, part._layer, part._mask, e, int(part._sensor), int(part._one_way),
                            iprops[7, r], cnt, spin, r, PART_BASE + (e << 6) + i, i)
            off[q, 0], off[q, 1] = ox, oy
            q += 1
    return fprops, iprops, off, verts


def _by_entity(cols: tuple[np.ndarray, ...], contacts: StepContacts) -> tuple[tuple[np.ndarray, ...], StepContacts]:
    """A compound scene's contacts (and ``cols`` beside them: rows then parts, as pairs, then any
    other) named as events name pairs: smaller entity first (swapped where not, normal negated),
    sorted by entities, then parts."""
    ea, eb = contacts.a, contacts.b
    swap = ea > eb
    out = list(cols)
    if swap.any():
        for i in range(0, 4 if len(out) >= 4 else 2, 2):
            out[i], out[i + 1] = np.where(swap, out[i + 1], out[i]), np.where(swap, out[i], out[i + 1])
        contacts = StepContacts(np.where(swap, eb, ea), np.where(swap, ea, eb),
                                np.where(swap, 0.0 - contacts.nx, contacts.nx),
                                np.where(swap, 0.0 - contacts.ny, contacts.ny), contacts.depth, contacts.px,
                                contacts.py)
    pa, pb = (out[2], out[3]) if len(out) >= 4 else (out[0], out[1])
    order = np.lexsort((pb, pa, contacts.b, contacts.a))
    return tuple(c[order] for c in out), contacts.take(order)


# the kernel's variants called in this process: (with joints, with capsules or chain segments)
_COMPILED: set[tuple[bool, bool]] = set()
_RARE = np.int64(1)  # (the kernel's ``rare``: capsules or chain segments in the scene; None: neither)
COMPILE_NOTICE = ("framework: compiling the soft step (once per installation, about 20 seconds, and again "
                  "for the first scene with joints, or with capsules or chains; later runs load it from numba's "
                  "cache)")


def _first_call(args: tuple[Any, ...], variant: tuple[bool, bool]) -> tuple[Any, ...]:
    """The kernel's first call in this process for scenes with joints or without, with capsules or
    chain segments or without (``variant``): if it has not returned within a second (numba is
    compiling it, not loading it from its cache), say so on stderr, once. (The variants are
    compiled apart: a scene without joints compiles none of the joints' code, one without capsules
    and chains none of their manifolds'.)"""
    try:
        with notice_if_slow(COMPILE_NOTICE):
            return soft_step(*args)
    finally:
        _COMPILED.add(variant)


class SoftStep(Stage):
    """Movement, detection and response in one compiled call, for ``Scene(solver="soft")``."""

    name = "soft_step"
    needs = frozenset()
    solver = "soft"

    def __init__(self, pipeline) -> None:
        super().__init__(pipeline)
        self.priority = PRIORITY["response"] + 1  # where the response runs (see the module docstring)
        self._tables_key: tuple[int, int, bool] | None = None
        self._params = np.zeros(len(PARAMS))
        self._settings_key: tuple[Any, ...] | None = None
        self._cols: tuple[np.ndarray, ...] = ()
        self._kernel_tables: tuple[np.ndarray, ...] = ()
        self._rare: np.int64 | None = None  # (the kernel's ``rare``, found with the tables)
        self._faces_key: tuple[int, int, int, bool] | None = None
        self._faces = np.zeros(0, dtype=np.int64)
        self._no_driven = np.zeros(0, dtype=np.bool_)
        self._joint_key: tuple[Any, ...] = (None, None, None)  # what the packed joint tables were packed from
        self._joint_tables: tuple[np.ndarray, ...] = ()
        self.reset()

    def reset(self) -> None:
        """Forget the candidate pairs and their contacts (warm starts and touching pairs)."""
        self.pairs = np.zeros((0, 3), dtype=np.int64)  # rows a, b and key (entity a << 32 | entity b)
        self.slots = np.zeros((0, len(SLOT)))
        self.fat = np.zeros((0, 4))
        self._pairs_key: tuple[int, int, bool] | None = None
        self.joints: tuple[np.ndarray, ...] = (_NO_KEYS, _NO_IMP, _NO_JF)  # keys, impulses, parameters

    def state(self) -> tuple[Any, ...]:
        """What the next step starts from (the kernel never modifies these arrays in place: a
        step replaces them, so keeping the references keeps the state)."""
        return self.fat, self.pairs, self.slots, self._pairs_key, self.joints

    def restore(self, state: tuple[Any, ...]) -> None:
        """Start the next step from ``state`` (of :meth:`state`)."""
        self.fat, self.pairs, self.slots, self._pairs_key, self.joints = state

    def reaction(self, entity: int, joint: Joint) -> tuple[float, float, float]:
        """The force ``(fx, fy)`` and torque the joint on ``entity`` applied to its body ``a`` in the
        last step (Box2D's constraint force and torque: the impulse of the last sub-step over its
        length; the torque is the joint's angular part: a motor's, a limit's, a weld's, not the
        moment of the force). Zeros before a step has solved it."""
        keys, imp, jf = self.joints
        key = 8 * entity + joint.kind
        i = int(np.searchsorted(keys, key))  # (keys are sorted: the joints come by entity, then kind)
        dt, nsub = self._params[PARAMS.index("dt")], self._params[PARAMS.index("substeps")]
        if i == keys.size or keys[i] != key or dt <= 0.0 or nsub <= 0:
            return 0.0, 0.0, 0.0
        inv_h = nsub / dt
        px, py, lower, upper, angular, spring = (float(v) for v in imp[i])
        if joint.kind == DISTANCE:  # along the line between the anchors (the kernel's b takes +impulse)
            store = self.bodies.store
            c = store.cols

            def world(body: int | None, lx: float, ly: float) -> tuple[float, float]:
                if body is None:
                    return lx, ly
                r = store.row_of[body]
                co, si = math.cos(c["rot"][r]), math.sin(c["rot"][r])
                return float(c["x"][r] + co * lx - si * ly), float(c["y"][r] + si * lx + co * ly)

            (ax, ay), (bx, by) = world(joint.a, jf[i, 0], jf[i, 1]), world(joint.b, jf[i, 2], jf[i, 3])
            d = math.hypot(bx - ax, by - ay)
            axial = px + lower - upper
            if d == 0.0:
                return 0.0, 0.0, 0.0
            return -axial * (bx - ax) / d * inv_h, -axial * (by - ay) / d * inv_h, 0.0
        if joint.kind in (PRISMATIC, WHEEL):  # along the axis (turned with b), across it, and the torque
            assert isinstance(joint, (PrismaticJoint, WheelJoint))
            store = self.bodies.store
            rot = 0.0 if joint.b is None else float(store.cols["rot"][store.row_of[joint.b]])
            lx, ly = joint._axis_local
            ux, uy = math.cos(rot) * lx - math.sin(rot) * ly, math.sin(rot) * lx + math.cos(rot) * ly
            # (the kernel's b is the joint's a: it takes +impulse)
            if joint.kind == PRISMATIC:  # along: motor, limits and spring; about: the angle's
                axial, turn = angular + lower - upper + spring, py
            else:  # along: spring and limits; about: the motor's
                axial, turn = py + lower - upper, angular
            return (axial * ux - px * uy) * inv_h, (axial * uy + px * ux) * inv_h, turn * inv_h
        turn = (angular + lower - upper + spring) * inv_h  # (spring: a revolute joint's)
        if joint.kind in (REVOLUTE, MOUSE, MOTOR):  # the kernel's b is the joint's a (see joint_tables)
            return px * inv_h, py * inv_h, turn
        return -px * inv_h, -py * inv_h, -turn  # a weld: the kernel's a is the joint's a

    def wanted(self) -> bool:
        effects = self.pipeline.effects
        return self.pipeline.solver == "soft" and bool(effects & {"movement", "detection"})

    def _tables(self) -> tuple[np.ndarray, ...]:
        """:func:`kernel_tables` and the pose and velocity columns (views of the live rows), kept
        until the rows, the columns' storage or the detection effect change."""
        store = self.bodies.store
        c = store.cols
        key = (store.version, store.n, "detection" in self.pipeline.effects)
        # (views of these very columns: a restored scene's copies are views of nothing, and an
        # unpickled copy of a column is not the column)
        if key != self._tables_key or not self._cols or self._cols[0].base is not c["x"]:
            n = store.n
            self._cols = tuple(c[name][:n] for name in _KERNEL_COLUMNS)
            self._kernel_tables = kernel_tables(store, key[-1])
            kinds = self._kernel_tables[1][1]  # (each shape row's kind, a chain segment's its own code)
            self._rare = _RARE if bool(((kinds == KIND_CAPSULE) | (kinds == CHAIN_KIND)).any()) else None
            self._tables_key = key
        return self._cols + self._kernel_tables + (self._internal_faces(),)

    def _internal_faces(self) -> np.ndarray:
        """Each row's internal faces (:func:`~framework.systems.soft_kernel.internal_faces`): the
        faces of static boxes that other static boxes cover, found again when the statics change."""
        store = self.bodies.store
        key = (store.version, store.static_epoch, store.n, "detection" in self.pipeline.effects)
        if key != self._faces_key:
            n = store.n
            fprops, iprops, off, verts = self._kernel_tables
            eligible = ((store.kind[:n] == KIND_AABB) & (store.body[:n] == STATIC) & ~store.sensor[:n]
                        & ~store.one_way[:n])
            c = store.cols
            half = np.ascontiguousarray(verts[:n, 2, 0:2])  # an AABB's corner 2: its half extents
            if np.count_nonzero(eligible) < 2:  # (one static box covers no face: nor is the pass compiled)
                self._faces = np.zeros(n, dtype=np.int64)
            else:
                self._faces = internal_faces(c["x"][:n], c["y"][:n], c["rot"][:n], off[:n], half, iprops[8, :n],
                                             eligible, iprops[2, :n], iprops[3, :n])
            if iprops.shape[1] > n:  # (the parts of compound bodies: no internal faces)
                self._faces = np.concatenate([self._faces, np.zeros(iprops.shape[1] - n, dtype=np.int64)])
            self._faces_key = key
        return self._faces

    def _driven(self, frame: StepFrame) -> np.ndarray:
        """Rows the character stage moved this step (the soft step moves them no further)."""
        n = self.bodies.store.n
        if self._no_driven.size != n:
            self._no_driven = np.zeros(n, dtype=np.bool_)
        if not frame.counters.get("characters"):
            return self._no_driven
        rows = self.bodies.rows_of([e for e, _c in esper.get_component(CharacterController)])
        driven = np.zeros(n, dtype=np.bool_)
        driven[rows[rows >= 0]] = True
        return driven

    def _settings(self, frame: StepFrame) -> np.ndarray:
        """The kernel's ``params`` for this step (rebuilt only when a setting changed)."""
        pipe, store = self.pipeline, self.bodies.store
        effects = pipe.effects
        # the scene's own sub-steps stiffen the joints with the sub-step rate (see joint_stiffness)
        runs = int(getattr(pipe.view, "substeps", 1))
        open_layers = store.layers_all_meet()
        key = (frame.dt, effects, pipe.gravity, pipe.length_unit, open_layers, runs)
        if key != self._settings_key:
            unit, s = pipe.length_unit, SOFT_SETTINGS
            gx, gy = pipe.active_gravity()
            moves = "movement" in effects
            self._params[:] = (frame.dt if moves else 0.0, s["substeps"] if moves else 0, gx, gy, s["slop"] * unit,
                               4.0 * s["slop"] * unit, s["hertz"], s["damping"], s["push_speed"] * unit,
                               s["restitution_threshold"] * unit, float(open_layers), float("response" in effects),
                               float("rotation" in effects), float("friction" in effects), s["fat_margin"] * unit,
                               s["joint_hertz"] * runs, s["joint_damping"])
            self._settings_key = key
        return self._params

    def _joints(self) -> tuple[np.ndarray | None, ...]:
        """The kernel's joint arguments ``(jint, jf, jimp, apart)``: the joint components packed
        (checked again: game code may have written to them), last step's impulses matched by joint.
        A sleeping body is woken where its joint's other body moves, or the joint is new or changed
        (a motor's speed, a mouse's target)."""
        joints = joint_components()
        old_keys, old_imp, old_jf = self.joints
        if not joints:
            if old_keys.size:
                self.joints = (_NO_KEYS, _NO_IMP, _NO_JF)
            return None, None, None, _NO_KEYS  # (the kernel's variant without joints)
        store = self.bodies.store
        key = (store.version, joint_writes(), joints)
        if not (key[:2] == self._joint_key[:2] and joints is self._joint_key[2]):
            for _e, j in joints:
                if j._frame is None:  # (added to the world by hand, not by the scene: measured now)
                    j.attach(store)
            check_joints(joints, store, "soft")
            key = (store.version, joint_writes(), joints)  # (attaching writes the anchors it measures)
            # (packed again only when a joint, its bodies or the rows changed: joint_components
            # answers with the same list while no component was added or removed)
            self._joint_tables = joint_tables(joints, store.row_of)
            self._joint_key = key
        jint, jf, keys, apart = self._joint_tables
        if keys is old_keys and jf is old_jf:  # (the same tables as last step: nothing changed)
            imp = old_imp
            changed = np.zeros(keys.size, dtype=bool)
        elif np.array_equal(keys, old_keys):
            imp = old_imp
            changed = np.any(jf != old_jf, axis=1)
        else:
            imp = np.zeros((keys.size, len(JOINT_IMP)))
            where = {int(k): i for i, k in enumerate(old_keys)}
            changed = np.ones(keys.size, dtype=bool)
            for i, k in enumerate(keys.tolist()):
                o = where.get(k)
                if o is not None:
                    imp[i] = old_imp[o]
                    changed[i] = bool(np.any(jf[i] != old_jf[o]))
        self._wake_joined(jint, changed)
        self.joints = (keys, imp, jf)
        return jint, jf, imp, apart

    def _wake_joined(self, jint: np.ndarray, changed: np.ndarray) -> None:
        """Wake the sleeping bodies of joints that are new or changed, or whose other body is an
        awake dynamic body or moves (a kinematic one with a velocity). (Joined dynamic bodies fall
        asleep together: the sleeping stage reads the joints' rows, ``frame.joined``.)"""
        store = self.bodies.store
        n = store.n
        asleep = store.cols["asleep"][:n]
        if not asleep.any():
            return
        c = store.cols
        going = (c["vx"][:n] != 0.0) | (c["vy"][:n] != 0.0) | (c["w"][:n] != 0.0)
        awake = ~asleep & store.has_vel[:n] & ((store.body[:n] == DYNAMIC) | ((store.body[:n] != STATIC) & going))
        moves = np.append(awake, False)  # (row -1: the world)
        ra, rb = jint[:, 1], jint[:, 2]
        wake = np.concatenate([ra[changed | moves[rb]], rb[changed | moves[ra]]])
        wake = wake[wake >= 0]
        if wake.size:
            store.wake(wake[asleep[wake]])

    def run(self, frame: StepFrame) -> bool:
        store = self.bodies.store
        effects = self.pipeline.effects
        if "sleeping" in effects:  # (where the step began: what the sleeping stage measures rest by)
            c, n = store.cols, store.n
            frame.start_x, frame.start_y = c["x"][:n].copy(), c["y"][:n].copy()
        key = (store.version, store.n, "detection" in effects)
        rebuild = key != self._pairs_key
        tables = self._tables()
        if rebuild:
            self.fat = np.zeros((tables[-2].shape[0], 4))  # (a row per shape: a compound body's parts too)
            self._pairs_key = key
        joints = self._joints()
        args = (self._settings(frame), *tables, self._driven(frame), self.fat, self.pairs, self.slots, rebuild,
                *joints, self._rare)
        jint = joints[0]
        variant = (jint is not None, self._rare is not None)
        out = soft_step(*args) if variant in _COMPILED else _first_call(args, variant)
        self.fat, self.pairs, self.slots, touch_i, touch_f, end_i, end_f, info, jimp = out
        if jint is not None:
            self.joints = (self.joints[0], jimp, self.joints[2])
            ja, jb = jint[:, 1], jint[:, 2]
            both = (ja >= 0) & (jb >= 0)
            frame.joined = (ja[both], jb[both])
        if "movement" in effects:
            store.motion += 1
        ra, rb, ea, eb, started, pa, pb = touch_i
        contacts = StepContacts(ea, eb, *touch_f)
        ended = StepContacts(end_i[0], end_i[1], *end_f)
        frame.parts = frame.ended_parts = None
        if store.parts or (end_i.size and int(end_i.max()) >= PART_BASE):  # compound bodies: name the parts
            (ra, rb, pa, pb, started), contacts = _by_entity((ra, rb, pa, pb, started), contacts)
            (ea_, pea), (eb_, peb) = part_ids(end_i[0]), part_ids(end_i[1])
            (pea, peb), ended = _by_entity((pea, peb), StepContacts(ea_, eb_, *end_f))
            frame.parts, frame.ended_parts = (pa, pb), (pea, peb)
        frame.contacts, frame.ended = contacts, ended
        frame.contact_rows, frame.started = (ra, rb), started.astype(bool)
        frame._events = None
        if info.size > 3:
            store.wake(info[3:])
        counters = frame.counters
        counters["integrated"] = int(store.active()[0].size)
        counters["candidate_pairs"] = int(self.pairs.shape[0])
        counters["rehashed"] = int(info[0])
        counters["contacts"] = int(ea.size)
        counters["events"] = int(ea.size + end_i.shape[1])
        counters["resolved"] = int(info[1])
        counters["asleep"] = frame.n_asleep = int(info[2])
        return True
