"""Joints in the soft step: Box2D v3's distance, revolute, prismatic, wheel, weld, mouse and motor
joints, compiled.

The soft step (:mod:`framework.systems.soft_kernel`) calls these in its sub-steps, joints before
contacts as Box2D does: :func:`prepare_joints` once a step (anchors relative to each body's origin
at the step's start, effective masses, spring coefficients), then every sub-step
:func:`warm_start_joints` (last step's impulses) and :func:`solve_joints`, once with the bias that
pulls a joint back together (soft: Box2D's joint stiffness, 60 hertz at most a quarter of the
sub-step rate, damping ratio 2; ``Scene(substeps=n)`` makes it ``60 n`` hertz, so the joints of a
scene that pays for n times the sub-steps are n**2 times as stiff) and once without (the
relax). As for contacts, nothing is re-measured geometrically inside the solve: a joint's error
is its separation at the step's start plus the bodies' motion since (``x - x0``) and their
anchors turned by the bodies' turn since (``qc, qs``), Box2D's ``deltaPosition`` and
``deltaRotation``. A body's angle is its ``rot``.

The tables (packed by :class:`~framework.systems.soft_step.SoftStep` from the joint components,
:mod:`framework.joints`): ``jint`` rows ``(kind, row a, row b)`` (row -1: the world, where an
anchor is a world point), ``jf`` rows of :data:`JOINT_F`, ``imp`` rows of :data:`JOINT_IMP` (the
accumulated impulses, kept between steps for warm starting; the kernel works on a copy).

Numba's cache of :mod:`~framework.systems.soft_kernel` does not see edits of this module: after
editing it, delete the ``soft_kernel*`` cache files in ``__pycache__``.
"""

from __future__ import annotations

import math

import numpy as np

from ..compiled import kernel, leaf
from .softness import soft

__all__ = ["JOINT_F", "JOINT_IMP", "prepare_joints", "solve_joints", "warm_start_joints"]

DISTANCE, REVOLUTE, WELD, MOUSE, PRISMATIC, WHEEL, MOTOR = 0, 1, 2, 3, 4, 5, 6  # (as framework.joints)

#: A joint's parameters: its anchors in each body's frame (a world point for the world), the
#: bodies' relative angle at creation; a distance joint's length, least and most length (and
#: whether it has a most), spring frequency and damping ratio (also the weld's, the mouse's, and
#: the springs of the revolute, prismatic and wheel joints); a revolute joint's limits (and
#: whether each is on), motor speed and torque; the mouse's force; a slide's axis; a motor
#: joint's correction factor (its target is the anchors and ``ref``, its most force and torque
#: ``force`` and ``torque``).
JOINT_F = ("ax", "ay", "bx", "by", "ref", "length", "lo", "hi", "has_hi", "hertz", "damping", "lower", "upper",
           "has_lower", "has_upper", "speed", "torque", "force", "axis_x", "axis_y", "correction")
(_AX, _AY, _BX, _BY, _REF, _LEN, _LO, _HI, _HAS_HI, _HZ, _ZETA, _LOWER, _UPPER, _HAS_LOWER, _HAS_UPPER, _SPEED,
 _TORQUE, _FORCE, _AXIS_X, _AXIS_Y, _CORRECTION) = range(len(JOINT_F))
#: A joint's accumulated impulses: the linear impulse (x, y; a distance joint's along its axis in
#: the first; a prismatic joint's across its axis, then its angular one; a wheel's across its axis,
#: then its spring's), the lower and upper limits', the angular one (a motor's, a weld's, a
#: mouse's or a motor joint's; a prismatic motor's, along its axis) and the spring's of a revolute
#: joint (angular) or a prismatic one (along its axis).
JOINT_IMP = ("px", "py", "lower", "upper", "angular", "spring")
_PX, _PY, _ILO, _IUP, _IANG, _ISPR = range(len(JOINT_IMP))
# Columns of a prepared joint: on; anchors from each origin at the step's start; the origins'
# offset (b - a); inverse masses; the axial (or angular) effective mass; the joint's own softness
# (a spring's, else the joints' stiffness); the mouse's linear effective mass (a symmetric 2x2)
# and its angular softness.
(_ON, _RAX, _RAY, _RBX, _RBY, _DCX, _DCY, _MA, _IA, _MB, _IB, _AXM, _SB, _SM, _SI, _K11, _K12, _K22, _AB, _AM,
 _AI, _WAX, _WAY) = range(23)  # (_WAX, _WAY: a prismatic joint's axis at the step's start)
_NP = 23


