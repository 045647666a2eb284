"""The one way robustctl compiles a numba kernel: :func:`~robustctl._jit.jit`.

``cache=True`` writes the machine code next to the module (``__pycache__``)
or, if that directory is not writable, to numba's user-wide cache directory
(``NUMBA_CACHE_DIR`` overrides both); when no cache location is writable the
function is compiled in place in each process (a warning says so).
``nogil=True`` releases the GIL, so threads may run kernels concurrently.
"""

from __future__ import annotations

import warnings

import numba

__all__ = ["jit"]


def jit(func):
    """``numba.njit(cache=True, nogil=True)``, or without the cache when no cache directory is writable."""
    try:
        return numba.njit(cache=True, nogil=True)(func)
    except RuntimeError as exc:              # numba: "cannot cache function ...: no locator available"
        warnings.warn(f"numba cannot cache {func.__name__} ({exc}); it is compiled in every process",
                      RuntimeWarning, stacklevel=2)
        return numba.njit(cache=False, nogil=True)(func)
