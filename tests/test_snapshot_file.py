"""Snapshot files without pickle: bit-identical restores, and files that cannot be restored
(another version, another scene, a class not allowed, damaged) refused with the scene unchanged."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_snapshot import Tag, build, run, state_hash  # noqa: I001  (tests/ is on sys.path)

from framework import InvalidValue, Transform
from framework.snapshot_file import load_snapshot, save_snapshot


def test_a_saved_file_restores_bit_identically_into_a_scene_built_the_same_way(tmp_path):
    s = build(11)
    run(s, 25)
    path = tmp_path / "save.npz"
    assert save_snapshot(s, path) == ()
    first = run(s, 90)
    other = build(12, bodies=2)
    load_snapshot(other, path)
    assert run(other, 90) == first


@pytest.mark.slow
@settings(max_examples=10, deadline=None)
@given(st.integers(0, 10_000), st.integers(0, 40))
def test_random_scenes_round_trip_through_files(tmp_path_factory, seed, before):
    path = tmp_path_factory.mktemp("snap") / "s.npz"
    s = build(seed, bodies=8)
    run(s, before)
    save_snapshot(s, path)
    first = run(s, 30)
    other = build(seed + 7, bodies=3)
    load_snapshot(other, path)
    assert run(other, 30) == first


@pytest.mark.slow
def test_the_platformer_saves_and_loads(tmp_path):
    from examples.platformer import Game
    from examples.platformer.components import GameState

    g = Game()
    for k in range(200):
        g.step({"right"} if k % 50 < 40 else {"space", "right"})
    path = tmp_path / "game.npz"
    skipped = save_snapshot(g.scene, path)
    assert skipped == ("examples.platformer.game.Game",)  # it holds the levels: classes not allowed in a file

    def play(game):
        out = []
        for k in range(150):
            game.step({"left"} if k % 40 < 20 else {"space"})
            out.append(state_hash(game.scene))
        return out

    first = play(g)
    fresh = Game()
    load_snapshot(fresh.scene, path)
    assert fresh.scene.resources[GameState] is fresh.state
    assert play(fresh) == first
    g.close()
    fresh.close()


def _meta(path):
    with np.load(path, allow_pickle=False) as npz:
        return {k: npz[k] for k in npz.files}


def _rewrite(path, arrays):
    with open(path, "wb") as f:
        np.savez(f, **arrays)


def _edit_meta(path, change):
    arrays = _meta(path)
    meta = json.loads(arrays["__meta__"].tobytes())
    change(meta)
    arrays["__meta__"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    _rewrite(path, arrays)


@pytest.fixture
def saved(tmp_path):
    s = build(13)
    run(s, 10)
    path = tmp_path / "s.npz"
    save_snapshot(s, path)
    target = build(14, bodies=4)
    run(target, 5)
    return path, target, state_hash(target)


def _refused(path, target, before, match):
    with pytest.raises(InvalidValue, match=match):
        load_snapshot(target, path)
    assert state_hash(target) == before


def test_another_version_or_scene_is_refused(saved):
    path, target, before = saved
    _edit_meta(path, lambda m: m.__setitem__("framework", "0.0.1"))
    _refused(path, target, before, "another version")
    _edit_meta(path, lambda m: (m.__setitem__("framework", __import__("framework").__version__),
                                m.__setitem__("version", 99)))
    _refused(path, target, before, "another version")
    _edit_meta(path, lambda m: (m.__setitem__("version", 1), m["shape"][0].pop()))
    _refused(path, target, before, "another shape")


def test_a_class_that_is_not_allowed_is_refused_and_nothing_runs(saved, tmp_path):
    path, target, before = saved
    marker = tmp_path / "ran"

    def plant(meta):
        meta["state"] = {"O": [0, "os:system", [["x", f"touch {marker}"]]]}

    _edit_meta(path, plant)
    _refused(path, target, before, "class 'os:system' is not allowed")
    _edit_meta(path, lambda m: m.__setitem__("state", {"C": "builtins:eval"}))
    _refused(path, target, before, "is not allowed")
    assert not marker.exists()


def test_damaged_files_are_refused(saved, tmp_path):
    path, target, before = saved
    data = path.read_bytes()
    for i, damaged in enumerate([data[: len(data) // 2], b"not a zip at all", b"", data[:100] + b"\x00" * 64]):
        bad = tmp_path / f"bad{i}.npz"
        bad.write_bytes(damaged)
        _refused(bad, target, before, "not a snapshot file")
    pickled = tmp_path / "pickled.npz"
    with open(pickled, "wb") as f:
        np.savez(f, __meta__=np.array([{"format": "framework-snapshot"}], dtype=object))
    _refused(pickled, target, before, "not a snapshot file")  # an object array: allow_pickle=False refuses it
    _edit_meta(path, lambda m: m.__setitem__("state", {"L": [0, [{"R": 5}]]}))
    _refused(path, target, before, "not a snapshot file this scene can take")
    _edit_meta(path, lambda m: m.__setitem__("state", {"Q": 1}))
    _refused(path, target, before, "unknown tag")


def test_a_file_over_the_size_limit_is_refused_before_inflating(saved, tmp_path):
    path, target, before = saved
    bomb = tmp_path / "bomb.npz"
    with zipfile.ZipFile(bomb, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("__meta__.npy", b"\x00" * (64 * 1024 * 1024))  # 64 MiB of zeros: a few KB compressed
    assert bomb.stat().st_size < 1024 * 1024
    with pytest.raises(InvalidValue, match="more than the limit"):
        load_snapshot(target, bomb, max_bytes=16 * 1024 * 1024)
    assert state_hash(target) == before


def test_an_unsaveable_component_is_named(tmp_path):
    class Local:  # a class the scene does not have as a component: not allowed in a file
        pass

    s = build(15, bodies=2)
    e = s.spawn(Transform(0.0, 0.0), Tag(0))
    s.get(e, Tag).n = Local()
    with pytest.raises(InvalidValue, match=rf"entity {e}: its Tag component cannot be saved in a snapshot file"):
        save_snapshot(s, tmp_path / "x.npz")
    save_snapshot(s, tmp_path / "x.npz", allow=[Local])  # allowed on purpose


# --- issue 25's audit: loading runs nothing, and a bad file changes nothing ---------------------------------


def _part(meta, key):
    """The node of the state's part ``key`` (the state is a dict node of [key, node] pairs)."""
    for k, node in meta["state"]["D"][1]:
        if k == key:
            return node
    raise KeyError(key)


