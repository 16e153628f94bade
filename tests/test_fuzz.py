"""Files from strangers: every loader, fed mutations of valid files, raises only its documented
error, within a memory bound (a resource limit on the process while it loads) and a time bound.

Snapshot files are also fuzzed by structure: their JSON description mutated as a tree (class
names, tags, keys, stage names, hostile nodes, nesting), never letting a named class run.

A short run is part of the normal test command (``FUZZ_EXAMPLES`` per loader, default 40). A long
run on request: ``FUZZ_EXAMPLES=3000 FUZZ_REPORT=docs/data/fuzz.json pytest tests/test_fuzz.py``
writes how many inputs each loader was given and how each ended. Every crash a run finds stays
below as a regression test with its input (``test_found_...``). Files at each loader's default
size limit, in the shape that costs the most memory, are loaded under the same bounds with
``RUN_SLOW=1`` (``-k at_the_limit``).
"""

from __future__ import annotations

import contextlib
import json
import os
import random
import re
import resource
import time
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from examples.platformer.levels import LevelError, builtin_levels, load_level, parse_text
from framework import InvalidValue
from framework.replay import Replay

EXAMPLES = int(os.environ.get("FUZZ_EXAMPLES", "40"))
REPORT = os.environ.get("FUZZ_REPORT")
MEMORY = 1024 * 1024 * 1024  # bytes a load may add to the process's address space
SECONDS = 10.0                # the longest a load may take
TALLY: dict[str, Counter] = {}


@contextlib.contextmanager
def bounded():
    """Cap the address space while a loader runs: an allocation beyond the bound fails there."""
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    with open("/proc/self/statm") as f:
        used = int(f.read().split()[0]) * resource.getpagesize()
    limit = used + MEMORY
    if hard != resource.RLIM_INFINITY:
        limit = min(limit, hard)
    resource.setrlimit(resource.RLIMIT_AS, (limit, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


def attempt(loader: str, load, allowed: tuple[type[BaseException], ...]) -> None:
    """Run ``load()`` under the bounds; it may succeed or raise one of ``allowed``, nothing else."""
    t0 = time.perf_counter()
    outcome = "loaded"
    with bounded():
        try:
            load()
        except allowed as exc:
            outcome = type(exc).__name__
    took = time.perf_counter() - t0
    TALLY.setdefault(loader, Counter())[outcome] += 1
    assert took < SECONDS, f"{loader}: a load took {took:.1f} s"


def _write_report() -> None:
    if REPORT:
        Path(REPORT).write_text(json.dumps({k: dict(v) | {"inputs": sum(v.values())} for k, v in TALLY.items()},
                                           indent=1, sort_keys=True))


# --- mutations ---------------------------------------------------------------------------------------

JUNK = [b"-1", b"1e308", b"-1e308", b"NaN", b"Infinity", b"99999999999999999999", b"100000", b"0", b"null",
        b"true", b'"x"', b"[]", b"{}", b"[" * 5000, b"{\"a\":" * 3000, b"\xff\xfe", b"\x00", b"\"\\ud800\""]


@st.composite
def mutated(draw, data: bytes) -> bytes:
    """A valid file's bytes, damaged: truncated, bytes flipped, a token replaced by a huge,
    negative or non-finite number or another type, a key duplicated, deep nesting, re-encoded."""
    rng = random.Random(draw(st.integers(0, 2**32)))
    how = draw(st.sampled_from(["truncate", "flip", "token", "duplicate", "nest", "encoding", "splice"]))
    if how == "truncate":
        return data[: rng.randrange(len(data) + 1)]
    if how == "flip":
        out = bytearray(data)
        for _ in range(rng.randint(1, 16)):
            out[rng.randrange(len(out))] = rng.randrange(256)
        return bytes(out)
    if how == "token":  # replace a number or a literal with junk
        spots = [i for i in range(len(data)) if data[i:i + 1].isdigit() or data[i:i + 1] in (b"t", b"f", b"\"")]
        if not spots:
            return data
        i = rng.choice(spots)
        j = i + 1
        while j < len(data) and data[j:j + 1] not in (b",", b"}", b"]", b"\n"):
            j += 1
        return data[:i] + rng.choice(JUNK) + data[j:]
    if how == "duplicate":  # a key given twice, the second time with junk
        keys = [i for i in range(len(data) - 1) if data[i:i + 1] == b"{"]
        if not keys:
            return data
        i = rng.choice(keys) + 1
        key = rng.choice([b"width", b"height", b"layers", b"data", b"format", b"frames", b"trace", b"tilesets"])
        return data[:i] + b'"' + key + b'": ' + rng.choice(JUNK) + b", " + data[i:]
    if how == "nest":
        depth = rng.choice([10, 1000, 100_000])
        return b"[" * depth + data + b"]" * rng.randint(0, depth)
    if how == "encoding":
        text = data.decode("utf-8", "replace") + "\u00e9\u4e2d"
        return text.encode(rng.choice(["utf-16", "latin-1", "utf-32"]), "replace")
    i, j = sorted(rng.randrange(len(data) + 1) for _ in range(2))
    return data[:i] + data[j:] + data[i:j]  # a piece moved


FUZZ = settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))


