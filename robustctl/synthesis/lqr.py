"""Discrete-time LQR via the algebraic Riccati equation.

Minimises ``sum_k x_k' Q x_k + u_k' R u_k`` subject to ``x_{k+1} = F x_k + G u_k``.
The stabilising solution ``P`` of

    P = F' P F - F' P G (R + G' P G)^-1 G' P F + Q

gives ``u = K x`` with ``K = -(R + G' P G)^-1 G' P F`` (note the sign:
python-control's ``dlqr`` returns ``-K``). Reference: Anderson & Moore,
*Optimal Control: Linear Quadratic Methods*, 1990, Ch. 2.

The stabilising solution exists if and only if ``(F, G)`` is stabilisable
and ``(Q^1/2, F)`` has no unobservable mode on the unit circle (Lancaster &
Rodman, *Algebraic Riccati Equations*, 1995, Thm 13.1.3; Zhou, Doyle &
Glover, *Robust and Optimal Control*, 1996, Sec. 21.1). A candidate ``P`` is
accepted when its Riccati residual is small relative to the terms of the
equation (a backward error, so the test does not depend on the units of the
states or inputs) and ``F + G K`` is Schur stable
(:func:`robustctl.systems.stability.is_schur_stable`).
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg

from .._validation import as_matrix, check_spd
from ..errors import ConvergenceError
from ..systems.controller import Controller
from ..systems.plant import Plant, check_plant
from ..systems.stability import (
    UNSTABLE_TOL,
    check_stabilizable,
    immovable_modes,
    is_schur_stable,
    is_stable,
    spectral_radius,
)

__all__ = ["lqr", "dare"]

#: A solution is accepted when ``||res||_F <= _RESIDUAL_TOL * (||F'PF|| + ||F'PG (R+G'PG)^-1 G'PF|| + ||Q|| + ||P||)``.
_RESIDUAL_TOL = 1e-8
#: Newton (Hewer) refinement steps at most, only when a backend's solution misses the tolerance.
_REFINE_STEPS = 3


def _weights(plant: Plant, Q, R) -> tuple[np.ndarray, np.ndarray]:
    n, m = plant.n, plant.m
    Q = np.eye(n) if Q is None else as_matrix(Q, "Q", rows=n, cols=n, rows_what="the number of states",
                                             cols_what="the number of states")
    R = np.eye(m) if R is None else as_matrix(R, "R", rows=m, cols=m, rows_what="the number of inputs",
                                             cols_what="the number of inputs")
    return check_spd(Q, "Q", semidefinite=True), check_spd(R, "R")


def _residual(F, G, Q, R, P) -> float:
    """Relative Riccati residual: ``||res||_F`` over the sum of the Frobenius norms of the equation's terms.

    ``res = F'PF - F'PG (R + G'PG)^-1 G'PF + Q - P``. Dividing by the size of
    the terms (not by ``max(1, ||P||)``) makes the measure invariant under a
    change of the state or input units (``F -> T F T^-1``, ``G -> T G S``
    with the weights transformed to match) and under scaling ``Q`` and ``R``
    together: it is the backward error of ``P`` (Higham, *Accuracy and
    Stability of Numerical Algorithms*, 2002, Sec. 16.2, for the Lyapunov
    case; Sun, *Linear Algebra Appl.* 259, 1997, for the Riccati equation).
    """
    with np.errstate(over="ignore", invalid="ignore"):
        GP = G.T @ P
        FPF = F.T @ P @ F
        cross = (GP @ F).T @ np.linalg.solve(R + GP @ G, GP @ F)
        res = FPF - cross + Q - P
        size = sum(float(np.linalg.norm(term)) for term in (FPF, cross, Q, P))
    if not (np.isfinite(size) and np.all(np.isfinite(res))):
        return float("inf")
    return float(np.linalg.norm(res)) / size if size > 0 else 0.0


def _gain(F, G, R, P) -> np.ndarray:
    """``K = -(R + G'PG)^-1 G'PF`` (``u = K x``)."""
    return -np.linalg.solve(R + G.T @ P @ G, G.T @ P @ F)


def _refine(F, G, Q, R, P) -> tuple[np.ndarray, float]:
    """``(P, residual)``, ``P`` improved by Newton steps while its residual is above the tolerance.

    A backend's ``P`` on a badly scaled problem may miss the tolerance by a few
    digits. One Newton step on the Riccati equation (Hewer's iteration,
    *IEEE Trans. Autom. Control* 16, 1971) solves the Lyapunov equation
    ``P+ = A' P+ A + Q + K' R K`` of the loop ``A = F + G K`` closed by
    ``P``'s gain; from a stabilising gain it converges quadratically to the
    stabilising solution (Kleinman's refinement, Benner, *Acta Appl. Math.*
    1998), so a well-posed problem reaches a residual near machine precision
    in a step or two. A ``P`` that already meets the tolerance is returned
    unchanged; a step that does not lower the residual is discarded.
    """
    res = _residual(F, G, Q, R, P)
    for _ in range(_REFINE_STEPS):
        if not res >= _RESIDUAL_TOL or not np.all(np.isfinite(P)):
            break
        K = _gain(F, G, R, P)
        A = F + G @ K
        if not is_schur_stable(A):
            break
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                new = scipy.linalg.solve_discrete_lyapunov(A.T, Q + K.T @ R @ K)
        except (ValueError, ArithmeticError, Warning):
            break
        new = 0.5 * (new + new.T)
        new_res = _residual(F, G, Q, R, new)
        if not new_res < res:
            break
        P, res = new, new_res
    return P, res


def _unobservable_on_circle(F, Q) -> np.ndarray:
    """Eigenvalues of ``F`` on the unit circle that ``Q^1/2`` does not see (PBH test on ``(F', Q^1/2)``)."""
    w, V = np.linalg.eigh(Q)
    root = (V * np.sqrt(np.clip(w, 0.0, None))) @ V.T
    edge = max(1e-6, 1e3 * UNSTABLE_TOL * max(1.0, float(np.linalg.norm(F, 2))))
    return immovable_modes(F.T, root, lambda lam: np.abs(np.abs(lam) - 1.0) <= edge)


def dare(F, G, Q=None, R=None) -> tuple[np.ndarray, str]:
    """Stabilising solution of the DARE: slycot (via python-control) if installed, scipy otherwise or as fallback.

    A backend that fails, raises, or warns (slycot's ``SlycotResultWarning``
    on a badly scaled problem) hands over to the other.

    Parameters
    ----------
    F : (n, n) array_like
        State matrix.
    G : (n, m) array_like
        Input matrix.
    Q : (n, n) array_like, optional
        State weight, symmetric positive semidefinite (default identity).
    R : (m, m) array_like, optional
        Input weight, symmetric positive definite (default identity).

    Returns
    -------
    P : (n, n) ndarray
        The stabilising solution.
    backend : str
        ``"slycot"`` or ``"scipy"``.

    Raises
    ------
    ConvergenceError
        Neither backend gives a solution with relative residual below 1e-8
        (relative to the norms of the equation's terms, module docstring)
        that makes ``F + G K`` Schur stable, e.g. when ``Q`` leaves a mode on
        the unit circle (an integrator) unweighted; the message says which.
    ValueError
        Arguments checked like :func:`lqr`'s.

    Examples
    --------
    >>> import numpy as np, scipy.linalg
    >>> from robustctl.synthesis.lqr import dare
    >>> F, G = np.array([[1.0, 0.1], [0.0, 1.0]]), np.array([[0.005], [0.1]])
    >>> P, backend = dare(F, G)
    >>> bool(np.allclose(P, scipy.linalg.solve_discrete_are(F, G, np.eye(2), np.eye(1))))
    True
    """
    plant = Plant(F, G, 1.0)
    P, backend, _, _ = _dare(plant.F, plant.G, *_weights(plant, Q, R))
    return P, backend


def _dare(F, G, Q, R) -> tuple[np.ndarray, str, np.ndarray, float]:
    """``(P, backend, K, relative residual)``: the stabilising solution, its gain ``u = K x`` (see :func:`dare`)."""
    reasons = []
    unstable = False
    for backend in ("slycot", "scipy"):
        try:
            with warnings.catch_warnings():
                # a backend's warning (slycot: "solution may be inaccurate", scipy/numpy: overflow) is its failure
                warnings.simplefilter("error")
                if backend == "slycot":
                    import control

                    P = np.asarray(control.dare(F, G, Q, R, method="slycot")[0])
                else:
                    P = scipy.linalg.solve_discrete_are(F, G, Q, R)
        except (ImportError, RuntimeError, ValueError, ArithmeticError, Warning) as exc:
            # slycot missing (ImportError), failed (SlycotError is a RuntimeError) or warned
            # (SlycotResultWarning, raised as an exception by python-control), or scipy failed: try the next
            reasons.append(f"{backend}: {type(exc).__name__}: {exc}")
            continue
        P = 0.5 * (P + P.T)
        P, res = _refine(F, G, Q, R, P)
        if not (np.all(np.isfinite(P)) and res < _RESIDUAL_TOL):
            reasons.append(f"{backend}: relative residual {res:.3g}")
            continue
        K = _gain(F, G, R, P)
        A = F + G @ K
        if not is_schur_stable(A):
            unstable = True
            reasons.append(f"{backend}: the solution leaves F + G K with spectral radius {spectral_radius(A):.17g}")
            continue
        return P, backend, K, res
    why = "(is (F, G) stabilisable and (Q^1/2, F) detectable?)"
    if unstable:
        circle = _unobservable_on_circle(F, Q)
        if circle.size:
            why = (f"(Q^1/2, F) is not detectable on the unit circle: the mode lambda = {complex(circle[0]):.6g} "
                   "of F is not weighted by Q (e.g. an integrator whose state Q leaves out), so no gain is optimal "
                   "and stabilising; weight that state in Q")
    raise ConvergenceError("no stabilising solution of the discrete Riccati equation " + why + "; "
                           + "; ".join(reasons))


def lqr(plant: Plant, *, Q=None, R=None) -> Controller:
    r"""LQR state feedback ``u = K x`` (``K = -control.dlqr(...)[0]``, or ``-control.lqr`` in continuous time).

    Parameters
    ----------
    plant : Plant
        Discrete-time plant, or continuous-time (``dt=None``: the continuous
        Riccati equation, by scipy's ``solve_continuous_are``).
    Q : (n, n) array_like, optional
        State weight, symmetric positive semidefinite; default identity.
    R : (m, m) array_like, optional
        Input weight, symmetric positive definite; default identity.

    Returns
    -------
    Controller
        ``info`` holds ``P`` (Riccati solution), ``residual`` (relative
        Riccati residual) and ``backend`` (``"slycot"`` if the optional
        ``robustctl[slycot]`` extra is installed and succeeds, else ``"scipy"``).

    Raises
    ------
    NotStabilizableError
        ``(F, G)`` is not stabilisable (PBH test on the plant with ``F``
        balanced, :mod:`robustctl.systems.stability`);
        ``rlqr``, ``hinf`` and ``h2`` raise the same (it is also an ``InfeasibleError``).
    ConvergenceError
        No backend finds the stabilising solution of the Riccati equation,
        e.g. ``(Q^1/2, F)`` has an unobservable mode on the unit circle (an
        integrator whose state ``Q`` does not weight); the message says why.
    ValueError
        Weights of the wrong shape or not positive (semi)definite.

    See Also
    --------
    robustctl.rlqr : the robust LQR (equal to the LQR without uncertainty).
    robustctl.synthesis.lqr.dare : the Riccati solution alone.

    Notes
    -----
    The gain minimises ``sum_k x_k' Q x_k + u_k' R u_k`` subject to
    ``x_{k+1} = F x_k + G u_k`` [1]_. With ``P`` the stabilising solution of
    the discrete algebraic Riccati equation

    .. math::

        P = F^T P F - F^T P G (R + G^T P G)^{-1} G^T P F + Q ,

    the gain is ``K = -(R + G' P G)^-1 G' P F`` and the optimal cost from
    ``x_0`` is ``x_0' P x_0``. The solution exists iff ``(F, G)`` is
    stabilisable and ``(Q^1/2, F)`` has no unobservable mode on the unit
    circle [2]_. It is accepted when its residual, relative to the sum of
    the norms of the equation's terms (a backward error), is below 1e-8 and
    ``F + G K`` is Schur stable. In continuous time ``P`` solves
    ``A'P + PA - P B R^-1 B'P + Q = 0`` and ``K = -R^-1 B'P``, accepted on
    the same relative residual and a stable ``A + B K``.

    References
    ----------
    .. [1] B. D. O. Anderson, J. B. Moore, *Optimal Control: Linear Quadratic
       Methods*, Prentice Hall 1990, Ch. 2.
    .. [2] P. Lancaster, L. Rodman, *Algebraic Riccati Equations*, Oxford
       1995, Thm 13.1.3.

    Examples
    --------
    A double integrator sampled at 0.1 s; python-control returns ``-K``:

    >>> import numpy as np, control, robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> ctrl = rc.lqr(plant, Q=np.diag([1.0, 0.1]), R=[[0.01]])
    >>> ctrl.K.round(4)
    array([[-7.613 , -4.5849]])
    >>> K_pc, _, _ = control.dlqr(plant.F, plant.G, np.diag([1.0, 0.1]), [[0.01]])
    >>> bool(np.allclose(ctrl.K, -K_pc)), ctrl.is_stabilizing()
    (True, True)

    The Riccati equation holds at ``info["P"]``:

    >>> F, G, P = plant.F, plant.G, ctrl.info["P"]
    >>> res = F.T @ P @ F - F.T @ P @ G @ np.linalg.solve(0.01 + G.T @ P @ G, G.T @ P @ F) + np.diag([1.0, 0.1]) - P
    >>> bool(np.abs(res).max() < 1e-9 * np.abs(P).max())
    True
    """
    check_plant(plant)
    Q, R = _weights(plant, Q, R)
    check_stabilizable(plant)
    if not plant.is_discrete:
        P, K, residual = _care(plant.F, plant.G, Q, R)
        return Controller(K, "lqr", plant, {"P": P, "backend": "scipy", "residual": residual})
    P, backend, K, residual = _dare(plant.F, plant.G, Q, R)
    return Controller(K, "lqr", plant, {"P": P, "backend": backend, "residual": residual})


def _care(A, B, Q, R) -> tuple[np.ndarray, np.ndarray, float]:
    """``(P, K, relative residual)`` of the continuous Riccati equation ``A'P + PA - PBR^-1B'P + Q = 0``."""
    why = "(is (A, B) stabilisable and (Q^1/2, A) detectable on the imaginary axis?)"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            P = scipy.linalg.solve_continuous_are(A, B, Q, R)
    except (ValueError, ArithmeticError, np.linalg.LinAlgError, Warning) as exc:
        raise ConvergenceError(f"no stabilising solution of the continuous Riccati equation {why}; scipy: "
                               f"{type(exc).__name__}: {exc}") from None
    P = 0.5 * (P + P.T)
    K = -np.linalg.solve(R, B.T @ P)
    PBK = P @ B @ K
    terms = 2 * np.linalg.norm(A.T @ P) + np.linalg.norm(PBK) + np.linalg.norm(Q)
    residual = float(np.linalg.norm(A.T @ P + P @ A + PBK + Q) / max(terms, np.finfo(float).tiny))
    if not (np.all(np.isfinite(P)) and residual < _RESIDUAL_TOL and is_stable(A + B @ K, discrete=False)):
        raise ConvergenceError(f"no stabilising solution of the continuous Riccati equation {why}; scipy's has a "
                               f"relative residual {residual:.3g}")
    return P, K, residual
