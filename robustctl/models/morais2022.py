"""The data and set-ups of Morais et al. (2022) and of the authors' public code, Barbosa et al. (2019).

Everything specific to the paper lives here; the general library (the truck
model :mod:`robustctl.models.truck`, the paths :mod:`robustctl.models.path`, the
path-following simulator :mod:`robustctl.models.pathfollow` and the designs) names
none of it and does not import this module. The truck MOP
(:mod:`moo.problems.applied`, :mod:`moo.problems.selection`) and the
``paper_repro`` scripts do.

The paper's printed values
--------------------------
* :data:`RLQR_MOP_Z`: the RLQR^MOP decision vector ``z*`` of Section 4.5.2.1,
  ``[EF (4), EG (2), (log10 mu)^2]`` (decoded by :func:`uncertainty_from_z`).
* :data:`PRINTED_EF`, :data:`PRINTED_EG`, :data:`PRINTED_LOG10_MU_SQ`: the
  RLQR^A uncertainty of Appendix A as printed (Section 4.5, after Eq. 18);
  :func:`algebraic_uncertainty` returns it, or the one the appendix's rule
  gives on the model (:func:`robustctl.models.truck.algebraic_uncertainty`).
  The printed values do not follow from the paper's own parameters (their
  ``EF[3] = -6.67e-3`` cannot arise from Eq. 1).
* :data:`PRINTED_MSE`: the paper's MSE table (Section 4.5.2), ``f1..f4`` of
  the four controllers at 0, 100, 200 and 300 % overload.

The authors' code
-----------------
Barbosa et al. (2019), GitHub ``barbosafilipe/robust_lqr``, read and mapped to
the 4-state truck ``[ydot, psidot, rho, theta]`` (the code's articulation
states dropped): the weights ``Q = diag(1, 1, 25000, 100)``, ``R = 67070 I2``
on the doubled steering column (:data:`AUTHORS_Q_DIAG`,
:data:`AUTHORS_R_DOUBLED`, :func:`authors_weights`;
``standard_formulation/parameters.m``, ``alternative_formulation/model.m``),
the initial state :data:`AUTHORS_X0` (same files), RLQR^A's ``E_G``
(:data:`CODE_EG`, where the paper prints two equal entries), the
game-Riccati level of its H-infinity law (:data:`CODE_GAMMA`,
``standard_formulation/h_infinity.m``) and its 30 s reference manoeuvre
(:func:`code_manoeuvre`).

Set-ups
-------
The paper states neither its reference, its initial state nor its weights.
:data:`SETUPS` holds the two :class:`~robustctl.models.pathfollow.PathFollowingSetup`
of the reproduction (:func:`get_setup` by name):

``"ours"`` (the engineering set-up)
    The simulator's default, :data:`robustctl.models.pathfollow.DEFAULT_SETUP`:
    ``x_ref`` and ``alpha_ff`` are the nominal model's steady cornering along
    the path (:func:`robustctl.models.truck.reference_states`; ``x_ref =
    [beta_1 v, v, 0, -beta_1] kappa``), with the steady-state steering as
    feedforward: the nominal plant follows a constant-curvature path with
    zero error, and errors come from transients, the initial offset and the
    payload mismatch; every state is a *tracking* error. Bryson's weights
    (:func:`robustctl.models.truck.lqr_weights`) and a 1 m initial offset.
``"authors"`` (the set-up of the authors' published code)
    ``u = K (x - x_ref)`` with no steering feedforward and ``x_ref = [0, 0,
    rho_ref, theta_ref]`` (``standard_formulation/main.m``: the lateral
    velocity and the yaw rate are regulated to zero, the paper's
    "regulation errors" f2-f4), the reference ``rho_ref, theta_ref`` of the
    nominal truck driven open loop by a smooth steering command
    (``standard_formulation/parameters.m``; here the path's steady-cornering
    steering, :func:`robustctl.models.truck.open_loop_reference`), the
    initial state ``[0, 0, 0.3, -0.1]`` and the weights ``Q = diag(1, 1,
    25000, 100)``, ``R = 67070 I2`` on the doubled column.

The truck with sensors
----------------------
The paper's controllers on the truck that measures its yaw rate, lateral
displacement and orientation error (:func:`robustctl.models.truck.sensor_plant`,
noise :class:`robustctl.models.truck.TruckSensors`) and feeds back an
estimate (``paper_repro/mse_table_sensors.py``). The filters' process noise,
:func:`sensor_filter_noise`, is a steering disturbance as large as the
payload mismatch of the table (0-300 %) makes the steady steering in the
path's tightest bend; the robust filter's uncertainty is the appendix's
printed model (:func:`algebraic_uncertainty`, ``H``, ``EF`` and one of the
equal ``EG`` entries on the single steering input).

Not taken from the code: its sampling time (0.01 s; the paper's 0.1 s is
kept), its Tustin discretisation (ZOH kept), its per-column saturation at
0.22 rad (the paper's 0.45 rad on the steering angle is kept), its
30 s manoeuvre on a straight road (the path is a parameter; the default
route is ours, :func:`code_manoeuvre` gives the code's) and its RLQR gains
recomputed online from ``P = I`` (the controllers here are steady-state
gains; its gains settle within seconds).

References
----------
G. A. Prudencio de Morais, L. B. Marcos, F. M. Barbosa, B. H. G. Barbosa,
M. H. Terra & V. Grassi Jr, "Robust path-following control design of heavy vehicles based on
multiobjective evolutionary optimization", *Expert Systems with Applications*
192 (2022) 116304.
F. M. Barbosa, L. B. Marcos, M. M. da Silva, M. H. Terra & V. Grassi Jr,
"Robust path-following control for articulated heavy-duty vehicles",
*Control Engineering Practice* 85 (2019) 246-256, and its code,
https://github.com/barbosafilipe/robust_lqr.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .._validation import as_batch, check_choice, frozen
from . import truck
from .path import LaneChange, ReferencePath, Straight, default_route
from .pathfollow import DEFAULT_SETUP, PathFollowingSetup

__all__ = [
    "RLQR_MOP_Z", "PRINTED_EF", "PRINTED_EG", "PRINTED_LOG10_MU_SQ", "algebraic_uncertainty",
    "uncertainty_from_z", "AUTHORS_Q_DIAG", "AUTHORS_R_DOUBLED", "AUTHORS_X0", "CODE_EG", "CODE_GAMMA",
    "authors_weights", "code_manoeuvre", "SETUPS", "get_setup", "MSE_OVERLOADS", "MSE_OBJECTIVES",
    "MSE_CONTROLLERS", "PRINTED_MSE", "sensor_filter_noise",
]

# -- the paper's printed values ---------------------------------------------------------------

#: RLQR^A uncertainty as printed in the paper (Section 4.5, after Eq. 18).
PRINTED_EF = (6.85718e-4, -8.62010e-4, 0.0, -6.6666e-3)
PRINTED_EG = (-6.66666e-3, -6.66666e-3)
PRINTED_LOG10_MU_SQ = 81.0
#: RLQR^MOP decision vector z* printed in Section 4.5.2.1: [EF (4), EG (2), (log10 mu)^2].
RLQR_MOP_Z = (4.45032, 57.84300, 21.90069, 455.67736, 48.05012, 44.98551, 280.28421)


def algebraic_uncertainty(source: str = "printed", *, params: truck.TruckParameters | None = None
                          ) -> truck.AlgebraicUncertainty:
    """``H``, ``EF``, ``EG`` and ``mu`` of RLQR^A (Appendix A of the paper), printed or computed.

    ``source="printed"`` returns the values the paper prints, which do not
    follow from its own parameters (its ``EF[3] = -6.67e-3`` cannot arise from
    Eq. 1): ``EF = [6.85718e-4, -8.62010e-4, 0, -6.6666e-3]``,
    ``EG = [-6.66666e-3, -6.66666e-3]``, ``H = [1, 1, 1, 1]^T``.
    ``source="computed"`` applies the appendix's rule to the model
    (:func:`robustctl.models.truck.algebraic_uncertainty`, with ``params``).
    Both use the printed ``(log10 mu)^2 = 81``, ``mu = 1e9``.

    Parameters
    ----------
    source : {"printed", "computed"}
        The paper's printed values, or the rule of its Appendix A applied to the model.
    params : TruckParameters, optional
        The model's parameters for ``"computed"`` (default the paper's).

    Returns
    -------
    AlgebraicUncertainty
        ``H``, ``EF``, ``EG``, ``mu`` and ``source``.

    Raises
    ------
    ValueError, TypeError
        An unknown ``source``.

    See Also
    --------
    robustctl.models.truck.algebraic_uncertainty : the rule on the model.

    References
    ----------
    .. [1] G. A. Prudencio de Morais et al., "Robust path-following control
       design of heavy vehicles based on multiobjective evolutionary
       optimization", Expert Systems with Applications 192, 116304, 2022,
       Section 4.5 and Appendix A.

    Examples
    --------
    The printed ``EF[3]`` is not zero, while the model's lateral velocity
    does not depend on ``theta`` (column 4 of row 1 of ``F`` is the same
    at every payload [1]_):

    >>> import numpy as np
    >>> from robustctl.models import morais2022, truck
    >>> printed = morais2022.algebraic_uncertainty()
    >>> computed = morais2022.algebraic_uncertainty("computed")
    >>> printed.mu, float(printed.EF[0, 3]), float(computed.EF[0, 3])
    (1000000000.0, -0.0066666, 0.0)
    >>> F = truck.discretise([0.0, 100.0])[0]
    >>> bool(F[0, 0, 3] == F[1, 0, 3] == 0.0)
    True
    """
    check_choice(source, "source", ("printed", "computed"))
    mu = 10.0 ** np.sqrt(PRINTED_LOG10_MU_SQ)
    if source == "computed":
        return truck.algebraic_uncertainty(mu=mu, params=params)
    return truck.AlgebraicUncertainty(frozen(np.ones((4, 1))), frozen(np.array([PRINTED_EF])),
                                      frozen(np.array([PRINTED_EG])), float(mu), "printed")


def uncertainty_from_z(z) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Decode the applied MOP's decision vectors ``z = [EF (4), EG (2), (log10 mu)^2]``.

    Parameters
    ----------
    z : (7,) or (B, 7) array_like
        ``z[6] = (log10 mu)^2 >= 0``, so ``mu = 10**sqrt(z[6])`` (the sign of
        ``log10 mu`` is taken positive, ``mu >= 1``).

    Returns
    -------
    EF : (B, 1, 4) ndarray
        ``z[:4]``.
    EG : (B, 1, 2) ndarray
        ``z[4:6]``.
    mu : (B,) ndarray
        ``10**sqrt(z[6])``. With ``H = ones((4, 1))`` they define the RLQR
        design on the doubled-column plant (``truck_plant(doubled=True)``).
        A single z gives B = 1.

    Raises
    ------
    ValueError
        Not 7 entries per vector, non-finite entries, ``z[6] < 0``.
    TypeError
        A string or other non-numeric input.

    Examples
    --------
    The paper's ``z*`` of RLQR^MOP:

    >>> import math
    >>> from robustctl.models.morais2022 import RLQR_MOP_Z, uncertainty_from_z
    >>> EF, EG, mu = uncertainty_from_z(RLQR_MOP_Z)
    >>> EF.shape, EG.shape, EG.ravel().tolist()
    ((1, 1, 4), (1, 1, 2), [48.05012, 44.98551])
    >>> bool(math.isclose(mu[0], 10 ** math.sqrt(280.28421)))
    True
    """
    Z = np.asarray(z, dtype=float) if not isinstance(z, (str, bytes)) else None
    if Z is None:
        raise TypeError("z must be an array of numbers, got str")
    Z = as_batch(Z[None] if Z.ndim == 1 else Z, "z", (None, 7), ("", "EF (4), EG (2), (log10 mu)^2"))
    if np.any(Z[:, 6] < 0):
        raise ValueError(f"z[6] = (log10 mu)^2 must be >= 0, got {Z[:, 6].min():g}")
    return Z[:, None, :4].copy(), Z[:, None, 4:6].copy(), 10.0 ** np.sqrt(Z[:, 6])


