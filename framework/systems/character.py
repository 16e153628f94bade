"""The character stage: moves every body with a :class:`~framework.character.CharacterController`
(the rules: :mod:`framework.character`), right after the movement stage, by swept shape casts
(:mod:`framework.casting`) against what blocks it. A Python loop over the characters (a game has a
few); each cast is a handful of exact time-of-impact tests against the nearby hitboxes.

The Python move here is the reference. A box among boxes (the body and every hitbox near it
axis-aligned boxes: a tile level's player and walkers) moves instead by one compiled call,
:mod:`.character_kernel`, with the same bits; it hands back to the Python move whatever it does
not decide itself (see there). :data:`FAST` = False turns it off. Where the scene's rows are few
enough for a pass and the body drops through nothing, that call is the whole move (undoing the
movement stage's move, the skin, the ride, the candidates, the move, the placing:
:meth:`CharacterStage._move_whole`); otherwise the stage gathers the candidates and the call
makes the move from there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import esper
import numpy as np

from ..arrays import IntpArray
from ..casting import cast_rows, overlapping_rows, shape_bounds, touch_point
from ..character import CharacterController
from ..collision import collide
from ..collision.box_rows import rows_within
from ..collision.broad_phase import DIRECT_QUERY
from ..collision.kinds import KIND_AABB
from ..components import Velocity
from ..frame import StepFrame
from ..store import DYNAMIC, KINEMATIC, STATIC
from ..validation import InvalidValue
from .stage import Stage

if TYPE_CHECKING:
    from ..queries import SpatialQueries
    from ..shapes import Shape

__all__ = ["FAST", "CharacterStage"]

_NONE = np.zeros(0, dtype=np.int64)

#: Whether a box among boxes moves by the compiled move (:mod:`.character_kernel`; the same
#: bits); False: every body by the Python move (the reference, the tests compare the two).
FAST = True
_RIDE_SLIDES = 4  # (the casts of a ride: ``_slide``'s default, as ``_ride`` calls it)


@dataclass
class _Move:
    """One body's move under way: its hitbox origin, what blocks it and what it met."""

    shape: Shape
    x: float
    y: float
    rot: float
    row: int
    mask: int
    skin: float
    floor_cos: float
    dropping: set[int]
    ignore: set[int] = field(default_factory=set)
    box: tuple[float, float, float, float] | None = None  # where ``rows`` holds every candidate
    rows: IntpArray | None = None  # candidate rows in ``box``: mask, sensors, itself, dropped out
    floor: tuple[int, float, float] | None = None  # (row, nx, ny)
    wall: tuple[int, float, float] | None = None
    ceiling: bool = False
    hits: list[tuple[int, float, float]] = field(default_factory=list)  # surfaces the own motion met
    pushed: list[tuple[int, float, float]] = field(default_factory=list)
    stood_on: int | None = None  # the row it stood on when the step began
    own: IntpArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))  # [row]: never its own candidate


