"""Bodies of several shapes (``Parts``): mass data, the soft solver, events, refusals, snapshots.

Issue 38, part 1: a body of several hitboxes, each with its own offset, material and filter; its
mass, centre of mass and inertia from all of them (the parallel-axis theorem); contacts act on the
whole body, events name the shape that touched. Only the soft solver takes them.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from framework import (
    AABB,
    CharacterController,
    Circle,
    Hitbox,
    InvalidValue,
    MassData,
    Parts,
    Polygon,
    Scene,
    Transform,
    Velocity,
    body_mass_data,
)
from framework.events import PartEvent

DT = 1 / 60


# --- mass data ---------------------------------------------------------------------------------

def test_two_boxes_give_the_parallel_axis_sum_exactly():
    # A: a 2 x 1 box at the origin, B: the same box at (0.5, 1); density 12 makes each mass 24
    # and each inertia about its own centre m (w^2 + h^2) / 12 = 10. Centre (0.25, 0.5); each
    # centre is sqrt(0.3125) from it: I = 10 + 10 + 48 * 0.3125 = 35. Every value is dyadic.
    a = Hitbox(Polygon.box(2, 1), density=12.0)
    b = Hitbox(Polygon.box(2, 1), offset=(0.5, 1.0), density=12.0)
    assert body_mass_data(a, Parts([b])) == MassData(48.0, (0.25, 0.5), 35.0)


def test_a_box_split_in_two_has_the_mass_data_of_the_whole_box():
    # a 2 x 2 box of mass 2 centred on (0, 0.5): inertia 2 (4 + 4) / 12 = 4/3
    halves = body_mass_data(Hitbox(Polygon.box(2, 1)), Parts([Hitbox(Polygon.box(2, 1), offset=(0.0, 1.0))]))
    whole = Hitbox(Polygon.box(2, 2), offset=(0.0, 0.5), mass=2.0).mass_data
    assert halves.mass == whole.mass == 2.0
    assert halves.center == whole.center == (0.0, 0.5)
    assert halves.inertia == pytest.approx(4 / 3, rel=1e-15) and whole.inertia == pytest.approx(4 / 3, rel=1e-15)


def test_box2d_offset_box_turns_about_its_centroid():
    # Box2D v3's ShapeMassTest: a box 1 x 0.5 of density 1 off the origin has inertia about its
    # centroid m (w^2 + h^2) / 12 = 0.5 * 1.25 / 12 = 0.0520833..., not the 0.377 about the origin.
    hb = Hitbox(Polygon.box(1.0, 0.5), offset=(0.7, 0.4), density=1.0)
    data = hb.mass_data
    assert data.mass == 0.5 and data.center == (0.7, 0.4)
    assert data.inertia == pytest.approx(0.0520833, abs=1e-7)
    # the same box as a part of a body whose own hitbox is a tiny far circle: the body's inertia
    # is the box's plus the circle's and both parallel-axis terms
    c = Hitbox(Circle(0.5), offset=(-0.5, 0.0), density=4.0)  # mass pi, inertia pi / 8 about its centre
    body = body_mass_data(c, Parts([hb]))
    m = math.pi + 0.5
    cx = (-0.5 * math.pi + 0.5 * 0.7) / m
    cy = 0.5 * 0.4 / m
    inertia = (math.pi / 8 + math.pi * ((-0.5 - cx) ** 2 + cy ** 2)
               + 0.5 * 1.25 / 12 + 0.5 * ((0.7 - cx) ** 2 + (0.4 - cy) ** 2))
    assert body.mass == pytest.approx(m, rel=1e-15)
    assert body.center == pytest.approx((cx, cy), rel=1e-14)
    assert body.inertia == pytest.approx(inertia, rel=1e-14)


@settings(max_examples=60, deadline=None)
@given(w=st.integers(1, 64), h=st.integers(1, 64), ox=st.integers(-64, 64), oy=st.integers(-64, 64),
       density=st.integers(1, 16), cut=st.integers(1, 7))
def test_mass_data_is_the_same_however_a_box_is_cut_in_two(w, h, ox, oy, density, cut):
    # a box (w / 8 wide, h / 8 high at (ox, oy) / 8) and its two pieces cut at cut / 8 of its width
    w, h, ox, oy = w / 8, h / 8, ox / 8, oy / 8
    whole = Hitbox(Polygon.box(w, h), offset=(ox, oy), density=float(density)).mass_data
    wl = w * cut / 8
    wr = w - wl
    left = Hitbox(Polygon.box(wl, h), offset=(ox - w / 2 + wl / 2, oy), density=float(density))
    right = Hitbox(Polygon.box(wr, h), offset=(ox + w / 2 - wr / 2, oy), density=float(density))
    cut_body = body_mass_data(left, Parts([right]))
    assert cut_body.mass == pytest.approx(whole.mass, rel=1e-14)
    assert cut_body.center[0] == pytest.approx(whole.center[0], rel=1e-12, abs=1e-12)
    assert cut_body.center[1] == pytest.approx(whole.center[1], rel=1e-12, abs=1e-12)
    assert cut_body.inertia == pytest.approx(whole.inertia, rel=1e-10)


def test_infinite_inertia_or_mass_in_a_part_holds_the_whole_body():
    base = Hitbox(Polygon.box(1, 1))
    assert math.isinf(body_mass_data(base, Parts([Hitbox(Circle(0.5), inertia=math.inf)])).inertia)
    data = body_mass_data(base, Parts([Hitbox(Circle(0.5), offset=(2.0, 0.0), mass=math.inf)]))
    assert math.isinf(data.mass) and math.isinf(data.inertia) and data.center == (2.0, 0.0)


def test_scene_mass_data_reads_the_whole_body():
    scene = Scene(solver="soft")
    e = scene.spawn(Transform(3, 4), Velocity(), Hitbox(Polygon.box(2, 1), density=12.0),
                    Parts([Hitbox(Polygon.box(2, 1), offset=(0.5, 1.0), density=12.0)]))
    assert scene.mass_data(e) == MassData(48.0, (0.25, 0.5), 35.0)
    plain = scene.spawn(Transform(0, 0), Hitbox(Circle(1.0), mass=2.0))
    assert scene.mass_data(plain) == MassData(2.0, (0.0, 0.0), 1.0)


# --- the API's refusals ------------------------------------------------------------------------

def test_parts_refuse_what_is_not_a_list_of_new_hitboxes():
    with pytest.raises(InvalidValue, match="got one Hitbox"):
        Parts(Hitbox(Circle(1)))  # type: ignore[arg-type]
    with pytest.raises(InvalidValue, match="1 to 63"):
        Parts([])
    with pytest.raises(InvalidValue, match="part 2 must be a Hitbox"):
        Parts([Hitbox(Circle(1)), Circle(1)])  # type: ignore[list-item]
    hb = Hitbox(Circle(1))
    with pytest.raises(InvalidValue, match="twice"):
        Parts([hb, hb])
    scene = Scene(solver="soft")
    with pytest.raises(InvalidValue, match="needs a Hitbox"):
        scene.spawn(Transform(0, 0), Parts([Hitbox(Circle(1))]))
    with pytest.raises(InvalidValue, match="part 1 is body='static'"):
        scene.spawn(Transform(0, 0), Velocity(), Hitbox(Circle(1)), Parts([Hitbox(Circle(1), body="static")]))
    from framework import Chain, Segment

    ground = Chain([(2.0, 0.0), (1.0, 0.0), (0.0, 0.0)]).segments[0]
    with pytest.raises(InvalidValue, match="part 1 is a chain segment"):
        scene.spawn(Transform(0, 0), Hitbox(AABB(1, 1), body="static"), Parts([Hitbox(ground, body="static")]))
    assert scene.entities == []
    scene.spawn(Transform(0, 0), Hitbox(AABB(1, 1), body="static"),
                Parts([Hitbox(Segment((0.0, 0.0), (2.0, 0.0)), body="static")]))  # a plain segment: fine


def _scene_with_compound(solver: str = "soft") -> tuple[Scene, int]:
    scene = Scene(gravity=(0.0, -10.0), solver=solver)
    scene.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static"))
    e = scene.spawn(Transform(0.0, 2.0), Velocity(1.0, 0.0), Hitbox(Polygon.box(1, 1)),
                    Parts([Hitbox(Circle(0.25), offset=(0.0, 0.75))]))
    return scene, e


def _pose(scene: Scene) -> list[tuple[float, ...]]:
    out = []
    for e in scene.entities:
        t = scene.get(e, Transform)
        v = scene.try_get(e, Velocity)
        out.append((e, t.x, t.y, t.rotation) + ((v.x, v.y, v.angular) if v is not None else ()))
    return out


def test_the_exact_solver_refuses_a_compound_body_and_changes_nothing():
    scene, e = _scene_with_compound("exact")
    before, frame, time = _pose(scene), scene.frame, scene.time
    with pytest.raises(InvalidValue, match=f"entity {e} is a body of several shapes .*solver='soft'"):
        scene.step(DT)
    assert _pose(scene) == before and scene.frame == frame and scene.time == time
    scene.solver = "soft"  # the same bodies step in the soft solver
    scene.step(DT)
    assert scene.frame == frame + 1
    scene.solver = "exact"  # and are refused again after a switch back
    with pytest.raises(InvalidValue, match=f"entity {e} is a body of several shapes"):
        scene.step(DT)


def test_the_character_controller_refuses_a_compound_body():
    scene = Scene(gravity=(0.0, -10.0), solver="soft")
    scene.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static"))
    e = scene.spawn(Transform(0.0, 1.0), Velocity(), Hitbox(AABB(0.5, 1.0), body="kinematic"), CharacterController(),
                    Parts([Hitbox(Circle(0.25), offset=(0.0, 0.75), body="kinematic")]))
    before = _pose(scene)
    with pytest.raises(InvalidValue, match=f"entity {e} is a character"):
        scene.step(DT)
    assert _pose(scene) == before


def test_a_bad_value_written_to_a_part_is_named_at_the_next_step():
    scene, e = _scene_with_compound()
    scene.step(DT)
    part = scene.get(e, Parts)[0]
    part.friction = -1.0
    before = _pose(scene)
    with pytest.raises(InvalidValue, match=f"entity {e}: part 1: Hitbox friction must be >= 0"):
        scene.step(DT)
    assert _pose(scene) == before
    part.friction = 0.5
    scene.step(DT)


# --- the soft solver ---------------------------------------------------------------------------

def _l_body_on_ledge(x: float) -> tuple[Scene, int]:
    """An L: a bar 2 x 0.5 (its Hitbox, centred on the entity) and an upright 0.5 x 1.5 at its
    right end (a part), resting on a floor whose right edge is x = 0, the bar's centre at ``x``."""
    scene = Scene(gravity=(0.0, -10.0), solver="soft")
    scene.spawn(Transform(-5.0, -0.5), Hitbox(AABB(10.0, 1.0), body="static", friction=0.6))
    e = scene.spawn(Transform(x, 0.25), Velocity(), Hitbox(Polygon.box(2.0, 0.5), density=1.0, friction=0.6),
                    Parts([Hitbox(Polygon.box(0.5, 1.5), offset=(0.75, 1.0), density=1.0, friction=0.6)]))
    return scene, e