# --- the loaders ---------------------------------------------------------------------------------------

TMJ = builtin_levels()[2].read_bytes()
TEXT = b"""
#..............#
#..C.....-----.#
#.P..E../##\\..G#
################
"""


@FUZZ
@given(st.data())
def test_tiled_maps(tmp_path_factory, data):
    path = tmp_path_factory.mktemp("tmj") / "map.tmj"
    path.write_bytes(data.draw(mutated(TMJ)))
    attempt("Tiled map (.tmj)", lambda: load_level(path), (LevelError,))
    _write_report()


@FUZZ
@given(st.data())
def test_text_levels(tmp_path_factory, data):
    path = tmp_path_factory.mktemp("txt") / "map.txt"
    path.write_bytes(data.draw(mutated(TEXT)))
    attempt("text level (.txt)", lambda: load_level(path), (LevelError,))
    _write_report()


def _replay_bytes() -> bytes:
    import tempfile

    r = Replay([{"right"}, {"right", "space"}, set(), {"left"}] * 5, seed=3, meta={"level": "x"})
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "r.jsonl"
        r.save(p)
        return p.read_bytes()


REPLAY = _replay_bytes()


@FUZZ
@given(st.data())
def test_replays(tmp_path_factory, data):
    path = tmp_path_factory.mktemp("replay") / "r.jsonl"
    path.write_bytes(data.draw(mutated(REPLAY)))
    attempt("replay", lambda: Replay.load(path), (InvalidValue,))
    _write_report()


def _golden_scene():
    from framework import Circle, Hitbox, Transform, Velocity
    from framework.testing import text_scene

    def ball(scene, x, y, tile):
        return scene.spawn(Transform(x, y), Velocity(2.0, 0.0), Hitbox(Circle(0.4)))

    return text_scene("#....#\n#.O..#\n######", {"O": ball}).scene


def _golden_bytes() -> bytes:
    import tempfile

    from framework.testing import check_golden

    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "g.json"
        check_golden(_golden_scene(), p, 20, update=True)
        return p.read_bytes()


GOLDEN = _golden_bytes()


@FUZZ
@given(st.data())
def test_golden_traces(tmp_path_factory, data):
    from framework.testing import GoldenMismatch, check_golden

    path = tmp_path_factory.mktemp("golden") / "g.json"
    path.write_bytes(data.draw(mutated(GOLDEN)))
    scene = _golden_scene()
    try:
        attempt("golden trace", lambda: check_golden(scene, path, 20, update=False), (InvalidValue, GoldenMismatch))
    finally:
        scene.close()
    _write_report()


def _snapshot_scene():
    from test_snapshot import build

    return build(5, bodies=4)


def _snapshot_bytes() -> bytes:
    import tempfile

    from framework.snapshot_file import save_snapshot

    s = _snapshot_scene()
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "s.npz"
        save_snapshot(s, p)
        return p.read_bytes()


SNAPSHOT = _snapshot_bytes()


@st.composite
def mutated_snapshot(draw) -> bytes:
    """Either the file's bytes damaged, or its description's JSON damaged inside a valid zip."""
    if draw(st.booleans()):
        return draw(mutated(SNAPSHOT))
    import io

    with np.load(io.BytesIO(SNAPSHOT), allow_pickle=False) as npz:
        arrays = {k: npz[k] for k in npz.files}
    arrays["__meta__"] = np.frombuffer(draw(mutated(arrays["__meta__"].tobytes())), dtype=np.uint8)
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def _load_or_refuse(tmp_path_factory, blob: bytes, label: str) -> None:
    """Load ``blob`` as a snapshot file into a fresh scene: loaded, or refused with an InvalidValue
    and the scene as it was."""
    from test_snapshot import state_hash

    from framework.snapshot_file import load_snapshot

    path = tmp_path_factory.mktemp("snap") / "s.npz"
    path.write_bytes(blob)
    scene = _snapshot_scene()
    before = state_hash(scene)
    try:
        outcome = []

        def load():
            load_snapshot(scene, path)
            outcome.append("loaded")

        attempt(label, load, (InvalidValue,))
        if not outcome:
            assert state_hash(scene) == before  # refused: the scene is as it was
    finally:
        scene.close()


