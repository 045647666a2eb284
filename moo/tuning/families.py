r"""Design families: a decision vector ``z`` -> a state-feedback gain, for a whole population at once.

A *design family* turns the MOEA's decision vectors into gains ``u = K x``
for the scenario plants of a :class:`~moo.tuning.TuningProblem`. Any object
with the small protocol :class:`DesignFamily` works; two are provided:

* :class:`RLQRFamily` - the paper's family, generalised: ``z = (E_F (l x n),
  E_G (l x m), (log10 mu)^2)`` is a candidate uncertainty model
  ``[dF dG] = H Delta [E_F E_G]`` and penalty ``mu`` of the steady-state
  robust LQR (:func:`robustctl.rlqr_gains`, batched);
* :class:`LQRFamily` - ``z = (log10 diag Q (n), log10 diag R (m))``, the
  discrete LQR of diagonal weights, all designs solved as one stack of
  Riccati equations (structure-preserving doubling, :func:`dlqr_gains`).

Both accept an ``input_map`` ``M`` (``p x m``): the design is done on
``(F, G M)`` (``m`` design inputs) and the gain applied to the plant is
``M K_d`` (``p x n``). The paper's truck is designed with a doubled steering
column ``[G G]`` and steers with ``alpha = u1 + u2``: ``input_map = [[1, 1]]``.

References
----------
D. C. Morais et al., "Robust path-following control design of heavy vehicles
based on multiobjective evolutionary optimization", Expert Systems with
Applications 192 (2022) 116304, Section 3.1 (the RLQR family).
E. K.-W. Chu, H.-Y. Fan, W.-W. Lin, C.-S. Wang, "Structure-preserving
algorithms for periodic discrete-time algebraic Riccati equations", Int. J.
Control 77(8) (2004) 767-788 (the doubling iteration of :func:`dlqr_gains`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, Protocol, runtime_checkable

import numpy as np

import robustctl as rc
from robustctl.validation import check_plant, check_positive_scalar

from ..validation import as_float_array, as_matrix, check_int

__all__ = ["DesignFamily", "FamilyGains", "FamilyControllers", "RLQRFamily", "LQRFamily", "dlqr_gains"]


@dataclass(frozen=True, eq=False, repr=False)
class FamilyGains:
    """Gains of a population of designs, with the designs that failed flagged.

    What a :class:`DesignFamily`'s ``gains`` returns: a failed design is a flagged row,
    never an exception for the whole population. The fields are attributes
    of the same names.

    Parameters
    ----------
    K : (B, m, n) ndarray
        Gains ``u = K x`` for the scenario plants (NaN rows where ``ok`` is False).
    ok : (B,) bool ndarray
        The design was computed.
    reason : (B,) object ndarray of str
        ``""`` where ``ok``, otherwise why not (e.g. ``"not converged"``, ``"rank"``).

    See Also
    --------
    DesignFamily : the protocol whose ``gains`` returns this.

    Examples
    --------
    >>> import numpy as np
    >>> from moo.tuning import FamilyGains
    >>> K = np.array([[[-1.0, -2.0]], [[np.nan, np.nan]]])
    >>> fg = FamilyGains(K, ok=np.array([True, False]), reason=np.array(["", "not converged"], dtype=object))
    >>> fg
    FamilyGains(B=2, m=1, n=2, failed=1)
    >>> fg.reason[~fg.ok].tolist()
    ['not converged']
    """

    K: np.ndarray
    ok: np.ndarray
    reason: np.ndarray

    def __repr__(self) -> str:
        B, m, n = self.K.shape
        return f"FamilyGains(B={B}, m={m}, n={n}, failed={int((~self.ok).sum())})"


@dataclass(frozen=True, eq=False, repr=False)
class FamilyControllers:
    """Dynamic output feedbacks of a population of designs, with the designs that failed flagged.

    What the ``gains`` of an output-feedback family returns (its
    ``feedback`` attribute is ``"output"``): the controllers
    ``x_c^+ = A_c x_c + B_c y``, ``u = C_c x_c + D_c y`` as one
    :class:`robustctl.ControllerBatch` of the family's plant. A failed design
    is a flagged row (NaN matrices), never an exception for the population.

    Parameters
    ----------
    controllers : robustctl.ControllerBatch
        ``B`` controllers (NaN matrices where ``ok`` is False).
    ok : (B,) bool ndarray
        The design was computed.
    reason : (B,) object ndarray of str
        ``""`` where ``ok``, otherwise why not.

    See Also
    --------
    FamilyGains : the same for state feedback.
    DesignFamily : the protocol.

    Examples
    --------
    Two static output feedbacks ``u = D_c y`` of a plant with one output:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import FamilyControllers
    >>> plant = rc.Plant([[1.1, 0.1], [0.0, 0.9]], [[0.0], [0.1]], 0.1, C=[[0.0, 1.0]])
    >>> Dc = np.array([[[-2.0]], [[-8.0]]])
    >>> batch = rc.ControllerBatch(plant, np.zeros((2, 0, 0)), np.zeros((2, 0, 1)), np.zeros((2, 1, 0)), Dc)
    >>> fc = FamilyControllers(batch, np.ones(2, bool), np.full(2, "", object))
    >>> fc
    FamilyControllers(B=2, order=0, m=1, p=1, failed=0)
    >>> bool(np.allclose(fc.controllers.closed_loops()[1], plant.F + plant.G @ Dc[1] @ plant.C))
    True
    """

    controllers: rc.ControllerBatch
    ok: np.ndarray
    reason: np.ndarray

    def __repr__(self) -> str:
        c = self.controllers
        return (f"FamilyControllers(B={len(c)}, order={c.order}, m={c.plant.m}, p={c.plant.p}, "
                f"failed={int((~self.ok).sum())})")


@runtime_checkable
class DesignFamily(Protocol):
    """What :class:`~moo.tuning.TuningProblem` needs of a design family (any object with these works).

    Attributes
    ----------
    n_var : int
        Length of the decision vector ``z``.
    xl, xu : (n_var,) ndarray
        Default bounds of ``z`` (``xl < xu``).
    n_states, n_inputs : int
        The scenario plants' ``n`` and ``m`` (a state feedback's gains are ``(n_inputs, n_states)``).
    feedback : {"state", "output"}, optional
        ``"output"`` for a family of dynamic output feedbacks (whose ``gains``
        return :class:`FamilyControllers` and which has a ``plant`` with the
        outputs it reads); missing means ``"state"``.

    Methods
    -------
    gains(Z)
        ``Z`` (B, n_var) -> :class:`FamilyGains` (state feedback) or
        :class:`FamilyControllers` (output feedback); a design that cannot be
        computed is flagged (``ok`` False, NaN row), never raised.

    See Also
    --------
    RLQRFamily, LQRFamily : state-feedback families.
    moo.tuning.StaticOutputFeedbackFamily, moo.tuning.PIDFamily, moo.tuning.FixedOrderFamily : output feedback.
    moo.tuning.TuningProblem : what uses a family.

    Examples
    --------
    A family that searches a gain directly, ``K = z.reshape(m, n)``:

    >>> import numpy as np
    >>> from moo.tuning import DesignFamily, FamilyGains
    >>> class DirectGain:
    ...     def __init__(self, n, m, bound=5.0):
    ...         self.n_states, self.n_inputs, self.n_var = n, m, n * m
    ...         self.xl, self.xu = np.full(n * m, -bound), np.full(n * m, bound)
    ...
    ...     def gains(self, Z):
    ...         B = Z.shape[0]
    ...         return FamilyGains(Z.reshape(B, self.n_inputs, self.n_states),
    ...                            np.ones(B, bool), np.full(B, "", object))
    >>> fam = DirectGain(n=2, m=1)
    >>> isinstance(fam, DesignFamily)
    True
    >>> fam.gains(np.array([[-1.0, -2.0]])).K
    array([[[-1., -2.]]])

    An output-feedback family in a few lines: a first-order controller
    ``x_c^+ = a x_c + y``, ``u = c x_c + d y`` with ``z = (a, c, d)``:

    >>> import robustctl as rc
    >>> from moo.tuning import FamilyControllers
    >>> class FirstOrder:
    ...     feedback, n_var = "output", 3
    ...     xl, xu = np.array([-1.0, -5.0, -5.0]), np.array([1.0, 5.0, 5.0])
    ...
    ...     def __init__(self, plant):
    ...         self.plant, self.n_states, self.n_inputs = plant, plant.n, plant.m
    ...
    ...     def gains(self, Z):
    ...         B = Z.shape[0]
    ...         batch = rc.ControllerBatch(self.plant, Z[:, 0, None, None], np.ones((B, 1, 1)),
    ...                                    Z[:, 1, None, None], Z[:, 2, None, None])
    ...         return FamilyControllers(batch, np.ones(B, bool), np.full(B, "", object))
    >>> plant = rc.Plant([[1.2]], [[1.0]], 0.1, C=[[1.0]])
    >>> fam = FirstOrder(plant)
    >>> fam.gains(np.array([[0.5, 0.0, -0.6]])).controllers.is_stabilizing().tolist()
    [True]
    """

    n_var: int
    xl: np.ndarray
    xu: np.ndarray
    n_states: int
    n_inputs: int

    def gains(self, Z: np.ndarray) -> FamilyGains:
        """Gains of a population ``Z`` (B, n_var), failed designs flagged."""
        ...


def _input_map(input_map, plant: rc.Plant) -> tuple[np.ndarray | None, rc.Plant]:
    """The checked input map ``M`` (or None) and the design plant ``(F, G M)`` (``plant`` itself without one)."""
    if input_map is None:
        return None, plant
    M = as_matrix(input_map, "input_map", rows=plant.m, rows_what="the plant's number of inputs")
    return M, rc.Plant(plant.F, plant.G @ M, dt=plant.dt)


def bound_vector(value, name: str, default: np.ndarray) -> np.ndarray:
    if value is None:
        return default.copy()
    arr = as_float_array(value, name)
    if arr.ndim == 0:
        arr = np.full(default.size, float(arr))
    if arr.shape != default.shape:
        raise ValueError(f"{name} must be a scalar or have shape {default.shape} (one per variable), "
                         f"got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must have finite entries (found NaN or inf)")
    return arr


def check_bounds(xl: np.ndarray, xu: np.ndarray) -> None:
    """``ValueError`` naming ``xl``/``xu`` unless ``xl < xu`` everywhere."""
    bad = np.flatnonzero(~(xl < xu))
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"bounds inverted or empty: xl[{i}] = {xl[i]:g} must be < xu[{i}] = {xu[i]:g}")


def population(Z, n_var: int, name: str = "Z") -> np.ndarray:
    """``Z`` as a finite (B, n_var) float array (a single (n_var,) vector becomes B = 1)."""
    arr = as_float_array(Z, name)
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != n_var:
        raise ValueError(f"{name} must have shape (B, {n_var}) (one decision vector per row), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must have finite entries (found NaN or inf)")
    return arr


def _reasons(ok: np.ndarray, reason) -> np.ndarray:
    out = np.asarray(reason).astype(object)
    out[~ok & (out == "ok")] = "non-finite gain"
    out[ok] = ""
    return out


class RLQRFamily:
    r"""The paper's RLQR design family, for any plant size and uncertainty rank.

    A decision vector ``z`` is a candidate uncertainty model ``(E_F, E_G)``
    and penalty ``mu``; its gain is the steady-state robust LQR of that model
    (Notes). The gains of a whole population come from one call of
    :func:`robustctl.rlqr_gains`; designs it flags (rank condition, not
    converged, diverged) are flagged here too.

    Parameters
    ----------
    plant : robustctl.Plant
        Nominal discrete-time design model ``(F, G)`` (``n`` states, ``p`` inputs).
    H : (n, l) array_like, optional
        Uncertainty input; default ``ones((n, 1))`` (the paper's: one
        uncertainty row reaching every state; the ``repr`` says which). With a
        model fitted to the plants, its ``H`` (:meth:`robustctl.NormBounded.from_plants`)
        is the natural choice (user guide, "Choosing the robust LQR's mu, alpha and H").
    Q : (n, n) array_like, optional
        State weight, default identity.
    R : (m, m) array_like, optional
        Input weight of the design inputs, default identity.
    alpha : float
        RLQR's ``lambda = (1 + alpha) ||mu H^T H||`` margin.
    max_iter : int
        Steps of the plain recursion :func:`robustctl.rlqr_gains` may take for
        designs the doubling leaves unsettled; a design not converged by then
        is flagged (the MOEA then penalises it: slow designs cost much and are
        rarely useful).
    fallback : {"newton", "recursion"}
        :func:`robustctl.rlqr_gains`'s treatment of those designs.
    input_map : (p, m) array_like, optional
        Design on ``(F, G M)``, apply ``M K_d`` (see the module docstring).
    e_bound : float
        Default upper bound of every ``E_F``, ``E_G`` entry (lower bound 0): 100.
    log_mu_bound : float
        Default upper bound of ``(log10 mu)^2`` (lower bound 0): 100, i.e.
        ``mu`` in ``[1, 1e10]``.

    Attributes
    ----------
    n_var : int
        ``l (n + m) + 1``.
    xl, xu : (n_var,) ndarray
        Default bounds (``[0, e_bound]`` and ``[0, log_mu_bound]``).
    design_plant : robustctl.Plant
        ``(F, G M)`` (the plant itself without an input map).

    Raises
    ------
    TypeError, ValueError
        ``plant`` not a discrete-time :class:`robustctl.Plant`, or not
        stabilisable (with the input map); ``H``, ``Q``, ``R`` or
        ``input_map`` of the wrong shape (the message names it and the
        shapes); a non-positive ``alpha``, ``e_bound`` or ``log_mu_bound``;
        an unknown ``fallback``.

    See Also
    --------
    robustctl.rlqr_gains : the batched RLQR every population goes through.
    robustctl.rlqr : one RLQR design.
    LQRFamily : diagonal LQR weights as the decision vector.

    Notes
    -----
    With ``l`` the number of columns of ``H`` (``Delta`` is ``l x l``) and
    :math:`\operatorname{vec}_r` the entries row by row,

    .. math::

        z = \big(\operatorname{vec}_r E_F\ (l n),\ \operatorname{vec}_r E_G\ (l m),\
        (\log_{10}\mu)^2\big), \qquad
        K(z) = \text{steady-state RLQR of } (F, G M;\ H, E_F, E_G, \mu;\ Q, R),

    so :math:`\mu = 10^{\sqrt{z_{-1}}}`. With an ``input_map`` ``M`` the
    returned gain is :math:`M K_d`.

    References
    ----------
    .. [1] D. C. Morais et al., "Robust path-following control design of heavy
       vehicles based on multiobjective evolutionary optimization", Expert
       Systems with Applications 192 (2022) 116304, Section 3.1.

    Examples
    --------
    The gain of ``z = (E_F, E_G, (log10 mu)^2) = (0.1, 0.2, 0.05, 4)`` is the
    RLQR design of that model with ``mu = 100``:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import RLQRFamily
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> fam = RLQRFamily(plant)
    >>> fam.n_var                                   # l (n + m) + 1, l = 1
    4
    >>> fg = fam.gains(np.array([[0.1, 0.2, 0.05, 4.0]]))
    >>> ctrl = rc.rlqr(plant, [[0.1, 0.2]], [[0.05]], 100.0, H=np.ones((2, 1)))
    >>> bool(fg.ok[0]), np.allclose(fg.K[0], ctrl.K)
    (True, True)
    """

    def __init__(self, plant: rc.Plant, *, H=None, Q=None, R=None, alpha: float = 0.1, max_iter: int = 500,
                 fallback: Literal["newton", "recursion"] = "newton", input_map=None, e_bound: float = 100.0,
                 log_mu_bound: float = 100.0):
        plant = check_plant(plant, "plant", discrete_for="RLQRFamily")
        self.plant = plant
        self.input_map, self.design_plant = _input_map(input_map, plant)
        if not self.design_plant.is_stabilizable:
            raise ValueError("plant must be stabilisable (with the input map) for RLQRFamily")
        n, m = self.design_plant.n, self.design_plant.m
        self.H = np.ones((n, 1)) if H is None else as_matrix(H, "H", rows=n, rows_what="the number of states")
        self._H_given = H is not None
        self.l = self.H.shape[1]
        self.Q = np.eye(n) if Q is None else as_matrix(Q, "Q")
        self.R = np.eye(m) if R is None else as_matrix(R, "R")
        self.alpha = check_positive_scalar(alpha, "alpha")
        self.max_iter = check_int(max_iter, "max_iter", 1)
        self.fallback = fallback
        l = self.l
        rc.rlqr_gains(self.design_plant, np.zeros((1, l, n)), np.zeros((1, l, m)), np.ones(1), Q=self.Q, R=self.R,
                      H=self.H, alpha=self.alpha, max_iter=1, fallback=fallback)   # checks Q, R, H, alpha, fallback
        self.n_states, self.n_inputs = plant.n, plant.m
        self.n_var = l * (n + m) + 1
        e_bound = check_positive_scalar(e_bound, "e_bound")
        log_mu_bound = check_positive_scalar(log_mu_bound, "log_mu_bound")
        self.xl = np.zeros(self.n_var)
        self.xu = np.full(self.n_var, e_bound)
        self.xu[-1] = log_mu_bound

    def decode(self, Z) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(EF (B, l, n), EG (B, l, m), mu (B,))`` of a population ``Z`` (B, n_var) or one ``z``.

        ``mu = 10 ** sqrt(z[:, -1])``; ``(log10 mu)^2`` must be ``>= 0``.
        """
        z = population(Z, self.n_var, "Z")
        if np.any(z[:, -1] < 0):
            raise ValueError(f"the last variable of Z, (log10 mu)^2, must be >= 0, got {z[:, -1].min():g}")
        B, l = z.shape[0], self.l
        n, m = self.design_plant.n, self.design_plant.m
        EF = z[:, :l * n].reshape(B, l, n).copy()
        EG = z[:, l * n:l * (n + m)].reshape(B, l, m).copy()
        return EF, EG, 10.0 ** np.sqrt(z[:, -1])

    def design(self, Z) -> rc.RLQRBatch:
        """The batched RLQR designs (gains of the design inputs, no input map) of a population ``Z``."""
        EF, EG, mu = self.decode(Z)
        return rc.rlqr_gains(self.design_plant, EF, EG, mu, Q=self.Q, R=self.R, H=self.H, alpha=self.alpha,
                             max_iter=self.max_iter, fallback=self.fallback)

    def gains(self, Z) -> FamilyGains:
        """:class:`FamilyGains` of a population ``Z`` (B, n_var): ``M K_d`` (or ``K_d``), flags."""
        batch = self.design(Z)
        ok = np.asarray(batch.ok, dtype=bool) & np.all(np.isfinite(batch.K), axis=(1, 2))
        K = np.where(ok[:, None, None], batch.K, np.nan)
        if self.input_map is not None:
            K = self.input_map @ K
        reason = getattr(batch, "reason", None)
        return FamilyGains(K=K, ok=ok, reason=_reasons(ok, np.full(ok.shape, "failed") if reason is None else reason))

    def nominal(self) -> np.ndarray:
        """The gain with no uncertainty: the LQR of ``Q``, ``R`` on the design plant (through the input map)."""
        K = rc.lqr(self.design_plant, Q=self.Q, R=self.R).K
        assert K is not None                                 # lqr designs a state feedback
        return K if self.input_map is None else self.input_map @ K

    def __repr__(self) -> str:
        H = f"given ({self.H.shape[0]}x{self.l})" if self._H_given else f"ones(({self.H.shape[0]}, 1)), the default"
        return (f"RLQRFamily(n={self.design_plant.n}, m={self.design_plant.m}, l={self.l}, n_var={self.n_var}, H={H}, "
                f"input_map={'none' if self.input_map is None else self.input_map.shape})")


