"""The response stage: which contacts the response applies, and what it keeps for the next step.

It gathers this step's contacts and last step's resting pairs (bodies resting on each other fall
by the same amount and merely touch; they overlap again once the body below is pushed up), keeps
the solid ones (not sensors, at least one movable body, one-way platforms only when landed on),
re-aims pushes away from the internal faces of tiles, and hands them to the solver
(:func:`framework.systems.push_out.resolve`). Bodies pushed by other dynamic bodies into static
geometry they did not touch when the step's contacts were found are then resolved against it too
(late contacts), so no body ends the step inside a static it can fall through.
"""

from __future__ import annotations

import math

import numpy as np

from ..arrays import distinct
from ..collision import batch
from ..events import pair_keys, sorted_member
from ..frame import NO_RESOLVED, NO_SUPPORT, StepFrame
from ..store import STATIC
from .internal_faces import InternalFaces
from .narrow_phase import filter_layers, pair_contacts
from .push_out import resolve
from .stage import Stage

__all__ = ["Response"]


class _Contacts:
    """The contacts handed to the solver: rows, entities, normal (a to b), depth, and whether each
    overlaps now (``alive0``; the others are last step's resting pairs)."""

    def __init__(self, ra, rb, ea, eb, nx, ny, depth, alive0) -> None:
        self.ra, self.rb, self.ea, self.eb = ra, rb, ea, eb
        self.nx, self.ny, self.depth, self.alive0 = nx, ny, depth, alive0


