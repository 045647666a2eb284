r"""Output-feedback design families: a decision vector ``z`` -> controllers ``u = K(z) y`` for a whole population.

Each family returns a :class:`~moo.tuning.FamilyControllers` (one
:class:`robustctl.ControllerBatch` for the population, failed designs
flagged) of its plant's measured outputs ``y = C x + D u``; the convention is
the library's, ``u = K(z) y`` (with a reference ``u = K(z) (y - r)``), no minus
sign:

* :class:`StaticOutputFeedbackFamily` - ``u = K y``, ``z = vec K``;
* :class:`PIDFamily` - a discrete PID with a derivative filter per
  (output, input) loop, decentralised, in the parallel form ``(K_p, K_i, K_d,
  T_f)`` acting on ``e = r - y``, so ``K(z) = -C_{PID}(z)``;
* :class:`FixedOrderFamily` - any controller of order ``k`` (MATLAB's
  ``tunableSS``), its poles parametrised inside a disc so that the search
  stays well scaled;
* :class:`LQGFamily` - the LQR on the Kalman filter's estimate, the weights
  and noise covariances tuned;
* :class:`RobustLQGFamily` - the RLQR on the robust filter's estimate, their
  uncertainty model and penalties tuned (the paper's method with sensors).

Default bounds come from the plant's scales: a gain from output ``i`` to
input ``j`` ranges over ``+- gain_bound / (||G_j|| ||C_i||)`` (``G_j`` the
``j``-th column of ``G``, ``C_i`` the ``i``-th row of ``C``), i.e. loop gains
per sample (per second for a continuous plant) up to ``gain_bound``.

References
----------
K. J. Astrom, R. M. Murray, *Feedback Systems*, 2nd ed., Princeton 2021,
Sec. 11.5 (implementation: forward differences for the integral, backward
differences for the filtered derivative).
P. Apkarian, D. Noll, "Nonsmooth H-infinity synthesis", IEEE TAC 51(1), 2006
(fixed-structure controllers; MATLAB's ``tunableSS``, ``tunablePID``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

import numpy as np

import robustctl as rc
from robustctl.validation import check_plant, check_positive_scalar

from ..validation import as_matrix, check_choice, check_int
from .families import FamilyControllers, dlqr_gains, population

__all__ = ["StaticOutputFeedbackFamily", "PIDFamily", "FixedOrderFamily", "LQGFamily", "RobustLQGFamily",
           "gain_scales", "observer_controllers"]


def gain_scales(plant: rc.Plant) -> np.ndarray:
    """``1 / (||G_j|| ||C_i||)`` for every input ``j`` and output ``i``, shape (m, p) (a zero norm counts as 1)."""
    C, _ = plant.output_matrices()
    g = np.linalg.norm(plant.G, axis=0)
    c = np.linalg.norm(C, axis=1)
    g, c = np.where(g > 0, g, 1.0), np.where(c > 0, c, 1.0)
    return 1.0 / (g[:, None] * c[None, :])


def _static(plant: rc.Plant, Dc: np.ndarray) -> rc.ControllerBatch:
    B = Dc.shape[0]
    return rc.ControllerBatch(plant, np.zeros((B, 0, 0)), np.zeros((B, 0, plant.p)), np.zeros((B, plant.m, 0)), Dc)


def _result(batch: rc.ControllerBatch) -> FamilyControllers:
    """Flag the designs with non-finite matrices (NaN everywhere for them)."""
    mats = (batch.Ac, batch.Bc, batch.Cc, batch.Dc)
    ok = np.all([np.isfinite(M).all(axis=(1, 2)) for M in mats], axis=0)
    if not ok.all():
        batch = rc.ControllerBatch(batch.plant, *(np.where(ok[:, None, None], M, np.nan) for M in mats))
    return FamilyControllers(batch, ok, np.where(ok, "", "non-finite controller").astype(object))


class _OutputFamily:
    """What the output-feedback families share: the plant, the sizes, the bounds."""

    feedback = "output"
    plant: rc.Plant
    n_var: int
    xl: np.ndarray
    xu: np.ndarray

    def _set_plant(self, plant: rc.Plant, name: str, discrete: bool) -> None:
        self.plant = check_plant(plant, "plant", discrete_for=name if discrete else None)
        self.n_states, self.n_inputs, self.n_outputs = plant.n, plant.m, plant.p

    def _check(self, Z) -> np.ndarray:
        return population(Z, self.n_var, "Z")


class StaticOutputFeedbackFamily(_OutputFamily):
    r"""Static output feedback ``u = K y``: ``z`` is the gain itself, row by row.

    Parameters
    ----------
    plant : robustctl.Plant
        The plant with the outputs ``y = C x + D u`` the gain reads (without an
        output model the state, ``p = n``); discrete or continuous (the goals
        decide what they need).
    gain_bound : float
        Default bounds ``K_ji in +- gain_bound / (||G_j|| ||C_i||)`` (default 10).

    Attributes
    ----------
    n_var : int
        ``m p``.
    xl, xu : (n_var,) ndarray
        Default bounds of ``z``.
    feedback : str
        ``"output"``.

    Raises
    ------
    TypeError, ValueError
        ``plant`` not a :class:`robustctl.Plant`, a non-positive ``gain_bound``.

    See Also
    --------
    PIDFamily, FixedOrderFamily : dynamic controllers.

    Notes
    -----
    .. math::

        u = K y, \qquad K = \begin{bmatrix} z_1 & \dots & z_p \\ \vdots & & \vdots \\
        z_{(m-1)p+1} & \dots & z_{mp} \end{bmatrix},

    and the closed loop ``x+ = (F + G E K C) x``, ``E = (I - K D)^{-1}``.

    Examples
    --------
    The closed loop of ``z`` is python-control's feedback of the plant and the
    static gain (positive feedback: our sign):

    >>> import numpy as np, control
    >>> import robustctl as rc
    >>> from moo.tuning import StaticOutputFeedbackFamily
    >>> plant = rc.Plant([[1.1, 0.1], [0.0, 0.9]], [[0.0], [0.1]], 0.1, C=[[1.0, 0.0]])
    >>> fam = StaticOutputFeedbackFamily(plant)
    >>> fam.n_var, fam.xu.round(1)
    (1, array([100.]))
    >>> batch = fam.gains(np.array([[-3.0]])).controllers
    >>> loop = control.feedback(plant.to_statespace(), control.ss([], [], [], [[-3.0]], 0.1), sign=1)
    >>> bool(np.allclose(np.sort(np.linalg.eigvals(batch.closed_loops()[0])), np.sort(loop.poles())))
    True
    """

    def __init__(self, plant: rc.Plant, *, gain_bound: float = 10.0):
        self._set_plant(plant, "StaticOutputFeedbackFamily", discrete=False)
        m, p = plant.m, plant.p
        self.n_var = m * p
        b = check_positive_scalar(gain_bound, "gain_bound") * gain_scales(plant).ravel()
        self.xl, self.xu = -b, b

    def gains(self, Z) -> FamilyControllers:
        """:class:`~moo.tuning.FamilyControllers` of a population ``Z`` (B, m p)."""
        z = self._check(Z)
        return _result(_static(self.plant, z.reshape(z.shape[0], self.n_inputs, self.n_outputs)))

    def __repr__(self) -> str:
        return f"StaticOutputFeedbackFamily(n={self.n_states}, m={self.n_inputs}, p={self.n_outputs})"


#: The terms :class:`PIDFamily` tunes, and the parameters of each loop (in this order).
PID_TERMS = {"pid": ("Kp", "Ki", "Kd", "Tf"), "pi": ("Kp", "Ki"), "pd": ("Kp", "Kd", "Tf"), "p": ("Kp",)}


class PIDFamily(_OutputFamily):
    r"""Discrete PID controllers with a derivative filter, one per (output, input) loop, decentralised.

    Each loop ``(i, j)`` (output ``y_i``, input ``u_j``) is the parallel PID
    ``C(s) = K_p + K_i / s + K_d s / (T_f s + 1)`` on ``e_i = r_i - y_i``,
    discretised as stated in the Notes; ``z`` holds ``log10`` of its
    parameters. In the library's convention ``u = K(z) (y - r)`` the
    controller is ``K(z) = -s C(z)`` (``s`` the loop's sign).

    Parameters
    ----------
    plant : robustctl.Plant
        A discrete-time plant with the outputs ``y`` the loops read.
    loops : sequence of (int, int), optional
        ``(output, input)`` pairs, each input at most once; default ``(k, k)``
        for a square plant.
    terms : {"pid", "pi", "pd", "p"}
        The terms tuned (the others are zero); default ``"pid"``.
    sign : "auto", +1, -1 or a sequence of them
        The loop's action: ``+1`` for a plant whose gain from ``u_j`` to
        ``y_i`` is positive. ``"auto"`` (default): the sign of that gain just
        above ``z = 1`` (the static gain, or an integrator's direction).
    gain_bounds : (float, float)
        Default bounds of ``log10`` of ``K_p``, ``K_i`` (1/s) and ``K_d`` (s),
        relative to the loop's scale ``1 / (||G_j|| ||C_i||)`` of
        :func:`gain_scales` (default ``(-4, 2)``).
    filter_bounds : (float, float)
        Default bounds of ``log10(T_f / dt)`` (default ``(-1, 2)``: ``T_f``
        from ``dt / 10`` to ``100 dt``).

    Attributes
    ----------
    n_var : int
        ``len(loops) * len(terms)`` (``"pid"``: 4 per loop).
    xl, xu : (n_var,) ndarray
        Default bounds of ``z``.
    loops : tuple of (int, int)
    signs : (len(loops),) ndarray
    parameters : tuple of str
        Names of the entries of ``z`` (``"Kp[0]"``, ``"Ki[0]"``, ...).

    Raises
    ------
    TypeError, ValueError
        ``plant`` not a discrete-time :class:`robustctl.Plant`, loops out of
        range or an input used twice, no default loops (a plant that is not
        square), an unknown ``terms``, a sign other than ``"auto"`` or +-1,
        bounds that are not increasing pairs.

    See Also
    --------
    StaticOutputFeedbackFamily, FixedOrderFamily

    Notes
    -----
    Per loop, with the sampling time ``h``, the integral by forward
    differences and the filtered derivative by backward differences [1]_:

    .. math::

        I[k+1] = I[k] + K_i h\, e[k], \qquad
        D[k] = \frac{T_f}{T_f + h} D[k-1] + \frac{K_d}{T_f + h} (e[k] - e[k-1]), \qquad
        u[k] = K_p e[k] + I[k] + D[k],

    that is

    .. math::

        C(z) = K_p + \frac{K_i h}{z - 1} + \frac{K_d (z - 1)}{(T_f + h) z - T_f},

    realised with the states ``(I, D[k-1] a - b e[k-1])``, ``a = T_f/(T_f + h)``,
    ``b = K_d/(T_f + h)``: ``A_c = diag(1, a)``, ``B_c = (K_i h, b (a - 1))``,
    ``C_c = (1, 1)``, ``D_c = K_p + b``. The family's controller is
    ``K(z) = -s C(z)``, i.e. ``(A_c, -s B_c, C_c, -s D_c)``.

    References
    ----------
    .. [1] K. J. Astrom, R. M. Murray, *Feedback Systems*, 2nd ed., Princeton
       2021, Sec. 11.5 (implementation of a PID controller).

    Examples
    --------
    ``z = log10(K_p, K_i, K_d, T_f)`` relative to the loop's scale; the
    family's controller is minus the textbook discretisation:

    >>> import numpy as np, control
    >>> import robustctl as rc
    >>> from moo.tuning import PIDFamily
    >>> plant = rc.Plant([[0.9]], [[0.1]], 0.1, C=[[1.0]])          # scale 1 / (0.1 * 1) = 10
    >>> fam = PIDFamily(plant)
    >>> fam.parameters, fam.signs
    (('Kp[0]', 'Ki[0]', 'Kd[0]', 'Tf[0]'), array([1.]))
    >>> Kp, Ki, Kd, Tf, h = 2.0, 5.0, 0.1, 0.05, 0.1
    >>> z = np.log10([Kp / 10, Ki / 10, Kd / 10, Tf / h])
    >>> K = fam.gains(z[None]).controllers[0].controller_statespace()
    >>> C = control.tf([Kp], [1], h) + control.tf([Ki * h], [1, -1], h) + control.tf([Kd, -Kd], [Tf + h, -Tf], h)
    >>> w = np.exp(1j * np.linspace(0.1, 3.0, 7))
    >>> bool(np.allclose(K(w), -C(w)))
    True
    """

    def __init__(self, plant: rc.Plant, loops: Sequence[tuple[int, int]] | None = None, *,
                 terms: Literal["pid", "pi", "pd", "p"] = "pid", sign="auto", gain_bounds=(-4.0, 2.0),
                 filter_bounds=(-1.0, 2.0)):
        self._set_plant(plant, "PIDFamily", discrete=True)
        m, p = plant.m, plant.p
        self._dt = float(plant.dt)  # type: ignore[arg-type]  # discrete: checked
        if loops is None:
            if m != p:
                raise ValueError(f"loops must be given for a plant with p={p} outputs and m={m} inputs "
                                 "(a list of (output, input) pairs)")
            loops = [(k, k) for k in range(m)]
        if isinstance(loops, (str, bytes)) or not isinstance(loops, Sequence) or not loops:
            raise TypeError(f"loops must be a non-empty list of (output, input) pairs, got {loops!r}")
        pairs = []
        for k, pair in enumerate(loops):
            if not isinstance(pair, Sequence) or len(pair) != 2:
                raise TypeError(f"loops[{k}] must be an (output, input) pair, got {pair!r}")
            i, j = check_int(pair[0], f"loops[{k}][0]", 0), check_int(pair[1], f"loops[{k}][1]", 0)
            if i >= p or j >= m:
                raise ValueError(f"loops[{k}] = ({i}, {j}) is out of range for p={p} outputs and m={m} inputs")
            pairs.append((i, j))
        inputs = [j for _, j in pairs]
        if len(set(inputs)) != len(inputs):
            raise ValueError(f"loops must use each input once (decentralised control), got {pairs}")
        self.loops = tuple(pairs)
        self.terms = check_choice(terms, "terms", tuple(PID_TERMS))
        self.signs = self._signs(sign)
        names = PID_TERMS[self.terms]
        self.parameters = tuple(f"{name}[{k}]" for k in range(len(pairs)) for name in names)
        self.n_var = len(self.parameters)
        lo, hi = _pair(gain_bounds, "gain_bounds"), _pair(filter_bounds, "filter_bounds")
        scale = np.log10(gain_scales(plant))
        xl, xu = [], []
        for i, j in pairs:
            for name in names:
                b, off = (hi, 0.0) if name == "Tf" else (lo, scale[j, i])
                xl.append(b[0] + off)
                xu.append(b[1] + off)
        self.xl, self.xu = np.array(xl), np.array(xu)
        self._scale = scale

    def _signs(self, sign) -> np.ndarray:
        L = len(self.loops)
        if isinstance(sign, str):
            check_choice(sign, "sign", ("auto",))
            return np.array([self._plant_sign(i, j) for i, j in self.loops])
        values = np.broadcast_to(np.asarray(sign, dtype=float), (L,)) if np.ndim(sign) in (0, 1) else None
        if values is None or values.shape != (L,) or not np.all(np.isin(values, (-1.0, 1.0))):
            raise ValueError(f"sign must be 'auto', +1, -1 or {L} of them (one per loop), got {sign!r}")
        return values.astype(float).copy()

    def _plant_sign(self, i: int, j: int) -> float:
        """Sign of the gain from ``u_j`` to ``y_i`` at ``z = 1 + 1e-6`` (+1 where it is zero)."""
        C, D = self.plant.output_matrices()
        z = 1.0 + 1e-6
        with np.errstate(all="ignore"):
            g = C[i] @ np.linalg.solve(z * np.eye(self.plant.n) - self.plant.F, self.plant.G[:, j]) + D[i, j]
        return -1.0 if np.isfinite(g) and g < 0 else 1.0

    def pid_parameters(self, Z) -> dict[str, np.ndarray]:
        """``{"Kp", "Ki", "Kd", "Tf"}`` -> (B, loops) arrays of a population (zero for the terms not tuned)."""
        z = self._check(Z)
        B, L = z.shape[0], len(self.loops)
        names = PID_TERMS[self.terms]
        out = {name: np.zeros((B, L)) for name in ("Kp", "Ki", "Kd", "Tf")}
        vals = z.reshape(B, L, len(names))
        scale = np.array([self._scale[j, i] for i, j in self.loops])
        with np.errstate(over="ignore"):
            for q, name in enumerate(names):
                out[name] = 10.0 ** (vals[:, :, q] + (np.log10(self._dt) if name == "Tf" else scale))
        return out

    def gains(self, Z) -> FamilyControllers:
        """:class:`~moo.tuning.FamilyControllers` of a population ``Z`` (B, n_var) (Notes)."""
        prm = self.pid_parameters(Z)
        B, L = prm["Kp"].shape
        h = self._dt
        m, p = self.n_inputs, self.n_outputs
        has_i, has_d = "Ki" in PID_TERMS[self.terms], "Kd" in PID_TERMS[self.terms]
        per = int(has_i) + int(has_d)
        nc = per * L
        Ac, Bc = np.zeros((B, nc, nc)), np.zeros((B, nc, p))
        Cc, Dc = np.zeros((B, m, nc)), np.zeros((B, m, p))
        with np.errstate(all="ignore"):
            a = prm["Tf"] / (prm["Tf"] + h)
            b = prm["Kd"] / (prm["Tf"] + h)
        for k, (i, j) in enumerate(self.loops):
            s = -self.signs[k]                                   # K(z) = -sign C(z)
            q = per * k
            Dc[:, j, i] = s * (prm["Kp"][:, k] + (b[:, k] if has_d else 0.0))
            if has_i:
                Ac[:, q, q] = 1.0
                Bc[:, q, i] = s * prm["Ki"][:, k] * h
                Cc[:, j, q] = 1.0
                q += 1
            if has_d:
                Ac[:, q, q] = a[:, k]
                Bc[:, q, i] = s * b[:, k] * (a[:, k] - 1.0)
                Cc[:, j, q] = 1.0
        return _result(rc.ControllerBatch(self.plant, Ac, Bc, Cc, Dc))

    def __repr__(self) -> str:
        return f"PIDFamily(loops={list(self.loops)}, terms={self.terms!r}, n_var={self.n_var})"


def _pair(value, name: str) -> tuple[float, float]:
    arr = np.asarray(value, dtype=float) if not isinstance(value, (str, bytes)) else np.zeros(0)
    if arr.shape != (2,) or not np.all(np.isfinite(arr)) or not arr[0] < arr[1]:
        raise ValueError(f"{name} must be an increasing pair (low, high) of finite numbers, got {value!r}")
    return float(arr[0]), float(arr[1])


class FixedOrderFamily(_OutputFamily):
    r"""Any discrete controller of order ``k``, its poles inside a disc of radius ``pole_radius``.

    ``A_c`` is block diagonal: ``k // 2`` second-order blocks in companion
    form and, for odd ``k``, one first-order block. Each block's two numbers
    in ``[-1, 1]`` map onto the Schur-Cohn stability triangle of the disc
    (Notes), so every ``z`` in the bounds is a controller with poles in the
    disc (integrators and pure delays included at ``pole_radius = 1``), and
    the search space has no unstable corner the MOEA has to learn about.
    ``B_c``, ``C_c`` and ``D_c`` are free, scaled by the plant.

    Parameters
    ----------
    plant : robustctl.Plant
        A discrete-time plant with the outputs ``y`` the controller reads.
    order : int
        ``k >= 1`` controller states.
    pole_radius : float
        Largest modulus of the controller's poles (default 1: stable or
        marginally stable controllers, integral action included).
    gain_bound : float
        Default bounds: ``B_c`` rows ``+- 1 / ||C_i||`` (per output), ``C_c``
        entries ``+- gain_bound / ||G_j||``, ``D_c`` as
        :class:`StaticOutputFeedbackFamily` (default 10).

    Attributes
    ----------
    n_var : int
        ``k + k p + m k + m p``.
    xl, xu : (n_var,) ndarray
        Default bounds of ``z``.
    order : int

    Raises
    ------
    TypeError, ValueError
        ``plant`` not a discrete-time :class:`robustctl.Plant`, ``order`` not
        a positive integer, a non-positive ``pole_radius`` or ``gain_bound``.

    See Also
    --------
    StaticOutputFeedbackFamily, PIDFamily

    Notes
    -----
    A second-order block ``[[0, 1], [-d, t]]`` has the characteristic
    polynomial ``z^2 - t z + d``, whose roots lie in ``|z| <= rho`` iff
    ``|d| <= rho^2`` and ``|t| <= rho + d / rho`` (Schur-Cohn / Jury); with
    ``(u, v)`` in ``[-1, 1]^2``

    .. math::

        d = \rho^2 v, \qquad t = \rho\, u\, (1 + v),

    covers that triangle (real and complex pairs alike). A first-order block
    is the pole ``\rho u``. ``z = (\text{block parameters } (k),\
    \operatorname{vec}_r B_c\ (k p),\ \operatorname{vec}_r C_c\ (m k),\
    \operatorname{vec}_r D_c\ (m p))``.

    References
    ----------
    .. [1] E. I. Jury, *Theory and Application of the z-Transform Method*,
       Wiley 1964 (the stability triangle of second-order polynomials).

    Examples
    --------
    Every decision vector inside the bounds is a controller with poles in the disc:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import FixedOrderFamily
    >>> plant = rc.Plant([[1.1, 0.1], [0.0, 0.9]], [[0.0], [0.1]], 0.1, C=[[1.0, 0.0]])
    >>> fam = FixedOrderFamily(plant, order=3, pole_radius=0.95)
    >>> fam.n_var                                    # 3 + 3 + 3 + 1
    10
    >>> Z = np.random.default_rng(0).uniform(fam.xl, fam.xu, (200, fam.n_var))
    >>> Ac = fam.gains(Z).controllers.Ac
    >>> bool(np.abs(np.linalg.eigvals(Ac)).max() <= 0.95 + 1e-12)
    True
    """

    def __init__(self, plant: rc.Plant, order: int, *, pole_radius: float = 1.0, gain_bound: float = 10.0):
        self._set_plant(plant, "FixedOrderFamily", discrete=True)
        self.order = check_int(order, "order", 1)
        self.pole_radius = check_positive_scalar(pole_radius, "pole_radius")
        gain_bound = check_positive_scalar(gain_bound, "gain_bound")
        k, m, p = self.order, plant.m, plant.p
        self.n_var = k + k * p + m * k + m * p
        C, _ = plant.output_matrices()
        c = np.linalg.norm(C, axis=1)
        g = np.linalg.norm(plant.G, axis=0)
        b_B = np.tile(1.0 / np.where(c > 0, c, 1.0), k)                       # B_c rows: per output column
        b_C = np.repeat(gain_bound / np.where(g > 0, g, 1.0), k)               # C_c rows: per input
        b_D = gain_bound * gain_scales(plant).ravel()
        self.xu = np.concatenate([np.ones(k), b_B, b_C, b_D])
        self.xl = -self.xu

    def gains(self, Z) -> FamilyControllers:
        """:class:`~moo.tuning.FamilyControllers` of a population ``Z`` (B, n_var) (Notes)."""
        z = self._check(Z)
        B, k, m, p, r = z.shape[0], self.order, self.n_inputs, self.n_outputs, self.pole_radius
        Ac = np.zeros((B, k, k))
        for q in range(0, k - 1, 2):
            u, v = z[:, q], z[:, q + 1]
            Ac[:, q, q + 1] = 1.0
            Ac[:, q + 1, q] = -(r * r) * v
            Ac[:, q + 1, q + 1] = r * u * (1.0 + v)
        if k % 2:
            Ac[:, k - 1, k - 1] = r * z[:, k - 1]
        o = k
        Bc = z[:, o:o + k * p].reshape(B, k, p)
        o += k * p
        Cc = z[:, o:o + m * k].reshape(B, m, k)
        Dc = z[:, o + m * k:].reshape(B, m, p)
        return _result(rc.ControllerBatch(self.plant, Ac, Bc, Cc, Dc))

    def __repr__(self) -> str:
        return (f"FixedOrderFamily(order={self.order}, n={self.n_states}, m={self.n_inputs}, p={self.n_outputs}, "
                f"n_var={self.n_var})")


def observer_controllers(plant: rc.Plant, K: np.ndarray, Fe: np.ndarray, Ge: np.ndarray, Lf: np.ndarray,
                         J: np.ndarray) -> rc.ControllerBatch:
    r"""The output feedbacks ``u = K x[k|k]`` of state feedbacks on filters' estimates, for stacks (filter form).

    Batched :func:`robustctl.observer_controller`: with
    ``L_p = F_e L_f + J`` and ``M = I + K L_f D``,

    .. math::

        D_c = M^{-1} K L_f, \quad C_c = M^{-1} K (I - L_f C), \quad
        A_c = F_e + G_e C_c - L_p (C + D C_c), \quad B_c = L_p (I - D D_c) + G_e D_c .

    Parameters
    ----------
    plant : robustctl.Plant
        With its output model ``C``, ``D``.
    K : (B, m, n) ndarray
        State feedbacks ``u = K x``.
    Fe, Ge, Lf, J : (B, n, n), (B, n, m), (B, n, p), (B, n, p) ndarrays
        The filters' models, filter gains and innovation terms
        (:class:`robustctl.EstimatorBatch` of form ``"filter"``).

    Returns
    -------
    robustctl.ControllerBatch
        Controllers of order ``n``; NaN where ``M`` is singular or an input is not finite.

    Examples
    --------
    The separation principle: the loop's poles are those of ``F + G K`` and
    ``F - L_p C`` (python-control's ``dlqr`` and ``dlqe``):

    >>> import numpy as np, control, robustctl as rc
    >>> from moo.tuning.output_feedback import observer_controllers
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], 0.1, C=[[1.0, 0.0]])
    >>> K = -control.dlqr(plant.F, plant.G, np.eye(2), [[1.0]])[0]
    >>> est = rc.kalman_gains(plant, 1e-3 * np.eye(2), [[1e-2]], Bw=np.eye(2))
    >>> batch = observer_controllers(plant, K[None], est.F, est.G, est.L, est.J)
    >>> Lp = control.dlqe(plant.F, np.eye(2), plant.C, 1e-3 * np.eye(2), [[1e-2]])[0]
    >>> want = np.r_[np.linalg.eigvals(plant.F + plant.G @ K), np.linalg.eigvals(plant.F - Lp @ plant.C)]
    >>> bool(np.allclose(np.sort_complex(np.linalg.eigvals(batch.closed_loops()[0])), np.sort_complex(want)))
    True
    """
    C, D = plant.output_matrices()
    n, m, p = plant.n, plant.m, plant.p
    with np.errstate(all="ignore"):
        Lp = Fe @ Lf + J
        M = np.eye(m) + K @ Lf @ D
        ok = np.isfinite(M).all(axis=(1, 2)) & np.isfinite(Lp).all(axis=(1, 2)) & np.isfinite(K).all(axis=(1, 2))
        if ok.any():
            ok[ok] &= np.linalg.svd(M[ok], compute_uv=False)[:, -1] > 1e-12 * (1.0 + np.abs(M[ok]).max(axis=(1, 2)))
        Ms = np.where(ok[:, None, None], M, np.eye(m))
        KLf = np.where(ok[:, None, None], K @ Lf, 0.0)
        Dc = np.linalg.solve(Ms, KLf)
        Cc = np.linalg.solve(Ms, np.where(ok[:, None, None], K @ (np.eye(n) - Lf @ C), 0.0))
        Ac = Fe + Ge @ Cc - Lp @ (C + D @ Cc)
        Bc = Lp @ (np.eye(p) - D @ Dc) + Ge @ Dc
    bad = ~ok[:, None, None]
    return rc.ControllerBatch(plant, *(np.where(bad, np.nan, X) for X in (Ac, Bc, Cc, Dc)))


def _combined(batch: rc.ControllerBatch, ok: np.ndarray, reason: np.ndarray) -> FamilyControllers:
    """:func:`_result` with the designs' own flags (regulator, estimator) folded in."""
    res = _result(batch)
    ok_all = res.ok & ok
    why = np.where(ok_all, "", np.where(ok, res.reason, reason)).astype(object)
    if (~ok_all & res.ok).any():
        mats = (batch.Ac, batch.Bc, batch.Cc, batch.Dc)
        batch = rc.ControllerBatch(batch.plant, *(np.where(ok_all[:, None, None], M, np.nan) for M in mats))
        return FamilyControllers(batch, ok_all, why)
    return FamilyControllers(res.controllers, ok_all, why)