def _objects(node, cls):
    """Every ``O`` node of class ``cls`` in ``node``."""
    if isinstance(node, dict):
        if "O" in node and node["O"][1] == cls:
            yield node["O"]
        for v in node.values():
            yield from _objects(v, cls)
    elif isinstance(node, list):
        for v in node:
            yield from _objects(v, cls)


def _field(obj_node, name):
    """The [name, node] pair of an ``O`` node's attribute ``name``."""
    return next(pair for pair in obj_node[2] if pair[0] == name)


NEW = 10**9  # an object number no saved file uses


def test_the_popen_chain_of_the_audit_runs_nothing(saved, tmp_path):
    """The audit's file: a class name walking through imported modules (framework.frame's numpy,
    numpy's f2py, its subprocess) to Popen, called by the enum tag. It ran ``touch`` before."""
    path, target, before = saved
    marker = tmp_path / "marker"
    popen = "framework.frame:np.f2py.subprocess.Popen"
    _edit_meta(path, lambda m: m.__setitem__("state", {"E": [popen, {"L": [0, ["touch", str(marker)]]}]}))
    with pytest.raises(InvalidValue, match=r"class 'framework\.frame:np\.f2py\.subprocess\.Popen' is not allowed"):
        load_snapshot(target, path)
    assert not marker.exists()
    assert state_hash(target) == before


@pytest.mark.parametrize("name", [
    "framework.frame:np.f2py.subprocess.Popen",  # through modules
    "framework.frame:np",                        # a module, not a class
    "framework.snapshot:pickle.Unpickler",
    "framework.snapshot_file:InvalidValue",      # imported there, defined elsewhere: not its own name
    "framework:Transform",                       # re-exported by the package: not its own name
    "framework.components:Transform._get",       # a function
    "framework.components:Transform.__class__",  # the metaclass, through an attribute
    "framework.components:Body.DYNAMIC",         # an enum member, not a class
    "builtins:eval", "builtins:object", "os:system", "subprocess:Popen", "numpy:load", "numpy:ndarray",
    "numpy:frombuffer", "numpy.lib.format:read_array", "framework.nonexistent:X", "framework.components:<lambda>",
])
@pytest.mark.parametrize("tag", ["C", "O", "E", "NT"])
def test_names_that_are_not_a_framework_class_resolve_to_nothing(saved, tmp_path, name, tag):
    path, target, before = saved
    marker = tmp_path / "marker"
    arg = {"L": [NEW + 1, ["touch", str(marker)]]}
    node = {"C": name, "O": [NEW, name, [["args", arg]]], "E": [name, arg], "NT": [name, [arg]]}[tag]
    _edit_meta(path, lambda m: m.__setitem__("state", {tag: node}))
    with pytest.raises(InvalidValue, match=rf"class {name!r:.60} is not allowed"):
        load_snapshot(target, path)
    assert not marker.exists()
    assert state_hash(target) == before