class Response(Stage):
    """Resolve the step's solid contacts; fill ``frame.resolved`` and ``frame.support``."""

    name = "response"
    needs = frozenset({"response"})

    def __init__(self, pipeline) -> None:
        super().__init__(pipeline)
        self.internal_faces = InternalFaces()
        self._faces = False  # whether this step's pushes look at internal faces

    def run(self, frame: StepFrame) -> bool:
        store = self.bodies.store
        cs = self._gather(frame)
        frame.support = NO_SUPPORT
        frame.resolved = NO_RESOLVED
        if cs.ra.size and cs.ra.max() >= store.n:  # rows spawned mid-step are not in this step
            return False
        idx = np.flatnonzero(self._solid(frame, cs))
        if idx.size == 0:
            return True
        every = idx.size == cs.ra.size  # (then the columns are used as they are, not gathered)
        pa, pb = (cs.ra, cs.rb) if every else (cs.ra[idx], cs.rb[idx])
        nx, ny, depth, alive0 = (cs.nx, cs.ny, cs.depth, cs.alive0) if every else (
            cs.nx[idx], cs.ny[idx], cs.depth[idx], cs.alive0[idx])
        # Push-outs avoid the internal faces of tiles (only looked at when a static is touched).
        self._faces = self.bodies.n_static > 0 and bool(((store.body[pa] == STATIC) | (store.body[pb] == STATIC)).any())
        rank = None
        if self._faces:
            rank = depth.copy()
            self._redirect(pa, pb, nx, ny, depth, alive0, rank)
        gravity, iterations = self.pipeline.active_gravity(), self.pipeline.response_iterations
        done, anx, any_, pushed = resolve(store, pa, pb, nx, ny, depth, gravity, iterations, self._remeasure,
                                          alive0, frame.dt, rank)
        if done.all():
            ea, eb = (cs.ea, cs.eb) if every else (cs.ea[idx], cs.eb[idx])
            out = [ea, eb, nx, ny, anx, any_, pushed]
        else:
            out = [cs.ea[idx[done]], cs.eb[idx[done]], nx[done], ny[done], anx[done], any_[done], pushed[done]]
        if self.bodies.n_static:
            dd = idx[done]
            dd = dd[(store.inv_mass[cs.ra[dd]] > 0) & (store.inv_mass[cs.rb[dd]] > 0)]
            out = self._late_static_contacts(frame, distinct(np.concatenate([cs.ra[dd], cs.rb[dd]])), out)
        self._record(frame, *out)
        return True

    def _gather(self, frame: StepFrame) -> _Contacts:
        """This step's contacts, plus the pairs the response resolved last step that no longer
        overlap (both bodies still there, with hitboxes whose layers meet)."""
        store = self.bodies.store
        c = frame.contacts
        sa, sb, snx, sny = frame.support
        old = ~sorted_member(pair_keys(sa, sb), pair_keys(c.a, c.b))
        sra, srb = self.bodies.rows_of(sa[old]), self.bodies.rows_of(sb[old])
        live = (sra >= 0) & (srb >= 0)
        ok = np.flatnonzero(live)
        live[ok] = (store.kind[sra[ok]] >= 0) & (store.kind[srb[ok]] >= 0) & filter_layers(store, sra[ok], srb[ok])
        ra = np.concatenate([frame.contact_rows[0], sra[live]])
        rb = np.concatenate([frame.contact_rows[1], srb[live]])
        ea, eb = np.concatenate([c.a, sa[old][live]]), np.concatenate([c.b, sb[old][live]])
        nx, ny = np.concatenate([c.nx, snx[old][live]]), np.concatenate([c.ny, sny[old][live]])
        gaps = self._support_gaps(frame, sra[live], srb[live], snx[old][live], sny[old][live])
        depth = np.concatenate([c.depth, gaps])
        alive0 = np.arange(ra.size) < c.a.size
        return _Contacts(ra, rb, ea, eb, nx, ny, depth, alive0)

    def _solid(self, frame: StepFrame, cs: _Contacts) -> np.ndarray:
        """Mask of the contacts the response acts on."""
        store = self.bodies.store
        ra, rb = cs.ra, cs.rb
        inv, asleep = store.inv_mass, store.asleep  # sleeping bodies keep still
        movable_a, movable_b = (inv[ra] > 0) & ~asleep[ra], (inv[rb] > 0) & ~asleep[rb]
        solid = ~(store.sensor[ra] | store.sensor[rb]) & (movable_a | movable_b)
        solid &= (store.kind[ra] >= 0) & (store.kind[rb] >= 0)  # a system may have removed a hitbox
        one_way = store.one_way[ra] | store.one_way[rb]
        if one_way.any():
            solid &= ~one_way | self._lands_on_one_way(frame, cs)
        return solid

    def _redirect(self, ra, rb, nx, ny, depth, hit, rank) -> None:
        """Re-aim (in place) pushes that would leave a tile through a face another tile covers."""
        b = self.bodies
        self.internal_faces.redirect(b.store, b.geometry, b.hash, b.rows_of, ra, rb, nx, ny, depth, hit, rank)

    def _remeasure(self, a: np.ndarray, b: np.ndarray):
        """The solver's re-measure of the pairs ``(a, b)`` after it moved bodies: ``(hit, nx, ny,
        depth, rank)`` from the narrow phase's kernels, pushes re-aimed off internal faces."""
        store, geom = self.bodies.store, self.bodies.geometry
        if geom.version != store.version:
            geom.update(store)
        elif geom.has_offset:  # hitbox origins of just these rows
            geom.update_rows(store, np.concatenate([a, b]))
        else:  # origins are the positions
            geom.hx, geom.hy = store.x, store.y
        r = pair_contacts(store, geom, a, b, remeasure=True)
        rank = r.depth.copy()
        if self._faces:
            self._redirect(a, b, r.nx, r.ny, r.depth, r.hit, rank)
        return r.hit, r.nx, r.ny, r.depth, rank

    def _late_static_contacts(self, frame: StepFrame, pushed_rows: np.ndarray, out: list) -> list:
        """Bodies pushed by other dynamic bodies may have been shoved into static geometry they did
        not touch when the step's contacts were found (a pile spawned on one spot): find those
        contacts now and resolve them, a few rounds. Pushes out of statics themselves need no such
        look (they move away from them). Returns ``out`` with the late contacts appended."""
        store = self.bodies.store
        gravity, iterations = self.pipeline.active_gravity(), self.pipeline.response_iterations
        for _ in range(max(1, iterations)):
            if pushed_rows.size == 0:
                break
            extra = self._new_static_contacts(pushed_rows, out[0], out[1])
            if extra is None:
                break
            xa, xb, xra, xrb, xr = extra
            xrank = xr.depth.copy()
            self._redirect(xra, xrb, xr.nx, xr.ny, xr.depth, xr.hit, xrank)
            xdone, xanx, xany, xpushed = resolve(store, xra, xrb, xr.nx, xr.ny, xr.depth, gravity, iterations,
                                                 self._remeasure, xr.hit, frame.dt, xrank)
            new = (xa, xb, xr.nx, xr.ny, xanx, xany, xpushed)
            out = [np.concatenate([o, v[xdone]]) for o, v in zip(out, new)]
            pushed_rows = distinct(np.where(store.inv_mass[xra] > 0, xra, xrb)[xdone])
            frame.counters["late_contacts"] += int(xdone.sum())
        return out

    def _record(self, frame: StepFrame, ea, eb, snx, sny, anx, any_, pushed) -> None:
        """``frame.resolved`` (sorted by pair) and the resting pairs kept for the next step (normal
        within 60 degrees of the vertical, which gravity presses together again; none without
        gravity)."""
        keys = pair_keys(ea, eb)
        if keys.size > 1 and not (keys[1:] > keys[:-1]).all():  # late contacts were appended
            order = np.argsort(keys, kind="stable")
            ea, eb, snx, sny, anx, any_, pushed = (v[order] for v in (ea, eb, snx, sny, anx, any_, pushed))
        frame.resolved = (ea, eb, anx, any_, pushed)
        gx, gy = self.pipeline.active_gravity()
        g = math.hypot(gx, gy)
        if g > 0.0:
            keep = np.flatnonzero(np.abs(snx * gx + sny * gy) > 0.5 * g)
            frame.support = (ea[keep], eb[keep], snx[keep], sny[keep])
        else:
            frame.support = NO_SUPPORT
        frame.counters["resolved"] = int(ea.size)

    def _support_gaps(self, frame: StepFrame, ra, rb, nx, ny) -> np.ndarray:
        """The depth (<= 0) of last step's resting pairs that no longer overlap: how far apart the
        step's movement took them along their normal. They touched when it began; a pair that
        fell together stays at 0 (and is resolved again if a push below makes them overlap),
        one flying apart starts this far from touching, so a small push below does not count
        as an overlap (a box bouncing off a base kept being pushed by it, a little every step)."""
        sx, sy, store = frame.start_x, frame.start_y, self.bodies.store
        if ra.size == 0 or sx.size <= max(int(ra.max()), int(rb.max())):
            return np.zeros(ra.size)
        gap = (((store.x[rb] - sx[rb]) - (store.x[ra] - sx[ra])) * nx
               + ((store.y[rb] - sy[rb]) - (store.y[ra] - sy[ra])) * ny)
        return np.minimum(-gap, 0.0)

    def _new_static_contacts(self, rows: np.ndarray, known_a: np.ndarray, known_b: np.ndarray):
        """Overlaps of ``rows`` (dynamic, just moved) with static bodies, other than the pairs
        ``(known_a, known_b)`` (entities, either order): ``(ents_a, ents_b, rows_a, rows_b, contacts)``
        or None."""
        bodies = self.bodies
        store, geom, hsh = bodies.store, bodies.geometry, bodies.hash
        # First a cheap look with bounds that hold the hitbox at any rotation (its bounding circle
        # about the body's position): most bodies have no static in their cells, and their exact
        # bounds are not needed; nor are any when all of them lie outside the statics' extent.
        reach = store.bound[rows] + np.hypot(store.ox[rows], store.oy[rows]) if geom.has_offset else store.bound[rows]
        x, y = store.x[rows], store.y[rows]
        box = (np.nextafter(x - reach, -np.inf), np.nextafter(y - reach, -np.inf),
               np.nextafter(x + reach, np.inf), np.nextafter(y + reach, np.inf))
        if hsh.outside_statics(*(f(v) for f, v in zip((np.min, np.min, np.max, np.max), box))):
            return None
        near = hsh.near_statics(*box) & (store.kind[rows] >= 0) & ~store.asleep[rows] & ~store.sensor[rows]
        rows = rows[near]
        if rows.size == 0:
            return None
        geom.update_rows(store, rows)
        ea, eb = hsh.static_pairs(geom.minx[rows], geom.miny[rows], geom.maxx[rows], geom.maxy[rows],
                                  store.entity[rows])
        if ea.size == 0:
            return None
        ra, rb = bodies.rows_of(ea), bodies.rows_of(eb)
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

    def _lands_on_one_way(self, frame: StepFrame, cs: _Contacts) -> np.ndarray:
        """Mask of contacts a one-way platform takes: the other body comes from above (the
        normal within 45 degrees of the platform's up) and sank in only by this step's motion."""
        store = self.bodies.store
        ra, rb, nx, ny = cs.ra, cs.rb, cs.nx, cs.ny
        plat_is_a = store.one_way[ra]
        plat = np.where(plat_is_a, ra, rb)
        other = np.where(plat_is_a, rb, ra)
        rot = store.rot[plat]
        ux, uy = -np.sin(rot), np.cos(rot)
        toward_other = np.where(plat_is_a, 1.0, -1.0)
        from_above = (nx * ux + ny * uy) * toward_other > 0.7071
        # Where each body started the step (rows spawned during the step: where they are).
        x0, y0 = store.x.copy(), store.y.copy()
        n0 = frame.start_x.size
        x0[:n0], y0[:n0] = frame.start_x, frame.start_y
        dx = (store.x[other] - x0[other]) - (store.x[plat] - x0[plat])
        dy = (store.y[other] - y0[other]) - (store.y[plat] - y0[plat])
        sank = -(dx * ux + dy * uy)
        tol = 1e-9 * (1.0 + store.bound[other])
        came_down = cs.depth <= np.maximum(sank, 0.0) + tol
        return from_above & (came_down | ~cs.alive0)
