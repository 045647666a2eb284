"""Argument checks shared by every public function.

Each helper raises ``ValueError``/``TypeError`` whose message names the
argument and, for shapes, both the expected and the actual shape, e.g.
``"EF must have 4 columns (the number of states), got shape (1, 3)"``.
Numbers are real numbers: booleans, strings (even ``"1.5"``), complex
values and ``None`` are refused with a ``TypeError``, nested lists of
unequal lengths with a ``ValueError``; non-finite entries are refused where
the helper says so. :mod:`robustctl.validation` makes these public.
"""

from __future__ import annotations

import numbers
from collections.abc import Collection, Sequence
from typing import NoReturn

import numpy as np

__all__ = ["as_float_array", "as_matrix", "as_batch", "check_square", "check_spd", "check_positive_scalar",
           "check_real", "check_positive_vector", "check_int", "check_bool", "check_choice", "as_rng",
           "check_performance", "frozen", "frozen_complex"]

#: Symmetry accepted by :func:`check_spd` (relative to the largest entry, at least 1).
SYMMETRY_TOL = 1e-10
#: Smallest eigenvalue accepted as semidefinite (``>= -PSD_TOL * scale``) and as definite (``> PD_TOL * scale``).
PSD_TOL = 1e-12
PD_TOL = 1e-14

_BOOL = (bool, np.bool_)


def frozen(arr) -> np.ndarray:
    """A read-only float64 copy of ``arr`` (the arrays that results and plants hold)."""
    arr = np.array(arr, dtype=np.float64)
    arr.flags.writeable = False
    return arr


def frozen_complex(arr) -> np.ndarray:
    """A read-only complex copy of ``arr``."""
    arr = np.array(arr, dtype=complex)
    arr.flags.writeable = False
    return arr


def _has_bool(seq) -> bool:
    """Any boolean inside nested lists/tuples (numpy silently turns ``[True, 2.0]`` into ``[1.0, 2.0]``)."""
    stack = [seq]
    while stack:
        for item in stack.pop():
            if isinstance(item, _BOOL) or (isinstance(item, np.ndarray) and item.dtype.kind == "b"):
                return True
            if isinstance(item, (list, tuple)):
                stack.append(item)
    return False


def as_float_array(value, name: str, *, want: str | None = None) -> np.ndarray:
    """``value`` as a real float64 array of any shape (finite or not).

    Raises ``TypeError`` naming ``name`` for booleans, strings, complex
    numbers, ``None`` and other non-numbers, and ``ValueError`` for nested
    sequences of unequal lengths. ``want`` (e.g. ``"a positive number"``)
    phrases the ``TypeError`` as ``"<name> must be <want>, got ..."``.
    """
    def refuse(what: str, default: str) -> NoReturn:
        raise TypeError(f"{name} must be {want}, got {what}" if want else default)

    if value is None or isinstance(value, (str, bytes, *_BOOL)):
        what = "a boolean" if isinstance(value, _BOOL) else type(value).__name__
        refuse(what, f"{name} must be an array of numbers (or one number), got {what}")
    if isinstance(value, (list, tuple)):
        try:
            arr = np.array(value)
        except ValueError:  # numpy >= 1.24: "inhomogeneous shape"
            raise ValueError(f"{name} must be a rectangular array: its nested sequences have different "
                             "lengths") from None
        if arr.dtype.kind in "iuf" and _has_bool(value):
            refuse("booleans", f"{name} must contain real numbers, got booleans")
    else:
        arr = np.asarray(value)
    kind = arr.dtype.kind
    if kind == "O":  # objects: accept real numbers only (e.g. fractions), never booleans
        items = arr.ravel().tolist()
        if all(isinstance(x, numbers.Real) and not isinstance(x, _BOOL) for x in items):
            return arr.astype(np.float64)
        bad = next(x for x in items if not (isinstance(x, numbers.Real) and not isinstance(x, _BOOL)))
        what = f"an entry of type {type(bad).__name__}"
        refuse(what, f"{name} must contain real numbers, got {what}")
    if kind not in "iuf":
        what = {"b": "booleans", "c": "complex entries", "U": "strings", "S": "strings"}.get(
            kind, f"entries of dtype {arr.dtype}")
        refuse(what, f"{name} must contain real numbers, got {what}")
    return np.array(arr, dtype=np.float64)  # a copy: callers may write into it