#: Overloads [%], objectives and controllers of the paper's MSE table (Section 4.5.2).
MSE_OVERLOADS = (0, 100, 200, 300)
MSE_OBJECTIVES = ("f1", "f2", "f3", "f4")
MSE_CONTROLLERS = ("RLQR_MOP", "RLQR_A", "Hinf", "LQR")
#: The paper's MSE table: ``PRINTED_MSE[objective][controller]`` at the overloads
#: :data:`MSE_OVERLOADS`. f1 lateral displacement (rho), f2 yaw-rate error, f3
#: lateral-velocity error, f4 orientation error (theta); RLQR_MOP (RLQR with the
#: NSGA-II/MO-LSP uncertainty z*), RLQR_A (RLQR with the algebraic uncertainty of
#: Barbosa et al. 2019), Hinf (standard H-infinity), LQR. The H-infinity f1 value at
#: 0 % is printed as "0.83135E-3".
PRINTED_MSE = {
    "f1": {
        "RLQR_MOP": (2.72161e-3, 9.52776e-3, 2.02697e-2, 3.46455e-2),
        "RLQR_A": (6.72252e-3, 1.29370e-2, 2.06950e-2, 3.00461e-2),
        "Hinf": (0.83135e-3, 1.08787e-3, 1.09022e-2, 4.19582e-2),
        "LQR": (3.92518e-3, 6.95036e-3, 1.10944e-2, 1.61736e-2),
    },
    "f2": {
        "RLQR_MOP": (1.44405e-3, 1.67467e-3, 1.85903e-3, 1.99537e-3),
        "RLQR_A": (1.84585e-3, 3.01635e-3, 4.09464e-3, 4.98721e-3),
        "Hinf": (1.85683e-2, 1.03793e-2, 4.64690e-3, 5.18353e-3),
        "LQR": (5.54885e-3, 1.04151e-2, 1.56832e-2, 2.02004e-2),
    },
    "f3": {
        "RLQR_MOP": (1.17762e-2, 3.07187e-2, 5.65872e-2, 8.72447e-2),
        "RLQR_A": (1.67254e-2, 6.45166e-2, 1.34078e-1, 2.15567e-1),
        "Hinf": (1.09009e-1, 7.74970e-2, 9.98572e-2, 1.95922e-1),
        "LQR": (4.54013e-2, 1.71043e-1, 3.76471e-1, 6.23971e-1),
    },
    "f4": {
        "RLQR_MOP": (7.35717e-5, 1.00885e-4, 1.44767e-4, 2.02602e-4),
        "RLQR_A": (2.42387e-4, 4.22745e-4, 6.48997e-4, 8.95945e-4),
        "Hinf": (8.74106e-5, 1.94354e-4, 3.50360e-4, 1.29590e-3),
        "LQR": (4.59179e-4, 1.02236e-3, 1.82643e-3, 2.72205e-3),
    },
}