@kernel
def prepare_joints(jint, jf, x, y, rot, moving, im, ii, h):
    """Each joint prepared for this step (rows of the columns above; ``_ON`` 0: skipped, no body
    of it moves or none takes impulses)."""
    m = jint.shape[0]
    jp = np.zeros((m, _NP))
    for j in range(m):
        kind, a, b = jint[j, 0], jint[j, 1], jint[j, 2]
        if not ((a >= 0 and moving[a]) or (b >= 0 and moving[b])):
            continue
        ma, ia, mb, ib = 0.0, 0.0, 0.0, 0.0
        rax, ray, cax, cay = jf[j, _AX], jf[j, _AY], 0.0, 0.0
        rbx, rby, cbx, cby = jf[j, _BX], jf[j, _BY], 0.0, 0.0
        if a >= 0:
            ma, ia, cax, cay = im[a], ii[a], x[a], y[a]
            c, s = math.cos(rot[a]), math.sin(rot[a])
            rax, ray = c * jf[j, _AX] - s * jf[j, _AY], s * jf[j, _AX] + c * jf[j, _AY]
        if b >= 0:
            mb, ib, cbx, cby = im[b], ii[b], x[b], y[b]
            c, s = math.cos(rot[b]), math.sin(rot[b])
            rbx, rby = c * jf[j, _BX] - s * jf[j, _BY], s * jf[j, _BX] + c * jf[j, _BY]
        if ma == 0.0 and ia == 0.0 and mb == 0.0 and ib == 0.0:
            continue
        jp[j, _ON] = 1.0
        jp[j, _RAX], jp[j, _RAY], jp[j, _RBX], jp[j, _RBY] = rax, ray, rbx, rby
        jp[j, _DCX], jp[j, _DCY] = cbx - cax, cby - cay
        jp[j, _MA], jp[j, _IA], jp[j, _MB], jp[j, _IB] = ma, ia, mb, ib
        jp[j, _SB], jp[j, _SM], jp[j, _SI] = soft(jf[j, _HZ], jf[j, _ZETA], h)
        if kind == DISTANCE:
            sx, sy = jp[j, _DCX] + rbx - rax, jp[j, _DCY] + rby - ray
            ux, uy = _unit(sx, sy)
            cra, crb = rax * uy - ray * ux, rbx * uy - rby * ux
            k = ma + mb + ia * cra * cra + ib * crb * crb
            jp[j, _AXM] = 1.0 / k if k > 0.0 else 0.0
        elif kind == PRISMATIC or kind == WHEEL:  # the axis turns with a (the world's: fixed); effective masses
            c, s = (math.cos(rot[a]), math.sin(rot[a])) if a >= 0 else (1.0, 0.0)
            wax, way = c * jf[j, _AXIS_X] - s * jf[j, _AXIS_Y], s * jf[j, _AXIS_X] + c * jf[j, _AXIS_Y]
            jp[j, _WAX], jp[j, _WAY] = wax, way
            dx, dy = jp[j, _DCX] + rbx - rax, jp[j, _DCY] + rby - ray
            a1 = (dx + rax) * way - (dy + ray) * wax
            a2 = rbx * way - rby * wax
            k = ma + mb + ia * a1 * a1 + ib * a2 * a2
            jp[j, _AXM] = 1.0 / k if k > 0.0 else 0.0
            if kind == WHEEL:  # across the axis (in _K11) and the motor's turn (in _K22)
                s1, s2 = (dx + rax) * wax + (dy + ray) * way, rbx * wax + rby * way
                k = ma + mb + ia * s1 * s1 + ib * s2 * s2
                jp[j, _K11] = 1.0 / k if k > 0.0 else 0.0
                jp[j, _K22] = 1.0 / (ia + ib) if ia + ib > 0.0 else 0.0
        elif kind == MOUSE:  # (body b, held to a world point)
            k11, k12, k22 = mb + ib * rby * rby, -ib * rbx * rby, mb + ib * rbx * rbx
            det = k11 * k22 - k12 * k12
            det = 1.0 / det if det != 0.0 else 0.0
            jp[j, _K11], jp[j, _K12], jp[j, _K22] = det * k22, -det * k12, det * k11
            jp[j, _AXM] = 1.0 / ib if ib > 0.0 else 0.0
            jp[j, _AB], jp[j, _AM], jp[j, _AI] = soft(0.5, 0.1, h)  # (Box2D's: damps the turn a little)
        elif kind == MOTOR:  # the point's 2x2 effective mass (inverted) and the angular one
            k11 = ma + mb + ray * ray * ia + rby * rby * ib
            k12 = -ray * rax * ia - rby * rbx * ib
            k22 = ma + mb + rax * rax * ia + rbx * rbx * ib
            det = k11 * k22 - k12 * k12
            det = 1.0 / det if det != 0.0 else 0.0
            jp[j, _K11], jp[j, _K12], jp[j, _K22] = det * k22, -det * k12, det * k11
            k = ia + ib
            jp[j, _AXM] = 1.0 / k if k > 0.0 else 0.0
        else:
            k = ia + ib
            jp[j, _AXM] = 1.0 / k if k > 0.0 else 0.0
    return jp


