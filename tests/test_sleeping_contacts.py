"""The narrow phase's contacts kept between idle bodies (``sleeping_contacts.kept_contacts``): the
numpy it replaced, element by element, on random contacts with sleepers, statics, sensors, pairs
whose bodies are gone, and contacts out of order."""

from __future__ import annotations

import numpy as np
import pytest

from framework.events import StepContacts
from framework.systems.sleeping_contacts import kept_contacts

STATIC = 2


def _reference(contacts, rows, prev, lut, asleep, body, sensor):
    """The numpy of ``NarrowPhase._keep_sleepers`` before it was compiled (the merge and the wakes)."""
    def rows_of(e):
        out = np.full(e.size, -1, dtype=np.int64)
        ok = e < lut.size
        out[ok] = lut[e[ok]]
        return out

    pa, pb = rows_of(prev.a), rows_of(prev.b)
    ok = (pa >= 0) & (pb >= 0)
    idle = asleep | (body == STATIC)
    frozen = np.flatnonzero(ok & idle[np.maximum(pa, 0)] & idle[np.maximum(pb, 0)])
    merged = bool(frozen.size)
    if frozen.size:
        cols = [np.concatenate([x, y[frozen]]) for x, y in zip(contacts, prev)]
        order = np.lexsort((cols[1], cols[0]))
        contacts = StepContacts(*(c[order] for c in cols))
        rows = (np.concatenate([rows[0], pa[frozen]])[order], np.concatenate([rows[1], pb[frozen]])[order])
    a_, b_ = rows
    solid = ~(sensor[a_] | sensor[b_])
    wake_b = solid & asleep[b_] & ~asleep[a_] & (body[a_] != STATIC)
    wake_a = solid & asleep[a_] & ~asleep[b_] & (body[b_] != STATIC)
    woken = np.unique(np.concatenate([b_[wake_b], a_[wake_a]]))
    return merged, contacts, rows, woken


def _contacts(rng, entity, count, ordered):
    i, j = rng.integers(0, entity.size, count), rng.integers(0, entity.size, count)
    a, b = np.minimum(entity[i], entity[j]), np.maximum(entity[i], entity[j])
    keep = a != b
    a, b = a[keep], b[keep]
    if ordered:
        order = np.lexsort((b, a))
        a, b = a[order], b[order]
    floats = [np.round(rng.normal(size=a.size), 2) for _ in range(5)]
    return StepContacts(a.astype(np.int64), b.astype(np.int64), *floats)


@pytest.mark.parametrize("seed", range(10))
def test_kept_contacts_are_the_numpy_merge_and_wakes(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 40))
    entity = rng.permutation(3 * n)[:n].astype(np.int64) + 1
    lut = np.full(3 * n + 1 - int(rng.integers(0, 3)), -1, dtype=np.int64)  # (a short table: ids past it are gone)
    keep = entity < lut.size
    lut[entity[keep]] = np.flatnonzero(keep)
    asleep = rng.random(n) < 0.5
    body = rng.integers(0, 3, n)
    sensor = rng.random(n) < 0.1
    ordered = seed % 3 != 0  # (a third of the cases out of order: the merge is a sort)
    now = _contacts(rng, entity[keep], int(rng.integers(0, 12)), ordered)
    prev = _contacts(rng, entity, int(rng.integers(0, 25)), ordered)
    rows = (lut[now.a], lut[now.b])
    want = _reference(now, rows, prev, lut, asleep, body, sensor)
    merged, ints, floats, woken = kept_contacts(*now, *rows, *prev, lut, asleep, body, sensor, STATIC)
    assert merged == want[0]
    if merged:
        got_contacts, got_rows = StepContacts(ints[0], ints[1], *floats), (ints[2], ints[3])
    else:
        assert ints.shape[1] == 0 and floats.shape[1] == 0
        got_contacts, got_rows = now, rows
    for g, w in zip(got_contacts, want[1]):
        assert g.tobytes() == w.tobytes()
    for g, w in zip(got_rows, want[2]):
        assert np.array_equal(g, w)
    assert np.array_equal(woken, want[3])
