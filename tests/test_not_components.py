"""Issue 34, item 2: objects that cannot be components are refused, and the scene is left unchanged.

A component is an instance of a class the game (or the framework) defines: plain classes, tag
classes, dataclasses, namedtuples, subclasses of built-in types. Refused by ``spawn`` and
``add_component`` (an :class:`InvalidValue` naming the value and the fix): None, classes, tuples
and lists (``spawn(*components)``), shapes (``Hitbox(shape)``), a Body kind, a Frame or Animation,
functions, and the values of built-in and library types (str, int, float, bool, bytes, dict, set,
numpy scalars and arrays, ...). ``on_collision`` refuses the classes of those values and shape
classes. A Hitbox outside a scene refuses a density written over a mass (and the reverse), as the
scene's step does.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import math
import re
from collections import OrderedDict, deque, namedtuple
from fractions import Fraction

import esper
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from framework import AABB, Body, Capsule, Circle, Hitbox, InvalidValue, Polygon, Scene, Transform, Velocity
from framework.components import Visual
from framework.sprites import Animation, Frame

DT = 1.0 / 60.0


# --- a game's own components -------------------------------------------------------------------------


class Player:
    """A tag class."""


class Health:
    def __init__(self, points: int = 3) -> None:
        self.points = points


@dataclasses.dataclass
class Score:
    value: int = 0


@dataclasses.dataclass(frozen=True)
class Team:
    name: str = "red"


class Slotted:
    __slots__ = ("n",)

    def __init__(self, n: int = 0) -> None:
        self.n = n


class Name(str):
    """A game's own subclass of a built-in type: its class, so a component."""


class Inventory(list):
    pass


class Callback:
    """A game's own callable object: still a component."""

    def __call__(self) -> None:
        pass


Cell = namedtuple("Cell", "col row")

USER_COMPONENTS = [Player, Health, Score, Team, Slotted, Name, Inventory, Callback, Cell]


def make_user(cls: type) -> object:
    return cls(1, 2) if cls is Cell else cls("x") if cls is Name else cls()


# --- the scene, and what "unchanged" means --------------------------------------------------------------


def build() -> tuple[Scene, dict[str, int]]:
    s = Scene(gravity=(0.0, -10.0))
    names = {
        "floor": s.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static")),
        "ball": s.spawn(Transform(0.0, 0.6), Velocity(1.0, 0.0), Hitbox(Circle(0.5)), Player()),
        "box": s.spawn(Transform(2.0, 0.5), Velocity(), Hitbox(AABB(1.0, 1.0), mass=2.0)),
        "plain": s.spawn(Transform(-3.0, 4.0)),
    }
    for _ in range(3):
        s.step(DT)
    return s, names


@pytest.fixture
def scene():
    s, names = build()
    yield s, names
    s.close()


def fingerprint(scene: Scene, addresses: bool = True) -> str:
    """The entities and each one's components (by repr), the store's columns and rows, the events,
    frame, time and the next entity id esper will give out. ``addresses=False``: without the
    object addresses of plain classes' reprs (to compare two scenes)."""
    h = hashlib.sha256()
    store = scene.store
    for name, col in sorted(store.cols.items()):
        h.update(name.encode())
        h.update(col[: store.n].tobytes())
    h.update(repr(sorted(store.row_of.items())).encode())
    h.update(repr([repr(hb) for hb in store.hitboxes]).encode())
    for e in scene.entities:  # (switches esper to the scene's world)
        shown = [repr(c) if addresses else re.sub(r" at 0x[0-9a-f]+", "", repr(c))
                 for c in esper.components_for_entity(e)]
        h.update(repr((e, sorted(shown))).encode())
    h.update(repr(esper._entity_count).encode())  # a refused spawn takes no id
    h.update(repr(([(ev.kind, ev.a, ev.b) for ev in scene.events], scene.frame, scene.time)).encode())
    h.update(repr(sorted(store.dirty_hitboxes)).encode())
    return h.hexdigest()


def refused(scene: Scene, call, *shown: str) -> str:
    """``call`` raises InvalidValue whose message holds each of ``shown``; the scene is unchanged."""
    entities, before = scene.entities, fingerprint(scene)
    with pytest.raises(InvalidValue) as info:
        call()
    message = str(info.value)
    for part in shown:
        assert part in message, f"{part!r} not in {message!r}"
    assert scene.entities == entities
    assert fingerprint(scene) == before, f"the refused call changed the scene: {message}"
    return message


def steps_as_a_twin_does(scene: Scene) -> None:
    """After the refusals the scene steps exactly as one that never saw them."""
    twin, _ = build()
    try:
        scene.step(DT)
        twin.step(DT)
        assert fingerprint(scene, addresses=False) == fingerprint(twin, addresses=False)
    finally:
        twin.close()


