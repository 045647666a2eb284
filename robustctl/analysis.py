r"""Robust analysis of a state feedback ``u = K x``: LMI certificates and a worst-case search.

For a plant ``(F, G)`` and a gain ``K`` the nominal closed loop is
``A = F + G K``. A norm-bounded uncertainty ``[dF dG] = H Delta [EF EG]``
(:class:`~robustctl.NormBounded`) gives the uncertain loop

    x+ = (A + H Delta E) x,    E = EF + EG K,    ||Delta||_2 <= 1

(``x' = ...`` in continuous time, ``plant.dt is None``), i.e. the feedback
of the nominal loop with ``q = Delta p``, ``p = E x`` entering through ``H``.
A polytope ``vertices=[Plant, ...]`` gives ``A_i = F_i + G_i K``.

Every function takes the controller as a :class:`~robustctl.Controller`
(its ``K`` and ``plant``) or as a pair ``(plant, K)`` (e.g. a gain designed
elsewhere, or a continuous-time one).

The LMIs (discrete time; ``M >= 0`` means positive semidefinite). With the
S-procedure for the quadratic constraint ``|q|^2 <= |E x|^2`` (lossless for
one full block ``Delta``; its multiplier is normalised to 1 where the LMI is
homogeneous):

* quadratic stability for ``||Delta|| <= r`` (Boyd, El Ghaoui, Feron &
  Balakrishnan 1994, Sec. 5.1.2)::

      [ P - A'PA - E'E    -r A'PH       ]
      [ -r H'PA           I - r^2 H'PH  ]  > 0,   P > 0

  By the bounded-real lemma this holds for some ``P`` iff ``A`` is stable
  and ``r ||E (zI - A)^-1 H||_inf < 1`` (Khargonekar, Petersen & Zhou
  1990), so the largest such ``r`` (the *margin*) is the small-gain value.
  It is computed as ``1 / sqrt(mu)`` from the convex problem "minimise
  ``mu`` s.t. ``[[P - A'PA - E'E, -A'PH], [-H'PA, mu I - H'PH]] >= 0``".
* guaranteed cost (Petersen & McFarlane 1994): with ``Q_K = Q + K'RK``::

      [ P - A'PA - Q_K - lam E'E    -A'PH          ]
      [ -H'PA                       lam I - H'PH   ]  >= 0

  implies ``V(x+) - V(x) <= -x'Q_K x`` for ``V = x'Px`` and every
  ``Delta`` (also time-varying), hence ``sum_k x'Qx + u'Ru <= x0'P x0``.
* robust H-infinity performance: with ``z = C_K x + Dzw w``,
  ``C_K = Cz + Dzu K`` and the inputs ``(q, w)``::

      diag(P, 0, 0) - [A H Bw]'P[A H Bw] - lam diag(E'E, -I, 0)
          - [C_K 0 Dzw]'[C_K 0 Dzw] + diag(0, 0, gamma^2 I)  >= 0

  implies ``V(x+) - V(x) <= gamma^2 |w|^2 - |z|^2`` for every ``Delta``,
  hence ``||T_zw||_inf <= gamma``.

Continuous time replaces ``diag(P, 0) - [A B]'P[A B]`` by
``-(He([I 0]' P [A B]))``, ``He(M) = M + M'``.

Norm-bounded robust stability without an SDP
--------------------------------------------
The margin is the small-gain value ``1 / ||E (zI - A)^-1 H||_inf``,
computed by a level-set H-infinity norm (Bruinsma & Steinbuch 1990;
imaginary-axis eigenvalues of a Hamiltonian, the discrete case through a
bilinear transform; :mod:`robustctl._hinfnorm`) to ``2e-10`` relative, on
the whole stack of gains at once. One gain per call uses SLICOT's AB13DD
(the same algorithm with a structure-preserving Hamiltonian eigensolver,
through slycot) when slycot is installed, the level-set iteration without
it (``info["norm"]``: ``"ab13dd"`` or ``"level-set"``). The certificate ``P`` at the radius
``r`` (1 if the margin exceeds 1, else ``margin / (1 + 1e-3)``) is the
stabilising solution of the bounded-real Riccati equation of
``(A, r H, [E; sqrt(eps) I])`` at the level ``gamma`` with
``gamma^2 = (1 + (r / margin)^2) / 2``: between the norm of the scaled loop
and 1, so that the LMI is strictly feasible (its Schur complement is at
least ``eps I``); for one gain of state size 14 or more it is computed by the
structure-preserving doubling algorithm (``n x n`` matrices only; Chu, Fan &
Lin 2005), with the Hamiltonian's eigenvectors as the fallback
(``info["riccati"]``). It is verified like any other certificate (eigenvalues of
the LMI blocks at ``P`` in the plant's coordinates); only a design whose
Riccati certificate fails that check goes to the SDP below (``info["path"]``
says which: ``"riccati"`` or ``"sdp"``). Polytopes always use the SDP.

Numerics of the SDPs
--------------------
* Each problem is solved in coordinates ``x = L'^-1 x^`` where the
  Lyapunov solution ``P_L = L L'`` of the nominal loop (weight: the
  problem's state weight plus ``1e-3`` of its norm times ``I``) becomes
  ``I``, with ``H`` and ``E`` scaled to comparable norms (the margin problem:
  unit norms), ``Bw`` to unit norm and the guaranteed-cost objective to
  unit size. Results are mapped back; margins and bounds are unchanged.
  Every bound is then independent of the units of the weights, of ``w``,
  ``z`` and ``x0`` (scaling ``Q, R`` by ``a^2`` scales the cost by ``a^2``;
  unscaled, the authors' truck weights ``R = 33535`` made the
  guaranteed-cost LMI fail).
* The margin minimisation is non-strict (it computes the infimum); the
  returned ``P`` comes from its optimum ``P*`` as ``P* + eps P_L``, which
  is strictly feasible at any radius below the margin for small ``eps``
  (no second solve). A certificate is a list of smallest eigenvalues,
  computed with numpy from the returned ``P`` in the original coordinates;
  it counts as strict when each exceeds ``1e-12`` times the block's norm.
* Every solve goes through :func:`robustctl._cvx.solve_sdp` (Clarabel,
  status checks, certificate eigenvalues).

Readings where the issue leaves room
------------------------------------
* ``certified`` is decided by the certificate at radius 1, not by
  ``margin > 1`` alone: for a margin within solver rounding of 1 it may be
  ``False``.
* The polytope margin is the largest ``r`` for which the polytope scaled
  by ``r`` about the nominal plant, ``conv{A_0 + r (A_i - A_0)}``, has a
  common Lyapunov matrix (a generalised eigenvalue problem, Boyd et al.
  1994, Sec. 5.1.1), solved by bisection to ``1e-3`` relative (the
  reported value is the certified end of the bracket) up to ``r = 1000``.
* ``guaranteed_cost`` without ``x0`` minimises ``lambda_max(P)``: one
  ``P`` bounds the cost of every unit initial state.

References
----------
S. Boyd, L. El Ghaoui, E. Feron, V. Balakrishnan, *Linear Matrix Inequalities
in System and Control Theory*, SIAM 1994, Sec. 5.1, 6.3.
P. P. Khargonekar, I. R. Petersen, K. Zhou, "Robust stabilization of uncertain
linear systems: quadratic stabilizability and H-infinity control theory",
IEEE TAC 35(3), 1990.
I. R. Petersen, D. C. McFarlane, "Optimal guaranteed cost control and
filtering for uncertain linear systems", IEEE TAC 39(9), 1994.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike
from scipy.linalg import lapack

from . import _cvx, _hinfnorm
from ._validation import as_batch, as_float_array, as_matrix, as_rng, check_int, check_performance, check_spd
from .controller import Controller
from .errors import ConvergenceError, InfeasibleError
from .plant import Plant, _frozen, check_vertices
from .stability import STABILITY_MARGIN, is_stable, spectral_abscissa, spectral_radius
from .uncertainty import NormBounded, check_norm_bounded

__all__ = ["RobustStability", "RobustStabilityBatch", "CostBound", "CostBoundBatch", "HinfBound", "WorstCase",
           "robust_stability", "guaranteed_cost", "robust_hinf_bound", "worst_case"]

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


# ---------------------------------------------------------------- results
def _ro(arr: np.ndarray) -> np.ndarray:
    """A read-only copy that keeps the dtype (bool, str)."""
    arr = np.array(arr)
    arr.flags.writeable = False
    return arr


def _fmt(x) -> str:
    return "None" if x is None else f"{x:.6g}"


@dataclass(frozen=True, eq=False, repr=False)
class RobustStability:
    """Quadratic-stability certificate of a closed loop.

    Attributes
    ----------
    certified : bool
        A common quadratic Lyapunov function ``x'Px`` proves stability for
        every ``||Delta|| <= 1`` (every plant of the polytope).
    margin : float
        Largest ``r`` for which that holds for every ``||Delta|| <= r`` (the
        polytope scaled by ``r``); ``1 / ||E (zI - A)^-1 H||_inf`` for a
        norm-bounded uncertainty; ``0`` if the nominal loop is unstable,
        ``inf`` if the uncertainty does not reach the loop.
    radius : float
        The radius that ``P`` certifies: 1 if ``certified``, else just below
        ``margin`` (0 with ``P = None`` if the nominal loop is unstable).
    P : (n, n) ndarray or None
        Lyapunov matrix, in the plant's coordinates.
    certificate : Mapping[str, float]
        Smallest eigenvalue of each block of the certificate LMI at ``P``
        (module docstring; multiplier 1): ``"P"`` and ``"lyapunov"`` for a
        norm-bounded uncertainty, ``"P"`` and ``"vertex[i]"`` (``i = 0``
        the nominal plant) for a polytope. All positive: proof.
    kind : str
        ``"norm-bounded"`` or ``"polytope"``.
    info : Mapping
        ``"nominal_radius"`` (spectral radius or abscissa of ``F + G K``);
        norm-bounded: ``"path"`` (``"riccati"`` or ``"sdp"``: which
        computation certified ``P``; None if neither passed the check),
        ``"norm"`` (``"ab13dd"`` or ``"level-set"``: which computed the
        H-infinity norm), ``"norm_iterations"`` (level-set steps; 0 for
        AB13DD) and ``"riccati"`` (``"doubling"`` or ``"eigenvectors"``:
        how the certifying Riccati solution was computed; None if the
        Riccati path did not certify); polytope: solver
        diagnostics (``solve_time``, ``iterations``, ``solves``).
    """

    certified: bool
    margin: float
    radius: float
    P: np.ndarray | None
    certificate: Mapping[str, float]
    kind: str
    info: Mapping[str, Any] = field(default_factory=dict)

    def __repr__(self) -> str:
        cert = min(self.certificate.values()) if self.certificate else None
        return (f"RobustStability(certified={self.certified}, margin={_fmt(self.margin)}, "
                f"radius={_fmt(self.radius)}, kind={self.kind!r}, smallest certificate eigenvalue={_fmt(cert)})")


@dataclass(frozen=True, eq=False, repr=False)
class RobustStabilityBatch:
    """Quadratic-stability margins and certificates of a stack of gains ``K`` (B, m, n) on one plant.

    Design ``b`` gets the answer that ``robust_stability((plant, K[b]), ...)``
    gives (:class:`RobustStability`), as entries of arrays.

    ``margin`` and ``reason`` are computed by the call. For a norm-bounded
    uncertainty the certificates (``certified``, ``radius``, ``P``,
    ``certificate``, ``info``) are computed on first access to any of them,
    for the whole stack at once (one batched Riccati solve and eigenvalue
    check, the SDP for designs whose Riccati certificate fails), then kept:
    a caller that needs only the margins (a tuning goal) does not pay for
    them. Pickling computes them first (the result can cross processes).

    Attributes
    ----------
    margin : (B,) ndarray
        ``1 / ||E (zI - A)^-1 H||_inf``; ``0`` where the nominal loop is
        unstable, ``nan`` where ``K[b]`` has a non-finite entry.
    reason : (B,) str ndarray
        ``"ok"`` (analysed: see ``certified`` and ``margin``), ``"unstable"``
        (the nominal loop ``F + G K`` is not stable: margin 0) or
        ``"not finite"`` (``K[b]`` has a NaN or infinite entry: margin NaN).
    kind : str
        ``"norm-bounded"`` or ``"polytope"``.
    certified : (B,) bool ndarray
        As :attr:`RobustStability.certified`: decided by the certificate at radius 1.
    radius : (B,) ndarray
        The radius that ``P[b]`` certifies (0 where there is no ``P``).
    P : (B, n, n) ndarray
        Lyapunov matrices in the plant's coordinates (NaN where there is none).
    certificate : Mapping[str, (B,) ndarray]
        Smallest eigenvalue of each block of the certificate LMI at ``P[b]``
        (the keys of :class:`RobustStability`; NaN where there is no ``P``).
    info : Mapping
        ``"path"``: (B,) str ndarray, which computation certified ``P[b]``
        (``"riccati"``, ``"sdp"``; ``""`` where there is no verified ``P``);
        ``"nominal_radius"``: (B,) spectral radius (abscissa) of ``F + G K``;
        ``"norm"``: ``"level-set"`` (the batched H-infinity norm);
        ``"norm_iterations"``: level-set steps of the H-infinity norm;
        ``"sdp_solves"``: designs that needed the SDP.
    """

    margin: np.ndarray
    reason: np.ndarray
    kind: str
    _certify: Any = field(repr=False)

    @functools.cached_property
    def _bundle(self) -> tuple:
        return self._certify()

    @property
    def certified(self) -> np.ndarray:
        """(B,) bool: certified at radius 1 (computed on first access)."""
        return self._bundle[0]

    @property
    def radius(self) -> np.ndarray:
        """(B,): the radius that ``P`` certifies (computed on first access)."""
        return self._bundle[1]

    @property
    def P(self) -> np.ndarray:
        """(B, n, n): Lyapunov matrices, NaN where there is none (computed on first access)."""
        return self._bundle[2]

    @property
    def certificate(self) -> Mapping[str, np.ndarray]:
        """Smallest eigenvalue of each certificate block, (B,) each (computed on first access)."""
        return self._bundle[3]

    @property
    def info(self) -> Mapping[str, Any]:
        """Diagnostics, ``path`` among them (computed on first access)."""
        return self._bundle[4]

    def __len__(self) -> int:
        return self.margin.shape[0]

    def __getstate__(self) -> dict:
        # pickling computes the certificates and drops the closure that computes them
        certified, radius, P, cert, info = self._bundle
        return {**self.__dict__, "_certify": None, "_bundle": (certified, radius, P, dict(cert), dict(info))}

    def __setstate__(self, state: dict) -> None:
        certified, radius, P, cert, info = state["_bundle"]
        bundle = (certified, radius, P, MappingProxyType(cert), MappingProxyType(info))
        self.__dict__.update({**state, "_bundle": bundle})

    def __repr__(self) -> str:
        ok = self.reason == "ok"
        return (f"RobustStabilityBatch(B={len(self)}, kind={self.kind!r}, certified={int(self.certified.sum())}"
                f"/{len(self)}, unstable={int((self.reason == 'unstable').sum())}, "
                f"not finite={int((self.reason == 'not finite').sum())}, "
                f"smallest margin={_fmt(float(self.margin[ok].min()) if ok.any() else None)})")


@dataclass(frozen=True, eq=False, repr=False)
class CostBound:
    """Guaranteed LQ cost: ``sum x'Qx + u'Ru <= bound`` for every admissible ``Delta``.

    Attributes
    ----------
    bound : float
        ``x0' P x0``, or ``lambda_max(P)`` (every unit ``x0``) when ``x0`` is not given.
    P : (n, n) ndarray
        Quadratic cost bound ``V(x) = x'Px``.
    multiplier : float
        S-procedure multiplier ``lam``.
    x0 : (n,) ndarray or None
    certificate : Mapping[str, float]
        Smallest eigenvalue of each LMI block at the solution (solver's coordinates, ``>= 0`` up to rounding).
    info : Mapping
    """

    bound: float
    P: np.ndarray
    multiplier: float
    x0: np.ndarray | None
    certificate: Mapping[str, float]
    info: Mapping[str, Any] = field(default_factory=dict)

    def __repr__(self) -> str:
        x0 = "given" if self.x0 is not None else "worst unit"
        return f"CostBound(bound={self.bound:.6g}, multiplier={self.multiplier:.6g}, x0={x0!r})"


@dataclass(frozen=True, eq=False, repr=False)
class CostBoundBatch:
    """Guaranteed LQ costs of a stack of gains ``K`` (B, m, n) on one plant (:func:`guaranteed_cost`).

    Design ``b`` gets the bound of :class:`CostBound` (computed by Riccati
    equations and a search over the multiplier instead of an SDP), as
    entries of arrays.

    Attributes
    ----------
    bound : (B,) ndarray
        ``x0' P x0``, or ``lambda_max(P)`` when ``x0`` is not given; ``inf``
        where no bound exists (``reason`` says why), ``nan`` where ``K[b]``
        has a non-finite entry.
    P : (B, n, n) ndarray
        Quadratic cost bounds ``V(x) = x'Px`` (NaN where there is none).
    multiplier : (B,) ndarray
        S-procedure multiplier ``lam`` (0 where the uncertainty does not reach the loop).
    reason : (B,) str ndarray
        ``"ok"``, ``"unstable"`` (``F + G K`` is not stable), ``"not robustly
        stable"`` (``||E (zI - A)^-1 H||_inf >= 1``: no bound exists) or
        ``"not finite"``.
    x0 : (n,) ndarray or None
    certificate : Mapping[str, (B,) ndarray]
        Smallest eigenvalue of each LMI block at ``(P, lam)`` in the plant's
        coordinates: ``"cost"`` (the guaranteed-cost LMI) and ``"P"``
        (``>= 0`` up to rounding: ``P`` solves the Riccati equation, on the
        boundary of the LMI, as the SDP's optimum is).
    info : Mapping
        ``"path"``: ``"riccati"``; ``"search_steps"``: golden-section steps
        of the multiplier search; ``"riccati_failures"``: designs whose
        Riccati solution failed at the optimal multiplier (bound ``inf``).
    """

    bound: np.ndarray
    P: np.ndarray
    multiplier: np.ndarray
    reason: np.ndarray
    x0: np.ndarray | None
    certificate: Mapping[str, np.ndarray]
    info: Mapping[str, Any] = field(default_factory=dict)

    def __len__(self) -> int:
        return self.bound.shape[0]

    def __repr__(self) -> str:
        ok = self.reason == "ok"
        x0 = "given" if self.x0 is not None else "worst unit"
        return (f"CostBoundBatch(B={len(self)}, ok={int(ok.sum())}, x0={x0!r}, "
                f"largest bound={_fmt(float(self.bound[ok].max()) if ok.any() else None)})")


@dataclass(frozen=True, eq=False, repr=False)
class HinfBound:
    """Robust H-infinity bound: ``||T_zw||_inf <= gamma`` for every admissible ``Delta``.

    Attributes
    ----------
    gamma : float
    P : (n, n) ndarray
        Storage function ``x'Px`` of the dissipation inequality.
    multiplier : float
        S-procedure multiplier ``lam``.
    certificate : Mapping[str, float]
        Smallest eigenvalue of each LMI block at the solution (solver's coordinates).
    info : Mapping
    """

    gamma: float
    P: np.ndarray
    multiplier: float
    certificate: Mapping[str, float]
    info: Mapping[str, Any] = field(default_factory=dict)

    def __repr__(self) -> str:
        return f"HinfBound(gamma={self.gamma:.6g}, multiplier={self.multiplier:.6g})"


@dataclass(frozen=True, eq=False, repr=False)
class WorstCase:
    """Result of the worst-case search over ``||Delta|| <= 1``.

    Attributes
    ----------
    Delta : (p, l) ndarray
        The worst perturbation found (``||Delta||_2 <= 1``).
    radius : float
        Spectral radius (discrete) or spectral abscissa (largest real part,
        continuous) of ``A + H Delta E``.
    destabilizing : bool
        The loop at ``Delta`` is not stable in the sense of
        :mod:`robustctl.stability`: ``radius >= 1 - STABILITY_MARGIN``
        (discrete) or ``radius >= -STABILITY_MARGIN`` (continuous), as
        ``not Controller.is_stabilizing``.
    nominal_radius : float
        The same for ``Delta = 0``.
    evaluations : int
        Eigenvalue decompositions used.
    """

    Delta: np.ndarray
    radius: float
    destabilizing: bool
    nominal_radius: float
    evaluations: int

    def __repr__(self) -> str:
        return (f"WorstCase(radius={self.radius:.6g}, destabilizing={self.destabilizing}, "
                f"nominal_radius={self.nominal_radius:.6g}, ||Delta||={np.linalg.norm(self.Delta, 2):.6g})")


# ---------------------------------------------------------------- validation
def _loop(controller, batch: bool = False) -> tuple[Plant, np.ndarray]:
    """``(plant, K)`` from a Controller or a ``(plant, K)`` pair.

    With ``batch``, ``K`` may also be a stack (B, m, n) (returned 3-D; its
    entries may be non-finite: the caller flags those designs).
    """
    if isinstance(controller, Controller):
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
    raise TypeError(f"controller must be a robustctl.Controller or a (Plant, K) pair, got {type(controller).__name__}")


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


# ---------------------------------------------------------------- robust stability
def _stability_blocks(A, H, E, P, r, discrete) -> dict[str, np.ndarray]:
    """Blocks of the quadratic-stability certificate at radius ``r`` (multiplier 1)."""
    return {"P": P, "lyapunov": _block(A, r * H, P, _diag(E.T @ E, -np.eye(H.shape[1])), discrete)}


def _relative_min_eig(blocks: Mapping[str, np.ndarray]) -> float:
    return min(_min_eig(M) / max(1.0, float(np.linalg.norm(M, 2))) for M in blocks.values())


def _norm_bounded_sdp(plant: Plant, K: np.ndarray, unc: NormBounded) -> RobustStability:
    """The margin and certificate by one SDP (the fallback of :func:`_norm_bounded_batch`)."""
    import cvxpy as cp

    discrete = plant.is_discrete
    A = plant.F + plant.G @ K
    H, E = unc.H, unc.EF + unc.EG @ K
    n, p = H.shape
    nominal = _radius(A, discrete)
    if not is_stable(A, discrete=discrete):
        return RobustStability(False, 0.0, 0.0, None, MappingProxyType({}), "norm-bounded",
                               MappingProxyType({"nominal_radius": nominal}))
    e = float(np.linalg.norm(E, 2))
    En = E / e if e > 0 else E
    T = _Coordinates(_lyapunov_factor(A, En.T @ En, discrete))
    # x = L'^-1 x^ with H^ and E^ of unit norm: the scaled loop's radius is r hh eh
    Ah, Hh, Eh = T.A(A), T.B(H), T.C(E)
    hh, eh = (float(np.linalg.norm(M, 2)) or 1.0 for M in (Hh, Eh))
    Hh, Eh = Hh / hh, Eh / eh
    P = cp.Variable((n, n), symmetric=True, name="P")
    mu = cp.Variable(name="mu")
    N = _diag(Eh.T @ Eh, np.zeros((p, p))) - mu * _diag(np.zeros((n, n)), np.eye(p))
    lmis = [_cvx.LMI("lyapunov", _block(Ah, Hh, P, N, discrete)), _cvx.LMI("P", P)]
    rep = _cvx.solve_sdp(cp.Minimize(mu), lmis, infeasible_msg="the bounded-real LMI of the uncertainty loop is "
                                                               "infeasible")
    mu_opt = max(float(_cvx.value(mu)), 0.0)
    no_reach = not (np.any(H) and np.any(E))
    margin = np.inf if no_reach or mu_opt == 0.0 else 1.0 / (np.sqrt(mu_opt) * hh * eh)
    radius = 1.0 if margin > 1.0 else margin / (1.0 + _BACKOFF)
    # Strict certificate at `radius` without a second solve: P^* + eps I (I
    # solves the Lyapunov equation of A^ with a positive definite weight) is
    # strictly feasible for small eps > 0 at any radius below the margin; the
    # LMI gains delta = 1 / (radius hh eh)^2 - mu_opt in its q block. The
    # plant's coordinates with multiplier 1 need P = eh^2 L (P^* + eps I) L'.
    P_val = _cvx.value(P)
    P_opt = 0.5 * (P_val + P_val.T)
    delta = 1.0 / (radius * hh * eh) ** 2 - mu_opt
    candidates = []
    for eps in max(delta, 1e-12) * 10.0 ** -np.arange(7.0):
        P_c = eh**2 * T.P(P_opt + eps * np.eye(n))
        blocks = _stability_blocks(A, H, E, P_c, radius, discrete)
        candidates.append((_relative_min_eig(blocks), P_c, blocks))
    score, P_c, blocks = max(candidates, key=lambda c: c[0])  # the first of the best scores
    cert = {k: _min_eig(M) for k, M in blocks.items()}
    info = {"nominal_radius": nominal, "mu": mu_opt, **_solve_info([rep])}
    return RobustStability(bool(radius == 1.0 and score > _STRICT), float(margin), float(radius), _frozen(P_c),
                           MappingProxyType(cert), "norm-bounded", MappingProxyType(info))


def _batched_blocks(A, Hr, E, P, discrete: bool) -> dict[str, np.ndarray]:
    """:func:`_stability_blocks` for stacks (``Hr`` (B, n, p) already scaled by the radius)."""
    n, p = A.shape[-1], Hr.shape[-1]
    AH = np.concatenate([A, Hr], axis=-1)
    if discrete:
        M = -(AH.mT @ P @ AH)
        M[:, :n, :n] += P
    else:
        S = P @ AH
        M = np.zeros_like(S, shape=(A.shape[0], n + p, n + p))
        M[:, :n, :] = -S
        M[:, :, :n] -= S.mT
    M[:, :n, :n] -= E.mT @ E
    M[:, n:, n:] += np.eye(p)
    return {"P": P, "lyapunov": M}


def _verify(blocks: Mapping[str, np.ndarray]) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Relative score (smallest of ``lambda_min / max(1, ||M||)`` over the blocks) and smallest eigenvalues."""
    cert, rel = {}, []
    for key, M in blocks.items():
        ev = _hinfnorm.eigvalsh(0.5 * (M + M.mT))
        cert[key] = ev[:, 0]
        rel.append(ev[:, 0] / np.maximum(1.0, np.maximum(np.abs(ev[:, 0]), np.abs(ev[:, -1]))))
    return np.minimum.reduce(rel), cert


def _riccati_certificates(A, H, E, g, peak, discrete: bool):
    """``(radius, P, certificate, verified)`` from the bounded-real Riccati equation (stacks).

    For ``g = ||E (zI - A)^-1 H||_inf`` the target radius is ``r = 1`` if
    ``g < 1`` (margin above 1), else ``r = margin / (1 + 1e-3)``. With
    ``gr = r g`` and ``gamma^2 = (1 + gr^2) / 2`` the stabilising solution
    ``P`` of the Riccati equation of ``(A, r H, [E; sqrt(eps) I])`` at level
    ``gamma`` (:mod:`robustctl._hinfnorm`) makes the certificate LMI at
    radius ``r`` strictly positive: its Schur complement is
    ``eps I + A'PH_r ((gamma^2 I - H_r'PH_r)^-1 - (I - H_r'PH_r)^-1) H_r'PA``
    (continuous alike), provided the level exceeds the norm of the
    regularised loop: ``eps = (gamma^2 - gr^2) / (4 h^2)`` with ``h`` the
    Frobenius norm of ``(zI - A)^-1 H_r`` at the peak frequency (``H_r`` and
    ``E`` balanced); a design whose ``P`` fails the check is retried with
    ``eps / 100``.
    """
    n = A.shape[-1]
    with np.errstate(divide="ignore"):
        margin = 1.0 / g
    r = np.where(margin > 1.0, 1.0, margin / (1.0 + _BACKOFF))
    Hr = r[:, None, None] * H
    gr = r * g
    gam = np.sqrt(0.5 * (1.0 + gr * gr))
    # H_r and E of equal norms (c): P = c^2 P~ of the balanced problem
    hn, en = np.sqrt((Hr * Hr).sum(axis=(1, 2))), np.sqrt((E * E).sum(axis=(1, 2)))
    reach = (hn > 0) & (en > 0)
    c = np.sqrt(en / hn) if reach.all() else np.where(reach, np.sqrt(en / np.where(reach, hn, 1.0)), 1.0)
    c2 = (c * c)[:, None, None]
    Hb, Eb = Hr * c[:, None, None], E / c[:, None, None]
    z = np.exp(1j * peak) if discrete else 1j * peak
    X = _hinfnorm.solve(z[:, None, None] * np.eye(n) - A, Hb.astype(complex))
    h2 = (X.real ** 2 + X.imag ** 2).sum(axis=(1, 2))
    eps = np.minimum((gam * gam - gr * gr) / (4.0 * np.where(h2 > 0, h2, 1.0)),
                     np.maximum(1.0, (Eb * Eb).sum(axis=(1, 2))))
    eye = np.eye(n)

    def attempt(idx):
        Ea = np.concatenate([Eb[idx], np.sqrt(eps[idx])[:, None, None] * eye], axis=1)
        P, ok = _hinfnorm.bounded_real_riccati(A[idx], Hb[idx], Ea, gam[idx], discrete=discrete)
        P = P * c2[idx]
        ok &= np.isfinite(P).all(axis=(1, 2))
        if ok.all():
            score, cert = _verify(_batched_blocks(A[idx], Hr[idx], E[idx], P, discrete))
            return P, score, cert
        score = np.full(P.shape[0], -np.inf)
        cert = {"P": np.full(P.shape[0], np.nan), "lyapunov": np.full(P.shape[0], np.nan)}
        if ok.any():
            sel = np.flatnonzero(ok) if isinstance(idx, slice) else idx[ok]
            score[ok], cert_ok = _verify(_batched_blocks(A[sel], Hr[sel], E[sel], P[ok], discrete))
            for key, v in cert_ok.items():
                cert[key][ok] = v
        return P, score, cert

    everyone = slice(None)
    P, score, cert = attempt(everyone)
    bad = np.flatnonzero(~(score > _STRICT))
    for _ in range(_EPS_TRIES - 1):
        if not bad.size:
            break
        eps[bad] *= 1e-2
        P2, s2, c2b = attempt(bad)
        up = s2 > score[bad]
        sel = bad[up]
        P[sel], score[sel] = P2[up], s2[up]
        for key in cert:
            cert[key][sel] = c2b[key][up]
        bad = bad[~(s2 > _STRICT)]
    return r, P, cert, score > _STRICT


def _norm_bounded_batch(plant: Plant, K: np.ndarray, unc: NormBounded) -> RobustStabilityBatch:
    """Margins (small-gain values by the level-set H-infinity norm) and Riccati certificates of a stack of gains."""
    discrete = plant.is_discrete
    B, n = K.shape[0], plant.n
    finite = np.isfinite(K).all(axis=(1, 2))
    all_finite = bool(finite.all())
    Kf = K if all_finite else np.where(finite[:, None, None], K, 0.0)
    A = plant.F + plant.G @ Kf
    E = unc.EF + unc.EG @ Kf
    lam = _hinfnorm.eigvals(A)
    if discrete:
        nominal = np.abs(lam).max(axis=1)
        stable = nominal < 1.0 - STABILITY_MARGIN
    else:
        nominal = lam.real.max(axis=1)
        stable = nominal < -STABILITY_MARGIN
    margin = np.zeros(B)
    if not all_finite:
        stable &= finite
        nominal[~finite] = np.nan
        margin[~finite] = np.nan
    reason = np.where(stable, "ok", "unstable").astype("<U10")
    if not all_finite:
        reason[~finite] = "not finite"
    if stable.all():
        idx = None
        As, Es, lam_s = A, E, lam
    else:
        idx = np.flatnonzero(stable)
        As, Es, lam_s = A[idx], E[idx], lam[idx]
    S = As.shape[0]
    g = peak = np.zeros(0)
    iterations = 0
    Hs = np.broadcast_to(unc.H, (S, *unc.H.shape))
    if S:
        g, peak, iterations = _hinfnorm.hinf_norm(As, Hs, Es, discrete=discrete, poles=lam_s)
        with np.errstate(divide="ignore"):
            m = 1.0 / g
        if idx is None:
            margin = m
        else:
            margin[idx] = m

    def certify() -> tuple:
        radius = np.zeros(B)
        certified = np.zeros(B, dtype=bool)
        path = np.full(B, "", dtype="<U7")
        P = np.full((B, n, n), np.nan)
        cert = {"P": np.full(B, np.nan), "lyapunov": np.full(B, np.nan)}
        sdp = 0
        if S:
            r, Ps, cs, ok = _riccati_certificates(As, Hs, Es, g, peak, discrete)
            how = np.where(ok, "riccati", "")
            for j in np.flatnonzero(~ok):   # rare: the SDP, one design at a time
                sdp += 1
                b = j if idx is None else int(idx[j])
                try:
                    res = _norm_bounded_sdp(plant, Kf[b], unc)
                except (InfeasibleError, ConvergenceError):
                    continue
                if res.P is None:
                    continue
                score, cs_b = _verify(_batched_blocks(As[j:j + 1], (r[j] * unc.H)[None], Es[j:j + 1],
                                                      res.P[None], discrete))
                if score[0] > _STRICT or not np.isfinite(Ps[j]).all():
                    Ps[j] = res.P
                    for key in cs:
                        cs[key][j] = cs_b[key][0]
                    ok[j] = score[0] > _STRICT
                    how[j] = "sdp" if ok[j] else ""
            if idx is None:
                radius, P, cert, path = r, Ps, cs, how
                certified = ok & (r == 1.0)
            else:
                radius[idx], P[idx], path[idx] = r, Ps, how
                for key in cs:
                    cert[key][idx] = cs[key]
                certified[idx] = ok & (r == 1.0)
        info = {"path": _ro(path), "nominal_radius": _frozen(nominal), "norm": "level-set",
                "norm_iterations": iterations, "sdp_solves": sdp}
        return (_ro(certified), _frozen(radius), _frozen(P), MappingProxyType({k: _frozen(v) for k, v in cert.items()}),
                MappingProxyType(info))

    return RobustStabilityBatch(_frozen(margin), _ro(reason), "norm-bounded", certify)


def _norm_bounded_stability(plant: Plant, K: np.ndarray, unc: NormBounded, *,
                            norm: str = "auto") -> RobustStability:
    """One gain: what :func:`_norm_bounded_batch` does for a stack, on 2-D arrays (less overhead).

    ``norm`` chooses the H-infinity norm (:func:`robustctl._hinfnorm.norm_one`):
    SLICOT AB13DD when slycot is installed (``"auto"``) or the level-set
    iteration of :mod:`robustctl._hinfnorm` (``"level-set"``).
    """
    discrete = plant.is_discrete
    n = plant.n
    A = plant.F + plant.G @ K
    H, E = unc.H, unc.EF + unc.EG @ K
    lam = _hinfnorm.eigvals(A[None])[0]
    nominal = float(np.abs(lam).max() if discrete else lam.real.max())
    if not nominal < ((1.0 - STABILITY_MARGIN) if discrete else -STABILITY_MARGIN):
        return RobustStability(False, 0.0, 0.0, None, MappingProxyType({}), "norm-bounded",
                               MappingProxyType({"nominal_radius": nominal}))
    g, peak, iterations, h2, method = _hinfnorm.norm_one(A, H, E, lam, discrete=discrete, method=norm)
    margin = 1.0 / g if g > 0 else math.inf
    r = 1.0 if margin > 1.0 else margin / (1.0 + _BACKOFF)
    gr = r * g
    gam = math.sqrt(0.5 * (1.0 + gr * gr))
    hn2, en2 = r * r * float(np.vdot(H, H)), float(np.vdot(E, E))
    c = (en2 / hn2) ** 0.25 if hn2 > 0 and en2 > 0 else 1.0
    Hb, Eb = (r * c) * H, E / c
    if h2 == 0.0:   # the norm did not evaluate the resolvent (AB13DD, or E = 0): do it at the peak
        z = np.exp(1j * peak) if discrete else 1j * peak
        _, _, X, info = lapack.zgesv(z * _hinfnorm.eye(n) - A, H)
        h2 = float(np.vdot(X, X).real) if info == 0 else 0.0
    h2 *= (r * c) ** 2   # ||(zI - A)^-1 H_b||_F^2 at the peak
    eps = min((gam * gam - gr * gr) / (4.0 * h2 if h2 > 0 else 1.0), max(1.0, en2 / c**2))
    best: tuple = (-np.inf, None, {})
    path = solver = None
    Ea = np.empty((Eb.shape[0] + n, n))
    Ea[:Eb.shape[0]] = Eb
    solvers = ("doubling", "eigenvectors") if n >= _SDA_MIN_N else ("eigenvectors",)
    for _ in range(_EPS_TRIES):
        Ea[Eb.shape[0]:] = math.sqrt(eps) * _hinfnorm.eye(n)
        for solver in solvers:
            if solver == "doubling":
                Pt = _hinfnorm.riccati_doubling(A, Hb, Ea, gam, lam, discrete=discrete)
            else:
                Pt = _hinfnorm.riccati_one(A, Hb, Ea, gam, discrete=discrete)
            if Pt is None:
                continue
            P = (c * c) * Pt
            score, cert = _certify_one(A, r * H, E, P, discrete)
            if score > best[0]:
                best = (score, P, cert)
            if score > _STRICT:
                path = "riccati"
                break
        if path is not None:
            break
        eps *= 1e-2
    if path is None:   # rare: the SDP
        try:
            res = _norm_bounded_sdp(plant, K, unc)
        except (InfeasibleError, ConvergenceError):
            res = None
        if res is not None and res.P is not None:
            score, cert = _verify_one(_stability_blocks_fast(A, r * H, E, res.P, discrete))
            if score > _STRICT or best[1] is None:
                best = (score, res.P, cert)
                path = "sdp" if score > _STRICT else None
    score, P, cert = best
    if P is not None:
        P.flags.writeable = False
    info = {"path": path, "nominal_radius": nominal, "norm_iterations": iterations, "norm": method,
            "riccati": solver if path == "riccati" else None}
    return RobustStability(path is not None and r == 1.0, margin, r, P, MappingProxyType(cert), "norm-bounded",
                           MappingProxyType(info))


def _certify_one(A, Hr, E, P, discrete: bool) -> tuple[float, dict[str, float]]:
    """:func:`_verify_one` of :func:`_stability_blocks_fast` (``P`` symmetric), with fewer small array operations."""
    n, p = A.shape[0], Hr.shape[1]
    M = np.empty((n + p, n + p))
    if discrete:
        PA, PH = P @ A, P @ Hr
        M[:n, :n] = P - A.T @ PA - E.T @ E
        M[n:, :n] = -(Hr.T @ PA)
        M[n:, n:] = _hinfnorm.eye(p) - Hr.T @ PH
    else:
        PA = P @ A
        M[:n, :n] = -(PA + PA.T) - E.T @ E
        M[n:, :n] = -(Hr.T @ P)
        M[n:, n:] = _hinfnorm.eye(p)
    score, cert = np.inf, {}
    for key, S in (("P", P), ("lyapunov", M)):   # dsyevd reads the lower triangle
        w, _, info = lapack.dsyevd(S, compute_v=0, lower=1)
        if info != 0:
            w = np.linalg.eigvalsh(S)
        lo, hi = float(w[0]), float(w[-1])
        cert[key] = lo
        score = min(score, lo / max(1.0, abs(lo), abs(hi)))
    return score, cert


def _stability_blocks_fast(A, Hr, E, P, discrete: bool) -> dict[str, np.ndarray]:
    """:func:`_stability_blocks` at radius 1 of ``(A, Hr, E)`` without block_diag."""
    n, p = A.shape[0], Hr.shape[1]
    AH = np.concatenate([A, Hr], axis=1)
    if discrete:
        M = -(AH.T @ P @ AH)
        M[:n, :n] += P
    else:
        S = P @ AH
        M = np.zeros((n + p, n + p))
        M[:n, :] = -S
        M[:, :n] -= S.T
    M[:n, :n] -= E.T @ E
    M[n:, n:] += _hinfnorm.eye(p)
    return {"P": P, "lyapunov": M}


def _verify_one(blocks: Mapping[str, np.ndarray]) -> tuple[float, dict[str, float]]:
    """:func:`_verify` of one design."""
    score, cert = np.inf, {}
    for key, M in blocks.items():
        ev = _hinfnorm.eigvalsh(0.5 * (M + M.T)[None])[0]
        cert[key] = float(ev[0])
        score = min(score, float(ev[0]) / max(1.0, abs(float(ev[0])), abs(float(ev[-1]))))
    return score, cert


def _polytope_stability(plants: list[Plant], K: np.ndarray) -> RobustStability:
    import cvxpy as cp

    discrete = plants[0].is_discrete
    A0 = plants[0].F + plants[0].G @ K
    D = [p.F + p.G @ K - A0 for p in plants]
    n = A0.shape[0]
    nominal = _radius(A0, discrete)
    if not is_stable(A0, discrete=discrete):
        return RobustStability(False, 0.0, 0.0, None, MappingProxyType({}), "polytope",
                               MappingProxyType({"nominal_radius": nominal}))
    T = _Coordinates(_lyapunov_factor(A0, np.eye(n), discrete))
    Ah0, Dh = T.A(A0), [T.A(Di) for Di in D]
    empty = np.zeros((n, 0))
    reports = []

    def feasible(r: float):
        """``P^`` with every scaled vertex's Lyapunov block >= t I, P^ >= t I, P^ <= I and t > 0, or None."""
        if any(not is_stable(A0 + r * Di, discrete=discrete) for Di in D):
            return None  # a vertex of the scaled polytope is unstable: no solve needed
        P, t = cp.Variable((n, n), symmetric=True, name="P"), cp.Variable(name="t")
        lmis = [_cvx.LMI(f"vertex[{i}]", _block(Ah0 + r * Di, empty, P, np.zeros((n, n)), discrete), t)
                for i, Di in enumerate(Dh)]
        lmis += [_cvx.LMI("P", P, t), _cvx.LMI("P_upper", np.eye(n) - P)]
        try:
            rep = _cvx.solve_sdp(cp.Maximize(t), lmis, infeasible_msg="")
        except (InfeasibleError, ConvergenceError):
            return None
        reports.append(rep)
        P_val = _cvx.value(P)
        return 0.5 * (P_val + P_val.T) if float(_cvx.value(t)) > _POLY_T else None

    if not any(np.any(Di) for Di in D):
        margin, (lo, P_lo) = np.inf, (1.0, np.eye(n))
    else:
        # bracket [lo, hi] (lo certified, hi not), then bisection; conv at r' < r
        # lies inside conv at r because the nominal plant is a vertex
        lo, P_lo, hi = 0.0, np.eye(n), None
        r = 1.0
        while hi is None:
            P_r = feasible(r)
            if P_r is None:
                hi = r
            else:
                lo, P_lo = r, P_r
                if r >= _POLY_RMAX:
                    break
                r = min(2.0 * r, _POLY_RMAX)
        for _ in range(_POLY_STEPS):
            if hi is None or hi - lo <= _POLY_RTOL * hi:
                break
            mid = 0.5 * (lo + hi)
            P_mid = feasible(mid)
            if P_mid is None:
                hi = mid
            else:
                lo, P_lo = mid, P_mid
        margin = lo
    radius = min(lo, 1.0)
    P_c = T.P(P_lo)
    blocks = {"P": P_c}
    for i, Di in enumerate(D):
        blocks[f"vertex[{i}]"] = _block(A0 + radius * Di, empty, P_c, np.zeros((n, n)), discrete)
    score = _relative_min_eig(blocks) if radius > 0 else -np.inf
    cert = {k: _min_eig(M) for k, M in blocks.items()}
    info = {"nominal_radius": nominal, **_solve_info(reports)}
    return RobustStability(bool(radius == 1.0 and score > _STRICT), float(margin), float(radius), _frozen(P_c),
                           MappingProxyType(cert), "polytope", MappingProxyType(info))


def robust_stability(controller: Controller | tuple[Plant, ArrayLike], uncertainty: NormBounded | None = None, *,
                     vertices: Sequence[Plant] | None = None) -> RobustStability | RobustStabilityBatch:
    r"""Quadratic-stability certificate and margin of ``u = K x`` under norm-bounded or polytopic uncertainty.

    Norm-bounded (``uncertainty``): stability of ``A + H Delta E`` for every
    ``||Delta|| <= r``, ``A = F + G K``, ``E = EF + EG K``, by the
    S-procedure LMI of the module docstring. Its ``margin`` equals the
    small-gain value ``1 / ||E (zI - A)^-1 H||_inf`` (continuous time:
    ``s``), computed by a level-set H-infinity norm (for one gain SLICOT's
    AB13DD when slycot is installed); the certificate ``P`` comes from the
    bounded-real Riccati equation at a level between the norm and 1 and is
    verified by eigenvalues (the SDP is the fallback).
    A stack of gains (B, m, n) is analysed at once (eigenvalue problems on
    (B, 2n, 2n) arrays, one level-set iteration for all); its certificates
    are computed when first asked for (:class:`RobustStabilityBatch`).

    Polytope (``vertices``): a common Lyapunov matrix of
    ``A_i = F_i + G_i K`` for the controller's plant and every vertex
    (``A_i' P A_i < P``, or ``A_i' P + P A_i < 0``), hence stability of every
    (even time-varying) plant in their convex hull. ``margin`` scales the
    polytope about the controller's plant (bisection, one SDP per step).

    Parameters
    ----------
    controller : Controller or (Plant, (m, n) or (B, m, n) array_like)
        The gain ``K`` (``u = K x``) and the nominal plant (discrete if
        ``plant.dt`` is set, else continuous). A stack of ``B`` gains may
        hold non-finite entries: those designs are flagged
        (``reason == "not finite"``, margin NaN), the others answered; a
        single gain must be finite.
    uncertainty : NormBounded, optional
        ``[dF dG] = H Delta [EF EG]``.
    vertices : list of Plant, optional
        Further plants (same ``n``, ``m``, ``dt``); the polytope is the convex
        hull of the controller's plant and these. Give exactly one of
        ``uncertainty`` and ``vertices``. (A stack of gains is analysed
        design by design here: a bisection of SDPs each.)

    Returns
    -------
    RobustStability or RobustStabilityBatch
        ``certified``, ``margin``, ``radius``, ``P`` and its ``certificate``
        for one gain; the same as (B,) arrays (``P`` (B, n, n)) and a
        per-design ``reason`` for a stack.

    Examples
    --------
    An LQR of the paper's truck against ``dG = G Delta 0.1``,
    ``dF = G Delta [0.1, 0, 0, 0]``; the margin is the reciprocal of the peak
    of ``|E (z I - A)^-1 H|`` on the unit circle (here on a fine grid), and
    the same gain is quadratically stable over the 0-300 % payload polytope:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.models.truck import truck_plant
    >>> plant = truck_plant(0.0)
    >>> ctrl = rc.lqr(plant)
    >>> unc = rc.NormBounded(plant.G, [[0.1, 0.0, 0.0, 0.0]], [[0.1]])
    >>> res = rc.robust_stability(ctrl, unc)
    >>> res.certified, round(res.margin, 4)
    (True, 4.0359)
    >>> A, H, E = ctrl.closed_loop(), unc.H, unc.EF + unc.EG @ ctrl.K
    >>> peak = max(abs(E @ np.linalg.solve(z * np.eye(4) - A, H)).item()
    ...            for z in np.exp(1j * np.linspace(0.0, np.pi, 20001)))
    >>> bool(abs(res.margin * peak - 1.0) < 1e-4)
    True
    >>> rc.robust_stability(ctrl, vertices=[truck_plant(300.0)]).certified
    True
    """
    plant, K = _loop(controller, batch=True)
    if (uncertainty is None) == (vertices is None):
        raise ValueError("give exactly one of uncertainty (a NormBounded) and vertices (a list of Plant)")
    if vertices is not None:
        # a polytope needs a vertex besides the nominal plant
        plants = check_vertices(plant, vertices, reference="the controller's plant", non_empty=True)
        if K.ndim == 2:
            return _polytope_stability(plants, K)
        return _polytope_batch(plants, K)
    unc = check_norm_bounded(uncertainty, plant)
    if K.ndim == 2:
        return _norm_bounded_stability(plant, K, unc)
    return _norm_bounded_batch(plant, K, unc)


def _polytope_batch(plants: list[Plant], K: np.ndarray) -> RobustStabilityBatch:
    """The polytope test design by design (a bisection of SDPs each), assembled like the norm-bounded batch."""
    B, n = K.shape[0], plants[0].n
    out = {"certified": np.zeros(B, dtype=bool), "margin": np.full(B, np.nan), "radius": np.zeros(B)}
    P = np.full((B, n, n), np.nan)
    cert = {f"vertex[{i}]": np.full(B, np.nan) for i in range(len(plants))}
    cert = {"P": np.full(B, np.nan), **cert}
    reason = np.full(B, "not finite", dtype=object)
    nominal = np.full(B, np.nan)
    path = np.full(B, "", dtype=object)
    for b in range(B):
        if not np.isfinite(K[b]).all():
            continue
        res = _polytope_stability(plants, K[b])
        out["certified"][b], out["margin"][b], out["radius"][b] = res.certified, res.margin, res.radius
        nominal[b] = res.info["nominal_radius"]
        reason[b] = "ok" if res.P is not None else "unstable"
        if res.P is not None:
            P[b] = res.P
            path[b] = "sdp"
            for key, v in res.certificate.items():
                cert[key][b] = v
    info = {"path": _ro(path.astype(str)), "nominal_radius": _frozen(nominal), "sdp_solves": int((path == "sdp").sum())}
    bundle = (_ro(out["certified"]), _frozen(out["radius"]), _frozen(P),
              MappingProxyType({k: _frozen(v) for k, v in cert.items()}), MappingProxyType(info))
    return RobustStabilityBatch(_frozen(out["margin"]), _ro(reason.astype(str)), "polytope", lambda: bundle)


# ---------------------------------------------------------------- performance bounds
def _robust_loop(controller, uncertainty, what: str):
    """``(plant, K, A, H, E)`` after checking that the loop is robustly stable (small gain < 1)."""
    plant, K = _loop(controller)
    unc = check_norm_bounded(uncertainty, plant)
    discrete = plant.is_discrete
    A, H, E = plant.F + plant.G @ K, unc.H, unc.EF + unc.EG @ K
    if not is_stable(A, discrete=discrete):
        kind = "spectral radius" if discrete else "spectral abscissa"
        raise InfeasibleError(f"no {what}: the nominal closed loop F + G K is unstable ({kind} "
                              f"{_radius(A, discrete):.6g})")
    if not (np.any(H) and np.any(E)):
        # the uncertainty does not reach the loop: drop its channel (else the
        # S-procedure multiplier would have to go to infinity)
        return plant, K, A, np.zeros((plant.n, 0)), np.zeros((0, plant.n))
    gain = float(_hinfnorm.hinf_norm(A[None], H[None], E[None], discrete=discrete)[0][0])
    if gain >= 1.0:
        raise InfeasibleError(f"no {what}: the closed loop is not quadratically stable for every "
                              f"||Delta|| <= 1 (||E (zI - A)^-1 H||_inf = {gain:.6g} >= 1, stability "
                              f"margin {1.0 / gain:.6g}; see robust_stability)")
    return plant, K, A, H, E


def _balanced(Hh: np.ndarray, Eh: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """``(H^ c, E^ / c, c)`` with equal norms (``H Delta E`` unchanged)."""
    h, e = float(np.linalg.norm(Hh, 2)), float(np.linalg.norm(Eh, 2))
    c = float(np.sqrt(e / h)) if h > 0 and e > 0 else 1.0
    return Hh * c, Eh / c, c


def _multiplier(lam, p: int, c: float) -> float:
    """The multiplier in the plant's scaling: ``lam^ (|E^ x^|^2 - |q^|^2) = lam^ (|E x|^2 - |q|^2) / c^2``."""
    return float(_cvx.value(lam)) / c**2 if p else 0.0


def _psd_factor(M: np.ndarray) -> np.ndarray:
    """``L`` with ``L'L = M`` for a symmetric positive semidefinite ``M`` (rows ``sqrt(w_i) v_i'``)."""
    w, V = np.linalg.eigh(M)
    return np.sqrt(np.clip(w, 0.0, None))[:, None] * V.T


def _cost_objective(P: np.ndarray, x0: np.ndarray | None) -> np.ndarray:
    """``x0' P x0`` or ``lambda_max(P)`` of a stack."""
    if x0 is not None:
        return np.einsum("i,bij,j->b", x0, P, x0)
    return np.linalg.eigvalsh(0.5 * (P + P.mT))[:, -1]


def _cost_lmi_eigs(A, H, E, QK, P, lam, discrete: bool) -> np.ndarray:
    """Eigenvalues (S, n + p), ascending, of the guaranteed-cost LMI at ``(P, lam)`` for stacks."""
    S, n = A.shape[0], A.shape[-1]
    p = H.shape[-1]
    AH = np.concatenate([A, np.broadcast_to(H, (S, n, p))], axis=-1)
    if discrete:
        M = -(AH.mT @ P @ AH)
        M[:, :n, :n] += P
    else:
        Sx = P @ AH
        M = np.zeros((S, n + p, n + p))
        M[:, :n, :] = -Sx
        M[:, :, :n] -= Sx.mT
    M[:, :n, :n] -= QK + lam[:, None, None] * (E.mT @ E)
    M[:, n:, n:] += lam[:, None, None] * np.eye(p)
    return np.linalg.eigvalsh(0.5 * (M + M.mT))


def _guaranteed_cost_batch(plant: Plant, K: np.ndarray, unc: NormBounded, Q: np.ndarray, R: np.ndarray,
                           x0: np.ndarray | None) -> CostBoundBatch:
    """:func:`guaranteed_cost` of a stack of gains by Riccati equations and a search over the multiplier.

    For a fixed ``lam`` the smallest ``P`` of the guaranteed-cost LMI is the
    stabilising solution ``P_lam`` of the bounded-real Riccati equation of
    ``(A, H, C_lam)`` at the level ``sqrt(lam)``, ``C_lam'C_lam = Q_K + lam
    E'E`` (the LMI's Schur complement at equality); both objectives grow
    with ``P``, so the bound is ``min over lam`` of ``f(lam) = x0'P_lam x0``
    (or ``lambda_max(P_lam)``), a convex function (the partial minimum of the
    convex SDP) on ``lam > lam*``. With ``q = ||C_Q (zI - A)^-1 H||_inf``
    (``C_Q'C_Q = Q_K``) and ``g = ||E (zI - A)^-1 H||_inf < 1``,
    ``q^2 <= lam* <= q^2 / (1 - g^2)``; from ``P_lam >= P_Q + lam P_E``
    (Lyapunov solutions of ``Q_K`` and ``E'E``) the minimiser is at most
    ``(f(lam_1) - f_Q) / f_E`` for any feasible ``lam_1``. A golden-section
    search on ``log lam`` over that bracket, all designs at once (one
    batched Riccati solve per step), finds it.
    """
    discrete = plant.is_discrete
    B, n = K.shape[0], plant.n
    finite = np.isfinite(K).all(axis=(1, 2))
    Kf = np.where(finite[:, None, None], K, 0.0)
    A = plant.F + plant.G @ Kf
    E = unc.EF + unc.EG @ Kf
    H = unc.H
    lam_A = _hinfnorm.eigvals(A)
    if discrete:
        stable = np.abs(lam_A).max(axis=1) < 1.0 - STABILITY_MARGIN
    else:
        stable = lam_A.real.max(axis=1) < -STABILITY_MARGIN
    stable &= finite
    reason = np.where(finite, np.where(stable, "ok", "unstable"), "not finite").astype("<U20")
    bound = np.where(finite, np.inf, np.nan)
    P_out = np.full((B, n, n), np.nan)
    mult = np.full(B, np.nan)
    cert = {"cost": np.full(B, np.nan), "P": np.full(B, np.nan)}
    steps = failures = 0
    idx = np.flatnonzero(stable)
    if idx.size:
        A, E = A[idx], E[idx]
        S = idx.size
        CQ = np.concatenate([np.broadcast_to(_psd_factor(Q), (S, n, n)), _psd_factor(R) @ Kf[idx]], axis=1)
        QK = CQ.mT @ CQ
        Hs = np.broadcast_to(H, (S, *H.shape))
        reach = bool(np.any(H)) & (np.abs(E).max(axis=(1, 2)) > 0)
        g = _hinfnorm.hinf_norm(A, Hs, E, discrete=discrete, poles=lam_A[idx])[0]
        robust = ~reach | (g < 1.0)
        reason[idx[~robust]] = "not robustly stable"
        zero = np.zeros_like(Hs)
        one = np.ones(S)
        # Lyapunov solutions (the Riccati equation without H): P_Q, and P_E for the bracket
        P_Q, ok_Q = _hinfnorm.bounded_real_riccati(A, zero, CQ, one, discrete=discrete)
        f_Q = np.where(ok_Q, _cost_objective(P_Q, x0), np.inf)
        best_f, best_P, best_lam = np.where(reach, np.inf, f_Q), P_Q.copy(), np.zeros(S)
        live = np.flatnonzero(reach & robust)
        if live.size:
            Al, El, CQl, Hl, QKl = A[live], E[live], CQ[live], Hs[live], QK[live]
            P_E, ok_E = _hinfnorm.bounded_real_riccati(Al, zero[live], El, one[live], discrete=discrete)
            f_E = np.where(ok_E, _cost_objective(P_E, x0), 0.0)
            q = _hinfnorm.hinf_norm(Al, Hl, CQl, discrete=discrete, poles=lam_A[idx[live]])[0]
            gl = g[live]

            def f(lam):
                C = np.concatenate([CQl, np.sqrt(lam)[:, None, None] * El], axis=1)
                P, ok = _hinfnorm.bounded_real_riccati(Al, Hl, C, np.sqrt(lam), discrete=discrete)
                ok &= np.isfinite(P).all(axis=(1, 2))
                P = np.where(ok[:, None, None], P, 0.0)
                # a level at or below the norm can pass the eigenvalue count with imaginary-axis
                # eigenvalues split by rounding: keep only P that satisfy the LMI (up to rounding)
                ev = _cost_lmi_eigs(Al, H, El, QKl, P, lam, discrete)
                ok &= ev[:, 0] >= -_COST_LMI_TOL * np.maximum(1.0, np.abs(ev).max(axis=1))
                val = _cost_objective(P, x0)
                val = np.where(ok & np.isfinite(val), val, np.inf)
                better = val < best_f[live]
                sel = live[better]
                best_f[sel], best_P[sel], best_lam[sel] = val[better], P[better], lam[better]
                return val

            scale = np.where(q > 0, q * q, np.maximum(f_Q[live], 1e-300) / np.maximum(f_E, 1e-300))
            lam1 = np.maximum(2.0 * q * q / (1.0 - gl * gl), 1e-12 * scale)
            f1 = f(lam1)
            with np.errstate(divide="ignore", invalid="ignore"):
                up = np.where(f_E > 0, (f1 - f_Q[live]) / f_E, 1e6 * lam1)
            up = np.where(np.isfinite(up) & (up > lam1), up, lam1)
            lo = np.where(q > 0, q * q, 1e-12 * up)
            a, b = np.log(lo), np.log(up) + 1e-12
            gr = (math.sqrt(5.0) - 1.0) / 2.0
            c, d = b - gr * (b - a), a + gr * (b - a)
            fc, fd = f(np.exp(c)), f(np.exp(d))
            width = float((b - a).max())
            steps = max(0, math.ceil(math.log(1e-9 / width) / math.log(gr))) if width > 1e-9 else 0
            for _ in range(min(steps, 100)):
                left = fc < fd
                b = np.where(left, d, b)
                a = np.where(left, a, c)
                c_new = np.where(left, b - gr * (b - a), d)
                d_new = np.where(left, c, a + gr * (b - a))
                x = np.where(left, c_new, d_new)
                fx = f(np.exp(x))
                fc, fd = np.where(left, fx, fd), np.where(left, fc, fx)
                c, d = c_new, d_new
        found = np.isfinite(best_f) & robust
        failures = int((robust & ~found).sum())
        rows = idx[found]
        Pf, lf = best_P[found], best_lam[found]
        bound[rows], P_out[rows], mult[rows] = best_f[found], Pf, lf
        if rows.size:   # the LMI blocks at (P, lam), in the plant's coordinates
            cert["cost"][rows] = _cost_lmi_eigs(A[found], H, E[found], QK[found], Pf, lf, discrete)[:, 0]
            cert["P"][rows] = np.linalg.eigvalsh(Pf)[:, 0]
    info = {"path": "riccati", "search_steps": steps, "riccati_failures": failures}
    return CostBoundBatch(_frozen(bound), _frozen(P_out), _frozen(mult), _ro(reason),
                          None if x0 is None else _frozen(x0),
                          MappingProxyType({k: _frozen(v) for k, v in cert.items()}), MappingProxyType(info))


def guaranteed_cost(controller: Controller | tuple[Plant, ArrayLike], uncertainty: NormBounded, Q: ArrayLike,
                    R: ArrayLike, x0: ArrayLike | None = None) -> CostBound | CostBoundBatch:
    r"""Upper bound on the LQ cost of ``u = K x`` valid for every ``||Delta|| <= 1``.

    The guaranteed-cost LMI of Petersen & McFarlane (1994), for a fixed gain:
    with ``Q_K = Q + K'RK`` find ``P >= 0``, ``lam >= 0`` with::

        [ P - A'PA - Q_K - lam E'E    -A'PH         ]
        [ -H'PA                       lam I - H'PH  ]  >= 0

    (continuous time: ``[[-(A'P + PA) - Q_K - lam E'E, -PH], [-H'P, lam I]]``).
    Then ``sum_k x_k'Q x_k + u_k'R u_k <= x0'P x0`` (continuous: the
    integral) for every admissible ``Delta``, also time-varying. The bound
    minimises ``x0'P x0``, or ``lambda_max(P)`` (one ``P`` for every unit
    initial state) if ``x0`` is not given.

    One gain: one SDP. A stack of gains (B, m, n) is answered at once
    without an SDP (:class:`CostBoundBatch`): for a fixed ``lam`` the
    smallest ``P`` is the stabilising solution of a bounded-real Riccati
    equation and the bound is convex in ``lam``, so a golden-section search
    over ``log lam`` with batched Riccati solves gives every design's bound
    (``_guaranteed_cost_batch``); designs that are unstable, not
    robustly stable or not finite are flagged (``reason``) instead of
    raising.

    Parameters
    ----------
    controller : Controller or (Plant, (m, n) or (B, m, n) array_like)
    uncertainty : NormBounded
    Q : (n, n) array_like, symmetric positive semidefinite
    R : (m, m) array_like, symmetric positive semidefinite
    x0 : (n,) array_like, optional
        Initial state.

    Returns
    -------
    CostBound or CostBoundBatch
        The latter for a stack of gains.

    Raises
    ------
    InfeasibleError
        One gain: the loop is not quadratically stable for ``||Delta|| <= 1`` (no bound exists).
    """
    import cvxpy as cp

    plant, K = _loop(controller, batch=True)
    if K.ndim == 3:
        unc = check_norm_bounded(uncertainty, plant)
        n, m = plant.n, plant.m
        Qc = check_spd(as_matrix(Q, "Q", rows=n, cols=n, rows_what="the number of states",
                                 cols_what="the number of states"), "Q", semidefinite=True)
        Rc = check_spd(as_matrix(R, "R", rows=m, cols=m, rows_what="the number of inputs",
                                 cols_what="the number of inputs"), "R", semidefinite=True)
        x0b = None if x0 is None else as_batch(x0, "x0", (n,), ("the number of states",))
        return _guaranteed_cost_batch(plant, K, unc, Qc, Rc, x0b)
    plant, K, A, H, E = _robust_loop(controller, uncertainty, "guaranteed cost")
    n, m, p = plant.n, plant.m, H.shape[1]
    Q = check_spd(as_matrix(Q, "Q", rows=n, cols=n, rows_what="the number of states",
                            cols_what="the number of states"), "Q", semidefinite=True)
    R = check_spd(as_matrix(R, "R", rows=m, cols=m, rows_what="the number of inputs",
                            cols_what="the number of inputs"), "R", semidefinite=True)
    if x0 is not None:
        x0 = as_batch(x0, "x0", (n,), ("the number of states",))
    QK = Q + K.T @ R @ K
    T = _Coordinates(_lyapunov_factor(A, QK, plant.is_discrete))
    Ah, QKh = T.A(A), T.Q(QK)
    Hh, Eh, c = _balanced(T.B(H), T.C(E))
    P, lam = cp.Variable((n, n), symmetric=True, name="P"), cp.Variable(name="lam")
    N = _diag(QKh, np.zeros((p, p))) + lam * _diag(Eh.T @ Eh, -np.eye(p))
    lmis = [_cvx.LMI("cost", _block(Ah, Hh, P, N, plant.is_discrete)), _cvx.LMI("P", P)]
    if x0 is None:
        s = cp.Variable(name="s")
        # lambda_max(L P^ L') <= s / c  <=>  s (L L')^-1 / c - P^ >= 0, c = ||(L L')^-1|| (s of unit size)
        M = T.Q(np.eye(n))
        lmis.append(_cvx.LMI("P_upper", s * (M / np.linalg.norm(M, 2)) - P))
        objective = cp.Minimize(s)
    else:
        xh = T.L.T @ x0
        xh = xh / (np.linalg.norm(xh) or 1.0)   # x0' P x0 = |L' x0|^2 xh' P^ xh: the direction only
        objective = cp.Minimize(xh @ P @ xh)
    rep = _cvx.solve_sdp(objective, lmis, infeasible_msg="the guaranteed-cost LMI is infeasible")
    P_orig = T.P(_cvx.value(P))
    bound = float(x0 @ P_orig @ x0) if x0 is not None else float(np.linalg.eigvalsh(P_orig)[-1])
    return CostBound(bound, _frozen(P_orig), _multiplier(lam, p, c), None if x0 is None else _frozen(x0),
                     MappingProxyType(dict(rep.certificate)), MappingProxyType(_solve_info([rep])))


def robust_hinf_bound(controller: Controller | tuple[Plant, ArrayLike], uncertainty: NormBounded, *,
                      Bw: ArrayLike, Cz: ArrayLike, Dzu: ArrayLike, Dzw: ArrayLike | None = None) -> HinfBound:
    r"""Upper bound on ``||T_zw||_inf`` of ``u = K x`` over every ``||Delta|| <= 1``.

    Closed loop ``x+ = (A + H Delta E) x + Bw w``, ``z = (Cz + Dzu K) x + Dzw w``
    (the plant convention of :func:`robustctl.hinf`). The bound is the
    smallest ``gamma`` of the robust dissipation LMI in the module docstring
    (S-procedure on ``q = Delta E x``): ``V(x+) - V(x) <= gamma^2 |w|^2 - |z|^2``
    for every admissible ``Delta``, also time-varying.

    Parameters
    ----------
    controller : Controller or (Plant, (m, n) array_like)
    uncertainty : NormBounded
    Bw : (n, q) array_like
    Cz : (pz, n) array_like
    Dzu : (pz, m) array_like
    Dzw : (pz, q) array_like, optional (default zero)

    Returns
    -------
    HinfBound

    Raises
    ------
    InfeasibleError
        The loop is not quadratically stable for ``||Delta|| <= 1``.
    """
    import cvxpy as cp

    plant, K, A, H, E = _robust_loop(controller, uncertainty, "robust H-infinity bound")
    n, p = plant.n, H.shape[1]
    Bw, Cz, Dzu, Dzw = check_performance(n, plant.m, Bw, Cz, Dzu, Dzw)
    C = Cz + Dzu @ K
    q = Bw.shape[1]
    T = _Coordinates(_lyapunov_factor(A, C.T @ C, plant.is_discrete))
    Ah, Ch = T.A(A), T.C(C)
    Hh, Eh, c = _balanced(T.B(H), T.C(E))
    Bh = T.B(Bw)
    b = float(np.linalg.norm(Bh, 2)) or 1.0  # w = w^ / b: gamma = b gamma^
    Bh, Dh = Bh / b, Dzw / b
    P, lam, mu = cp.Variable((n, n), symmetric=True, name="P"), cp.Variable(name="lam"), cp.Variable(name="mu")
    CD = np.hstack([Ch, np.zeros((C.shape[0], p)), Dh])
    N = (CD.T @ CD + lam * _diag(Eh.T @ Eh, -np.eye(p), np.zeros((q, q)))
         - mu * _diag(np.zeros((n + p, n + p)), np.eye(q)))
    lmis = [_cvx.LMI("hinf", _block(Ah, np.hstack([Hh, Bh]), P, N, plant.is_discrete)), _cvx.LMI("P", P)]
    rep = _cvx.solve_sdp(cp.Minimize(mu), lmis, infeasible_msg="the robust H-infinity LMI is infeasible")
    gamma = b * float(np.sqrt(max(float(_cvx.value(mu)), 0.0)))
    return HinfBound(gamma, _frozen(T.P(_cvx.value(P))), _multiplier(lam, p, c),
                     MappingProxyType(dict(rep.certificate)), MappingProxyType(_solve_info([rep])))


# ---------------------------------------------------------------- worst case
def _polar(M: np.ndarray) -> np.ndarray:
    """The nearest matrix with every singular value 1 (``U V'`` of ``M = U S V'``)."""
    U, _, Vt = np.linalg.svd(M, full_matrices=False)
    return U @ Vt


def _project(D: np.ndarray) -> np.ndarray:
    """Projection onto ``||D||_2 <= 1``: singular values clipped at 1."""
    U, s, Vt = np.linalg.svd(D, full_matrices=False)
    return (U * np.minimum(s, 1.0)) @ Vt


class _Objective:
    """Spectral radius (or abscissa) of ``A + H D E`` and its gradient in ``D``, counting evaluations."""

    def __init__(self, A, H, E, discrete):
        self.A, self.H, self.E, self.discrete = A, H, E, discrete
        self.count = 0

    def _eig(self, D):
        self.count += 1
        return scipy.linalg.eig(self.A + self.H @ D @ self.E, left=True, right=True)

    def value(self, D) -> float:
        self.count += 1
        return _radius(self.A + self.H @ D @ self.E, self.discrete)

    def value_grad(self, D) -> tuple[float, np.ndarray]:
        # d lambda = y^H H dD E x / (y^H x) for a simple eigenvalue (y^H A = lambda y^H)
        lam, Y, X = self._eig(D)
        i = int(np.argmax(np.abs(lam) if self.discrete else lam.real))
        x, y = X[:, i], Y[:, i]
        den = y.conj() @ x  # ~0 only at a defective eigenvalue: keep the direction
        g = np.outer(y.conj() @ self.H, self.E @ x) / (den if abs(den) > 1e-300 else 1.0)
        if self.discrete:
            f = float(abs(lam[i]))
            grad = (np.conj(lam[i]) * g).real / f if f > 0 else g.real
        else:
            f, grad = float(lam[i].real), g.real
        return f, grad


def _ascend(obj: _Objective, D: np.ndarray) -> tuple[float, np.ndarray]:
    """Projected gradient ascent with a step that doubles on success and halves on failure."""
    f, g = obj.value_grad(D)
    step = 1.0
    for _ in range(_ASCENT_ITER):
        gn = float(np.linalg.norm(g))
        if gn == 0.0 or step < 1e-10:
            break
        Dn = _project(D + step * g / gn)
        fn = obj.value(Dn)
        if fn > f + 1e-15 * max(1.0, abs(f)):
            D = Dn
            f, g = obj.value_grad(D)
            step = min(2.0 * step, 2.0)
        else:
            step *= 0.5
    return f, D


def worst_case(controller: Controller | tuple[Plant, ArrayLike], uncertainty: NormBounded, *,
               seed=None, n_starts: int = 20) -> WorstCase:
    r"""Search ``||Delta||_2 <= 1`` for the perturbation that most destabilises ``u = K x``.

    Maximises the spectral radius (discrete time) or the spectral abscissa
    (continuous time) of ``A + H Delta E`` by projected gradient ascent
    (gradient of a simple eigenvalue, projection by clipping singular
    values; at most 200 steps per start) from

    * the boundary points along the worst-case directions: ``+-`` the polar
      factor (all singular values 1) and ``+-`` the rank-one part of the
      gradient at ``Delta = 0``, and ``+-`` the normalised real part of the
      small-gain destabiliser ``v u^H`` (``T(e^{j w*}) v = sigma u`` at the
      peak frequency of ``T = E (zI - A)^-1 H``, python-control's
      ``linfnorm``); for a scalar ``Delta`` these are the vertices ``+-1``;
    * ``n_starts`` random extreme points (polar factors of Gaussian matrices).

    A search, not a certificate: the value is a lower bound on the worst
    case (compare :func:`robust_stability` for the upper side).

    Parameters
    ----------
    controller : Controller or (Plant, (m, n) array_like)
    uncertainty : NormBounded
    seed : None, int, SeedSequence or Generator
        For the random starts (``np.random.default_rng``).
    n_starts : int, default 20
        Number of random starts (>= 0).

    Returns
    -------
    WorstCase
    """
    import control

    plant, K = _loop(controller)
    unc = check_norm_bounded(uncertainty, plant)
    try:
        n_starts = check_int(n_starts, "n_starts", minimum=0)
    except TypeError as exc:  # worst_case has raised ValueError for every bad n_starts: keep that type
        raise ValueError(str(exc)) from None
    rng = as_rng(seed)
    discrete = plant.is_discrete
    A, H, E = plant.F + plant.G @ K, unc.H, unc.EF + unc.EG @ K
    p, l = unc.p, unc.l
    obj = _Objective(A, H, E, discrete)
    nominal, g0 = obj.value_grad(np.zeros((p, l)))
    starts = []
    if np.any(g0):
        U, _, Vt = np.linalg.svd(g0)
        starts += [_polar(g0), np.outer(U[:, 0], Vt[0])]
    if is_stable(A, discrete=discrete) and np.any(H) and np.any(E):
        sys = control.ss(A, H, E, np.zeros((l, p)), plant.dt if discrete else 0)
        _, w = control.linfnorm(sys)
        z = np.exp(1j * w * plant.dt) if discrete else 1j * w
        Tz = E @ np.linalg.solve(z * np.eye(plant.n) - A, H)
        U, _s, Vh = np.linalg.svd(Tz)
        Dc = np.outer(Vh[0].conj(), U[:, 0].conj()).real  # Re(v u^H)
        if np.any(Dc):
            starts.append(Dc / np.linalg.norm(Dc, 2))
    starts = [sgn * S for S in starts for sgn in (1.0, -1.0)]
    starts += [_polar(rng.standard_normal((p, l))) for _ in range(n_starts)]
    best_f, best_D = nominal, np.zeros((p, l))
    for S in starts:
        f, D = _ascend(obj, S)
        if f > best_f:
            best_f, best_D = f, D
    worst = A + H @ best_D @ E
    return WorstCase(_frozen(best_D), _radius(worst, discrete), not is_stable(worst, discrete=discrete), nominal,
                     obj.count)
from ._margins_report import MarginsReport, margins_report  # noqa: E402, F401 (re-exported: the margins report)