@leaf
def _unit(x, y):
    """``(x, y)`` normalised; (0, 0) for a vector too short to have a direction (``b2Normalize``)."""
    d = math.sqrt(x * x + y * y)
    if d < 1e-300:
        return 0.0, 0.0
    return x / d, y / d


@leaf
def _state(r, x, y, x0, y0, qc, qs, rot, vx, vy, w):
    """A body's motion since the step began (dx, dy, turn cos, sin), angle and velocity; the
    world's (row -1) is still."""
    if r < 0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0
    return x[r] - x0[r], y[r] - y0[r], qc[r], qs[r], rot[r], vx[r], vy[r], w[r]


@leaf
def _store(r, m, i, vxr, vyr, wr, vx, vy, w):
    """Write a body's new velocity (a body that takes no impulse keeps its own)."""
    if r >= 0 and (m > 0.0 or i > 0.0):
        vx[r], vy[r], w[r] = vxr, vyr, wr


@leaf
def warm_start_joints(jint, jf, jp, imp, x, y, x0, y0, qc, qs, rot, vx, vy, w):
    """Apply each joint's accumulated impulses (Box2D's ``b2WarmStart*Joint``)."""
    for j in range(jint.shape[0]):
        if jp[j, _ON] == 0.0:
            continue
        kind, a, b = jint[j, 0], jint[j, 1], jint[j, 2]
        dax, day, ca, sa, _ra, vax, vay, wa = _state(a, x, y, x0, y0, qc, qs, rot, vx, vy, w)
        dbx, dby, cb, sb, _rb, vbx, vby, wb = _state(b, x, y, x0, y0, qc, qs, rot, vx, vy, w)
        rax, ray = ca * jp[j, _RAX] - sa * jp[j, _RAY], sa * jp[j, _RAX] + ca * jp[j, _RAY]
        rbx, rby = cb * jp[j, _RBX] - sb * jp[j, _RBY], sb * jp[j, _RBX] + cb * jp[j, _RBY]
        if kind == DISTANCE:
            ux, uy = _unit(jp[j, _DCX] + dbx - dax + rbx - rax, jp[j, _DCY] + dby - day + rby - ray)
            axial = imp[j, _PX] + imp[j, _ILO] - imp[j, _IUP]
            px, py, ang = axial * ux, axial * uy, 0.0
        elif kind == PRISMATIC or kind == WHEEL:  # Box2D's b2WarmStart{Prismatic,Wheel}Joint
            dx, dy = jp[j, _DCX] + dbx - dax + rbx - rax, jp[j, _DCY] + dby - day + rby - ray
            ux, uy = ca * jp[j, _WAX] - sa * jp[j, _WAY], sa * jp[j, _WAX] + ca * jp[j, _WAY]
            if kind == PRISMATIC:  # along (motor, limits and spring), across, about
                axial = imp[j, _IANG] + imp[j, _ILO] - imp[j, _IUP]
                if jf[j, _HZ] > 0.0:  # (only then: a slider without a spring adds nothing, not even a 0)
                    axial += imp[j, _ISPR]
                elif imp[j, _ISPR] != 0.0:  # a spring taken off: it starts afresh if put back (Box2D)
                    imp[j, _ISPR] = 0.0
                perp, turn = imp[j, _PX], imp[j, _PY]
            else:  # along (spring and limits), across; the motor's turn
                axial = imp[j, _PY] + imp[j, _ILO] - imp[j, _IUP]
                perp, turn = imp[j, _PX], imp[j, _IANG]
            a1, a2 = (dx + rax) * uy - (dy + ray) * ux, rbx * uy - rby * ux
            s1, s2 = (dx + rax) * ux + (dy + ray) * uy, rbx * ux + rby * uy  # (crosses with the left perp)
            px, py = axial * ux - perp * uy, axial * uy + perp * ux
            la, lb = axial * a1 + perp * s1 + turn, axial * a2 + perp * s2 + turn
            ma, ia, mb, ib = jp[j, _MA], jp[j, _IA], jp[j, _MB], jp[j, _IB]
            _store(a, ma, ia, vax - ma * px, vay - ma * py, wa - ia * la, vx, vy, w)
            _store(b, mb, ib, vbx + mb * px, vby + mb * py, wb + ib * lb, vx, vy, w)
            continue
        else:
            px, py = imp[j, _PX], imp[j, _PY]
            ang = imp[j, _IANG] + imp[j, _ILO] - imp[j, _IUP]
            if kind == REVOLUTE and jf[j, _HZ] > 0.0:  # the spring's turn
                ang += imp[j, _ISPR]
            elif imp[j, _ISPR] != 0.0:  # (a spring taken off, as above)
                imp[j, _ISPR] = 0.0
        ma, ia, mb, ib = jp[j, _MA], jp[j, _IA], jp[j, _MB], jp[j, _IB]
        _store(a, ma, ia, vax - ma * px, vay - ma * py, wa - ia * (rax * py - ray * px + ang), vx, vy, w)
        _store(b, mb, ib, vbx + mb * px, vby + mb * py, wb + ib * (rbx * py - rby * px + ang), vx, vy, w)