def test_an_l_shaped_body_tips_over_the_edge_where_its_centre_of_mass_says():
    # the centre of mass is 0.75 * 0.75 / 1.75 = 0.3214 right of the bar's centre: with the bar's
    # centre 0.2 or 0.31 inside the edge the centre of mass is past it, by 0.12 or 0.011 (tips);
    # 0.332 or 0.45 inside, it is not, by 0.011 or 0.13 (stays).
    for x, tips in ((-0.2, True), (-0.31, True), (-0.332, False), (-0.45, False)):
        scene, e = _l_body_on_ledge(x)
        com = x + scene.mass_data(e).center[0]
        assert (com > 0.0) == tips and abs(com) > 0.01
        for _ in range(240):
            scene.step(DT)
        t = scene.get(e, Transform)
        if tips:
            assert t.rotation < -0.5 and t.y < 0.0, (x, t)
        else:
            assert abs(t.rotation) < 1e-3 and t.y == pytest.approx(0.25, abs=1e-3), (x, t)
            assert t.x == pytest.approx(x, abs=1e-3)
    # the bar alone, its centre 0.2 inside the edge, stays: it is the part that tips the L
    scene = Scene(gravity=(0.0, -10.0), solver="soft")
    scene.spawn(Transform(-5.0, -0.5), Hitbox(AABB(10.0, 1.0), body="static", friction=0.6))
    bar = scene.spawn(Transform(-0.2, 0.25), Velocity(), Hitbox(Polygon.box(2.0, 0.5), density=1.0, friction=0.6))
    for _ in range(180):
        scene.step(DT)
    assert abs(scene.get(bar, Transform).rotation) < 1e-3


