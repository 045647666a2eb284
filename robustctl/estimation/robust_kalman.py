r"""The robust filter for norm-bounded model uncertainty (Ishihara, Terra & Cerri 2015), one design or a batch.

Uncertain model (discrete time)::

    x[k+1] = (F + dF) x[k] + (G + dG) u[k] + (Bw + dBw) w[k],   y[k] = (C + dC) x[k] + D u[k] + v[k],
    [dF dG dBw] = H Delta1 [EF EG EBw],   dC = HC Delta2 EC,   ||Delta1||, ||Delta2|| <= 1,
    cov(w) = W,   cov(v) = V.

Each step of the filter solves the regularised least-squares min-max
problem of the step (Sayed 2001) with the penalty ``mu`` on the model's
equations: for ``lambda = (1 + alpha) mu max(||H'H||, ||HC'HC||)`` it is a
weighted least-squares problem, one KKT system (the block form,
``robustctl.estimation._recursion.block_step``), whose closed form
is a Kalman filter with extra noise ``Phi1 = mu^-1 I - lambda^-1 H H'``,
``Phi2 = mu^-1 I - lambda^-1 HC HC'`` and the pseudo-measurements ``0 = EF
x + EG u + EBw w`` and ``0 = EC x`` of noise ``lambda^-1 I``
(``robustctl.estimation._recursion``). The estimator runs a modified model
``xhat+ = Fe x[k|k] + Ge u``, ``Fe = F - J EF``, ``Ge = G - J EG``. It is the
estimation dual of the RLQR (:func:`robustctl.rlqr`): the same framework,
the same ``mu``, ``alpha`` and ``lambda``; as ``mu -> inf`` the
pseudo-measurements become exact constraints and ``H``, ``HC`` drop out.
"""

from __future__ import annotations

import numpy as np

from .._kkt import DEFAULT_ALPHA, check_penalty, relchange
from .._validation import as_matrix, check_bool, check_choice, check_int, check_positive_scalar, frozen
from ..errors import ConvergenceError
from ..systems.plant import Plant
from ..systems.stability import check_detectable
from ._arguments import check_form, covariance, design_stack, noise_input, outputs
from ._model import FilterModel, robust_model
from ._recursion import block_step
from ._steady import DEFAULT_MAX_ITER, DEFAULT_TOL, steady_state
from .estimator import Estimator, EstimatorBatch
from .kalman import _estimator, _failure, _flagged, batch_result

__all__ = ["robust_kalman", "robust_kalman_gains"]

_IMPLEMENTATIONS = ("closed", "block")


def _build(plant, W, V, Bw, H, EF, EG, EBw, HC, EC, mu, alpha, batch: bool):
    """Check every argument and build the filter model (B designs) and ``mu`` (B,)."""
    plant = outputs(plant, "the robust filter")
    if not plant.is_discrete:
        raise ValueError("plant must be discrete-time (dt > 0) for the robust filter; discretise it first")
    n, m, p = plant.n, plant.m, plant.p
    Bw = noise_input(plant, Bw)
    nw = Bw.shape[1]
    W = covariance(W, "W", nw, "columns of Bw", definite=False)
    V = covariance(V, "V", p, "the number of outputs", definite=True)
    if H is None or EF is None:
        raise TypeError("H and EF are required: [dF dG dBw] = H Delta [EF EG EBw] (H = 0 for no uncertainty)")
    H = as_matrix(H, "H", rows=n, vector="column", rows_what="the number of states", allow_empty=True)
    EF = design_stack(EF, "EF", (None, n), ("", "the number of states"), batch)
    q = EF.shape[1]
    EG = np.zeros((1, q, m)) if EG is None else design_stack(EG, "EG", (q, m), ("the rows of EF",
                                                                               "the number of inputs"), batch)
    EBw = np.zeros((1, q, nw)) if EBw is None else design_stack(EBw, "EBw", (q, nw), ("the rows of EF",
                                                                                     "columns of Bw"), batch)
    if (HC is None) != (EC is None):
        raise TypeError("give HC and EC together (dC = HC Delta2 EC), or neither")
    if HC is None:
        HC, EC = np.zeros((p, 0)), np.zeros((0, n))
    else:
        HC = as_matrix(HC, "HC", rows=p, vector="column", rows_what="the number of outputs")
        EC = as_matrix(EC, "EC", cols=n, cols_what="the number of states")
    mu = check_penalty(mu, "mu", batch=batch, what="robust_kalman (use robust_kalman_gains for batches)")
    alpha = check_positive_scalar(alpha, "alpha")
    sizes = {EF.shape[0], EG.shape[0], EBw.shape[0], mu.shape[0]} - {1}
    if len(sizes) > 1:
        raise ValueError(f"batch sizes differ: EF {EF.shape[0]}, EG {EG.shape[0]}, EBw {EBw.shape[0]}, "
                         f"mu {mu.shape[0]}")
    B = sizes.pop() if sizes else 1
    EF, EG, EBw, mu = (np.broadcast_to(a, (B, *a.shape[1:])) for a in (EF, EG, EBw, mu))
    C, D = plant.output_matrices()
    d = robust_model(plant.F, plant.G, C, D, Bw, W, V, H=H, EF=EF, EG=EG, EBw=EBw, HC=HC, EC=EC, mu=mu,
                     alpha=alpha)
    info = {"W": W, "V": V, "Bw": Bw, "H": H, "HC": HC, "alpha": alpha}
    return plant, d, mu, info