# -- the authors' code ------------------------------------------------------------------------

#: State weight of the authors' published code (Barbosa et al. 2019, GitHub
#: ``barbosafilipe/robust_lqr``, ``standard_formulation/parameters.m`` and
#: ``alternative_formulation/model.m``: ``Q = diag(1, 1, 1, 1, 25000, 100)`` on
#: the articulated truck's six states), on ``[ydot, psidot, rho, theta]``.
AUTHORS_Q_DIAG = (1.0, 1.0, 25000.0, 100.0)
#: The code's input weight on the doubled steering column, ``R = 67070 I2`` (same files).
AUTHORS_R_DOUBLED = 67070.0
#: The code's initial state (same files: ``x0 = [0; 0; 0; 0; 0.3; -0.1]``): 0.3 m
#: left of the path, heading -0.1 rad, velocities zero; ``[ydot, psidot, rho, theta]``.
AUTHORS_X0 = (0.0, 0.0, 0.3, -0.1)
#: RLQR^A's ``E_G`` in the code (``standard_formulation/parameters.m``,
#: ``alternative_formulation/model.m``: ``Eg = [-0.0666666666666667 -0.0066666666666667]``,
#: ``[-1/15, -1/150]`` to the 16 digits printed); the paper prints two equal entries, :data:`PRINTED_EG`.
CODE_EG = (-0.0666666666666667, -0.0066666666666667)
#: The level of the code's game-Riccati H-infinity law (``standard_formulation/h_infinity.m``:
#: ``gamma = 14350``).
CODE_GAMMA = 14350.0


