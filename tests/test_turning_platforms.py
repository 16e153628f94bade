"""A character riding a platform that turns (issue 37: a swinging platform the player rides): it is
carried by the motion of the point under its feet, the platform's displacement and its turn about
its origin, so it stays where it stands on the platform, in both solvers."""

from __future__ import annotations

import math

import pytest

from framework import AABB, Hitbox, Polygon, Scene, Transform, Velocity
from framework.character import CharacterController

DT = 1 / 64
W, H = 16.0, 32.0


def board(hw: float, hh: float) -> Polygon:
    return Polygon([(-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)])


def riding(solver: str, at: float, spin: float, vx: float = 0.0):
    """A character standing ``at`` from the middle of a kinematic board (128 x 16, origin at its
    middle, y = 100), which then turns at ``spin`` radians a second (and moves at ``vx``)."""
    s = Scene(gravity=(0.0, -1024.0), solver=solver)
    plat = s.spawn(Transform(200.0, 100.0), Velocity(), Hitbox(board(64.0, 8.0), body="kinematic"))
    e = s.spawn(Transform(200.0 + at, 108.0 + H / 2), Velocity(), Hitbox(AABB(W, H), body="kinematic"),
                CharacterController())
    for _ in range(20):
        s.step(DT)
    assert s.get(e, CharacterController).floor_entity == plat
    s.get(plat, Velocity).angular, s.get(plat, Velocity).x = spin, vx
    return s, plat, e


def on_board(s: Scene, plat: int, e: int) -> tuple[float, float]:
    """The character's feet (its bottom middle) in the board's frame."""
    p, t = s.get(plat, Transform), s.get(e, Transform)
    dx, dy = t.x - p.x, t.y - H / 2 - p.y
    c, si = math.cos(p.rotation), math.sin(p.rotation)
    return c * dx + si * dy, -si * dx + c * dy


@pytest.mark.parametrize("solver", ["exact", "soft"])
@pytest.mark.parametrize("at, spin", [(40.0, 0.5), (-40.0, 0.5), (40.0, -0.5), (0.0, 0.5)])
def test_a_character_on_a_turning_board_stays_where_it_stands_on_it(solver, at, spin):
    # the board turns by a quarter radian (14 degrees, a walkable slope) in half a second: the
    # character, standing still on it, keeps its place along the board (its feet turn with the
    # board's point under them, about the board's middle) and stays on it
    s, plat, e = riding(solver, at, spin)
    along0, _up0 = on_board(s, plat, e)
    for _ in range(32):
        s.step(DT)
        assert s.get(e, CharacterController).on_floor
        assert s.get(e, CharacterController).floor_entity == plat
    assert s.get(plat, Transform).rotation == pytest.approx(spin * 0.5)
    along, _up = on_board(s, plat, e)
    # (its box does not turn: its lower corner rests on the tilted board, its feet's middle a
    # little off the surface, which the frame's x reads as at most (W/2) tan(0.25) x sin(0.25))
    assert along == pytest.approx(along0, abs=0.6)


@pytest.mark.parametrize("solver", ["exact", "soft"])
def test_before_the_turn_was_carried_the_character_drifted_off_its_place(solver):
    # what the fix changes, measured: carried by the board's middle alone (which stays put) the
    # character 40 from the middle would keep its world x while the board's point under it goes
    # round: 40 (1 - cos 0.25) + 8 sin 0.25 along the board, about 3.2 - its drift must be far less
    s, plat, e = riding(solver, 40.0, 0.5)
    x0 = s.get(e, Transform).x
    for _ in range(32):
        s.step(DT)
    moved_with_board = 40.0 * (math.cos(0.25) - 1.0) - 8.0 * math.sin(0.25)
    assert s.get(e, Transform).x - x0 == pytest.approx(moved_with_board, abs=1.0)


@pytest.mark.parametrize("solver", ["exact", "soft"])
def test_jumping_off_a_turning_board_keeps_the_speed_of_its_point(solver):
    # leaving a turning board keeps the velocity of the board's point under its feet: at 40 right
    # of the middle of a board turning at 0.5 rad/s counter-clockwise, about (0, 20) up
    s, plat, e = riding(solver, 40.0, 0.5)
    s.step(DT)
    s.get(e, Velocity).y = 200.0  # jump
    s.step(DT)
    # 200 of its own and the board's point's 0.5 x 40 = 20 (carried by the board's middle alone, which
    # stays put, it got none), less a step of gravity
    assert s.get(e, Velocity).y == pytest.approx(200.0 + 20.0 - 1024.0 * DT, abs=0.1)
    assert not s.get(e, CharacterController).on_floor


@pytest.mark.parametrize("solver", ["exact", "soft"])
@pytest.mark.parametrize("vy", [64.0, -64.0])
def test_a_character_on_a_rising_or_sinking_board_stays_on_its_top_every_step(solver, vy):
    # the soft step moves the board after the character stage: the character moves on the board
    # where it is, then rides to where the board will be (before, riding first and landing on the
    # board not yet moved, it sank into it by vy dt and left the floor for a step)
    s, plat, e = riding(solver, 40.0, 0.0)
    s.get(plat, Velocity).y = vy
    for _ in range(16):
        s.step(DT)
        assert s.get(e, CharacterController).on_floor
        gap = s.get(e, Transform).y - H / 2 - (s.get(plat, Transform).y + 8.0)
        assert 0.0 <= gap < 1e-6


@pytest.mark.parametrize("solver", ["exact", "soft"])
@pytest.mark.parametrize("at, spin", [(40.0, 0.5), (-40.0, 0.5), (0.0, 0.5), (40.0, -0.5)])
def test_a_one_way_board_turning_under_a_character_holds_it(solver, at, spin):
    # a one-way platform holds a body whose feet were above its top when the step began; for a
    # tilted board that top (its bounding box's) is its higher end, above the feet of a character
    # standing anywhere else on it: the board it stood on when the step began holds it regardless
    # (it was above it then), so it rides a one-way board as it tilts (before: it fell through)
    s = Scene(gravity=(0.0, -1024.0), solver=solver)
    plat = s.spawn(Transform(200.0, 100.0), Velocity(), Hitbox(board(64.0, 8.0), body="kinematic", one_way=True))
    e = s.spawn(Transform(200.0 + at, 108.0 + H / 2), Velocity(), Hitbox(AABB(W, H), body="kinematic"),
                CharacterController())
    for _ in range(20):
        s.step(DT)
    s.get(plat, Velocity).angular = spin
    for _ in range(32):
        s.step(DT)
        assert s.get(e, CharacterController).on_floor and s.get(e, CharacterController).floor_entity == plat
