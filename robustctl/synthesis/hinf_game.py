"""H-infinity control by the game Riccati recursion: finite horizon, its stationary limit, three laws.

Plant and criterion (discrete time)::

    x[k+1] = F x[k] + G u[k] + Bw w[k],

    J = x[N]' P_N x[N] + sum_{k<N} ( x[k]' Q x[k] + u[k]' R u[k] - gamma^2 |w[k]|^2 ).

The minimising ``u`` and the maximising ``w`` play a zero-sum game whose
value is ``x[0]' P_0 x[0]``, with ``P`` from the backward recursion
(``B = [G Bw]``)::

    R_e[k]  = B' P[k+1] B + blkdiag(R, -gamma^2 I)
    P[k]    = F' P[k+1] F + Q - F' P[k+1] B R_e[k]^-1 B' P[k+1] F,      P[N] = P_N.

The game has a value (and ``sup_w J / sum |w|^2 < gamma^2`` for ``x[0] = 0``)
when, at every step, ``R + G' P G > 0`` and the disturbance block is concave
after the input's best reply::

    D[k] = Bw' P Bw - gamma^2 I - Bw' P G (R + G' P G)^-1 G' P Bw  < 0     (P = P[k+1]).

Three laws reach the level ``gamma``; they differ in what ``u[k]`` may see:

* *full information* (``u[k]`` sees ``x[k]`` and ``w[k]``):
  ``u = K_x x + K_w w`` with ``[K_x K_w] = -(R + G'PG)^-1 G'P [F Bw]``;
* *state feedback* (the saddle point of the simultaneous game; it needs the
  stronger condition ``Bw'PBw < gamma^2 I``): ``u = K x``,
  ``K = -[I 0] R_e^-1 B'PF``;
* *delayed full information*: ``F x[k-1] + Bw w[k-1] = x[k] - G u[k-1]`` is
  measured one step late, so the full-information input of step ``k-1`` can
  be applied at step ``k``: ``u[k] = K_e (x[k] - G u[k-1])`` with
  ``K_e = -(R + G'PG)^-1 G'P``, i.e. ``u[k] = K_e x[k] + K_u u[k-1]``,
  ``K_u = -K_e G``. It is the law of the authors' published code
  (Barbosa et al. 2019, GitHub ``barbosafilipe/robust_lqr``,
  ``standard_formulation/h_infinity.m``: the input fed back from the error
  and the previous input through ``P`` alone); nothing guarantees the level
  ``gamma`` for it: the loop must be checked
  (:func:`robustctl.systems.input_memory.with_input_memory` gives the plant with ``u[k-1]`` as a state).

:func:`hinf_game` runs the recursion over a horizon (time-varying gains), or
until it settles (``horizon=None``: the stationary game Riccati equation of
:func:`robustctl.synthesis.hinf_riccati.riccati_level`, reached from ``P_N``; the
recursion then settles in a few hundred steps on the truck).

References
----------
B. Hassibi, A. H. Sayed, T. Kailath, *Indefinite-Quadratic Estimation and
Control: A Unified Approach to H2 and H-infinity Theories*, SIAM 1999: the
finite-horizon full-information H-infinity control problem and its
conditions (pp. 228-234, the pages the authors' code cites).
T. Basar and P. Bernhard, *H-infinity Optimal Control and Related Minimax
Design Problems*, 2nd ed., Birkhaeuser 1995, Ch. 3 (the discrete-time game,
full-information and state-feedback cases).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import as_matrix, check_int, check_positive_scalar, check_spd
from ..errors import ConvergenceError, InfeasibleError
from ..systems.plant import Plant, check_plant

__all__ = ["HinfGame", "hinf_game"]


@dataclass(frozen=True, eq=False, repr=False)
class HinfGame:
    """Result of :func:`hinf_game`: the Riccati solution and the gains of the three laws.

    Stationary (``horizon`` None): ``P`` (n, n) and gains (m, n). Finite
    horizon N: ``P`` (N + 1, n, n) holds ``P[0] .. P[N]`` and each gain has a
    leading axis of N (the gain of step k uses ``P[k+1]``).

    Attributes
    ----------
    gamma : float
    P : ndarray
    K : ndarray
        State-feedback (saddle-point) gain, ``u = K x``.
    K_x, K_w : ndarray
        Full-information gains, ``u = K_x x + K_w w``.
    K_e, K_u : ndarray
        Delayed full-information gains, ``u[k] = K_e x[k] + K_u u[k-1]`` (K_u is (m, m)).
    state_feedback : bool
        ``Bw' P Bw < gamma^2 I`` held at every step: the state-feedback law reaches ``gamma`` too.
    horizon : int or None
    iterations : int
        Recursion steps taken.
    """

    gamma: float
    P: np.ndarray
    K: np.ndarray
    K_x: np.ndarray
    K_w: np.ndarray
    K_e: np.ndarray
    K_u: np.ndarray
    state_feedback: bool
    horizon: int | None
    iterations: int

    def __repr__(self) -> str:
        kind = "stationary" if self.horizon is None else f"horizon={self.horizon}"
        return (f"HinfGame(gamma={self.gamma:.6g}, {kind}, iterations={self.iterations}, "
                f"state_feedback={self.state_feedback})")


_Gains = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]   # K, K_x, K_w, K_e, K_u


def _step(F, G, Bw, Q, R, gamma, P, where: str) -> tuple[np.ndarray, _Gains, bool]:
    """One backward step from ``P = P[k+1]``: ``(P[k], gains, state-feedback condition)``; raises if no value."""
    m, q = G.shape[1], Bw.shape[1]
    scale = max(1.0, float(np.abs(P).max()))
    Ruu = R + G.T @ P @ G
    Ruu = 0.5 * (Ruu + Ruu.T)
    if np.linalg.eigvalsh(Ruu).min() <= 1e-14 * scale:
        raise InfeasibleError(f"no game value at {where}: R + G'PG is not positive definite")
    K_e = -np.linalg.solve(Ruu, G.T @ P)                                # (m, n)
    PBw = P @ Bw
    D = Bw.T @ PBw - gamma**2 * np.eye(q) + (PBw.T @ G) @ np.linalg.solve(Ruu, G.T @ PBw)
    D = 0.5 * (D + D.T)
    if np.linalg.eigvalsh(D).max() >= -1e-14 * gamma**2:
        raise InfeasibleError(f"gamma = {gamma:.6g} is below the achievable level: at {where} the "
                              f"disturbance block Bw'PBw - gamma^2 I - Bw'PG (R + G'PG)^-1 G'PBw is not "
                              f"negative definite (largest eigenvalue {np.linalg.eigvalsh(D).max():.6g})")
    B = np.hstack([G, Bw])
    Re = B.T @ P @ B
    Re[:m, :m] += R
    Re[m:, m:] -= gamma**2 * np.eye(q)
    L = -np.linalg.solve(Re, B.T @ P @ F)                               # [u; w] saddle point
    P_new = F.T @ P @ F + Q + (F.T @ P @ B) @ L
    P_new = 0.5 * (P_new + P_new.T)
    sf = bool(np.linalg.eigvalsh(Bw.T @ PBw - gamma**2 * np.eye(q)).max() < 0)
    return P_new, (L[:m], K_e @ F, K_e @ Bw, K_e, -K_e @ G), sf


def hinf_game(plant: Plant, *, Bw, Q, R, gamma: float, horizon: int | None = None, P_final=None,
              tol: float = 1e-12, max_iter: int = 100_000) -> HinfGame:
    """Run the H-infinity game Riccati recursion (module docstring) and return the three laws' gains.

    Parameters
    ----------
    plant : Plant
        Discrete-time ``(F, G)``.
    Bw : (n, q) array_like
        Disturbance input (a 1-D array is one column).
    Q : (n, n) array_like
        State weight (symmetric, >= 0).
    R : (m, m) array_like
        Input weight (symmetric, > 0).
    gamma : float
        Level (> 0); too small a level raises :class:`~robustctl.errors.InfeasibleError`.
    horizon : int, optional
        N steps (time-varying gains); None iterates to the stationary solution.
    P_final : (n, n) array_like, optional
        Terminal weight ``P_N`` (symmetric, >= 0; default zero), the start of the recursion.
    tol : float
        Stationary case: stop when ``||P[k] - P[k+1]|| <= tol ||P[k]||`` (Frobenius).
    max_iter : int
        Stationary case: give up (:class:`~robustctl.errors.ConvergenceError`) after this many steps.

    Returns
    -------
    HinfGame

    Raises
    ------
    InfeasibleError
        A step with ``R + G'PG`` not positive definite or the disturbance block not negative definite.
    ConvergenceError
        No stationary solution within ``max_iter`` steps.
    """
    check_plant(plant, discrete_for="the game Riccati recursion")
    n, m = plant.n, plant.m
    Bw = as_matrix(Bw, "Bw", rows=n, vector="column", rows_what="the number of states")
    Q = check_spd(as_matrix(Q, "Q", rows=n, cols=n, rows_what="the number of states",
                            cols_what="the number of states"), "Q", semidefinite=True)
    R = check_spd(as_matrix(R, "R", rows=m, cols=m, rows_what="the number of inputs",
                            cols_what="the number of inputs"), "R")
    gamma = check_positive_scalar(gamma, "gamma")
    P = np.zeros((n, n)) if P_final is None else check_spd(
        as_matrix(P_final, "P_final", rows=n, cols=n, rows_what="the number of states",
                  cols_what="the number of states"), "P_final", semidefinite=True)
    F, G = plant.F, plant.G
    state_feedback = True
    if horizon is not None:
        N = check_int(horizon, "horizon", 1)
        Ps, gains = [P], []
        for k in range(N - 1, -1, -1):
            P, g, sf = _step(F, G, Bw, Q, R, gamma, P, f"step {k}")
            Ps.append(P)
            gains.append(g)
            state_feedback &= sf
        Ps, gains = Ps[::-1], gains[::-1]
        K, K_x, K_w, K_e, K_u = (np.stack([g[i] for g in gains]) for i in range(5))
        return HinfGame(gamma, np.stack(Ps), K, K_x, K_w, K_e, K_u, state_feedback=state_feedback, horizon=N,
                        iterations=N)
    tol = check_positive_scalar(tol, "tol")
    max_iter = check_int(max_iter, "max_iter", 1)
    change = np.inf
    for it in range(1, max_iter + 1):
        P_new, _, sf = _step(F, G, Bw, Q, R, gamma, P, f"iteration {it}")
        state_feedback &= sf
        change = float(np.linalg.norm(P_new - P)) / max(float(np.linalg.norm(P_new)), np.finfo(float).tiny)
        P = P_new
        if change <= tol:
            _, g, sf = _step(F, G, Bw, Q, R, gamma, P, f"iteration {it + 1}")    # the gains of the settled P
            return HinfGame(gamma, P, *g, state_feedback=bool(state_feedback and sf), horizon=None,
                            iterations=it)
    raise ConvergenceError(f"the game Riccati recursion did not settle in max_iter={max_iter} steps "
                           f"(relative change of P {change:.3g}, tol={tol:g}); gamma may be too close to "
                           "the achievable level")