def test_a_compound_body_rests_at_the_height_of_the_one_shape_body_of_its_outline():
    def rest(parts: bool) -> Transform:
        scene = Scene(gravity=(0.0, -10.0), solver="soft")
        scene.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static", friction=0.5))
        if parts:  # two 1 x 1 boxes side by side: the outline of a 2 x 1 box
            e = scene.spawn(Transform(0.0, 1.0), Velocity(), Hitbox(Polygon.box(1, 1), offset=(-0.5, 0.0),
                                                                     friction=0.5),
                            Parts([Hitbox(Polygon.box(1, 1), offset=(0.5, 0.0), friction=0.5)]))
        else:
            e = scene.spawn(Transform(0.0, 1.0), Velocity(), Hitbox(Polygon.box(2, 1), mass=2.0, friction=0.5))
        for _ in range(240):
            scene.step(DT)
        return scene.get(e, Transform)

    two, one = rest(True), rest(False)
    # (the soft solver's tolerance: a body rests a little inside what holds it, as a stiff spring
    # under its weight, 1.2e-4 here for a mass of 2)
    # (the two-shape body's weight on four points: 2.1e-5)
    assert one.y == pytest.approx(0.5, abs=2e-4)
    assert two.y == pytest.approx(0.5, abs=2e-4)
    assert abs(two.y - one.y) < 1.5e-4
    assert abs(two.rotation) < 1e-3 and abs(two.x) < 1e-3