def authors_weights(*, doubled: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """The weights of the authors' published code: ``Q = diag(1, 1, 25000, 100)``, ``R = 67070 I2``.

    From Barbosa et al. (2019)'s code (GitHub ``barbosafilipe/robust_lqr``,
    ``standard_formulation/parameters.m``, ``alternative_formulation/model.m``),
    whose RLQR and H-infinity designs both use them; 25000 weighs the lateral
    displacement ``rho``, 100 the orientation ``theta``, 1 the velocities (the
    code's articulation states are dropped). ``R = 67070 I2`` is on the doubled
    steering column; on the plain truck (``doubled=False``) the equivalent
    weight is ``67070 / 2 = 33535``: the cheapest split of a steering angle
    ``alpha`` is ``u1 = u2 = alpha/2`` at a cost ``67070 alpha^2 / 2`` (the rule
    of :func:`robustctl.models.truck.lqr_weights`).

    Parameters
    ----------
    doubled : bool
        Weights for the doubled steering column (two inputs).

    Returns
    -------
    Q : (4, 4) ndarray
        ``diag(1, 1, 25000, 100)``.
    R : (1, 1) or (2, 2) ndarray
        ``[[33535]]``, or ``67070 I2`` for the doubled column.

    References
    ----------
    .. [1] F. M. Barbosa, L. B. Marcos, M. M. da Silva, M. H. Terra,
       V. Grassi Jr, "Robust path-following control for articulated
       heavy-duty vehicles", Control Engineering Practice 85, 246-256, 2019,
       and its code, https://github.com/barbosafilipe/robust_lqr.

    Examples
    --------
    The even split ``u1 = u2 = alpha / 2`` of the doubled column costs what
    ``alpha`` costs on the plain truck [1]_:

    >>> import numpy as np
    >>> from robustctl.models.morais2022 import authors_weights
    >>> Q, R2 = authors_weights(doubled=True)
    >>> _, R1 = authors_weights()
    >>> half = np.array([0.5, 0.5])
    >>> bool(np.isclose(half @ R2 @ half, R1[0, 0])), np.diag(Q).tolist()
    (True, [1.0, 1.0, 25000.0, 100.0])
    """
    Q = np.diag(AUTHORS_Q_DIAG)
    return Q, (AUTHORS_R_DOUBLED * np.eye(2) if doubled else np.array([[AUTHORS_R_DOUBLED / 2.0]]))


def code_manoeuvre(*, params: truck.TruckParameters | None = None) -> ReferencePath:
    r"""The reference manoeuvre of the authors' code, as a path: 30 s with two sine lane changes.

    ``standard_formulation/parameters.m`` of Barbosa et al. (2019)'s code
    (GitHub ``barbosafilipe/robust_lqr``) drives the nominal vehicle open
    loop for 30 s on a straight road with the steering command ``0.01
    sin(0.4 pi t)`` rad for 5 s from ``t = 10 s`` (a lane change to the left)
    and its negative from ``t = 20 s`` (back). This is the path whose
    steady-cornering steering (``alpha_per_kappa kappa``,
    :func:`robustctl.models.truck.steady_state_cornering`, nominal payload)
    is that command: straights and two :class:`~robustctl.models.path.LaneChange`
    elements of ``5 v`` metres and offset ``0.01 L^2 / (2 pi alpha_per_kappa)``
    (``L = 5 v``), so the ``"open_loop"`` reference of the ``"authors"``
    set-up (:data:`SETUPS`) along it is the code's ``x_ref`` (at our 0.1 s
    sampling, ZOH model).

    Parameters
    ----------
    params : TruckParameters, optional
        Defaults to the paper's parameters.

    Returns
    -------
    ReferencePath
        30 s at the model's speed and sampling time.

    Notes
    -----
    The code's command is

    .. math::

        u(t) = 0.01 \sin(0.4 \pi (t - 10)) \text{ on } [10, 15) \text{ s},
        \qquad -0.01 \sin(0.4 \pi (t - 20)) \text{ on } [20, 25) \text{ s},

    zero elsewhere, and :class:`~robustctl.models.path.LaneChange` has the
    curvature ``offset (2 pi / L^2) sin(2 pi s / L)``, so with ``s = v t``
    and ``L = 5 v`` the offset above gives ``alpha_per_kappa kappa = u``.

    Examples
    --------
    The steady-cornering steering along the path is the code's command,
    sample by sample (``kappa[k]`` is the mean over the sample, so the
    command is compared at mid-sample):

    >>> import numpy as np
    >>> from robustctl.models import morais2022, truck
    >>> path = morais2022.code_manoeuvre()
    >>> path.T, path.duration
    (300, 30.0)
    >>> _, alpha_per_kappa = truck.steady_state_cornering(0.0)
    >>> t = path.t + path.dt / 2
    >>> u = np.where((t >= 10) & (t < 15), 0.01 * np.sin(0.4 * np.pi * (t - 10)), 0.0)
    >>> u -= np.where((t >= 20) & (t < 25), 0.01 * np.sin(0.4 * np.pi * (t - 20)), 0.0)
    >>> bool(np.abs(alpha_per_kappa * path.kappa - u).max() < 1e-5)
    True
    """
    p = truck._params(params)
    _, a_per_kappa = truck.steady_state_cornering(0.0, params=p)
    L = 5.0 * p.v
    offset = 0.01 * L**2 / (2.0 * np.pi * a_per_kappa)
    return ReferencePath.from_segments([Straight(2 * L), LaneChange(offset, L), Straight(L), LaneChange(-offset, L)],
                                       duration=30.0, speed=p.v, dt=p.dt, name="code manoeuvre")


# -- the two set-ups --------------------------------------------------------------------------

#: The two set-ups (module docstring): ``"ours"`` (the simulator's default set-up) and ``"authors"``.
SETUPS = {
    "ours": dataclasses.replace(DEFAULT_SETUP, name="ours"),
    "authors": PathFollowingSetup(
        "authors", "open_loop", False, AUTHORS_X0, AUTHORS_Q_DIAG, AUTHORS_R_DOUBLED / 2.0,
        "Barbosa et al. (2019)'s code, github.com/barbosafilipe/robust_lqr: standard_formulation/main.m "
        "(loop), parameters.m (reference, x0, Q, R), alternative_formulation/model.m (x0, Q, R)"),
}


def get_setup(setup: str | PathFollowingSetup) -> PathFollowingSetup:
    """A :class:`~robustctl.models.pathfollow.PathFollowingSetup` by name (a key of :data:`SETUPS`), or ``setup``.

    Parameters
    ----------
    setup : str or PathFollowingSetup
        ``"ours"`` or ``"authors"`` (module docstring), or a set-up, returned as it is.

    Returns
    -------
    PathFollowingSetup

    Raises
    ------
    TypeError
        Neither a string nor a set-up.
    ValueError
        An unknown name.

    Examples
    --------
    The ``"authors"`` set-up carries the weights of the authors' code:

    >>> import numpy as np
    >>> from robustctl.models.morais2022 import authors_weights, get_setup
    >>> setup = get_setup("authors")
    >>> setup.reference, setup.feedforward, setup.x0
    ('open_loop', False, (0.0, 0.0, 0.3, -0.1))
    >>> Q, R = setup.weights(doubled=True)
    >>> Q_ref, R_ref = authors_weights(doubled=True)
    >>> bool(np.allclose(Q, Q_ref) and np.allclose(R, R_ref))
    True
    """
    if isinstance(setup, PathFollowingSetup):
        return setup
    if not isinstance(setup, str):
        raise TypeError(f"setup must be a name ({', '.join(SETUPS)}) or a PathFollowingSetup, "
                        f"got {type(setup).__name__}")
    if setup not in SETUPS:
        raise ValueError(f"unknown setup {setup!r}; valid: {', '.join(SETUPS)}")
    return SETUPS[setup]


# -- the truck with sensors -------------------------------------------------------------------


def sensor_filter_noise(path: ReferencePath | None = None, *, overloads=MSE_OVERLOADS,
                        params: truck.TruckParameters | None = None) -> tuple[np.ndarray, np.ndarray]:
    r"""The process noise of the MSE table's filters: a steering disturbance as large as the payload mismatch.

    The filters run on the nominal (0 %) model while the truck carries up to
    the table's largest overload. In steady cornering on a bend of
    curvature ``kappa`` the truck at an overload ``k`` needs the steering
    ``alpha_per_kappa(k) kappa`` (:func:`robustctl.models.truck.steady_state_cornering`);
    the filters take the largest difference from the nominal model's, in
    the path's tightest bend, as the standard deviation of a white
    disturbance on the steering input.

    Parameters
    ----------
    path : ReferencePath, optional
        The course (default :func:`robustctl.models.path.default_route`).
    overloads : sequence of float
        The payload range [%] (default the table's, :data:`MSE_OVERLOADS`).
    params : TruckParameters, optional
        Defaults to the paper's parameters.

    Returns
    -------
    Bw : (4, 1) ndarray
        The nominal model's steering input ``G``.
    W : (1, 1) ndarray
        ``sigma^2``.

    Raises
    ------
    ValueError, TypeError
        Negative or non-numeric overloads, ``path`` not a ReferencePath.

    Notes
    -----
    .. math::

        \sigma = \max_k |\alpha_\kappa(k) - \alpha_\kappa(0)| \, \max_t |\kappa(t)| .

    Examples
    --------
    The steering of the steady-cornering references at 300 % and at 0 %,
    in the route's tightest bend (200 m), differ by ``sigma``, about 0.1 rad:

    >>> import numpy as np
    >>> from robustctl.models import morais2022, truck
    >>> from robustctl.models.path import default_route
    >>> Bw, W = morais2022.sensor_filter_noise()
    >>> kappa = np.abs(default_route().kappa).max()
    >>> steering = [truck.reference_states(np.array([kappa]), ov)[1][0] for ov in (0.0, 300.0)]
    >>> bool(np.isclose(np.sqrt(W[0, 0]), steering[1] - steering[0])), round(float(np.sqrt(W[0, 0])), 3)
    (True, 0.101)
    >>> bool(np.array_equal(Bw, truck.truck_plant(0.0).G))
    True
    """
    path = default_route() if path is None else path
    if not isinstance(path, ReferencePath):
        raise TypeError(f"path must be a robustctl.models.path.ReferencePath, got {type(path).__name__}")
    ovs = np.atleast_1d(truck.check_overload(overloads, "overloads"))
    nominal = truck.steady_state_cornering(0.0, params=params)[1]
    mismatch = max(abs(truck.steady_state_cornering(float(ov), params=params)[1] - nominal) for ov in ovs)
    sigma = mismatch * float(np.abs(path.kappa).max())
    return truck.truck_plant(0.0, params=params).G, np.array([[sigma**2]])