# --- spawn -------------------------------------------------------------------------------------------------


SPAWN_CASES = {
    "str": (lambda: (Transform(), "hello"), ["'hello'", "a str is not a component", "a class of your own"]),
    "int": (lambda: (Transform(), 5), ["got 5, an int", "an int is not a component", "a class of your own"]),
    "float": (lambda: (Transform(), 2.5), ["got 2.5, a float", "a class of your own"]),
    "bool": (lambda: (Transform(), True), ["got True, a bool", "a class of your own"]),
    "bytes": (lambda: (Transform(), b"tag"), ["got b'tag', a bytes", "a class of your own"]),
    "dict": (lambda: (Transform(), {"hp": 3}), ["got {'hp': 3}, a dict", "a class of your own"]),
    "None": (lambda: (Transform(), None), ["got None", "leave it out"]),
    "tuple": (lambda: ((Transform(), Velocity()),),
              ["not a tuple", "(Transform(x=0.0, y=0.0, rotation=0.0), Velocity(x=0.0, y=0.0, angular=0.0))",
               "spawn(*components)"]),
    "list": (lambda: ([Transform()],), ["not a list", "[Transform(x=0.0, y=0.0, rotation=0.0)]", "spawn(*components)"]),
    "tuple after a transform": (lambda: (Transform(), (Velocity(), Hitbox(Circle(1.0)))),
                                ["not a tuple", "spawn(*components)"]),
    "circle": (lambda: (Transform(), Circle(1)),
               ["got a Circle", "wrap a shape in a Hitbox", "e.g. Hitbox(Circle(radius=1.0))"]),
    "aabb": (lambda: (Transform(), AABB(1.0, 2.0)), ["got an AABB", "Hitbox(AABB(width=1.0, height=2.0))"]),
    "polygon": (lambda: (Transform(), Polygon.box(1.0, 1.0)), ["got a Polygon", "wrap a shape in a Hitbox"]),
    "capsule": (lambda: (Transform(), Capsule(0.5, 1.0)), ["got a Capsule", "wrap a shape in a Hitbox"]),
    "class": (lambda: (Transform(), Player), ["the class Player", "Player()"]),
    "body kind": (lambda: (Transform(), Body.STATIC), ["Body.STATIC", "Hitbox(shape, body=Body.STATIC)"]),
    "function": (lambda: (Transform(), print), ["the function <built-in function print>", "add_system"]),
    "lambda": (lambda: (Transform(), lambda scene, dt: None), ["the function <function", "add_system"]),
    "partial": (lambda: (Transform(), functools.partial(print, 1)), ["functools.partial", "not a component"]),
    "numpy float": (lambda: (Transform(), np.float64(1.5)), ["1.5", "a float64 is not a component"]),
    "numpy array": (lambda: (Transform(), np.zeros(2)), ["array([0., 0.])", "ndarray is not a component"]),
    "fraction": (lambda: (Transform(), Fraction(1, 3)), ["Fraction(1, 3)", "a Fraction is not a component"]),
    "deque": (lambda: (Transform(), deque([1])), ["deque([1])", "a deque is not a component"]),
    "set": (lambda: (Transform(), {1, 2}), ["{1, 2}", "a set is not a component"]),
    "object()": (lambda: (Transform(), object()), ["<object object", "an object is not a component"]),
    "frame": (lambda: (Transform(), Frame("x.png", 0, 0, 8, 8)), ["got a Frame", "Visual(frame=...)"]),
    "first of several": (lambda: ("hello", Transform(), Velocity()), ["'hello'", "a str is not a component"]),
}


@pytest.mark.parametrize("case", sorted(SPAWN_CASES))
def test_spawn_refuses_what_cannot_be_a_component_and_changes_nothing(scene, case):
    s, _ = scene
    make, shown = SPAWN_CASES[case]
    comps = make()
    message = refused(s, lambda: s.spawn(*comps), *shown)
    assert message.startswith("spawn")
    steps_as_a_twin_does(s)


def test_a_refused_spawn_leaves_its_components_free_to_use(scene):
    # Nothing was bound: the Transform and Hitbox passed alongside the mistake spawn later.
    s, _ = scene
    t, hb = Transform(5.0, 5.0), Hitbox(AABB(1.0, 1.0))
    refused(s, lambda: s.spawn(t, hb, "enemy"), "'enemy'")
    e = s.spawn(t, hb)
    assert s.get(e, Transform) is t and s.get(e, Hitbox) is hb