@leaf
def solve_joints(jint, jf, jp, imp, x, y, x0, y0, qc, qs, rot, vx, vy, w, use_bias, csoft, h, inv_h):
    """One pass over the joints (Box2D's ``b2Solve*Joint``): with the bias that pulls them back
    together (``use_bias``; ``csoft``: the joints' softness) or without it (the relax)."""
    for j in range(jint.shape[0]):
        if jp[j, _ON] == 0.0:
            continue
        kind, a, b = jint[j, 0], jint[j, 1], jint[j, 2]
        dax, day, ca, sa, rota, vax, vay, wa = _state(a, x, y, x0, y0, qc, qs, rot, vx, vy, w)
        dbx, dby, cb, sb, rotb, vbx, vby, wb = _state(b, x, y, x0, y0, qc, qs, rot, vx, vy, w)
        # the anchors now: turned by each body's turn since the step began
        rax, ray = ca * jp[j, _RAX] - sa * jp[j, _RAY], sa * jp[j, _RAX] + ca * jp[j, _RAY]
        rbx, rby = cb * jp[j, _RBX] - sb * jp[j, _RBY], sb * jp[j, _RBX] + cb * jp[j, _RBY]
        # the separation of the anchors (b's less a's) now
        sx, sy = jp[j, _DCX] + dbx - dax + rbx - rax, jp[j, _DCY] + dby - day + rby - ray
        ma, ia, mb, ib = jp[j, _MA], jp[j, _IA], jp[j, _MB], jp[j, _IB]
        if kind == DISTANCE:
            vax, vay, wa, vbx, vby, wb = _distance(jf, jp, imp, j, sx, sy, rax, ray, rbx, rby, ma, ia, mb, ib,
                                                   vax, vay, wa, vbx, vby, wb, use_bias, csoft, h, inv_h)
        elif kind == REVOLUTE:
            angle = rotb - rota - jf[j, _REF]
            vax, vay, wa, vbx, vby, wb = _revolute(jf, jp, imp, j, angle, sx, sy, rax, ray, rbx, rby, ma, ia, mb,
                                                   ib, vax, vay, wa, vbx, vby, wb, use_bias, csoft, h, inv_h)
        elif kind == PRISMATIC:
            angle = rotb - rota - jf[j, _REF]
            ux, uy = ca * jp[j, _WAX] - sa * jp[j, _WAY], sa * jp[j, _WAX] + ca * jp[j, _WAY]
            vax, vay, wa, vbx, vby, wb = _prismatic(jf, jp, imp, j, angle, ux, uy, sx, sy, rax, ray, rbx, rby, ma, ia,
                                                    mb, ib, vax, vay, wa, vbx, vby, wb, use_bias, csoft, h, inv_h)
        elif kind == WHEEL:
            ux, uy = ca * jp[j, _WAX] - sa * jp[j, _WAY], sa * jp[j, _WAX] + ca * jp[j, _WAY]
            vax, vay, wa, vbx, vby, wb = _wheel(jf, jp, imp, j, ux, uy, sx, sy, rax, ray, rbx, rby, ma, ia, mb, ib,
                                                vax, vay, wa, vbx, vby, wb, use_bias, csoft, h, inv_h)
        elif kind == WELD:
            angle = rotb - rota - jf[j, _REF]
            vax, vay, wa, vbx, vby, wb = _weld(jf, jp, imp, j, angle, sx, sy, rax, ray, rbx, rby, ma, ia, mb, ib,
                                               vax, vay, wa, vbx, vby, wb, use_bias, csoft)
        elif kind == MOTOR:
            angle = _unwind(rotb - rota - jf[j, _REF])
            vax, vay, wa, vbx, vby, wb = _motor(jf, jp, imp, j, angle, sx, sy, rax, ray, rbx, rby, ma, ia, mb, ib,
                                                vax, vay, wa, vbx, vby, wb, h, inv_h)
        else:
            vbx, vby, wb = _mouse(jf, jp, imp, j, sx, sy, rbx, rby, mb, ib, vbx, vby, wb, h)
        _store(a, ma, ia, vax, vay, wa, vx, vy, w)
        _store(b, mb, ib, vbx, vby, wb, vx, vy, w)


@leaf
def _axial(s, ux, uy, rax, ray, rbx, rby, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb):
    """The velocities after the impulse ``s`` along the axis ``(ux, uy)`` at the anchors."""
    px, py = s * ux, s * uy
    return (vax - ma * px, vay - ma * py, wa - ia * (rax * py - ray * px),
            vbx + mb * px, vby + mb * py, wb + ib * (rbx * py - rby * px))


