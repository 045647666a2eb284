r"""Robust linear quadratic regulator (RLQR) for norm-bounded uncertainty.

System (paper Eq. statespaceDT, RLQRuncertainties)::

    x[k+1] = (F + H Delta EF) x[k] + (G + H Delta EG) u[k],   ||Delta|| <= 1,

with ``H`` (n x p), ``EF`` (l x n), ``EG`` (l x m). The RLQR (Cerri, Terra &
Ishihara 2009; Cerri et al. 2014; paper Section 2.2) solves, at each step, the
regularised min-max problem with penalty ``mu`` and gives ``u = K x`` and the
closed loop ``x[k+1] = L x[k]``.

Public functions: :func:`rlqr` (one steady-state design, a
:class:`~robustctl.Controller`), :func:`rlqr_schedule` (finite horizon, an
:class:`RLQRSchedule`), :func:`rlqr_gains` (a batch, an :class:`RLQRBatch`),
and the single steps :func:`rlqr_step`, :func:`rlqr_step_block`.

Three equivalent forms of one recursion step ``P[k+1] -> (L[k], K[k], P[k])``:

* **Block system** (Theorem 1 as corrected in PAPER_NOTES.md),
  :func:`rlqr_step_block`: ``L``, ``K`` are blocks 5 and 6 of ``Xi^-1 b`` and
  ``P = b' Xi^-1 b``. The reference implementation used by the tests.
* **W form** of PAPER_NOTES.md: ``W = Sigma + Ihat P^-1 Ihat' + Ghat R^-1 Ghat'``,
  ``K = -R^-1 Ghat' W^-1 Fhat``, ``P = Q + Fhat' W^-1 Fhat``. Used in tests only.
* **Penalty / KKT form** (the fast path, :func:`rlqr_step`). With
  ``lambda = (1 + alpha) ||mu H'H||`` and ``S = mu^-1 I - lambda^-1 H H'``
  (positive definite for ``alpha > 0``), Woodbury's identity turns the W form into

  .. math::

      \tilde P &= (I + P S)^{-1} P = (P^{-1} + S)^{-1}, \\
      \begin{bmatrix} R + G'\tilde P G & E_G' \\ E_G & -\lambda^{-1} I \end{bmatrix}
      \begin{bmatrix} K \\ \nu \end{bmatrix} &=
      -\begin{bmatrix} G'\tilde P F \\ E_F \end{bmatrix}, \\
      L_c = F + G K, \quad L &= (I + S P)^{-1} L_c, \\
      P_{new} &= Q + K' R K + L_c' \tilde P L_c + \lambda^{-1} \nu'\nu .

  Here ``nu = lambda (EF + EG K)``. Every term is a sum of positive
  semidefinite matrices, nothing is multiplied by ``lambda`` and no inverse of
  ``P`` or ``Q`` is needed, so the step stays accurate for ``mu`` up to 1e22
  and is exact at ``mu = inf`` (``S = 0``, ``lambda^-1 = 0``: the KKT system
  then enforces ``EF + EG K = 0`` and ``L = F + G K``; it is solvable iff
  ``EG`` has full row rank, i.e. ``[I -G; 0 -EG]`` has full row rank).

Steady state. The steady-state recursion is the Riccati equation of an
ordinary LQ problem with the augmented input ``(u, v)``, ``x+ = F x + G u + v``
and stage cost ``x'Qx + u'Ru + lambda ||EF x + EG u||^2 + v' S^-1 v``; its
closed loop is ``L``. The fixed point ``P = f(P)`` is found either by
iterating ``f`` from ``P = Q`` (or ``P_N``) - the paper's recursion,
``accelerate=False`` - or, much faster, by the structure-preserving doubling
algorithm on that Riccati equation written without cross terms (Woodbury
again keeps it finite for every ``mu``), which converges quadratically (about
10 doubling steps where the recursion takes hundreds). Either way the result
is accepted only when one more step of the recursion changes ``P`` by less
than ``tol`` (relative, Frobenius norm) and ``L`` is stable
(``rho(L) < 1 - 1e-9``, :data:`robustctl.systems.stability.STABILITY_MARGIN`), which
singles out the stabilising solution. A design on which doubling settles but
misses that test (ill-conditioned ones: the doubled steering column with
nearly equal ``EG`` entries has ``P ~ 1e15`` and a doubling result about
1e-8 off) is redone with the plain recursion (``fallback="recursion"``) or
first refined by Newton's method (``fallback="newton"``): ``f``'s derivative
at ``P`` is ``X -> L' X L``, so each Newton (Kleinman-Hewer) step is one
Stein equation ``X = L' X L + f(P) - P``, solved by Smith's doubling.
The doubling steps, the plain recursion and the evaluation of their results
run in a compiled numba kernel (:mod:`robustctl.synthesis._rlqr.kernel`: the same
steps, operation for operation, and the same stopping rules; numpy's
per-call overhead, about 80 us a step on the MOPs' small systems, made the
recursion the cost of the fallback and the doubling a fifth of a MOP
evaluation); the numpy loops are the references its tests compare with.

``lambda`` with no uncertainty. With ``H = 0`` the bound ``lambda >
||mu H'H|| = 0`` leaves ``lambda`` free, but any finite ``lambda > 0`` adds a
spurious penalty ``lambda ||EF x + EG u||^2`` although ``dF = dG = 0``. We
take the exact limit ``lambda -> 0``, in which the min-max problem no longer
depends on ``EF, EG``: the design is the nominal regulator (``S = mu^-1 I``),
equal to the LQR as ``mu -> inf``. With ``EF = EG = 0`` and ``H != 0``,
``lambda`` has no effect.

Errors. :func:`rlqr` raises :class:`~robustctl.errors.NotStabilizableError`
for a plant that is not stabilisable (PBH test,
:func:`robustctl.systems.stability.check_stabilizable`), as :func:`robustctl.lqr`
does, and so do :func:`robustctl.hinf` and :func:`robustctl.h2`
(``NotStabilizableError`` is also an ``InfeasibleError``). Without the check the
recursion would not fail: for finite ``mu`` the fictitious input ``v``
"stabilises" ``L`` while no ``K`` stabilises ``F + G K``.
:func:`rlqr_gains` flags every design ``"unstabilizable"`` instead.

A design that converges is not always a stabilising gain. For finite ``mu``
the RLQR stabilises its own closed loop ``L = (I + S P)^-1 (F + G K)``, in
which the fictitious input ``v`` (penalised by ``S^-1``, i.e. by ``mu``) helps
``u``; the nominal loop ``F + G K`` may still be unstable (a cart-pole with
a sizeable ``EF``, a nearly uncontrollable mode: ``v`` moves what ``G``
hardly can). :func:`rlqr` therefore also checks ``F + G K`` (Schur stable,
``rho < 1 - 1e-9``) and raises :class:`NotStabilizingError` (a
``ConvergenceError``) with both spectral radii unless called with
``check_stability=False``, which returns the design with
``info["stabilizing"] = False``. :func:`rlqr_gains` never raises for this:
it flags such designs ``ok`` but ``stabilizing`` False.

References
----------
Cerri, J. P., Terra, M. H., & Ishihara, J. Y. (2009). Recursive robust
regulator for discrete-time state-space systems. ACC 2009, 3077-3082.
Sayed, A. H. (2001). A framework for state-space estimation with uncertain
models. IEEE TAC 46(7), 998-1013.
Chu, E. K.-W., Fan, H.-Y., & Lin, W.-W. (2005). A structure-preserving
doubling algorithm for continuous-time algebraic Riccati equations. Linear
Algebra Appl. 396, 55-80 (and its discrete-time form, ibid.).
Hewer, G. (1971). An iterative technique for the computation of the steady
state gains for the discrete optimal regulator. IEEE TAC 16(4), 382-384.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._kkt import DEFAULT_ALPHA
from .._validation import as_matrix, check_bool, check_choice, check_int, check_positive_scalar, check_spd, frozen
from ..errors import ConvergenceError, NotStabilizingError
from ..systems.controller import Controller
from ..systems.plant import Plant
from ..systems.stability import STABILITY_MARGIN, check_stabilizable, is_schur_stable, spectral_radius
from ._rlqr.model import Model, build
from ._rlqr.steady import DEFAULT_MAX_ITER, DEFAULT_TOL, steady_state
from ._rlqr.step import block_steps, kkt_step, rlqr_step, rlqr_step_block

__all__ = ["rlqr", "rlqr_schedule", "rlqr_gains", "rlqr_step", "rlqr_step_block", "RLQRBatch", "RLQRSchedule"]


_IMPLEMENTATIONS = ("kkt", "block")
_FALLBACKS = ("recursion", "newton")


@dataclass(frozen=True, eq=False, repr=False)
class RLQRBatch:
    """Steady-state RLQR designs for a batch of ``B`` uncertainty models (:func:`rlqr_gains`).

    Design ``b`` is the steady state that ``rlqr`` computes for the ``b``-th
    uncertainty and penalty, as entries of stacked arrays; a design that
    fails is flagged in ``ok`` and ``reason``, never raised for the batch.

    Parameters
    ----------
    K, P, L, ok, reason, stabilizing, iterations, residual : ndarray
        The attributes below (built by :func:`rlqr_gains`).

    Attributes
    ----------
    K : (B, m, n) ndarray
        Gains, ``u = K x``. Rows of designs that failed (``ok`` False) are NaN.
    P : (B, n, n) ndarray
        Steady-state Riccati matrices (NaN where ``ok`` is False).
    L : (B, n, n) ndarray
        Closed-loop matrices of the RLQR (``F + G K`` at ``mu = inf``).
    ok : (B,) bool ndarray
        The design converged to a finite fixed point with ``residual < tol``.
    reason : (B,) str ndarray
        Why a design failed (``"ok"`` where it did not):

        ====================  ==================================================
        ``reason``            meaning
        ====================  ==================================================
        ``"ok"``              converged; see ``stabilizing``
        ``"rank"``            ``mu = inf`` and ``EG`` is not of full row rank
        ``"unstabilizable"``  the plant is not stabilisable (every design)
        ``"not converged"``   no fixed point within ``max_iter`` steps
        ``"diverged"``        ``P`` grows without bound: no stabilising steady state
        ====================  ==================================================
    stabilizing : (B,) bool ndarray
        ``F + G K`` is Schur stable (``rho < 1 - 1e-9``, the nominal closed
        loop). For finite ``mu`` the RLQR stabilises its own closed loop
        ``L``, not necessarily ``F + G K``: a converged design (``ok``) can
        still destabilise the nominal plant.
    iterations : (B,) int ndarray
        Doubling steps (plus Newton evaluations and recursion steps where they were needed).
    residual : (B,) ndarray
        Relative change of ``P`` in one more recursion step at the returned ``P``.

    See Also
    --------
    rlqr_gains : builds it.
    robustctl.rlqr : one design, as a :class:`~robustctl.Controller`.

    Examples
    --------
    Three penalties at once; the first asks for ``EF + EG K = 0`` with a
    rank-deficient ``EG`` (two rows, one input) and is flagged:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> EF, EG = [[0.1, 0.0], [0.0, 0.1]], [[0.1], [0.2]]
    >>> batch = rc.rlqr_gains(plant, EF, EG, [np.inf, 1e2, 1e4], H=np.eye(2))
    >>> batch.reason.tolist(), batch.stabilizing.tolist()
    (['rank', 'ok', 'ok'], [False, True, True])
    >>> bool(np.isnan(batch.K[0]).all())
    True
    >>> rho = [max(abs(np.linalg.eigvals(plant.F + plant.G @ K))) for K in batch.K[1:]]
    >>> bool(max(rho) < 1.0)
    True
    """

    K: np.ndarray
    P: np.ndarray
    L: np.ndarray
    ok: np.ndarray
    reason: np.ndarray
    stabilizing: np.ndarray
    iterations: np.ndarray
    residual: np.ndarray

    def __len__(self) -> int:
        return self.K.shape[0]

    def __repr__(self) -> str:
        return (f"RLQRBatch(B={len(self)}, m={self.K.shape[1]}, n={self.K.shape[2]}, "
                f"ok={int(self.ok.sum())}/{len(self)}, max_iterations={int(self.iterations.max(initial=0))})")


@dataclass(frozen=True, eq=False, repr=False)
class RLQRSchedule:
    """Finite-horizon RLQR: time-varying gains ``u[k] = K[k] x[k]``, ``k = 0..N-1`` (:func:`rlqr_schedule`).

    Parameters
    ----------
    K, L, P : ndarray
        The gains, closed loops and Riccati matrices (attributes below).
    plant : Plant
        The nominal plant.
    info : Mapping, optional
        Diagnostics.

    Attributes
    ----------
    K : (N, m, n) ndarray
        Gains, ``u[k] = K[k] x[k]``.
    L : (N, n, n) ndarray
        Closed loops of the RLQR, ``x*[k+1] = L[k] x*[k]``.
    P : (N + 1, n, n) ndarray
        Riccati matrices; ``P[N]`` is the terminal weight ``P_N``.
    plant : Plant
        The nominal plant.
    info : Mapping
        ``"mu"``, ``"alpha"``, ``"lambda"``, ``"H"`` and ``"implementation"`` (as in
        :func:`rlqr`'s table).

    See Also
    --------
    rlqr_schedule : builds it.

    Examples
    --------
    Far from the end of a long horizon the gains settle at the steady
    state that :func:`rlqr` finds by doubling:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> H, EF, EG = [[0.0], [0.1]], [[0.1, 0.0]], [[0.1]]
    >>> schedule = rc.rlqr_schedule(plant, EF, EG, 1e4, H=H, horizon=200)
    >>> schedule
    RLQRSchedule(horizon=200, plant=Plant(n=2, m=1, dt=0.1))
    >>> schedule.K.shape, schedule.P.shape
    ((200, 1, 2), (201, 2, 2))
    >>> bool(np.allclose(schedule.K[0], rc.rlqr(plant, EF, EG, 1e4, H=H).K, rtol=1e-8))
    True
    """

    K: np.ndarray
    L: np.ndarray
    P: np.ndarray
    plant: Plant
    info: Mapping[str, Any] = field(default_factory=dict)

    @property
    def horizon(self) -> int:
        """Number of steps ``N``."""
        return self.K.shape[0]

    def controller(self, k: int) -> Controller:
        """The gain of step ``k`` as a :class:`Controller`.

        Parameters
        ----------
        k : int
            The step, ``0 <= k < N`` (negative indices count from the end).

        Returns
        -------
        Controller
            ``K[k]``, with ``info`` holding ``step``, ``L`` (``L[k]``) and ``P`` (``P[k]``).
        """
        return Controller(self.K[k], "rlqr", self.plant, {"step": k, "L": self.L[k], "P": self.P[k]})

    def __repr__(self) -> str:
        return f"RLQRSchedule(horizon={self.horizon}, plant={self.plant!r})"


def _start(P, name: str, d: Model, definite: bool) -> np.ndarray:
    """Starting point / terminal weight of the recursion (default ``Q``), symmetric PSD (PD if ``definite``)."""
    if definite:
        check_spd(d.Q, "Q")
    if P is None:
        return d.Q
    n = d.F.shape[0]
    return check_spd(as_matrix(P, name, rows=n, cols=n), name, semidefinite=not definite)


def _info(d: Model, implementation: str) -> dict:
    return {"mu": float(d.mu[0]), "alpha": d.alpha, "lambda": float(d.lam()[0]), "H": frozen(d.H),
            "implementation": implementation}


def rlqr_gains(plant: Plant, EF=None, EG=None, mu=None, *, Q=None, R=None, H=None,
               alpha: float = DEFAULT_ALPHA, uncertainty=None, tol: float = DEFAULT_TOL,
               max_iter: int = DEFAULT_MAX_ITER, P_N=None, fallback: str = "recursion") -> RLQRBatch:
    r"""Steady-state RLQR gains for ``B`` uncertainty models at once (vectorised).

    Parameters
    ----------
    plant : Plant
        Nominal discrete-time plant (shared by the batch).
    EF : (B, l, n) array_like
        State part of each design's uncertainty.
    EG : (B, l, m) array_like
        Input part of each design's uncertainty.
    mu : (B,) array_like
        Penalty parameters in ``[1e-100, inf]``; ``np.inf`` gives the limit form.
        Any of ``EF``, ``EG``, ``mu`` may omit the batch axis to be shared.
    Q : (n, n) array_like, optional
        State weight, symmetric positive semidefinite (default identity).
    R : (m, m) array_like, optional
        Input weight, symmetric positive definite (default identity).
    H : (n, p) array_like, default ``ones((n, l))``
        Same default as :func:`rlqr` (every row of ``Delta [EF EG]`` perturbs
        every state equally); give it explicitly unless that is the
        uncertainty meant. Designs with the same arguments equal
        :func:`rlqr`'s.
    alpha : float
        ``lambda = (1 + alpha) ||mu H'H||``.
    uncertainty : NormBounded, optional
        ``H``, ``EF``, ``EG`` of one uncertainty model, instead of the three arguments.
    tol : float
        Acceptance: one more recursion step changes ``P`` by less than ``tol``
        (relative) and ``rho(L) < 1 - 1e-9``.
    max_iter : int
        At most this many steps of the plain recursion where it is needed.
    P_N : (n, n) array_like, optional
        Starting point of the plain recursion where it is needed (default
        ``Q``; the steady state does not depend on it). The same name as in
        :func:`rlqr` and :func:`rlqr_schedule`, where the recursion starts from
        the terminal weight ``P[N]``.
    fallback : {"recursion", "newton"}
        What happens to designs on which doubling settles but misses the
        acceptance test (ill-conditioned ones, e.g. the doubled steering
        column with nearly equal ``EG`` entries, ``P`` near 1e15):
        ``"recursion"`` (default) redoes them with the plain recursion from
        ``P_N``, so ``max_iter`` also decides which slowly converging designs
        are flagged ``"not converged"``; ``"newton"`` first refines the doubling
        result by Newton's method (a few Stein equations; on the truck's
        ill-conditioned designs about 2.5 times cheaper than the compiled
        recursion, 20 times cheaper than the numpy one, and closer to the
        fixed point) and uses the
        recursion only where that misses the test too. The acceptance test is
        the same; ``"newton"`` also accepts designs whose recursion would need
        more than ``max_iter`` steps.

    Returns
    -------
    RLQRBatch
        Gains and per-design flags; failed designs are flagged, never silently
        NaN: check ``ok``/``reason``. A plant that is not stabilisable flags
        every design ``"unstabilizable"`` (:func:`rlqr` raises instead).

    Raises
    ------
    TypeError
        ``plant`` is not a Plant; a non-numeric argument.
    ValueError
        Shapes that do not agree (named), ``mu`` outside ``[1e-100, inf]``,
        weights that are not symmetric positive (semi)definite, an unknown
        ``fallback``. Designs that cannot be computed are flagged, not raised.

    See Also
    --------
    rlqr : one design, with its errors raised.
    RLQRBatch : the result.

    Notes
    -----
    Every design is the fixed point ``P = f(P)`` of the recursion of
    :func:`rlqr` (its Notes), found for all designs together with stacked
    ``(B, k, k)`` solves by the structure-preserving doubling algorithm
    [1]_ on the equivalent Riccati equation (module docstring); no Python
    loop over designs. The fixed point is accepted when

    .. math::

        \frac{\|f(P) - P\|_F}{\|P\|_F} < \mathrm{tol}
        \quad\text{and}\quad \rho(L) < 1 - 10^{-9}.

    References
    ----------
    .. [1] E. K.-W. Chu, H.-Y. Fan, W.-W. Lin, "A structure-preserving
       doubling algorithm for continuous-time algebraic Riccati equations",
       Linear Algebra Appl. 396, 55-80, 2005.

    Examples
    --------
    Three penalties at once; each gain is a fixed point of the paper's block
    recursion (:func:`rlqr_step_block`, an independent implementation):

    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> H, EF, EG = [[0.0], [0.1]], [[0.0, 0.0]], [[0.3]]
    >>> batch = rc.rlqr_gains(plant, EF, EG, [1e2, 1e4, 1e6], H=H)
    >>> batch.ok.tolist(), batch.stabilizing.tolist()
    ([True, True, True], [True, True, True])
    >>> _, K, P = rc.rlqr_step_block(batch.P[1], plant.F, plant.G, EF, EG, np.eye(2), np.eye(1), H, 1e4)
    >>> bool(np.allclose(P, batch.P[1], rtol=1e-8) and np.allclose(K, batch.K[1], rtol=1e-6))
    True
    """
    d = build(plant, EF, EG, mu, Q=Q, R=R, H=H, alpha=alpha, uncertainty=uncertainty, batch=True)
    tol = check_positive_scalar(tol, "tol")
    max_iter = check_int(max_iter, "max_iter")
    P0 = _start(P_N, "P_N", d, definite=False)
    fallback = check_choice(fallback, "fallback", _FALLBACKS)
    B, (n, m) = d.size, plant.G.shape
    K, P, L = np.full((B, m, n), np.nan), np.full((B, n, n), np.nan), np.full((B, n, n), np.nan)
    iterations, residual = np.zeros(B, dtype=int), np.full(B, np.inf)
    if plant.is_stabilizable:
        rank_ok = d.rank_ok()
        reason = np.where(rank_ok, "ok", "rank").astype("<U14")
    else:
        rank_ok = np.zeros(B, dtype=bool)
        reason = np.full(B, "unstabilizable", dtype="<U14")
    if rank_ok.any():
        idx = np.flatnonzero(rank_ok)
        st = steady_state(d.select(rank_ok), P0, tol, max_iter, fallback=fallback)
        P[idx], K[idx], L[idx], iterations[idx], residual[idx], reason[idx] = st
    ok = reason == "ok"
    K[~ok], P[~ok], L[~ok] = np.nan, np.nan, np.nan
    stabilizing = np.zeros(B, dtype=bool)
    stabilizing[ok] = is_schur_stable(plant.F + plant.G @ K[ok])
    return RLQRBatch(frozen(K), frozen(P), frozen(L), ok, reason, stabilizing, iterations, residual)


def rlqr(plant: Plant, EF=None, EG=None, mu=None, *, Q=None, R=None, H=None, alpha: float = DEFAULT_ALPHA,
         uncertainty=None, P_N=None, tol: float = DEFAULT_TOL, max_iter: int = DEFAULT_MAX_ITER,
         accelerate: bool = True, implementation: str = "kkt", fallback: str = "recursion",
         check_stability: bool = True) -> Controller:
    r"""Steady-state robust LQR for ``[dF dG] = H Delta [EF EG]``, ``||Delta|| <= 1`` (paper Theorem 1).

    Parameters
    ----------
    plant : Plant
        Nominal discrete-time plant ``(F, G)``.
    EF : (l, n) array_like
        State part of the uncertainty.
    EG : (l, m) array_like
        Input part of the uncertainty.
    mu : float
        Penalty parameter in ``[1e-100, inf]``; ``np.inf`` gives Algorithm 1 (``Sigma = 0``),
        which forces ``EF + EG K = 0`` and ``L = F + G K`` and needs ``EG`` of
        full row rank.
    Q : (n, n) array_like, optional
        State weight, symmetric positive semidefinite (positive definite for
        ``implementation="block"``); default identity.
    R : (m, m) array_like, optional
        Input weight, symmetric positive definite; default identity.
    H : (n, p) array_like, default ``ones((n, l))``
        ``[dF dG] = H Delta [EF EG]``. Without ``H`` every row of
        ``Delta [EF EG]`` perturbs every state equally (``H`` all ones, the
        paper's choice for its examples), which is rarely the uncertainty
        meant: give ``H``. ``H = 0`` means no uncertainty (``lambda -> 0``
        limit: ``EF``, ``EG`` are then ignored). :func:`rlqr_gains` has the
        same default.
    alpha : float, default 0.1
        ``lambda = (1 + alpha) ||mu H'H||``.
    uncertainty : NormBounded, optional
        ``H``, ``EF``, ``EG`` in one object, instead of the three arguments
        (``rlqr(plant, mu=1e8, uncertainty=rc.NormBounded(H, EF, EG))``).
    P_N : (n, n) array_like, optional
        Starting point of the plain recursion (default ``Q``).
    tol : float
        Acceptance: one more recursion step changes ``P`` by less than
        ``tol`` (relative Frobenius norm) and ``rho(L) < 1 - 1e-9``.
    max_iter : int
        At most this many steps of the plain recursion.
    accelerate : bool, default True
        Find the steady state by doubling (same fixed point, same acceptance
        test, far fewer steps). ``False``: the paper's plain recursion.
    implementation : {"kkt", "block"}
        Step formula: the penalty/KKT form (default) or the paper's block
        system (reference; plain recursion, needs ``Q`` and ``P_N`` PD).
    fallback : {"recursion", "newton"}
        With ``accelerate``: how a design on which doubling misses the
        acceptance test is redone (see :func:`rlqr_gains`).
    check_stability : bool, default True
        Raise :class:`NotStabilizingError` if the gain does not make ``F + G
        K`` Schur stable (possible at finite ``mu``, package docstring).
        ``False`` returns such a design with ``info["stabilizing"]`` False.

    Returns
    -------
    Controller
        ``K`` and, in ``info``:

        ======================  ===========================================================
        key                     value
        ======================  ===========================================================
        ``"P"``                 (n, n) steady-state Riccati matrix
        ``"L"``                 (n, n) closed loop of the RLQR, ``x*[k+1] = L x*[k]``
        ``"mu"``                the penalty
        ``"alpha"``             the margin of ``lambda``
        ``"lambda"``            ``(1 + alpha) ||mu H'H||`` (0 without uncertainty)
        ``"H"``                 (n, p) the ``H`` used (its default filled in)
        ``"implementation"``    ``"kkt"`` or ``"block"``
        ``"iterations"``        doubling (or recursion) steps
        ``"residual"``          relative change of ``P`` in one more recursion step
        ``"stabilizing"``       ``F + G K`` is Schur stable (True unless ``check_stability=False``)
        ======================  ===========================================================

    Raises
    ------
    NotStabilizableError
        ``(F, G)`` is not stabilisable; :func:`robustctl.lqr`, :func:`robustctl.hinf`
        and :func:`robustctl.h2` raise the same (it is also an ``InfeasibleError``).
    RankConditionError
        ``mu = inf`` and ``EG`` is not of full row rank (``[I -G; 0 -EG]`` is
        then not of full row rank and ``EF + EG K = 0`` may have no solution).
    ConvergenceError
        No stabilising steady state was reached (the recursion diverged, or
        did not converge in ``max_iter`` steps).
    NotStabilizingError
        (a ``ConvergenceError``) The steady state was reached but ``F + G K``
        is not Schur stable, with ``check_stability`` True (the default).
    ValueError, TypeError
        Bad arguments (shapes, weights that are not positive (semi)definite,
        ``mu`` outside ``[1e-100, inf]``), named in the message.

    See Also
    --------
    rlqr_gains : many uncertainty models at once.
    rlqr_schedule : the finite-horizon gains.
    robustctl.robust_stability : certify the design against the uncertainty.

    Notes
    -----
    Each step of the recursion solves the regularised min-max problem of
    Cerri, Terra & Ishihara [1]_ [2]_ (paper Section 2.2 [3]_)

    .. math::

        \min_{x_{k+1},\,u_k} \max_{\|\Delta\| \le 1}\;
        x_{k+1}^T P_{k+1} x_{k+1} + u_k^T R u_k + x_k^T Q x_k
        + \mu \,\| x_{k+1} - (F + H\Delta E_F) x_k - (G + H\Delta E_G) u_k \|^2 ,

    whose solution is ``u_k = K_k x_k``, ``x_{k+1} = L_k x_k`` and the new
    ``P_k``. With ``Fhat = [F; EF]``, ``Ghat = [G; EG]``, ``Ihat = [I; 0]``,
    ``lambda = (1 + alpha) ||mu H'H||`` and
    ``Sigma = blkdiag(mu^-1 I - lambda^-1 H H', lambda^-1 I)``:

    .. math::

        W &= \Sigma + \hat I P_{k+1}^{-1} \hat I^T + \hat G R^{-1} \hat G^T, \\
        K_k &= -R^{-1} \hat G^T W^{-1} \hat F, \qquad
        L_k = P_{k+1}^{-1} \hat I^T W^{-1} \hat F, \\
        P_k &= Q + \hat F^T W^{-1} \hat F .

    The code evaluates the equivalent penalty/KKT form of the module
    docstring, which needs no inverse of ``P`` or ``Q`` and is exact at
    ``mu = inf`` (then ``EF + EG K = 0`` and ``L = F + G K``). The steady
    state is the fixed point ``P = P_k = P_{k+1}``.

    References
    ----------
    .. [1] J. P. Cerri, M. H. Terra, J. Y. Ishihara, "Recursive robust
       regulator for discrete-time state-space systems", American Control
       Conference 2009, 3077-3082.
    .. [2] M. H. Terra, J. P. Cerri, J. Y. Ishihara, "Optimal robust linear
       quadratic regulator for systems subject to uncertainties", IEEE Trans.
       Automatic Control 59(9), 2586-2591, 2014.
    .. [3] G. A. Prudencio de Morais et al., "Robust path-following control
       design of heavy vehicles based on multiobjective evolutionary
       optimization", Expert Systems with Applications 192, 116304, 2022.

    Examples
    --------
    With no uncertainty (``EF = 0``, ``EG = 0``) the RLQR is the LQR
    (python-control returns ``-K``); with an uncertain input gain it
    certifies robust stability for every ``||Delta|| <= 1``:

    >>> import numpy as np, control, robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> nominal = rc.rlqr(plant, [[0.0, 0.0]], [[0.0]], 1e10)
    >>> bool(np.allclose(nominal.K, -control.dlqr(plant.F, plant.G, np.eye(2), np.eye(1))[0], rtol=1e-6))
    True
    >>> H, EF, EG = [[0.0], [0.1]], [[0.0, 0.0]], [[0.3]]         # G + H Delta EG: input gain 1 +- 30 %
    >>> robust = rc.rlqr(plant, EF, EG, 1e4, H=H)
    >>> rc.robust_stability(robust, rc.NormBounded(H, EF, EG)).certified
    True
    """
    d = build(plant, EF, EG, mu, Q=Q, R=R, H=H, alpha=alpha, uncertainty=uncertainty, batch=False)
    implementation = check_choice(implementation, "implementation", _IMPLEMENTATIONS)
    tol = check_positive_scalar(tol, "tol")
    max_iter = check_int(max_iter, "max_iter")
    accelerate = check_bool(accelerate, "accelerate")
    fallback = check_choice(fallback, "fallback", _FALLBACKS)
    check_stability = check_bool(check_stability, "check_stability")
    P_N = _start(P_N, "P_N", d, definite=implementation == "block")
    check_stabilizable(plant)
    if not d.rank_ok()[0]:
        raise d.rank_error()
    block = implementation == "block"
    st = steady_state(d, P_N, tol, max_iter, accelerate=accelerate and not block, fallback=fallback,
                      step=block_steps if block else kkt_step)
    verdict, res = st.reason[0], float(st.residual[0])
    if verdict == "diverged":
        why = (" At mu = inf the gain must satisfy EF + EG K = 0; the closed loop F + G K it forces "
               "may be unstable." if np.isinf(d.mu[0]) else "")
        raise ConvergenceError(f"the RLQR recursion diverged (P grows without bound): no stabilising "
                               f"steady state for this plant and uncertainty.{why}")
    if verdict != "ok":
        raise ConvergenceError(f"the RLQR recursion did not reach a stabilising steady state in "
                               f"max_iter={max_iter} steps (relative change of P {res:.3g}, tol={tol:g})")
    K = st.K[0]
    closed = plant.F + plant.G @ K
    stabilizing = bool(is_schur_stable(closed))
    if not stabilizing and check_stability:
        raise NotStabilizingError(
            f"the RLQR design at mu = {float(d.mu[0]):g} converged but does not stabilise the nominal plant: "
            f"rho(F + G K) = {spectral_radius(closed):.6g} >= 1 - {STABILITY_MARGIN:g}, while its own closed "
            f"loop L, helped by the fictitious input a finite mu allows, has rho(L) = "
            f"{spectral_radius(st.L[0]):.6g}. Increase mu (mu = inf forces L = F + G K), reduce EF, EG or H, "
            "or pass check_stability=False to get this design anyway (info['stabilizing'] is then False)")
    info = _info(d, implementation)
    info.update(P=st.P[0], L=st.L[0], iterations=int(st.iterations[0]), residual=res, stabilizing=stabilizing)
    return Controller(K, "rlqr", plant, info)


def rlqr_schedule(plant: Plant, EF=None, EG=None, mu=None, *, horizon: int, Q=None, R=None, H=None,
                  alpha: float = DEFAULT_ALPHA, uncertainty=None, P_N=None,
                  implementation: str = "kkt") -> RLQRSchedule:
    r"""Finite-horizon RLQR: the recursion run ``horizon`` steps back from the terminal weight ``P_N``.

    The time-varying gains ``K_0 .. K_{N-1}`` of the recursion of
    :func:`rlqr` (its Notes), ``P_N`` at the end. No stabilisability is needed.

    Parameters
    ----------
    plant : Plant
        Nominal discrete-time plant.
    EF : (l, n) array_like
        State part of the uncertainty.
    EG : (l, m) array_like
        Input part of the uncertainty.
    mu : float
        Penalty in ``[1e-100, inf]``.
    horizon : int
        The number of steps ``N``.
    Q : (n, n) array_like, optional
        State weight (default identity).
    R : (m, m) array_like, optional
        Input weight (default identity).
    H : (n, p) array_like, optional
        As in :func:`rlqr` (default ``ones((n, l))``).
    alpha : float
        ``lambda = (1 + alpha) ||mu H'H||``.
    uncertainty : NormBounded, optional
        ``H``, ``EF``, ``EG`` in one object.
    P_N : (n, n) array_like, optional
        Terminal weight (default ``Q``).
    implementation : {"kkt", "block"}
        Step formula (as in :func:`rlqr`).

    Returns
    -------
    RLQRSchedule
        ``K`` (N, m, n), ``L`` (N, n, n), ``P`` (N + 1, n, n).

    Raises
    ------
    RankConditionError
        ``mu = inf`` and ``EG`` is not of full row rank.
    ConvergenceError
        The recursion produced non-finite values.

    See Also
    --------
    rlqr : the steady state of the same recursion.

    Notes
    -----
    ``P[N] = P_N`` and, for ``k = N-1 .. 0``, ``(L[k], K[k], P[k])`` is the
    step of :func:`rlqr_step` from ``P[k+1]``. With no uncertainty and a
    large ``mu`` it is the dynamic-programming recursion of the
    finite-horizon LQR [1]_,

    .. math::

        K_k = -(R + G^T P_{k+1} G)^{-1} G^T P_{k+1} F, \qquad
        P_k = Q + F^T P_{k+1} (F + G K_k).

    References
    ----------
    .. [1] B. D. O. Anderson, J. B. Moore, *Optimal Control: Linear Quadratic
       Methods*, Prentice Hall 1990, Ch. 2.

    Examples
    --------
    Without uncertainty, the gains are those of the LQR recursion, written
    out here:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> schedule = rc.rlqr_schedule(plant, [[0.0, 0.0]], [[0.0]], 1e10, horizon=3)
    >>> F, G, P, gains = plant.F, plant.G, np.eye(2), []
    >>> for _ in range(3):
    ...     K = -np.linalg.solve(np.eye(1) + G.T @ P @ G, G.T @ P @ F)
    ...     P = np.eye(2) + F.T @ P @ (F + G @ K)
    ...     gains.insert(0, K)
    >>> bool(np.allclose(schedule.K, gains, rtol=1e-6))
    True
    """
    d = build(plant, EF, EG, mu, Q=Q, R=R, H=H, alpha=alpha, uncertainty=uncertainty, batch=False)
    horizon = check_int(horizon, "horizon")
    implementation = check_choice(implementation, "implementation", _IMPLEMENTATIONS)
    P_N = _start(P_N, "P_N", d, definite=implementation == "block")
    if not d.rank_ok()[0]:
        raise d.rank_error()
    step = block_steps if implementation == "block" else kkt_step
    Ps: list[np.ndarray] = [P_N]
    Ks: list[np.ndarray] = []
    Ls: list[np.ndarray] = []
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for _ in range(horizon):
            Pk, Kk, Lk = step(Ps[0][None], d)
            Ps.insert(0, Pk[0])
            Ks.insert(0, Kk[0])
            Ls.insert(0, Lk[0])
    K, L, P = (frozen(np.array(a)) for a in (Ks, Ls, Ps))
    if not (np.isfinite(K).all() and np.isfinite(P).all()):
        raise ConvergenceError("the finite-horizon recursion produced non-finite values")
    return RLQRSchedule(K, L, P, plant, _info(d, implementation))
