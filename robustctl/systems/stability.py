"""Stability tests shared by every design and tuning problem.

One tolerance for "stable": a discrete-time matrix ``A`` is Schur stable
when its spectral radius is below ``1 - STABILITY_MARGIN``; a continuous-time
one (Hurwitz) when every eigenvalue has real part below ``-STABILITY_MARGIN``.
The margin keeps a loop with a pole on the unit circle up to rounding (an
integrator left in place, ``rho = 1 - 1e-15``) from counting as stable.
Every stability decision of :mod:`robustctl` goes through :func:`is_stable`
or :func:`is_schur_stable` (designs, internal checks of the LMI gains, the
Riccati reference, the robust analysis and the worst-case search).

A plant ``(F, G)`` is stabilisable when every mode that is not stable can be
moved by the input: ``rank [F - lambda I, G] = n`` at each eigenvalue
``lambda`` of ``F`` on or outside the stability boundary, the
Popov-Belevitch-Hautus test (Hautus 1969; Zhou, Doyle & Glover, *Robust and
Optimal Control*, 1996, Thm 3.2). With ``s = max(1, ||[F G]||_2)``:

* a mode counts as not stable when ``|lambda| >= 1 - UNSTABLE_TOL s``
  (discrete) or ``Re lambda >= -UNSTABLE_TOL s`` (continuous): the computed
  eigenvalues are exact only to about ``eps ||F||`` (a backward stable
  eigensolver), so a mode on the boundary (an integrator left in place) is
  found within a distance that grows with the norm, in either time domain
  (a plant with ``||F|| = 1e6`` puts an exact ``lambda = 1`` or ``0`` at
  ``1e-10`` from it);
* the input cannot move it when the smallest singular value of
  ``[F - lambda I, G]`` is at most ``PBH_TOL s``.

:func:`immovable_modes` is the test at any chosen eigenvalues (also used for
the reachability of pole regions, :mod:`robustctl.systems.regions`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.linalg

from .._validation import as_float_array, as_matrix, check_square
from ..errors import NotDetectableError, NotStabilizableError

__all__ = ["STABILITY_MARGIN", "spectral_radius", "spectral_abscissa", "is_schur_stable", "is_stable",
           "stability_of_eigenvalues", "immovable_modes", "unstabilizable_modes", "check_stabilizable",
           "undetectable_modes", "check_detectable"]

#: A discrete loop is stable when ``rho(A) < 1 - STABILITY_MARGIN``.
STABILITY_MARGIN = 1e-9
#: Modes with ``|lambda| >= 1 - UNSTABLE_TOL s`` (``Re lambda >= -UNSTABLE_TOL s``) must be controllable,
#: ``s = max(1, ||[F G]||_2)``.
UNSTABLE_TOL = 1e-12
#: PBH rank test: rank deficient when the smallest singular value is at most ``PBH_TOL * max(1, ||[F G]||)``.
PBH_TOL = 1e-9
# Batches of at most this many matrices get eigenvalues directly (cheaper than the squaring certificate).
_EIG_BATCH = 8
_SQUARINGS = 10


def _stack(A, name: str = "A") -> np.ndarray:
    A = as_float_array(A, name)
    if A.ndim < 2 or A.shape[-1] != A.shape[-2]:
        raise ValueError(f"{name} must be a square matrix or a stack of them (..., n, n), got shape {A.shape}")
    return A


def _largest(A: np.ndarray, measure) -> np.ndarray:
    """``max measure(eig(A))`` of each matrix of a stack (B, n, n); ``inf`` where an entry is not finite."""
    out = np.full(A.shape[0], np.inf)
    finite = np.isfinite(A).all(axis=(1, 2))
    if finite.any():
        out[finite] = measure(np.linalg.eigvals(A[finite])).max(axis=1)
    return out


def _radius(A: np.ndarray) -> np.ndarray:
    """Spectral radius of a stack (B, n, n); ``inf`` where an entry is not finite."""
    return _largest(A, np.abs)


def _per_matrix(A, measure) -> np.ndarray | float:
    A = _stack(A)
    out = _largest(A.reshape(-1, *A.shape[-2:]), measure).reshape(A.shape[:-2])
    return float(out) if out.ndim == 0 else out


def spectral_radius(A) -> np.ndarray | float:
    r"""``max |eig(A)|`` of a matrix (n, n) or of each matrix of a stack (..., n, n).

    Parameters
    ----------
    A : (n, n) or (..., n, n) array_like
        A square matrix or a stack of them.

    Returns
    -------
    float or ndarray
        A float for one matrix, else an array of the leading shape ``(...)``;
        ``inf`` for a matrix with a non-finite entry.

    Raises
    ------
    ValueError
        ``A`` is not square in its last two axes.
    TypeError
        A non-numeric entry.

    See Also
    --------
    is_schur_stable : the stability test on the radius.
    spectral_abscissa : ``max Re eig(A)``, for continuous time.

    Notes
    -----
    .. math::

        \rho(A) = \max_i |\lambda_i(A)|,

    from the eigenvalues of the whole stack at once (``numpy.linalg.eigvals``).

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> A = np.array([[[0.5, 1.0], [0.0, -0.9]], [[1.0, 0.1], [0.0, 0.3]]])
    >>> rc.spectral_radius(A)
    array([0.9, 1. ])
    >>> bool(np.allclose(rc.spectral_radius(A), [max(abs(np.diag(a))) for a in A]))   # triangular
    True
    """
    return _per_matrix(A, np.abs)


def spectral_abscissa(A) -> np.ndarray | float:
    """``max Re eig(A)`` of a matrix (n, n) or of each matrix of a stack (..., n, n) (continuous time).

    Parameters
    ----------
    A : (n, n) or (..., n, n) array_like
        A square matrix or a stack of them.

    Returns
    -------
    float or ndarray
        A float for one matrix, else an array of the leading shape; ``inf``
        for a matrix with a non-finite entry.

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.systems.stability import spectral_abscissa
    >>> A = [[-1.0, 5.0], [0.0, -2.0]]
    >>> spectral_abscissa(A)
    -1.0
    >>> bool(spectral_abscissa(A) == max(np.linalg.eigvals(A).real))
    True
    """
    return _per_matrix(A, np.real)


def _schur(A: np.ndarray, bound: float) -> np.ndarray:
    """``rho(A) < bound`` for a stack (B, n, n).

    Certificate first: ``rho(M) <= ||M^k||_F``, so ``||(A/bound)^(2^j)||_F < 1``
    for some ``j`` proves stability with a few stacked products; only the
    matrices left undecided get eigenvalues.
    """
    if A.shape[0] <= _EIG_BATCH:
        return _radius(A) < bound
    M = A / bound
    stable = np.zeros(A.shape[0], dtype=bool)
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(_SQUARINGS):
            stable |= np.sqrt(np.add.reduce(M * M, axis=(1, 2))) < 1.0
            if stable.all():
                return stable
            M = M @ M
    undecided = ~stable
    stable[undecided] = _radius(A[undecided]) < bound
    return stable


def is_schur_stable(A, margin: float = STABILITY_MARGIN) -> np.ndarray | bool:
    r"""``rho(A) < 1 - margin`` for a matrix or each matrix of a stack (..., n, n).

    The one test of discrete-time stability of :mod:`robustctl` (module
    docstring); the margin keeps a pole on the unit circle up to rounding
    from counting as stable.

    Parameters
    ----------
    A : (n, n) or (..., n, n) array_like
        A square matrix or a stack of them.
    margin : float, optional
        Required distance of the spectral radius below 1 (default
        ``STABILITY_MARGIN``, 1e-9).

    Returns
    -------
    bool or ndarray of bool
        A bool for one matrix, else an array of the leading shape; False for
        a matrix with a non-finite entry.

    Raises
    ------
    ValueError
        ``A`` is not square in its last two axes.

    See Also
    --------
    spectral_radius : the radius itself.
    is_stable : one matrix, discrete or continuous time.

    Notes
    -----
    A stack of more than a few matrices is decided first by the certificate

    .. math::

        \rho(A) \le \| A^{k} \|_F^{1/k}, \qquad k = 2^j,

    with a few stacked squarings of ``A / (1 - margin)``; only the
    matrices it leaves undecided get eigenvalues.

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> A = np.array([[[0.5, 1.0], [0.0, -0.9]], [[1.0, 0.1], [0.0, 0.3]]])   # an integrator in the second
    >>> rc.is_schur_stable(A)
    array([ True, False])
    >>> bool(np.array_equal(rc.is_schur_stable(A), abs(np.linalg.eigvals(A)).max(axis=1) < 1 - 1e-9))
    True
    """
    A = _stack(A)
    out = _schur(A.reshape(-1, *A.shape[-2:]), 1.0 - margin).reshape(A.shape[:-2])
    return bool(out) if out.ndim == 0 else out


def stability_of_eigenvalues(lam, *, discrete: bool,
                             margin: float = STABILITY_MARGIN) -> tuple[np.ndarray, np.ndarray]:
    """``(nominal, stable)`` of eigenvalues already computed, ``lam`` (..., n), row by row.

    Parameters
    ----------
    lam : (..., n) array_like
        Eigenvalues, one row per matrix.
    discrete : bool
        Discrete time (spectral radius) or continuous time (abscissa).
    margin : float, optional
        The margin of :func:`is_stable` (default ``STABILITY_MARGIN``).

    Returns
    -------
    nominal : (...) ndarray
        The spectral radius (``discrete``) or abscissa of each row.
    stable : (...) ndarray of bool
        Whether it is below ``1 - margin`` (resp. ``-margin``), the rule of :func:`is_stable`.

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.systems.stability import stability_of_eigenvalues
    >>> radius, stable = stability_of_eigenvalues([[0.5, -0.9], [1.0, 0.3]], discrete=True)
    >>> radius.tolist(), stable.tolist()
    ([0.9, 1.0], [True, False])
    """
    lam = np.asarray(lam)
    nominal = np.abs(lam).max(axis=-1) if discrete else lam.real.max(axis=-1)
    return nominal, nominal < ((1.0 - margin) if discrete else -margin)


def is_stable(A, *, discrete: bool, margin: float = STABILITY_MARGIN) -> bool:
    """One matrix: Schur stable (``discrete``) or Hurwitz stable (every ``Re lambda < -margin``).

    Parameters
    ----------
    A : (n, n) array_like
        One square matrix.
    discrete : bool
        Discrete time (:func:`is_schur_stable`) or continuous time.
    margin : float, optional
        Required distance from the stability boundary (default ``STABILITY_MARGIN``).

    Returns
    -------
    bool

    Raises
    ------
    ValueError
        ``A`` is not one square matrix.

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.systems.stability import is_stable
    >>> A = [[-1.0, 5.0], [0.0, -2.0]]
    >>> is_stable(A, discrete=False), is_stable(A, discrete=True)
    (True, False)
    >>> bool(max(np.linalg.eigvals(A).real) < 0)
    True
    """
    A = _stack(A)
    if A.ndim != 2:
        raise ValueError(f"A must be one square matrix, got shape {A.shape}")
    if discrete:
        return bool(is_schur_stable(A, margin))
    return bool(spectral_abscissa(A) < -margin)


def _pair(F, G) -> tuple[np.ndarray, np.ndarray, float]:
    """``(D^-1 F D, D^-1 G, max(1, ||[D^-1 F D  D^-1 G]||_2))`` after checking their shapes, ``D`` balancing ``F``.

    Eigenvalues and the PBH rank are invariant under a change of state
    coordinates, but the test's tolerances are relative to ``||[F G]||``: a
    plant in badly chosen units (states scaled 1e-8..1e8, so ``||F||`` is huge
    while its eigenvalues are not) would be refused although its modes are all
    controllable. Balancing ``F`` (LAPACK ``gebal``, powers of two, so exact;
    Parlett & Reinsch, *Numer. Math.* 13, 1969) undoes such a scaling first; a
    balanced plant is tested as given.
    """
    F = check_square(as_matrix(F, "F"), "F")
    G = as_matrix(G, "G", rows=F.shape[0], vector="column", rows_what="the number of states, from F")
    if np.all(np.isfinite(F)) and np.all(np.isfinite(G)):
        _, (d, _) = scipy.linalg.matrix_balance(F, permute=False, separate=True)
        if not np.all(d == 1.0):
            F, G = F / d[:, None] * d[None, :], G / d[:, None]
    return F, G, max(1.0, float(np.linalg.norm(np.hstack([F, G]), 2)))


def _immovable(F: np.ndarray, G: np.ndarray, scale: float, modes: np.ndarray) -> np.ndarray:
    n = F.shape[0]
    stuck = [lam for lam in modes
             if np.linalg.svd(np.hstack([F - lam * np.eye(n), G]), compute_uv=False)[-1] <= PBH_TOL * scale]
    return np.array(stuck, dtype=complex)


def immovable_modes(F, G, concerned: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """Eigenvalues ``lambda`` of ``F`` with ``concerned(lambda)`` that no gain ``u = K x`` moves (PBH test).

    The rank rule is that of the module docstring. The eigenvalues of
    ``F + G K`` are those of ``F`` not returned plus any the gain places
    (Wonham's pole assignment).

    Parameters
    ----------
    F : (n, n) array_like
        State matrix.
    G : (n, m) array_like
        Input matrix.
    concerned : callable
        Maps the (complex) eigenvalues of ``F`` to a boolean mask, e.g.
        "outside a pole region".

    Returns
    -------
    ndarray of complex
        The concerned eigenvalues that ``G`` cannot move (empty if none).

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.systems.stability import immovable_modes
    >>> F, G = np.diag([2.0, 0.5]), [[0.0], [1.0]]
    >>> immovable_modes(F, G, lambda lam: abs(lam) > 0.4)
    array([2.+0.j])
    >>> int(np.linalg.matrix_rank(np.hstack([F - 2.0 * np.eye(2), G])))
    1
    """
    F, G, scale = _pair(F, G)
    modes = np.linalg.eigvals(F)
    return _immovable(F, G, scale, modes[np.asarray(concerned(modes), dtype=bool)])


def unstabilizable_modes(F, G, *, discrete: bool = True) -> np.ndarray:
    """Eigenvalues of ``F`` that are not stable and that ``G`` cannot move (PBH test, module docstring).

    Parameters
    ----------
    F : (n, n) array_like
        State matrix.
    G : (n, m) array_like
        Input matrix.
    discrete : bool, default True
        Unstable means ``|lambda| >= 1`` (discrete) or ``Re lambda >= 0``,
        up to the tolerance of the module docstring.

    Returns
    -------
    ndarray of complex
        Empty for a stabilisable pair.

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.systems.stability import unstabilizable_modes
    >>> F, G = np.diag([2.0, 0.5]), [[0.0], [1.0]]
    >>> unstabilizable_modes(F, G)
    array([2.+0.j])
    >>> int(np.linalg.matrix_rank(np.hstack([F - 2.0 * np.eye(2), G])))
    1
    """
    F, G, scale = _pair(F, G)
    modes = np.linalg.eigvals(F)
    edge = UNSTABLE_TOL * scale
    unstable = np.abs(modes) >= 1.0 - edge if discrete else modes.real >= -edge
    return _immovable(F, G, scale, modes[unstable])


def undetectable_modes(F, C, *, discrete: bool = True) -> np.ndarray:
    """Eigenvalues of ``F`` that are not stable and that ``C`` does not see (PBH test on ``(F', C')``).

    Parameters
    ----------
    F : (n, n) array_like
        State matrix.
    C : (p, n) array_like
        Output matrix.
    discrete : bool, default True
        As in :func:`unstabilizable_modes`.

    Returns
    -------
    ndarray of complex
        Empty for a detectable pair.

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.systems.stability import undetectable_modes
    >>> F, C = np.diag([2.0, 0.5]), [[0.0, 1.0]]
    >>> undetectable_modes(F, C)
    array([2.+0.j])
    >>> int(np.linalg.matrix_rank(np.vstack([F - 2.0 * np.eye(2), C])))
    1
    """
    F = check_square(as_matrix(F, "F"), "F")
    C = as_matrix(C, "C", cols=F.shape[0], cols_what="the number of states, from F")
    return unstabilizable_modes(F.T, C.T, discrete=discrete)


def check_stabilizable(plant, name: str = "plant") -> None:
    """Raise :class:`~robustctl.errors.NotStabilizableError` if ``plant`` (a ``Plant``) is not stabilisable.

    ``lqr``, ``rlqr``, ``hinf`` and ``h2`` call this first (the latter two at
    every vertex): no gain ``u = K x`` stabilises such a plant, so there is no
    design to return. ``name`` names the plant in the message (e.g.
    ``"vertices[0]"``). The error is also an ``InfeasibleError`` (what the LMI
    syntheses raise) and a ``ConvergenceError``.

    Parameters
    ----------
    plant : Plant
        The plant to test.
    name : str
        Its name in the message.

    Raises
    ------
    NotStabilizableError
        The plant has an unstable mode its input cannot move.

    Examples
    --------
    >>> import robustctl as rc
    >>> from robustctl.systems.stability import check_stabilizable
    >>> check_stabilizable(rc.Plant([[2.0]], [[1.0]], dt=0.1))      # passes silently
    >>> check_stabilizable(rc.Plant([[2.0, 0.0], [0.0, 0.5]], [[0.0], [1.0]], dt=0.1))
    Traceback (most recent call last):
    ...
    robustctl.errors.NotStabilizableError: plant is not stabilisable: its mode lambda = 2+0j ...
    """
    stuck = plant.unstabilizable_modes  # cached on the plant
    if stuck.size:
        kind = "|lambda| >= 1" if plant.is_discrete else "Re(lambda) >= 0"
        raise NotStabilizableError(
            f"{name} is not stabilisable: its mode lambda = {complex(stuck[0]):.6g} ({kind}) cannot be moved "
            "by the input G (PBH rank test), so no gain u = K x makes the loop stable")


def check_detectable(plant, name: str = "plant") -> None:
    """Raise :class:`~robustctl.errors.NotDetectableError` if ``plant`` (a ``Plant`` with outputs) is not detectable.

    The estimators and the output-feedback syntheses call this first: no
    observer gain makes the estimation error of such a plant converge.

    Parameters
    ----------
    plant : Plant
        The plant to test (without an output model the state is measured:
        always detectable).
    name : str
        Its name in the message.

    Raises
    ------
    NotDetectableError
        The plant has an unstable mode its outputs do not see.

    Examples
    --------
    >>> import robustctl as rc
    >>> from robustctl.systems.stability import check_detectable
    >>> check_detectable(rc.Plant([[2.0]], [[1.0]], dt=0.1, C=[[1.0]]))     # passes silently
    >>> check_detectable(rc.Plant([[2.0, 0.0], [0.0, 0.5]], [[1.0], [1.0]], dt=0.1, C=[[0.0, 1.0]]))
    Traceback (most recent call last):
    ...
    robustctl.errors.NotDetectableError: plant is not detectable: its mode lambda = 2+0j ...
    """
    hidden = plant.undetectable_modes  # cached on the plant
    if hidden.size:
        kind = "|lambda| >= 1" if plant.is_discrete else "Re(lambda) >= 0"
        raise NotDetectableError(
            f"{name} is not detectable: its mode lambda = {complex(hidden[0]):.6g} ({kind}) is not seen by the "
            "outputs C (PBH rank test), so no observer makes the estimation error converge; measure that mode")