@leaf
def _limit(c, cdot, mass, old, use_bias, csoft, inv_h):
    """A one-sided limit's new accumulated impulse (>= 0), ``c >= 0`` where it is kept: ahead of
    it, speculative (close the gap, no more); past it, soft (with the bias) or rigid."""
    bias, ms, isc = 0.0, 1.0, 0.0
    if c > 0.0:
        bias = c * inv_h
    elif use_bias:
        bias, ms, isc = csoft[0] * c, csoft[1], csoft[2]
    return max(old - ms * mass * (cdot + bias) - isc * old, 0.0)


@leaf
def _distance(jf, jp, imp, j, sx, sy, rax, ray, rbx, rby, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb, use_bias,
              csoft, h, inv_h):
    """Box2D's ``b2SolveDistanceJoint``: a spring toward the length (``hertz > 0``) and the
    limits, or one rigid row where the least and the most length are one."""
    length = math.sqrt(sx * sx + sy * sy)
    ux, uy = _unit(sx, sy)
    mass = jp[j, _AXM]
    lo, hi, has_hi = jf[j, _LO], jf[j, _HI], jf[j, _HAS_HI] != 0.0
    if jf[j, _HZ] > 0.0 or not has_hi or lo < hi:
        if jf[j, _HZ] > 0.0:  # the spring: always soft, always biased
            cdot = (vbx - wb * rby - vax + wa * ray) * ux + (vby + wb * rbx - vay - wa * rax) * uy
            old = imp[j, _PX]
            s = -jp[j, _SM] * mass * (cdot + jp[j, _SB] * (length - jf[j, _LEN])) - jp[j, _SI] * old
            imp[j, _PX] = old + s
            vax, vay, wa, vbx, vby, wb = _axial(s, ux, uy, rax, ray, rbx, rby, ma, ia, mb, ib, vax, vay, wa, vbx,
                                                vby, wb)
        # the least length
        cdot = (vbx - wb * rby - vax + wa * ray) * ux + (vby + wb * rbx - vay - wa * rax) * uy
        old = imp[j, _ILO]
        new = _limit(length - lo, cdot, mass, old, use_bias, csoft, inv_h)
        imp[j, _ILO] = new
        vax, vay, wa, vbx, vby, wb = _axial(new - old, ux, uy, rax, ray, rbx, rby, ma, ia, mb, ib, vax, vay, wa,
                                            vbx, vby, wb)
        if has_hi:  # the most (signs flipped: c and the impulse stay positive where it holds)
            cdot = (vbx - wb * rby - vax + wa * ray) * ux + (vby + wb * rbx - vay - wa * rax) * uy
            old = imp[j, _IUP]
            new = _limit(hi - length, -cdot, mass, old, use_bias, csoft, inv_h)
            imp[j, _IUP] = new
            vax, vay, wa, vbx, vby, wb = _axial(old - new, ux, uy, rax, ray, rbx, rby, ma, ia, mb, ib, vax, vay,
                                                wa, vbx, vby, wb)
    else:  # rigid
        cdot = (vbx - wb * rby - vax + wa * ray) * ux + (vby + wb * rbx - vay - wa * rax) * uy
        bias, ms, isc = 0.0, 1.0, 0.0
        if use_bias:
            bias, ms, isc = csoft[0] * (length - jf[j, _LEN]), csoft[1], csoft[2]
        s = -ms * mass * (cdot + bias) - isc * imp[j, _PX]
        imp[j, _PX] += s
        vax, vay, wa, vbx, vby, wb = _axial(s, ux, uy, rax, ray, rbx, rby, ma, ia, mb, ib, vax, vay, wa, vbx, vby,
                                            wb)
    return vax, vay, wa, vbx, vby, wb


@leaf
def _point(jp, imp, j, sx, sy, rax, ray, rbx, rby, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb, bias_rate, ms, isc):
    """The point-to-point row of the revolute and weld joints (Box2D's 2x2 block): the anchors'
    relative velocity, plus ``bias_rate`` times their separation, to zero."""
    cx = vbx - wb * rby - vax + wa * ray + bias_rate * sx
    cy = vby + wb * rbx - vay - wa * rax + bias_rate * sy
    k11 = ma + mb + ray * ray * ia + rby * rby * ib
    k12 = -ray * rax * ia - rby * rbx * ib
    k22 = ma + mb + rax * rax * ia + rbx * rbx * ib
    det = k11 * k22 - k12 * k12
    det = 1.0 / det if det != 0.0 else 0.0
    bx, by = det * (k22 * cx - k12 * cy), det * (k11 * cy - k12 * cx)
    px = -ms * bx - isc * imp[j, _PX]
    py = -ms * by - isc * imp[j, _PY]
    imp[j, _PX] += px
    imp[j, _PY] += py
    return (vax - ma * px, vay - ma * py, wa - ia * (rax * py - ray * px),
            vbx + mb * px, vby + mb * py, wb + ib * (rbx * py - rby * px))


