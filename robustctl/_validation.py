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
    """A read-only float64 copy of ``arr`` (the arrays that results and plants hold).

    Parameters
    ----------
    arr : array_like
        Real numbers.

    Returns
    -------
    ndarray
        float64, ``flags.writeable`` False.

    Examples
    --------
    >>> from robustctl._validation import frozen
    >>> a = frozen([1, 2])
    >>> a.dtype.name, a.flags.writeable
    ('float64', False)
    """
    arr = np.array(arr, dtype=np.float64)
    arr.flags.writeable = False
    return arr


def frozen_complex(arr) -> np.ndarray:
    """A read-only complex copy of ``arr``.

    Parameters
    ----------
    arr : array_like
        Complex (or real) numbers.

    Returns
    -------
    ndarray
        complex128, ``flags.writeable`` False.
    """
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

    Parameters
    ----------
    value : array_like
        Real numbers: a number, nested lists, an array (integers, floats,
        objects that are real numbers such as fractions).
    name : str
        The argument's name in the messages.
    want : str, optional
        Phrases the ``TypeError`` as ``"<name> must be <want>, got ..."``
        (e.g. ``"a positive number"``).

    Returns
    -------
    ndarray
        A float64 copy (callers may write into it).

    Raises
    ------
    TypeError
        Booleans, strings, complex numbers, ``None`` and other non-numbers,
        naming ``name``.
    ValueError
        Nested sequences of unequal lengths.

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.validation import as_float_array
    >>> as_float_array([1, 2.5], "x")
    array([1. , 2.5])
    >>> as_float_array([True, 2.0], "x")       # numpy alone would read True as 1.0
    Traceback (most recent call last):
    ...
    TypeError: x must contain real numbers, got booleans
    >>> np.array([True, 2.0]).tolist()
    [1.0, 2.0]
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

    Parameters
    ----------
    value : array_like
        A number, a 1-D or a 2-D array of real numbers.
    name : str
        The argument's name in the messages.
    rows, cols : int, optional
        Required numbers of rows and columns.
    rows_what, cols_what : str
        What the required numbers are, for the messages (e.g. ``"the number of states"``).
    allow_empty : bool
        Accept an array with no entries.
    vector : {"row", "column"}, optional
        How a 1-D array is read.

    Returns
    -------
    (r, c) ndarray
        A float64 copy.

    Raises
    ------
    ValueError
        More than two axes, the wrong number of rows or columns (naming the
        argument, what the number is and the shape), an empty array,
        non-finite entries.
    TypeError
        As :func:`as_float_array`.

    Examples
    --------
    >>> from robustctl.validation import as_matrix
    >>> as_matrix([1.0, 2.0], "H", vector="column")
    array([[1.],
           [2.]])
    >>> as_matrix([[1.0, 2.0, 3.0]], "EF", cols=4, cols_what="the number of states")
    Traceback (most recent call last):
    ...
    ValueError: EF must have 4 columns (the number of states), got shape (1, 3)
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
    """Return ``value`` as a finite float64 array of ``shape`` (``None`` = any size).

    Parameters
    ----------
    value : array_like
        Real numbers.
    name : str
        The argument's name in the messages.
    shape : sequence of int or None
        The required shape; ``None`` leaves an axis free (e.g. a batch axis).
    what : sequence of str
        What each axis counts, for the messages.

    Returns
    -------
    ndarray
        A float64 copy of the required number of axes.

    Raises
    ------
    ValueError
        Another number of axes, a wrong size (naming the axis and what it
        counts), non-finite entries.
    TypeError
        As :func:`as_float_array`.

    Examples
    --------
    >>> from robustctl.validation import as_batch
    >>> as_batch([[1.0, 2.0]], "K", (None, 2)).shape
    (1, 2)
    >>> as_batch([[1.0, 2.0]], "K", (None, 3), ("designs", "the number of states"))
    Traceback (most recent call last):
    ...
    ValueError: K must have size 3 along axis 1 (the number of states), got shape (1, 2)
    """
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
    """``arr`` if it is square (a 2-D array with as many rows as columns).

    Parameters
    ----------
    arr : (r, c) ndarray
        A 2-D array (e.g. from :func:`as_matrix`).
    name : str
        The argument's name in the message.

    Returns
    -------
    ndarray
        ``arr`` itself.

    Raises
    ------
    ValueError
        ``r != c``.

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.validation import check_square
    >>> check_square(np.ones((2, 3)), "F")
    Traceback (most recent call last):
    ...
    ValueError: F must be square, got shape (2, 3)
    """
    if arr.shape[0] != arr.shape[1]:
        raise ValueError(f"{name} must be square, got shape {arr.shape}")
    return arr


