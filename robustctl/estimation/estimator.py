r"""The result of a filter design: an :class:`Estimator` (one design) or an :class:`EstimatorBatch`.

Every estimator of :mod:`robustctl.estimation` (the Kalman filter, the robust
filter) is a linear recursion on the a-priori estimate ``xhat = x[k|k-1]``
with the innovation ``e = y[k] - C xhat - D u[k]``:

.. math::

    \hat x_{k|k} = \hat x_{k|k-1} + L_f e_k, \qquad
    \hat x_{k+1|k} = F_e \hat x_{k|k} + G_e u_k + J e_k
                   = F_e \hat x_{k|k-1} + G_e u_k + L_p e_k, \quad L_p = F_e L_f + J .

``Fe``, ``Ge`` are the plant's ``F``, ``G`` for the Kalman filter and the
robust filter's modified model otherwise; ``J = Bw N Re^-1`` for a Kalman
filter with a cross-covariance ``N`` and zero otherwise. The ``"filter"``
form estimates ``x[k]`` by ``x[k|k]`` (it uses ``y[k]``: the filter gain
``Lf``); the ``"predictor"`` form by ``x[k|k-1]`` (the predictor gain
``Lp``, what python-control's ``dlqe`` returns). MATLAB's ``kalman`` calls the
two the ``"current"`` and ``"delayed"`` estimators.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._validation import as_float_array, as_matrix, check_spd
from ..errors import ConvergenceError
from ._model import FilterModel
from ._recursion import step as filter_step

if TYPE_CHECKING:
    from ..systems.plant import Plant

__all__ = ["Estimator", "EstimatorBatch", "FilterRun", "FORMS"]

#: The two forms of a discrete-time estimator.
FORMS = ("filter", "predictor")


@dataclass(frozen=True, eq=False, repr=False)
class FilterRun:
    """The time-varying filter run on whole sequences (:meth:`Estimator.run`).

    ``N`` trajectories of ``T`` steps (no leading axis when one trajectory was given).

    Parameters
    ----------
    x_prior, x_filtered, x_next, P_prior, P_filtered, L, form :
        The attributes below (built by :meth:`Estimator.run`).

    Attributes
    ----------
    x_prior : (N, T, n) ndarray
        ``x[k|k-1]``, the estimate of ``x[k]`` before ``y[k]`` (``x_prior[..., 0, :] = x0``).
    x_filtered : (N, T, n) ndarray
        ``x[k|k]``, after ``y[k]``.
    x_next : (N, n) ndarray
        ``x[T|T-1]``, the prediction of the state after the last step.
    P_prior, P_filtered : (T, n, n) ndarrays
        Their covariances (the same for every trajectory).
    L : (T, n, p) ndarray
        The gain of the estimator's form at each step.
    form : str

    Examples
    --------
    From a wide prior the time-varying gain settles to the steady-state one:

    >>> import numpy as np, robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1, C=[[1.0, 0.0]])
    >>> est = rc.kalman(plant, np.diag([1e-4, 1e-2]), [[0.01]])
    >>> run = est.run(np.zeros((300, 1)), np.zeros((300, 1)), P0=100 * np.eye(2))
    >>> run
    FilterRun(form='filter', x shape (300, 2))
    >>> bool(np.allclose(run.L[-1], est.L)), bool(np.allclose(run.P_prior[-1], est.P))
    (True, True)
    """

    x_prior: np.ndarray
    x_filtered: np.ndarray
    x_next: np.ndarray
    P_prior: np.ndarray
    P_filtered: np.ndarray
    L: np.ndarray
    form: str

    @property
    def x(self) -> np.ndarray:
        """The form's estimate of ``x[k]``: ``x_filtered`` (``"filter"``) or ``x_prior`` (``"predictor"``)."""
        return self.x_filtered if self.form == "filter" else self.x_prior

    def __repr__(self) -> str:
        return f"FilterRun(form={self.form!r}, x shape {self.x_prior.shape})"


