"""The small array helpers the per-step stages use in place of slower numpy idioms, held to the
idioms they replace (property tests)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from framework import AABB, Hitbox, Scene, Transform, Velocity
from framework.arrays import distinct
from framework.events import pair_keys
from framework.geometry import widen_down, widen_up
from framework.pair_tracking import track_pairs
from framework.store import as_selector

ints = st.lists(st.integers(-(2**40), 2**40), max_size=200)


@given(ints)
def test_distinct_is_np_unique(values):
    a = np.array(values, dtype=np.int64)
    assert np.array_equal(distinct(a), np.unique(a))


pairs = st.sets(st.tuples(st.integers(0, 40), st.integers(0, 2**32 - 1)), max_size=80)


@settings(deadline=None)  # (the first example compiles the merge)
@given(pairs, pairs, st.booleans(), st.randoms(use_true_random=False))
def test_track_pairs_is_isin_both_ways(now, last, in_order, rng):
    """The tracker's merge (sorted keys, the pipeline's) and its sort (keys in any order) say
    which pairs were there last step and where the gone ones were, as np.isin does."""
    now_l, last_l = sorted(now), sorted(last)
    if not in_order:
        rng.shuffle(now_l)
        rng.shuffle(last_l)
    a = np.array([p[0] for p in now_l], dtype=np.int64)
    b = np.array([p[1] for p in now_l], dtype=np.int64)
    last_keys = pair_keys(np.array([p[0] for p in last_l], dtype=np.int64),
                          np.array([p[1] for p in last_l], dtype=np.int64))
    keys, was, gone = track_pairs(a, b, last_keys)
    assert np.array_equal(keys, pair_keys(a, b))
    assert np.array_equal(was, np.isin(keys, last_keys))
    assert np.array_equal(gone, np.flatnonzero(~np.isin(last_keys, keys)))


finite = st.floats(allow_nan=False, allow_infinity=False)


@given(st.lists(finite, min_size=1, max_size=50))
def test_widening_moves_a_bound_out_by_one_or_two_ulps(values):
    v = np.array(values + [0.0, -0.0, 5e-324, -5e-324, 1.0, 2.0, -2.0, 0.5, 2.0**-1022])
    with np.errstate(over="ignore"):  # (at the largest floats, widening reaches inf, as nextafter does)
        down, up = widen_down(v), widen_up(v)
        once_down, once_up = np.nextafter(v, -np.inf), np.nextafter(v, np.inf)
        assert (down <= once_down).all() and (down >= np.nextafter(once_down, -np.inf)).all()
        assert (up >= once_up).all() and (up <= np.nextafter(once_up, np.inf)).all()


def test_widening_keeps_infinite_bounds_infinite():
    with np.errstate(invalid="ignore"):
        assert widen_down(np.array([-np.inf]))[0] == -np.inf
        assert widen_up(np.array([np.inf]))[0] == np.inf


@given(st.sets(st.integers(0, 60), max_size=40))
def test_a_selector_selects_the_same_rows(rows):
    rows = np.array(sorted(rows), dtype=np.int64)
    col = np.arange(100.0) * 3.0
    sel = as_selector(rows)
    contiguous = rows.size > 0 and rows[-1] - rows[0] + 1 == rows.size
    assert isinstance(sel, slice) == contiguous
    assert np.array_equal(col[sel], col[rows])


@settings(deadline=None)  # (run alone on a new installation, the first example compiles the step)
@given(st.lists(st.tuples(st.integers(1, 15), st.integers(0, 15)), min_size=1, max_size=8))
def test_layers_all_meet_only_when_every_pair_does(layers):
    with Scene(effects=("detection",)) as s:
        for k, (layer, mask) in enumerate(layers):
            s.spawn(Transform(3.0 * k, 0.0), Velocity(), Hitbox(AABB(1, 1), layer=layer, mask=mask))
        s.step(1 / 60)
        every = all((la & mb) and (lb & ma) for la, ma in layers for lb, mb in layers)
        if s.store.layers_all_meet():
            assert every  # may say "not sure" (False) when every pair meets, never the opposite


def test_default_layers_all_meet_and_an_edit_is_seen():
    with Scene() as s:
        a = s.spawn(Transform(0, 0), Velocity(), Hitbox(AABB(1, 1)))
        s.spawn(Transform(0.5, 0), Velocity(), Hitbox(AABB(1, 1)))
        s.step(1 / 60)
        assert s.store.layers_all_meet() and s.counters["candidate_pairs"] == 1
        s.get(a, Hitbox).mask = 0
        s.step(1 / 60)
        assert not s.store.layers_all_meet() and s.counters["candidate_pairs"] == 0
        assert math.isfinite(s.get(a, Transform).x)


def test_kinds_present_follow_the_hitboxes_and_the_narrow_phase_counts_stay_right():
    from framework import Circle
    from framework.store import KIND_AABB, KIND_CIRCLE

    with Scene() as s:
        s.spawn(Transform(0, 0), Velocity(), Hitbox(AABB(1, 1)))
        s.spawn(Transform(0.5, 0), Velocity(), Hitbox(AABB(1, 1)))
        s.step(1 / 60)
        assert s.store.kinds_present() == {KIND_AABB}
        assert s.counters["narrow_tests"] == {"aabb-aabb": 1}
        s.spawn(Transform(0.25, 0.5), Velocity(), Hitbox(Circle(0.5)))
        s.step(1 / 60)
        assert s.store.kinds_present() == {KIND_AABB, KIND_CIRCLE}
        assert sum(s.counters["narrow_tests"].values()) == s.counters["candidate_pairs"] == 3