class LQGFamily(_OutputFamily):
    r"""LQG controllers of diagonal weights: the LQR on the steady-state Kalman filter's estimate.

    ``z = (log10 diag Q (n), log10 diag R (m), log10 diag W (nw), log10 diag V (p))``:
    the regulator's weights and the noise covariances the filter is designed
    for (design knobs, as in loop-transfer recovery), all designs of a
    population solved as stacks (:func:`~moo.tuning.dlqr_gains`,
    :func:`robustctl.kalman_gains`), combined in the filter form
    (:func:`observer_controllers`).

    Parameters
    ----------
    plant : robustctl.Plant
        Discrete time, with measured outputs; stabilisable and detectable.
    Bw : (n, nw) array_like, optional
        The process-noise input of the filter (default ``plant.Bw``, else the identity).
    log_bound : float
        Default bounds ``[-log_bound, log_bound]`` of every variable (default 4).

    Attributes
    ----------
    n_var : int
        ``n + m + nw + p``.
    xl, xu : (n_var,) ndarray
    order : int
        ``n`` (the controller's order).

    Raises
    ------
    TypeError, ValueError
        ``plant`` not a discrete-time plant with outputs, not stabilisable or
        not detectable; ``Bw`` of the wrong shape; a non-positive ``log_bound``.

    See Also
    --------
    RobustLQGFamily, robustctl.lqg, robustctl.kalman_gains, moo.tuning.LQRFamily

    Notes
    -----
    .. math::

        K = \text{DLQR}(F, G; 10^{z_Q}, 10^{z_R}), \qquad
        L_f = \text{Kalman}(F, B_w, C; 10^{z_W}, 10^{z_V}), \qquad
        u = K\, \hat x_{k|k} .

    References
    ----------
    .. [1] K. J. Astrom, *Introduction to Stochastic Control Theory*,
       Academic Press 1970, Ch. 8 (LQG and the separation principle).

    Examples
    --------
    ``z = 0`` is ``Q = I``, ``R = 1``, ``W = I``, ``V = 1``; the loop's poles
    are the LQR's and the Kalman predictor's (python-control):

    >>> import numpy as np, control
    >>> import robustctl as rc
    >>> from moo.tuning import LQGFamily
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], 0.1, C=[[1.0, 0.0]])
    >>> fam = LQGFamily(plant)
    >>> fam.n_var
    6
    >>> batch = fam.gains(np.zeros((1, 6))).controllers
    >>> K = -control.dlqr(plant.F, plant.G, np.eye(2), [[1.0]])[0]
    >>> Lp = control.dlqe(plant.F, np.eye(2), plant.C, np.eye(2), [[1.0]])[0]
    >>> want = np.r_[np.linalg.eigvals(plant.F + plant.G @ K), np.linalg.eigvals(plant.F - Lp @ plant.C)]
    >>> bool(np.allclose(np.sort_complex(np.linalg.eigvals(batch.closed_loops()[0])), np.sort_complex(want)))
    True
    """

    def __init__(self, plant: rc.Plant, *, Bw=None, log_bound: float = 4.0):
        self._set_plant(plant, "LQGFamily", discrete=True)
        if not plant.has_outputs:
            raise ValueError("plant must have measured outputs (C) for LQGFamily; without them use LQRFamily")
        if not plant.is_stabilizable:
            raise ValueError("plant must be stabilisable for LQGFamily")
        if not plant.is_detectable:
            raise ValueError("plant must be detectable (its unstable modes seen by C) for LQGFamily")
        self.Bw = _noise_input(plant, Bw)
        n, m, p, nw = plant.n, plant.m, plant.p, self.Bw.shape[1]
        self._sizes = (n, m, nw, p)
        self.order = n
        self.n_var = n + m + nw + p
        b = check_positive_scalar(log_bound, "log_bound")
        self.xl, self.xu = np.full(self.n_var, -b), np.full(self.n_var, b)

    def weights(self, Z) -> tuple[np.ndarray, ...]:
        """``(Q, R, W, V)`` stacks (diagonal) of a population ``Z``."""
        z = self._check(Z)
        out, o = [], 0
        with np.errstate(over="ignore"):
            for size in self._sizes:
                out.append(10.0 ** z[:, o:o + size, None] * np.eye(size))
                o += size
        return tuple(out)

    def gains(self, Z) -> FamilyControllers:
        """:class:`~moo.tuning.FamilyControllers` of a population ``Z`` (B, n_var)."""
        Q, R, W, V = self.weights(Z)
        K, _, k_ok = dlqr_gains(self.plant.F, self.plant.G, Q, R)
        finite = np.isfinite(W).all(axis=(1, 2)) & np.isfinite(V).all(axis=(1, 2)) \
            & (np.diagonal(V, axis1=1, axis2=2) > 0).all(axis=1)
        eye_w, eye_p = np.eye(W.shape[-1]), np.eye(V.shape[-1])
        est = rc.kalman_gains(self.plant, np.where(finite[:, None, None], W, eye_w),
                              np.where(finite[:, None, None], V, eye_p), Bw=self.Bw, form="filter")
        ok = k_ok & finite & np.asarray(est.ok, dtype=bool)
        reason = np.where(~k_ok, "regulator not converged", np.where(~finite, "weights under- or overflow",
                                                                    np.asarray(est.reason, dtype=object)))
        batch = observer_controllers(self.plant, np.where(ok[:, None, None], K, np.nan), est.F, est.G, est.L,
                                     est.J)
        return _combined(batch, ok, reason)

    def __repr__(self) -> str:
        n, m, nw, p = self._sizes
        return f"LQGFamily(n={n}, m={m}, p={p}, nw={nw}, n_var={self.n_var})"