def _check_finite(arr: np.ndarray, name: str) -> None:
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must have finite entries (found NaN or inf)")


def as_matrix(
    value,
    name: str,
    *,
    rows: int | None = None,
    cols: int | None = None,
    rows_what: str = "",
    cols_what: str = "",
    allow_empty: bool = False,
    vector: str | None = None,
) -> np.ndarray:
    """Return ``value`` as a finite float64 2-D array, checking its shape.

    Scalars become 1x1. A 1-D array becomes a column if ``vector="column"``,
    a row if ``vector="row"``; by default a row, except when ``cols == 1``
    (then a column).
    """
    arr = as_float_array(value, name)
    if arr.ndim == 0:
        arr = arr.reshape(1, 1)
    elif arr.ndim == 1:
        column = vector == "column" or (vector is None and cols == 1 and rows != 1)
        arr = arr.reshape(-1, 1) if column else arr.reshape(1, -1)
    elif arr.ndim != 2:
        raise ValueError(f"{name} must be a 2-D matrix, got an array of shape {arr.shape}")
    if rows is not None and arr.shape[0] != rows:
        what = f" ({rows_what})" if rows_what else ""
        raise ValueError(f"{name} must have {rows} rows{what}, got shape {arr.shape}")
    if cols is not None and arr.shape[1] != cols:
        what = f" ({cols_what})" if cols_what else ""
        raise ValueError(f"{name} must have {cols} columns{what}, got shape {arr.shape}")
    if arr.size == 0 and not allow_empty:
        raise ValueError(f"{name} must not be empty, got shape {arr.shape}")
    _check_finite(arr, name)
    return arr


def as_batch(value, name: str, shape: Sequence[int | None], what: Sequence[str] = ()) -> np.ndarray:
    """Return ``value`` as a finite float64 array of ``shape`` (``None`` = any size)."""
    arr = as_float_array(value, name)
    if arr.ndim != len(shape):
        raise ValueError(f"{name} must be a {len(shape)}-D array of shape "
                         f"{tuple('B' if s is None else s for s in shape)}, got shape {arr.shape}")
    for axis, (want, got) in enumerate(zip(shape, arr.shape, strict=True)):
        if want is not None and want != got:
            label = f" ({what[axis]})" if axis < len(what) and what[axis] else ""
            raise ValueError(f"{name} must have size {want} along axis {axis}{label}, "
                             f"got shape {arr.shape}")
    _check_finite(arr, name)
    return arr


def check_square(arr: np.ndarray, name: str) -> np.ndarray:
    if arr.shape[0] != arr.shape[1]:
        raise ValueError(f"{name} must be square, got shape {arr.shape}")
    return arr


def check_spd(arr: np.ndarray, name: str, *, semidefinite: bool = False) -> np.ndarray:
    """Check symmetry and positive (semi)definiteness (tolerances above); return the symmetrised matrix."""
    check_square(arr, name)
    scale = max(1.0, float(np.max(np.abs(arr))))
    if np.max(np.abs(arr - arr.T)) > SYMMETRY_TOL * scale:
        raise ValueError(f"{name} must be symmetric")
    sym = 0.5 * (arr + arr.T)
    eig_min = float(np.linalg.eigvalsh(sym).min())
    if semidefinite and eig_min < -PSD_TOL * scale:
        raise ValueError(f"{name} must be positive semidefinite (smallest eigenvalue {eig_min:.3g})")
    if not semidefinite and eig_min <= PD_TOL * scale:
        raise ValueError(f"{name} must be positive definite (smallest eigenvalue {eig_min:.3g})")
    return sym


def _scalar(value, name: str, want: str) -> float:
    """A real scalar (Python or numpy number, 0-d array) as a float, NaN and inf kept."""
    arr = as_float_array(value, name, want=want)
    if arr.shape != ():
        raise TypeError(f"{name} must be {want}, got an array of shape {arr.shape}")
    return float(arr)


def check_positive_scalar(value, name: str, *, allow_inf: bool = False) -> float:
    """A real scalar > 0 (``inf`` only if ``allow_inf``); booleans and strings are refused."""
    x = _scalar(value, name, "a real number > 0")
    if np.isnan(x):
        raise ValueError(f"{name} must be a number, got NaN")
    if np.isinf(x) and not (allow_inf and x > 0):
        raise ValueError(f"{name} must be finite, got {x}")
    if x <= 0:
        raise ValueError(f"{name} must be > 0, got {x}")
    return x


