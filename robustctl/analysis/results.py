"""The result classes of :mod:`robustctl.analysis` and their formatting helpers."""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np


def _ro(arr: np.ndarray) -> np.ndarray:
    """A read-only copy that keeps the dtype (bool, str)."""
    arr = np.array(arr)
    arr.flags.writeable = False
    return arr


def _fmt(x) -> str:
    return "None" if x is None else f"{x:.6g}"


@dataclass(frozen=True, eq=False, repr=False)
class RobustStability:
    r"""Quadratic-stability certificate of a closed loop (:func:`robustctl.robust_stability`).

    Parameters
    ----------
    certified, margin, radius, P, certificate, kind, info
        The attributes below.

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
        diagnostics (``solve_time``, ``iterations``, ``solves``). The table
        of keys is in :func:`robustctl.robust_stability`.

    See Also
    --------
    robustctl.robust_stability : computes it.
    RobustStabilityBatch : the same for a stack of gains.

    Notes
    -----
    For a norm-bounded uncertainty the certificate is the LMI at ``r = radius``

    .. math::

        \begin{bmatrix} P - A^T P A - E^T E & -r A^T P H \\
                        -r H^T P A & I - r^2 H^T P H \end{bmatrix} \succ 0,
        \qquad P \succ 0,

    whose smallest eigenvalues are ``certificate["lyapunov"]`` and
    ``certificate["P"]``.

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> ctrl = rc.lqr(plant)
    >>> unc = rc.NormBounded([[0.0], [0.1]], [[0.0, 0.0]], [[0.5]])        # input gain +- 50 %
    >>> res = rc.robust_stability(ctrl, unc)
    >>> res.certified, res.radius
    (True, 1.0)

    The certificate holds, rebuilt here from ``P``:

    >>> A, H, E, P = ctrl.closed_loop(), unc.H, unc.EF + unc.EG @ ctrl.K, res.P
    >>> M = np.block([[P - A.T @ P @ A - E.T @ E, -A.T @ P @ H], [-H.T @ P @ A, np.eye(1) - H.T @ P @ H]])
    >>> bool(np.isclose(np.linalg.eigvalsh(M)[0], res.certificate["lyapunov"]))
    True
    >>> bool(np.linalg.eigvalsh(M)[0] > 0 and np.linalg.eigvalsh(P)[0] > 0)
    True
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

    Parameters
    ----------
    margin, reason, kind
        The attributes below.
    _certify : callable
        Returns ``(certified, radius, P, certificate, info)``; called on first access.

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
        ``"sdp_solves"``: designs that needed the SDP (the table of
        :func:`robustctl.robust_stability`).

    See Also
    --------
    robustctl.robust_stability : computes it.
    RobustStability : the result for one gain.

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> ctrl = rc.lqr(plant)
    >>> unc = rc.NormBounded([[0.0], [0.1]], [[0.0, 0.0]], [[0.5]])        # input gain +- 50 %
    >>> batch = rc.robust_stability((plant, np.stack([ctrl.K, 0.5 * ctrl.K, -ctrl.K])), unc)
    >>> batch.reason.tolist(), batch.certified.tolist()
    (['ok', 'ok', 'unstable'], [True, True, False])

    The margins are the small-gain values (python-control's ``linfnorm``):

    >>> import control
    >>> ref = [1.0 / control.linfnorm(control.ss(plant.F + plant.G @ K, unc.H, unc.EG @ K, 0, 0.1))[0]
    ...        for K in (ctrl.K, 0.5 * ctrl.K)]
    >>> bool(np.allclose(batch.margin[:2], ref, rtol=1e-8))
    True
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
    r"""Guaranteed LQ cost: ``sum x'Qx + u'Ru <= bound`` for every admissible ``Delta``.

    Parameters
    ----------
    bound, P, multiplier, x0, certificate, info
        The attributes below.

    Attributes
    ----------
    bound : float
        ``x0' P x0``, or ``lambda_max(P)`` (every unit ``x0``) when ``x0`` is not given.
    P : (n, n) ndarray
        Quadratic cost bound ``V(x) = x'Px``.
    multiplier : float
        S-procedure multiplier ``lam``.
    x0 : (n,) ndarray or None
        The initial state, None for the worst unit one.
    certificate : Mapping[str, float]
        Smallest eigenvalue of each LMI block at the solution (solver's coordinates, ``>= 0`` up to rounding).
    info : Mapping
        Solver diagnostics: ``"solve_time"`` [s], ``"iterations"``,
        ``"solves"`` (one report per SDP).

    See Also
    --------
    robustctl.guaranteed_cost : computes it (the LMI is in its Notes).
    CostBoundBatch : the same for a stack of gains.

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> ctrl = rc.lqr(plant)
    >>> unc = rc.NormBounded([[0.0], [0.1]], [[0.0, 0.0]], [[0.5]])        # input gain +- 50 %
    >>> cost = rc.guaranteed_cost(ctrl, unc, Q=np.eye(2), R=np.eye(1))
    >>> bool(np.isclose(cost.bound, np.linalg.eigvalsh(cost.P)[-1]))      # x0 not given: lambda_max(P)
    True

    ``(P, multiplier)`` satisfies the guaranteed-cost LMI, rebuilt here:

    >>> A, H, E, P, lam = ctrl.closed_loop(), unc.H, unc.EG @ ctrl.K, cost.P, cost.multiplier
    >>> QK = np.eye(2) + ctrl.K.T @ ctrl.K
    >>> M = np.block([[P - A.T @ P @ A - QK - lam * E.T @ E, -A.T @ P @ H],
    ...               [-H.T @ P @ A, lam * np.eye(1) - H.T @ P @ H]])
    >>> bool(np.linalg.eigvalsh(M)[0] > -1e-8 * np.linalg.eigvalsh(M)[-1])
    True
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
    """Guaranteed LQ costs of a stack of gains ``K`` (B, m, n) on one plant (:func:`robustctl.guaranteed_cost`).

    Design ``b`` gets the bound of :class:`CostBound` (computed by Riccati
    equations and a search over the multiplier instead of an SDP), as
    entries of arrays.

    Parameters
    ----------
    bound, P, multiplier, reason, x0, certificate, info
        The attributes below.

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
        The initial state, None for the worst unit one.
    certificate : Mapping[str, (B,) ndarray]
        Smallest eigenvalue of each LMI block at ``(P, lam)`` in the plant's
        coordinates: ``"cost"`` (the guaranteed-cost LMI) and ``"P"``
        (``>= 0`` up to rounding: ``P`` solves the Riccati equation, on the
        boundary of the LMI, as the SDP's optimum is).
    info : Mapping
        ``"path"``: ``"riccati"``; ``"search_steps"``: golden-section steps
        of the multiplier search; ``"riccati_failures"``: designs whose
        Riccati solution failed at the optimal multiplier (bound ``inf``).

    See Also
    --------
    robustctl.guaranteed_cost : computes it.

    Examples
    --------
    A scalar loop ``x+ = (0.5 + k + 0.2 Delta) x`` costs at worst
    ``(1 + k^2) / (1 - (|0.5 + k| + 0.2)^2)`` from ``x0 = 1``:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[0.5]], [[1.0]], dt=0.1)
    >>> unc = rc.NormBounded([[1.0]], [[0.2]], [[0.0]])
    >>> gains = np.array([-0.2, -0.4, 0.5]).reshape(3, 1, 1)
    >>> batch = rc.guaranteed_cost((plant, gains), unc, Q=[[1.0]], R=[[1.0]], x0=[1.0])
    >>> batch.reason.tolist()
    ['ok', 'ok', 'unstable']
    >>> k = gains[:2, 0, 0]
    >>> bool(np.allclose(batch.bound[:2], (1 + k**2) / (1 - (abs(0.5 + k) + 0.2) ** 2), rtol=1e-6))
    True
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

    Parameters
    ----------
    gamma, P, multiplier, certificate, info
        The attributes below.

    Attributes
    ----------
    gamma : float
        The bound.
    P : (n, n) ndarray
        Storage function ``x'Px`` of the dissipation inequality.
    multiplier : float
        S-procedure multiplier ``lam``.
    certificate : Mapping[str, float]
        Smallest eigenvalue of each LMI block at the solution (solver's coordinates).
    info : Mapping
        Solver diagnostics: ``"solve_time"`` [s], ``"iterations"``,
        ``"solves"`` (one report per SDP).

    See Also
    --------
    robustctl.robust_hinf_bound : computes it (the LMI is in its Notes).

    Examples
    --------
    The bound is at least the nominal norm (python-control's ``linfnorm``)
    and at least the norm of every plant of the set, here ``Delta = -1``:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> ctrl = rc.lqr(plant)
    >>> unc = rc.NormBounded([[0.0], [0.1]], [[0.0, 0.0]], [[0.5]])        # input gain +- 50 %
    >>> Bw, Cz = [[0.0], [0.1]], [[1.0, 0.0]]
    >>> res = rc.robust_hinf_bound(ctrl, unc, Bw=Bw, Cz=Cz, Dzu=[[0.0]])
    >>> import control
    >>> worst = unc.perturb(plant, [[-1.0]])
    >>> norms = [control.linfnorm(control.ss(p.F + p.G @ ctrl.K, Bw, Cz, 0, 0.1))[0] for p in (plant, worst)]
    >>> bool(res.gamma >= max(norms))
    True
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
    """Result of the worst-case search over ``||Delta|| <= 1`` (:func:`robustctl.worst_case`).

    Parameters
    ----------
    Delta, radius, destabilizing, nominal_radius, evaluations
        The attributes below.

    Attributes
    ----------
    Delta : (p, l) ndarray
        The worst perturbation found (``||Delta||_2 <= 1``).
    radius : float
        Spectral radius (discrete) or spectral abscissa (largest real part,
        continuous) of ``A + H Delta E``.
    destabilizing : bool
        The loop at ``Delta`` is not stable in the sense of
        :mod:`robustctl.systems.stability`: ``radius >= 1 - STABILITY_MARGIN``
        (discrete) or ``radius >= -STABILITY_MARGIN`` (continuous), as
        ``not Controller.is_stabilizing``.
    nominal_radius : float
        The same for ``Delta = 0``.
    evaluations : int
        Eigenvalue decompositions used.

    See Also
    --------
    robustctl.worst_case : computes it.

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> ctrl = rc.lqr(plant)
    >>> unc = rc.NormBounded([[0.0], [0.1]], [[0.0, 0.0]], [[0.5]])        # input gain +- 50 %
    >>> wc = rc.worst_case(ctrl, unc)
    >>> wc.destabilizing, float(np.linalg.norm(wc.Delta, 2))
    (False, 1.0)
    >>> A, H, E = ctrl.closed_loop(), unc.H, unc.EG @ ctrl.K
    >>> bool(np.isclose(wc.radius, max(abs(np.linalg.eigvals(A + H @ wc.Delta @ E)))))
    True
    """

    Delta: np.ndarray
    radius: float
    destabilizing: bool
    nominal_radius: float
    evaluations: int

    def __repr__(self) -> str:
        return (f"WorstCase(radius={self.radius:.6g}, destabilizing={self.destabilizing}, "
                f"nominal_radius={self.nominal_radius:.6g}, ||Delta||={np.linalg.norm(self.Delta, 2):.6g})")
