"""Shared by the analyses of :mod:`robustctl.analysis`: tolerances, the loop and linear algebra.

The tolerances of every analysis (in one place), the loop ``(plant, K)``
from a controller, and the linear algebra of the certificates: the
Lyapunov coordinates, the dissipation blocks and their eigenvalues.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .. import _cvx
from .._validation import as_float_array, as_matrix
from ..errors import ConvergenceError
from ..systems.controller import Controller, ControllerBatch
from ..systems.interconnect import augmented_gain
from ..systems.plant import Plant
from ..systems.stability import spectral_abscissa, spectral_radius
from ..systems.uncertainty import NormBounded, check_norm_bounded

# Regularisation (relative to the weight's norm) of the Lyapunov equation defining the coordinates.
_REG = 1e-3
# When the margin is <= 1, P certifies the radius margin / (1 + _BACKOFF).
_BACKOFF = 1e-3
# A certificate eigenvalue is strict if it exceeds _STRICT times max(1, ||block||).
_STRICT = 1e-12
# Polytope margin: feasibility margin t (normalised coordinates) that counts as
# strictly feasible, bisection tolerance (relative) and the largest scaling searched.
_POLY_T = 1e-9
_POLY_RTOL = 1e-3
_POLY_RMAX = 1e3
_POLY_STEPS = 60
# Riccati certificate: tries of the regularisation eps (each 100 times smaller) before the SDP.
_EPS_TRIES = 3
# Batched guaranteed cost: a Riccati solution counts when the LMI's smallest eigenvalue is at least
# -_COST_LMI_TOL times its largest (rounding of a boundary point).
_COST_LMI_TOL = 1e-9
# One loop: state size from which the Riccati certificate is tried by the doubling algorithm first.
_SDA_MIN_N = 14
# Worst-case search: projected-gradient iterations per start.
_ASCENT_ITER = 200


# ---------------------------------------------------------------- validation
def _augmented_plant(plant: Plant, order: int) -> Plant:
    """``(diag(F, 0), diag(G, I), dt)``: the plant whose static gain ``K_a`` is a dynamic controller's loop."""
    if order == 0:
        return plant
    n = plant.n
    Fa = np.zeros((n + order, n + order))
    Fa[:n, :n] = plant.F
    return Plant(Fa, scipy.linalg.block_diag(plant.G, np.eye(order)), plant.dt)


def _augmented_uncertainty(uncertainty: NormBounded, order: int) -> NormBounded:
    """The uncertainty of the augmented loop: ``H_a = [H; 0]``, ``EF_a = [EF 0]``, ``EG_a = [EG 0]``.

    The controller is known exactly: the uncertainty acts on the plant part
    (:mod:`robustctl.systems.interconnect`).
    """
    if order == 0:
        return uncertainty
    H, EF, EG = uncertainty.H, uncertainty.EF, uncertainty.EG
    pad = np.zeros((EF.shape[0], order))
    return NormBounded(np.vstack([H, np.zeros((order, H.shape[1]))]), np.hstack([EF, pad]), np.hstack([EG, pad]))


def _controller_plant(controller) -> Plant:
    """The plant a controller (or a ``(plant, K)`` pair) was given with: what its arguments are checked against."""
    return controller[0] if isinstance(controller, tuple) else controller.plant


def _uncertain_loop(controller, uncertainty, batch: bool = False) -> tuple[Plant, np.ndarray, NormBounded]:
    """``(plant, K, uncertainty)`` of :func:`_loop`, the uncertainty checked against the controller's plant.

    For a dynamic controller all three are those of the augmented loop.
    """
    plant, K = _loop(controller, batch)
    base = _controller_plant(controller)
    return plant, K, _augmented_uncertainty(check_norm_bounded(uncertainty, base), plant.n - base.n)


def _loop(controller, batch: bool = False) -> tuple[Plant, np.ndarray]:
    """``(plant, K)`` from a Controller, a ControllerBatch or a ``(plant, K)`` pair.

    With ``batch``, ``K`` may also be a stack (B, m, n) (returned 3-D; its
    entries may be non-finite: the caller flags those designs). A dynamic
    controller (or batch) comes back as the static gain ``K_a`` of its
    augmented plant (:mod:`robustctl.systems.interconnect`); an ill-posed
    loop of a batch has NaN entries.
    """
    if isinstance(controller, ControllerBatch) or (isinstance(controller, Controller) and controller.is_dynamic):
        single = isinstance(controller, Controller)
        if not single and not batch:
            raise TypeError("controller must be one robustctl.Controller here, got a ControllerBatch; "
                            "analyse its designs one at a time (batch[i])")
        stack = controller.as_batch() if isinstance(controller, Controller) else controller
        C, D = stack.plant.output_matrices()
        Ka, ok = augmented_gain(C, D, stack.Ac, stack.Bc, stack.Cc, stack.Dc)
        if single and not ok[0]:
            raise ValueError("controller: the loop is ill posed (I - Dc D is singular: u depends on itself)")
        return _augmented_plant(stack.plant, stack.order), Ka[0] if single else Ka
    if isinstance(controller, Controller):
        assert controller.K is not None
        return controller.plant, controller.K
    if isinstance(controller, tuple) and len(controller) == 2 and isinstance(controller[0], Plant):
        plant = controller[0]
        if batch:
            arr = as_float_array(controller[1], "K")
            if arr.ndim == 3:
                if arr.shape[1:] != (plant.m, plant.n) or arr.shape[0] == 0:
                    raise ValueError(f"K must be a gain ({plant.m}, {plant.n}) or a non-empty stack of gains "
                                     f"(B, {plant.m}, {plant.n}) (the numbers of inputs and states), "
                                     f"got shape {arr.shape}")
                return plant, arr
            if arr.ndim > 3:
                raise ValueError(f"K must be a gain ({plant.m}, {plant.n}) or a stack of gains "
                                 f"(B, {plant.m}, {plant.n}), got an array of shape {arr.shape}")
        K = as_matrix(controller[1], "K", rows=plant.m, cols=plant.n,
                      rows_what="the number of inputs", cols_what="the number of states")
        return plant, K
    raise TypeError(f"controller must be a robustctl.Controller, a ControllerBatch or a (Plant, K) pair, "
                    f"got {type(controller).__name__}")