def test_spawn_of_a_tuple_used_to_make_an_entity_with_no_physics(scene):
    # Before: spawn((Transform(), Velocity())) made an entity holding one tuple; it never moved.
    s, _ = scene
    refused(s, lambda: s.spawn((Transform(0.0, 9.0), Velocity(1.0, 0.0))), "spawn(*components)")
    e = s.spawn(*(Transform(0.0, 9.0), Velocity(1.0, 0.0)))
    s.step(DT)
    assert s.get(e, Transform).x > 0.0


def test_frame_and_animation_are_refused_with_visual_as_the_fix(scene):
    s, _ = scene
    frame = Frame("x.png", 0, 0, 8, 8)
    anim = Animation([frame], 0.1)
    refused(s, lambda: s.spawn(Transform(), anim), "got an Animation", "Visual(animation=...)")


# --- add_component ----------------------------------------------------------------------------------------


ADD_CASES = {
    "str": (lambda: "tag", ["add_component got 'tag', a str", "a str is not a component", "a class of your own"]),
    "int": (lambda: 7, ["got 7, an int", "a class of your own"]),
    "None": (lambda: None, ["got None", "leave it out"]),
    "tuple": (lambda: (Velocity(),), ["not a tuple", "(Velocity(x=0.0, y=0.0, angular=0.0),)", "one at a time"]),
    "list": (lambda: [Player()], ["not a list", "one at a time"]),
    "circle": (lambda: Circle(2.0), ["got a Circle", "Hitbox(Circle(radius=2.0))"]),
    "class": (lambda: Velocity, ["the class Velocity", "Velocity()"]),
    "dict": (lambda: {}, ["got {}, a dict"]),
    "function": (lambda: len, ["the function <built-in function len>"]),
    "body kind": (lambda: Body.KINEMATIC, ["Body.KINEMATIC", "Hitbox(shape, body=Body.KINEMATIC)"]),
}


@pytest.mark.parametrize("case", sorted(ADD_CASES))
@pytest.mark.parametrize("who", ["ball", "plain"])
def test_add_component_refuses_what_cannot_be_a_component_and_changes_nothing(scene, case, who):
    s, names = scene
    make, shown = ADD_CASES[case]
    value = make()
    message = refused(s, lambda: s.add_component(names[who], value), *shown)
    assert message.startswith("add_component")
    steps_as_a_twin_does(s)


# --- what stays accepted ------------------------------------------------------------------------------------


@pytest.mark.parametrize("cls", USER_COMPONENTS, ids=lambda c: c.__name__)
def test_a_games_own_classes_are_components(scene, cls):
    s, names = scene
    held = [ent for ent, _ in s.query(cls)]  # (the ball is a Player)
    comp, other = make_user(cls), make_user(cls)
    e = s.spawn(Transform(1.0, 8.0), Velocity(), Hitbox(Circle(0.25)), comp)
    assert s.get(e, cls) is comp
    s.add_component(names["plain"], other)
    assert s.get(names["plain"], cls) is other
    assert [ent for ent, _ in s.query(cls)] == sorted({*held, e, names["plain"]})
    s.step(DT)
    s.remove_component(e, cls)
    assert [ent for ent, _ in s.query(cls)] == sorted({*held, names["plain"]})


def test_framework_components_are_still_components(scene):
    s, names = scene
    e = s.spawn(Transform(), Velocity(), Hitbox(Circle(1.0)), Visual())
    s.add_component(names["plain"], Visual(color=(1, 2, 3)))
    assert s.exists(e)


# --- on_collision ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("args, shown", [
    (("Transform", Hitbox), "got 'Transform' as type_a: pass the class itself (Transform), not its name"),
    ((Hitbox, "Player"), "got 'Player' as type_b"),
    ((Circle, Hitbox), "the shape class Circle as type_a"),
    ((Player, AABB), "the shape class AABB as type_b"),
    ((str, Hitbox), "the class str as type_a: str is not a component class"),
    ((Player, tuple), "the class tuple as type_b"),
    ((int, Player), "the class int as type_a"),
], ids=["name a", "name b", "circle", "aabb", "str", "tuple", "int"])
def test_on_collision_refuses_classes_that_no_entity_can_hold(scene, args, shown):
    s, _ = scene
    before = list(s.handlers._handlers)
    message = refused(s, lambda: s.on_collision(*args, lambda ev: None), shown)
    assert message.startswith("on_collision")
    assert s.handlers._handlers == before


def test_on_collision_takes_a_games_own_classes():
    with Scene(gravity=(0.0, 0.0)) as s:
        seen = []
        s.on_collision(Player, Name, lambda ev: seen.append((ev.a, ev.b)))
        a = s.spawn(Transform(0.0, 0.0), Hitbox(Circle(1.0)), Player())
        b = s.spawn(Transform(1.0, 0.0), Hitbox(Circle(1.0)), Name("wall"))
        s.step(DT)
        assert seen == [(a, b)]