def check_spd(arr: np.ndarray, name: str, *, semidefinite: bool = False) -> np.ndarray:
    r"""Check symmetry and positive (semi)definiteness (tolerances above); return the symmetrised matrix.

    Parameters
    ----------
    arr : (n, n) ndarray
        A square matrix (e.g. from :func:`as_matrix`).
    name : str
        The argument's name in the messages.
    semidefinite : bool
        Accept a positive semidefinite matrix (default: definite).

    Returns
    -------
    (n, n) ndarray
        ``(arr + arr') / 2``.

    Raises
    ------
    ValueError
        Not square, not symmetric, or not positive (semi)definite (the
        message gives the smallest eigenvalue).

    Notes
    -----
    With ``s = max(1, max |a_ij|)`` and ``lambda_min`` the smallest
    eigenvalue of the symmetric part, the matrix is accepted when

    .. math::

        \max_{ij} |a_{ij} - a_{ji}| \le 10^{-10} s
        \quad	ext{and}\quad
        \lambda_{\min} > 10^{-14} s \;\; (	ext{definite}), \qquad
        \lambda_{\min} \ge -10^{-12} s \;\; (	ext{semidefinite}).

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.validation import check_spd
    >>> check_spd(np.array([[2.0, 1.0], [1.0, 2.0]]), "Q")
    array([[2., 1.],
           [1., 2.]])
    >>> check_spd(np.array([[1.0, 2.0], [2.0, 1.0]]), "Q")
    Traceback (most recent call last):
    ...
    ValueError: Q must be positive definite (smallest eigenvalue -1)
    >>> float(np.linalg.eigvalsh([[1.0, 2.0], [2.0, 1.0]])[0])
    -1.0
    """
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
    """A real scalar > 0 (``inf`` only if ``allow_inf``); booleans and strings are refused.

    Parameters
    ----------
    value : float
        A Python or numpy number, or a 0-d array.
    name : str
        The argument's name in the messages.
    allow_inf : bool
        Accept ``+inf``.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        NaN, ``inf`` (unless allowed), ``<= 0``.
    TypeError
        Not one real number (booleans, strings, arrays of several entries).

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.validation import check_positive_scalar
    >>> check_positive_scalar(np.float32(0.5), "dt")
    0.5
    >>> check_positive_scalar(0, "dt")
    Traceback (most recent call last):
    ...
    ValueError: dt must be > 0, got 0.0
    """
    x = _scalar(value, name, "a real number > 0")
    if np.isnan(x):
        raise ValueError(f"{name} must be a number, got NaN")
    if np.isinf(x) and not (allow_inf and x > 0):
        raise ValueError(f"{name} must be finite, got {x}")
    if x <= 0:
        raise ValueError(f"{name} must be > 0, got {x}")
    return x


def check_real(value, name: str, *, minimum: float | None = None) -> float:
    """A finite real scalar, ``>= minimum`` if given; booleans, strings and complex numbers are refused.

    Parameters
    ----------
    value : float
        A Python or numpy number, or a 0-d array.
    name : str
        The argument's name in the messages.
    minimum : float, optional
        Smallest accepted value.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        Not finite, or below ``minimum``.
    TypeError
        Not one real number.

    Examples
    --------
    >>> from robustctl.validation import check_real
    >>> check_real(-2, "center")
    -2.0
    >>> check_real(1j, "center")
    Traceback (most recent call last):
    ...
    TypeError: center must be a real number, got complex entries
    """
    x = _scalar(value, name, "a real number")
    if not np.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x}")
    if minimum is not None and x < minimum:
        raise ValueError(f"{name} must be >= {minimum:g}, got {x:g}")
    return x