def dlqr_gains(F, G, Q, R, *, tol: float = 1e-12, max_iter: int = 100) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Discrete LQR gains of a stack of weights, by structure-preserving doubling (vectorised).

    For each ``b`` solves the DARE
    ``X = F^T X F - F^T X G (R_b + G^T X G)^{-1} G^T X F + Q_b`` with the
    doubling iteration (Chu et al. 2004): ``A_0 = F``, ``S_0 = G R_b^{-1} G^T``,
    ``X_0 = Q_b``,

    .. math::

        W_k = I + S_k X_k,\quad A_{k+1} = A_k W_k^{-1} A_k,\quad
        S_{k+1} = S_k + A_k W_k^{-1} S_k A_k^T,\quad
        X_{k+1} = X_k + A_k^T X_k W_k^{-1} A_k,

    which converges quadratically to the stabilising solution when ``(F, G)``
    is stabilisable and ``(Q_b^{1/2}, F)`` detectable; then
    ``K_b = -(R_b + G^T X G)^{-1} G^T X F`` (``u = K x``).

    Parameters
    ----------
    F, G : (n, n), (n, m) ndarray
    Q, R : (B, n, n), (B, m, m) ndarray
        Symmetric positive definite weights.
    tol : float
        Stop when ``||X_{k+1} - X_k||_F <= tol ||X_{k+1}||_F`` for every design.
    max_iter : int
        Doubling steps at most (each doubles the horizon).

    Returns
    -------
    K : (B, m, n) ndarray
        The gains, ``u = K x``.
    X : (B, n, n) ndarray
        The Riccati solutions.
    ok : (B,) bool ndarray
        Converged, finite, and ``F + G K`` Schur-stable; a design that is not
        (weights that are not finite, an ``R_b`` that is not positive definite,
        e.g. weights ``10**-400`` that underflow to 0, a singular step) is
        flagged here, never raised.

    See Also
    --------
    LQRFamily : the family built on it.
    scipy.linalg.solve_discrete_are : one DARE, by the Schur method.

    Notes
    -----
    The arguments are not checked (the families pass checked arrays).
    Vectorised over the designs, the doubling steps of a population cost a
    few batched ``(B, n, n)`` solves each, against one Schur decomposition
    per design for :func:`scipy.linalg.solve_discrete_are`.

    References
    ----------
    .. [1] E. K.-W. Chu, H.-Y. Fan, W.-W. Lin, C.-S. Wang, "Structure-preserving
       algorithms for periodic discrete-time algebraic Riccati equations",
       Int. J. Control 77(8) (2004) 767-788.

    Examples
    --------
    Two designs at once; the second Riccati solution satisfies the DARE as
    :func:`scipy.linalg.solve_discrete_are` computes it:

    >>> import numpy as np
    >>> from scipy.linalg import solve_discrete_are
    >>> from moo.tuning import dlqr_gains
    >>> F, G = np.array([[1.0, 0.1], [0.0, 1.0]]), np.array([[0.005], [0.1]])
    >>> Q = np.stack([np.eye(2), np.diag([1.0, 10.0])])
    >>> R = np.stack([np.eye(1), 0.1 * np.eye(1)])
    >>> K, X, ok = dlqr_gains(F, G, Q, R)
    >>> K.shape, ok
    ((2, 1, 2), array([ True,  True]))
    >>> np.allclose(X[1], solve_discrete_are(F, G, Q[1], R[1]))
    True
    """
    B, n = Q.shape[0], F.shape[0]
    eye, eye_m = np.eye(n), np.eye(G.shape[1])
    # weights that are not finite, or an R that is not positive definite (e.g. 10**-400 == 0): flagged, not solved
    with np.errstate(all="ignore"):
        good = np.isfinite(Q).all(axis=(1, 2)) & np.isfinite(R).all(axis=(1, 2))
        good[good] &= np.linalg.eigvalsh(0.5 * (R[good] + np.swapaxes(R[good], 1, 2)))[:, 0] > 0
    if not good.all():
        Q, R = np.where(good[:, None, None], Q, eye), np.where(good[:, None, None], R, eye_m)
    A = np.broadcast_to(F, (B, n, n)).copy()
    S, solved = _solve(R, np.broadcast_to(G.T, (B, *G.T.shape)))
    S = G @ S
    good &= solved
    X = Q.copy()
    done = ~good
    with np.errstate(all="ignore"):
        for _ in range(max_iter):
            act = np.flatnonzero(~done)
            a, s, x = A[act], S[act], X[act]
            W = eye + s @ x
            WA, ok_a = _solve(W, a)                           # W^{-1} A
            WS, ok_s = _solve(W, s)                           # W^{-1} S
            x_new = x + np.swapaxes(a, 1, 2) @ x @ WA
            step = np.linalg.norm(x_new - x, axis=(1, 2))
            A[act], S[act], X[act] = a @ WA, s + a @ WS @ np.swapaxes(a, 1, 2), x_new
            good[act[~(ok_a & ok_s)]] = False
            conv = ~(step > tol * np.linalg.norm(x_new, axis=(1, 2))) | ~(ok_a & ok_s)   # NaN: settled (flagged)
            done[act[conv]] = True
            if done.all():
                break
        X = 0.5 * (X + np.swapaxes(X, 1, 2))
        GX = G.T @ X                                          # (B, m, n)
        K, solved = _solve(R + GX @ G, GX @ F)
        K = -K
    ok = good & solved & done & np.all(np.isfinite(K), axis=(1, 2))
    ok[ok] = np.asarray(rc.is_schur_stable(F + G @ K[ok]), dtype=bool)
    return K, X, ok


def _solve(A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``A_b^{-1} B_b`` for stacks, and which designs were solved: a singular ``A_b`` is a NaN row, not an error."""
    try:
        return np.linalg.solve(A, B), np.ones(A.shape[0], dtype=bool)
    except np.linalg.LinAlgError:
        out = np.full(np.broadcast_shapes((*A.shape[:-1], B.shape[-1]), B.shape), np.nan)
        ok = np.zeros(A.shape[0], dtype=bool)
        for b in range(A.shape[0]):
            try:
                out[b] = np.linalg.solve(A[b], B[b])
                ok[b] = True
            except np.linalg.LinAlgError:
                pass
        return out, ok