class RobustLQGFamily(_OutputFamily):
    r"""Robust LQG: the RLQR on the robust filter's estimate, their uncertainty parameters tuned.

    The paper's method for a plant with sensors: a decision vector is one
    candidate uncertainty model ``[dF dG] = H Delta [E_F E_G]`` (shared by
    the regulator and the filter, as :func:`robustctl.rlqg`) and the two
    penalties,

    .. math::

        z = \big(\operatorname{vec}_r E_F\ (l n),\ \operatorname{vec}_r E_G\ (l m),\
        (\log_{10}\mu)^2,\ (\log_{10}\mu_f)^2\big),

    the gain the steady-state RLQR of that model (:func:`robustctl.rlqr_gains`),
    the estimator the steady-state robust filter (:func:`robustctl.robust_kalman_gains`,
    filter form, penalty :math:`\mu_f`), combined as :func:`observer_controllers`.

    Parameters
    ----------
    plant : robustctl.Plant
        Discrete time, with measured outputs; stabilisable and detectable.
    H : (n, l) array_like, optional
        Uncertainty input; default ``ones((n, 1))`` (the paper's).
    Q, R : array_like, optional
        The RLQR's weights (default identities).
    W, V : array_like, optional
        The filter's noise covariances (default identities).
    Bw : (n, nw) array_like, optional
        The filter's process-noise input (default ``plant.Bw``, else the identity).
    alpha : float
        ``lambda = (1 + alpha) ||mu H'H||`` of both (default 0.1).
    e_bound, log_mu_bound : float
        Default upper bounds of the ``E`` entries (lower bound 0) and of both
        ``(log10 mu)^2`` (default 100 and 100).

    Attributes
    ----------
    n_var : int
        ``l (n + m) + 2``.
    xl, xu : (n_var,) ndarray
    order : int

    Raises
    ------
    TypeError, ValueError
        As :class:`LQGFamily`; ``H``, ``Q``, ``R``, ``W``, ``V`` of the wrong
        shape (the message names the matrix), a non-positive ``alpha`` or bound.

    See Also
    --------
    LQGFamily, moo.tuning.RLQRFamily, robustctl.rlqg

    References
    ----------
    .. [1] D. C. Morais et al., "Robust path-following control design of heavy
       vehicles based on multiobjective evolutionary optimization", Expert
       Systems with Applications 192 (2022) 116304.
    .. [2] J. Y. Ishihara, M. H. Terra, J. P. Cerri, "Optimal robust filtering
       for systems subject to uncertainties", Automatica 52, 2015.

    Examples
    --------
    With no uncertainty (``E = 0``) and large penalties the robust LQG is the
    LQG of the same weights:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import LQGFamily, RobustLQGFamily
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], 0.1, C=[[1.0, 0.0]])
    >>> robust = RobustLQGFamily(plant).gains(np.array([[0.0, 0.0, 0.0, 144.0, 144.0]])).controllers
    >>> nominal = LQGFamily(plant).gains(np.zeros((1, 6))).controllers
    >>> bool(np.allclose(robust.Ac, nominal.Ac, atol=1e-6)), bool(np.allclose(robust.Dc, nominal.Dc, atol=1e-6))
    (True, True)
    """

    def __init__(self, plant: rc.Plant, *, H=None, Q=None, R=None, W=None, V=None, Bw=None, alpha: float = 0.1,
                 e_bound: float = 100.0, log_mu_bound: float = 100.0):
        self._set_plant(plant, "RobustLQGFamily", discrete=True)
        if not plant.has_outputs:
            raise ValueError("plant must have measured outputs (C) for RobustLQGFamily; without them use RLQRFamily")
        if not plant.is_stabilizable:
            raise ValueError("plant must be stabilisable for RobustLQGFamily")
        if not plant.is_detectable:
            raise ValueError("plant must be detectable (its unstable modes seen by C) for RobustLQGFamily")
        n, m, p = plant.n, plant.m, plant.p
        self.H = np.ones((n, 1)) if H is None else as_matrix(H, "H", rows=n, rows_what="the number of states")
        self.l = self.H.shape[1]
        self.Q = np.eye(n) if Q is None else as_matrix(Q, "Q", rows=n, cols=n, rows_what="the number of states")
        self.R = np.eye(m) if R is None else as_matrix(R, "R", rows=m, cols=m, rows_what="the number of inputs")
        self.Bw = _noise_input(plant, Bw)
        nw = self.Bw.shape[1]
        self.W = np.eye(nw) if W is None else as_matrix(W, "W", rows=nw, cols=nw, rows_what="the columns of Bw")
        self.V = np.eye(p) if V is None else as_matrix(V, "V", rows=p, cols=p, rows_what="the number of outputs")
        self.alpha = check_positive_scalar(alpha, "alpha")
        self.order = n
        l = self.l
        self.n_var = l * (n + m) + 2
        self.xl = np.zeros(self.n_var)
        self.xu = np.full(self.n_var, check_positive_scalar(e_bound, "e_bound"))
        self.xu[-2:] = check_positive_scalar(log_mu_bound, "log_mu_bound")
        self.gains(np.zeros((1, self.n_var)))                 # checks Q, R, W, V against the designs' own checks

    def decode(self, Z) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(EF (B, l, n), EG (B, l, m), mu (B,), mu_filter (B,))`` of a population ``Z``."""
        z = self._check(Z)
        if np.any(z[:, -2:] < 0):
            raise ValueError(f"the last two variables of Z, (log10 mu)^2, must be >= 0, got {z[:, -2:].min():g}")
        B, l, n, m = z.shape[0], self.l, self.n_states, self.n_inputs
        EF = z[:, :l * n].reshape(B, l, n).copy()
        EG = z[:, l * n:l * (n + m)].reshape(B, l, m).copy()
        with np.errstate(over="ignore"):
            return EF, EG, 10.0 ** np.sqrt(z[:, -2]), 10.0 ** np.sqrt(z[:, -1])

    def gains(self, Z) -> FamilyControllers:
        """:class:`~moo.tuning.FamilyControllers` of a population ``Z`` (B, n_var)."""
        EF, EG, mu, mu_f = self.decode(Z)
        reg = rc.rlqr_gains(self.plant, EF, EG, mu, Q=self.Q, R=self.R, H=self.H, alpha=self.alpha)
        est = rc.robust_kalman_gains(self.plant, self.W, self.V, Bw=self.Bw, H=self.H, EF=EF, EG=EG, mu=mu_f,
                                     alpha=self.alpha, form="filter")
        r_ok, e_ok = np.asarray(reg.ok, dtype=bool), np.asarray(est.ok, dtype=bool)
        ok = r_ok & e_ok & np.isfinite(reg.K).all(axis=(1, 2))
        reason = np.where(~r_ok, np.char.add("regulator: ", np.asarray(reg.reason, dtype=str)),
                          np.char.add("filter: ", np.asarray(est.reason, dtype=str))).astype(object)
        batch = observer_controllers(self.plant, np.where(ok[:, None, None], reg.K, np.nan), est.F, est.G, est.L,
                                     est.J)
        return _combined(batch, ok, reason)

    def __repr__(self) -> str:
        return (f"RobustLQGFamily(n={self.n_states}, m={self.n_inputs}, p={self.n_outputs}, l={self.l}, "
                f"n_var={self.n_var})")


def _noise_input(plant: rc.Plant, Bw) -> np.ndarray:
    """``Bw`` (n rows), else ``plant.Bw``, else the identity (as :func:`robustctl.kalman`)."""
    if Bw is not None:
        return as_matrix(Bw, "Bw", rows=plant.n, rows_what="the number of states")
    return np.eye(plant.n) if plant.Bw is None else np.array(plant.Bw)