def check_positive_vector(value, name: str, size: int, *, what: str = "") -> np.ndarray:
    """``size`` finite numbers > 0 as a float array ``(size,)``; one number stands for all of them.

    Parameters
    ----------
    value : float or (size,) array_like
        One number or ``size`` of them.
    name : str
        The argument's name in the messages.
    size : int
        The number of entries.
    what : str
        What ``size`` counts (e.g. ``"the number of inputs"``), for the messages.

    Returns
    -------
    (size,) ndarray

    Raises
    ------
    ValueError
        Another number of entries, non-finite or non-positive entries.
    TypeError
        Non-numeric entries.

    Examples
    --------
    >>> from robustctl.validation import check_positive_vector
    >>> check_positive_vector(2.0, "u_limit", 3)
    array([2., 2., 2.])
    >>> check_positive_vector([1.0, -1.0], "u_limit", 2)
    Traceback (most recent call last):
    ...
    ValueError: u_limit must be > 0 for every entry, got [1.0, -1.0]
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
    """An integer ``>= minimum`` (Python or numpy integer; booleans and floats such as 3.0 are refused).

    Parameters
    ----------
    value : int
        A Python or numpy integer.
    name : str
        The argument's name in the messages.
    minimum : int
        Smallest accepted value.

    Returns
    -------
    int

    Raises
    ------
    TypeError
        Not an integer (a float, even 3.0; a boolean).
    ValueError
        Below ``minimum``.

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.validation import check_int
    >>> check_int(np.int64(3), "n")
    3
    >>> check_int(3.0, "n")
    Traceback (most recent call last):
    ...
    TypeError: n must be a positive integer, got float
    """
    want = "a positive integer" if minimum == 1 else f"an integer >= {minimum}"
    if isinstance(value, _BOOL) or not isinstance(value, (numbers.Integral, np.integer)):
        what = "a boolean" if isinstance(value, _BOOL) else type(value).__name__
        raise TypeError(f"{name} must be {want}, got {what}")
    if value < minimum:
        raise ValueError(f"{name} must be {want}, got {value}")
    return int(value)


def check_bool(value, name: str) -> bool:
    """``True`` or ``False`` (numpy booleans too); anything else, e.g. ``"no"`` or ``0``, is refused.

    Parameters
    ----------
    value : bool
        A Python or numpy boolean.
    name : str
        The argument's name in the message.

    Returns
    -------
    bool

    Raises
    ------
    TypeError
        Anything but a boolean.

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.validation import check_bool
    >>> check_bool(np.True_, "accelerate")
    True
    >>> check_bool(0, "accelerate")
    Traceback (most recent call last):
    ...
    TypeError: accelerate must be a bool (True or False), got 0
    """
    if not isinstance(value, _BOOL):
        raise TypeError(f"{name} must be a bool (True or False), got {value!r}")
    return bool(value)


def as_rng(seed, name: str = "seed") -> np.random.Generator:
    """``np.random.default_rng(seed)`` (``None``, an int >= 0, a SeedSequence, a Generator, ...); booleans refused.

    Parameters
    ----------
    seed : None, int, SeedSequence or Generator
        What :func:`numpy.random.default_rng` takes; a Generator is returned as it is.
    name : str
        The argument's name in the messages.

    Returns
    -------
    numpy.random.Generator

    Raises
    ------
    TypeError
        A boolean, or what ``default_rng`` refuses with a ``TypeError``.
    ValueError
        What ``default_rng`` refuses with a ``ValueError`` (a negative integer).

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.validation import as_rng
    >>> rng = np.random.default_rng()
    >>> as_rng(rng) is rng, type(as_rng(None)).__name__
    (True, 'Generator')
    >>> as_rng(True)
    Traceback (most recent call last):
    ...
    TypeError: seed must be None, an integer >= 0, a SeedSequence or a Generator, got a boolean
    """
    if isinstance(seed, _BOOL):
        raise TypeError(f"{name} must be None, an integer >= 0, a SeedSequence or a Generator, got a boolean")
    try:
        return np.random.default_rng(seed)
    except (TypeError, ValueError) as exc:
        raise type(exc)(f"{name} must be None, an integer >= 0, a SeedSequence or a Generator ({exc})") from None


def check_choice(value, name: str, choices: Collection[str]) -> str:
    """One of the strings ``choices``, matched exactly (case-sensitive); a non-string is a TypeError.

    Parameters
    ----------
    value : str
        The argument.
    name : str
        The argument's name in the messages.
    choices : collection of str
        The accepted values (listed in the messages).

    Returns
    -------
    str

    Raises
    ------
    TypeError
        Not a string.
    ValueError
        Not one of ``choices``.

    Examples
    --------
    >>> from robustctl.validation import check_choice
    >>> check_choice("lhs", "method", ("grid", "lhs"))
    'lhs'
    >>> check_choice("LHS", "method", ("grid", "lhs"))
    Traceback (most recent call last):
    ...
    ValueError: method must be one of 'grid', 'lhs', got 'LHS'
    """
    if not isinstance(value, str):
        raise TypeError(f"{name} must be one of {', '.join(map(repr, choices))}, got {type(value).__name__}")
    if value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")
    return value


def check_performance(n: int, m: int, Bw, Cz, Dzu, Dzw) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Disturbance and performance channels of ``x+ = F x + Bw w + G u``, ``z = Cz x + Dzw w + Dzu u``.

    Parameters
    ----------
    n, m : int
        States and inputs of the plant.
    Bw : (n, q) array_like
        Disturbance input; a 1-D array is one column.
    Cz : (pz, n) array_like
        State part of the performance output.
    Dzu : (pz, m) array_like
        Input part of the performance output.
    Dzw : (pz, q) array_like or None
        Feedthrough from ``w``; None is zero.

    Returns
    -------
    Bw, Cz, Dzu, Dzw : ndarray
        Float copies of the checked shapes.

    Raises
    ------
    ValueError
        Shapes that do not agree (named), non-finite entries.
    """
    Bw = as_matrix(Bw, "Bw", rows=n, vector="column", rows_what="the number of states")
    Cz = as_matrix(Cz, "Cz", cols=n, cols_what="the number of states")
    p, q = Cz.shape[0], Bw.shape[1]
    Dzu = as_matrix(Dzu, "Dzu", rows=p, cols=m, rows_what="rows of Cz", cols_what="the number of inputs")
    Dzw = np.zeros((p, q)) if Dzw is None else as_matrix(
        Dzw, "Dzw", rows=p, cols=q, rows_what="rows of Cz", cols_what="columns of Bw")
    return Bw, Cz, Dzu, Dzw
