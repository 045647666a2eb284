"""Argument checks shared by the ``moo`` modules.

Each helper raises ``TypeError`` for a value of the wrong kind and
``ValueError`` for one out of range or of the wrong shape; both messages name
the argument (and the shape), e.g. ``"pop_size must be >= 2, got 1"``.
"""

from __future__ import annotations

import numbers

import numpy as np

# Generic array checks (no control code) are shared with robustctl: this is the
# one import of robustctl in moo outside moo/problems/.
from robustctl._validation import as_float_array, as_matrix, check_positive_scalar

__all__ = ["as_float_array", "as_matrix", "as_objectives", "check_choice", "check_directions", "check_int",
           "check_positive_scalar", "check_real"]


def check_int(value, name: str, minimum: int) -> int:
    """An integer ``>= minimum`` (Python ``int`` or any NumPy integer; ``bool`` is refused)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__}")
    if value < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {value}")
    return int(value)


def check_choice(value, name: str, choices: tuple[str, ...]) -> str:
    """One of the lower-case strings ``choices`` (matched case-insensitively); returned lower-cased."""
    if not isinstance(value, str) or value.lower() not in choices:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")
    return value.lower()


def check_real(value, name: str, *, positive: bool) -> float:
    """A finite real number, ``> 0`` if ``positive`` else ``>= 0`` (``bool`` is refused)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__}")
    x = float(value)
    if not np.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x}")
    if positive and x <= 0:
        raise ValueError(f"{name} must be > 0, got {x}")
    if not positive and x < 0:
        raise ValueError(f"{name} must be >= 0, got {x}")
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
    """Weight / reference-direction vectors: a finite, non-negative ``(n_dirs, n_obj)`` array,
    ``n_obj >= 2``, every row with a positive sum."""
    W = np.asarray(W, dtype=float)
    if W.ndim != 2 or W.shape[0] < 1 or W.shape[1] < 2:
        raise ValueError(f"{name} must be a 2-D array (n_dirs, n_obj) with n_obj >= 2, got shape {W.shape}")
    if not np.all(np.isfinite(W)) or np.any(W < 0) or np.any(W.sum(axis=1) <= 0):
        raise ValueError(f"{name} must be finite, non-negative and each row must have a positive sum")
    return W