def test_the_shapes_of_one_body_never_collide_with_each_other():
    # two overlapping parts: were they pushed apart, the body would fly off or spin
    scene = Scene(gravity=(0.0, 0.0), solver="soft")
    e = scene.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(Polygon.box(1, 1)),
                    Parts([Hitbox(Polygon.box(1, 1), offset=(0.25, 0.25)), Hitbox(Circle(0.5))]))
    for _ in range(30):
        scene.step(DT)
    assert _pose(scene) == [(e, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)]
    assert scene.events == []


def test_a_head_that_hits_a_ceiling_is_named_by_its_part():
    scene = Scene(gravity=(0.0, -10.0), solver="soft")
    ceiling = scene.spawn(Transform(0.0, 3.5), Hitbox(AABB(4.0, 1.0), body="static"))
    # a character-like body: a 0.5 x 1 box (its Hitbox) and a head circle above it (part 1)
    body = scene.spawn(Transform(0.0, 0.0), Velocity(0.0, 8.0), Hitbox(Polygon.box(0.5, 1.0), inertia=math.inf),
                       Parts([Hitbox(Circle(0.25), offset=(0.0, 0.75))]))
    started = []
    for _ in range(40):
        scene.step(DT)
        started += [ev for ev in scene.events if ev.kind == "started"]
    assert started, "the head never reached the ceiling"
    first = started[0]
    assert isinstance(first, PartEvent)
    assert (first.a, first.b, first.part_a, first.part_b) == (ceiling, body, 0, 1)
    assert first.normal.y == pytest.approx(-1.0)  # from the ceiling (a) down toward the body (b)
    assert first.flipped().part_a == 1 and first.flipped().a == body
    assert scene.get(body, Velocity).y < 0.0  # it bounced off: the head's contact acted on the body