# --- a hitbox outside a scene: mass and density ------------------------------------------------------------


def test_density_written_over_a_mass_outside_a_scene_is_refused_and_changes_nothing():
    # Before: accepted, and the mass silently became density x area (2.0 -> 1.0).
    hb = Hitbox(AABB(1.0, 1.0), mass=2.0)
    with pytest.raises(InvalidValue, match=re.escape("Hitbox mass and density are both given (2.0 and 1.0)")) as info:
        hb.density = 1.0
    assert "set its mass back to 1.0 first" in str(info.value)
    assert hb.mass == 2.0 and hb.density is None
    hb.mass = 1.0  # the way from a mass to a density
    hb.density = 3.0
    assert hb.mass == 3.0 and hb.density == 3.0


def test_a_mass_written_over_a_density_outside_a_scene_is_refused_and_changes_nothing():
    hb = Hitbox(AABB(2.0, 1.0), density=2.0)
    with pytest.raises(InvalidValue, match=re.escape("Hitbox mass and density are both given (3.0 and 2.0)")) as info:
        hb.mass = 3.0
    assert "set its density to None first" in str(info.value)
    assert hb.mass == 4.0 and hb.density == 2.0
    hb.mass = 1.0  # the default: allowed alongside a density
    assert hb.mass == 4.0
    hb.density = None
    hb.mass = 3.0
    assert hb.mass == 3.0 and hb.density is None


def test_inside_a_scene_the_step_still_refuses_them_naming_the_entity():
    with Scene(gravity=(0.0, 0.0)) as s:
        hb = Hitbox(AABB(1.0, 1.0), mass=2.0)
        e = s.spawn(Transform(), Velocity(), hb)
        hb.density = 1.0  # kept as written while in the scene...
        with pytest.raises(InvalidValue, match=f"entity {e}: Hitbox mass and density"):
            s.step(DT)  # ...and refused by the next step
        hb.density = None
        s.step(DT)


# --- any built-in value (hypothesis) -------------------------------------------------------------------------


SCALARS = st.one_of(
    st.none(), st.from_type(int), st.from_type(float), st.from_type(str), st.from_type(bytes), st.from_type(bool),
    st.from_type(complex), st.from_type(bytearray), st.from_type(Fraction),
)
BUILTIN_VALUES = st.one_of(
    SCALARS,
    st.tuples(SCALARS, SCALARS),
    st.lists(SCALARS, max_size=4),
    st.dictionaries(st.text(max_size=4), SCALARS, max_size=3),
    st.sets(st.integers(), max_size=3),
    st.frozensets(st.integers(), max_size=3),
    st.lists(st.builds(Transform, st.floats(-5, 5), st.floats(-5, 5)), min_size=1, max_size=3),
    st.tuples(st.builds(Transform), st.builds(Velocity)),
    st.builds(OrderedDict, st.dictionaries(st.integers(), st.integers(), max_size=2)),
    st.sampled_from([math.pi, math.inf, math.nan, print, len, Transform, int, object]),
)

FIXES = ("a class of your own", "spawn(*components)", "one at a time", "leave it out", "pass an instance",
         "add_system")
_SETTINGS = settings(max_examples=120, deadline=None, derandomize=True,
                     suppress_health_check=[HealthCheck.too_slow])


@pytest.mark.slow
@_SETTINGS
@given(value=BUILTIN_VALUES, first=st.booleans())
def test_any_builtin_value_is_refused_by_spawn_and_add_component_and_changes_nothing(value, first):
    s, names = build()
    try:
        comps = (value, Transform(), Velocity()) if first else (Transform(), Velocity(), value)
        shown = value.__name__ if isinstance(value, type) else repr(value)[:60]
        for message in (refused(s, lambda: s.spawn(*comps), "spawn"),
                        refused(s, lambda: s.add_component(names["ball"], value), "add_component")):
            assert shown in message  # the bad value
            assert any(fix in message for fix in FIXES), message  # and what to do instead
        steps_as_a_twin_does(s)
    finally:
        s.close()


@pytest.mark.slow
@_SETTINGS
@given(cls=st.sampled_from(USER_COMPONENTS), x=st.floats(-5, 5), first=st.booleans())
def test_any_instance_of_a_games_own_class_is_accepted(cls, x, first):
    s, names = build()
    try:
        comp, other = make_user(cls), make_user(cls)
        comps = (comp, Transform(x, 6.0)) if first else (Transform(x, 6.0), comp)
        e = s.spawn(*comps)
        s.add_component(names["ball"], other)
        assert s.get(e, cls) is comp and s.get(names["ball"], cls) is other
        s.step(DT)
    finally:
        s.close()