# ---------------------------------------------------------------- linear algebra
def _radius(A: np.ndarray, discrete: bool) -> float:
    """Spectral radius (discrete) or spectral abscissa (continuous)."""
    return float(spectral_radius(A) if discrete else spectral_abscissa(A))


def _lyapunov_factor(A: np.ndarray, Q: np.ndarray, discrete: bool) -> np.ndarray:
    """``L`` with ``L L' = P_L``, ``A'P_L A - P_L + Q_r = 0`` (or ``A'P_L + P_L A + Q_r = 0``).

    ``Q_r = Q + 1e-3 max(||Q||, tiny) I``; ``A`` must be stable.
    """
    n = A.shape[0]
    q = float(np.linalg.norm(Q, 2))
    Qr = Q + _REG * (q if q > 0 else 1.0) * np.eye(n)
    if discrete:
        P = scipy.linalg.solve_discrete_lyapunov(A.T, Qr)
    else:
        P = scipy.linalg.solve_continuous_lyapunov(A.T, -Qr)
    try:
        return np.linalg.cholesky(0.5 * (P + P.T))
    except np.linalg.LinAlgError:
        raise ConvergenceError("the Lyapunov equation of the nominal closed loop has no positive definite "
                               "solution in floating point: the loop is on the edge of stability") from None


def _block(A: np.ndarray, B: np.ndarray, P, N, discrete: bool):
    """``diag(P, 0) - [A B]'P[A B] - N`` (discrete) or ``-He([I 0]'P[A B]) - N`` (continuous).

    ``P`` and ``N`` are numpy arrays or cvxpy expressions; ``M >= 0`` is the dissipation inequality.
    """
    n, k = A.shape[0], B.shape[1]
    AB = np.hstack([A, B])
    I0 = np.eye(n, n + k)
    if discrete:
        return I0.T @ P @ I0 - AB.T @ P @ AB - N
    S = I0.T @ P @ AB
    return -(S + S.T) - N


def _blocks(A: np.ndarray, H: np.ndarray, P: np.ndarray, W: np.ndarray, lam, discrete: bool) -> np.ndarray:
    """:func:`_block` for stacks with ``B = H`` and ``N = diag(W, -lam I)``: shape (S, n + p, n + p).

    ``A``, ``P``, ``W`` (S, n, n); ``H`` (S, n, p) or one (n, p) for all;
    ``lam`` a number or (S,). Discrete: ``[[P - A'PA - W, -A'PH], [-H'PA,
    lam I - H'PH]]``; continuous: ``[[-He(PA) - W, -PH], [-H'P, lam I]]``.
    """
    S, n, p = A.shape[0], A.shape[-1], H.shape[-1]
    AH = np.concatenate([A, np.broadcast_to(H, (S, n, p))], axis=-1)
    if discrete:
        M = -(AH.mT @ P @ AH)
        M[:, :n, :n] += P
    else:
        PAH = P @ AH
        M = np.zeros((S, n + p, n + p))
        M[:, :n, :] = -PAH
        M[:, :, :n] -= PAH.mT
    M[:, :n, :n] -= W
    M[:, n:, n:] += np.asarray(lam)[..., None, None] * np.eye(p)
    return M


def _diag(*blocks: np.ndarray) -> np.ndarray:
    return scipy.linalg.block_diag(*blocks)


def _min_eig(M: np.ndarray) -> float:
    return float(np.linalg.eigvalsh(0.5 * (M + M.T))[0])


class _Coordinates:
    """``x = L'^-1 x^``: maps data in and Lyapunov matrices out (``P = L P^ L'``)."""

    def __init__(self, L: np.ndarray):
        self.L = L

    def A(self, A):
        return self.L.T @ np.linalg.solve(self.L, A.T).T      # L' A L'^-1

    def B(self, B):
        return self.L.T @ B

    def C(self, C):
        return np.linalg.solve(self.L, C.T).T                 # C L'^-1

    def Q(self, Q):
        X = np.linalg.solve(self.L, Q)
        return np.linalg.solve(self.L, X.T).T                 # L^-1 Q L'^-1

    def P(self, P_hat):
        P = self.L @ P_hat @ self.L.T
        return 0.5 * (P + P.T)


def _solve_info(reports) -> dict:
    solves = tuple(r.as_dict() for r in reports)
    return {**_cvx.totals(solves), "solves": solves}