@pytest.mark.parametrize("node, match", [
    ({"E": ["framework.components:Transform", 1]}, "is not an enum"),                 # no constructor call
    ({"E": ["framework.store:BodyStore", 64]}, "is not an enum"),
    ({"E": ["framework.components:Body", "no such value"]}, "Body has no member of value"),
    ({"E": ["framework.components:Body", {"L": [NEW, []]}]}, "an enum value of class list"),
    ({"NT": ["framework.components:Transform", [1, 2, 3]]}, "is not a named tuple"),
    ({"NT": ["framework.events:StepContacts", [1]]}, "a StepContacts of 1 values"),
    ({"O": [NEW, "framework.components:Body", []]}, "has its own __new__"),            # an enum
    ({"O": [NEW, "framework.validation:InvalidValue", []]}, "has its own __new__"),    # built on a builtin
    ({"O": [NEW, "framework.events:StepContacts", []]}, "has its own __new__"),       # a named tuple
    ({"O": [NEW, "framework.scene:Scene", [["world", "default"], ["closed", False]]]}, "has a __del__"),
    ({"O": [NEW, "framework.components:Transform", [["x", {"F": "0x1p+0"}]]]}, "Transform.x is not a plain attr"),
    ({"O": [NEW, "framework.components:Transform", [["__class__", {"C": "framework.scene:Scene"}]]]},
     "attribute name '__class__'"),
    ({"O": [NEW, "framework.components:Transform", [["__dict__", {"D": [NEW + 1, []]}]]]}, "attribute name"),
    ({"O": [NEW, "framework.components:Transform", [["nope", 1]]]}, "has no attribute 'nope'"),  # slots only
    ({"DT": "O"}, "dtype 'O' is not one"),
    ({"DT": "|O"}, "is not one"),
    ({"A": "0"}, "array '0' is missing"),
    ({"I": 5}, "not text"),
    ({"S": [NEW, [{"O": [NEW + 1, "framework.shapes:Circle", [["radius", {"F": "0x1p+0"}]]]}]]},
     "a set member of class Circle"),  # its hash would be the dataclass's, on what the file holds
    ({"D": [NEW, [[{"L": [NEW + 1, []]}, 1]]]}, "a dict key of class list"),
])
def test_every_tag_makes_only_what_it_may(saved, node, match):
    path, target, before = saved
    _edit_meta(path, lambda m: m.__setitem__("state", node))
    _refused(path, target, before, match)


def test_a_scene_objects_del_never_runs_on_what_a_file_holds(saved):
    """framework.scene.Scene's __del__ deletes the esper world its ``world`` names: made from a
    file and dropped, it would delete a world of the file's choosing."""
    import esper

    path, target, before = saved
    world = target.world
    node = {"O": [NEW, "framework.scene:Scene", [["world", world], ["closed", False]]]}
    _edit_meta(path, lambda m: m.__setitem__("state", {"L": [NEW + 1, [node]]}))
    _refused(path, target, before, "has a __del__")
    import gc

    gc.collect()
    assert world in esper.list_worlds()


def test_colliding_set_members_are_refused_at_once(saved):
    """Integers equal modulo the hash modulus all hash alike: 40,000 of them took 66 s to put in a
    set. At most MAX_SHARED_HASH members of one set (or keys of one dict) may share a hash."""
    import sys
    import time

    path, target, before = saved
    p = sys.hash_info.modulus
    members = [{"I": str(k * p)} for k in range(1, 40_001)]
    _edit_meta(path, lambda m: m.__setitem__("state", {"S": [NEW, members]}))
    t0 = time.perf_counter()
    _refused(path, target, before, "share a hash")
    assert time.perf_counter() - t0 < 5.0
    pairs = [[{"I": str(k * p)}, 0] for k in range(1, 40)]  # and as dict keys
    _edit_meta(path, lambda m: m.__setitem__("state", {"D": [NEW, pairs]}))
    _refused(path, target, before, "share a hash")


class Spy:
    """A component whose __setattr__ and property setter record that they ran."""

    calls: list[str] = []

    def __init__(self, n: int) -> None:
        object.__setattr__(self, "n", n)

    def __setattr__(self, name, value):
        Spy.calls.append(f"setattr {name}")
        object.__setattr__(self, name, value)

    @property
    def loud(self):
        return self.n

    @loud.setter
    def loud(self, value):
        Spy.calls.append("property")