@leaf
def _revolute(jf, jp, imp, j, angle, sx, sy, rax, ray, rbx, rby, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb,
              use_bias, csoft, h, inv_h):
    """Box2D's ``b2SolveRevoluteJoint``: the spring (``hertz > 0``: toward the angle it was made
    at; a real spring, in the relax too), the motor, the angle limits, then the shared point."""
    mass = jp[j, _AXM]
    if ia + ib > 0.0:
        if jf[j, _HZ] > 0.0:
            old = imp[j, _ISPR]
            s = -jp[j, _SM] * mass * (wb - wa + jp[j, _SB] * angle) - jp[j, _SI] * old
            imp[j, _ISPR] = old + s
            wa -= ia * s
            wb += ib * s
        if jf[j, _TORQUE] > 0.0:  # the motor: the relative turn at its speed, with at most its torque
            old = imp[j, _IANG]
            most = h * jf[j, _TORQUE]
            new = min(max(old - mass * (wb - wa - jf[j, _SPEED]), -most), most)
            imp[j, _IANG] = new
            wa -= ia * (new - old)
            wb += ib * (new - old)
        if jf[j, _HAS_LOWER] != 0.0:
            old = imp[j, _ILO]
            new = _limit(angle - jf[j, _LOWER], wb - wa, mass, old, use_bias, csoft, inv_h)
            imp[j, _ILO] = new
            wa -= ia * (new - old)
            wb += ib * (new - old)
        if jf[j, _HAS_UPPER] != 0.0:  # (signs flipped)
            old = imp[j, _IUP]
            new = _limit(jf[j, _UPPER] - angle, wa - wb, mass, old, use_bias, csoft, inv_h)
            imp[j, _IUP] = new
            wa += ia * (new - old)
            wb -= ib * (new - old)
    bias_rate, ms, isc = 0.0, 1.0, 0.0
    if use_bias:
        bias_rate, ms, isc = csoft[0], csoft[1], csoft[2]
    return _point(jp, imp, j, sx, sy, rax, ray, rbx, rby, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb, bias_rate, ms,
                  isc)


@leaf
def _along(s, ux, uy, a1, a2, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb):
    """The velocities after the impulse ``s`` along a slide's axis ``(ux, uy)`` (B takes it, A its
    opposite; ``a1``, ``a2``: the turning arms, Box2D's crosses of ``d + rA`` and ``rB`` with it)."""
    return (vax - ma * s * ux, vay - ma * s * uy, wa - ia * s * a1,
            vbx + mb * s * ux, vby + mb * s * uy, wb + ib * s * a2)


@leaf
def _slide_limits(jf, imp, j, slide, ux, uy, a1, a2, mass, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb, use_bias, csoft,
                  inv_h):
    """The lower and upper limits of a slide (prismatic and wheel joints) at ``slide`` along the axis."""
    if jf[j, _HAS_LOWER] != 0.0:
        cdot = ux * (vbx - vax) + uy * (vby - vay) + a2 * wb - a1 * wa
        old = imp[j, _ILO]
        new = _limit(slide - jf[j, _LOWER], cdot, mass, old, use_bias, csoft, inv_h)
        imp[j, _ILO] = new
        vax, vay, wa, vbx, vby, wb = _along(new - old, ux, uy, a1, a2, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb)
    if jf[j, _HAS_UPPER] != 0.0:  # (signs flipped)
        cdot = ux * (vax - vbx) + uy * (vay - vby) + a1 * wa - a2 * wb
        old = imp[j, _IUP]
        new = _limit(jf[j, _UPPER] - slide, cdot, mass, old, use_bias, csoft, inv_h)
        imp[j, _IUP] = new
        vax, vay, wa, vbx, vby, wb = _along(old - new, ux, uy, a1, a2, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb)
    return vax, vay, wa, vbx, vby, wb