def _lam(d: FilterModel, mu: np.ndarray) -> np.ndarray:
    """``lambda`` per design (``inf`` at ``mu = inf``; 0 without uncertainty), for the record."""
    with np.errstate(divide="ignore"):
        return np.where(d.uncertain, np.where(mu == np.inf, np.inf, 1.0 / d.li), 0.0)


def _block(d: FilterModel, tol: float, max_iter: int) -> tuple:
    """The steady state by the block (KKT) system alone: its plain recursion, then its linear maps."""
    n, m, p = d.F.shape[0], d.G.shape[1], d.C.shape[0]
    zn, zm, zp = np.zeros(n), np.zeros(m), np.zeros(p)
    Pf, it, change = np.eye(n), 0, np.inf
    while it < max_iter and change >= tol:
        it += 1
        Pf_new = block_step(zn, Pf, zm, zm, zp, d)[1]
        change = float(relchange(Pf_new[None], Pf[None])[0])
        Pf = Pf_new
    P = block_step(zn, Pf, zm, zm, zp, d, measure=False)[1]
    # x[k|k] = Mx x[k-1|k-1] + Mu u[k-1] + Lf (y[k] - D u[k]): the block system's linear maps, column by column
    Mx = np.column_stack([block_step(e, Pf, zm, zm, zp, d)[0] for e in np.eye(n)])
    Mu = np.column_stack([block_step(zn, Pf, e, zm, zp, d)[0] for e in np.eye(m)])
    Lf = np.column_stack([block_step(zn, Pf, zm, zm, e, d)[0] for e in np.eye(p)])
    ILC = np.eye(n) - Lf @ d.C                        # Mx = (I - Lf C) Fe, Mu = (I - Lf C) Ge
    return P, Pf, Lf, np.linalg.solve(ILC, Mx), np.linalg.solve(ILC, Mu), it, change