def check_real(value, name: str, *, minimum: float | None = None) -> float:
    """A finite real scalar, ``>= minimum`` if given; booleans, strings and complex numbers are refused."""
    x = _scalar(value, name, "a real number")
    if not np.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x}")
    if minimum is not None and x < minimum:
        raise ValueError(f"{name} must be >= {minimum:g}, got {x:g}")
    return x


def check_positive_vector(value, name: str, size: int, *, what: str = "") -> np.ndarray:
    """``size`` finite numbers > 0 as a float array ``(size,)``; one number stands for all of them.

    ``what`` says what ``size`` counts (e.g. ``"the number of inputs"``).
    """
    want = "a positive number" + ("" if size == 1 else f" or {size} positive numbers")
    arr = as_float_array(value, name, want=want)
    if arr.ndim == 0:
        arr = np.full(size, float(arr))
    if arr.shape != (size,):
        label = f" ({what})" if what else ""
        raise ValueError(f"{name} must be a scalar or have {size} {'entry' if size == 1 else 'entries'}{label}, "
                         f"got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {arr.tolist()}")
    if np.any(arr <= 0):
        raise ValueError(f"{name} must be > 0 for every entry, got {arr.tolist()}")
    return arr


def check_int(value, name: str, minimum: int = 1) -> int:
    """An integer ``>= minimum`` (Python or numpy integer; booleans and floats such as 3.0 are refused)."""
    want = "a positive integer" if minimum == 1 else f"an integer >= {minimum}"
    if isinstance(value, _BOOL) or not isinstance(value, (numbers.Integral, np.integer)):
        what = "a boolean" if isinstance(value, _BOOL) else type(value).__name__
        raise TypeError(f"{name} must be {want}, got {what}")
    if value < minimum:
        raise ValueError(f"{name} must be {want}, got {value}")
    return int(value)


def check_bool(value, name: str) -> bool:
    """``True`` or ``False`` (numpy booleans too); anything else, e.g. ``"no"`` or ``0``, is refused."""
    if not isinstance(value, _BOOL):
        raise TypeError(f"{name} must be a bool (True or False), got {value!r}")
    return bool(value)


def as_rng(seed, name: str = "seed") -> np.random.Generator:
    """``np.random.default_rng(seed)`` (``None``, an int >= 0, a SeedSequence, a Generator, ...); booleans refused."""
    if isinstance(seed, _BOOL):
        raise TypeError(f"{name} must be None, an integer >= 0, a SeedSequence or a Generator, got a boolean")
    try:
        return np.random.default_rng(seed)
    except (TypeError, ValueError) as exc:
        raise type(exc)(f"{name} must be None, an integer >= 0, a SeedSequence or a Generator ({exc})") from None


def check_choice(value, name: str, choices: Collection[str]) -> str:
    """One of the strings ``choices``, matched exactly (case-sensitive); a non-string is a TypeError."""
    if not isinstance(value, str):
        raise TypeError(f"{name} must be one of {', '.join(map(repr, choices))}, got {type(value).__name__}")
    if value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")
    return value


def check_performance(n: int, m: int, Bw, Cz, Dzu, Dzw) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Disturbance and performance channels of ``x+ = F x + Bw w + G u``, ``z = Cz x + Dzw w + Dzu u``.

    Returns float arrays ``(Bw, Cz, Dzu, Dzw)``; ``Dzw=None`` is zero; a 1-D ``Bw`` is one column.
    """
    Bw = as_matrix(Bw, "Bw", rows=n, vector="column", rows_what="the number of states")
    Cz = as_matrix(Cz, "Cz", cols=n, cols_what="the number of states")
    p, q = Cz.shape[0], Bw.shape[1]
    Dzu = as_matrix(Dzu, "Dzu", rows=p, cols=m, rows_what="rows of Cz", cols_what="the number of inputs")
    Dzw = np.zeros((p, q)) if Dzw is None else as_matrix(
        Dzw, "Dzw", rows=p, cols=q, rows_what="rows of Cz", cols_what="columns of Bw")
    return Bw, Cz, Dzu, Dzw