def test_events_name_the_part_of_a_compound_body_on_either_side():
    # the compound body spawned first (the smaller id): its part is part_a
    scene = Scene(gravity=(0.0, -10.0), solver="soft")
    body = scene.spawn(Transform(0.0, 2.0), Velocity(), Hitbox(Polygon.box(1, 1)),
                       Parts([Hitbox(Polygon.box(0.5, 0.5), offset=(0.0, -0.75), sensor=True)]))
    floor = scene.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static"))
    kinds = []
    for _ in range(90):
        scene.step(DT)
        kinds += [(ev.kind, ev.a, ev.b, ev.part_a, ev.part_b) for ev in scene.events if ev.kind != "ongoing"]
    # the sensor foot (part 1) touches the floor first and stays inside it: the box rests on it
    assert kinds[0] == ("started", body, floor, 1, 0)
    assert ("started", body, floor, 0, 0) in kinds
    assert scene.get(body, Transform).y == pytest.approx(0.5, abs=1e-3)


def test_a_compound_body_falls_asleep_and_wakes():
    scene, e = _scene_with_compound()
    scene.get(e, Velocity).x = 0.0
    for _ in range(240):
        scene.step(DT)
    assert scene.store.asleep[scene.store.row_of[e]]
    # a ball dropped on its head (part 1) wakes it
    ball = scene.spawn(Transform(0.0, 3.0), Velocity(0.0, -2.0), Hitbox(Circle(0.2)))
    woke, head = False, False
    for _ in range(60):
        scene.step(DT)
        woke = woke or not scene.store.asleep[scene.store.row_of[e]]
        head = head or any(ev.a == e and ev.b == ball and ev.part_a == 1 for ev in scene.events)
    assert woke and head


def test_despawning_a_compound_body_removes_all_its_shapes():
    scene = Scene(gravity=(0.0, -10.0), solver="soft")
    shelf = scene.spawn(Transform(0.0, 0.0), Hitbox(AABB(0.5, 0.5), body="static"),
                        Parts([Hitbox(AABB(4.0, 0.5), offset=(3.0, 0.0), body="static")]))
    ball = scene.spawn(Transform(3.0, 2.0), Velocity(), Hitbox(Circle(0.25)))
    for _ in range(60):
        scene.step(DT)
    assert scene.get(ball, Transform).y == pytest.approx(0.5, abs=1e-3)  # on the shelf's part 1
    assert any(isinstance(ev, PartEvent) and ev.part_a == 1 for ev in scene.events)
    parts = scene.get(shelf, Parts)
    scene.despawn(shelf)
    assert scene.store.parts == {} and parts._store is None and parts[0]._store is None
    ended = []
    for _ in range(30):
        scene.step(DT)
        ended += [ev for ev in scene.events if ev.kind == "ended"]
    assert [(ev.a, ev.b, ev.part_a) for ev in ended] == [(shelf, ball, 1)]
    assert scene.get(ball, Transform).y < 0.0  # falls where the part was


def test_parts_added_and_removed_between_steps():
    scene = Scene(gravity=(0.0, -10.0), solver="soft")
    scene.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static"))
    e = scene.spawn(Transform(0.0, 0.5), Velocity(), Hitbox(Polygon.box(1, 1)))
    for _ in range(30):
        scene.step(DT)
    scene.add_component(e, Parts([Hitbox(Polygon.box(1, 1), offset=(0.0, 1.0))]))
    assert scene.mass_data(e).mass == 2.0
    for _ in range(60):
        scene.step(DT)
    assert scene.get(e, Transform).y == pytest.approx(0.5, abs=1e-3)  # its base still rests on the floor
    scene.remove_component(e, Parts)
    assert scene.store.parts == {}
    scene.step(DT)


def test_a_snapshot_keeps_the_parts_and_continues_bit_for_bit():
    scene, e = _l_body_on_ledge(-0.2)
    for _ in range(20):
        scene.step(DT)
    snap = scene.snapshot()
    run = []
    for _ in range(60):
        scene.step(DT)
        run.append((_pose(scene), [(ev.kind, ev.a, ev.b, ev.part_a, ev.part_b) for ev in scene.events]))
    scene.restore(snap)
    assert isinstance(scene.get(e, Parts), Parts) and len(scene.get(e, Parts)) == 1
    again = []
    for _ in range(60):
        scene.step(DT)
        again.append((_pose(scene), [(ev.kind, ev.a, ev.b, ev.part_a, ev.part_b) for ev in scene.events]))
    assert again == run
    # the restored parts are bound to the restored scene: an edit is seen at the next step
    scene.get(e, Parts)[0].friction = -2.0
    with pytest.raises(InvalidValue, match="part 1"):
        scene.step(DT)