def test_attributes_are_written_without_setattr_or_setters(tmp_path):
    s = build(16, bodies=2)
    e = s.spawn(Transform(0.0, 0.0), Spy(7))
    path = tmp_path / "spy.npz"
    save_snapshot(s, path)
    other = build(16, bodies=2)
    other.spawn(Transform(0.0, 0.0), Spy(0))
    Spy.calls.clear()
    load_snapshot(other, path)
    assert other.get(e, Spy).n == 7 and Spy.calls == []

    def loud(meta):
        spy = next(_objects(meta["state"], f"{Spy.__module__}:Spy"))
        spy[2].append(["loud", 1])

    _edit_meta(path, loud)
    before = state_hash(other)
    _refused(path, other, before, "Spy.loud is not a plain attribute")
    assert Spy.calls == []


def test_a_npy_member_declaring_more_than_it_holds_is_refused_before_allocating(saved, tmp_path):
    import io

    path, target, before = saved
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": (2**33,)})
    arrays = _meta(path)
    bomb = tmp_path / "claims.npz"
    with zipfile.ZipFile(bomb, "w") as zf:
        for k, a in arrays.items():
            buf = io.BytesIO()
            np.lib.format.write_array(buf, a)
            zf.writestr(f"{k}.npy", buf.getvalue())
        zf.writestr(f"a{len(arrays)}.npy", header.getvalue() + b"\x00" * 64)
    _refused(bomb, target, before, r"declares 68719476736 bytes of data, the member holds")


def test_zips_numpy_never_writes_are_refused(saved, tmp_path):
    path, target, before = saved
    data = path.read_bytes()
    commented = tmp_path / "comment.npz"
    with zipfile.ZipFile(commented, "w") as zf:
        with zipfile.ZipFile(path) as src:
            for m in src.infolist():
                zf.writestr(m.filename, src.read(m))
        zf.comment = b"hello"
    _refused(commented, target, before, "no zip end record")
    many = bytearray(data)
    many[-12:-10] = (65_535).to_bytes(2, "little")  # more entries than the directory's bytes can hold
    many[-10:-6] = (200 * 65_535).to_bytes(4, "little")
    (tmp_path / "many.npz").write_bytes(bytes(many))
    _refused(tmp_path / "many.npz", target, before, "a zip directory of")
    extra = tmp_path / "extra.npz"
    arrays = _meta(path)
    arrays["payload"] = np.zeros(3)
    _rewrite(extra, arrays)
    _refused(extra, target, before, "unexpected members")


@pytest.fixture
def pair(tmp_path):
    """A saved scene with its future, and a target scene with a twin to compare with."""
    s = build(17)
    run(s, 12)
    path = tmp_path / "s.npz"
    save_snapshot(s, path)
    future = run(s, 40)
    target, twin = build(18, bodies=5), build(18, bodies=5)
    run(target, 7)
    run(twin, 7)
    return path, future, target, twin


def _set(meta, part, key, node):
    """Set the field ``key`` of the state's part ``part`` to ``node``."""
    next(pair for pair in _part(meta, part)["D"][1] if pair[0] == key)[1] = node


def test_a_private_cache_may_be_none_either_way(pair):
    """A fresh scene holds None in some caches (named with _) that a stepped one has filled: a
    file of either loads into the other."""
    path, future, target, _twin = pair
    _edit_meta(path, lambda m: (_set(m, "bodies", "_geometry_stamp", None), _set(m, "scene", "_totals", None)))
    load_snapshot(target, path)
    assert run(target, 40) == future


def _positions(scene):
    return {e: (t.x, t.y) for e, t in scene.query(Transform)}


