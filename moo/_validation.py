"""Scalar argument checks shared by the ``moo`` modules.

Each helper raises ``TypeError`` for a value of the wrong kind and
``ValueError`` for one out of range; both messages name the argument, e.g.
``"pop_size must be >= 2, got 1"``. Array checks live in
``robustctl._validation`` (used by :mod:`moo.problems`).
"""

from __future__ import annotations

import numbers

import numpy as np

__all__ = ["check_choice", "check_int", "check_real"]


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