@pytest.mark.slow
@FUZZ
@given(mutated_snapshot())
def test_snapshot_files(tmp_path_factory, blob):
    _load_or_refuse(tmp_path_factory, blob, "snapshot file (.npz)")
    _write_report()


# --- snapshot files: mutations of the description's structure ---------------------------------------

def _description() -> tuple[dict, dict]:
    import io

    with np.load(io.BytesIO(SNAPSHOT), allow_pickle=False) as npz:
        arrays = {k: npz[k] for k in npz.files}
    return arrays, json.loads(arrays.pop("__meta__").tobytes())


MARKER = Path(os.environ.get("TMPDIR", "/tmp")) / f"framework-fuzz-marker-{os.getpid()}"
POPEN = "framework.frame:np.f2py.subprocess.Popen"
HOSTILE = [{"E": [POPEN, {"L": [10**9, ["touch", str(MARKER)]]}]},  # the audit's file
           {"O": [10**9, POPEN, [["args", ["touch", str(MARKER)]]]]}, {"NT": [POPEN, [["touch", str(MARKER)]]]},
           {"C": "builtins:eval"}, {"C": "os:system"}, {"O": [10**9, "framework.scene:Scene", [["world", "default"]]]},
           {"E": ["framework.components:Transform", 1]}, {"O": [10**9, "framework.components:Body", []]},
           {"NT": ["framework.components:Transform", [1, 2, 3]]}, {"S": [10**9, [{"L": [10**9 + 1, []]}]]},
           {"F": "nan"}, {"F": "inf"}, {"I": "9" * 5000}, {"I": "-1"}, {"B": "!!"}, {"DT": "O"}, {"DT": "<f8"},
           {"SL": [1, 2, {"F": "0x1p+0"}]}, {"A": 10**6}, {"NS": 0}, {"R": 10**9}, {"R": 0}, {"P": "scene"},
           {"P": "nope"}, {"Q": 1}, {"L": [0, []]}, {}, [], None, True, -1, 2**60, "x", {"T": []}]
CLASSES = [POPEN, "builtins:eval", "os:system", "numpy:load", "framework.frame:np", "framework:Transform",
           "framework.scene:Scene", "framework.components:Body", "framework.events:StepContacts",
           "framework.components:Transform", "framework.store:BodyStore", "framework.frame:StepFrame",
           "framework.shapes:Circle", "framework.validation:InvalidValue", "", 7, None]
TAGS = ["I", "F", "P", "A", "NS", "C", "E", "B", "SL", "DT", "T", "NT", "R", "L", "D", "S", "FS", "O", "?"]


def _slots(node, out, depth=0):
    """Every place in a JSON tree a value sits: (its container, its key or index)."""
    if depth > 200:
        return
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for k, v in items:
        out.append((node, k))
        _slots(v, out, depth + 1)


def _state_parts(meta):
    """(name, fields) of each part of the state whose layout earlier mutations left intact."""
    try:
        pairs = meta["state"]["D"][1]
        return [(p[0], p[1]["D"][1]) for p in pairs if isinstance(p, list) and len(p) == 2
                and isinstance(p[1], dict) and isinstance(p[1].get("D"), list) and len(p[1]["D"]) == 2
                and isinstance(p[1]["D"][1], list) and all(isinstance(f, list) and f for f in p[1]["D"][1])]
    except (KeyError, IndexError, TypeError):
        return []


