"""Argument checks shared by every public function.

Each helper raises ``ValueError``/``TypeError`` whose message names the
argument and, for shapes, both the expected and the actual shape, e.g.
``"EF must have 4 columns (the number of states), got shape (1, 3)"``.
"""

from __future__ import annotations

import numbers
from collections.abc import Sequence

import numpy as np

__all__ = ["as_float_array", "as_matrix", "as_batch", "check_square", "check_spd", "check_positive_scalar",
           "check_performance"]


def as_float_array(value, name: str) -> np.ndarray:
    """``value`` as a real float64 array (any shape); ``TypeError`` naming ``name`` otherwise."""
    if isinstance(value, (str, bytes)) or value is None:
        raise TypeError(f"{name} must be an array of numbers, got {type(value).__name__}")
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be an array of real numbers ({exc})") from None
    if np.iscomplexobj(np.asarray(value)):
        raise TypeError(f"{name} must be real, got complex entries")
    return arr


def as_matrix(
    value,
    name: str,
    *,
    rows: int | None = None,
    cols: int | None = None,
    rows_what: str = "",
    cols_what: str = "",
    allow_empty: bool = False,
) -> np.ndarray:
    """Return ``value`` as a finite float64 2-D array, checking its shape.

    Scalars become 1x1 and 1-D arrays become a single row, except when
    ``cols == 1`` (a 1-D array is then read as a column).
    """
    arr = as_float_array(value, name)
    if arr.ndim == 0:
        arr = arr.reshape(1, 1)
    elif arr.ndim == 1:
        arr = arr.reshape(-1, 1) if cols == 1 and rows != 1 else arr.reshape(1, -1)
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
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must have finite entries (found NaN or inf)")
    return arr


def as_batch(value, name: str, shape: Sequence[int | None], what: Sequence[str] = ()) -> np.ndarray:
    """Return ``value`` as a finite float64 array of ``shape`` (``None`` = any size)."""
    arr = as_float_array(value, name)
    if arr.ndim != len(shape):
        raise ValueError(f"{name} must be a {len(shape)}-D array of shape "
                         f"{tuple('B' if s is None else s for s in shape)}, got shape {arr.shape}")
    for axis, (want, got) in enumerate(zip(shape, arr.shape)):
        if want is not None and want != got:
            label = f" ({what[axis]})" if axis < len(what) and what[axis] else ""
            raise ValueError(f"{name} must have size {want} along axis {axis}{label}, "
                             f"got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must have finite entries (found NaN or inf)")
    return arr


def check_square(arr: np.ndarray, name: str) -> np.ndarray:
    if arr.shape[0] != arr.shape[1]:
        raise ValueError(f"{name} must be square, got shape {arr.shape}")
    return arr


def check_spd(arr: np.ndarray, name: str, *, semidefinite: bool = False) -> np.ndarray:
    """Check symmetry (relative 1e-10) and positive (semi)definiteness; return the symmetrised matrix."""
    check_square(arr, name)
    scale = max(1.0, float(np.max(np.abs(arr))))
    if np.max(np.abs(arr - arr.T)) > 1e-10 * scale:
        raise ValueError(f"{name} must be symmetric")
    sym = 0.5 * (arr + arr.T)
    eig_min = float(np.linalg.eigvalsh(sym).min())
    if semidefinite and eig_min < -1e-12 * scale:
        raise ValueError(f"{name} must be positive semidefinite (smallest eigenvalue {eig_min:.3g})")
    if not semidefinite and eig_min <= 1e-14 * scale:
        raise ValueError(f"{name} must be positive definite (smallest eigenvalue {eig_min:.3g})")
    return sym


def check_positive_scalar(value, name: str, *, allow_inf: bool = False) -> float:
    """A real scalar > 0 (``inf`` only if ``allow_inf``)."""
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, np.floating, np.integer)):
        arr = np.asarray(value)
        if arr.shape != () or not np.issubdtype(arr.dtype, np.number) or np.iscomplexobj(arr):
            raise TypeError(f"{name} must be a real scalar, got {type(value).__name__}")
    x = float(value)
    if np.isnan(x):
        raise ValueError(f"{name} must be a number, got NaN")
    if np.isinf(x) and not (allow_inf and x > 0):
        raise ValueError(f"{name} must be finite, got {x}")
    if x <= 0:
        raise ValueError(f"{name} must be > 0, got {x}")
    return x


def check_performance(n: int, m: int, Bw, Cz, Dzu, Dzw):
    """Disturbance and performance channels of ``x+ = F x + Bw w + G u``, ``z = Cz x + Dzw w + Dzu u``.

    Returns float arrays ``(Bw, Cz, Dzu, Dzw)``; ``Dzw=None`` is zero.
    """
    Bw = as_matrix(Bw, "Bw", rows=n, cols=1 if np.ndim(Bw) == 1 else None, rows_what="the number of states")
    Cz = as_matrix(Cz, "Cz", cols=n, cols_what="the number of states")
    p, q = Cz.shape[0], Bw.shape[1]
    Dzu = as_matrix(Dzu, "Dzu", rows=p, cols=m, rows_what="rows of Cz", cols_what="the number of inputs")
    Dzw = np.zeros((p, q)) if Dzw is None else as_matrix(
        Dzw, "Dzw", rows=p, cols=q, rows_what="rows of Cz", cols_what="columns of Bw")
    return Bw, Cz, Dzu, Dzw