def robust_kalman(plant: Plant, W, V, *, Bw=None, H, EF, EG=None, EBw=None, HC=None, EC=None, mu,
                  alpha: float = DEFAULT_ALPHA, form: str = "filter", implementation: str = "closed",
                  tol: float = DEFAULT_TOL, max_iter: int = DEFAULT_MAX_ITER, accelerate: bool = True) -> Estimator:
    r"""Steady-state robust filter for norm-bounded uncertainty (the estimation dual of the RLQR).

    Parameters
    ----------
    plant : Plant
        Nominal discrete-time plant with an output matrix ``C``.
    W, V : array_like
        Covariances of ``w`` (nw, nw; positive semidefinite) and ``v`` (p, p; positive definite).
    Bw : (n, nw) array_like, optional
        Default ``plant.Bw``, else the identity (as :func:`kalman`).
    H : (n, k) array_like
        ``[dF dG dBw] = H Delta1 [EF EG EBw]``; ``H = 0`` means no uncertainty in the dynamics.
    EF : (q, n) array_like
    EG : (q, m) array_like, optional
        Default zero (no uncertainty in ``G``). ``EG`` changes only the
        estimator's input matrix ``Ge``, not ``P`` or ``L``.
    EBw : (q, nw) array_like, optional
        Default zero.
    HC : (p, k2) array_like, optional
    EC : (q2, n) array_like, optional
        ``dC = HC Delta2 EC`` (both or neither; default no output uncertainty).
    mu : float
        Penalty in ``[1e-100, inf]``; ``np.inf`` gives the optimal robust
        filter of Ishihara, Terra & Cerri (2015), in which ``EF x + EG u +
        EBw w = 0`` and ``EC x = 0`` hold exactly and ``H``, ``HC`` drop out.
        The rows are first rotated onto the row space of ``[EF, EBw W^1/2]``
        (and of ``EC``) and the rows outside it, which say nothing about the
        state, dropped: the same uncertain model, and no rank condition at
        ``mu = inf``.
    alpha : float, default 0.1
        ``lambda = (1 + alpha) mu max(||H'H||, ||HC'HC||)`` (as for :func:`robustctl.rlqr`).
    form : {"filter", "predictor"}
        As for :func:`kalman`.
    implementation : {"closed", "block"}
        The step's closed form (default) or the block (KKT) system of the
        framework, by its plain recursion (the reference; slow).
    tol, max_iter, accelerate :
        Acceptance of the steady state (as for :func:`kalman`); ``accelerate=False``
        finds it by the plain recursion of the closed form.

    Returns
    -------
    Estimator
        ``method="robust_kalman"``; ``F``, ``G`` are the filter's modified
        model ``Fe``, ``Ge``; ``P`` is the a-priori covariance of the filter's
        regularised problem (after the pseudo-measurement ``EC x``), ``L`` the
        gain of the form with ``L_filter = P C' (C P C' + V + Phi2)^-1``.
        ``run`` is the finite-horizon (time-varying) filter. ``info`` holds
        ``mu``, ``alpha``, ``lambda``, ``implementation``, ``residual``,
        ``iterations`` and the noise data.

    Raises
    ------
    ValueError
        The plant is continuous-time or has no ``C``; an argument of the
        wrong shape (the message names it); ``(C, F)`` not detectable.
    ConvergenceError
        No stabilising steady state.

    See Also
    --------
    robust_kalman_gains : a batch of uncertainty models.
    kalman : the nominal filter (equal at zero uncertainty and ``mu = inf``).
    robustctl.rlqr : the regulator of the same framework.

    Notes
    -----
    One step is the regularised least-squares problem, over ``z = (x[k-1],
    w[k-1], v[k], x[k])``,

    .. math::

        \min_z \max_{\Delta} \; \|x_{k-1} - \hat x_{k-1|k-1}\|^2_{P_{k-1|k-1}^{-1}}
        + \|w\|^2_{W^{-1}} + \|v\|^2_{V^{-1}} + \mu \|r_\Delta(z)\|^2,

    ``r`` the residuals of the uncertain dynamics and measurement equations.
    For ``lambda > mu ||blkdiag(H'H, HC'HC)||`` its solution is that of the
    weighted least-squares problem with the inverse weights ``Phi1``,
    ``Phi2`` on the residuals and ``lambda^-1`` on ``EF x[k-1] + EBw w[k-1] +
    EG u[k-1]`` and ``EC x[k]`` (Sayed 2001, Thm. 1), a KKT system per step
    (the block form of Ishihara, Terra & Cerri 2015). It splits into a
    measurement update with ``R = V + Phi2``, a joint update of ``(x, w)``
    by the pseudo-measurement, which gives

    .. math::

        J = (F P_f E_F' + B_w W E_{Bw}')(E_F P_f E_F' + E_{Bw} W E_{Bw}' + \lambda^{-1} I)^{-1},
        \quad F_e = F - J E_F, \quad G_e = G - J E_G,

    and ``P+ = F Pf F' + Bw W Bw' + Phi1 - J (...) J'``, then the update by
    ``EC x``. The steady state is the stabilising solution of a filter
    Riccati equation with the stacked measurement ``(y, EC x, EF x + EBw
    w)``, found by doubling and Newton's method and checked by one step of
    the recursion.

    References
    ----------
    .. [1] J. Y. Ishihara, M. H. Terra and J. P. Cerri, "Optimal robust
       filtering for systems subject to uncertainties", Automatica 52, 2015,
       111-117.
    .. [2] A. H. Sayed, "A framework for state-space estimation with uncertain
       models", IEEE Trans. Autom. Control 46(7), 2001, 998-1013.
    .. [3] M. H. Terra, J. P. Cerri and J. Y. Ishihara, "Optimal robust linear
       quadratic regulator for systems subject to uncertainties", IEEE Trans.
       Autom. Control 59(9), 2014 (the regulator of the same framework).

    Examples
    --------
    Sayed's (2001) example: ``F[0, 1] = 0.0196 + 0.099 delta``, ``|delta| <= 1``.
    Without uncertainty (``H = 0``) at ``mu = inf`` the filter is the Kalman filter:

    >>> import numpy as np, robustctl as rc
    >>> plant = rc.Plant([[0.9802, 0.0196], [0.0, 0.9802]], np.zeros((2, 1)), dt=1.0, C=[[1.0, -1.0]])
    >>> W, V = [[1.9608, 0.0195], [0.0195, 1.9605]], [[1.0]]
    >>> nominal = rc.robust_kalman(plant, W, V, H=np.zeros((2, 1)), EF=[[0.0, 5.0]], mu=np.inf)
    >>> bool(np.allclose(nominal.L, rc.kalman(plant, W, V).L, rtol=1e-12))
    True
    >>> est = rc.robust_kalman(plant, W, V, H=[[0.0198], [0.0]], EF=[[0.0, 5.0]], mu=np.inf)
    >>> est.F.round(4)                      # the modified model: EF x = 0 is enforced
    array([[ 0.9802, -0.715 ],
           [ 0.    ,  0.    ]])
    """
    implementation = check_choice(implementation, "implementation", _IMPLEMENTATIONS)
    accelerate = check_bool(accelerate, "accelerate")
    tol = check_positive_scalar(tol, "tol")
    max_iter = check_int(max_iter, "max_iter")
    plant, d, mu_arr, info = _build(plant, W, V, Bw, H, EF, EG, EBw, HC, EC, mu, alpha, batch=False)
    form = check_form(form, plant)
    check_detectable(plant)
    info.update(mu=float(mu_arr[0]), **{"lambda": float(_lam(d, mu_arr)[0])}, implementation=implementation)
    if implementation == "block":
        P, Pf, Lf, Fe, Ge, it, change = _block(d, tol, max_iter)
        if not (np.all(np.isfinite(P)) and change < tol):
            raise ConvergenceError(f"the block recursion did not reach a steady state in max_iter={max_iter} steps "
                                   f"(relative change of P {change:.3g}, tol={tol:g})")
        info.update(residual=float(change), iterations=it)
        Lf, Lp, P, Pf, Fe, Ge, Je = (frozen(a) for a in (Lf, Fe @ Lf, P, Pf, Fe, Ge, np.zeros_like(Lf)))
        return Estimator(Lf, Lp, P, Pf, form, Fe, Ge, Je, plant, "robust_kalman", info, d)
    st = steady_state(d, tol, max_iter, accelerate=accelerate)
    if st.reason[0] != "ok":
        raise _failure(st, 0, max_iter, tol, "robust filter's")
    info.update(residual=float(st.residual[0]), iterations=int(st.iterations[0]))
    return _estimator(st, 0, plant, form, "robust_kalman", info, d)