@leaf
def _prismatic(jf, jp, imp, j, angle, ux, uy, dx, dy, rax, ray, rbx, rby, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb,
               use_bias, csoft, h, inv_h):
    """Box2D's ``b2SolvePrismaticJoint``: the spring along the axis ``(ux, uy)`` (``hertz > 0``:
    toward where it was made; a real spring, in the relax too), the motor along it, the limits of
    the slide, then the block that keeps the anchors on the axis's line and the angle (``dx, dy``:
    the anchors' separation, b's less a's)."""
    a1, a2 = (dx + rax) * uy - (dy + ray) * ux, rbx * uy - rby * ux
    mass = jp[j, _AXM]
    if jf[j, _HZ] > 0.0:
        cdot = ux * (vbx - vax) + uy * (vby - vay) + a2 * wb - a1 * wa
        s = -jp[j, _SM] * mass * (cdot + jp[j, _SB] * (ux * dx + uy * dy)) - jp[j, _SI] * imp[j, _ISPR]
        imp[j, _ISPR] += s
        vax, vay, wa, vbx, vby, wb = _along(s, ux, uy, a1, a2, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb)
    if jf[j, _FORCE] > 0.0:  # the motor: the slide at its speed, with at most its force
        cdot = ux * (vbx - vax) + uy * (vby - vay) + a2 * wb - a1 * wa
        old = imp[j, _IANG]
        most = h * jf[j, _FORCE]
        new = min(max(old + mass * (jf[j, _SPEED] - cdot), -most), most)
        imp[j, _IANG] = new
        vax, vay, wa, vbx, vby, wb = _along(new - old, ux, uy, a1, a2, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb)
    slide = ux * dx + uy * dy
    vax, vay, wa, vbx, vby, wb = _slide_limits(jf, imp, j, slide, ux, uy, a1, a2, mass, ma, ia, mb, ib, vax, vay, wa,
                                               vbx, vby, wb, use_bias, csoft, inv_h)
    # across the axis (its left perpendicular) and the angle, as one 2x2 block
    nx, ny = -uy, ux
    s1, s2 = (dx + rax) * ny - (dy + ray) * nx, rbx * ny - rby * nx
    c1 = nx * (vbx - vax) + ny * (vby - vay) + s2 * wb - s1 * wa
    c2 = wb - wa
    ms, isc = 1.0, 0.0
    if use_bias:
        c1 += csoft[0] * (nx * dx + ny * dy)
        c2 += csoft[0] * angle
        ms, isc = csoft[1], csoft[2]
    k11 = ma + mb + ia * s1 * s1 + ib * s2 * s2
    k12 = ia * s1 + ib * s2
    k22 = ia + ib
    if k22 == 0.0:  # (bodies that do not turn)
        k22 = 1.0
    det = k11 * k22 - k12 * k12
    det = 1.0 / det if det != 0.0 else 0.0
    b1, b2 = det * (k22 * c1 - k12 * c2), det * (k11 * c2 - k12 * c1)
    p1 = -ms * b1 - isc * imp[j, _PX]
    p2 = -ms * b2 - isc * imp[j, _PY]
    imp[j, _PX] += p1
    imp[j, _PY] += p2
    la, lb = p1 * s1 + p2, p1 * s2 + p2
    return (vax - ma * p1 * nx, vay - ma * p1 * ny, wa - ia * la,
            vbx + mb * p1 * nx, vby + mb * p1 * ny, wb + ib * lb)


@leaf
def _wheel(jf, jp, imp, j, ux, uy, dx, dy, rax, ray, rbx, rby, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb, use_bias,
           csoft, h, inv_h):
    """Box2D's ``b2SolveWheelJoint``: the motor's turn, the suspension spring along the axis
    ``(ux, uy)`` (a real spring: in the relax too), the limits of the slide, then the point kept on
    the axis's line (``dx, dy``: the anchors' separation, b's less a's)."""
    if jf[j, _TORQUE] > 0.0 and ia + ib > 0.0:
        old = imp[j, _IANG]
        most = h * jf[j, _TORQUE]
        new = min(max(old - jp[j, _K22] * (wb - wa - jf[j, _SPEED]), -most), most)
        imp[j, _IANG] = new
        wa -= ia * (new - old)
        wb += ib * (new - old)
    a1, a2 = (dx + rax) * uy - (dy + ray) * ux, rbx * uy - rby * ux
    mass = jp[j, _AXM]
    slide = ux * dx + uy * dy
    if jf[j, _HZ] > 0.0:
        cdot = ux * (vbx - vax) + uy * (vby - vay) + a2 * wb - a1 * wa
        s = -jp[j, _SM] * mass * (cdot + jp[j, _SB] * slide) - jp[j, _SI] * imp[j, _PY]
        imp[j, _PY] += s
        vax, vay, wa, vbx, vby, wb = _along(s, ux, uy, a1, a2, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb)
    vax, vay, wa, vbx, vby, wb = _slide_limits(jf, imp, j, slide, ux, uy, a1, a2, mass, ma, ia, mb, ib, vax, vay, wa,
                                               vbx, vby, wb, use_bias, csoft, inv_h)
    nx, ny = -uy, ux  # across the axis: the point on the line
    s1, s2 = (dx + rax) * ny - (dy + ray) * nx, rbx * ny - rby * nx
    bias, ms, isc = 0.0, 1.0, 0.0
    if use_bias:
        bias, ms, isc = csoft[0] * (nx * dx + ny * dy), csoft[1], csoft[2]
    cdot = nx * (vbx - vax) + ny * (vby - vay) + s2 * wb - s1 * wa
    s = -ms * jp[j, _K11] * (cdot + bias) - isc * imp[j, _PX]
    imp[j, _PX] += s
    return (vax - ma * s * nx, vay - ma * s * ny, wa - ia * s * s1,
            vbx + mb * s * nx, vby + mb * s * ny, wb + ib * s * s2)