@dataclass(frozen=True, eq=False, repr=False)
class Estimator:
    r"""A steady-state estimator of a plant's state from its inputs and measured outputs.

    Made by :func:`robustctl.kalman` and :func:`robustctl.robust_kalman`.

    Parameters
    ----------
    L_filter, L_predictor, P, P_filtered, form, F, G, J, plant, method, info :
        The attributes below (built by the functions above).

    Attributes
    ----------
    L : (n, p) ndarray
        The gain of the form: the filter gain ``Lf`` (``"filter"``) or the
        predictor gain ``Lp`` (``"predictor"``).
    P : (n, n) ndarray
        The steady-state a-priori covariance ``P = cov(x[k] - x[k|k-1])``
        (whatever the form; python-control's ``dlqe`` returns the same).
    P_filtered : (n, n) ndarray
        The a-posteriori covariance ``cov(x[k] - x[k|k])``.
    form : {"filter", "predictor"}
    F, G : ndarrays
        The estimator's model ``Fe`` (n, n), ``Ge`` (n, m) (module docstring).
    J : (n, p) ndarray
        The innovation term of the time update (zero unless a cross-covariance ``N`` was given).
    L_filter, L_predictor : (n, p) ndarrays
        Both gains, whatever the form (``L_predictor = F L_filter + J``).
    plant : Plant
    method : str
        ``"kalman"`` or ``"robust_kalman"``.
    info : Mapping
        Design data (``W``, ``V``, ``Bw``, ...; see the function that made it).

    Examples
    --------
    The steady-state recursion (:meth:`step`) is the time-varying filter
    (:meth:`run`) started from the steady-state covariance:

    >>> import numpy as np, robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1, C=[[1.0, 0.0]])
    >>> est = rc.kalman(plant, np.diag([1e-4, 1e-2]), [[0.01]])
    >>> rng = np.random.default_rng(0)
    >>> u, y = rng.normal(size=(50, 1)), rng.normal(size=(50, 1))
    >>> run = est.run(u, y)                      # x0 = 0, P0 = est.P
    >>> xhat = np.zeros(2)
    >>> for k in range(50):
    ...     xhat, x_k = est.step(xhat, u[k], y[k])
    >>> bool(np.allclose(x_k, run.x[-1])), bool(np.allclose(xhat, run.x_next))
    (True, True)
    """

    L_filter: np.ndarray
    L_predictor: np.ndarray
    P: np.ndarray
    P_filtered: np.ndarray
    form: str
    F: np.ndarray
    G: np.ndarray
    J: np.ndarray
    plant: Plant
    method: str
    info: Mapping[str, Any] = field(default_factory=dict)
    _model: FilterModel | None = field(default=None, repr=False)

    @property
    def L(self) -> np.ndarray:
        """The gain of the form (``L_filter`` or ``L_predictor``)."""
        return self.L_filter if self.form == "filter" else self.L_predictor

    @property
    def n(self) -> int:
        """Number of states."""
        return self.P.shape[0]

    @property
    def closed_loop(self) -> np.ndarray:
        """``A = F - L_predictor C``: the estimator's own dynamics, ``xhat+ = A xhat + ...`` (stable).

        For a continuous-time plant, ``d xhat/dt = A xhat + ...`` with ``A = F - L C``.
        """
        return self.F - self.L_predictor @ self.plant.output_matrices()[0]

    def _discrete(self, what: str) -> FilterModel:
        if self._model is None:
            raise ValueError(f"{what} needs a discrete-time estimator; this one is continuous-time "
                             "(discretise the plant, e.g. Plant.from_continuous, and design again)")
        return self._model

    def step(self, xhat, u, y) -> tuple[np.ndarray, np.ndarray]:
        """One step of the steady-state estimator.

        Parameters
        ----------
        xhat : (n,) or (N, n) array_like
            The a-priori estimate ``x[k|k-1]`` (the estimator's state).
        u : (m,) or (N, m) array_like
            The input ``u[k]``.
        y : (p,) or (N, p) array_like
            The measurement ``y[k]``.

        Returns
        -------
        x_next : ndarray
            ``x[k+1|k]``, the estimator's next state.
        x_est : ndarray
            The form's estimate of ``x[k]``: ``x[k|k]`` (``"filter"``) or ``x[k|k-1]`` (``"predictor"``).
        """
        d = self._discrete("step")
        xhat, u, y = (self._col(a, name, size) for a, name, size in
                      ((xhat, "xhat", self.n), (u, "u", d.G.shape[1]), (y, "y", d.C.shape[0])))
        e = y - xhat @ d.C.T - u @ d.D.T
        xf = xhat + e @ self.L_filter.T
        x_next = xf @ self.F.T + u @ self.G.T + e @ self.J.T
        return x_next, (xf if self.form == "filter" else xhat)

    @staticmethod
    def _col(value, name: str, size: int) -> np.ndarray:
        arr = as_float_array(value, name)
        if arr.ndim == 0 and size == 1:
            arr = arr.reshape(1)
        if arr.ndim not in (1, 2) or arr.shape[-1] != size:
            raise ValueError(f"{name} must have shape ({size},) or (N, {size}), got shape {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{name} must have finite entries (found NaN or inf)")
        return arr

    def run(self, u, y, x0=None, P0=None) -> FilterRun:
        """The time-varying filter on whole sequences, from the prior ``(x0, P0)`` of ``x[0]``.

        Parameters
        ----------
        u : (T, m) or (N, T, m) array_like
            Inputs ``u[0] .. u[T-1]``.
        y : (T, p) or (N, T, p) array_like
            Measurements ``y[0] .. y[T-1]`` (the same leading shape as ``u``).
        x0 : (n,) or (N, n) array_like, default zeros
            The prior mean of ``x[0]`` (before ``y[0]``).
        P0 : (n, n) array_like, default ``P``
            The prior covariance of ``x[0]`` (symmetric positive semidefinite).
            From the steady state ``P`` the gains stay at their steady values.

        Returns
        -------
        FilterRun
            Estimates, covariances and gains at every step: the
            time-varying (finite-horizon) filter; for the robust filter the
            recursion of Ishihara, Terra & Cerri (2015) with its time-varying
            modified model.
        """
        d = self._discrete("run")
        n, m, p = self.n, d.G.shape[1], d.C.shape[0]
        u = as_float_array(u, "u")
        y = as_float_array(y, "y")
        if u.ndim == 1 and m == 1:
            u = u[:, None]
        if y.ndim == 1 and p == 1:
            y = y[:, None]
        if u.ndim not in (2, 3) or u.shape[-1] != m:
            raise ValueError(f"u must have shape (T, {m}) or (N, T, {m}), got shape {u.shape}")
        if y.shape[:-1] != u.shape[:-1] or y.shape[-1] != p:
            raise ValueError(f"y must have shape {(*u.shape[:-1], p)} (u's leading axes, {p} outputs), "
                             f"got shape {y.shape}")
        for name, arr in (("u", u), ("y", y)):
            if not np.all(np.isfinite(arr)):
                raise ValueError(f"{name} must have finite entries (found NaN or inf)")
        single = u.ndim == 2
        U, Y = (u[None], y[None]) if single else (u, y)
        Ntraj, T = U.shape[:2]
        x = np.zeros((Ntraj, n)) if x0 is None else self._col(x0, "x0", n)
        x = np.broadcast_to(x, (Ntraj, n)).copy() if x.ndim == 1 else x
        if x.shape[0] != Ntraj:
            raise ValueError(f"x0 must have shape ({n},) or ({Ntraj}, {n}), got shape {x.shape}")
        P = self.P if P0 is None else check_spd(as_matrix(P0, "P0", rows=n, cols=n), "P0", semidefinite=True)
        x_prior, x_filt = np.empty((Ntraj, T, n)), np.empty((Ntraj, T, n))
        P_prior, P_filt, gains = np.empty((T, n, n)), np.empty((T, n, n)), np.empty((T, n, p))
        P = P[None]
        with np.errstate(over="ignore", invalid="ignore"):
            for k in range(T):
                g = filter_step(P, d)
                e = Y[:, k] - x @ d.C.T - U[:, k] @ d.D.T
                xf = x + e @ g.Lf[0].T
                x_prior[:, k], x_filt[:, k], P_prior[k], P_filt[k] = x, xf, P[0], g.Pf[0]
                gains[k] = g.Lf[0] if self.form == "filter" else g.Fe[0] @ g.Lf[0] + g.Je[0]
                x = xf @ g.Fe[0].T + U[:, k] @ g.Ge[0].T + e @ g.Je[0].T
                P = g.P_next
        if not (np.isfinite(P_prior).all() and np.isfinite(x_filt).all()):
            raise ConvergenceError("the time-varying filter produced non-finite values (is P0 positive "
                                   "definite where the uncertainty constraints need it?)")
        if single:
            x_prior, x_filt, x = x_prior[0], x_filt[0], x[0]
        return FilterRun(x_prior, x_filt, x, P_prior, P_filt, gains, self.form)

    def __repr__(self) -> str:
        time = "continuous" if not self.plant.is_discrete else f"dt={self.plant.dt:g}"
        return (f"Estimator(method={self.method!r}, form={self.form!r}, n={self.n}, "
                f"p={self.L_filter.shape[1]}, {time})")