@st.composite
def mutated_description(draw) -> bytes:
    """A valid snapshot file whose description is changed as a tree, not as bytes: a class name,
    a tag, a key or a stage name replaced, dropped or added, a node replaced by a hostile one,
    two nodes swapped, nodes nested deeply; each inside a valid zip."""
    import io

    arrays, meta = _description()
    rng = random.Random(draw(st.integers(0, 2**32)))
    for _ in range(draw(st.integers(1, 3))):
        how = draw(st.sampled_from(["class", "tag", "key", "stage", "scene", "hostile", "swap", "nest", "drop",
                                    "number", "part"]))
        slots: list = []
        _slots(meta, slots)
        parent, k = rng.choice(slots)
        v = parent[k]
        if how == "class":  # a class name of an O, E, NT or C node
            named = [(n, key) for n, key in slots if isinstance(n, dict) and key in ("O", "E", "NT", "C")]
            if named:
                n, key = rng.choice(named)
                cname = rng.choice(CLASSES)
                if key == "C":
                    n[key] = cname
                elif isinstance(n[key], list) and n[key]:
                    n[key][1 if key == "O" and len(n[key]) > 1 else 0] = cname
        elif how == "tag" and isinstance(v, dict) and len(v) == 1:
            (tag, body), = v.items()
            parent[k] = {rng.choice(TAGS): body}
        elif how == "key":  # a dict node's key, or an object's attribute name, renamed / duplicated
            pairs = [n for n, key in slots if isinstance(n, dict) and key in ("D", "O")]
            if pairs:
                n = rng.choice(pairs)
                fields = n.get("D", n.get("O"))[-1] if isinstance(n.get("D", n.get("O")), list) else None
                if isinstance(fields, list) and fields and isinstance(fields[0], list):
                    pair = rng.choice(fields)
                    choice = rng.choice(["rename", "duplicate", "drop", "add"])
                    if not isinstance(pair, list) or not pair:
                        pass
                    elif choice == "rename":
                        pair[0] = rng.choice(["bogus", "__class__", "__dict__", "", "x y", 1, None, "_store", "n"])
                    elif choice == "duplicate":
                        fields.append([pair[0], rng.choice(HOSTILE)])
                    elif choice == "drop":
                        fields.remove(pair)
                    else:
                        fields.append([rng.choice(["bogus", "closed", "_pipeline", "frame"]), rng.choice(HOSTILE)])
        elif how in ("stage", "scene"):  # a stage name or a scene field added, dropped or renamed
            for part in _state_parts(meta):
                if part[0] == ("stages" if how == "stage" else "scene"):
                    fields = part[1]
                    choice = rng.choice(["add", "drop", "rename"])
                    if choice == "add":
                        fields.append([rng.choice(["bogus", "render", "frame", "time"]), {"D": [10**9, []]}])
                    elif fields and choice == "drop":
                        fields.pop(rng.randrange(len(fields)))
                    elif fields:
                        fields[rng.randrange(len(fields))][0] = rng.choice(["bogus", "closed", "narrow_phase"])
        elif how == "hostile":
            parent[k] = rng.choice(HOSTILE)
        elif how == "swap":
            other_parent, other_k = rng.choice(slots)
            parent[k], other_parent[other_k] = other_parent[other_k], v
        elif how == "nest":
            depth = rng.choice([2, 50, 400, 5000])
            for i in range(depth):
                v = rng.choice([{"T": [v]}, {"L": [10**9 + i, [v]]}])
            parent[k] = v
        elif how == "drop" and isinstance(v, list) and v:
            v.pop(rng.randrange(len(v)))
        elif how == "number":
            ints = [(n, key) for n, key in slots if type(n[key]) is int]
            if ints:
                n, key = rng.choice(ints)
                n[key] = rng.choice([-1, 0, 2**53, -(2**53), 10**9, True, None, {"F": "0x1p+0"}, {"I": "1" * 400}])
        elif how == "part":
            key = rng.choice(sorted(meta))
            meta[key] = rng.choice(HOSTILE + [meta.get(rng.choice(sorted(meta)))])
    try:
        text = json.dumps(meta)
    except (RecursionError, ValueError):  # nested too deeply to write, or a node swapped into itself
        text = json.dumps({"format": "framework-snapshot"})
    arrays["__meta__"] = np.frombuffer(text.encode(), dtype=np.uint8)
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


@pytest.mark.slow
@FUZZ
@given(mutated_description())
def test_snapshot_file_descriptions(tmp_path_factory, blob):
    """Structure-aware: the description's tree mutated (see :func:`mutated_description`). Refused
    or loaded; refused, the scene is as it was; and nothing a hostile class name names ever runs."""
    _load_or_refuse(tmp_path_factory, blob, "snapshot file description (structure)")
    assert not MARKER.exists(), "a class named in the file ran"
    _write_report()


# --- hostile values: every number and literal of a valid file ----------------------------------------
#
# What found issue 34's loader escapes: each number, literal or string of a valid file (chosen by the
# key it belongs to, so that a map's few header numbers are as likely as its hundreds of tile ids)
# replaced by a value that breaks the usual conversions: ints beyond float64 (10**400) or beyond
# Python's int max str digits (4,301 digits), unicode digits ('²', '٣'), 1e999, -0.0, NaN, nesting
# just under and over the decoder's recursion limit. Tilesets are fuzzed with their image's header
# too (the image is the stranger's file as well).