class CharacterStage(Stage):
    """The pipeline's character stage: moves every body with a :class:`CharacterController`."""

    name = "character"
    needs = frozenset({"character"})

    def __init__(self, pipeline: Any) -> None:
        super().__init__(pipeline)
        from ..queries import SpatialQueries

        self.queries: SpatialQueries = SpatialQueries(pipeline)
        # (values a snapshot can keep: it saves the stages' state; the compiled move's module is
        # the process's, _compiled_move)
        self._outputs: tuple[Any, ...] = ()  # the arrays the compiled move writes its outcome to
        self.fast_moves = 0  # moves made by the compiled move (the tests' evidence it ran)
        self.fallbacks: dict[str, int] = {}  # the moves it handed back, by reason

    # --- checks before the step ------------------------------------------------------------------

    def check(self) -> None:
        """Raise :class:`InvalidValue` naming the first entity whose controller cannot run: it
        needs a Velocity and a kinematic hitbox. Called before a step changes anything."""
        store = self.bodies.store
        for e, _ctrl in sorted(esper.get_component(CharacterController), key=lambda p: p[0]):
            row = store.row_of.get(e)
            hb = store.hitboxes[row] if row is not None else None
            if hb is None:
                raise InvalidValue(f"entity {e}: a CharacterController needs a Transform and a Hitbox")
            if not store.cols["has_vel"][row]:
                raise InvalidValue(f"entity {e}: a CharacterController needs a Velocity (the velocity it wants)")
            if store.cols["body"][row] != KINEMATIC:
                raise InvalidValue(f"entity {e}: a CharacterController moves a kinematic body; "
                                   f"give its Hitbox body='kinematic' (it has {hb.body.value!r})")

    # --- the stage ----------------------------------------------------------------------------

    def run(self, frame: StepFrame) -> bool:
        found = sorted(esper.get_component(CharacterController), key=lambda p: p[0])
        if not found:
            return False
        store = self.bodies.store
        moved = "movement" in frame.counters["systems"]
        for e, ctrl in found:
            row = store.row_of.get(e)
            if row is None or store.hitboxes[row] is None:
                continue
            undo = moved and row < frame.start_x.size
            if FAST and self._fast(row, ctrl):
                if self._move_whole(frame, e, row, ctrl, moved, undo):
                    continue
            elif undo:
                self.bodies.place_row(row, frame.start_x[row], frame.start_y[row])  # undo movement: ours to move
            self._move(frame, e, row, ctrl, moved)
        frame.counters["characters"] = len(found)
        return True

    def _fast(self, row: int, ctrl: CharacterController) -> bool:
        """Whether the whole move of ``row`` may be one compiled call (:meth:`_move_whole`): a box
        without offset, in a scene of rows few enough for a pass, neither dropping through one-way
        platforms nor asked to; the geometry made current (as the move would)."""
        store = self.bodies.store
        if store.cols["kind"][row] != KIND_AABB or store.n > DIRECT_QUERY or ctrl.drop_through or ctrl.dropping:
            return False
        return _solid_mask(ctrl, store, row) >= 0 and not self.queries._synced_geometry().has_offset

    def _move_whole(self, frame: StepFrame, entity: int, row: int, ctrl: CharacterController, moved: bool,
                    undo: bool) -> bool:
        """:meth:`_move` (and the undo of the movement stage's move before it) as one compiled
        call, :func:`~.character_kernel.move_character`, for the bodies :meth:`_fast` admits: the
        same bits. False where it hands the move back (then only the undo was done)."""
        kernel = _compiled_move()
        if not self._outputs:
            self._outputs = kernel.outputs()
        store, geom = self.bodies.store, self.bodies.geometry
        c = store.cols
        gx, gy = self.pipeline.active_gravity()
        snap = ctrl.snap_length if ctrl.snap_length is not None else ctrl.step_height
        fnx, fny = ctrl.floor_normal
        cfg = np.array([math.nan if ctrl.skin is None else ctrl.skin, ctrl.floor_cos, ctrl.gravity_scale,
                        ctrl.step_height, snap, math.tan(math.radians(ctrl.max_floor_angle)), fnx, fny, frame.dt,
                        gx, gy])
        mask = _solid_mask(ctrl, store, row)
        floor_row = self._row_of(ctrl.floor_entity)
        ctrl.crushed = False
        st, si, push_r, push_n = self._outputs
        reason = kernel.move_character(
            row, undo, moved, self.pipeline.solver == "soft", cfg, mask, -1 if floor_row is None else floor_row,
            ctrl.on_floor, ctrl.max_slides, _RIDE_SLIDES, frame.start_x, frame.start_y, geom.hx, geom.hy, c["vx"],
            c["vy"], c["w"], c["has_vel"], c["body"], c["asleep"], store.kind, geom.minx, geom.miny, geom.maxx,
            geom.maxy, c["hw"], c["hh"], c["one_way"], c["entity"], c["bound"], c["layer"], c["sensor"], st, si,
            push_r, push_n)
        if undo or not reason:
            self.bodies.placed_boxes()
        if reason:
            why = kernel.REASONS[reason]
            self.fallbacks[why] = self.fallbacks.get(why, 0) + 1
            return False
        self._moved(entity, ctrl, frame.dt)
        return True

    def _move(self, frame: StepFrame, entity: int, row: int, ctrl: CharacterController, moved: bool) -> None:
        store = self.bodies.store
        geom = self.bodies.ensure_geometry()
        hb = store.hitboxes[row]
        assert hb is not None  # (run() moves only rows with a hitbox)
        shape = hb.shape
        dt = frame.dt
        ox, oy = float(geom.hx[row] - store.cols["x"][row]), float(geom.hy[row] - store.cols["y"][row])
        x0, y0 = float(geom.hx[row]), float(geom.hy[row])
        size = min(_extent(shape))
        skin = ctrl.skin if ctrl.skin is not None else default_skin(size, x0, y0)
        mask = _solid_mask(ctrl, store, row)
        mv = _Move(shape, x0, y0, float(store.cols["rot"][row]), row, mask, skin, ctrl.floor_cos, ctrl.dropping)
        mv.own = np.array([row], dtype=np.int64)
        vel: Velocity = esper.component_for_entity(entity, Velocity)
        vx, vy = float(store.cols["vx"][row]), float(store.cols["vy"][row])
        was_on_floor, floor_row = ctrl.on_floor, self._row_of(ctrl.floor_entity)
        start_bottom = shape_bottom(shape, x0, y0, mv.rot)
        ctrl.crushed = False

        if ctrl.drop_through:
            ctrl.drop_through = False
            under = self._one_way_under(mv, size)
            if under:
                ctrl.dropping.update(under)
                if floor_row is not None and int(store.cols["entity"][floor_row]) in under:
                    was_on_floor, floor_row = False, None
        self._forget_dropped(mv, ctrl)
        mv.stood_on = floor_row if was_on_floor else None

        # 1. Ride: the displacement of the point under its feet on what it stood on, this step (the
        # floor's own displacement, and where the floor turns, that point turned about its origin).
        carried = (0.0, 0.0)
        going = (was_on_floor and floor_row is not None and bool(store.cols["has_vel"][floor_row])
                 and store.cols["body"][floor_row] != STATIC and not store.cols["asleep"][floor_row])
        pivot = None
        ride_after = False
        if was_on_floor and floor_row is not None and moved and floor_row < frame.start_x.size:
            carried = (float(store.cols["x"][floor_row] - frame.start_x[floor_row]),
                       float(store.cols["y"][floor_row] - frame.start_y[floor_row]))
            pivot = (float(frame.start_x[floor_row]), float(frame.start_y[floor_row]))
        elif going and self.pipeline.solver == "soft":
            # (the soft step moves what it stands on after this stage, by its velocity: the body
            # moves on it where it is now, then rides to where it will be)
            carried = (float(store.cols["vx"][floor_row]) * dt, float(store.cols["vy"][floor_row]) * dt)
            pivot = (float(store.cols["x"][floor_row]), float(store.cols["y"][floor_row]))
            ride_after = True
        turn = float(store.cols["w"][floor_row]) * dt if going and pivot is not None else 0.0
        if turn != 0.0 and pivot is not None:  # (moved by the movement stage, or by the soft step next)
            dx, dy = x0 - pivot[0], start_bottom - pivot[1]
            c, s = math.cos(turn), math.sin(turn)
            carried = (carried[0] + (c * dx - s * dy - dx), carried[1] + (s * dx + c * dy - dy))
        self._gather(mv, ctrl, carried, vx, vy, dt, size)
        if FAST and store.cols["kind"][row] == KIND_AABB and self._move_box(
                mv, ctrl, entity, carried, vx, vy, dt, floor_row, was_on_floor, ride_after, ox, oy):
            return
        if carried != (0.0, 0.0) and floor_row is not None and not ride_after:
            self._ride(mv, floor_row, carried)
        # 2. Whatever moved into it (a platform rising under it, one pushing it): out.
        if not self._depenetrate(mv, start_bottom, frame, moved):
            ctrl.crushed = True

        # 3. Its own motion.
        cos_f = mv.floor_cos
        jumping = vy > 0.0
        if was_on_floor and jumping and floor_row is not None and dt > 0.0:
            vx += carried[0] / dt  # leaving a moving platform: keep its velocity
            vy += carried[1] / dt
        if was_on_floor and not jumping:
            vy = 0.0
            nx, ny = ctrl.floor_normal
            if ny < cos_f:  # (the floor it stood on was re-measured this step)
                nx, ny = 0.0, 1.0
            mx, my = vx * dt, vx * dt * (nx / ny) * -1.0  # along the floor, x advancing vx * dt
        else:
            gx, gy = self.pipeline.active_gravity()
            vx += gx * ctrl.gravity_scale * dt
            vy += gy * ctrl.gravity_scale * dt
            mx, my = vx * dt, vy * dt
        on_floor_now = was_on_floor and not jumping
        px = mv.x
        self._slide(mv, mx, my, on_floor=on_floor_now, step=ctrl.step_height, max_slides=ctrl.max_slides)
        # 4. Snap down onto the floor (down slopes, over crests, down small steps); also after a
        # floor was met on the way, since the walk may have gone on along it past a crest. What
        # the body ends on is measured where it ends: a floor met on the way (or one it was lifted
        # onto) and left again is not kept.
        if on_floor_now or (mv.floor is not None and not jumping):
            snap = ctrl.snap_length if ctrl.snap_length is not None else ctrl.step_height
            reach = snap + abs(mv.x - px) * math.tan(math.radians(ctrl.max_floor_angle)) + 2.0 * skin
            mv.floor = self._land(mv, reach)
        elif mv.floor is not None:  # jumping: only a floor it still touches (no pull down)
            mv.floor = self._land(mv, 4.0 * skin)
        if ride_after and carried != (0.0, 0.0) and floor_row is not None:
            # (what it met and stands on is kept: the floor takes it along, as the others would)
            kept = (mv.floor, mv.wall, mv.ceiling, list(mv.hits))
            self._ride(mv, floor_row, carried)
            mv.floor, mv.wall, mv.ceiling, mv.hits = kept
        # 5. State and velocity.
        ctrl.on_floor = mv.floor is not None
        if mv.floor is not None:
            r, nx, ny = mv.floor
            ctrl.floor_normal, ctrl.floor_entity = (nx, ny), int(store.cols["entity"][r])
            vy = 0.0  # (a jump that ends on a floor is cut; velocity on a floor is along it)
        else:
            ctrl.floor_normal, ctrl.floor_entity = (0.0, 0.0), None
        ctrl.on_wall = mv.wall is not None
        ctrl.wall_normal = (mv.wall[1], mv.wall[2]) if mv.wall is not None else (0.0, 0.0)
        if mv.ceiling and vy > 0.0:
            vy = 0.0
        vx, vy = self._unblocked(mv, vx, vy)
        ctrl.on_ceiling = mv.ceiling
        if ctrl.push_mass > 0.0 and dt > 0.0:
            self._push(mv.pushed, ctrl.push_mass, mx / dt, my / dt)
        self.bodies.place_row(row, mv.x - ox, mv.y - oy)
        if vel.x != vx:
            vel.x = vx
        if vel.y != vy:
            vel.y = vy

    def _move_box(self, mv: _Move, ctrl: CharacterController, entity: int, carried: tuple[float, float],
                  vx: float, vy: float, dt: float, floor_row: int | None, was_on_floor: bool, ride_after: bool,
                  ox: float, oy: float) -> bool:
        """The rest of ``_move`` (its candidates gathered) by the compiled move, for a box among
        boxes: False, nothing changed, where it hands the move back to the Python code."""
        kernel = _compiled_move()
        if not self._outputs:
            self._outputs = kernel.outputs()
        store, geom = self.bodies.store, self.bodies.geometry
        c, row = store.cols, mv.row
        assert mv.rows is not None and mv.box is not None  # (gathered)
        gx, gy = self.pipeline.active_gravity()
        snap = ctrl.snap_length if ctrl.snap_length is not None else ctrl.step_height
        me = np.array([c["hw"][row], c["hh"][row], mv.skin, mv.floor_cos, c["bound"][row], *mv.box])
        go = np.array([mv.x, mv.y, carried[0], carried[1], vx, vy, dt, gx, gy, ctrl.gravity_scale, ctrl.step_height,
                       snap, math.tan(math.radians(ctrl.max_floor_angle)), *ctrl.floor_normal])
        world = (mv.rows, geom.minx, geom.miny, geom.maxx, geom.maxy, geom.hx, geom.hy, c["hw"], c["hh"],
                 c["one_way"], c["body"], c["entity"], c["bound"], c["kind"])
        st, si, push_r, push_n = self._outputs
        reason = kernel.move_box(world, me, go, -1 if floor_row is None else floor_row, was_on_floor,
                                       ride_after, ctrl.max_slides, _RIDE_SLIDES, st, si, push_r, push_n)
        if reason:
            why = kernel.REASONS[reason]
            self.fallbacks[why] = self.fallbacks.get(why, 0) + 1
            return False
        self.bodies.place_row(row, float(st[0]) - ox, float(st[1]) - oy)
        self._moved(entity, ctrl, dt)
        return True

    def _moved(self, entity: int, ctrl: CharacterController, dt: float) -> None:
        """After a compiled move: the controller's state, the pushes and the velocity from its
        outcome (the stage's outputs)."""
        st, si, push_r, push_n = self._outputs
        store = self.bodies.store
        self.fast_moves += 1
        _x, _y, fnx, fny, wnx, wny, vx, vy, mx, my = st.tolist()
        floor, wall = int(si[0]), int(si[1])
        # (the state, not settings: written past the settings' check)
        ctrl.__dict__.update(on_floor=floor >= 0, floor_normal=(fnx, fny) if floor >= 0 else (0.0, 0.0),
                             floor_entity=int(store.cols["entity"][floor]) if floor >= 0 else None,
                             on_wall=wall >= 0, wall_normal=(wnx, wny) if wall >= 0 else (0.0, 0.0),
                             on_ceiling=bool(si[2]))
        pushed = int(si[4])
        if ctrl.push_mass > 0.0 and dt > 0.0 and pushed:
            self._push([(r, nx, ny) for r, (nx, ny) in zip(push_r[:pushed].tolist(), push_n[:pushed].tolist())],
                       ctrl.push_mass, mx / dt, my / dt)
        row = store.row_of[entity]
        if store.cols["vx"][row] != vx or store.cols["vy"][row] != vy:  # (the Velocity's values, read faster)
            vel: Velocity = esper.component_for_entity(entity, Velocity)
            if vel.x != vx:
                vel.x = vx
            if vel.y != vy:
                vel.y = vy

    # --- moving ----------------------------------------------------------------------------

    def _ride(self, mv: _Move, floor_row: int, carried: tuple[float, float]) -> None:
        """Move by what the floor carries it (the floor itself not in the way); what that move
        meets is not the body's own contact."""
        mv.ignore.add(floor_row)
        self._slide(mv, carried[0], carried[1], on_floor=False, step=0.0)
        mv.ignore.discard(floor_row)
        mv.floor = mv.wall = None
        mv.ceiling = False
        mv.hits.clear()

    def _row_of(self, entity: int | None) -> int | None:
        if entity is None:
            return None
        return self.bodies.store.row_of.get(entity)

    def _forget_dropped(self, mv: _Move, ctrl: CharacterController) -> None:
        """Stop ignoring one-way platforms the body has fallen clear of (or that are gone)."""
        if not ctrl.dropping:
            return
        store, geom = self.bodies.store, self.bodies.ensure_geometry()
        x0, y0, x1, y1 = _bounds(mv)
        keep = set()
        for e in ctrl.dropping:
            r = store.row_of.get(e)
            if r is None:
                continue
            if geom.maxx[r] > x0 and geom.minx[r] < x1 and geom.maxy[r] > y0 - mv.skin and geom.miny[r] < y1:
                keep.add(e)
        ctrl.dropping = keep
        mv.dropping = keep

    def _one_way_under(self, mv: _Move, size: float) -> set[int]:
        """The one-way platforms right under the body's feet (all of them: it may stand on the
        seam of two)."""
        store, geom = self.bodies.store, self.bodies.ensure_geometry()
        x0, y0, x1, _y1 = _bounds(mv)
        eps = max(4.0 * mv.skin, 1e-6 * size)
        rows = self.queries._candidate_rows(x0, y0 - eps, x1, y0 + eps)
        rows = rows[store.cols["one_way"][rows] & ((store.cols["layer"][rows] & mv.mask) != 0) & (rows != mv.row)]
        rows = rows[np.abs(geom.maxy[rows] - y0) <= eps]
        return {int(e) for e in store.cols["entity"][rows]}

    def _gather(self, mv: _Move, ctrl: CharacterController, carried: tuple[float, float], vx: float, vy: float,
                dt: float, size: float) -> None:
        """The candidates of every cast this step, from one look-up: the hitboxes near enough to be
        met by the farthest this body can go (a cast reaching further looks up again)."""
        gx, gy = self.pipeline.active_gravity()
        own = (abs(vx) + abs(vy) + (abs(gx) + abs(gy)) * abs(ctrl.gravity_scale) * dt) * dt
        carry = abs(carried[0]) + abs(carried[1])
        snap = ctrl.snap_length if ctrl.snap_length is not None else ctrl.step_height
        reach = (2.0 * carry + own * (1.0 + math.tan(math.radians(ctrl.max_floor_angle))) + 2.0 * ctrl.step_height
                 + snap + 0.5 * size + 8.0 * mv.skin)
        x0, y0, x1, y1 = _bounds(mv)
        mv.box = (x0 - reach, y0 - reach, x1 + reach, y1 + reach)
        mv.rows = None
        mv.rows = self._near(mv, mv.box)

    def _near(self, mv: _Move, box: tuple[float, float, float, float]) -> IntpArray:
        """The rows that may block the body whose bounds meet ``box`` (minus those ignored for
        now): from the gathered candidates if ``box`` lies in the gathered region, else looked up
        afresh (layers, sensors, the dropped platforms). One compiled pass (:mod:`~framework.collision.box_rows`)."""
        store, geom = self.bodies.store, self.bodies.ensure_geometry()
        b = mv.box
        skip_rows = np.array(sorted(mv.ignore | {mv.row}), dtype=np.int64) if mv.ignore else mv.own
        if not (mv.rows is not None and b is not None and (b[0] <= box[0] and b[1] <= box[1] and box[2] <= b[2]
                                                           and box[3] <= b[3])):
            return self.queries._blocking_rows(box, mv.mask, skip_rows, self._dropped(mv))
        c = store.cols  # (from the gathered candidates, already filtered by layers, sensors and drops)
        return rows_within(mv.rows, geom.minx, geom.miny, geom.maxx, geom.maxy, *box, c["layer"], c["sensor"], -1,
                           skip_rows, c["entity"], _NONE)

    @staticmethod
    def _dropped(mv: _Move) -> IntpArray:
        """The entities of the one-way platforms the body is dropping through, sorted."""
        return np.array(sorted(mv.dropping), dtype=np.int64) if mv.dropping else _NONE

    def _cast(self, mv: _Move, mx: float, my: float) -> tuple[int, float, float, float] | None:
        store = self.bodies.store

        def accept(r: int, f: float, nx: float, ny: float) -> bool:
            if not store.cols["one_way"][r]:
                return True
            # A one-way platform blocks only a body coming down onto its top.
            if ny < mv.floor_cos or (my > 0.0 and f == 0.0):
                return False
            if f == 0.0:  # touching, or already inside it (then it does not hold the body)
                geom = self.bodies.geometry
                return collide(mv.shape, (mv.x, mv.y, mv.rot), store.hitboxes[r].shape,  # type: ignore[union-attr]
                               (float(geom.hx[r]), float(geom.hy[r]), float(store.cols["rot"][r]))) is None
            return True

        x0, y0, x1, y1 = _bounds(mv)
        pad = 1e-6 * (abs(x0) + abs(y0) + abs(mx) + abs(my) + x1 - x0 + y1 - y0)
        box = (min(x0, x0 + mx) - pad, min(y0, y0 + my) - pad, max(x1, x1 + mx) + pad, max(y1, y1 + my) + pad)
        return cast_rows(self.queries, mv.shape, mv.x, mv.y, mv.rot, mx, my, accept, mask=mv.mask,
                         rows=self._near(mv, box), exact=False)

    def _advance(self, mv: _Move, mx: float, my: float, f: float, nx: float, ny: float) -> None:
        """Move by ``f`` of ``(mx, my)`` (up to a contact of normal ``n``), then back along the way
        it came until it is ``skin`` clear of that surface (never further back than it went)."""
        length = math.hypot(mx, my)
        if length == 0.0:
            return
        go = f * length
        into = -(mx * nx + my * ny) / length  # cosine of the way in with the surface's normal
        back = min(go, mv.skin / into) if into > 0.0 else 0.0
        t = (go - back) / length
        mv.x += mx * t
        mv.y += my * t

    def _slide(self, mv: _Move, mx: float, my: float, *, on_floor: bool, step: float, max_slides: int = 4) -> None:
        """Move by ``(mx, my)``, sliding along what it hits (see the module docstring)."""
        planes: list[tuple[float, float]] = []
        cos_f = mv.floor_cos
        scale = mv.skin * 1e-6
        for _ in range(max_slides):
            if abs(mx) <= scale and abs(my) <= scale:
                return
            hit = self._cast(mv, mx, my)
            if hit is None:
                mv.x += mx
                mv.y += my
                return
            r, f, nx, ny = hit
            self._advance(mv, mx, my, f, nx, ny)
            rx, ry = mx * (1.0 - f), my * (1.0 - f)
            if ny >= cos_f:  # a floor
                mv.floor = (r, nx, ny)
                mv.hits.append((r, nx, ny))
                on_floor = True
                # Keep walking: the horizontal part goes on along the floor; the fall stops.
                mx, my = rx, -rx * nx / ny
            elif ny <= -cos_f:  # a ceiling: slide along it
                mv.ceiling = True
                mv.hits.append((r, nx, ny))
                d = rx * nx + ry * ny
                mx, my = (rx - d * nx, ry - d * ny) if d < 0.0 else (rx, ry)
            else:  # a wall, or a slope too steep to walk
                if self.bodies.store.cols["body"][r] == DYNAMIC:
                    mv.pushed.append((r, nx, ny))  # it may give way: the walk keeps its velocity
                if on_floor and step > 0.0 and rx != 0.0 and abs(ny) < cos_f and self._step_up(mv, rx, step):
                    return  # (climbed: the step's face is behind it, not a wall it stands at)
                mv.wall = (r, nx, ny)
                mv.hits.append((r, nx, ny))
                d = rx * nx + ry * ny
                mx, my = (rx - d * nx, ry - d * ny) if d < 0.0 else (rx, ry)
                if on_floor and my > 0.0:
                    mx = my = 0.0  # no climbing a steep slope from the floor
            for px, py in planes:
                if mx * px + my * py < -scale:
                    mx = my = 0.0  # in a crease between two surfaces: stop
            planes.append((nx, ny))

    def _step_up(self, mv: _Move, rx: float, step: float) -> bool:
        """Try to step up onto a ledge at most ``step`` high in the way of ``rx``: up, across, down
        onto a floor. On success the body is on it (and True); otherwise it is untouched.

        Across is the rest of the frame's move, or further if that would leave the body's bottom
        on the ledge's edge at a slope too steep to stand on (a round bottom, moving slowly): then
        it goes as far as its bottom must for the edge to be under it at a standing angle (for a
        circle or capsule of radius r, at most r (1 - sin(0.9 max_floor_angle)) further), so a
        step that may be climbed is climbed at any speed."""
        x0, y0, cos_f = mv.x, mv.y, mv.floor_cos
        bottom = _bounds(mv)[1]
        up = self._cast(mv, 0.0, step)
        rise = step
        if up is not None:
            rise = max(0.0, step * up[1] - mv.skin)
        if rise <= mv.skin:
            return False
        top = y0 + rise
        go = rx
        further = nudged = False
        for _ in range(3):
            mv.x, mv.y = x0, top
            across = self._cast(mv, go, 0.0)
            if across is not None:
                self._advance(mv, go, 0.0, across[1], across[2], across[3])
            else:
                mv.x += go
            if abs(mv.x - x0) <= mv.skin:  # the rest of the move is too short to get onto it
                if not nudged and across is None:
                    go, nudged = go + math.copysign(4.0 * mv.skin, rx), True
                    continue
                break
            down = self._cast(mv, 0.0, -rise)
            if down is None:
                break
            r, fd, nx, ny = down
            if ny >= cos_f:
                self._advance(mv, 0.0, -rise, fd, nx, ny)
                if self._contact_height(mv, r, nx, ny) > bottom + step + 4.0 * mv.skin:
                    break  # resting on the edge of something higher than a step (a round bottom)
                mv.floor = (r, nx, ny)
                if across is not None:
                    mv.wall = (across[0], across[2], across[3])
                    mv.hits.append((across[0], across[2], across[3]))
                return True
            extra = self._to_stand(mv, nx, ny, rx) if not further and across is None else 0.0
            if not extra > 0.0:
                break
            go, further = go + math.copysign(extra, rx), True
        mv.x, mv.y = x0, y0
        return False

    def _contact_height(self, mv: _Move, r: int, nx: float, ny: float) -> float:
        """The height of where the body touches row ``r`` (met at normal ``n``, facing the body)."""
        store, geom = self.bodies.store, self.bodies.ensure_geometry()
        other = store.hitboxes[r]
        assert other is not None  # (a cast meets only rows with a hitbox)
        at = touch_point(mv.shape, (mv.x, mv.y, mv.rot), other.shape,
                         (float(geom.hx[r]), float(geom.hy[r]), float(store.cols["rot"][r])), -nx, -ny)
        return float(at.y)

    def _to_stand(self, mv: _Move, nx: float, ny: float, rx: float) -> float:
        """How much further across a round bottom (a circle's, a capsule's end) resting on an edge
        at normal ``n`` must go for the edge to hold it at a standing angle (0: not round, or not
        an edge ahead of it)."""
        radius = getattr(mv.shape, "radius", None)
        if radius is None or nx * rx >= 0.0:
            return 0.0
        if mv.shape.kind == "capsule" and mv.shape.length > 0.0:  # type: ignore[attr-defined]
            # The contact must be on an end's half disc: a normal square to the axis is its side.
            c, s = math.cos(mv.rot), math.sin(mv.rot)
            if abs(-s * nx + c * ny) <= 1e-9:
                return 0.0
        angle = 0.9 * math.acos(mv.floor_cos)  # well inside the floor's cone
        want = math.sin(angle)
        return radius * (abs(nx) - want) if abs(nx) > want else 0.0

    def _land(self, mv: _Move, reach: float) -> tuple[int, float, float] | None:
        """Cast down by ``reach``; if it meets a floor, move down onto it and return it (row and
        normal), else None (the body does not move). A steep surface met first does not hide a floor
        met at the same height (a body in the corner of a floor and a wall, a round bottom against
        a step's edge): the body stops at the steep one and stands on the floor."""
        cos_f = mv.floor_cos
        hit = self._cast(mv, 0.0, -reach)
        first = hit
        ignored: list[int] = []
        found = None
        for _ in range(3):
            if hit is None or first is None:
                break
            if hit[3] >= cos_f:
                if (hit[1] - first[1]) * reach <= 4.0 * mv.skin:
                    found = hit
                break
            ignored.append(hit[0])
            mv.ignore.add(hit[0])
            hit = self._cast(mv, 0.0, -reach)
        for r in ignored:
            mv.ignore.discard(r)
        if found is None or first is None:
            return None
        self._advance(mv, 0.0, -reach, first[1], first[2], first[3])
        return found[0], found[2], found[3]

    def _unblocked(self, mv: _Move, vx: float, vy: float) -> tuple[float, float]:
        """The velocity without its part into the surfaces the move met this step (dynamic bodies
        excepted: pushed, they may give way). On a floor the velocity is a walk along it: walking
        into a wall or ceiling met stops the walk (``vx`` = 0). In the air its part into each
        surface met is taken away (it slides along them); if that cannot be done for all of them
        at once (a crease), it stops."""
        store = self.bodies.store
        planes = [(nx, ny) for r, nx, ny in mv.hits if store.cols["body"][r] != DYNAMIC]
        if not planes:
            return vx, vy
        if mv.floor is not None:
            _r, fx, fy = mv.floor
            tx, ty = 1.0, -fx / fy  # the walk's direction for vx = 1
            if any(ny < mv.floor_cos and vx * (tx * nx + ty * ny) < 0.0 for nx, ny in planes):
                vx = 0.0
            return vx, vy
        tol = 1e-12 * math.hypot(vx, vy)  # (what rounding leaves of a part taken away)
        for _ in range(3):
            into = False
            for nx, ny in planes:
                d = vx * nx + vy * ny
                if d < -tol:
                    vx, vy = vx - d * nx, vy - d * ny
                    into = True
            if not into:
                return vx, vy
        if any(vx * nx + vy * ny < -tol for nx, ny in planes):
            return 0.0, 0.0  # in a crease: no way along all of them
        return vx, vy

    def _depenetrate(self, mv: _Move, start_bottom: float, frame: StepFrame, moved: bool) -> bool:
        """Push the body out of what it overlaps (something that moved into it this step); a
        one-way platform lifts it only if its feet were above the platform's top when the step
        began. False if it is pinned (pushed out of one thing into another)."""
        store = self.bodies.store
        free = True
        for _ in range(4):
            found = overlapping_rows(self.queries, mv.shape, mv.x, mv.y, mv.rot, mv.mask,
                                     rows=self._near(mv, _bounds(mv)), apart=0.5 * mv.skin)
            found = [o for o in found if self._holds(mv, o, start_bottom, frame, moved)]
            if not found:
                return free
            r, nx, ny, depth = max(found, key=lambda o: (o[3], -store.cols["entity"][o[0]]))
            push = depth + mv.skin
            mv.ignore.add(r)
            hit = self._cast(mv, nx * push, ny * push)
            mv.ignore.discard(r)
            if hit is None:
                mv.x += nx * push
                mv.y += ny * push
            else:
                self._advance(mv, nx * push, ny * push, hit[1], hit[2], hit[3])
                free = False
            if ny >= mv.floor_cos:
                mv.floor = (r, nx, ny)
        return free and not overlapping_rows(self.queries, mv.shape, mv.x, mv.y, mv.rot, mv.mask,
                                             rows=self._near(mv, _bounds(mv)), apart=0.5 * mv.skin)

    def _holds(self, mv: _Move, overlap: tuple[int, float, float, float], start_bottom: float,
               frame: StepFrame, moved: bool) -> bool:
        """Whether an overlapped body pushes this one out: anything solid; a one-way platform only
        from below its feet (its top, when the step began, was under them)."""
        r, _nx, ny, _depth = overlap
        store, geom = self.bodies.store, self.bodies.geometry
        if not store.cols["one_way"][r]:
            return True
        if ny < mv.floor_cos:
            return False
        if r == mv.stood_on:
            # (it stood on it when the step began, so it was above it: a turning board tilts up
            # under one lower corner, below the board's highest point, which the test below takes
            # for its top)
            return True
        top = float(geom.maxy[r])
        if moved and r < frame.start_y.size:
            top -= float(store.cols["y"][r] - frame.start_y[r])
        return start_bottom >= top - 1e-6 * (abs(top) + _extent(mv.shape)[1])

    def _push(self, pushed: list[tuple[int, float, float]], mass: float, vx: float, vy: float) -> None:
        """Dynamic bodies walked into get the impulse of a body of ``mass`` moving at ``(vx, vy)``
        meeting them (perfectly inelastic, along the contact normal)."""
        store = self.bodies.store
        for r, nx, ny in pushed:
            vn = -(vx * nx + vy * ny)  # the body's speed into the other one
            other = -(float(store.cols["vx"][r]) * nx + float(store.cols["vy"][r]) * ny)
            if vn <= other:
                continue
            inv = float(store.cols["inv_mass"][r])
            share = (mass * inv) / (1.0 + mass * inv) if math.isfinite(mass) else 1.0
            dv = (vn - other) * share
            store.cols["vx"][r] -= dv * nx
            store.cols["vy"][r] -= dv * ny
            if store.cols["asleep"][r]:
                store.wake(r)