class LQRFamily:
    r"""LQR designs of diagonal weights: ``z = (log10 diag Q (n), log10 diag R (m))``.

    All designs of a population are solved together (:func:`dlqr_gains`).
    The sign convention is ``u = K x`` (python-control's ``dlqr`` returns
    ``-K``).

    Parameters
    ----------
    plant : robustctl.Plant
        Discrete-time design model (must be stabilisable).
    input_map : (p, m) array_like, optional
        Design on ``(F, G M)``, apply ``M K_d``.
    log_bound : float
        Default bounds ``[-log_bound, log_bound]`` of every variable (default 4:
        weights from ``1e-4`` to ``1e4``).
    tol, max_iter
        Stopping rule of :func:`dlqr_gains` (relative step ``1e-12``, at most
        100 doubling steps).

    Attributes
    ----------
    n_var : int
        ``n + m``.
    xl, xu : (n_var,) ndarray
        Default bounds of ``z``.
    design_plant : robustctl.Plant
        ``(F, G M)`` (the plant itself without an input map).

    Raises
    ------
    TypeError, ValueError
        ``plant`` not a discrete-time :class:`robustctl.Plant`, an
        ``input_map`` of the wrong shape, a design plant that is not
        stabilisable, a non-positive ``log_bound`` or ``tol``.

    See Also
    --------
    dlqr_gains : the batched Riccati solver.
    robustctl.lqr : one LQR design.
    RLQRFamily : the paper's robust family.

    Notes
    -----
    .. math::

        K(z) = \text{DLQR}\big(F, G M;\ \operatorname{diag}(10^{z_{1..n}}),\
        \operatorname{diag}(10^{z_{n+1..n+m}})\big).

    Examples
    --------
    ``z = (0, 1, -1)`` is ``Q = diag(1, 10)``, ``R = 0.1``; the gain equals
    :func:`robustctl.lqr`'s:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import LQRFamily
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> fam = LQRFamily(plant)
    >>> fam.n_var, fam.xl, fam.xu
    (3, array([-4., -4., -4.]), array([4., 4., 4.]))
    >>> K = fam.gains(np.array([[0.0, 1.0, -1.0]])).K[0]
    >>> np.allclose(K, rc.lqr(plant, Q=np.diag([1.0, 10.0]), R=[[0.1]]).K)
    True
    """

    def __init__(self, plant: rc.Plant, *, input_map=None, log_bound: float = 4.0, tol: float = 1e-12,
                 max_iter: int = 100):
        plant = check_plant(plant, "plant", discrete_for="LQRFamily")
        self.plant = plant
        self.input_map, self.design_plant = _input_map(input_map, plant)
        if not self.design_plant.is_stabilizable:
            raise ValueError("plant must be stabilisable (with the input map) for LQRFamily")
        n, m = self.design_plant.n, self.design_plant.m
        self.n_states, self.n_inputs = plant.n, plant.m
        self.n_var = n + m
        b = check_positive_scalar(log_bound, "log_bound")
        self.xl, self.xu = np.full(self.n_var, -b), np.full(self.n_var, b)
        self.tol = check_positive_scalar(tol, "tol")
        self.max_iter = check_int(max_iter, "max_iter", 1)

    def weights(self, Z) -> tuple[np.ndarray, np.ndarray]:
        """``(Q (B, n, n), R (B, m, m))``, the diagonal weights of a population ``Z`` (``10**z``: may be 0 or inf)."""
        z = population(Z, self.n_var, "Z")
        n = self.design_plant.n
        with np.errstate(over="ignore"):
            w = 10.0 ** z
        return w[:, :n, None] * np.eye(n), w[:, n:, None] * np.eye(self.design_plant.m)

    def gains(self, Z) -> FamilyGains:
        """:class:`FamilyGains` of a population ``Z`` (B, n_var).

        A design whose weights ``10**z`` under- or overflow (0 or inf) is
        flagged (``reason``), as is one whose Riccati iteration does not converge.
        """
        Q, R = self.weights(Z)
        K, _, ok = dlqr_gains(self.design_plant.F, self.design_plant.G, Q, R, tol=self.tol, max_iter=self.max_iter)
        K = np.where(ok[:, None, None], K, np.nan)
        if self.input_map is not None:
            K = self.input_map @ K
        w = np.concatenate([np.diagonal(Q, axis1=1, axis2=2), np.diagonal(R, axis1=1, axis2=2)], axis=1)
        in_range = np.all(np.isfinite(w) & (w > 0), axis=1)
        reason = np.where(ok, "", np.where(in_range, "not converged", "weights under- or overflow"))
        return FamilyGains(K=K, ok=ok, reason=reason.astype(object))

    def __repr__(self) -> str:
        return f"LQRFamily(n={self.design_plant.n}, m={self.design_plant.m}, n_var={self.n_var})"