SLOW = os.environ.get("RUN_SLOW") == "1"
HOSTILE_EXAMPLES = int(os.environ.get("FUZZ_EXAMPLES", "1000" if SLOW else "100"))  # a loader, in the normal run
HOSTILE_FUZZ = settings(max_examples=HOSTILE_EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))
HOSTILE_FUZZ_SNAPSHOTS = settings(HOSTILE_FUZZ, max_examples=max(1, HOSTILE_EXAMPLES // 3))  # each builds a scene
_DEPTH = 1000  # sys.getrecursionlimit(): the decoder gives up around here
HOSTILE_NUMBERS = [b"1" + b"0" * 400, b"-1" + b"0" * 400, b"9" * 4301, b"-" + b"9" * 4301, b"1" + b"0" * 4300,
                   b"1e999", b"-1e999", b"-0.0", b"-0", b"NaN", b"-Infinity", b"1e-400", b"5e-324",
                   b"1.7976931348623157e308",
                   b"2147483648", b"4294967296", b"18446744073709551616", b"-2147483649", b"0", b"-1", b"0.5",
                   b'"\xc2\xb2"', b'"\xd9\xa3"', b'"--2"', b'"1e999"', b'"' + b"9" * 5000 + b'"', b"true", b"null",
                   b"[]", b"{}", b"[" * (_DEPTH - 40) + b"]" * (_DEPTH - 40), b"[" * (_DEPTH - 5) + b"]" * (_DEPTH - 5),
                   b'{"a":' * (_DEPTH - 40) + b"0" + b"}" * (_DEPTH - 40)]
HOSTILE_STRINGS = [b'"\xc2\xb2"', b'"\xd9\xa3"', b'"--2"', b'"-"', b'""', b'"+1"', b'" 1"',
                   b'"1' + b"0" * 400 + b'"', b'"' + b"9" * 5000 + b'"', b'"\\ud800"', b'"NaN"', b'"-0.0"',
                   b'"\\u0000"', b'"solid"', b'"platform"']
_TOKEN = re.compile(rb'"(?:[^"\\]|\\.)*"|-?(?:0|[1-9][0-9]*)(?:\.[0-9]+)?(?:[eE][+-]?[0-9]+)?|true|false|null')
_KEY = re.compile(rb'"((?:[^"\\]|\\.)*)"\s*:\s*$')


def _spots(data: bytes) -> dict[bytes, list[tuple[int, int, bool]]]:
    """The file's tokens grouped by the key they belong to (the nearest key before them):
    ``(start, end, is_a_string)``."""
    groups: dict[bytes, list[tuple[int, int, bool]]] = {}
    key = b""
    for m in _TOKEN.finditer(data):
        before = _KEY.search(data, max(0, m.start() - 200), m.start())
        if before:
            key = before.group(1)
        is_key = data[m.end():m.end() + 3].lstrip()[:1] == b":"
        groups.setdefault(b"<key>" if is_key else key, []).append((m.start(), m.end(), m.group().startswith(b'"')))
    return groups


@st.composite
def hostile(draw, data: bytes) -> bytes:
    """``data`` with one to three of its numbers, literals or strings replaced by hostile values (a
    string by a hostile string or value, so keys stay keys)."""
    rng = random.Random(draw(st.integers(0, 2**32)))
    groups = _spots(data)
    names = sorted(groups)
    picks = []
    for _ in range(draw(st.integers(1, 3))):
        start, end, text = rng.choice(groups[rng.choice(names)])
        key = data[end:end + 3].lstrip()[:1] == b":"
        picks.append((start, end, rng.choice(HOSTILE_STRINGS if key else
                                             (HOSTILE_STRINGS + HOSTILE_NUMBERS) if text else HOSTILE_NUMBERS)))
    out, last = [], 0
    for start, end, value in sorted(set(picks)):
        if start >= last:
            out += [data[last:start], value]
            last = end
    return b"".join(out) + data[last:]


@pytest.mark.slow
@HOSTILE_FUZZ
@given(st.data())
def test_tiled_maps_with_hostile_values(tmp_path_factory, data):
    path = tmp_path_factory.mktemp("tmj") / "map.tmj"
    path.write_bytes(data.draw(hostile(TMJ)))
    attempt("Tiled map (.tmj), hostile values", lambda: load_level(path), (LevelError,))
    _write_report()


@HOSTILE_FUZZ
@given(st.data())
def test_text_levels_with_hostile_characters(tmp_path_factory, data):
    rng = random.Random(data.draw(st.integers(0, 2**32)))
    text = bytearray(TEXT)
    for _ in range(rng.randint(1, 3)):
        i = rng.randrange(len(text))
        text[i:i + 1] = rng.choice(["\u00b2", "\u0663", "\u2028", "\x85", "\x00", "\ufeff", "\r", "M~~", "~"]).encode()
    path = tmp_path_factory.mktemp("txt") / "map.txt"
    path.write_bytes(bytes(text))
    attempt("text level (.txt), hostile characters", lambda: load_level(path), (LevelError,))
    _write_report()


@HOSTILE_FUZZ
@given(st.data())
def test_replays_with_hostile_values(tmp_path_factory, data):
    path = tmp_path_factory.mktemp("replay") / "r.jsonl"
    path.write_bytes(data.draw(hostile(REPLAY)))
    attempt("replay, hostile values", lambda: Replay.load(path), (InvalidValue,))
    _write_report()


GOLDEN_SHORT = None  # a 5-step trace: the hostile fuzzing replays the scene, so fewer steps, more inputs


def _golden_short() -> bytes:
    global GOLDEN_SHORT
    if GOLDEN_SHORT is None:
        import tempfile

        from framework.testing import check_golden

        with tempfile.TemporaryDirectory() as tmp:
            p = Path(tmp) / "g.json"
            check_golden(_golden_scene(), p, 5, update=True)
            GOLDEN_SHORT = p.read_bytes()
    return GOLDEN_SHORT


@pytest.mark.slow
@HOSTILE_FUZZ
@given(st.data())
def test_golden_traces_with_hostile_values(tmp_path_factory, data):
    from framework.testing import GoldenMismatch, check_golden

    path = tmp_path_factory.mktemp("golden") / "g.json"
    path.write_bytes(data.draw(hostile(_golden_short())))
    scene = _golden_scene()
    try:
        attempt("golden trace, hostile values", lambda: check_golden(scene, path, 5, update=False),
                (InvalidValue, GoldenMismatch))
    finally:
        scene.close()
    _write_report()


@pytest.mark.slow
@HOSTILE_FUZZ_SNAPSHOTS
@given(st.data())
def test_snapshot_file_descriptions_with_hostile_values(tmp_path_factory, data):
    import io

    arrays, meta = _description()
    arrays["__meta__"] = np.frombuffer(data.draw(hostile(json.dumps(meta).encode())), dtype=np.uint8)
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    _load_or_refuse(tmp_path_factory, buf.getvalue(), "snapshot file description, hostile values")
    assert not MARKER.exists(), "a class named in the file ran"
    _write_report()


TILESET = json.dumps({
    "type": "tileset", "name": "hero", "image": "hero.png", "imagewidth": 64, "imageheight": 32, "tilewidth": 16,
    "tileheight": 16, "margin": 0, "spacing": 0, "columns": 4, "tilecount": 8, "tiledversion": "1.10.2",
    "tiles": [{"id": 0, "type": "run", "animation": [{"tileid": 0, "duration": 100}, {"tileid": 1, "duration": 150},
                                                      {"tileid": 7, "duration": 0.5}]},
              {"id": 4, "properties": [{"name": "speed", "type": "float", "value": 2.5}],
               "animation": [{"tileid": 4, "duration": 1000}]}],
}).encode()
IMAGE_SIZES = [0, 1, 15, 16, 17, 64, 4096, 4112, 40_000, 65_536, 2**31 - 1, 2**31, 2**32 - 1]


def _png_header(width: int, height: int) -> bytes:
    import struct

    return b"\x89PNG\r\n\x1a\n\x00\x00\x00\x0dIHDR" + struct.pack(">II", width, height) + b"\x08\x06\x00\x00\x00"


def test_the_valid_tileset_loads():
    import tempfile

    from framework.sprites import SpriteSheet

    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "hero.png").write_bytes(_png_header(64, 32))
        (Path(tmp) / "hero.tsj").write_bytes(TILESET)
        sheet = SpriteSheet.from_tiled(Path(tmp) / "hero.tsj")
        assert len(sheet) == 8 and sorted(sheet.animations) == [0, 4]


@HOSTILE_FUZZ
@given(st.data())
def test_tilesets_with_hostile_values(tmp_path_factory, data):
    from framework.sprites import SpriteSheet

    where = tmp_path_factory.mktemp("tileset")
    rng = random.Random(data.draw(st.integers(0, 2**32)))
    width, height = 64, 32
    what = data.draw(st.sampled_from(["json", "json", "image", "both"]))
    text = TILESET
    if what in ("image", "both"):
        width, height = rng.choice(IMAGE_SIZES + [64]), rng.choice(IMAGE_SIZES + [32])
    if what in ("json", "both"):
        text = data.draw(hostile(TILESET))
    (where / "hero.png").write_bytes(_png_header(width, height))
    path = where / "hero.tsj"
    path.write_bytes(text)
    attempt("tileset (.tsj), hostile values", lambda: SpriteSheet.from_tiled(path), (InvalidValue,))
    _write_report()


# --- the limits at their maximum --------------------------------------------------------------------
#
# A file as large as each loader's default limit allows, of the worst shape for memory, under the
# same bound as the fuzzing. Slow (a few seconds each): run with RUN_SLOW=1.

AT_MAXIMUM = pytest.mark.skipif(os.environ.get("RUN_SLOW") != "1", reason="files at the size limits: RUN_SLOW=1")


def _bounded_load(load, allowed, seconds=30.0):
    t0 = time.perf_counter()
    with bounded():
        try:
            load()
        except allowed:
            pass
    assert time.perf_counter() - t0 < seconds


@pytest.mark.slow
@AT_MAXIMUM
@pytest.mark.parametrize("shape", ["sets", "lists", "objects"])
def test_a_snapshot_description_at_the_limit_stays_within_the_bound(tmp_path, shape):
    import io

    from framework.snapshot_file import MAX_DESCRIPTION_BYTES, load_snapshot

    arrays, meta = _description()
    room = MAX_DESCRIPTION_BYTES - len(json.dumps(meta)) - 64
    item = {"sets": lambda i: {"S": [10**6 + i, []]}, "lists": lambda i: {"L": [10**6 + i, []]},
            "objects": lambda i: {"O": [10**6 + i, "framework.shapes:Circle", [["radius", 1]]]}}[shape]
    meta["state"] = {"L": [0, [item(i) for i in range(room // (len(json.dumps(item(0), separators=(",", ":"))) + 1))]]}
    arrays["__meta__"] = np.frombuffer(json.dumps(meta, separators=(",", ":")).encode(), dtype=np.uint8)
    assert 0.99 * MAX_DESCRIPTION_BYTES < arrays["__meta__"].size <= MAX_DESCRIPTION_BYTES
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    path = tmp_path / "s.npz"
    path.write_bytes(buf.getvalue())
    del arrays, meta, buf
    scene = _snapshot_scene()
    _bounded_load(lambda: load_snapshot(scene, path), (InvalidValue,))
    scene.close()


@pytest.mark.slow
@AT_MAXIMUM
@pytest.mark.parametrize("shape", ["distinct frames", "empty frames", "header"])
def test_a_replay_at_the_limit_stays_within_the_bound(tmp_path, shape):
    import itertools

    from framework.replay import MAX_BYTES

    header = {"format": "framework-replay", "version": 1, "dt": 1 / 60, "seed": 0, "frames": 0, "meta": {}}
    lines: list[str] = []
    if shape == "header":
        header["meta"] = {"k": [[]] * ((MAX_BYTES - 200) // 3)}
    elif shape == "empty frames":
        lines = ["[]"] * ((MAX_BYTES - 200) // 3)
    else:
        size, names = 200, ["".join(p) for p in itertools.product("abcdefghijklmnopqrstuvwxyz", repeat=2)]
        for pick in itertools.chain(itertools.combinations(names, 2), itertools.combinations(names, 3)):
            line = json.dumps(list(pick), separators=(",", ":"))
            if size + len(line) + 1 > MAX_BYTES:
                break
            lines.append(line)
            size += len(line) + 1
    header["frames"] = len(lines)
    path = tmp_path / "r.jsonl"
    path.write_text(json.dumps(header, separators=(",", ":")) + "\n" + "".join(line + "\n" for line in lines))
    assert 0.99 * MAX_BYTES < path.stat().st_size <= MAX_BYTES
    del lines, header
    _bounded_load(lambda: Replay.load(path), (InvalidValue,))


@pytest.mark.slow
@AT_MAXIMUM
def test_a_golden_trace_at_the_limit_stays_within_the_bound(tmp_path):
    from framework.testing import GoldenMismatch, check_golden
    from framework.testing.golden import MAX_BYTES

    path = tmp_path / "g.json"
    path.write_text('{"format":1,"framework":"x","dt":0,"steps":0,"trace":[' + ",".join(["[]"] * ((MAX_BYTES - 100)
                                                                                                 // 3)) + "]}")
    assert 0.99 * MAX_BYTES < path.stat().st_size <= MAX_BYTES
    scene = _golden_scene()
    _bounded_load(lambda: check_golden(scene, path, 20, update=False), (InvalidValue, GoldenMismatch))
    scene.close()


def test_a_golden_trace_over_its_limit_is_refused_and_the_limit_can_be_raised(tmp_path):
    from framework.testing import check_golden

    path = tmp_path / "g.json"
    path.write_bytes(GOLDEN)
    with pytest.raises(InvalidValue, match=r"more than the limit of 1000 for a golden trace \(max_bytes\)"):
        check_golden(_golden_scene(), path, 20, max_bytes=1000)
    check_golden(_golden_scene(), path, 20, max_bytes=len(GOLDEN))  # raised: it loads and matches
    with pytest.raises(InvalidValue, match="max_bytes must be an int > 0"):
        check_golden(_golden_scene(), path, 20, max_bytes=0)


# --- found by fuzzing, kept ------------------------------------------------------------------------


def test_found_a_map_declaring_a_huge_size_with_one_cell(tmp_path):
    """Issue 25's first finding: 100,000 x 100,000 declared, one data cell (allocated for the
    declared size: MemoryError after 5 s under a 4 GB limit)."""
    path = tmp_path / "huge.tmj"
    path.write_text(json.dumps({"width": 100_000, "height": 100_000, "tilewidth": 32, "tileheight": 32,
                                "layers": [{"type": "tilelayer", "name": "solid", "data": [1]}]}))
    with bounded(), pytest.raises(LevelError, match="more than the limit of 4000000"):
        load_level(path)


def test_found_a_replay_of_deeply_nested_brackets(tmp_path):
    """Issue 25's second finding: 100,000 nested brackets (a RecursionError from the decoder)."""
    path = tmp_path / "deep.jsonl"
    path.write_text("[" * 100_000 + "]" * 100_000 + "\n")
    with pytest.raises(InvalidValue, match="nested too deeply"):
        Replay.load(path)


@pytest.mark.slow
def test_found_a_zlib_bomb_in_tile_data(tmp_path):
    """Compressed tile data that inflates far beyond what the map declares is refused while it
    inflates, not after."""
    import base64
    import zlib

    bomb = base64.b64encode(zlib.compress(b"\x00" * (256 * 1024 * 1024), 9)).decode()
    path = tmp_path / "bomb.tmj"
    path.write_text(json.dumps({"width": 4, "height": 4, "tilewidth": 32, "tileheight": 32, "layers": [
        {"type": "tilelayer", "name": "solid", "encoding": "base64", "compression": "zlib", "data": bomb}]}))
    with bounded(), pytest.raises(LevelError, match="holds more than the 64 bytes"):
        load_level(path)


def test_found_deeply_nested_group_layers(tmp_path):
    inner = '{"type": "tilelayer", "name": "solid", "data": [0, 0, 0, 0]}'
    layers = '{"type": "group", "layers": [' * 5000 + inner + "]}" * 5000
    path = tmp_path / "groups.tmj"
    path.write_text('{"width": 2, "height": 2, "tilewidth": 8, "tileheight": 8, "layers": [' + layers + "]}")
    with pytest.raises(LevelError, match="nested too deeply|more than 1000 layers"):
        load_level(path)


@pytest.mark.parametrize("tilesets", [
    [{"firstgid": 1, "tiles": [{"type": "solid"}]}],              # a typed tile without an id
    [{"firstgid": 1, "tiles": [{"id": "x", "type": "solid"}]}],   # an id that is not a number
    [{"firstgid": 1, "tiles": "solid"}],                          # tiles that are not a list
    [{"firstgid": "1", "tiles": []}],                             # firstgid as text
    [{"firstgid": 1, "tiles": [{"id": 0, "properties": [{"name": ["k"], "value": 1}]}]}],  # a list as a name
])
def test_found_malformed_tilesets(tmp_path, tilesets):
    path = tmp_path / "ts.tmj"
    path.write_text(json.dumps({"width": 2, "height": 1, "tilewidth": 8, "tileheight": 8, "tilesets": tilesets,
                                "layers": [{"type": "tilelayer", "name": "t", "data": [1, 0]}]}))
    with pytest.raises(LevelError):
        load_level(path)


def test_found_base64_tile_data_that_is_not_text(tmp_path):
    path = tmp_path / "b64.tmj"
    path.write_text(json.dumps({"width": 1, "height": 1, "tilewidth": 8, "tileheight": 8, "layers": [
        {"type": "tilelayer", "name": "solid", "encoding": "base64", "data": [1]}]}))
    with pytest.raises(LevelError, match="base64 tile data must be text"):
        load_level(path)


def test_text_levels_that_are_too_big_are_refused():
    with pytest.raises(LevelError, match="more than the limit"):
        parse_text("#" * 3000 + "\n" + ("#\n" * 2000) + "P", "big.txt")


def test_found_a_snapshot_file_with_an_unknown_compression_method(tmp_path):
    """Found by the long run: a flipped byte in a zip header's compression method made zipfile
    raise NotImplementedError."""
    from test_snapshot import state_hash

    from framework.snapshot_file import load_snapshot

    data = bytearray(SNAPSHOT)
    for sig, at in ((b"PK\x03\x04", 8), (b"PK\x01\x02", 10)):
        i = data.find(sig)
        data[i + at:i + at + 2] = (99).to_bytes(2, "little")
    path = tmp_path / "s.npz"
    path.write_bytes(bytes(data))
    scene = _snapshot_scene()
    before = state_hash(scene)
    with pytest.raises(InvalidValue, match="not a snapshot file"):
        load_snapshot(scene, path)
    assert state_hash(scene) == before
