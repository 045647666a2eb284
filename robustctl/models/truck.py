"""Single-track lateral model of a heavy truck with path-following states.

The model of Morais et al. (2022), Section 2.1, Eq. (1): a linear single-track
("bicycle") model (van Zanten / Pacejka, linear tyres) combined with the
path-following kinematics of Skjetne & Fossen (2001). States and input::

    x = [ydot, psidot, rho, theta]       alpha = front steering angle [rad]

``ydot`` lateral velocity in the body frame [m/s], ``psidot`` yaw rate [rad/s],
``rho`` lateral displacement from the path [m], ``theta`` orientation
(heading) error relative to the path tangent [rad]. Positive is to the left
(counter-clockwise) for all of them, and for the path curvature ``kappa``.

Continuous-time model (Eq. 1 with its two typos corrected)::

    m ydot'   = -(c1 + c2)/v ydot + ((b c2 - a c1)/v - m v) psidot + c1 alpha
    J psidot' =  (b c2 - a c1)/v ydot - (a^2 c1 + b^2 c2)/v psidot + a c1 alpha
    rho'      =  ydot + v theta
    theta'    =  psidot - v kappa

The paper prints entry (1,2) as ``(b c1 - a c1 - m v^2)/v`` and entry (2,2) as
``(-a^2 c1 - b^2 c1)/v``; the rear cornering stiffness ``c2`` belongs with the
rear distance ``b`` in both (the standard single-track model, e.g.
Schramm, Hiller & Bardini, *Vehicle Dynamics*, 2014, Sec. 10.3). The paper's
Eq. 1 also has ``theta' = psidot`` with no path term: the path enters here as
the known disturbance ``-v kappa`` on ``theta'`` (``E = [0, 0, 0, -v]^T``),
which is zero on a straight path, so Eq. 1 is recovered there.

Mass and inertia at an overload
-------------------------------
The parameter table lists the vehicle mass ``m = 16030 kg`` and, separately,
the payload ``12550 kg``. We read ``m`` and ``J`` as the *unladen* vehicle and
the nominal operating point (0 % overload) as the vehicle with its nominal
payload. An overload of ``k`` % multiplies the payload by ``1 + k/100``
(100 % overload = twice the nominal payload, as in the paper's Section 4.5.2)::

    m_total(k) = m + payload (1 + k/100)
    J_total(k) = J m_total(k) / m

i.e. the payload is spread like the vehicle's own mass, so the radius of
gyration ``sqrt(J/m) = 3.67 m`` is unchanged. The appendix's "unloaded"
vehicle (``m_total = m``) is overload -100 %; it is used only by
:func:`algebraic_uncertainty` (public functions reject negative overloads).

References
----------
Morais, Barbosa, Tonidandel, Wanner & Grassi Jr (2022), "Robust path-following
control design of heavy vehicles based on multiobjective evolutionary
optimization", *Expert Systems with Applications* 192, 116304.
Barbosa, Ferreira, Cerri & Grassi Jr (2019), "Robust path-following control
for articulated heavy-duty vehicles", *Control Engineering Practice* 85.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
import scipy.linalg

from .._validation import as_batch, check_positive_scalar, frozen
from ..systems.plant import Plant

__all__ = [
    "TruckParameters", "PAPER_PARAMETERS", "STATE_NAMES", "STATE_UNITS", "OBJECTIVE_STATES",
    "STEER_LIMIT", "continuous_model", "truck_plant", "discretise", "steady_state_cornering",
    "reference_states", "AlgebraicUncertainty", "algebraic_uncertainty", "check_overload",
    "MAX_ERRORS", "MAX_STEER", "lqr_weights", "DOUBLED_INPUT_MAP", "open_loop_reference",
]

#: State names, in the model's order.
STATE_NAMES = ("ydot", "psidot", "rho", "theta")
STATE_UNITS = ("m/s", "rad/s", "m", "rad")
#: State index of each of the paper's objectives f1..f4: rho, psidot, ydot, theta.
OBJECTIVE_STATES = (2, 1, 0, 3)
#: Steering saturation used in the paper's simulations [rad].
STEER_LIMIT = 0.45
#: Input map of the doubled steering column: the steering angle is ``alpha = u1 + u2``
#: (``input_map`` of :func:`robustctl.models.pathfollow.simulate`).
DOUBLED_INPUT_MAP = ((1.0, 1.0),)

@dataclass(frozen=True)
class TruckParameters:
    """Parameters of the single-track truck model (paper's Table "Vehicle parameters values").

    Attributes
    ----------
    a : float
        Distance front axle - centre of gravity [m].
    b : float
        Distance rear axle - centre of gravity [m].
    v : float
        Forward speed [m/s] (60 km/h).
    m : float
        Unladen vehicle mass [kg].
    payload : float
        Nominal payload [kg] (the 0 % overload case).
    J : float
        Unladen yaw moment of inertia [kg m^2].
    c1, c2 : float
        Cornering stiffness of the front and rear axle [N/rad].
    dt : float
        Sampling time [s].
    """

    a: float = 3.1870
    b: float = 1.6180
    v: float = 16.6667
    m: float = 16030.0
    payload: float = 12550.0
    J: float = 2.1572e5
    c1: float = 1.0645e5
    c2: float = 5.4042e5
    dt: float = 0.1

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "payload":
                if not np.isfinite(value) or value < 0:
                    raise ValueError(f"payload must be finite and >= 0, got {value}")
            else:
                check_positive_scalar(value, f.name)

    @property
    def wheelbase(self) -> float:
        """``a + b`` [m] (4.805 m)."""
        return self.a + self.b

    def total_mass(self, overload: float = 0.0) -> float:
        """``m + payload (1 + overload/100)`` [kg]."""
        return self._mass(1.0 + check_overload(overload) / 100.0)

    def inertia(self, overload: float = 0.0) -> float:
        """``J m_total / m`` [kg m^2] (payload with the vehicle's radius of gyration)."""
        return self._inertia(1.0 + check_overload(overload) / 100.0)

    def _mass(self, load):
        return self.m + self.payload * np.asarray(load, dtype=float)

    def _inertia(self, load):
        return self.J * self._mass(load) / self.m


PAPER_PARAMETERS = TruckParameters()


def check_overload(overload, name: str = "overload") -> float | np.ndarray:
    """Return ``overload`` (percent, >= 0, finite) as float or float array; raise otherwise."""
    if isinstance(overload, (str, bytes)) or overload is None or isinstance(overload, bool):
        raise TypeError(f"{name} must be a number (percent), got {type(overload).__name__}")
    try:
        arr = np.asarray(overload, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a number (percent), got {type(overload).__name__}") from None
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {overload!r}")
    if np.any(arr < 0):
        raise ValueError(f"{name} must be >= 0 percent (0 = nominal payload), got {arr.min():g}")
    return float(arr) if arr.ndim == 0 else arr


def _params(params) -> TruckParameters:
    if params is None:
        return PAPER_PARAMETERS
    if not isinstance(params, TruckParameters):
        raise TypeError(f"params must be a TruckParameters, got {type(params).__name__}")
    return params


def _continuous_batch(p: TruckParameters, load: float | np.ndarray):
    """A (k,4,4), B (k,4,1), E (4,) for payload multipliers ``load`` (k,)."""
    load = np.atleast_1d(np.asarray(load, dtype=float))
    m = p._mass(load)
    J = p._inertia(load)
    a, b, v, c1, c2 = p.a, p.b, p.v, p.c1, p.c2
    A = np.zeros((load.size, 4, 4))
    A[:, 0, 0] = -(c1 + c2) / (m * v)
    A[:, 0, 1] = (b * c2 - a * c1 - m * v**2) / (m * v)
    A[:, 1, 0] = (b * c2 - a * c1) / (J * v)
    A[:, 1, 1] = -(a**2 * c1 + b**2 * c2) / (J * v)
    A[:, 2, 0] = 1.0
    A[:, 2, 3] = v
    A[:, 3, 1] = 1.0
    B = np.zeros((load.size, 4, 1))
    B[:, 0, 0] = c1 / m
    B[:, 1, 0] = a * c1 / J
    E = np.array([0.0, 0.0, 0.0, -v])
    return A, B, E


def continuous_model(overload: float = 0.0, *, params: TruckParameters | None = None
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Continuous-time matrices ``x' = A x + B alpha + E kappa`` at ``overload`` percent.

    Returns
    -------
    A : (4, 4) ndarray
    B : (4, 1) ndarray
        Steering input column ``[c1/m, a c1/J, 0, 0]^T``.
    E : (4,) ndarray
        Path-curvature input ``[0, 0, 0, -v]^T`` (``kappa`` in 1/m, positive to the left).
    """
    p = _params(params)
    A, B, E = _continuous_batch(p, 1.0 + check_overload(overload) / 100.0)
    return A[0], B[0], E


def truck_plant(overload: float = 0.0, *, params: TruckParameters | None = None,
                doubled: bool = False) -> Plant:
    """The truck discretised with zero-order hold at ``params.dt`` (0.1 s).

    Parameters
    ----------
    overload : float
        Payload overload in percent (0 = nominal payload, 100 = twice the payload).
    params : TruckParameters, optional
        Defaults to the paper's parameters.
    doubled : bool
        If True, return the "doubled steering column" plant ``G2 = [G G]`` with
        two inputs whose sum is the steering angle, ``alpha = u1 + u2``
        (Barbosa et al. 2019, used by the paper's applied RLQR designs so that
        a gain remains free after the ``mu -> inf`` constraint
        ``EF + EG K = 0``). ZOH commutes with the duplication.

    Returns
    -------
    Plant
        ``x[k+1] = F x[k] + G u[k]``, the exact ZOH of :func:`discretise`
        (``expm`` of the augmented matrix; bit-identical to python-control's
        ``c2d`` through :meth:`robustctl.Plant.from_continuous`, which a test
        checks, without importing python-control). The curvature input is
        not part of the plant; see :func:`discretise`.
    """
    p = _params(params)
    F, G, _ = _discrete_batch(p, 1.0 + check_overload(overload) / 100.0)
    return Plant(F[0], np.hstack([G[0], G[0]]) if doubled else G[0], p.dt)


def _zoh(A: np.ndarray, BE: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Batched exact ZOH: ``expm([[A, BE], [0, 0]] dt)`` for A (k,n,n), BE (k,n,q)."""
    k, n, q = BE.shape
    M = np.zeros((k, n + q, n + q))
    M[:, :n, :n] = A * dt
    M[:, :n, n:] = BE * dt
    Phi = scipy.linalg.expm(M)
    return Phi[:, :n, :n], Phi[:, :n, n:]


def _discrete_batch(p: TruckParameters, load) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    A, B, E = _continuous_batch(p, load)
    BE = np.concatenate([B, np.broadcast_to(E[None, :, None], (A.shape[0], 4, 1))], axis=2)
    F, GE = _zoh(A, BE, p.dt)
    return F, GE[:, :, :1], GE[:, :, 1]


def discretise(overloads, *, params: TruckParameters | None = None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ZOH discretisation at many overloads at once, with the curvature input.

    ``x[k+1] = F x[k] + G alpha[k] + Gk kappa[k]`` with ``alpha`` and ``kappa``
    held constant over each sample (exact for piecewise-constant signals).

    Parameters
    ----------
    overloads : float or (k,) array_like
        Overloads in percent (>= 0).

    Returns
    -------
    F : (k, 4, 4) ndarray
    G : (k, 4, 1) ndarray
    Gk : (k, 4) ndarray
        Discretised curvature input.
    """
    p = _params(params)
    ov = np.atleast_1d(check_overload(overloads, "overloads"))
    if ov.ndim != 1:
        raise ValueError(f"overloads must be a scalar or a 1-D array, got shape {ov.shape}")
    return _discrete_batch(p, 1.0 + ov / 100.0)


def steady_state_cornering(overload: float = 0.0, *, params: TruckParameters | None = None
                           ) -> tuple[np.ndarray, float]:
    """State and steering per unit curvature in steady cornering on the path.

    Solves ``A x + B alpha + E kappa = 0`` with ``rho = 0`` for ``kappa = 1``:
    ``psidot = v kappa`` (row 4), ``theta = -ydot / v`` (row 3, the body's
    sideslip: the heading differs from the path tangent by minus the slip
    angle) and rows 1-2 give ``ydot`` and ``alpha`` (Ackermann angle
    ``L kappa`` plus the understeer term). Because ZOH keeps equilibria, this is
    also a fixed point of the discretised model.

    Returns
    -------
    x_per_kappa : (4,) ndarray
        ``[ydot, psidot, rho, theta]`` per 1/m of curvature.
    alpha_per_kappa : float
        Steady-state steering angle per 1/m of curvature [rad m].
    """
    A, B, _ = continuous_model(overload, params=params)
    v = _params(params).v
    r = v  # psidot per unit kappa
    # rows 1-2:  A[i,0] ydot + B[i] alpha = -A[i,1] r
    M = np.array([[A[0, 0], B[0, 0]], [A[1, 0], B[1, 0]]])
    ydot, alpha = np.linalg.solve(M, -r * A[:2, 1])
    return np.array([ydot, r, 0.0, -ydot / v]), float(alpha)


def reference_states(kappa, overload: float = 0.0, *, params: TruckParameters | None = None
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Reference states and steady-state steering feedforward along a curvature signal.

    The reference is quasi-static steady cornering (:func:`steady_state_cornering`)
    of the model at ``overload`` (the controller's nominal model, 0 % by default):
    ``x_ref[k] = x_per_kappa kappa[k]``, ``alpha_ff[k] = alpha_per_kappa kappa[k]``.
    On a straight, ``x_ref = 0``.

    Parameters
    ----------
    kappa : (T,) array_like
        Path curvature at each sample [1/m].

    Returns
    -------
    x_ref : (T, 4) ndarray
    alpha_ff : (T,) ndarray
    """
    kappa = as_batch(kappa, "kappa", (None,))
    xk, ak = steady_state_cornering(overload, params=params)
    return kappa[:, None] * xk[None, :], ak * kappa


def open_loop_reference(kappa, overload: float = 0.0, *, params: TruckParameters | None = None
                        ) -> tuple[np.ndarray, np.ndarray]:
    """The truck at ``overload`` driven open loop by its steady-cornering steering along a path.

    The reference of the authors' published code (Barbosa et al. 2019, GitHub
    ``barbosafilipe/robust_lqr``, ``standard_formulation/parameters.m``): the
    nominal vehicle, started at rest on the path, is driven by a smooth
    steering command ``u_ref`` and its simulated states are the reference
    (there: two 5 s sine steering lane changes on a straight road). Here the
    command is the steady-cornering steering of the path's curvature,
    ``u_ref[k] = alpha_per_kappa kappa[k]`` (:func:`steady_state_cornering`),
    so lane changes and bends of any :class:`robustctl.models.path.ReferencePath`
    give the command::

        x_ref[0] = 0,   x_ref[k+1] = F x_ref[k] + G u_ref[k] + Gk kappa[k]

    (the ZOH model of :func:`discretise`). Open loop, the vehicle lags the
    path in every transition and nothing pulls it back, so ``rho_ref``
    drifts away from the path (about 22 m over the 9 km default route):
    the reference trajectory is the open-loop vehicle's, the path only its
    frame. Because the curvature enters the true and the reference vehicle
    alike (``Gk`` does not depend on the payload), it cancels from the
    tracking error ``x - x_ref``: only ``u_ref`` matters.

    Parameters
    ----------
    kappa : (T,) array_like
        Path curvature at each sample [1/m].
    overload : float
        Payload of the reference vehicle (the controller's nominal model).

    Returns
    -------
    x_ref : (T, 4) ndarray
        States ``[ydot, psidot, rho, theta]`` of the open-loop vehicle.
    u_ref : (T,) ndarray
        The steering command [rad].
    """
    kappa = as_batch(kappa, "kappa", (None,))
    _, a_per_kappa = steady_state_cornering(overload, params=params)
    u_ref = a_per_kappa * kappa
    F, G, Gk = discretise(overload, params=params)
    drive = G[0, :, 0][None, :] * u_ref[:, None] + Gk[0][None, :] * kappa[:, None]   # (T, 4)
    x_ref = np.zeros((kappa.size, 4))
    for k in range(kappa.size - 1):                  # one sequential recursion (T steps of a 4 x 4 product)
        x_ref[k + 1] = F[0] @ x_ref[k] + drive[k]
    return x_ref, u_ref


@dataclass(frozen=True, eq=False, repr=False)
class AlgebraicUncertainty:
    """Norm-bounded uncertainty of the RLQR^A design (paper's Appendix A).

    Attributes
    ----------
    H : (4, 1) ndarray
    EF : (1, 4) ndarray
    EG : (1, 2) ndarray
        For the doubled steering column.
    mu : float
        Penalty parameter (the appendix's ``(log10 mu)^2 = 81``, i.e. ``mu = 1e9``).
    source : str
        ``"computed"`` (from the model, :func:`algebraic_uncertainty`) or
        ``"printed"`` (the paper's values,
        :func:`robustctl.models.morais2022.algebraic_uncertainty`).
    """

    H: np.ndarray
    EF: np.ndarray
    EG: np.ndarray
    mu: float
    source: str

    def __repr__(self) -> str:
        with np.printoptions(precision=6, linewidth=120):
            return (f"AlgebraicUncertainty(source={self.source!r}, EF={self.EF.ravel()}, "
                    f"EG={self.EG.ravel()}, H={self.H.ravel()}, mu={self.mu:.3g})")


def algebraic_uncertainty(*, mu: float = 1e9, params: TruckParameters | None = None) -> AlgebraicUncertainty:
    """``H``, ``EF``, ``EG`` of RLQR^A computed from the model by the rule of the paper's Appendix A.

    With ``F_min, G_min`` the discretised model of the unloaded vehicle (mass
    ``m``) and ``F_max, G_max`` that at 100 % overload (``m + 2 payload``),
    ``Gamma_F = F_min - F_max``, ``Gamma_G = G_min - G_max``; the first row
    (lateral velocity, the one most affected by the mass) gives
    ``EF = [1, 1, 1, 0.1] .* Gamma_F[0, :]`` and
    ``EG = [0.1, 0.1] .* [Gamma_G[0], Gamma_G[0]]`` (the doubled column; the
    appendix's Eq. for E_G weights both entries by 0.1), ``H = [1, 1, 1, 1]^T``.
    With this model ``Gamma_F[0, 2] = Gamma_F[0, 3] = 0`` (lateral velocity does
    not depend on ``rho`` or ``theta``), so EF has zeros there.

    Parameters
    ----------
    mu : float
        The RLQR penalty parameter returned with them (the appendix's
        ``(log10 mu)^2 = 81``, ``mu = 1e9``, by default).
    params : TruckParameters, optional
        Defaults to the model's reference vehicle.

    Returns
    -------
    AlgebraicUncertainty
        ``source = "computed"``. The values the paper prints instead are
        :func:`robustctl.models.morais2022.algebraic_uncertainty`.
    """
    mu = check_positive_scalar(mu, "mu")
    p = _params(params)
    F, G, _ = _discrete_batch(p, np.array([0.0, 2.0]))
    gF = F[0] - F[1]
    gG = G[0] - G[1]
    EF = (np.array([1.0, 1.0, 1.0, 0.1]) * gF[0])[None, :]
    EG = (np.array([0.1, 0.1]) * gG[0, 0])[None, :]
    return AlgebraicUncertainty(frozen(np.ones((4, 1))), frozen(EF), frozen(EG), float(mu), "computed")


#: Acceptable errors of Bryson's rule: ydot 0.5 m/s, psidot 0.1 rad/s (5.7 deg/s),
#: rho 0.25 m (a quarter of the free space in a 3.5 m lane), theta 0.05 rad (2.9 deg).
MAX_ERRORS = (0.5, 0.1, 0.25, 0.05)
#: Acceptable steering angle of Bryson's rule [rad] (5.7 deg, well inside the 0.45 rad limit).
MAX_STEER = 0.1


def lqr_weights(*, doubled: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Bryson's-rule weights used for every truck design (LQR, RLQR, H-infinity).

    ``Q = diag(1 / MAX_ERRORS^2)``, ``R = 1 / MAX_STEER^2``: each state or the
    steering costs 1 when it reaches its acceptable value (Bryson & Ho, *Applied
    Optimal Control*, 1975, Sec. 5.4). With ``doubled=True`` (the doubled
    steering column, ``alpha = u1 + u2``) ``R = 2 r I_2``: the cheapest split
    of a steering angle ``alpha`` is ``u1 = u2 = alpha/2`` and costs
    ``2 r (alpha^2/4 + alpha^2/4) = r alpha^2``, the same as on the plain plant.

    Returns
    -------
    Q : (4, 4) ndarray
    R : (1, 1) or (2, 2) ndarray
    """
    Q = np.diag(1.0 / np.square(MAX_ERRORS))
    r = 1.0 / MAX_STEER**2
    return Q, (2.0 * r * np.eye(2) if doubled else np.array([[r]]))
