"""Discrete-time LQR via the algebraic Riccati equation.

Minimises ``sum_k x_k' Q x_k + u_k' R u_k`` subject to ``x_{k+1} = F x_k + G u_k``.
The stabilising solution ``P`` of

    P = F' P F - F' P G (R + G' P G)^-1 G' P F + Q

gives ``u = K x`` with ``K = -(R + G' P G)^-1 G' P F`` (note the sign:
python-control's ``dlqr`` returns ``-K``). Reference: Anderson & Moore,
*Optimal Control: Linear Quadratic Methods*, 1990, Ch. 2.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from ._validation import as_matrix, check_spd
from .controller import Controller
from .errors import ConvergenceError
from .plant import Plant, check_plant
from .stability import check_stabilizable

__all__ = ["lqr", "dare"]

_RESIDUAL_TOL = 1e-8


def _weights(plant: Plant, Q, R) -> tuple[np.ndarray, np.ndarray]:
    n, m = plant.n, plant.m
    Q = np.eye(n) if Q is None else as_matrix(Q, "Q", rows=n, cols=n, rows_what="the number of states",
                                             cols_what="the number of states")
    R = np.eye(m) if R is None else as_matrix(R, "R", rows=m, cols=m, rows_what="the number of inputs",
                                             cols_what="the number of inputs")
    return check_spd(Q, "Q", semidefinite=True), check_spd(R, "R")


def _residual(F, G, Q, R, P) -> float:
    GP = G.T @ P
    res = F.T @ P @ F - F.T @ P @ G @ np.linalg.solve(R + GP @ G, GP @ F) + Q - P
    return float(np.linalg.norm(res)) / max(1.0, float(np.linalg.norm(P)))


def dare(F, G, Q=None, R=None) -> tuple[np.ndarray, str]:
    """Stabilising solution of the DARE: slycot (via python-control) if installed, scipy otherwise or as fallback.

    Returns ``(P, backend)``; raises :class:`ConvergenceError` if neither
    backend gives a solution with relative residual below 1e-8. The
    arguments are checked like :func:`lqr`'s (``Q``, ``R`` may be ``None``: identity).
    """
    plant = Plant(F, G, 1.0)
    return _dare(plant.F, plant.G, *_weights(plant, Q, R))


def _dare(F, G, Q, R) -> tuple[np.ndarray, str]:
    reasons = []
    for backend in ("slycot", "scipy"):
        try:
            if backend == "slycot":
                import control

                P = np.asarray(control.dare(F, G, Q, R, method="slycot")[0])
            else:
                P = scipy.linalg.solve_discrete_are(F, G, Q, R)
        except (ImportError, RuntimeError, ValueError, ArithmeticError) as exc:
            # slycot missing (ImportError) or failed (SlycotError is a RuntimeError), or scipy failed: try the next
            reasons.append(f"{backend}: {exc}")
            continue
        P = 0.5 * (P + P.T)
        res = _residual(F, G, Q, R, P)
        if np.all(np.isfinite(P)) and res < _RESIDUAL_TOL:
            return P, backend
        reasons.append(f"{backend}: residual {res:.3g}")
    raise ConvergenceError("no stabilising solution of the discrete Riccati equation "
                           "(is (F, G) stabilisable and (F, Q) detectable?); " + "; ".join(reasons))


def lqr(plant: Plant, *, Q=None, R=None) -> Controller:
    """Discrete-time LQR state feedback ``u = K x`` (``K = -control.dlqr(...)[0]``).

    Parameters
    ----------
    plant : Plant
        Discrete-time plant.
    Q : (n, n) symmetric positive semidefinite, default identity
    R : (m, m) symmetric positive definite, default identity

    Returns
    -------
    Controller
        ``info`` holds ``P`` (Riccati solution), ``residual`` (relative
        Riccati residual) and ``backend`` (``"slycot"`` if the optional
        ``robustctl[slycot]`` extra is installed and succeeds, else ``"scipy"``).

    Raises
    ------
    NotStabilizableError
        ``(F, G)`` is not stabilisable (PBH test, :mod:`robustctl.stability`);
        ``rlqr``, ``hinf`` and ``h2`` raise the same (it is also an ``InfeasibleError``).
    ConvergenceError
        No backend solves the Riccati equation (e.g. ``(F, Q)`` not detectable).
    """
    check_plant(plant, discrete_for="lqr")
    Q, R = _weights(plant, Q, R)
    check_stabilizable(plant)
    P, backend = _dare(plant.F, plant.G, Q, R)
    G = plant.G
    K = -np.linalg.solve(R + G.T @ P @ G, G.T @ P @ plant.F)
    return Controller(K, "lqr", plant, {"P": P, "backend": backend,
                                        "residual": _residual(plant.F, G, Q, R, P)})