_KERNEL: Any = None  # the compiled move's module, once imported (a module is no stage state)


def _compiled_move() -> Any:
    """The compiled move's module, imported (and so compiled, or loaded from numba's cache) when a
    scene first has a box character to move."""
    global _KERNEL
    if _KERNEL is None:
        from . import character_kernel

        _KERNEL = character_kernel
    return _KERNEL


def _solid_mask(ctrl: CharacterController, store: Any, row: int) -> int:
    """The layers that block the body of ``row``: its controller's ``solid_mask``, else its hitbox's
    mask."""
    if ctrl.solid_mask is not None:
        return ctrl.solid_mask
    hb = store.hitboxes[row]
    assert hb is not None  # (the stage moves only rows with a hitbox)
    return int(hb.mask)


def default_skin(size: float, x: float, y: float) -> float:
    """The gap kept by default: 2**-40 of the body's smaller size, and at least 256 units of
    rounding of its coordinates (so rounding never puts it inside what it touches): far below
    anything visible, as exact as "on the floor" can be in floating point."""
    return max(size * 2.0**-40, (abs(x) + abs(y)) * 2.0**-44)


def _extent(shape: Shape) -> tuple[float, float]:
    """Width and height of a shape's box at rotation 0 (a polygon's and a circle's bounds)."""
    x0, y0, x1, y1 = shape_bounds(shape, 0.0, 0.0, 0.0)
    return x1 - x0, y1 - y0


def _bounds(mv: _Move) -> tuple[float, float, float, float]:
    return shape_bounds(mv.shape, mv.x, mv.y, mv.rot)


def shape_bottom(shape: Shape, x: float, y: float, rot: float) -> float:
    """The lowest y of ``shape`` placed at ``(x, y, rot)``."""
    return shape_bounds(shape, x, y, rot)[1]
