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

Sensors
-------
The paper's controllers feed back the whole state. The truck with sensors
(:func:`sensor_plant`) measures its yaw rate (a MEMS gyroscope) and its
lateral displacement and orientation error (RTK GNSS with dual-antenna
heading, against the map of the path), not its lateral velocity; the noise
levels, from data sheets, are :class:`TruckSensors`'.

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
    "SENSOR_NAMES", "SENSOR_OUTPUTS", "TruckSensors", "sensor_plant",
]

#: State names, in the model's order.
STATE_NAMES = ("ydot", "psidot", "rho", "theta")
#: Units of the states, in the model's order.
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
    r"""Parameters of the single-track truck model (paper's Table "Vehicle parameters values").

    The defaults are the paper's values [1]_ (:data:`PAPER_PARAMETERS`).

    Parameters
    ----------
    a, b, v, m, payload, J, c1, c2, dt : float
        The attributes below; each positive (``payload`` may be 0).

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

    Raises
    ------
    ValueError
        A parameter that is not positive and finite (``payload``: negative).

    See Also
    --------
    truck_plant : the discretised model at an overload.

    Notes
    -----
    At an overload of ``k`` percent the payload is ``payload (1 + k/100)``,
    spread like the vehicle's own mass (module docstring):

    .. math::

        m_{total}(k) = m + \text{payload}\,(1 + k/100), \qquad
        J_{total}(k) = J\, m_{total}(k) / m .

    References
    ----------
    .. [1] G. A. Prudencio de Morais et al., "Robust path-following control
       design of heavy vehicles based on multiobjective evolutionary
       optimization", Expert Systems with Applications 192, 116304, 2022,
       Table "Vehicle parameters values".

    Examples
    --------
    >>> from robustctl.models.truck import PAPER_PARAMETERS as p
    >>> round(p.wheelbase, 3), float(p.total_mass(100.0))
    (4.805, 41130.0)
    >>> bool(p.total_mass(100.0) == p.m + 2 * p.payload)
    True
    >>> bool(abs(p.inertia(100.0) / p.total_mass(100.0) - p.J / p.m) < 1e-12)     # same radius of gyration
    True
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
        """``m + payload (1 + overload/100)`` [kg].

        Parameters
        ----------
        overload : float
            Payload overload in percent (>= 0).

        Returns
        -------
        float
        """
        return self._mass(1.0 + check_overload(overload) / 100.0)

    def inertia(self, overload: float = 0.0) -> float:
        """``J m_total / m`` [kg m^2] (payload with the vehicle's radius of gyration).

        Parameters
        ----------
        overload : float
            Payload overload in percent (>= 0).

        Returns
        -------
        float
        """
        return self._inertia(1.0 + check_overload(overload) / 100.0)

    def _mass(self, load):
        return self.m + self.payload * np.asarray(load, dtype=float)

    def _inertia(self, load):
        return self.J * self._mass(load) / self.m


PAPER_PARAMETERS = TruckParameters()


def check_overload(overload, name: str = "overload") -> float | np.ndarray:
    """Return ``overload`` (percent, >= 0, finite) as float or float array; raise otherwise.

    Parameters
    ----------
    overload : float or array_like
        Payload overload in percent (0 = nominal payload).
    name : str
        The argument's name in the messages.

    Returns
    -------
    float or ndarray
        A float for a scalar, a float array otherwise.

    Raises
    ------
    TypeError
        Not a number (a string, a boolean, None).
    ValueError
        Negative or non-finite.

    Examples
    --------
    >>> from robustctl.models.truck import check_overload
    >>> check_overload(50), check_overload([0, 100]).tolist()
    (50.0, [0.0, 100.0])
    >>> check_overload(-10)
    Traceback (most recent call last):
    ...
    ValueError: overload must be >= 0 percent (0 = nominal payload), got -10
    """
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
    r"""Continuous-time matrices ``x' = A x + B alpha + E kappa`` at ``overload`` percent.

    Parameters
    ----------
    overload : float
        Payload overload in percent (0 = nominal payload).
    params : TruckParameters, optional
        Defaults to the paper's parameters.

    Returns
    -------
    A : (4, 4) ndarray
        State matrix (Notes).
    B : (4, 1) ndarray
        Steering input column ``[c1/m, a c1/J, 0, 0]^T``.
    E : (4,) ndarray
        Path-curvature input ``[0, 0, 0, -v]^T`` (``kappa`` in 1/m, positive to the left).

    Raises
    ------
    ValueError, TypeError
        A negative or non-numeric overload.

    See Also
    --------
    truck_plant : the zero-order hold of this model.

    Notes
    -----
    The single-track model of the paper's Eq. 1 [1]_ with its two typos
    corrected (module docstring), ``m`` and ``J`` at the overload:

    .. math::

        A = \begin{bmatrix}
        -\frac{c_1 + c_2}{m v} & \frac{b c_2 - a c_1 - m v^2}{m v} & 0 & 0 \\
        \frac{b c_2 - a c_1}{J v} & -\frac{a^2 c_1 + b^2 c_2}{J v} & 0 & 0 \\
        1 & 0 & 0 & v \\
        0 & 1 & 0 & 0 \end{bmatrix}, \qquad
        B = \begin{bmatrix} c_1 / m \\ a c_1 / J \\ 0 \\ 0 \end{bmatrix}, \qquad
        E = \begin{bmatrix} 0 \\ 0 \\ 0 \\ -v \end{bmatrix}.

    References
    ----------
    .. [1] G. A. Prudencio de Morais et al., "Robust path-following control
       design of heavy vehicles based on multiobjective evolutionary
       optimization", Expert Systems with Applications 192, 116304, 2022,
       Eq. 1.

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.models.truck import PAPER_PARAMETERS as p, continuous_model
    >>> A, B, E = continuous_model(0.0)
    >>> m, J = p.m + p.payload, p.J * (p.m + p.payload) / p.m
    >>> bool(np.isclose(A[1, 1], -(p.a**2 * p.c1 + p.b**2 * p.c2) / (J * p.v)))
    True
    >>> bool(np.allclose(B[:2, 0], [p.c1 / m, p.a * p.c1 / J]))
    True
    """
    p = _params(params)
    A, B, E = _continuous_batch(p, 1.0 + check_overload(overload) / 100.0)
    return A[0], B[0], E


def truck_plant(overload: float = 0.0, *, params: TruckParameters | None = None,
                doubled: bool = False) -> Plant:
    r"""The truck discretised with zero-order hold at ``params.dt`` (0.1 s).

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

    Raises
    ------
    ValueError, TypeError
        A negative or non-numeric overload, ``params`` not a TruckParameters.

    See Also
    --------
    continuous_model : the continuous-time matrices.
    discretise : many overloads at once, with the curvature input.

    Notes
    -----
    The zero-order hold of ``(A, B)`` of :func:`continuous_model`,

    .. math::

        \exp\left(\begin{bmatrix} A & B \\ 0 & 0 \end{bmatrix} dt\right) =
        \begin{bmatrix} F & G \\ 0 & I \end{bmatrix},

    for the ZOH model of the paper [1]_ (``dt`` = 0.1 s).

    References
    ----------
    .. [1] G. A. Prudencio de Morais et al., "Robust path-following control
       design of heavy vehicles based on multiobjective evolutionary
       optimization", Expert Systems with Applications 192, 116304, 2022.

    Examples
    --------
    The plant is python-control's zero-order hold of the continuous model:

    >>> import numpy as np, control
    >>> from robustctl.models.truck import continuous_model, truck_plant
    >>> plant = truck_plant(100.0)
    >>> plant
    Plant(n=4, m=1, dt=0.1)
    >>> A, B, _ = continuous_model(100.0)
    >>> ref = control.c2d(control.ss(A, B, np.eye(4), 0), 0.1, "zoh")
    >>> bool(np.allclose(plant.F, ref.A) and np.allclose(plant.G, ref.B))
    True
    >>> truck_plant(0.0, doubled=True).G.shape       # alpha = u1 + u2
    (4, 2)
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
    r"""ZOH discretisation at many overloads at once, with the curvature input.

    ``x[k+1] = F x[k] + G alpha[k] + Gk kappa[k]`` with ``alpha`` and ``kappa``
    held constant over each sample (exact for piecewise-constant signals).

    Parameters
    ----------
    overloads : float or (k,) array_like
        Overloads in percent (>= 0).
    params : TruckParameters, optional
        Defaults to the paper's parameters.

    Returns
    -------
    F : (k, 4, 4) ndarray
        State matrices.
    G : (k, 4, 1) ndarray
        Steering input columns.
    Gk : (k, 4) ndarray
        Discretised curvature input.

    Raises
    ------
    ValueError, TypeError
        Negative or non-numeric overloads, more than one axis.

    See Also
    --------
    truck_plant : one overload as a :class:`~robustctl.Plant`.

    Notes
    -----
    With ``E`` the curvature input of :func:`continuous_model`,

    .. math::

        \exp\left(\begin{bmatrix} A & B & E \\ 0 & 0 & 0 \\ 0 & 0 & 0 \end{bmatrix} dt\right) =
        \begin{bmatrix} F & G & G_\kappa \\ 0 & I & 0 \\ 0 & 0 & 1 \end{bmatrix},

    for every overload at once (a stack of matrix exponentials).

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> from robustctl.models.truck import continuous_model, discretise
    >>> F, G, Gk = discretise([0.0, 300.0])
    >>> F.shape, G.shape, Gk.shape
    ((2, 4, 4), (2, 4, 1), (2, 4))
    >>> A, B, E = continuous_model(300.0)
    >>> Fd, BEd, *_ = scipy.signal.cont2discrete((A, np.c_[B, E], np.eye(4), np.zeros((4, 2))), 0.1)
    >>> bool(np.allclose(F[1], Fd) and np.allclose(G[1, :, 0], BEd[:, 0]) and np.allclose(Gk[1], BEd[:, 1]))
    True
    """
    p = _params(params)
    ov = np.atleast_1d(check_overload(overloads, "overloads"))
    if ov.ndim != 1:
        raise ValueError(f"overloads must be a scalar or a 1-D array, got shape {ov.shape}")
    return _discrete_batch(p, 1.0 + ov / 100.0)


def steady_state_cornering(overload: float = 0.0, *, params: TruckParameters | None = None
                           ) -> tuple[np.ndarray, float]:
    r"""State and steering per unit curvature in steady cornering on the path.

    Solves ``A x + B alpha + E kappa = 0`` with ``rho = 0`` for ``kappa = 1``:
    ``psidot = v kappa`` (row 4), ``theta = -ydot / v`` (row 3, the body's
    sideslip: the heading differs from the path tangent by minus the slip
    angle) and rows 1-2 give ``ydot`` and ``alpha`` (Ackermann angle
    ``L kappa`` plus the understeer term). Because ZOH keeps equilibria, this is
    also a fixed point of the discretised model.

    Parameters
    ----------
    overload : float
        Payload overload in percent.
    params : TruckParameters, optional
        Defaults to the paper's parameters.

    Returns
    -------
    x_per_kappa : (4,) ndarray
        ``[ydot, psidot, rho, theta]`` per 1/m of curvature.
    alpha_per_kappa : float
        Steady-state steering angle per 1/m of curvature [rad m].

    Raises
    ------
    ValueError, TypeError
        A negative or non-numeric overload.

    See Also
    --------
    reference_states : the reference along a curvature signal.

    Notes
    -----
    The equilibrium of :func:`continuous_model` on a path of constant
    curvature ``kappa = 1`` with ``rho = 0``:

    .. math::

        A x + B \alpha + E = 0, \qquad \dot\psi = v, \quad \theta = -\dot y / v .

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.models.truck import continuous_model, steady_state_cornering
    >>> x, alpha = steady_state_cornering(0.0)
    >>> A, B, E = continuous_model(0.0)
    >>> bool(np.allclose(A @ x + B[:, 0] * alpha + E, 0.0, atol=1e-12))
    True
    >>> alpha > 4.805          # more than the Ackermann angle (wheelbase * kappa): the truck understeers
    True
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
    overload : float
        Payload of the model the reference is computed on, in percent.
    params : TruckParameters, optional
        Defaults to the paper's parameters.

    Returns
    -------
    x_ref : (T, 4) ndarray
        Reference states, ``x_per_kappa kappa[k]``.
    alpha_ff : (T,) ndarray
        Steering feedforward [rad], ``alpha_per_kappa kappa[k]``.

    Raises
    ------
    ValueError, TypeError
        ``kappa`` not a finite 1-D array, a bad overload.

    See Also
    --------
    open_loop_reference : the reference of the authors' code.

    Examples
    --------
    On a constant curvature the reference is a fixed point of the
    discretised model driven by its feedforward (ZOH keeps equilibria):

    >>> import numpy as np
    >>> from robustctl.models.truck import discretise, reference_states
    >>> x_ref, alpha_ff = reference_states([0.002, 0.002])
    >>> F, G, Gk = discretise(0.0)
    >>> bool(np.allclose(F[0] @ x_ref[1] + G[0, :, 0] * alpha_ff[1] + Gk[0] * 0.002, x_ref[1]))
    True
    """
    kappa = as_batch(kappa, "kappa", (None,))
    xk, ak = steady_state_cornering(overload, params=params)
    return kappa[:, None] * xk[None, :], ak * kappa


def open_loop_reference(kappa, overload: float = 0.0, *, params: TruckParameters | None = None
                        ) -> tuple[np.ndarray, np.ndarray]:
    r"""The truck at ``overload`` driven open loop by its steady-cornering steering along a path.

    The reference of the authors' published code (Barbosa et al. 2019 [1]_, GitHub
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

    params : TruckParameters, optional
        Defaults to the paper's parameters.

    Returns
    -------
    x_ref : (T, 4) ndarray
        States ``[ydot, psidot, rho, theta]`` of the open-loop vehicle.
    u_ref : (T,) ndarray
        The steering command [rad].

    Raises
    ------
    ValueError, TypeError
        ``kappa`` not a finite 1-D array, a bad overload.

    See Also
    --------
    reference_states : the steady-cornering reference.
    robustctl.models.morais2022.code_manoeuvre : the manoeuvre of the authors' code.

    References
    ----------
    .. [1] F. M. Barbosa, L. B. Marcos, M. M. da Silva, M. H. Terra,
       V. Grassi Jr, "Robust path-following control for articulated
       heavy-duty vehicles", Control Engineering Practice 85, 246-256, 2019,
       and its code, https://github.com/barbosafilipe/robust_lqr.

    Examples
    --------
    A straight then a constant bend; the reference obeys the recursion of
    the ZOH model, written out here:

    >>> import numpy as np
    >>> from robustctl.models.truck import discretise, open_loop_reference
    >>> kappa = np.r_[np.zeros(5), np.full(20, 0.002)]
    >>> x_ref, u_ref = open_loop_reference(kappa)
    >>> F, G, Gk = discretise(0.0)
    >>> x = np.zeros(4)
    >>> for k in range(24):
    ...     x = F[0] @ x + G[0, :, 0] * u_ref[k] + Gk[0] * kappa[k]
    >>> bool(np.allclose(x, x_ref[-1]))
    True
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

    Parameters
    ----------
    H, EF, EG, mu, source
        The attributes below.

    Attributes
    ----------
    H : (4, 1) ndarray
        Input matrix of the uncertainty.
    EF : (1, 4) ndarray
        State part.
    EG : (1, 2) ndarray
        Input part, for the doubled steering column.
    mu : float
        Penalty parameter (the appendix's ``(log10 mu)^2 = 81``, i.e. ``mu = 1e9``).
    source : str
        ``"computed"`` (from the model, :func:`algebraic_uncertainty`) or
        ``"printed"`` (the paper's values,
        :func:`robustctl.models.morais2022.algebraic_uncertainty`).

    See Also
    --------
    algebraic_uncertainty : computes it.

    Examples
    --------
    Its matrices make a :class:`~robustctl.NormBounded` of the doubled-column plant:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.models.truck import algebraic_uncertainty, truck_plant
    >>> au = algebraic_uncertainty()
    >>> unc = rc.NormBounded(au.H, au.EF, au.EG)
    >>> unc.check_plant(truck_plant(0.0, doubled=True))       # passes: the sizes fit
    >>> unc
    NormBounded(n=4, m=2, p=1, l=1)
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
    r"""``H``, ``EF``, ``EG`` of RLQR^A computed from the model by the rule of the paper's Appendix A.

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

    Raises
    ------
    ValueError, TypeError
        ``mu`` not a positive number, ``params`` not a TruckParameters.

    Notes
    -----
    With the unloaded (``min``) and the 100 %-overloaded (``max``) ZOH
    models [1]_:

    .. math::

        E_F = [1, 1, 1, 0.1] \circ (F_{min} - F_{max})_{1,:}, \qquad
        E_G = 0.1\, (G_{min} - G_{max})_{1} [1, 1], \qquad H = [1, 1, 1, 1]^T .

    References
    ----------
    .. [1] G. A. Prudencio de Morais et al., "Robust path-following control
       design of heavy vehicles based on multiobjective evolutionary
       optimization", Expert Systems with Applications 192, 116304, 2022,
       Appendix A.

    Examples
    --------
    The rule applied here by hand to the unloaded truck (no payload) and
    the truck at 100 % overload:

    >>> import numpy as np
    >>> from robustctl.models.truck import TruckParameters, algebraic_uncertainty, truck_plant
    >>> au = algebraic_uncertainty()
    >>> unloaded, heavy = truck_plant(0.0, params=TruckParameters(payload=0.0)), truck_plant(100.0)
    >>> bool(np.allclose(au.EF[0], [1.0, 1.0, 1.0, 0.1] * (unloaded.F - heavy.F)[0]))
    True
    >>> bool(np.allclose(au.EG[0], 0.1 * (unloaded.G - heavy.G)[0, 0]))
    True
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
    r"""Bryson's-rule weights used for every truck design (LQR, RLQR, H-infinity).

    ``Q = diag(1 / MAX_ERRORS^2)``, ``R = 1 / MAX_STEER^2``: each state or the
    steering costs 1 when it reaches its acceptable value (Bryson & Ho, *Applied
    Optimal Control*, 1975, Sec. 5.4). With ``doubled=True`` (the doubled
    steering column, ``alpha = u1 + u2``) ``R = 2 r I_2``: the cheapest split
    of a steering angle ``alpha`` is ``u1 = u2 = alpha/2`` and costs
    ``2 r (alpha^2/4 + alpha^2/4) = r alpha^2``, the same as on the plain plant.

    Parameters
    ----------
    doubled : bool
        Weights for the doubled steering column (two inputs).

    Returns
    -------
    Q : (4, 4) ndarray
        ``diag(1 / MAX_ERRORS^2)``.
    R : (1, 1) or (2, 2) ndarray
        ``1 / MAX_STEER^2``, or ``2 / MAX_STEER^2 I_2`` for the doubled column.

    Notes
    -----
    Bryson's rule [1]_: each term of the cost is 1 at its acceptable value,

    .. math::

        Q_{ii} = \frac{1}{x_{i,\max}^2}, \qquad R = \frac{1}{\alpha_{\max}^2} .

    References
    ----------
    .. [1] A. E. Bryson, Y.-C. Ho, *Applied Optimal Control*, Hemisphere
       1975, Sec. 5.4.

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.models.truck import MAX_ERRORS, MAX_STEER, lqr_weights
    >>> Q, R = lqr_weights()
    >>> bool(np.allclose(np.diag(Q) * np.square(MAX_ERRORS), 1.0) and np.isclose(R[0, 0] * MAX_STEER**2, 1.0))
    True

    On the doubled column the even split ``u1 = u2 = alpha / 2`` costs what
    ``alpha`` costs on the plain truck:

    >>> _, R2 = lqr_weights(doubled=True)
    >>> half = np.array([0.5, 0.5])
    >>> bool(np.isclose(half @ R2 @ half, R[0, 0]))
    True
    """
    Q = np.diag(1.0 / np.square(MAX_ERRORS))
    r = 1.0 / MAX_STEER**2
    return Q, (2.0 * r * np.eye(2) if doubled else np.array([[r]]))


# -- sensors ----------------------------------------------------------------------------------

#: The measured states of the truck with sensors, in the order of :data:`SENSOR_OUTPUTS`:
#: the yaw rate (gyroscope), the lateral displacement and the orientation error (RTK GNSS
#: position and dual-antenna heading against the map of the path). The lateral velocity is not measured.
SENSOR_NAMES = ("psidot", "rho", "theta")
#: State index of each measured output (:data:`STATE_NAMES` order).
SENSOR_OUTPUTS = (1, 2, 3)
# CEP = sigma sqrt(2 ln 2) for a circular normal (the median of a Rayleigh law); the median
# of |e| for a normal e is sigma times the normal quantile 0.75.
_CEP_PER_SIGMA = float(np.sqrt(2.0 * np.log(2.0)))
_MEDIAN_ABS_PER_SIGMA = 0.6744897501960817


@dataclass(frozen=True)
class TruckSensors:
    r"""Noise levels of the truck's sensors, from published data sheets (the defaults).

    The truck measures its yaw rate with a MEMS gyroscope and its lateral
    displacement ``rho`` and orientation error ``theta`` with an RTK GNSS
    receiver pair with dual-antenna heading, against a map of the path
    (:data:`SENSOR_NAMES`); the lateral velocity is not measured.
    :meth:`covariance` turns the data-sheet figures into the covariance of
    the white measurement noise sampled every ``dt``.

    Parameters
    ----------
    gyro_noise_density, position_cep, heading_error_50 : float
        The attributes below; each positive and finite.

    Attributes
    ----------
    gyro_noise_density : float
        Rate noise density of the gyroscope [deg/s/sqrt(Hz)]. Default
        ``5e-3``: 5 mdps/sqrt(Hz), the ST ISM330DHCX 6-axis MEMS IMU
        (industrial grade, -40 to +105 degC) [1]_ (Table 3, ``Rn``,
        high-performance mode, independent of the range and the output
        rate).
    position_cep : float
        Horizontal position error of the RTK fix, circular error probable
        [m] (the radius that holds half of the fixes). Default ``0.02``: the
        u-blox ZED-F9P's ``0.01 m + 1 ppm CEP`` [2]_ at 10 km from the base
        station.
    heading_error_50 : float
        Heading error that half of the fixes stay within [deg]. Default
        ``0.4``: the u-blox ZED-F9H rover on a ZED-F9P moving base, ``0.4
        deg 50 %`` for a 1 m antenna baseline [3]_ (the error falls about
        as one over the baseline).

    Raises
    ------
    ValueError, TypeError
        A level that is not a positive finite number.

    See Also
    --------
    sensor_plant : the truck with these outputs.

    Notes
    -----
    Each sensor's error is taken white, independent of the others and of
    zero mean: the gyroscope's bias is taken calibrated (it is estimated at
    standstill in practice) and the slow, correlated part of the RTK
    errors is not modelled. The standard deviations of one sample, sampled
    every ``dt`` [s]:

    * the gyroscope averaged over the sample (equivalent noise bandwidth
      ``1 / (2 dt)``): :math:`\sigma_{\dot\psi} = N_\omega / \sqrt{2\,dt}`;
    * one horizontal axis of a circular normal position error, whose CEP is
      the median of a Rayleigh law: :math:`\sigma_\rho = CEP / \sqrt{2 \ln 2}`;
    * a normal heading error whose absolute value has the median
      :math:`h_{50}`: :math:`\sigma_\theta = h_{50} / \Phi^{-1}(0.75)`,
      :math:`\Phi^{-1}(0.75) = 0.6745`.

    The default levels give, at ``dt = 0.1`` s, :math:`\sigma_{\dot\psi} =
    1.95 \cdot 10^{-4}` rad/s, :math:`\sigma_\rho = 0.0170` m and
    :math:`\sigma_\theta = 0.0103` rad (0.59 deg).

    References
    ----------
    .. [1] STMicroelectronics, "ISM330DHCX: iNEMO inertial module with
       machine learning core", datasheet DS13012, Rev 6, Table 3.
    .. [2] u-blox, "ZED-F9P high precision GNSS module, Integration
       manual", UBX-18010802, Sec. 2.1.2 (RTK: 0.01 m + 1 ppm CEP).
    .. [3] u-blox, "ZED-F9H u-blox F9 module for heading applications,
       Integration manual", UBX-19030120, R05, 2022, Sec. 2.1.1 (0.4 deg
       50 % for 1 m baseline).

    Examples
    --------
    The standard deviations at the paper's 0.1 s sampling, checked against
    scipy's Rayleigh and half-normal laws (the CEP and the 50 % heading
    error are their medians):

    >>> import numpy as np
    >>> from scipy import stats
    >>> from robustctl.models.truck import TruckSensors
    >>> sensors = TruckSensors()
    >>> s_gyro, s_rho, s_theta = sensors.std(0.1)
    >>> bool(np.isclose(stats.rayleigh.median(scale=s_rho), sensors.position_cep))
    True
    >>> bool(np.isclose(np.degrees(stats.halfnorm.median(scale=s_theta)), sensors.heading_error_50))
    True
    >>> bool(np.isclose(np.degrees(s_gyro), 5e-3 / np.sqrt(0.2)))
    True
    >>> sensors.covariance(0.1).shape
    (3, 3)
    """

    gyro_noise_density: float = 5e-3
    position_cep: float = 0.02
    heading_error_50: float = 0.4

    def __post_init__(self):
        for f in fields(self):
            check_positive_scalar(getattr(self, f.name), f.name)

    def std(self, dt: float) -> np.ndarray:
        """Standard deviations of one sample of ``[psidot, rho, theta]`` [rad/s, m, rad] (class Notes).

        Parameters
        ----------
        dt : float
            Sampling time [s].

        Returns
        -------
        (3,) ndarray
            In the order of :data:`SENSOR_NAMES`.

        Raises
        ------
        ValueError, TypeError
            ``dt`` not a positive number.
        """
        dt = check_positive_scalar(dt, "dt")
        return np.array([np.radians(self.gyro_noise_density) / np.sqrt(2.0 * dt),
                         self.position_cep / _CEP_PER_SIGMA,
                         np.radians(self.heading_error_50) / _MEDIAN_ABS_PER_SIGMA])

    def covariance(self, dt: float) -> np.ndarray:
        """The measurement noise covariance ``V = diag(std(dt)**2)`` (3, 3) of :func:`sensor_plant`'s outputs.

        Parameters
        ----------
        dt : float
            Sampling time [s].

        Returns
        -------
        (3, 3) ndarray
            Diagonal: the sensors' errors are independent.

        Raises
        ------
        ValueError, TypeError
            ``dt`` not a positive number.
        """
        return np.diag(self.std(dt) ** 2)


def sensor_plant(overload: float = 0.0, *, params: TruckParameters | None = None) -> Plant:
    r"""The truck of :func:`truck_plant` with its measured outputs ``y = [psidot, rho, theta]``.

    Parameters
    ----------
    overload : float
        Payload overload in percent.
    params : TruckParameters, optional
        Defaults to the paper's parameters.

    Returns
    -------
    Plant
        ``F``, ``G`` of :func:`truck_plant` (one steering input) and ``C``
        (3, 4) selecting the states :data:`SENSOR_OUTPUTS`; ``D = 0``. The
        noise levels of the outputs are :class:`TruckSensors`'.

    Raises
    ------
    ValueError, TypeError
        As :func:`truck_plant`.

    See Also
    --------
    TruckSensors : the measurement noise.
    robustctl.kalman : a filter of these outputs.

    Notes
    -----
    .. math::

        y_k = C x_k + v_k, \qquad C = \begin{bmatrix} 0 & 1 & 0 & 0 \\
        0 & 0 & 1 & 0 \\ 0 & 0 & 0 & 1 \end{bmatrix},

    so the lateral velocity is seen only through the dynamics: ``(C, F)``
    is observable (``rho' = ydot + v theta``).

    Examples
    --------
    The outputs see every state: the observability matrix has full rank
    (python-control's ``obsv``):

    >>> import numpy as np, control
    >>> from robustctl.models.truck import sensor_plant
    >>> plant = sensor_plant(100.0)
    >>> plant
    Plant(n=4, m=1, p=3, dt=0.1)
    >>> int(np.linalg.matrix_rank(control.obsv(plant.F, plant.C)))
    4
    """
    plant = truck_plant(overload, params=params)
    return Plant(plant.F, plant.G, plant.dt, C=np.eye(4)[list(SENSOR_OUTPUTS)])