@dataclass(frozen=True, eq=False, repr=False)
class EstimatorBatch:
    """Steady-state estimators of one plant for a batch of ``B`` designs.

    Made by :func:`robustctl.kalman_gains` and :func:`robustctl.robust_kalman_gains`:
    design ``b`` is the estimator that :func:`robustctl.kalman` (or
    :func:`robustctl.robust_kalman`) makes of the ``b``-th covariances (or
    uncertainty), as entries of stacked arrays; a design that fails is
    flagged in ``ok`` and ``reason``, never raised for the batch.

    Parameters
    ----------
    L, P, F, G, J, ok, reason, stable, iterations, residual, form :
        The attributes below.

    Attributes
    ----------
    L : (B, n, p) ndarray
        The gains of the form (NaN where ``ok`` is False).
    P : (B, n, n) ndarray
        Steady-state a-priori covariances.
    F, G, J : ndarrays
        The estimators' models (:class:`Estimator`), (B, n, n), (B, n, m), (B, n, p).
    ok : (B,) bool ndarray
        The design converged to a stabilising steady state.
    reason : (B,) str ndarray
        Why a design failed (``"ok"`` where it did not):

        ====================  ==================================================
        ``reason``            meaning
        ====================  ==================================================
        ``"ok"``              a stabilising steady state
        ``"undetectable"``    ``(C, F)`` is not detectable (every design)
        ``"not converged"``   no stabilising fixed point within ``max_iter``
                              steps (or one more step still moves ``P``)
        ``"diverged"``        ``P`` grows without bound
        ====================  ==================================================
    stable : (B,) bool ndarray
        The estimator's own loop ``F - L_predictor C`` is stable (always True where ``ok``).
    iterations : (B,) int ndarray
        Doubling steps plus Newton and recursion steps where they were needed.
    residual : (B,) ndarray
        Relative change of ``P`` in one more step of the recursion.
    form : str

    Examples
    --------
    Two measurement noise levels at once; a plant that measures only the
    velocity cannot see the position (an integrator: ``(C, F)`` is not
    detectable), and every design is flagged:

    >>> import numpy as np, robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1, C=[[1.0, 0.0]])
    >>> batch = rc.kalman_gains(plant, np.diag([1e-4, 1e-2]), [[[0.01]], [[0.1]]])
    >>> batch.ok.tolist(), batch.L.shape
    ([True, True], (2, 2, 1))
    >>> blind = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1, C=[[0.0, 1.0]])
    >>> rc.kalman_gains(blind, np.diag([1e-4, 1e-2]), [[0.01]]).reason.tolist()
    ['undetectable']
    """

    L: np.ndarray
    P: np.ndarray
    F: np.ndarray
    G: np.ndarray
    J: np.ndarray
    ok: np.ndarray
    reason: np.ndarray
    stable: np.ndarray
    iterations: np.ndarray
    residual: np.ndarray
    form: str

    def __len__(self) -> int:
        return self.L.shape[0]

    def __repr__(self) -> str:
        return (f"EstimatorBatch(B={len(self)}, n={self.L.shape[1]}, p={self.L.shape[2]}, form={self.form!r}, "
                f"ok={int(self.ok.sum())}/{len(self)}, max_iterations={int(self.iterations.max(initial=0))})")