def robust_kalman_gains(plant: Plant, W, V, *, Bw=None, H, EF, EG=None, EBw=None, mu,
                        alpha: float = DEFAULT_ALPHA, form: str = "filter", tol: float = DEFAULT_TOL,
                        max_iter: int = DEFAULT_MAX_ITER) -> EstimatorBatch:
    """Steady-state robust filters for ``B`` uncertainty models at once (vectorised), as :func:`robustctl.rlqr_gains`.

    Parameters
    ----------
    plant, W, V, Bw, H, alpha, form, tol, max_iter :
        As for :func:`robust_kalman` (shared by the batch).
    EF : (B, q, n) array_like
    EG : (B, q, m) array_like, optional
    EBw : (B, q, nw) array_like, optional
    mu : (B,) array_like
        Penalties in ``[1e-100, inf]``. Any of ``EF``, ``EG``, ``EBw``, ``mu``
        may omit the batch axis to be shared.

    Returns
    -------
    EstimatorBatch
        ``L`` (B, n, p), ``P``, the filters' models ``F``, ``G``, and the
        per-design ``ok``, ``reason`` (``"undetectable"``: every design, when
        ``(C, F)`` is not detectable; ``"diverged"``, ``"not converged"``). A
        design's failure is flagged, never raised; designs with the same
        arguments equal :func:`robust_kalman`'s.

    Notes
    -----
    All designs are solved together with stacked ``(B, k, k)`` operations
    (doubling, Newton's method on the exact step, and the acceptance test of
    :func:`robust_kalman`); no Python loop over designs.

    Examples
    --------
    >>> import numpy as np, robustctl as rc
    >>> plant = rc.Plant([[0.9802, 0.0196], [0.0, 0.9802]], np.zeros((2, 1)), dt=1.0, C=[[1.0, -1.0]])
    >>> W, V = [[1.9608, 0.0195], [0.0195, 1.9605]], [[1.0]]
    >>> EF = np.array([[[0.0, 1.0]], [[0.0, 5.0]]])
    >>> batch = rc.robust_kalman_gains(plant, W, V, H=[[0.0198], [0.0]], EF=EF, mu=[1e4, np.inf])
    >>> batch.ok
    array([ True,  True])
    >>> single = rc.robust_kalman(plant, W, V, H=[[0.0198], [0.0]], EF=[[0.0, 5.0]], mu=np.inf)
    >>> bool(np.allclose(batch.L[1], single.L))
    True
    """
    tol = check_positive_scalar(tol, "tol")
    max_iter = check_int(max_iter, "max_iter")
    plant, d, _, _ = _build(plant, W, V, Bw, H, EF, EG, EBw, None, None, mu, alpha, batch=True)
    form = check_form(form, plant)
    if not plant.is_detectable:
        return _flagged(d.size, plant, form, "undetectable")
    return batch_result(steady_state(d, tol, max_iter), form)
