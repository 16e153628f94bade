"""The narrow phase's sorting of its pairs by shape: each pair's code (:func:`~.kinds.pair_code`),
how many pairs of each code, and which families of kernels (:data:`~.kinds.PAIRS`) they need, in
one compiled pass over the pairs (numpy took eight calls and their arrays, about a fifth of a small
scene's narrow phase).
"""

from __future__ import annotations

import numpy as np

from ..compiled import kernel
from .kinds import KINDS, PAIRS

__all__ = ["FAMILY_OF_CODE", "classify_pairs"]

#: Each pair code's family (``BOXES`` ...), in :data:`PAIRS`' order.
FAMILY_OF_CODE = np.array([rule.family for rule in PAIRS.values()], dtype=np.int64)


@kernel
def _classify(kind, ra, rb, n_kinds, family_of_code):  # pragma: no cover - compiled
    code = np.empty(ra.size, dtype=np.int64)
    n_of = np.zeros(family_of_code.size, dtype=np.int64)
    families = 0
    for i in range(ra.size):
        ka, kb = np.int64(kind[ra[i]]), np.int64(kind[rb[i]])
        if ka < 0 or kb < 0 or ka >= n_kinds or kb >= n_kinds:
            return code, n_of, -1
        c = ka * n_kinds + kb
        code[i] = c
        n_of[c] += 1
        families |= np.int64(1) << family_of_code[c]
    return code, n_of, families


def classify_pairs(kind: np.ndarray, ra: np.ndarray, rb: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """``(code, n_of, families)``: each pair's code, how many pairs of each code (indexed by code),
    and the families present as bits (``1 << BOXES`` ...); families -1 where a row has no kind
    (no hitbox): the caller's own arithmetic says what that means."""
    code, n_of, families = _classify(kind, ra, rb, np.int64(len(KINDS)), FAMILY_OF_CODE)
    return code, n_of, int(families)