def test_the_debug_overlay_outlines_every_part_posed_by_its_body():
    from framework.render.overlay import OVERLAY_COLORS, _part_segments

    scene = Scene(solver="soft")
    e = scene.spawn(Transform(1.0, 2.0, math.pi / 2), Velocity(), Hitbox(Polygon.box(1, 1)),
                    Parts([Hitbox(Polygon.box(1.0, 0.5), offset=(2.0, 0.0)), Hitbox(AABB(1.0, 0.5), offset=(0.0, 1.0),
                                                                                  sensor=True)]))
    (ends, colors), = _part_segments(scene.store)
    assert ends.shape == (8, 4)
    # the box part turned a quarter: its centre at (1, 2) + R(90) (2, 0) = (1, 4), 0.5 wide, 1 high
    xs, ys = ends[:4, 0], ends[:4, 1]
    assert xs.min() == pytest.approx(0.75) and xs.max() == pytest.approx(1.25)
    assert ys.min() == pytest.approx(3.5) and ys.max() == pytest.approx(4.5)
    # the AABB part: its offset turns, its box does not: centre (0, 2), 1 wide, 0.5 high
    xs, ys = ends[4:, 0], ends[4:, 1]
    assert xs.min() == pytest.approx(-0.5) and xs.max() == pytest.approx(0.5)
    assert ys.min() == pytest.approx(1.75) and ys.max() == pytest.approx(2.25)
    assert [tuple(c) for c in colors] == [OVERLAY_COLORS["dynamic"]] * 4 + [OVERLAY_COLORS["sensor"]] * 4
    scene.despawn(e)
    assert _part_segments(scene.store) == []


# --- queries -----------------------------------------------------------------------------------

def _query_scene() -> tuple[Scene, int, int]:
    """A compound body at (0, 0) turned a quarter: its Hitbox a 1 x 1 box, its part a circle of
    radius 0.5 whose offset (2, 0) the turn puts at (0, 2); and a plain box at (5, 0)."""
    scene = Scene(solver="soft")
    e = scene.spawn(Transform(0.0, 0.0, math.pi / 2), Velocity(), Hitbox(Polygon.box(1, 1)),
                    Parts([Hitbox(Circle(0.5), offset=(2.0, 0.0), layer=2)]))
    plain = scene.spawn(Transform(5.0, 0.0), Hitbox(AABB(1, 1), body="static"))
    return scene, e, plain


def test_rays_and_point_queries_meet_the_parts_and_name_the_entity():
    scene, e, plain = _query_scene()
    hit = scene.raycast((-3.0, 2.0), (1.0, 0.0))  # only the part lies on this line
    assert hit is not None and hit.entity == e
    assert hit.distance == pytest.approx(2.5) and hit.point.y == pytest.approx(2.0)
    assert scene.raycast((-3.0, 2.0), (1.0, 0.0), mask=1) is None  # the part's layer is 2
    # a ray through both shapes: the entity once, where it first enters the body
    hits = scene.raycast_all((0.0, 5.0), (0.0, -1.0))
    assert [h.entity for h in hits] == [e] and hits[0].distance == pytest.approx(2.5)
    assert scene.query_point(0.0, 2.25) == [e]
    assert scene.query_point(0.0, 1.25) == []
    assert scene.query_box(-0.1, 2.3, 0.1, 2.4) == [e]
    assert scene.query_shape(Circle(0.25), (0.6, 2.0)) == [e]
    near = scene.nearest((0.0, 3.5))
    assert near is not None and near.entity == e and near.distance == pytest.approx(1.0)
    assert scene.distance(plain, e).distance == pytest.approx(4.0)  # its box is nearer than its circle (4.24)
    above = scene.spawn(Transform(0.0, 5.0), Hitbox(AABB(1, 1), body="static"))
    assert scene.distance(e, above).distance == pytest.approx(2.0)  # its circle (top at 2.5) is nearer
    cast = scene.shape_cast(Circle(0.25), (-3.0, 2.0), (3.0, 2.0))
    assert cast is not None and cast.entity == e and cast.fraction == pytest.approx(2.25 / 6)
    assert cast.normal.x == pytest.approx(-1.0)
    assert scene.shape_cast(Circle(0.25), (-3.0, 2.0), (3.0, 2.0), ignore=[e]) is None


