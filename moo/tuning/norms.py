r"""Norm goals: the H2 and H-infinity norms of a performance channel of the closed loop, and its variance under noise.

The channel ``xi+ = A_cl xi + B_a w``, ``z = C_K xi``, ``C_K = [Cz 0] + Dzu K_u``
of the closed loops of :mod:`moo.tuning.loops` (``A_cl = F + G K``,
``C_K = Cz + Dzu K`` for a state feedback), per scenario, reduced with
``over="max"`` by default:

* :class:`H2Norm` - ``||T_zw||_2 = sqrt(trace(C_K P C_K'))`` with the
  controllability Gramian ``P = A_cl P A_cl' + B_a B_a'`` (:func:`gramians`:
  the squared Smith iteration, Smith 1968; continuous plants through the
  Cayley transform);
* :class:`Variance` - the stationary variance of ``z`` under process noise
  and measurement noise (the same Gramians);
* :class:`HinfNorm` - ``||C_K (zI - A_cl)^-1 B_a||_inf``, as ``1 / margin`` of
  :func:`robustctl.robust_stability` with ``NormBounded(Bw, Cz, Dzu)`` (the
  small-gain value: one norm implementation in the project).

The protocol every goal follows is in :mod:`moo.tuning.goals`.

References
----------
K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*, Prentice Hall
1996, Ch. 4 (H2 and H-infinity norms, Gramians).
R. A. Smith, "Matrix equation XA + BX = C", SIAM J. Appl. Math. 16(1), 1968.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

import robustctl as rc
from robustctl.validation import as_matrix, check_choice

from .goals import OVER, Goal, check_scenarios, checked_loops, reduce, set_fields
from .loops import Loops, is_output_feedback
from .margins import robust_margins

__all__ = ["H2Norm", "HinfNorm", "Variance", "gramians"]

# Squared Smith iteration: relative size of the last increment, and the most doublings
# (A^(2^64) of a stable A is zero unless its spectral radius is within ~1e-17 of 1).
_SMITH_RTOL = 1e-16
_SMITH_MAX = 64


def _matrix(value, name: str, vector: str) -> np.ndarray:
    """A finite non-empty 2-D float array, read-only (a 1-D array is a ``vector``: "column" or "row")."""
    arr = as_matrix(value, name, vector=vector)
    arr.flags.writeable = False
    return arr


@dataclass(frozen=True, eq=False, repr=False)
class _Channel(Goal):
    """A performance channel ``x+ = A x + Bw w``, ``z = (Cz + Dzu K) x`` of the closed loop."""

    Bw: Any
    Cz: Any
    Dzu: Any = None
    over: str = "max"
    name: str = ""

    def __post_init__(self):
        Bw, Cz = _matrix(self.Bw, "Bw", "column"), _matrix(self.Cz, "Cz", "row")
        Dzu = None if self.Dzu is None else _matrix(self.Dzu, "Dzu", "row")
        if Dzu is not None and Dzu.shape[0] != Cz.shape[0]:
            raise ValueError(f"Dzu must have {Cz.shape[0]} rows (the rows of Cz), got shape {Dzu.shape}")
        set_fields(self, Bw=Bw, Cz=Cz, Dzu=Dzu, over=check_choice(self.over, "over", OVER),
             name=self.name or self._default_name)

    _default_name = ""

    def check(self, plants) -> None:
        """``ValueError`` naming ``Bw``, ``Cz`` or ``Dzu`` if its size does not fit ``plants``."""
        plants = check_scenarios(plants, continuous=True)
        n, m = plants[0].n, plants[0].m
        if self.Bw.shape[0] != n:
            raise ValueError(f"Bw must have {n} rows (the number of states of the plants), got shape {self.Bw.shape}")
        if self.Cz.shape[1] != n:
            raise ValueError(f"Cz must have {n} columns (the number of states of the plants), "
                             f"got shape {self.Cz.shape}")
        if self.Dzu is not None and self.Dzu.shape[1] != m:
            raise ValueError(f"Dzu must have {m} columns (the number of inputs of the plants), "
                             f"got shape {self.Dzu.shape}")

    def _channel(self, loops: Loops) -> tuple[np.ndarray, np.ndarray]:
        """``(B_a (N, q), C_K (B, S, l, N))``: ``w`` enters the plant states, ``z = [C_z 0] + D_zu K_u``."""
        N = loops.A.shape[-1]
        Ba = np.zeros((N, self.Bw.shape[1]))
        Ba[:loops.n] = self.Bw
        Ca = np.zeros((self.Cz.shape[0], N))
        Ca[:, :loops.n] = self.Cz
        C = np.broadcast_to(Ca, (*loops.A.shape[:2], *Ca.shape))
        return Ba, (C if self.Dzu is None else C + self.Dzu @ loops.Ku)


@dataclass(frozen=True, eq=False, repr=False)
class H2Norm(_Channel):
    r"""H2 norm of the channel ``w -> z = Cz x + Dzu u`` of the closed loop ``x+ = (F + G K) x + Bw w``.

    With white ``w`` of unit intensity its square is the steady-state
    variance of ``z``. The max (default) or mean over the scenarios.

    Parameters
    ----------
    Bw : (n, q) array_like (1-D: one column)
        Disturbance input matrix.
    Cz : (l, n) array_like (1-D: one row)
        Performance output matrix.
    Dzu : (l, m) array_like, optional
        Feedthrough of the input to the performance output (default none).
    over : {"mean", "max"}
        Reduction over the scenarios (default the max).
    name : str, optional
        Label for tables and plots (default ``"H2 norm"``).

    Raises
    ------
    ValueError
        ``Bw``, ``Cz`` or ``Dzu`` not finite or of sizes that do not fit each
        other or the plants (the message names the matrix and the shapes).

    See Also
    --------
    HinfNorm : the worst-case gain of the same channel.
    robustctl.h2 : H2-optimal synthesis.

    Notes
    -----
    .. math::

        \|T_{zw}\|_2^2 = \operatorname{trace}(C_K P C_K^T), \qquad
        C_K = C_z + D_{zu} K, \qquad P = A P A^T + B_w B_w^T, \qquad A = F + G K,

    the controllability Gramian :math:`P` computed by the batched squared
    Smith iteration [1]_ (:math:`P \leftarrow P + A_j P A_j^T`,
    :math:`A_j \leftarrow A_j^2`); a loop where it does not settle gets ``inf``.

    References
    ----------
    .. [1] R. A. Smith, "Matrix equation XA + BX = C", SIAM J. Appl. Math.
       16(1), 198-201, 1968.
    .. [2] K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*,
       Prentice Hall, 1996, Ch. 4.

    Examples
    --------
    Against the Gramian of :func:`scipy.linalg.solve_discrete_lyapunov`:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from scipy.linalg import solve_discrete_lyapunov
    >>> from moo.tuning import H2Norm
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> K = np.array([[[-1.0, -2.0]]])
    >>> goal = H2Norm(Bw=[[0.0], [1.0]], Cz=[[1.0, 0.0]])
    >>> P = solve_discrete_lyapunov(plant.F + plant.G @ K[0], np.diag([0.0, 1.0]))
    >>> np.allclose(goal(K, [plant]), np.sqrt(P[0, 0]))
    True
    """

    _default_name = "H2 norm"

    def measure(self, K, plants) -> np.ndarray:
        """The H2 norm of each design, shape (B,)."""
        self.check(plants)
        _, _, loops = checked_loops(K, plants)
        Ba, C = self._channel(loops)
        P, done = gramians(loops.A, Ba @ Ba.T, discrete=loops.discrete)
        value = np.sqrt(np.maximum(np.einsum("bsln,bsnk,bslk->bs", C, P, C), 0.0))
        value[~done | ~np.isfinite(value)] = np.inf
        return reduce(value, self.over)


def gramians(A: np.ndarray, Q: np.ndarray, *, discrete: bool) -> tuple[np.ndarray, np.ndarray]:
    r"""Controllability Gramians of a stack of stable loops: ``P = A P A' + Q`` (discrete) or ``A P + P A' + Q = 0``.

    ``A`` (..., N, N), ``Q`` (N, N) or (..., N, N) positive semidefinite;
    returns ``P`` and where the iteration settled (a loop that is not stable,
    or too close to the boundary, does not). Discrete: the squared Smith
    iteration [1]_, ``P <- P + A_j P A_j'``, ``A_j <- A_j^2``. Continuous: the
    Cayley transform ``A_d = (cI - A)^{-1} (cI + A)``,
    ``Q_d = 2c (cI - A)^{-1} Q (cI - A)^{-T}`` (same ``P``; ``c`` the mean
    modulus of the diagonal of ``A``), then the same iteration.

    References
    ----------
    .. [1] R. A. Smith, "Matrix equation XA + BX = C", SIAM J. Appl. Math.
       16(1), 198-201, 1968.
    """
    A = np.asarray(A, dtype=float)
    Q = np.broadcast_to(Q, A.shape).astype(float)
    if not discrete:
        N = A.shape[-1]
        c = np.maximum(np.abs(np.diagonal(A, axis1=-2, axis2=-1)).mean(axis=-1), 1e-6)[..., None, None]
        M = c * np.eye(N) - A
        with np.errstate(all="ignore"):
            Minv = np.linalg.solve(np.where(np.isfinite(M), M, 0.0), np.broadcast_to(np.eye(N), M.shape))
        A, Q = Minv @ (c * np.eye(N) + A), 2.0 * c * (Minv @ Q @ np.swapaxes(Minv, -1, -2))
    P = Q.copy()
    Aj = A.copy()
    done = np.zeros(A.shape[:-2], dtype=bool)
    with np.errstate(all="ignore"):
        for _ in range(_SMITH_MAX):
            inc = Aj @ P @ np.swapaxes(Aj, -1, -2)
            P += inc
            done = np.abs(inc).max(axis=(-2, -1)) <= _SMITH_RTOL * np.abs(P).max(axis=(-2, -1))
            if done.all():
                break
            Aj = Aj @ Aj
    return P, done & np.isfinite(P).all(axis=(-2, -1))


@dataclass(frozen=True, eq=False, repr=False)
class HinfNorm(_Channel):
    r"""H-infinity norm of the channel ``w -> z = Cz x + Dzu u`` of ``x+ = (F + G K) x + Bw w``.

    The worst-case energy gain from ``w`` to ``z``, per scenario; the max
    (default) or mean over the scenarios.

    Parameters
    ----------
    Bw : (n, q) array_like (1-D: one column)
        Disturbance input matrix.
    Cz : (l, n) array_like (1-D: one row)
        Performance output matrix.
    Dzu : (l, m) array_like, optional
        Feedthrough of the input to the performance output (default none).
    over : {"mean", "max"}
        Reduction over the scenarios (default the max).
    name : str, optional
        Label for tables and plots (default ``"Hinf norm"``).

    Raises
    ------
    ValueError
        ``Bw``, ``Cz`` or ``Dzu`` not finite or of sizes that do not fit each
        other or the plants (the message names the matrix and the shapes).

    See Also
    --------
    H2Norm : the average gain of the same channel.
    RobustMargin : the same computation, read as a robustness margin.
    robustctl.robust_stability : the small-gain analysis it uses.

    Notes
    -----
    .. math::

        \|T_{zw}\|_\infty = \max_{\omega} \sigma_{\max}\big((C_z + D_{zu} K)
        (e^{j\omega} I - F - G K)^{-1} B_w\big)
        = 1 / \text{margin},

    the margin of ``robustctl.robust_stability((plant, K),
    NormBounded(Bw, Cz, Dzu))`` (the small-gain value: one norm
    implementation in the project; 0 where the channel is zero).

    References
    ----------
    .. [1] K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*,
       Prentice Hall, 1996, Ch. 4.

    Examples
    --------
    This loop's gain is largest at ``omega = 0`` (its DC gain, 9); a
    frequency sweep finds the same value:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import HinfNorm
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> K = np.array([[[-1.0, -2.0]]])
    >>> norm = HinfNorm(Bw=[[0.0], [1.0]], Cz=[[1.0, 0.0]])(K, [plant])
    >>> A, z = plant.F + plant.G @ K[0], np.exp(1j * np.linspace(0.0, np.pi, 2001))
    >>> sweep = max(abs(np.linalg.solve(zk * np.eye(2) - A, [0.0, 1.0])[0]) for zk in z)
    >>> np.allclose(norm, sweep), np.allclose(norm, 9.0)
    (True, True)
    """

    _default_name = "Hinf norm"

    def measure(self, K, plants) -> np.ndarray:
        """The H-infinity norm of each design, shape (B,)."""
        self.check(plants)
        K, plants, _ = checked_loops(K, plants)
        Dzu = np.zeros((self.Cz.shape[0], plants[0].m)) if self.Dzu is None else self.Dzu
        unc = rc.NormBounded(self.Bw, self.Cz, Dzu)
        with np.errstate(divide="ignore"):
            norms = np.stack([1.0 / robust_margins(p, K, unc) for p in plants], axis=1)   # (B, S)
        return reduce(norms, self.over)


@dataclass(frozen=True, eq=False, repr=False)
class Variance(Goal):
    r"""Stationary variance of an output under process and measurement noise (noise to output, H2).

    MATLAB's ``TuningGoal.Variance``: with white process noise ``w`` of
    covariance ``W`` entering ``x+ = F x + G u + B_w w`` and white measurement
    noise ``v`` of covariance ``V`` added to what the controller measures
    (``y + v``; the state for a state feedback), the value is the sum of the
    stationary variances of ``z = C_z x + D_zu u`` (``trace E[z z']``).
    Continuous plants: ``W`` and ``V`` are intensities and ``z`` must not
    see ``v`` directly. The max (default) or mean over the scenarios.

    Parameters
    ----------
    Bw : (n, q) array_like (1-D: one column)
        Process noise input.
    W : (q, q) array_like, optional
        Process noise covariance (default identity).
    V : (r, r) array_like, optional
        Measurement noise covariance (``r`` the measured signals: the plant's
        ``p``, or ``n`` for a state feedback); default none.
    Cz : (l, n) array_like, optional
        Performance output (default the plant's output ``C``, the state
        without an output model).
    Dzu : (l, m) array_like, optional
        Its input feedthrough (default the plant's ``D`` with the default
        ``Cz``, else zero).
    over : {"mean", "max"}
        Reduction over the scenarios (default the max).
    name : str, optional
        Label (default ``"variance"``).

    Raises
    ------
    ValueError
        Matrices not finite, ``W`` or ``V`` not symmetric positive
        semidefinite, sizes that do not fit each other or the plants.

    See Also
    --------
    H2Norm : the unit-intensity case without measurement noise.

    Notes
    -----
    In the loop states :math:`\xi = (x, x_c)`, with :math:`E = (I - D_c D)^{-1}`,

    .. math::

        \xi^+ = A_{cl} \xi + B_a w + B_v v, \quad
        z = C_a \xi + D_v v, \quad
        B_a = \begin{bmatrix} B_w \\ 0 \end{bmatrix}, \quad
        B_v = \begin{bmatrix} G E D_c \\ B_c (I + D E D_c) \end{bmatrix},

    :math:`C_a = [C_z\ 0] + D_{zu} K_u`, :math:`D_v = D_{zu} E D_c`, and

    .. math::

        \operatorname{var} z = \operatorname{trace}\big(C_a P C_a^T + D_v V D_v^T\big), \qquad
        P = A_{cl} P A_{cl}^T + B_a W B_a^T + B_v V B_v^T

    (continuous: :math:`A_{cl} P + P A_{cl}^T + B_a W B_a^T + B_v V B_v^T = 0`),
    by the batched Gramians of :func:`gramians`.

    References
    ----------
    .. [1] K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*,
       Prentice Hall, 1996, Ch. 4 (H2 norm and covariance).

    Examples
    --------
    ``x+ = 0.5 x + w`` (the loop ``x+ = 0.7 x - 0.2 x + w``): the variance
    ``1 / (1 - 0.25)``, python-control's H2 norm squared:

    >>> import numpy as np, control
    >>> import robustctl as rc
    >>> from moo.tuning import Variance
    >>> plant = rc.Plant([[0.7]], [[1.0]], 0.1)
    >>> Variance(Bw=[[1.0]])(np.array([[[-0.2]]]), [plant])
    array([1.33333333])
    >>> round(float(control.norm(control.ss([[0.5]], [[1.0]], [[1.0]], [[0.0]], 0.1), 2) ** 2), 10)
    1.3333333333
    """

    Bw: Any
    W: Any = None
    V: Any = None
    Cz: Any = None
    Dzu: Any = None
    over: str = "max"
    name: str = ""

    def __post_init__(self):
        Bw = _matrix(self.Bw, "Bw", "column")
        q = Bw.shape[1]
        W = np.eye(q) if self.W is None else _covariance(self.W, "W", q, "the columns of Bw")
        V = None if self.V is None else _covariance(self.V, "V", None, "")
        Cz = None if self.Cz is None else _matrix(self.Cz, "Cz", "row")
        Dzu = None if self.Dzu is None else _matrix(self.Dzu, "Dzu", "row")
        if Cz is not None and Dzu is not None and Dzu.shape[0] != Cz.shape[0]:
            raise ValueError(f"Dzu must have {Cz.shape[0]} rows (the rows of Cz), got shape {Dzu.shape}")
        set_fields(self, Bw=Bw, W=W, V=V, Cz=Cz, Dzu=Dzu, over=check_choice(self.over, "over", OVER),
             name=self.name or "variance")

    def check(self, plants) -> None:
        """``ValueError`` naming ``Bw``, ``V``, ``Cz`` or ``Dzu`` if its size does not fit ``plants``."""
        plants = check_scenarios(plants, continuous=True)
        n, m = plants[0].n, plants[0].m
        if self.Bw.shape[0] != n:
            raise ValueError(f"Bw must have {n} rows (the number of states of the plants), got shape {self.Bw.shape}")
        if self.Cz is not None and self.Cz.shape[1] != n:
            raise ValueError(f"Cz must have {n} columns (the number of states), got shape {self.Cz.shape}")
        if self.Dzu is not None and self.Dzu.shape[1] != m:
            raise ValueError(f"Dzu must have {m} columns (the number of inputs), got shape {self.Dzu.shape}")
        if self.Cz is None and self.Dzu is not None and self.Dzu.shape[0] != plants[0].p:
            raise ValueError(f"Dzu must have {plants[0].p} rows (the plant's outputs, the default Cz), "
                             f"got shape {self.Dzu.shape}")
        if self.V is not None and self.V.shape[0] not in (n, plants[0].p):
            raise ValueError(f"V must be ({plants[0].p}, {plants[0].p}) (the measured outputs) or ({n}, {n}) (a state "
                             f"feedback's), got shape {self.V.shape}")

    def measure(self, K, plants) -> np.ndarray:
        """The summed stationary variance of ``z`` of each design, shape (B,)."""
        self.check(plants)
        K, plants, loops = checked_loops(K, plants)
        B, S, N = loops.A.shape[:3]
        n, m = loops.n, plants[0].m
        C0, D0 = plants[0].output_matrices()
        Cz = C0 if self.Cz is None else self.Cz
        Dzu = (D0 if self.Cz is None else np.zeros((Cz.shape[0], m))) if self.Dzu is None else self.Dzu
        Ca = np.zeros((Cz.shape[0], N))
        Ca[:, :n] = Cz
        Ca = Ca + Dzu @ loops.Ku                                                     # (B, S, l, N)
        Ba = np.zeros((N, self.Bw.shape[1]))
        Ba[:n] = self.Bw
        Q = np.broadcast_to(Ba @ self.W @ Ba.T, loops.A.shape).copy()
        extra = np.zeros((B, S))
        if self.V is not None:
            Dc = K.Dc if is_output_feedback(K) else np.asarray(K)
            r = Dc.shape[-1]
            if self.V.shape != (r, r):
                raise ValueError(f"V must be ({r}, {r}) (the signals these controllers measure), got shape "
                                 f"{self.V.shape}")
            Bv = loops.Bv @ Dc[:, None]                                              # (B, S, N, r)
            if is_output_feedback(K) and K.order:
                Bv[..., n:, :] += K.Bc[:, None]
            Q += Bv @ self.V @ np.swapaxes(Bv, -1, -2)
            Dv = Dzu @ loops.E @ Dc[:, None]                                         # (B, S, l, r)
            if not loops.discrete and np.any(Dv):
                raise ValueError("V: the output z sees the measurement noise directly (D_zu E D_c != 0): its "
                                 "variance is infinite for a continuous plant")
            extra = np.einsum("bsli,ij,bslj->bs", Dv, self.V, Dv)
        P, done = gramians(loops.A, Q, discrete=loops.discrete)
        value = np.einsum("bsln,bsnk,bslk->bs", Ca, P, Ca) + extra
        value[~done | ~np.isfinite(value)] = np.inf
        return reduce(np.maximum(value, 0.0), self.over)


def _covariance(value, name: str, size: int | None, what: str) -> np.ndarray:
    """A finite symmetric positive semidefinite (size, size) matrix, read-only."""
    M = as_matrix(value, name)
    if M.shape[0] != M.shape[1] or (size is not None and M.shape[0] != size):
        want = f"({size}, {size}) ({what})" if size is not None else "square"
        raise ValueError(f"{name} must be {want}, got shape {M.shape}")
    scale = max(1.0, float(np.abs(M).max()))
    if not np.allclose(M, M.T, rtol=1e-10, atol=1e-12 * scale) \
            or np.linalg.eigvalsh(0.5 * (M + M.T))[0] < -1e-12 * scale:
        raise ValueError(f"{name} must be symmetric positive semidefinite (a covariance)")
    M = 0.5 * (M + M.T)
    M.flags.writeable = False
    return M
