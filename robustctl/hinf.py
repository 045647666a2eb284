r"""H-infinity state feedback by LMI optimisation (cvxpy + Clarabel).

Plant, with the gain ``u = K x`` (the paper's sign convention)::

    x+ = F x + Bw w + G u         (discrete, dt > 0; x' = ... for dt = None)
    z  = Cz x + Dzw w + Dzu u

The closed loop ``T_zw`` has ``A_K = F + G K``, ``C_K = Cz + Dzu K``. With the
change of variables ``Y = K X`` (Bernussou, Peres & Geromel 1989) the
bounded-real lemma becomes linear in ``(X, Y, mu)``, ``mu = gamma^2``.

Discrete time (``X > 0``; storage ``V(x) = x' X^-1 x``)::

    [ X      A X + G Y   Bw   0            ]
    [ *      X           0    (Cz X + Dzu Y)' ]  > 0
    [ *      *           I    Dzw'         ]
    [ *      *           *    mu I         ]

Continuous time::

    [ He(F X + G Y)   Bw    (Cz X + Dzu Y)' ]
    [ *               -I    Dzw'            ]  < 0,   He(M) = M + M'
    [ *               *     -mu I           ]

Either inequality says ``V(x+) - V(x) <= |w|^2 - |z|^2 / gamma^2`` (or
``dV/dt <= ...``), hence ``||T_zw||_inf < gamma`` and internal stability.
This is the *gamma^2 form*: the same ``X`` bounds the reachable set,
``x' X^-1 x <= E`` for every disturbance of energy ``sum |w|^2 <= E``
(Boyd, El Ghaoui, Feron & Balakrishnan 1994, Sec. 6.1.3), so
``|u_j| = |k_j x| <= u_max_j`` holds whenever (Sec. 7.2.3)::

    [ u_max_j^2 / E   y_j ]
    [ y_j'            X   ]  >= 0       (y_j: row j of Y).

Polytopic plants: the LMI is imposed at every vertex ``(F_i, G_i)`` with one
common ``(X, Y)``; it is affine in ``(F, G)``, so the gain is guaranteed for
every plant in the convex hull (even time-varying). The *extended* (slack
variable) discrete-time condition of de Oliveira, Bernussou & Geromel (1999)
and de Oliveira, Geromel & Bernussou (2002) uses a vertex-dependent ``P_i``
and a common slack ``S`` (not symmetric), ``K = L S^-1``::

    [ P_i    F_i S + G_i L   Bw   0               ]
    [ *      S + S' - P_i    0    (Cz S + Dzu L)' ]  > 0
    [ *      *               I    Dzw'            ]
    [ *      *               *    mu I            ]

It reduces to the standard one for ``S = P_i = X`` (never more
conservative) and guarantees the bound for every *constant* plant of the
hull (storage ``x' P(a)^-1 x`` with ``P(a) = sum a_i P_i``). The input bound
then uses ``[[u_max_j^2/E, l_j], [l_j', S + S' - P_i]] >= 0`` at each vertex
(``S + S' - P <= S' P^-1 S``).

Numerics
--------
* Data normalisation (levels and input bounds are unchanged up to recorded
  factors): states balanced by a diagonal similarity (SLICOT ``TB01ID`` on
  ``[[F, [Bw G]], [Cz, 0]]``) and scaled so that ``||Bw|| = 1``; ``w``
  scaled to unit energy when ``u_max`` is given; ``z`` scaled so that the
  fixed level of the centring problem is 1; ``[Cz Dzu Dzw]`` replaced by a
  factor with the same Gram matrix when that has fewer rows.
* The constant disturbance block ``I`` is eliminated by a Schur complement
  (e.g. the discrete block becomes ``[[X - Bw Bw', A X + G Y, -Bw Dzw'], [*,
  X, (Cz X + Dzu Y)'], [*, *, mu I - Dzw Dzw']] >= 0``): same set, ``q``
  rows smaller.
* A single plant is solved in coordinates where the inverse of its LQR
  Riccati solution (weight ``[Cz Dzu]'[Cz Dzu]``) is ~ I: the optimal ``X``
  has roughly that shape, so the optimum is well conditioned (on the
  benchmark plants with n = 10: 13-16 interior-point iterations instead of
  ~27 ending ``optimal_inaccurate``). If that solve fails the balanced
  coordinates are used.
* ``gamma_opt`` comes from minimising ``mu`` (non-strict LMIs: the
  infimum): in the LQR coordinates of one plant at tolerance 1e-8, first
  without Clarabel's iterative refinement (see
  :func:`robustctl._cvx.solve_sdp`); otherwise at 1e-10 with refinement
  (the truck polytope is badly conditioned). If the solver reports
  ``optimal_inaccurate`` the problem is solved again in coordinates where
  the optimal ``X`` is ~ I (a similarity) and the lower certified level is
  kept.
* At the optimum ``X`` can be nearly singular and ``K = Y X^-1`` huge (in
  continuous time the optimum is often reached only as ``|K| -> inf``).
  Therefore, unless ``backoff=0``, the gain is certified at the fixed level
  ``gamma = (1 + backoff) gamma_opt``:

  - discrete time, one plant, standard LMI: the optimum's own gain ``K``
    (finite there) is kept if a strictly feasible ``(X, K X)`` at that level
    exists; ``X`` is built from a Riccati equation of the closed loop and
    accepted only on the eigenvalues of every block
    (:meth:`_Problem.certify_at_level`; no second solve);
  - otherwise (or if that fails) a second problem at the fixed level
    maximises the smallest eigenvalue ``t`` of every LMI block (a
    well-centred strictly feasible point). If that fails or its
    certificate is not strictly positive, two variants are tried (maximise
    ``lambda_min(X)`` under ``X <= 10 lambda_max(X_opt)``, in the balanced
    and in the recentred coordinates), then a tenfold backoff (at most
    twice). ``info["gain_from"]`` names the route.
* Every solve goes through :func:`robustctl._cvx.solve_sdp`: status check,
  explicit symmetrisation, certificate eigenvalues; solver failures are
  retried with looser tolerances, the certificate is checked regardless.
* A fixed ``gamma`` is a feasibility problem posed as "maximise the common
  margin ``t <= 1``" (always feasible); ``t <= 0`` means infeasible.

References
----------
S. Boyd, L. El Ghaoui, E. Feron, V. Balakrishnan, *Linear Matrix Inequalities
in System and Control Theory*, SIAM 1994, Sec. 6.1.3, 7.2.3, 7.5.
M. C. de Oliveira, J. Bernussou, J. C. Geromel, "A new discrete-time robust
stability condition", Systems & Control Letters 37, 1999.
M. C. de Oliveira, J. C. Geromel, J. Bernussou, "Extended H2 and H-infinity
norm characterizations and controller parametrizations for discrete-time
systems", Int. J. Control 75(9), 2002.
P. Gahinet, P. Apkarian, "A linear matrix inequality approach to
H-infinity control", Int. J. Robust Nonlinear Control 4, 1994.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike

from . import _cvx
from ._validation import check_performance, check_positive_scalar
from .controller import Controller
from .errors import ConvergenceError, InfeasibleError
from .plant import Plant

__all__ = ["hinf", "HinfController"]

# Smallest acceptable strictness (centring) margin t of the gain-extraction
# problem, whose data are normalised (||Bw~|| = 1, level 1, unit energy).
# The gamma minimisation uses the non-strict LMIs: it computes an infimum.
_STRICT = 1e-8
# Regularisation (relative to lambda_max) of the optimal X before it defines
# the coordinates of the centring problem.
_RECENTRE_REG = 1e-3
# The same for polishing an inaccurate gamma minimisation (a pure similarity).
_POLISH_REG = 1e-6
# Upper bound of X in the centring problem, relative to lambda_max of the optimal X.
_X_UPPER = 10.0
# Solver tolerance of the gamma minimisation: 1e-8 in the LQR coordinates of
# one plant (gamma_opt then agrees with the Riccati bisection to ~1e-8
# relative, and the first attempt skips iterative refinement); 1e-10
# otherwise (several vertices, e.g. the truck polytope with an input bound,
# are badly conditioned: a looser first solve there ends 1e-3 above the level
# that the tighter one and its polish reach).
_MIN_TOL = 1e-8
_MIN_TOL_GENERAL = 1e-10
# Solver tolerance of the centring problem (its optimum need not be exact).
_CENTRE_TOL = 1e-7
# u-bound LMIs use u_max^2 (1 - _U_SLACK) / E so that solver rounding cannot
# exceed u_max (the bound is conservative by 0.005 %).
_U_SLACK = 1e-4
# backoff=0: eigenvalues of the optimal X (solver coordinates) below this
# fraction of lambda_max(X) are below the accuracy of the level minimisation
# (_MIN_TOL) and are raised to it before K = Y X^-1 (see _Problem.gain).
_OPTIMUM_X_FLOOR = 1e-8


@dataclass(frozen=True, eq=False, repr=False)
class HinfController(Controller):
    """An H-infinity state feedback ``u = K x`` with its guaranteed level.

    Attributes
    ----------
    gamma : float
        Level guaranteed by the returned gain: ``||T_zw||_inf < gamma`` for
        the plant (and every plant of the hull of ``vertices``). Equals
        ``(1 + backoff) * gamma_opt``, or the requested ``gamma``.
    gamma_opt : float or None
        The optimal level of the LMI problem (``None`` when ``gamma`` was fixed).
    """

    gamma: float = float("nan")
    gamma_opt: float | None = None

    def __repr__(self) -> str:
        opt = "None" if self.gamma_opt is None else f"{self.gamma_opt:.6g}"
        base = super().__repr__()
        return base.replace("Controller(", f"HinfController(gamma={self.gamma:.6g}, gamma_opt={opt}, ", 1)


# ---------------------------------------------------------------- validation
def _vertices(plant: Plant, vertices) -> list[Plant]:
    plants = [plant]
    if vertices is None:
        return plants
    if isinstance(vertices, Plant) or not isinstance(vertices, Sequence):
        raise TypeError("vertices must be a list of robustctl.Plant")
    for i, v in enumerate(vertices):
        if not isinstance(v, Plant):
            raise TypeError(f"vertices[{i}] must be a robustctl.Plant, got {type(v).__name__}")
        if (v.n, v.m) != (plant.n, plant.m):
            raise ValueError(f"vertices[{i}] must have n={plant.n} states and m={plant.m} inputs like plant, "
                             f"got n={v.n}, m={v.m}")
        if v.dt != plant.dt:
            raise ValueError(f"vertices[{i}] must have the sampling time of plant (dt={plant.dt}), got dt={v.dt}")
        plants.append(v)
    return plants


def _u_max(u_max, m: int) -> np.ndarray:
    if isinstance(u_max, (str, bytes)):
        raise TypeError(f"u_max must be a positive number or {m} positive numbers, got {type(u_max).__name__}")
    try:
        arr = np.array(u_max, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"u_max must be a positive number or {m} positive numbers") from None
    if arr.ndim == 0:
        arr = np.full(m, float(arr))
    if arr.shape != (m,):
        raise ValueError(f"u_max must be a scalar or have {m} {'entry' if m == 1 else 'entries'} "
                         f"(the number of inputs), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError("u_max must be finite (use u_max=None for no input bound)")
    if np.any(arr <= 0):
        raise ValueError(f"u_max must be > 0 for every input, got {arr.tolist()}")
    return arr


def _check_stabilisable(plants: list[Plant]) -> None:
    """PBH test at every unstable eigenvalue of every vertex; plain-English error if it fails."""
    for i, p in enumerate(plants):
        F, G = p.F, p.G
        n = p.n
        scale = max(1.0, np.linalg.norm(np.hstack([F, G]), 2))
        for lam in np.linalg.eigvals(F):
            unstable = abs(lam) >= 1.0 - 1e-12 if p.is_discrete else lam.real >= -1e-12 * scale
            if not unstable:
                continue
            smin = np.linalg.svd(np.hstack([F - lam * np.eye(n), G]), compute_uv=False)[-1]
            if smin <= 1e-9 * scale:
                where = "plant" if i == 0 else f"vertices[{i - 1}]"
                kind = "|lambda| >= 1" if p.is_discrete else "Re(lambda) >= 0"
                raise InfeasibleError(
                    f"{where} is not stabilisable: its mode lambda = {complex(lam):.6g} ({kind}) cannot be moved "
                    "by the input G (PBH rank test), so no gain u = K x makes the loop stable and no finite "
                    "gamma exists")


# ---------------------------------------------------------------- scaling
def _balance(F, Bw, G, Cz) -> np.ndarray:
    """Diagonal state scaling ``d`` (x = diag(d) x~) balancing ``[[F, [Bw G]], [Cz, 0]]``."""
    n = F.shape[0]
    B = np.hstack([Bw, G])
    try:
        from slycot import tb01id

        _, _, _, _, d = tb01id(n, B.shape[1], Cz.shape[0], 0.0, F.copy(), B.copy(), Cz.copy(), job="A")
        d = np.asarray(d, dtype=float)
    except Exception:  # slycot missing or failed: no scaling
        return np.ones(n)
    if d.shape != (n,) or not np.all(np.isfinite(d)) or np.any(d <= 0):
        return np.ones(n)
    # TB01ID returns D with A~ = D^-1 A D, i.e. x = D x~.
    return d


# ---------------------------------------------------------------- LMIs
class _Value:
    """Stands in for a cvxpy variable holding ``value`` (for :meth:`_Problem.recentre`)."""

    def __init__(self, value):
        self.value = value


def _strict(certificate) -> bool:
    """Every H-infinity block and the Lyapunov (slack) matrix strictly positive definite."""
    return all(v > 0 for k, v in certificate.items() if k.startswith(("hinf", "X", "S")) and k != "X_upper")


class _Problem:
    """The scaled data and the LMI builders for one synthesis.

    Scaling (the H-infinity level and the input bound are unchanged up to the
    recorded factors): ``x = diag(d) x~`` (balancing, then one scalar so that
    ``||Bw~||_2 = 1``), ``w = a w~`` with ``a = sqrt(w_energy)`` when an input
    bound is given (the bound then reads for unit energy), and ``z~ = b z``
    with ``b`` chosen per solve (``b = 1 / (a gamma)`` at a fixed level, so
    that the scaled level is 1). The scaled level is ``a b gamma``.
    """

    def __init__(self, plants, Bw, Cz, Dzu, Dzw, extended, u_max, w_energy):
        import cvxpy as cp

        self.cp = cp
        self.discrete = plants[0].is_discrete
        d = _balance(plants[0].F, Bw, plants[0].G, Cz)
        self.a = float(np.sqrt(w_energy)) if u_max is not None else 1.0
        bw = np.linalg.norm(Bw / d[:, None] * self.a, 2)
        if bw > 0 and np.isfinite(bw):
            d = d * bw
        self.d = d
        # Only z'z matters: replace [Cz Dzu Dzw] by a full-row-rank factor R
        # with R'R = [Cz Dzu Dzw]'[Cz Dzu Dzw] when that has fewer rows.
        n, m = Cz.shape[1], Dzu.shape[1]
        CD = np.hstack([Cz, Dzu, Dzw])
        _, sv, Vt = np.linalg.svd(CD, full_matrices=False)
        r = int(np.sum(sv > 1e-13 * max(1.0, sv[0] if sv.size else 0.0)))
        if 0 < r < CD.shape[0]:
            CD = sv[:r, None] * Vt[:r]
            Cz, Dzu, Dzw = CD[:, :n], CD[:, n:n + m], CD[:, n + m:]
        self._orig = ([p.F for p in plants], [p.G for p in plants], Bw * self.a, Cz)
        self.Dzu, self.Dzw = Dzu, Dzw * self.a
        self._transform(np.diag(d))
        self.n, self.m = plants[0].n, plants[0].m
        self.p, self.q = Cz.shape[0], Bw.shape[1]  # p after compression
        self.extended = extended
        self.u_max = u_max

    def _transform(self, T: np.ndarray) -> None:
        """Use the state coordinates ``x = T x^`` for the LMI data."""
        Fs, Gs, Bw, Cz = self._orig
        self.T = T
        self.F = [np.linalg.solve(T, F @ T) for F in Fs]
        self.G = [np.linalg.solve(T, G) for G in Gs]
        self.Bw = np.linalg.solve(T, Bw)
        self.Cz = Cz @ T

    def precondition(self) -> bool:
        """Coordinates in which the LQR storage of the nominal vertex is ~ I.

        The optimal Lyapunov matrix ``X`` has roughly the shape of ``P^-1``,
        ``P`` the stabilising Riccati solution of the LQR problem with the
        weight ``[Cz Dzu]'[Cz Dzu]`` (both diagonal blocks regularised by
        ``1e-9`` of their norm). In coordinates where ``P^-1 ~ I`` (then
        scaled so that ``||Bw|| = 1`` again) the optimum is usually well
        conditioned: fewer interior-point iterations, rarely
        ``optimal_inaccurate``. A similarity: levels and input bounds are
        unchanged. Returns ``False`` (coordinates unchanged) if the Riccati
        solve fails.
        """
        import scipy.linalg

        F, G, C, D = self.F[0], self.G[0], self.Cz, self.Dzu
        Q, R, S = C.T @ C, D.T @ D, C.T @ D
        Q = Q + 1e-9 * max(1.0, np.linalg.norm(Q, 2)) * np.eye(self.n)
        R = R + 1e-9 * max(1.0, np.linalg.norm(R, 2)) * np.eye(self.m)
        care = scipy.linalg.solve_discrete_are if self.discrete else scipy.linalg.solve_continuous_are
        try:
            with np.errstate(all="ignore"):
                P = care(F, G, Q, R, s=S)
            lam = np.linalg.eigvalsh(0.5 * (P + P.T))
        except (ValueError, np.linalg.LinAlgError):
            return False
        if not (np.all(np.isfinite(lam)) and lam[-1] > 0):
            return False
        X = np.linalg.inv(0.5 * (P + P.T) + max(0.0, _RECENTRE_REG * lam[-1] - lam[0]) * np.eye(self.n))
        T = self.T
        if not np.isfinite(self.recentre({"S": _Value(X), "X": _Value(X)}, _RECENTRE_REG)):
            return False
        bw = np.linalg.norm(self.Bw, 2)
        if not (bw > 0 and np.isfinite(bw)):
            self._transform(T)
            return False
        self._transform(self.T * bw)
        return True

    def recentre(self, V, reg: float) -> float:
        """Change coordinates so that the Lyapunov matrix of a previous solution becomes ~ I.

        With ``X + reg lambda_max(X) I = R R'`` (Cholesky; ``X`` the previous
        solution, ``S`` for the extended LMI) the new coordinates are
        ``x^ = R^-1 x~``: a similarity, so levels and input bounds are
        unchanged, but margins of the next solve are measured relative to the
        solution's own shape. Returns ``lambda_max`` of the previous solution
        in the new coordinates (<= 1), or ``nan`` if it was unusable.
        """
        if self.extended:
            Sv = V["S"].value
            X = 0.5 * (Sv + Sv.T)
        else:
            X = 0.5 * (V["X"].value + V["X"].value.T)
        lam = np.linalg.eigvalsh(X)
        if not (np.all(np.isfinite(lam)) and lam[-1] > 0):
            return float("nan")
        Xr = X + max(0.0, reg * lam[-1] - lam[0]) * np.eye(self.n)
        try:
            R = np.linalg.cholesky(Xr)
        except np.linalg.LinAlgError:
            return float("nan")
        self._transform(self.T @ R)
        Xh = np.linalg.solve(R, np.linalg.solve(R, X).T)
        return float(np.linalg.eigvalsh(0.5 * (Xh + Xh.T))[-1])

    def variables(self):
        cp = self.cp
        n, m = self.n, self.m
        if self.extended:
            V = {"P": [cp.Variable((n, n), symmetric=True, name=f"P{i}") for i in range(len(self.F))],
                 "S": cp.Variable((n, n), name="S"), "L": cp.Variable((m, n), name="L")}
        else:
            V = {"X": cp.Variable((n, n), symmetric=True, name="X"), "Y": cp.Variable((m, n), name="Y")}
        return V

    def lmis(self, V, mu, margin, b: float = 1.0, x_margin=None, x_upper: float | None = None) -> list:
        """LMI blocks at scaled level ``mu`` (``= (a b gamma)^2``), output scaling ``b``.

        ``margin`` applies to the H-infinity blocks. With ``x_margin`` the
        Lyapunov (or slack) matrix must also satisfy ``X >= x_margin I`` and
        ``X <= x_upper I``.
        """
        cp = self.cp
        p = self.p
        Ip = np.eye(p)
        Cz, Dzu, Dzw = b * self.Cz, b * self.Dzu, b * self.Dzw
        # The disturbance block (the constant I) is eliminated by a Schur
        # complement, which keeps the LMIs linear and q rows smaller:
        Bw = self.Bw
        BB, BD, DD = Bw @ Bw.T, Bw @ Dzw.T, Dzw @ Dzw.T
        out = []
        for i, (F, G) in enumerate(zip(self.F, self.G)):
            if self.extended:
                P, S, L = V["P"][i], V["S"], V["L"]
                AS = F @ S + G @ L
                CS = Cz @ S + Dzu @ L
                M = cp.bmat([
                    [P - BB, AS, -BD],
                    [AS.T, S + S.T - P, CS.T],
                    [-BD.T, CS, mu * Ip - DD]])
            elif self.discrete:
                X, Y = V["X"], V["Y"]
                AX = F @ X + G @ Y
                CX = Cz @ X + Dzu @ Y
                M = cp.bmat([
                    [X - BB, AX, -BD],
                    [AX.T, X, CX.T],
                    [-BD.T, CX, mu * Ip - DD]])
            else:
                X, Y = V["X"], V["Y"]
                AX = F @ X + G @ Y
                CX = Cz @ X + Dzu @ Y
                # -(continuous BRL) >= 0
                M = cp.bmat([
                    [-(AX + AX.T) - BB, -CX.T - BD],
                    [-CX - BD.T, mu * Ip - DD]])
            out.append(_cvx.LMI(f"hinf[{i}]", M, margin))
        if x_margin is not None:
            n_eye = np.eye(self.n)
            if self.extended:
                out.append(_cvx.LMI("S", 0.5 * (V["S"] + V["S"].T), x_margin))
                out += [_cvx.LMI(f"P_upper[{i}]", x_upper * n_eye - P) for i, P in enumerate(V["P"])]
            else:
                out.append(_cvx.LMI("X", V["X"], x_margin))
                out.append(_cvx.LMI("X_upper", x_upper * n_eye - V["X"]))
        elif not self.discrete:
            out.append(_cvx.LMI("X", V["X"], margin))
        if self.u_max is not None:
            for j, umax in enumerate(self.u_max):
                c = np.array([[umax**2 * (1.0 - _U_SLACK)]])  # unit energy after scaling w
                if self.extended:
                    for i, P in enumerate(V["P"]):
                        S, L = V["S"], V["L"]
                        M = cp.bmat([[c, L[j:j + 1, :]], [L[j:j + 1, :].T, S + S.T - P]])
                        out.append(_cvx.LMI(f"u_max[{j}][{i}]", M, 0.0))
                else:
                    M = cp.bmat([[c, V["Y"][j:j + 1, :]], [V["Y"][j:j + 1, :].T, V["X"]]])
                    out.append(_cvx.LMI(f"u_max[{j}]", M, 0.0))
        return out

    def certify_at_level(self, V, b: float, backoff: float):
        """A strictly feasible ``(X, Y = K X)`` at scaled level 1 for the optimum's gain ``K``, or ``None``.

        Discrete time, one vertex, standard LMI. With ``K = Y X^-1`` from the
        optimal point and ``(A, B, C, D) = (F + G K, Bw, b (Cz + Dzu K), b Dzw)``
        the Schur complement of the H-infinity block with respect to its
        last two block rows is ``X - A X A' - B B' - (A X C' + B D')
        (I - C X C' - D D')^-1 (.)'``; the stabilising solution of the
        Riccati equation setting it to ``eps I`` (``scipy.linalg.
        solve_discrete_are`` with the indefinite weight ``D D' - I``) makes
        every block strictly positive when ``||T_zw(K)||_inf`` is below the
        level. ``eps`` is tried at ``1e-2`` and ``1e-1`` times ``backoff``
        (the data are normalised). A point is accepted only if the smallest
        eigenvalue of *every* LMI block (input bounds included) evaluated at
        it exceeds ``_STRICT``: the certificate does not rely on the Riccati
        solver. Returns ``(V, certificate, t)``, ``t`` the smallest
        eigenvalue of the H-infinity block.
        """
        import scipy.linalg

        cp = self.cp
        Xo, Yo = V["X"].value, V["Y"].value
        K = np.linalg.solve(0.5 * (Xo + Xo.T), Yo.T).T
        A = self.F[0] + self.G[0] @ K
        B, C, D = self.Bw, b * (self.Cz + self.Dzu @ K), b * self.Dzw
        for eps in (1e-2 * backoff, 1e-1 * backoff):
            try:
                with np.errstate(all="ignore"):
                    X = scipy.linalg.solve_discrete_are(A.T, C.T, B @ B.T + eps * np.eye(self.n),
                                                        D @ D.T - np.eye(self.p), s=B @ D.T)
            except (ValueError, np.linalg.LinAlgError):
                continue
            if not np.all(np.isfinite(X)):
                continue
            X = 0.5 * (X + X.T)
            cert = {}
            for lmi in self.lmis({"X": cp.Constant(X), "Y": cp.Constant(K @ X)}, 1.0, 0.0, b=b):
                M = np.asarray(lmi.M.value, dtype=float)
                cert[lmi.name] = float(np.linalg.eigvalsh(0.5 * (M + M.T))[0])
            if min(cert.values()) > _STRICT:
                return {"X": _Value(X), "Y": _Value(K @ X)}, cert, cert["hinf[0]"]
        return None

    def gain(self, V, x_floor: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """``(K, X)`` in the original coordinates (``X``: Lyapunov matrix of the nominal vertex).

        With ``x_floor > 0`` (standard LMI) the eigenvalues of ``X`` below
        ``x_floor * lambda_max(X)`` are raised to that value first. At a
        singular optimum (continuous time, reached only as ``|K| -> inf``)
        the smallest eigenvalue of the solver's ``X`` is rounding noise of
        either sign, and its sign decides the direction of the unbounded part
        of ``K = Y X^-1``: a negative one gives a destabilising gain. The
        floor makes ``K`` the member of the optimal family with ``X > 0``,
        independent of the last bits; a well-conditioned ``X`` is unchanged.
        """
        if self.extended:
            S, L = V["S"].value, V["L"].value
            Ks = np.linalg.solve(S.T, L.T).T
            Xs = V["P"][0].value
        else:
            Xs, Y = V["X"].value, V["Y"].value
            Xs = 0.5 * (Xs + Xs.T)
            if x_floor > 0:
                lam, U = np.linalg.eigh(Xs)
                Xs = (U * np.maximum(lam, x_floor * lam[-1])) @ U.T
            Ks = np.linalg.solve(Xs, Y.T).T
        T = self.T
        return np.linalg.solve(T.T, Ks.T).T, T @ Xs @ T.T


# ---------------------------------------------------------------- public
def hinf(plant: Plant, *, Bw: ArrayLike, Cz: ArrayLike, Dzu: ArrayLike, Dzw: ArrayLike | None = None,
         vertices: Sequence[Plant] | None = None, gamma: float | None = None, u_max: ArrayLike | None = None,
         w_energy: float | None = None, backoff: float = 1e-3, extended: bool = False,
         solver: str = "CLARABEL") -> HinfController:
    r"""H-infinity state feedback ``u = K x`` by LMI optimisation.

    Finds ``K`` minimising ``gamma`` such that ``||T_zw||_inf < gamma`` for

    ``x+ = F x + Bw w + G u``, ``z = Cz x + Dzw w + Dzu u`` (discrete plant) or
    ``x' = F x + Bw w + G u`` (continuous plant, ``plant.dt is None``; ``F``,
    ``G`` are then ``A``, ``B``). The LMIs are given in the module docstring.

    Parameters
    ----------
    plant : Plant
        The nominal plant ``(F, G)``.
    Bw : (n, q) array_like
        Disturbance input matrix.
    Cz : (p, n) array_like
        Performance output matrix.
    Dzu : (p, m) array_like
        Feedthrough from ``u`` to ``z``. With ``Dzu`` not of full column rank
        the optimum may need an unbounded gain (the backoff then matters).
    Dzw : (p, q) array_like, optional
        Feedthrough from ``w`` to ``z`` (default zero).
    vertices : list of Plant, optional
        Further plants (same ``n``, ``m``, ``dt``). The bound then holds for
        every plant in the convex hull of ``[plant] + vertices``.
    gamma : float, optional
        Fixed level: solve the feasibility problem at this ``gamma`` (no
        minimisation). Raises :class:`~robustctl.errors.InfeasibleError`
        naming ``gamma`` if no gain achieves it.
    u_max : float or (m,) array_like, optional
        Bound on each ``|u_j|``, guaranteed (from ``x0 = 0``) for every
        disturbance with ``sum_k |w_k|^2 <= w_energy`` (continuous time:
        ``int |w|^2 dt <= w_energy``). Uses the reachable-set ellipsoid of
        the same Lyapunov matrix, so ``gamma_opt`` is then the best level
        *subject to* the bound.
    w_energy : float, optional
        Disturbance energy for ``u_max`` (default 1). Only valid with ``u_max``.
    backoff : float, default 1e-3
        The gain is computed at ``gamma = (1 + backoff) gamma_opt`` from a
        well-centred strictly feasible point. ``0`` returns the optimal
        point's gain (can be badly conditioned; eigenvalues of ``X`` below
        ``1e-8 lambda_max(X)``, the accuracy of the minimisation, are raised
        to that floor first, so that a singular optimum gives a stabilising,
        reproducible gain). If no strictly feasible point
        with a positive certificate is found at that level (nearly infeasible
        problems, e.g. a tight ``u_max``), the backoff is raised tenfold, at
        most twice; ``info["backoff"]`` and ``gamma`` report the value used.
    extended : bool, default False
        Use the slack-variable condition of de Oliveira et al. (discrete time
        only): less conservative with ``vertices``, equal without.
    solver : str, default "CLARABEL"
        cvxpy SDP solver. Clarabel is run with explicit tolerances (1e-8 for
        the level of one plant, 1e-10 with vertices, 1e-7 for centring);
        other solvers use their defaults and may not reach 1e-5 accuracy.

    Returns
    -------
    HinfController
        ``K`` (``u = K x``), ``gamma``, ``gamma_opt`` and ``info`` with
        ``status``, ``solve_time`` (s, summed over solves), ``iterations``,
        ``certificate`` (smallest eigenvalue of each LMI block at the
        returned point), ``gain_from`` (``"optimum-certified"``,
        ``"optimum"`` for ``backoff=0``, or the centring variant),
        ``X_min_eig``, ``margin`` (centring margin ``t``), ``solves``
        (per-solve diagnostics), ``X`` (Lyapunov matrix; ``P`` of the
        nominal vertex when ``extended``), ``u_bound`` (guaranteed
        ``max |u_j|`` for ``w_energy``, when ``u_max`` is given),
        ``scaling`` (state balancing), ``lmi``, ``vertices`` and ``backoff``
        (the value used). Each entry of ``solves`` has the solver's
        ``status``, ``value``, ``tol``, ``solve_time``, ``iterations`` and
        ``certificate``; centring solves also name their ``centring`` variant.

    Raises
    ------
    InfeasibleError
        A vertex is not stabilisable, the fixed ``gamma`` or the input bound
        cannot be met, or no common Lyapunov matrix exists for the vertices.
    ValueError, TypeError
        Bad arguments (named in the message).

    Examples
    --------
    >>> ctrl = rc.design("hinf", plant, Bw=Bw, Cz=Cz, Dzu=Dzu)   # doctest: +SKIP
    >>> ctrl.gamma, ctrl.info["gamma_opt"]                       # doctest: +SKIP
    """
    if not isinstance(plant, Plant):
        raise TypeError(f"plant must be a robustctl.Plant, got {type(plant).__name__}")
    plants = _vertices(plant, vertices)
    Bw, Cz, Dzu, Dzw = check_performance(plant.n, plant.m, Bw, Cz, Dzu, Dzw)
    if gamma is not None:
        gamma = check_positive_scalar(gamma, "gamma")
    if u_max is not None:
        u_max = _u_max(u_max, plant.m)
        w_energy = 1.0 if w_energy is None else check_positive_scalar(w_energy, "w_energy")
    elif w_energy is not None:
        raise ValueError("w_energy is only used together with u_max; give u_max or drop w_energy")
    if isinstance(backoff, bool) or not isinstance(backoff, numbers.Real) or not np.isfinite(backoff) \
            or backoff < 0:
        raise ValueError(f"backoff must be a finite number >= 0, got {backoff!r}")
    if not isinstance(extended, (bool, np.bool_)):
        raise TypeError(f"extended must be a bool, got {type(extended).__name__}")
    if extended and not plant.is_discrete:
        raise ValueError("extended=True is the discrete-time slack-variable LMI; plant is continuous-time (dt=None)")
    solver = _cvx.check_solver(solver)
    _check_stabilisable(plants)

    import cvxpy as cp

    prob = _Problem(plants, Bw, Cz, Dzu, Dzw, bool(extended), u_max, w_energy)
    T_bal = prob.T
    preconditioned = len(plants) == 1 and prob.precondition()
    if len(plants) == 1:
        what = "no stabilising gain satisfies the H-infinity LMI"
    else:
        what = (f"no common {'slack matrix' if extended else 'Lyapunov matrix'} and gain satisfy the "
                f"H-infinity LMI at all {len(plants)} vertices" + ("" if extended else " (try extended=True)"))
    if u_max is not None:
        what += (f" together with |u_j| <= u_max = {u_max.tolist()} for every disturbance of energy "
                 f"{w_energy:g} (the input bound may be too tight for this disturbance energy)")
    solves = []

    b_min = 1.0  # output scaling of the minimisation: level (a b gamma)^2 = mu

    def minimise():
        V = prob.variables()
        mu = cp.Variable(name="mu")
        rep = _cvx.solve_sdp(cp.Minimize(mu), prob.lmis(V, mu, 0.0, b=b_min), solver=solver,
                             tol=_MIN_TOL if preconditioned else _MIN_TOL_GENERAL,
                             infeasible_msg=f"no H-infinity state feedback: {what}", fast=preconditioned)
        return V, mu, rep

    # 1. minimise mu = gamma^2 (scaled level a * gamma)
    gamma_opt = None
    if gamma is None:
        try:
            try:
                V, mu, rep = minimise()
            except ConvergenceError:
                if not preconditioned:
                    raise
                prob._transform(T_bal)  # the LQR coordinates may not suit this problem
                preconditioned = False
                V, mu, rep = minimise()
        except ConvergenceError:
            if not extended:
                raise
            # The slack-variable problem is numerically harder near the edge of
            # feasibility: solve the standard one (feasible => the extended one
            # is too) and restart the extended one in coordinates where its X ~ I.
            # Its level also scales z so that the extended level is <= 1.
            prob.extended = False
            try:
                Vs, mu_s, rep_s = minimise()
                solves.append(rep_s.as_dict())
                ok = np.isfinite(prob.recentre(Vs, _POLISH_REG)) and mu_s.value > 0
            except (ConvergenceError, InfeasibleError):
                ok = False
            finally:
                prob.extended = True
            if not ok:
                raise
            b_min = 1.0 / float(np.sqrt(mu_s.value))
            T_bal = prob.T
            V, mu, rep = minimise()
        solves.append(rep.as_dict())
        T_sol = prob.T
        if rep.status != "optimal" and np.isfinite(prob.recentre(V, _POLISH_REG)):
            # Polish: the same problem in coordinates where the optimal X is ~ I.
            try:
                V2, mu2, rep2 = minimise()
            except (ConvergenceError, InfeasibleError):
                rep2 = None
            if rep2 is not None:
                solves.append(rep2.as_dict(prefix=""))
                # both passed the certificate check: the lower level is nearer the infimum
                if rep2.value < rep.value:
                    V, mu, rep, T_sol = V2, mu2, rep2, prob.T
        gamma_opt = float(np.sqrt(max(mu.value, 0.0))) / (prob.a * b_min)
        gamma_fix = gamma_opt * (1.0 + backoff)
        prob._transform(T_sol)
        _, X_opt = prob.gain(V)
    else:
        gamma_fix = gamma

    # 2. well-centred gain at the fixed level
    certified = None
    if gamma is None and backoff > 0 and prob.discrete and not extended and len(plants) == 1:
        # The optimum's own gain, certified at the backed-off level by a
        # Riccati-built strictly feasible point (no second solve).
        certified = prob.certify_at_level(V, 1.0 / (prob.a * gamma_fix), backoff)
    if gamma is None and backoff == 0:
        final_margin, final_cert, gain_from = 0.0, solves[-1]["certificate"], "optimum"
    elif certified is not None:
        V, final_cert, final_margin = certified
        gain_from = "optimum-certified"
    elif gamma is None:
        # "margin": maximise the common smallest eigenvalue t of all blocks
        # at the backed-off level. If the solver fails or the certificate is
        # not strictly positive: "conditioned" (maximise the smallest
        # eigenvalue of X, S for the extended LMI, below x_upper = 10
        # lambda_max of the optimal point, with the H-infinity blocks >= a
        # margin that scales with the backoff: the best-conditioned X, hence
        # a moderate K = Y X^-1), then the same in coordinates where the
        # optimal X is ~ I, then a tenfold backoff.
        failure = None
        for used_backoff in (backoff, 10.0 * backoff, 100.0 * backoff):
            gamma_fix = gamma_opt * (1.0 + used_backoff)
            eps = max(_STRICT, 1e-2 * used_backoff)
            for attempt in ("margin", "conditioned", "conditioned-recentred"):
                prob._transform(T_bal)
                if attempt == "conditioned-recentred":
                    Vr = {"S": _Value(X_opt), "X": _Value(X_opt)}
                    prob._transform(np.eye(prob.n))
                    if not np.isfinite(prob.recentre(Vr, _RECENTRE_REG)):
                        break
                V = prob.variables()
                t = cp.Variable(name="t")
                b_fix = 1.0 / (prob.a * gamma_fix)  # scaled level a * b * gamma_fix = 1
                if attempt == "margin":
                    # largest common margin of every block (bounded: t <= 1)
                    lmis, cons, x_upper = prob.lmis(V, 1.0, t, b=b_fix), [t <= 1.0], 1.0
                else:
                    Xc = np.linalg.solve(prob.T, np.linalg.solve(prob.T, X_opt).T)
                    x_upper = _X_UPPER * float(np.max(np.abs(np.linalg.eigvalsh(0.5 * (Xc + Xc.T)))))
                    lmis, cons = prob.lmis(V, 1.0, eps, b=b_fix, x_margin=t, x_upper=x_upper), []
                try:
                    rep = _cvx.solve_sdp(
                        cp.Maximize(t), lmis, cons, solver=solver, tol=_CENTRE_TOL,
                        infeasible_msg=f"could not find a strictly feasible gain at gamma={gamma_fix:.6g} = "
                                       f"(1 + {used_backoff:g}) gamma_opt; increase backoff")
                except (ConvergenceError, InfeasibleError) as exc:
                    failure = exc
                    continue
                solves.append(rep.as_dict(prefix=""))
                solves[-1]["centring"] = attempt
                if _strict(rep.certificate):
                    failure, final_cert, gain_from = None, rep.certificate, attempt
                    break
                failure = ConvergenceError(
                    f"the gain at gamma={gamma_fix:.6g} = (1 + {used_backoff:g}) gamma_opt has no strictly "
                    f"positive certificate (smallest eigenvalues {rep.certificate}); increase backoff")
            if failure is None:
                break
        if failure is not None:
            raise failure
        backoff = used_backoff
        final_margin = float(t.value) / x_upper
    else:
        V = prob.variables()
        t = cp.Variable(name="t")
        # scaled level a * b * gamma_fix = 1
        # Feasibility as a always-feasible problem: the largest t with every
        # block >= t I (t <= 1 keeps it bounded); strictly feasible iff t > 0.
        infeasible = f"no gain achieves gamma={gamma_fix:.6g}: {what} at this level"
        rep = _cvx.solve_sdp(cp.Maximize(t), prob.lmis(V, 1.0, t, b=1.0 / (prob.a * gamma_fix)),
                             [t <= 1.0], solver=solver, tol=_CENTRE_TOL, infeasible_msg=infeasible)
        solves.append(rep.as_dict())
        final_margin, final_cert, gain_from = float(t.value), rep.certificate, "margin"
        if not final_margin > _STRICT:
            raise InfeasibleError(f"{infeasible} (largest strictness margin {final_margin:.3g})")

    K, X = prob.gain(V, x_floor=_OPTIMUM_X_FLOOR if gain_from == "optimum" else 0.0)
    if not np.all(np.isfinite(K)):
        raise ConvergenceError("the gain K = Y X^-1 is not finite; increase backoff")
    for i, p in enumerate(plants):
        poles = np.linalg.eigvals(p.F + p.G @ K)
        stable = np.max(np.abs(poles)) < 1 if p.is_discrete else np.max(poles.real) < 0
        if not stable:
            raise ConvergenceError(f"internal check failed: the LMI gain does not stabilise "
                                   f"{'plant' if i == 0 else f'vertices[{i - 1}]'}; increase backoff")

    last = solves[-1]
    Xs = 0.5 * (X + X.T)
    info = {
        "gamma": gamma_fix, "gamma_opt": gamma_opt, "backoff": float(backoff) if gamma is None else None,
        "lmi": ("extended" if extended else "standard") + ("-discrete" if plant.is_discrete else "-continuous"),
        "vertices": len(plants), "status": last["status"],
        "solve_time": float(sum(s["solve_time"] for s in solves)),
        "iterations": int(sum(s["iterations"] or 0 for s in solves)),
        "certificate": final_cert, "gain_from": gain_from, "X_min_eig": float(np.linalg.eigvalsh(Xs).min()),
        "margin": final_margin, "solves": solves, "X": Xs, "scaling": prob.d, "solver": solver,
    }
    if u_max is not None:
        T = prob.T
        Ks = K @ T  # gain in the solver's coordinates (unit energy)
        mats = [np.asarray(P.value) for P in V["P"]] if extended else [np.linalg.solve(T, np.linalg.solve(T, Xs).T)]
        info["u_bound"] = np.max([np.sqrt(np.einsum("ij,jk,ik->i", Ks, Pk, Ks)) for Pk in mats], axis=0)
        info["u_max"], info["w_energy"] = u_max, w_energy
        if np.any(info["u_bound"] > u_max * (1.0 + 1e-6)):
            raise ConvergenceError(f"internal check failed: the guaranteed input bound {info['u_bound'].tolist()} "
                                   f"exceeds u_max = {u_max.tolist()} (solver inaccuracy); increase backoff")
    return HinfController(K=K, method="hinf", plant=plant, info=info, gamma=float(gamma_fix),
                          gamma_opt=gamma_opt)