def test_the_batch_queries_answer_the_parts_as_the_single_ones():
    scene, e, plain = _query_scene()
    pts = [(0.0, 2.25), (0.0, 1.25), (5.0, 0.0), (0.0, 0.0)]
    hits = scene.query_points(pts)
    assert [hits.of(i) for i in range(len(pts))] == [scene.query_point(*p) for p in pts]
    near = scene.nearest_many(pts)
    for i, p in enumerate(pts):
        one = scene.nearest(p)
        assert one is not None and (near.entity[i], near.distance[i]) == (one.entity, one.distance)
    rays = scene.raycast_many([(-3.0, 2.0), (-3.0, 0.0), (-3.0, 9.0)], [(1.0, 0.0)] * 3)
    assert rays.entity.tolist() == [e, e, -1]
    assert rays.distance.tolist()[:2] == [scene.raycast((-3.0, 2.0), (1.0, 0.0)).distance,  # type: ignore[union-attr]
                                          scene.raycast((-3.0, 0.0), (1.0, 0.0)).distance]  # type: ignore[union-attr]


def test_a_scene_with_characters_refuses_solid_parts_the_controller_cannot_see():
    scene = Scene(gravity=(0.0, -10.0), solver="soft")
    scene.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static"))
    player = scene.spawn(Transform(-3.0, 0.5), Velocity(), Hitbox(AABB(0.5, 1.0), body="kinematic"),
                         CharacterController())
    crate = scene.spawn(Transform(2.0, 0.5), Velocity(), Hitbox(Polygon.box(1, 1)),
                        Parts([Hitbox(Circle(0.5), offset=(0.0, 1.0), sensor=True)]))
    scene.step(DT)  # a sensor part: seen by nobody's moves, fine
    scene.add_component(crate, Parts([Hitbox(Circle(0.5), offset=(0.0, 1.0))]))
    before = _pose(scene)
    with pytest.raises(InvalidValue, match=f"entity {crate} .* with characters \\(entity {player}\\)"):
        scene.step(DT)
    assert _pose(scene) == before


def test_a_compound_body_swings_on_a_joint_about_its_pin():
    from framework import RevoluteJoint

    scene = Scene(gravity=(0.0, -10.0), solver="soft")
    # a hammer: a handle (its Hitbox) pinned at its top end, a heavy head (a part) at its bottom
    # (let go turned by 1 radian about the pin at (0, 1): its origin at (sin 1, 1 - cos 1))
    e = scene.spawn(Transform(math.sin(1.0), 1.0 - math.cos(1.0), 1.0), Velocity(), Hitbox(Polygon.box(0.2, 2.0)),
                    Parts([Hitbox(Polygon.box(1.0, 0.5), offset=(0.0, -1.0), mass=4.0)]))
    scene.spawn(RevoluteJoint(e, None, (0.0, 1.0)))
    lowest = 1.0
    for _ in range(120):
        scene.step(DT)
        t = scene.get(e, Transform)
        pin = (t.x - math.sin(t.rotation) * 1.0, t.y + math.cos(t.rotation) * 1.0)  # the body's (0, 1), in the world
        assert pin == pytest.approx((0.0, 1.0), abs=2e-3)
        lowest = min(lowest, t.rotation)
    assert lowest < -0.8  # it swung through to the other side, as a pendulum (to -1 without losses)