@pytest.mark.parametrize("change, match", [
    (lambda m: _part(m, "stages")["D"][1].append(["bogus", {"D": [NEW, []]}]), "unknown 'bogus'"),
    (lambda m: _part(m, "stages")["D"][1].pop(), "missing render"),
    (lambda m: _part(m, "scene")["D"][1].append(["closed", True]), "the scene part: unknown 'closed'"),
    (lambda m: _part(m, "scene")["D"][1].append(["_pipeline", None]), "unknown '_pipeline'"),
    (lambda m: _part(m, "scene")["D"][1].__setitem__(0, ["frame", "twelve"]),
     "frame is of type str, where this scene's is of type int"),
    (lambda m: _part(m, "scene")["D"][1].__setitem__(1, ["time", {"F": "inf"}]), "time inf are not a step's"),
    (lambda m: _part(m, "scene")["D"][1].__setitem__(0, ["frame", 13]), "frame 13 .* not a step's"),
    (lambda m: _part(m, "bodies")["D"][1].pop(), "the bodies part: missing"),
    (lambda m: _part(m, "bodies")["D"][1].append(["renderer", None]), "the bodies part: unknown 'renderer'"),
    (lambda m: _part(m, "pipeline")["D"][1].append(["renderer", None]), "the pipeline part: unknown 'renderer'"),
    (lambda m: _part(m, "pipeline")["D"][1].__setitem__(2, ["response_iterations", {"F": "0x1p+0"}]),
     "response_iterations is of type float, where this scene's is of type int"),
    (lambda m: _set(m, "bodies", "store", None), "store is of type NoneType, where this scene's is of type BodyStore"),
    (lambda m: _set(m, "pipeline", "frame", None), "frame is of type NoneType, where this scene's is of type StepFr"),
    (lambda m: _set(m, "bodies", "n_static", None), "n_static is of type NoneType"),
    (lambda m: _part(m, "pending")["L"][1].append(99_999), "pending despawn entity 99999"),
    (lambda m: m["state"]["D"][1].append(["extra", 1]), "the state: unknown 'extra'"),
    (lambda m: m.__setitem__("resources", []), "the resources' states are not"),
    (lambda m: m["resource_headers"][0].__setitem__(1, {"C": "framework.store:BodyStore"}), "its header is not"),
    (lambda m: m.__setitem__("comment", "hi"), "description's parts are"),
])
def test_a_bad_file_changes_nothing_and_the_scene_steps_on(pair, change, match):
    """Checked before anything is applied: a file with an unknown stage raised KeyError 'bogus'
    with the entities already replaced."""
    path, _future, target, twin = pair
    before, where = state_hash(target), _positions(target)
    _edit_meta(path, change)
    with pytest.raises(InvalidValue, match=match) as info:
        load_snapshot(target, path)
    assert str(path) in str(info.value)
    assert state_hash(target) == before and _positions(target) == where
    assert run(target, 30) == run(twin, 30)  # steps on as if nothing had happened


def test_a_good_file_after_a_bad_one_loads_and_steps_on(pair, tmp_path):
    path, future, target, _twin = pair
    good = path.read_bytes()
    _edit_meta(path, lambda m: _part(m, "stages")["D"][1].append(["bogus", {"D": [NEW, []]}]))
    with pytest.raises(InvalidValue, match="bogus"):
        load_snapshot(target, path)
    path.write_bytes(good)
    load_snapshot(target, path)
    assert run(target, 40) == future


def _store(meta):
    return next(_objects(meta["state"], "framework.store:BodyStore"))


@pytest.mark.parametrize("change, match", [
    (lambda st: _field(st, "n").__setitem__(1, 10_000), "row count 10000 and capacity"),
    (lambda st: _field(st, "n").__setitem__(1, 3), "rows are not one for each entity with a Transform"),
    (lambda st: _field(st, "cols")[1]["D"][1].pop(), "columns are not this scene's"),
    (lambda st: _field(st, "cap").__setitem__(1, 4096), "is not 4096 rows"),
    (lambda st: _field(st, "hitboxes")[1]["L"][1].append(None), "hitboxes and shapes are not one for each row"),
    (lambda st: _field(st, "row_of").__setitem__(1, {"D": [NEW, []]}), "rows are not one for each entity"),
    (lambda st: _field(st, "n").__setitem__(1, {"F": "0x1p+0"}), "store's n is of type float"),
    (lambda st: st[2].remove(_field(st, "cols")), "the body store has no cols"),
])
def test_a_body_store_that_does_not_fit_its_entities_is_refused(pair, change, match):
    path, _future, target, twin = pair
    before = state_hash(target)
    _edit_meta(path, lambda m: change(_store(m)))
    _refused(path, target, before, match)
    assert run(target, 10) == run(twin, 10)


def test_entities_that_do_not_add_up_are_refused(pair):
    path, _future, target, before = pair[0], None, pair[2], state_hash(pair[2])

    def world(meta):
        return dict(_part(meta, "esper")["D"][1])

    _edit_meta(path, lambda m: world(m)["dead"]["S"][1].append(12_345))
    _refused(path, target, before, "dead entity 12345")
    _edit_meta(path, lambda m: world(m)["dead"]["S"][1].clear())
    _edit_meta(path, lambda m: _part(m, "esper")["D"][1].__setitem__(1, ["next", 1]))
    _refused(path, target, before, "next entity id, 1, is one in use")
