"""Argument checks shared by the ``moo`` modules.

Package-internal: the modules of :mod:`moo` import it; the package does not
re-export it.

Each helper raises ``TypeError`` for a value of the wrong kind and
``ValueError`` for one out of range or of the wrong shape; both messages name
the argument (and the shape), e.g. ``"pop_size must be >= 2, got 1"``.
"""

from __future__ import annotations

import numbers
from typing import TypeVar

import numpy as np

# moo's generic core (algorithms, MO-LSP, indicators, runner, ...) does not import robustctl:
# these few array checks are moo's own (robustctl/_validation.py has its own for the control code).

__all__ = ["as_float_array", "as_matrix", "as_objectives", "check_choice", "check_directions", "check_int",
           "check_positive_scalar", "check_real"]


def as_float_array(value, name: str) -> np.ndarray:
    """``value`` as a real float64 array (any shape); ``TypeError`` naming ``name`` otherwise."""
    if isinstance(value, (str, bytes)) or value is None:
        raise TypeError(f"{name} must be an array of numbers, got {type(value).__name__}")
    try:
        arr = np.asarray(value)
        if np.iscomplexobj(arr):
            raise TypeError("complex entries")
        return np.array(arr, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be an array of real numbers ({exc})") from None


def as_matrix(value, name: str, *, rows: int | None = None, cols: int | None = None, rows_what: str = "",
              cols_what: str = "", allow_empty: bool = False) -> np.ndarray:
    """``value`` as a finite float64 2-D array with the given numbers of rows and columns.

    A scalar becomes 1x1 and a 1-D array one row (one column when ``cols == 1``);
    ``rows_what`` / ``cols_what`` say in the message what the expected size is.
    """
    arr = as_float_array(value, name)
    if arr.ndim == 0:
        arr = arr.reshape(1, 1)
    elif arr.ndim == 1:
        arr = arr.reshape(-1, 1) if cols == 1 and rows != 1 else arr.reshape(1, -1)
    elif arr.ndim != 2:
        raise ValueError(f"{name} must be a 2-D matrix, got an array of shape {arr.shape}")
    for axis, want, what in ((0, rows, rows_what), (1, cols, cols_what)):
        if want is not None and arr.shape[axis] != want:
            unit = "rows" if axis == 0 else "columns"
            raise ValueError(f"{name} must have {want} {unit}{f' ({what})' if what else ''}, got shape {arr.shape}")
    if arr.size == 0 and not allow_empty:
        raise ValueError(f"{name} must not be empty, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must have finite entries (found NaN or inf)")
    return arr


def check_int(value, name: str, minimum: int) -> int:
    """An integer ``>= minimum`` (Python ``int`` or any NumPy integer; ``bool`` is refused)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__}")
    if value < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {value}")
    return int(value)


_Choice = TypeVar("_Choice", bound=str)


def check_choice(value, name: str, choices: tuple[_Choice, ...]) -> _Choice:
    """One of the lower-case strings ``choices`` (matched case-insensitively); returned lower-cased.

    The result is the matching entry of ``choices``, so a tuple of ``Literal``
    strings gives a value of that ``Literal`` type.
    """
    if not isinstance(value, str):
        raise TypeError(f"{name} must be one of {', '.join(map(repr, choices))}, got {type(value).__name__}")
    if value.lower() not in choices:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")
    return choices[choices.index(value.lower())]


def _real_scalar(value, name: str, want: str) -> float:
    """A real number (Python or NumPy, or a 0-d real array) as a float, NaN and inf kept; ``bool`` is refused."""
    real_0d = isinstance(value, np.ndarray) and value.shape == () and value.dtype.kind in "iuf"
    if isinstance(value, (bool, np.bool_)) or not (isinstance(value, numbers.Real) or real_0d):
        raise TypeError(f"{name} must be {want}, got {type(value).__name__}")
    return float(value)


def check_real(value, name: str, *, positive: bool) -> float:
    """A finite real number, ``> 0`` if ``positive`` else ``>= 0`` (``bool`` is refused)."""
    x = _real_scalar(value, name, "a real number")
    if not np.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x}")
    if positive and x <= 0:
        raise ValueError(f"{name} must be > 0, got {x}")
    if not positive and x < 0:
        raise ValueError(f"{name} must be >= 0, got {x}")
    return x


def check_positive_scalar(value, name: str, *, allow_inf: bool = False) -> float:
    """A real number > 0, a NumPy 0-d array included (``inf`` only if ``allow_inf``; ``bool`` is refused).

    moo's own copy of :func:`robustctl.validation.check_positive_scalar`, with
    the same checks: the generic core does not import robustctl, and
    :mod:`moo.problems` uses robustctl's.
    """
    x = _real_scalar(value, name, "a real number > 0")
    if np.isnan(x):
        raise ValueError(f"{name} must be a number, got NaN")
    if np.isinf(x) and not (allow_inf and x > 0):
        raise ValueError(f"{name} must be finite, got {x}")
    if x <= 0:
        raise ValueError(f"{name} must be > 0, got {x}")
    return x


def as_objectives(F, name: str = "F") -> np.ndarray:
    """``F`` as a finite, non-empty float64 array of shape ``(n_individuals, n_obj)``."""
    arr = as_float_array(F, name)
    if arr.ndim != 2 or arr.shape[0] < 1 or arr.shape[1] < 1:
        raise ValueError(f"{name} must be a non-empty 2-D array (n_individuals, n_obj), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must have finite entries (found NaN or inf)")
    return arr


def check_directions(W, name: str = "ref_dirs") -> np.ndarray:
    """Weight / reference-direction vectors: a finite, non-negative ``(n_dirs, n_obj)`` array.

    ``n_obj >= 2`` and every row must have a positive sum.
    """
    W = np.asarray(W, dtype=float)
    if W.ndim != 2 or W.shape[0] < 1 or W.shape[1] < 2:
        raise ValueError(f"{name} must be a 2-D array (n_dirs, n_obj) with n_obj >= 2, got shape {W.shape}")
    if not np.all(np.isfinite(W)) or np.any(W < 0) or np.any(W.sum(axis=1) <= 0):
        raise ValueError(f"{name} must be finite, non-negative and each row must have a positive sum")
    return W