def test_a_file_snapshot_keeps_the_parts(tmp_path):
    from framework.snapshot_file import load_snapshot, save_snapshot

    def build() -> tuple[Scene, int]:
        return _l_body_on_ledge(-0.2)

    scene, e = build()
    for _ in range(20):
        scene.step(DT)
    _ = scene.events  # (made and kept in the frame: PartEvents in the file too)
    save_snapshot(scene, tmp_path / "l.npz")
    for _ in range(40):
        scene.step(DT)
    other, e2 = build()
    load_snapshot(other, tmp_path / "l.npz")
    assert other.store.parts[e2] is other.get(e2, Parts) and other.get(e2, Parts)[0]._store is other.store
    for _ in range(40):
        other.step(DT)
    assert _pose(other) == _pose(scene)


def test_an_event_between_parts_names_both_with_the_normal_from_a_to_b():
    # (in the solver's pair table a part's key comes after every entity's own: the pair is found
    # as (b's Hitbox, a's part) and named as events name pairs, a < b, the normal turned round)
    scene = Scene(gravity=(0.0, 0.0), solver="soft")
    left = scene.spawn(Transform(-2.0, 0.0), Velocity(2.0, 0.0), Hitbox(Polygon.box(1, 1)),
                       Parts([Hitbox(Circle(0.5), offset=(1.0, 0.0))]))
    right = scene.spawn(Transform(1.0, 0.0), Velocity(), Hitbox(Polygon.box(1, 1)))
    first = None
    for _ in range(30):
        scene.step(DT)
        first = first or next((ev for ev in scene.events if ev.kind == "started"), None)
    assert first is not None
    assert (first.a, first.b, first.part_a, first.part_b) == (left, right, 1, 0)
    assert first.normal.x == pytest.approx(1.0)  # from the left body's head toward the right box
    contacts = scene.contacts
    assert contacts.a.tolist() == [left] and contacts.b.tolist() == [right] and contacts.nx[0] > 0.0
    # and two parts: each names its own
    scene = Scene(gravity=(0.0, 0.0), solver="soft")
    a = scene.spawn(Transform(-2.0, 0.0), Velocity(2.0, 0.0), Hitbox(Polygon.box(1, 1)),
                    Parts([Hitbox(Circle(0.25), offset=(0.0, 2.0)), Hitbox(Circle(0.5), offset=(1.0, 0.0))]))
    b = scene.spawn(Transform(2.0, 0.0), Velocity(-2.0, 0.0), Hitbox(Polygon.box(1, 1)),
                    Parts([Hitbox(Circle(0.5), offset=(-1.0, 0.0))]))
    seen = set()
    for _ in range(30):
        scene.step(DT)
        seen |= {(ev.a, ev.b, ev.part_a, ev.part_b) for ev in scene.events if ev.kind == "started"}
    assert (a, b, 2, 1) in seen


def test_a_scene_without_compound_bodies_gives_the_kernel_its_rows_as_before():
    from framework.systems.soft_step import kernel_tables

    scene, e = _scene_with_compound()
    scene.remove_component(e, Parts)
    store = scene.store
    fprops, iprops, off, verts = kernel_tables(store)
    n = store.n
    assert fprops.shape[1] == iprops.shape[1] == off.shape[0] == verts.shape[0] == n
    assert iprops[10].tolist() == list(range(n)) and iprops[11].tolist() == store.entity.tolist()
    assert iprops[12].tolist() == [0] * n


def test_a_failed_step_of_a_compound_scene_is_undone_and_the_scene_goes_on_as_its_twin():
    scene, e = _l_body_on_ledge(-0.2)
    twin, _ = _l_body_on_ledge(-0.2)
    for _ in range(15):
        scene.step(DT)
        twin.step(DT)
    fail = [True]

    def once(s, dt):  # a game system that fails in the next step, after the physics moved everything
        if fail:
            fail.clear()
            s.get(e, Parts)[0].friction = 0.1  # (an edit the undone step must forget too)
            raise RuntimeError("a game system failed")

    scene.add_system(once, after="response")
    before = _pose(scene)
    with pytest.raises(RuntimeError, match="a game system failed"):
        scene.step(DT)
    assert _pose(scene) == before
    scene.get(e, Parts)[0].friction = 0.6  # (what it was: the game's edit is its own to undo)
    for _ in range(30):
        scene.step(DT)
        twin.step(DT)
        assert _pose(scene) == _pose(twin)
