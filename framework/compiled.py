"""How the hot loops are compiled: :data:`kernel`, :data:`inner` and :data:`leaf`, numba's ``njit``
with the options each kind of function needs, every one cached on disk and without the C-callable
wrapper numba otherwise builds for every function (nothing here calls one; 7% of a new
installation's compiling, measured on the exact solver's test scene of ``scripts/cold_start.py``).

:data:`leaf` is for functions that allocate nothing.

numba counts references to every array a compiled function passes to another compiled function it
does not inline: an atomic increment and decrement per array per call. In a loop that calls a
helper per joint or per contact pair with five arrays, that bookkeeping was most of the time
(measured: a revolute joint's solve, 171 ns with it, 26 ns without; the same bits). A function
compiled with :data:`leaf` keeps no count: it must create no array (no ``np.empty``, no
``.copy()``, no slicing that outlives the caller's arrays) and call only other :data:`leaf`
functions or plain ``njit`` ones that allocate nothing either. The arrays it is given are owned by
its caller, who keeps them alive for the call.
"""

from __future__ import annotations

from typing import Any

from numba import njit

__all__ = ["inner", "kernel", "leaf", "numpy_kernel"]

# (``_nrt`` is numba's own switch for its reference counting; its type stubs do not list it)
_LEAF_OPTIONS: dict[str, Any] = {"cache": True, "no_cfunc_wrapper": True, "_nrt": False}

#: ``@leaf``: compile (cached on disk) without reference counting. See the module docstring.
leaf = njit(**_LEAF_OPTIONS)

# (``no_cpython_wrapper`` is numba's own option; its type stubs do not list it)
_INNER_OPTIONS: dict[str, Any] = {"cache": True, "no_cfunc_wrapper": True, "no_cpython_wrapper": True}

#: ``@inner``: a compiled helper only other compiled functions call: no wrapper to call it from
#: Python is built, a third less compiling on a new installation (measured on the character move).
inner = njit(**_INNER_OPTIONS)

# (``no_cfunc_wrapper``, numba's own option too: see the module docstring)
_KERNEL_OPTIONS: dict[str, Any] = {"cache": True, "no_cfunc_wrapper": True}

#: ``@kernel``: a compiled function called from Python (or from other compiled functions).
kernel = njit(**_KERNEL_OPTIONS)

#: ``@numpy_kernel``: a :data:`kernel` whose arithmetic errors are numpy's (``1/0`` is inf, ``0/0``
#: NaN, not a ``ZeroDivisionError``): for passes that restate numpy code, bit for bit.
numpy_kernel = njit(**_KERNEL_OPTIONS, error_model="numpy")