@leaf
def _weld(jf, jp, imp, j, angle, sx, sy, rax, ray, rbx, rby, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb, use_bias,
          csoft):
    """Box2D's ``b2SolveWeldJoint`` (not block solved): the relative angle, then the shared point;
    a spring (``hertz > 0``) is always biased, a rigid weld only with ``use_bias``."""
    spring = jf[j, _HZ] > 0.0
    bias_rate, ms, isc = 0.0, 1.0, 0.0
    if spring:
        bias_rate, ms, isc = jp[j, _SB], jp[j, _SM], jp[j, _SI]
    elif use_bias:
        bias_rate, ms, isc = csoft[0], csoft[1], csoft[2]
    old = imp[j, _IANG]
    s = -ms * jp[j, _AXM] * (wb - wa + bias_rate * angle) - isc * old
    imp[j, _IANG] = old + s
    wa -= ia * s
    wb += ib * s
    return _point(jp, imp, j, sx, sy, rax, ray, rbx, rby, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb, bias_rate, ms,
                  isc)


@leaf
def _mouse(jf, jp, imp, j, sx, sy, rbx, rby, mb, ib, vbx, vby, wb, h):
    """Box2D's ``b2SolveMouseJoint``: damp the body's turn a little, then pull its anchor toward the
    target (a spring, always biased), the accumulated impulse at most ``max_force * h``."""
    if ib > 0.0:
        old = imp[j, _IANG]
        s = -jp[j, _AM] * jp[j, _AXM] * wb - jp[j, _AI] * old
        imp[j, _IANG] = old + s
        wb += ib * s
    cx = vbx - wb * rby + jp[j, _SB] * sx
    cy = vby + wb * rbx + jp[j, _SB] * sy
    bx = jp[j, _K11] * cx + jp[j, _K12] * cy
    by = jp[j, _K12] * cx + jp[j, _K22] * cy
    ox, oy = imp[j, _PX], imp[j, _PY]
    nx = ox - jp[j, _SM] * bx - jp[j, _SI] * ox
    ny = oy - jp[j, _SM] * by - jp[j, _SI] * oy
    most = jf[j, _FORCE] * h
    mag = math.sqrt(nx * nx + ny * ny)
    if mag > most:
        nx, ny = nx * most / mag, ny * most / mag
    imp[j, _PX], imp[j, _PY] = nx, ny
    px, py = nx - ox, ny - oy
    return vbx + mb * px, vby + mb * py, wb + ib * (rbx * py - rby * px)


@leaf
def _unwind(angle):
    """``angle`` brought into [-pi, pi) by whole turns."""
    if -math.pi <= angle < math.pi:
        return angle
    return angle - 2.0 * math.pi * math.floor((angle + math.pi) / (2.0 * math.pi))


@leaf
def _motor(jf, jp, imp, j, angle, sx, sy, rax, ray, rbx, rby, ma, ia, mb, ib, vax, vay, wa, vbx, vby, wb, h, inv_h):
    """Box2D's ``b2SolveMotorJoint``: the relative turn, then the point, each driven toward its
    target at ``correction`` of the error a sub-step (``angle``: b's turn relative to a's less the
    target, unwound; ``sx, sy``: b's origin less a's target point), the accumulated impulses at most
    ``torque * h`` and (in length) ``force * h``. Always biased: in the relax too, as Box2D does."""
    beta = jf[j, _CORRECTION] * inv_h
    if ia + ib > 0.0:
        old = imp[j, _IANG]
        most = h * jf[j, _TORQUE]
        new = min(max(old - jp[j, _AXM] * (wb - wa + beta * angle), -most), most)
        imp[j, _IANG] = new
        wa -= ia * (new - old)
        wb += ib * (new - old)
    cx = vbx - wb * rby - vax + wa * ray + beta * sx
    cy = vby + wb * rbx - vay - wa * rax + beta * sy
    ox, oy = imp[j, _PX], imp[j, _PY]
    nx = ox - (jp[j, _K11] * cx + jp[j, _K12] * cy)
    ny = oy - (jp[j, _K12] * cx + jp[j, _K22] * cy)
    most = h * jf[j, _FORCE]
    mag = math.sqrt(nx * nx + ny * ny)
    if mag > most:
        nx, ny = nx * most / mag, ny * most / mag
    imp[j, _PX], imp[j, _PY] = nx, ny
    px, py = nx - ox, ny - oy
    return (vax - ma * px, vay - ma * py, wa - ia * (rax * py - ray * px),
            vbx + mb * px, vby + mb * py, wb + ib * (rbx * py - rby * px))
