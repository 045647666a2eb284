r"""The steady-state Kalman filter of a plant with measured outputs, one design or a batch.

Model (discrete time; ``dt=None``: the continuous-time analogue)::

    x[k+1] = F x[k] + G u[k] + Bw w[k],   y[k] = C x[k] + D u[k] + v[k],
    cov(w) = W,  cov(v) = V,  cov(w, v) = N.

The steady-state a-priori covariance ``P = cov(x[k] - x[k|k-1])`` is the
stabilising solution of the filter Riccati equation

.. math::

    P = F P F' + B_w W B_w' - (F P C' + B_w N)(C P C' + V)^{-1}(F P C' + B_w N)',

and the gains are ``Lf = P C' (C P C' + V)^-1`` (filter) and ``Lp = (F P C'
+ Bw N)(C P C' + V)^-1 = F Lf + Bw N Re^-1`` (predictor). Both share the
robust filter's recursion and steady-state solver
(``robustctl.estimation._steady``: doubling, checked by one step of the
recursion and the estimator's stability).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .._validation import check_int, check_positive_scalar, frozen
from ..errors import ConvergenceError
from ..systems.plant import Plant
from ..systems.stability import check_detectable, is_stable, spectral_abscissa
from ._arguments import (
    check_form,
    check_noise_reaches_boundary,
    covariance,
    covariance_stack,
    cross_covariance,
    noise_input,
    outputs,
)
from ._model import kalman_model
from ._steady import DEFAULT_MAX_ITER, DEFAULT_TOL, SteadyState, steady_state
from .estimator import Estimator, EstimatorBatch

__all__ = ["kalman", "kalman_gains"]

#: A continuous-time solution is accepted when its residual is below this, relative to the equation's terms.
_CARE_TOL = 1e-8


def _failure(st: SteadyState, i: int, max_iter: int, tol: float, what: str) -> ConvergenceError:
    """The error for a design that did not reach a stabilising steady state."""
    if st.reason[i] == "diverged":
        return ConvergenceError(f"the {what} recursion diverged (P grows without bound): no stabilising steady "
                                "state. Does the process noise Bw W Bw' reach every mode of F on or outside the "
                                "unit circle?")
    why = ("its estimator loop is not stable: a mode of F on the unit circle that the process noise does not "
           "reach (an integrator without noise) has no stabilising solution; add process noise to it"
           if st.residual[i] < tol else f"the relative change of P is still {st.residual[i]:.3g} (tol={tol:g})")
    return ConvergenceError(f"the {what} recursion did not reach a stabilising steady state in max_iter={max_iter} "
                            f"steps: {why}")


def _estimator(st: SteadyState, i: int, plant: Plant, form: str, method: str, info: dict, model) -> Estimator:
    g = st.gains
    arrays = (g.Lf[i], g.Fe[i] @ g.Lf[i] + g.Je[i], st.P[i], g.Pf[i], g.Fe[i], g.Ge[i], g.Je[i])
    for a in arrays:  # the result's arrays are read-only (the steady state's own arrays: no copies)
        a.flags.writeable = False
    Lf, Lp, P, Pf, Fe, Ge, Je = arrays
    return Estimator(Lf, Lp, P, Pf, form, Fe, Ge, Je, plant, method, info, model)


def _check_noise(plant: Plant, Bw, W, V, N) -> None:
    """Raise if a mode on the stability boundary is not reached by the process noise (the usual failure)."""
    if N is None:
        check_noise_reaches_boundary(plant.F, Bw, W, discrete=plant.is_discrete)
    else:  # the pair without cross term: F - Bw N V^-1 C and W - N V^-1 N'
        NV = np.linalg.solve(V, N[0].T).T
        check_noise_reaches_boundary(plant.F - Bw @ NV @ plant.output_matrices()[0], Bw, W - NV @ N[0].T,
                                     discrete=plant.is_discrete)


def _continuous(plant: Plant, Bw, W, V, N, info: dict) -> Estimator:
    """The Kalman-Bucy filter: ``A P + P A' - (P C' + S) V^-1 (P C' + S)' + Bw W Bw' = 0``, ``S = Bw N``."""
    A, C = plant.F, plant.output_matrices()[0]
    Q = Bw @ W @ Bw.T
    S = np.zeros((plant.n, C.shape[0])) if N is None else Bw @ N[0]
    VS = np.linalg.solve(V, S.T)
    try:
        P = scipy.linalg.solve_continuous_are((A - S @ np.linalg.solve(V, C)).T, C.T, Q - S @ VS, V)
    except (ValueError, np.linalg.LinAlgError) as exc:
        _check_noise(plant, Bw, W, V, N)
        raise ConvergenceError(f"no stabilising solution of the filter's continuous Riccati equation ({exc}); "
                               "does the process noise Bw W Bw' reach every mode of F on the imaginary axis?") from None
    P = 0.5 * (P + P.T)
    PCS = P @ C.T + S
    L = np.linalg.solve(V, PCS.T).T
    terms = (A @ P, P @ A.T, L @ PCS.T, Q)
    residual = float(np.linalg.norm(terms[0] + terms[1] - terms[2] + terms[3]) / max(
        sum(float(np.linalg.norm(t)) for t in terms), np.finfo(float).tiny))
    if not (np.all(np.isfinite(P)) and residual < _CARE_TOL and is_stable(A - L @ C, discrete=False)):
        _check_noise(plant, Bw, W, V, N)
        raise ConvergenceError(
            f"no stabilising solution of the filter's continuous Riccati equation (relative residual {residual:.3g}, "
            f"spectral abscissa of A - L C {spectral_abscissa(A - L @ C):.6g}); does the process noise reach every "
            "mode of F on the imaginary axis?")
    info.update(residual=residual, iterations=0)
    L, P = frozen(L), frozen(P)
    return Estimator(L, L, P, P, "filter", frozen(A), frozen(plant.G), frozen(np.zeros_like(L)), plant, "kalman", info)


def kalman(plant: Plant, W, V, *, Bw=None, N=None, form: str = "filter", tol: float = DEFAULT_TOL,
           max_iter: int = DEFAULT_MAX_ITER) -> Estimator:
    r"""Steady-state Kalman filter of a plant with measured outputs.

    Parameters
    ----------
    plant : Plant
        Discrete- or continuous-time plant with an output matrix ``C`` (and ``D``).
    W : (nw, nw) array_like
        Process noise covariance (symmetric positive semidefinite; the
        intensity for a continuous-time plant, see
        :func:`robustctl.noise_covariance` for its discrete equivalent).
    V : (p, p) array_like
        Measurement noise covariance (symmetric positive definite).
    Bw : (n, nw) array_like, optional
        Where ``w`` enters: default ``plant.Bw``, and the identity (noise on
        every state, ``W`` then ``(n, n)``) when the plant has none.
    N : (nw, p) array_like, optional
        Cross-covariance ``cov(w[k], v[k])``; ``[[W, N], [N', V]]`` must be
        positive semidefinite. Default zero.
    form : {"filter", "predictor"}
        Which estimate ``est.L`` (and :meth:`Estimator.step`) gives: ``x[k|k]``
        with the filter gain ``Lf = P C' (C P C' + V)^-1`` or ``x[k|k-1]`` with
        the predictor gain ``Lp = F Lf + Bw N (C P C' + V)^-1`` (what
        ``control.dlqe`` returns, ``Lp = F Lf`` without ``N``). A
        continuous-time plant has one form, ``"filter"``.
    tol, max_iter :
        Acceptance of the steady state (discrete time): one more step of the
        Riccati recursion changes ``P`` by less than ``tol`` (relative) and the
        estimator's loop is stable; at most ``max_iter`` steps of the plain
        recursion where the doubling does not settle.

    Returns
    -------
    Estimator
        ``L``, ``P`` (a-priori, whatever the form: the same as
        ``control.dlqe``'s), ``P_filtered``, ``form``, both gains, and the
        methods ``step`` and ``run`` (discrete time). ``info`` holds ``W``,
        ``V``, ``N``, ``Bw``, ``residual`` and ``iterations``.

    Raises
    ------
    ValueError
        The plant has no output matrix ``C``; ``W``, ``V`` or ``N`` of the
        wrong shape, not symmetric or not positive (semi)definite; ``(C, F)``
        not detectable (the message names the mode ``C`` does not see).
    ConvergenceError
        No stabilising steady state, e.g. a mode of ``F`` on the unit circle
        that the process noise does not reach.

    See Also
    --------
    kalman_gains : a batch of covariances.
    robust_kalman : the robust filter for uncertain models.

    Notes
    -----
    The filter Riccati equation (discrete time)

    .. math::

        P = F P F' + B_w W B_w' - (F P C' + B_w N)(C P C' + V)^{-1}(F P C' + B_w N)'

    is solved by doubling on its standard form, without cross term
    (``robustctl.estimation._steady``). The filter form updates
    ``x[k|k] = x[k|k-1] + Lf e`` with ``e = y[k] - C x[k|k-1] - D u[k]``, then
    ``x[k+1|k] = F x[k|k] + G u[k] + Bw N Re^-1 e``. Continuous time:
    ``A P + P A' - (P C' + Bw N) V^-1 (P C' + Bw N)' + Bw W Bw' = 0``
    (``scipy.linalg.solve_continuous_are``) and ``L = (P C' + Bw N) V^-1``.

    References
    ----------
    .. [1] R. E. Kalman, "A new approach to linear filtering and prediction
       problems", J. Basic Eng. 82, 1960.
    .. [2] B. D. O. Anderson and J. B. Moore, *Optimal Filtering*,
       Prentice-Hall, 1979, Ch. 3-5.

    Examples
    --------
    A double integrator measured in position; python-control returns the
    predictor gain and the same a-priori covariance:

    >>> import numpy as np, control, robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1, C=[[1.0, 0.0]])
    >>> W, V = np.diag([1e-4, 1e-2]), [[0.01]]
    >>> est = rc.kalman(plant, W, V)
    >>> est
    Estimator(method='kalman', form='filter', n=2, p=1, dt=0.1)
    >>> Lp, P, _ = control.dlqe(plant.F, np.eye(2), plant.C, W, V)
    >>> bool(np.allclose(est.P, P)), bool(np.allclose(est.L_predictor, Lp))
    (True, True)
    >>> Lf = P @ plant.C.T @ np.linalg.inv(plant.C @ P @ plant.C.T + V)
    >>> bool(np.allclose(est.L, Lf))
    True
    """
    plant = outputs(plant, "the Kalman filter")
    form = check_form(form, plant)
    tol = check_positive_scalar(tol, "tol")
    max_iter = check_int(max_iter, "max_iter")
    Bw = noise_input(plant, Bw)
    W = covariance(W, "W", Bw.shape[1], "columns of Bw", definite=False)
    V = covariance(V, "V", plant.p, "the number of outputs", definite=True)
    N = cross_covariance(N, W[None], V[None])
    check_detectable(plant)
    C, D = plant.output_matrices()
    info = {"W": W, "V": V, "N": None if N is None else N[0], "Bw": Bw}
    if not plant.is_discrete:
        return _continuous(plant, Bw, W, V, N, info)
    d = kalman_model(plant.F, plant.G, C, D, Bw, W[None], V[None], N)
    st = steady_state(d, tol, max_iter)
    if st.reason[0] != "ok":
        _check_noise(plant, Bw, W, V, N)         # the usual cause, named
        raise _failure(st, 0, max_iter, tol, "Kalman filter's")
    info.update(residual=float(st.residual[0]), iterations=int(st.iterations[0]))
    return _estimator(st, 0, plant, form, "kalman", info, d)


def kalman_gains(plant: Plant, W, V, *, Bw=None, N=None, form: str = "filter", tol: float = DEFAULT_TOL,
                 max_iter: int = DEFAULT_MAX_ITER) -> EstimatorBatch:
    """Steady-state Kalman filters of one discrete-time plant for a batch of noise covariances.

    Parameters
    ----------
    plant : Plant
        Discrete-time plant with an output matrix ``C``.
    W : (B, nw, nw) or (nw, nw) array_like
        Process noise covariances (each symmetric positive semidefinite).
    V : (B, p, p) or (p, p) array_like
        Measurement noise covariances (each symmetric positive definite).
        ``W``, ``V`` and ``N`` may omit the batch axis to be shared.
    Bw, N, form, tol, max_iter :
        As for :func:`kalman` (``N`` may be a stack (B, nw, p)).

    Returns
    -------
    EstimatorBatch
        Gains, covariances and per-design flags: a design that fails is
        flagged (``ok`` False, ``reason``), never raised; a plant whose
        ``(C, F)`` is not detectable flags every design ``"undetectable"``
        (:func:`kalman` raises instead).

    Raises
    ------
    ValueError
        A continuous-time plant, a plant without ``C``, covariances of the wrong
        shape or not symmetric positive (semi)definite (naming ``W[i]``).

    Examples
    --------
    Three measurement noise levels at once, each the single design's:

    >>> import numpy as np, robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1, C=[[1.0, 0.0]])
    >>> V = np.array([1e-3, 1e-2, 1e-1]).reshape(3, 1, 1)
    >>> batch = rc.kalman_gains(plant, np.diag([1e-4, 1e-2]), V)
    >>> batch
    EstimatorBatch(B=3, n=2, p=1, form='filter', ok=3/3, max_iterations=...)
    >>> bool(np.allclose(batch.L[1], rc.kalman(plant, np.diag([1e-4, 1e-2]), [[1e-2]]).L))
    True
    """
    plant = outputs(plant, "the Kalman filter")
    if not plant.is_discrete:
        raise ValueError("kalman_gains needs a discrete-time plant (dt > 0); call kalman for a continuous-time one")
    form = check_form(form, plant)
    tol = check_positive_scalar(tol, "tol")
    max_iter = check_int(max_iter, "max_iter")
    Bw = noise_input(plant, Bw)
    W = covariance_stack(W, "W", Bw.shape[1], "columns of Bw", definite=False)
    V = covariance_stack(V, "V", plant.p, "the number of outputs", definite=True)
    sizes = {W.shape[0], V.shape[0]} - {1}
    if len(sizes) > 1:
        raise ValueError(f"batch sizes differ: W {W.shape[0]}, V {V.shape[0]}")
    B = sizes.pop() if sizes else 1
    W, V = (np.broadcast_to(a, (B, *a.shape[1:])) for a in (W, V))
    N = cross_covariance(N, W, V)
    C, D = plant.output_matrices()
    d = kalman_model(plant.F, plant.G, C, D, Bw, W, V, N)
    if not plant.is_detectable:
        return _flagged(B, plant, form, "undetectable")
    return batch_result(steady_state(d, tol, max_iter), form)


def _flagged(B: int, plant: Plant, form: str, reason: str) -> EstimatorBatch:
    n, m, p = plant.n, plant.m, plant.p
    nan = np.full
    return EstimatorBatch(nan((B, n, p), np.nan), nan((B, n, n), np.nan), nan((B, n, n), np.nan),
                          nan((B, n, m), np.nan), nan((B, n, p), np.nan), np.zeros(B, dtype=bool),
                          np.full(B, reason, dtype="<U13"), np.zeros(B, dtype=bool), np.zeros(B, dtype=int),
                          np.full(B, np.inf), form)


def batch_result(st: SteadyState, form: str) -> EstimatorBatch:
    """The :class:`EstimatorBatch` of a steady state (NaN gains where a design failed)."""
    g = st.gains
    ok = st.reason == "ok"
    L, P, F, G, J = ((g.Lf if form == "filter" else g.Fe @ g.Lf + g.Je).copy(), st.P.copy(), g.Fe.copy(), g.Ge.copy(),
                     g.Je.copy())
    for a in (L, P, F, G, J):
        a[~ok] = np.nan
        a.flags.writeable = False
    return EstimatorBatch(L, P, F, G, J, ok, st.reason, st.stable & ok, st.iterations, st.residual, form)
