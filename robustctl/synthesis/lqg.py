r"""Observer-based output feedback: a state feedback on a state estimate (LQG and robust LQG).

A state feedback ``u = K x`` and an estimator of the plant's state make a
dynamic output feedback ``u = K(z) y`` (:meth:`robustctl.Controller.dynamic`),
whose state is the estimator's a-priori estimate ``xc = x[k|k-1]``. The
estimator (:class:`robustctl.estimation.estimator.Estimator`, from
:func:`robustctl.kalman` or :func:`robustctl.robust_kalman`) runs

.. math::

    e = y - C x_c - D u, \quad x_f = x_c + L_f e, \quad
    x_c^+ = F_e x_f + G_e u + J e ,

with ``L_p = F_e L_f + J`` its predictor gain [2]_. The *filter* form feeds back
the filtered estimate, ``u = K x_f`` (it uses ``y[k]`` at once, the current
estimator of [1]_); with
``M = (I + K L_f D)^{-1}``

.. math::

    D_c = M K L_f, \quad C_c = M K (I - L_f C), \quad
    A_c = F_e + G_e C_c - L_p (C + D C_c), \quad B_c = L_p (I - D D_c) + G_e D_c .

The *predictor* form feeds back ``u = K x_c`` (``D_c = 0``, ``C_c = K``,
``A_c = F_e + G_e K - L_p (C + D K)``, ``B_c = L_p``); its matrices are also
those of continuous time, with ``L_p`` the Kalman-Bucy gain. For the Kalman filter
(``F_e = F``, ``G_e = G``) the closed-loop poles are those of ``F + G K`` and
of ``F - L_p C`` (the separation principle).

References
----------
.. [1] G. F. Franklin, J. D. Powell, M. L. Workman, *Digital Control of
   Dynamic Systems*, 3rd ed., Addison-Wesley 1998, Sec. 8.6 (the current
   estimator) and 9.5 (LQG).
.. [2] J. Y. Ishihara, M. H. Terra, J. P. Cerri, "Optimal robust filtering
   for systems subject to uncertainties", Automatica 52, 2015.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .._kkt import DEFAULT_ALPHA
from .._validation import as_matrix, check_choice
from ..errors import NotStabilizingError
from ..estimation import kalman, robust_kalman
from ..estimation.estimator import Estimator
from ..systems.controller import Controller
from ..systems.plant import Plant, check_plant
from .lqr import lqr
from .rlqr import rlqr

__all__ = ["observer_controller", "lqg", "rlqg"]


def observer_controller(K, estimator: Estimator, *, method: str = "observer",
                        info: Mapping[str, Any] | None = None) -> Controller:
    r"""The output feedback ``u = K xhat`` of a state feedback ``K`` on an estimator's estimate.

    Parameters
    ----------
    K : (m, n) array_like or Controller
        The state feedback ``u = K x`` (a state-feedback :class:`~robustctl.Controller` too).
    estimator : Estimator
        From :func:`robustctl.kalman` or :func:`robustctl.robust_kalman`; its
        ``form`` says which estimate is fed back (module docstring).
    method : str
        The result's ``method``.
    info : Mapping, optional
        Stored in the result's ``info`` with the estimator (key ``"estimator"``) and ``K`` (key ``"K"``).

    Returns
    -------
    Controller
        A dynamic controller of order ``n`` (``ctrl.Ac, Bc, Cc, Dc``) on the estimator's plant.

    Raises
    ------
    TypeError
        ``estimator`` is not an estimator, or ``K`` a dynamic controller.
    ValueError
        ``K`` of the wrong shape, or ``I + K L_f D`` singular (named).

    See Also
    --------
    lqg, rlqg : the designs built on it.

    Notes
    -----
    See the module docstring for the controller matrices of the two forms.

    Examples
    --------
    The separation principle: the loop's poles are the regulator's and the
    estimator's (python-control's ``dlqr`` and ``dlqe`` give the references):

    >>> import numpy as np, control, robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], 0.1, C=[[1.0, 0.0]])
    >>> K = -control.dlqr(plant.F, plant.G, np.eye(2), [[1.0]])[0]
    >>> est = rc.kalman(plant, np.eye(2) * 1e-3, [[1e-2]], Bw=np.eye(2))
    >>> ctrl = rc.observer_controller(K, est)
    >>> Lp = control.dlqe(plant.F, np.eye(2), plant.C, np.eye(2) * 1e-3, [[1e-2]])[0]
    >>> expected = np.concatenate([np.linalg.eigvals(plant.F + plant.G @ K), np.linalg.eigvals(plant.F - Lp @ plant.C)])
    >>> bool(np.allclose(np.sort_complex(ctrl.closed_loop_poles()), np.sort_complex(expected)))
    True
    """
    if not isinstance(estimator, Estimator):
        raise TypeError(f"estimator must be a robustctl estimator (from kalman or robust_kalman), "
                        f"got {type(estimator).__name__}")
    plant = estimator.plant
    if isinstance(K, Controller):
        if K.K is None:
            raise TypeError("K must be a state feedback (a gain or a state-feedback Controller), got a dynamic "
                            "controller")
        K = K.K
    K = as_matrix(K, "K", rows=plant.m, cols=plant.n, rows_what="the number of inputs",
                  cols_what="the number of states")
    C, D = plant.output_matrices()
    Fe, Ge, Lp = estimator.F, estimator.G, estimator.L_predictor
    if estimator.form == "filter" and plant.is_discrete:   # continuous time: the estimate itself is fed back
        Lf = estimator.L_filter
        Mi = np.eye(plant.m) + K @ Lf @ D
        if np.linalg.svd(Mi, compute_uv=False)[-1] <= 1e-12 * (1.0 + np.linalg.norm(K @ Lf @ D, 2)):
            raise ValueError("K: I + K Lf D is singular, so u = K x[k|k] does not define u (the loop is ill posed); "
                             "use form='predictor'")
        Dc = np.linalg.solve(Mi, K @ Lf)
        Cc = np.linalg.solve(Mi, K @ (np.eye(plant.n) - Lf @ C))
    else:
        Dc, Cc = np.zeros((plant.m, plant.p)), K
    Ac = Fe + Ge @ Cc - Lp @ (C + D @ Cc)
    Bc = Lp @ (np.eye(plant.p) - D @ Dc) + Ge @ Dc
    return Controller.dynamic(Ac, Bc, Cc, Dc, method, plant, {**(info or {}), "K": K, "estimator": estimator})


def lqg(plant: Plant, *, Q=None, R=None, W, V, Bw=None, N=None, form: str = "filter") -> Controller:
    r"""LQG: the LQR on the steady-state Kalman filter's estimate (discrete or continuous time).

    Parameters
    ----------
    plant : Plant
        With measured outputs (``C``).
    Q, R : array_like, optional
        The LQR weights of :func:`robustctl.lqr` (default identities).
    W, V : array_like
        Process and measurement noise covariances (intensities in continuous
        time) of :func:`robustctl.kalman`.
    Bw : (n, nw) array_like, optional
        Process-noise input; default the plant's ``Bw`` (see :func:`robustctl.kalman`).
    N : array_like, optional
        Cross-covariance of the process and measurement noises.
    form : {"filter", "predictor"}
        Feed back ``x[k|k]`` (default) or ``x[k|k-1]``; in continuous time the
        estimate of the Kalman-Bucy filter (``form`` is ignored).

    Returns
    -------
    Controller
        A dynamic controller of order ``n``; ``info`` holds ``"K"`` (the LQR
        gain), ``"estimator"``, ``"lqr"`` (its Controller) and ``"form"``.

    Raises
    ------
    ValueError
        A plant without outputs (naming ``C``), or bad weights and covariances (named).
    robustctl.NotStabilizableError, robustctl.NotDetectableError
        No stabilising regulator, or no converging estimator.

    See Also
    --------
    observer_controller, rlqg, robustctl.kalman, robustctl.lqr

    Notes
    -----
    The LQR minimises ``sum x'Qx + u'Ru`` with the state known; the Kalman
    filter the error covariance; by the separation principle their
    combination is the optimal output feedback for the expected cost with
    Gaussian noises [1]_, and the loop's poles are those of both.

    References
    ----------
    .. [1] K. J. Astrom, *Introduction to Stochastic Control Theory*,
       Academic Press 1970, Ch. 8.

    Examples
    --------
    Against python-control's LQR and estimator assembled by hand, in continuous time:

    >>> import numpy as np, control, robustctl as rc
    >>> plant = rc.Plant([[0.0, 1.0], [0.0, 0.0]], [[0.0], [1.0]], None, C=[[1.0, 0.0]])
    >>> ctrl = rc.lqg(plant, Q=np.eye(2), R=[[1.0]], W=np.eye(2), V=[[0.1]], Bw=np.eye(2))
    >>> K = -control.lqr(plant.F, plant.G, np.eye(2), [[1.0]])[0]
    >>> L = control.lqe(plant.F, np.eye(2), plant.C, np.eye(2), [[0.1]])[0]
    >>> bool(np.allclose(ctrl.Ac, plant.F + plant.G @ K - L @ plant.C)), bool(np.allclose(ctrl.Bc, L))
    (True, True)
    """
    check_plant(plant)
    form = check_choice(form, "form", ("filter", "predictor"))
    est = kalman(plant, W, V, Bw=Bw, N=N, form=form if plant.is_discrete else "filter")  # Kalman-Bucy: one form
    regulator = lqr(plant, Q=Q, R=R)
    return observer_controller(regulator, est, method="lqg", info={"lqr": regulator, "form": est.form})


def rlqg(plant: Plant, EF=None, EG=None, mu=None, *, Q=None, R=None, H=None, W, V, Bw=None, mu_filter=None,
         HC=None, EC=None, alpha: float = DEFAULT_ALPHA, form: str = "filter", check_stability: bool = True
         ) -> Controller:
    r"""Robust LQG: the robust LQR on the robust filter's estimate, for one norm-bounded uncertainty.

    The paper's controller [1]_ for a plant with sensors: :func:`robustctl.rlqr`
    for ``[dF dG] = H Delta [EF EG]`` and :func:`robustctl.robust_kalman` for
    the same uncertainty of ``F`` and ``G`` (and, with ``HC`` and ``EC``, of
    ``C``), both in the regularised least-squares framework.

    Parameters
    ----------
    plant : Plant
        Discrete time, with measured outputs.
    EF, EG, mu, Q, R, H
        As in :func:`robustctl.rlqr` (``mu`` may be ``np.inf``).
    W, V, Bw
        As in :func:`robustctl.robust_kalman`.
    mu_filter : float, optional
        The filter's penalty parameter; default ``mu``.
    HC, EC : array_like, optional
        Uncertainty of the output matrix, ``dC = HC Delta2 EC``.
    alpha : float, default 0.1
        ``lambda = (1 + alpha) ||mu H'H||`` for both.
    form : {"filter", "predictor"}
        The estimate fed back (see :func:`observer_controller`).
    check_stability : bool, default True
        Raise :class:`~robustctl.NotStabilizingError` when the robust LQR or
        the nominal loop is not stable (``False`` returns the design anyway).

    Returns
    -------
    Controller
        A dynamic controller of order ``n``; ``info`` holds ``"K"``,
        ``"estimator"``, ``"rlqr"`` (its Controller) and ``"form"``.

    Raises
    ------
    robustctl.NotStabilizingError
        The robust LQR and the robust filter are each stable but their loop
        is not (Notes), with ``check_stability`` True.
    Others
        As :func:`robustctl.rlqr` and :func:`robustctl.robust_kalman`.

    See Also
    --------
    lqg, observer_controller

    Notes
    -----
    With no uncertainty (``EF = 0``, ``EG = 0``) and a large ``mu`` both parts
    tend to their nominal counterparts, and the controller to the LQG.

    The separation principle does not hold: the robust filter runs a
    modified model ``(F_e, G_e)`` that treats ``EF x + EG u`` as a
    pseudo-measurement of zero, weighted by ``lambda ~ mu`` (exact at
    ``mu = inf``). With an input term ``EG`` that pseudo-measurement feeds
    the control back into the estimate, and at a large ``mu_filter`` the loop
    can be unstable although the regulator and the filter are each stable;
    a smaller ``mu_filter``, or ``EG`` left out of the filter's model, is
    then the remedy (the user guide measures it).

    References
    ----------
    .. [1] G. A. Prudencio de Morais et al., "Robust path-following control
       design of heavy vehicles based on multiobjective evolutionary
       optimization", Expert Systems with Applications 192, 116304, 2022.
    .. [2] J. Y. Ishihara, M. H. Terra, J. P. Cerri, "Optimal robust filtering
       for systems subject to uncertainties", Automatica 52, 2015.

    Examples
    --------
    Without uncertainty the robust LQG is the LQG:

    >>> import numpy as np, robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], 0.1, C=[[1.0, 0.0]], Bw=np.eye(2))
    >>> a = rc.rlqg(plant, [[0.0, 0.0]], [[0.0]], 1e12, H=[[0.0], [0.0]], W=1e-3 * np.eye(2), V=[[1e-2]])
    >>> b = rc.lqg(plant, W=1e-3 * np.eye(2), V=[[1e-2]])
    >>> bool(np.allclose(a.Ac, b.Ac, atol=1e-8)), bool(np.allclose(a.Dc, b.Dc, atol=1e-8))
    (True, True)
    """
    check_plant(plant, discrete_for="rlqg")
    form = check_choice(form, "form", ("filter", "predictor"))
    regulator = rlqr(plant, EF, EG, mu, Q=Q, R=R, H=H, alpha=alpha, check_stability=check_stability)
    est = robust_kalman(plant, W, V, Bw=Bw, H=regulator.info["H"], EF=EF, EG=EG, HC=HC, EC=EC,
                        mu=mu if mu_filter is None else mu_filter, alpha=alpha, form=form)
    ctrl = observer_controller(regulator, est, method="rlqg", info={"rlqr": regulator, "form": form})
    if check_stability and not ctrl.is_stabilizing():
        radius = float(np.abs(ctrl.closed_loop_poles()).max())
        raise NotStabilizingError(
            f"the robust LQG loop is not stable (spectral radius {radius:.6g}) although the robust LQR and the "
            f"robust filter each are: the filter's pseudo-measurement EF x + EG u = 0 at mu_filter = "
            f"{est.info.get('mu', mu_filter if mu_filter is not None else mu)} feeds the input back into the "
            "estimate; use a smaller mu_filter, or pass check_stability=False to get this design anyway")
    return ctrl
