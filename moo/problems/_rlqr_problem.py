"""What the two RLQR tuning MOPs of the paper share (Morais et al. 2022, Sections 3.1, 4.4, 4.5).

A decision vector ``z = (E_F (n), E_G (m), (log10 mu)^2)`` parametrises a
steady-state robust LQR gain ``u = K x`` designed with the candidate
uncertainty ``(E_F, E_G)``, ``H`` and penalty ``mu = 10**sqrt(z[-1])`` (the
paper searches ``(log10 mu)^2``). :class:`RLQRTuningProblem` holds the steps
both MOPs take for a whole population at once:

1. check and decode the population (:meth:`~RLQRTuningProblem.decode`);
2. design all gains in one batched call (:func:`robustctl.rlqr_gains`);
3. screen the closed loops ``F_s + G_s M K`` of the S scenarios for Schur
   stability (:func:`robustctl.is_schur_stable`, and
   :func:`robustctl.spectral_radius` for the unstable designs' penalty; ``M``
   maps the controller's inputs to the plant's, e.g. the doubled steering
   column);
4. compute the raw objectives of the stable designs only (the subclass's
   :meth:`~RLQRTuningProblem.scenario_objectives`, one batched simulation),
   combine the scenarios (``mean`` or ``max``) and apply the penalty rule.

The penalty rule (:func:`penalise`) makes every objective finite: not
computable designs (the RLQR failed or did not converge) get ``2 * penalty``,
unstable ones ``penalty * min(rho, 2)`` (``rho`` the largest closed-loop
spectral radius over the scenarios, so the MOEA still prefers the less
unstable), stable ones ``min(J, penalty)``.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pymoo.core.problem import Problem

import robustctl as rc
from robustctl.batchsim import BACKENDS
from robustctl.validation import check_positive_scalar

from .._validation import as_float_array, as_matrix, check_int

__all__ = ["RLQRTuningProblem", "penalise"]


def penalise(J: np.ndarray, ok: np.ndarray, stable: np.ndarray, rho: np.ndarray, penalty: float) -> np.ndarray:
    """Apply the penalty rule (module docstring) to raw objectives ``J`` (B, M).

    ``ok`` (B,): the RLQR design was computed; ``stable`` (B,): its closed
    loops are Schur-stable in every scenario; ``rho`` (B,): the largest
    closed-loop spectral radius over the scenarios (read only where
    ``ok & ~stable``). Every returned value is finite and the penalised ones
    are ``>= penalty``.
    """
    out = np.where(np.isfinite(J), np.minimum(J, penalty), penalty)
    unstable = ok & ~stable
    out[unstable] = (penalty * np.minimum(np.nan_to_num(rho[unstable], nan=2.0), 2.0))[:, None]
    out[~ok] = 2.0 * penalty
    return out


def _ref_point(value, name: str, default: np.ndarray) -> np.ndarray:
    if value is None:
        return default.copy()
    arr = as_matrix(value, name, rows=1, cols=default.size, cols_what="the number of objectives").ravel()
    if np.any(arr <= 0):
        raise ValueError(f"{name} must have positive entries, got {arr}")
    return arr


class RLQRTuningProblem(Problem):
    """Population ``z`` (B, n + m + 1) -> batched RLQR gains -> stability screen -> penalised objectives.

    Subclasses call ``__init__`` with their design plant, scenario plants and
    defaults, and implement :meth:`scenario_objectives`.

    Parameters
    ----------
    plant : robustctl.Plant
        The design model (n states, m inputs).
    H : (n, 1) ndarray
        Uncertainty input of the RLQR design.
    F_s, G_s : (S, n, n), (S, n, p) ndarray
        The true plants of the S scenarios (stability screen).
    input_map : (p, m) array_like or None
        Plant inputs from controller inputs (None: identity, p = m).
    Q, R, alpha, max_iter, aggregate, penalty, hv_ref_point, molsp_ref_point
        As documented by the subclasses; ``Q``, ``R`` and ``alpha`` are checked
        by :func:`robustctl.rlqr_gains` itself (one trial design here), so a bad
        weight is reported at construction with the library's message.
    fallback : {"recursion", "newton"}
        :func:`robustctl.rlqr_gains`'s treatment of designs the doubling
        leaves unsettled.
    default_hv, default_molsp : (M,) ndarray
        The subclass's reference points.
    n_obj : int
    xl, xu : float or (n_var,) array_like
        Bounds of ``z``.
    backend : {"numba", "numpy"}
        Simulator backend (:mod:`robustctl.batchsim`): the compiled kernel or
        the numpy reference.
    """

    def __init__(self, plant: rc.Plant, H: np.ndarray, F_s: np.ndarray, G_s: np.ndarray, input_map, *,
                 Q, R, alpha: float, max_iter: int, fallback: str, aggregate: str, penalty: float, hv_ref_point,
                 molsp_ref_point, default_hv: np.ndarray, default_molsp: np.ndarray, n_obj: int, xl, xu,
                 backend: Literal["numba", "numpy"]):
        self.plant, self.H = plant, H
        self.alpha = check_positive_scalar(alpha, "alpha")
        self.max_iter = check_int(max_iter, "max_iter", 1)
        n, m = plant.n, plant.m
        self.Q = np.eye(n) if Q is None else as_matrix(Q, "Q")
        self.R = np.eye(m) if R is None else as_matrix(R, "R")
        self.fallback = fallback
        rc.rlqr_gains(plant, np.zeros((1, 1, n)), np.zeros((1, 1, m)), np.ones(1), Q=self.Q, R=self.R, H=H,
                      alpha=self.alpha, max_iter=1, fallback=fallback)   # checks Q, R, H, alpha, fallback
        if aggregate not in ("mean", "max"):
            raise ValueError(f"aggregate must be 'mean' or 'max', got {aggregate!r}")
        self.aggregate = aggregate
        self.penalty = check_positive_scalar(penalty, "penalty")
        self.hv_ref_point = _ref_point(hv_ref_point, "hv_ref_point", default_hv)
        self.molsp_ref_point = _ref_point(molsp_ref_point, "molsp_ref_point", default_molsp)
        if backend not in BACKENDS:
            raise ValueError(f"backend must be one of {', '.join(map(repr, BACKENDS))}, got {backend!r}")
        self.backend = backend
        M = np.eye(G_s.shape[-1]) if input_map is None else np.asarray(input_map, dtype=float)
        self._G_s_steer = G_s @ M                                           # (S, n, m): F_s + G_s M K
        self._F_s = F_s
        super().__init__(n_var=n + m + 1, n_obj=n_obj, xl=xl, xu=xu, vtype=float)

    # -- population ------------------------------------------------------------
    def population(self, z, name: str = "z") -> np.ndarray:
        """``z`` as a finite (B, n_var) float array (a single (n_var,) vector becomes B = 1)."""
        arr = as_float_array(z, name)
        if arr.ndim == 1:
            arr = arr[None, :]
        if arr.ndim != 2 or arr.shape[1] != self.n_var:
            raise ValueError(f"{name} must have shape (B, {self.n_var}) (one decision vector per row), "
                             f"got shape {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{name} must have finite entries (found NaN or inf)")
        if np.any(arr[:, -1] < 0):
            raise ValueError(f"the last variable of {name}, (log10 mu)^2, must be >= 0, got {arr[:, -1].min():g}")
        return arr

    def decode(self, z) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(EF (B, 1, n), EG (B, 1, m), mu (B,))`` of a population ``z`` (B, n + m + 1) or one ``z``.

        ``mu = 10 ** sqrt(z[:, -1])``. ``(n, m)`` is ``(3, 1)`` for the generic
        problem and ``(4, 2)`` for the applied one.
        """
        z = self.population(z)
        n, m = self.plant.n, self.plant.m
        return z[:, None, :n].copy(), z[:, None, n:n + m].copy(), 10.0 ** np.sqrt(z[:, n + m])

    def gains(self, z) -> rc.RLQRBatch:
        """The batched RLQR design of a population ``z`` (B, n + m + 1)."""
        EF, EG, mu = self.decode(z)
        return rc.rlqr_gains(self.plant, EF, EG, mu, Q=self.Q, R=self.R, H=self.H, alpha=self.alpha,
                             max_iter=self.max_iter, fallback=self.fallback)

    # -- closed loops -------------------------------------------------------------
    def check_gains(self, K) -> np.ndarray:
        """``K`` as a (B, m, n) float array (NaN rows allowed: failed designs)."""
        K = as_float_array(K, "K")
        n, m = self.plant.n, self.plant.m
        if K.ndim != 3 or K.shape[1:] != (m, n):
            raise ValueError(f"K must have shape (B, {m}, {n}), got shape {K.shape}")
        return K

    def closed_loops(self, K) -> np.ndarray:
        """The true closed loops ``F_s + G_s M K`` (B, S, n, n) of gains ``K`` (B, m, n)."""
        K = self.check_gains(K)
        return self._F_s[None] + self._G_s_steer[None] @ K[:, None]

    def closed_loop_radius(self, K) -> np.ndarray:
        """Spectral radius (B, S) of the true closed loop per scenario (inf for non-finite K)."""
        return np.asarray(rc.spectral_radius(self.closed_loops(K)))      # a stack: an array

    def stability(self, K) -> tuple[np.ndarray, np.ndarray]:
        """``(stable (B, S), rho (B,))``: Schur stability per scenario, and the worst spectral radius.

        ``rho`` is the largest spectral radius over the scenarios of the designs unstable somewhere
        (NaN for the others, which need no eigenvalues; inf for non-finite K).
        """
        A = self.closed_loops(K)
        stable = np.asarray(rc.is_schur_stable(A))                         # a stack: an array
        rho = np.full(A.shape[0], np.nan)
        bad = ~stable.all(axis=1)
        if bad.any():
            rho[bad] = np.asarray(rc.spectral_radius(A[bad])).max(axis=1)
        return stable, rho

    def scenario_objectives(self, K: np.ndarray) -> np.ndarray:
        """Raw objectives (B, S, n_obj) of finite gains whose closed loops are all stable (subclass)."""
        raise NotImplementedError

    # -- pymoo hooks -----------------------------------------------------------------
    def evaluate(self, X, *args, **kwargs):
        """Check ``X`` (errors that name it, not pymoo's assertion), then pymoo's ``Problem.evaluate``."""
        arr = self.population(X, "X")
        return super().evaluate(arr[0] if np.ndim(X) == 1 else arr, *args, **kwargs)

    def _evaluate(self, x, out, *args, **kwargs):
        z = self.population(x, "X")
        batch = self.gains(z)
        ok = np.asarray(batch.ok, dtype=bool) & np.all(np.isfinite(batch.K), axis=(1, 2))
        K = np.where(ok[:, None, None], batch.K, np.nan)
        stable, rho = self.stability(K)
        run = ok & stable.all(axis=1)
        J = np.full((z.shape[0], self.n_obj), np.inf)
        if run.any():
            e = self.scenario_objectives(K[run])
            J[run] = e.mean(axis=1) if self.aggregate == "mean" else e.max(axis=1)
        out["F"] = penalise(J, ok, run, rho, self.penalty)
