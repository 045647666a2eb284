r"""Batched closed-loop runs of dynamic output feedbacks ``u = K(z) (y - r)`` (an :class:`~robustctl.ControllerBatch`).

For ``B`` controllers of a :class:`~robustctl.ControllerBatch` and ``S``
plants at once, from the plant state ``x[0] = x0`` and the controller state
``xc[0] = 0``,

.. math::

    y[k] = C x[k] + D u[k], \qquad
    x_c[k+1] = A_c x_c[k] + B_c (y[k] - r[k]), \qquad
    u[k] = \operatorname{sat}\big(C_c x_c[k] + D_c (y[k] - r[k])\big), \qquad
    x[k+1] = F x[k] + G u[k],

the library's sign convention (no minus sign: a PID acting on ``e = r - y`` is
``K(z) = -C_{PID}(z)``). Only ``u`` saturates (``|u_j| <= u_limit_j``); the
controller state runs on the measured ``y``. With ``D != 0`` the loop has the
algebraic part ``u = E (D_c (C x - r) + C_c x_c)``, ``E = (I - D_c D)^{-1}``
(:mod:`robustctl.systems.interconnect`; saturation is then refused, since the
measured ``y`` would depend on the saturated ``u`` implicitly).

How: the loop is the state feedback ``u_a = K_a x_a`` of an augmented plant
(:func:`robustctl.systems.interconnect.augmented_gain`), run by the compiled
kernel of :mod:`robustctl.sim.simulator`. The reference is carried as ``p``
more plant states ``\rho[k] = r[k]`` (its next value enters as the known
disturbance ``w``), so the controller reads the output
``y - r = [C\ \ -I] (x, \rho) + D u`` of the plant
``(\operatorname{diag}(F, 0), [G; 0])``; with the augmented state
``x_a = (x, \rho, x_c)`` and input ``u_a = (u, x_c^+)``,

.. math::

    F_a = \operatorname{diag}(F, 0, 0), \quad
    G_a = \begin{bmatrix} G & 0 \\ 0 & 0 \\ 0 & I \end{bmatrix}, \quad
    K_a = \text{augmented\_gain}([C\ \ -I], D, A_c, B_c, C_c, D_c),

with saturation on the first ``m`` inputs only. The divergence bound of
:mod:`robustctl.sim.simulator` applies to ``x``, ``x_c`` and ``r``. Plants
of the same ``C`` and ``D`` share one run; a plant without an output model
takes the batch plant's ``C`` and ``D``.

References
----------
K. J. Astrom & R. M. Murray, *Feedback Systems*, 2nd ed., Princeton 2021,
Sec. 8.5 and 11.1 (output feedback, reference tracking).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .._validation import as_float_array, check_choice, check_int, check_positive_scalar
from ..systems.controller import ControllerBatch
from ..systems.interconnect import augmented_gain
from ..systems.plant import Plant, check_plants
from .simulator import BACKENDS, DEFAULT_BOUND, LinearSimulator, _limits

__all__ = ["OutputFeedbackSimulator", "OutputFeedbackResult", "simulate_output_feedback"]


@dataclass(frozen=True, eq=False, repr=False)
class OutputFeedbackResult:
    """Trajectories of ``B`` output feedbacks on ``S`` plants over ``T`` samples.

    What :meth:`OutputFeedbackSimulator.run` returns; the fields are
    attributes of the same names, ``errors`` (``y - r``) and ``T`` are derived.

    Parameters
    ----------
    states : (B, S, T, n) ndarray
        Plant states ``x[k]``, ``k = 0 .. T-1``.
    controller_states : (B, S, T, nc) ndarray
        ``x_c[k]`` (``nc = 0`` for static output feedbacks).
    inputs : (B, S, T, m) ndarray
        Applied (saturated) inputs ``u[k]``.
    outputs : (B, S, T, p) ndarray
        Measured outputs ``y[k] = C x[k] + D u[k]``.
    reference : (S, T, p) ndarray
        ``r[k]``.
    diverged : (B, S) bool ndarray
        The run left the divergence bound (then frozen; see :mod:`robustctl.sim.simulator`).
    diverged_step : (B, S) int ndarray
        First step beyond the bound, -1 if none.
    saturated_steps : (B, S) int ndarray
        Steps at which an input was at its limit.
    dt : float
        Sampling time.

    See Also
    --------
    simulate_output_feedback : makes it.

    Examples
    --------
    A static output feedback ``u = -0.4 (y - 1)`` of ``x+ = 0.5 x + u``,
    ``y = x``: ``x[k+1] = 0.1 x[k] + 0.4``, settling at ``0.4 / 0.9``:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.sim import simulate_output_feedback
    >>> plant = rc.Plant([[0.5]], [[1.0]], 0.1, C=[[1.0]])
    >>> batch = rc.ControllerBatch(plant, np.zeros((1, 0, 0)), np.zeros((1, 0, 1)), np.zeros((1, 1, 0)),
    ...                            [[[-0.4]]])
    >>> res = simulate_output_feedback(batch, [plant], 30, reference=np.ones((30, 1)))
    >>> res
    OutputFeedbackResult(B=1, S=1, T=30, n=1, nc=0, p=1, diverged=0/1)
    >>> bool(np.isclose(res.outputs[0, 0, -1, 0], 0.4 / 0.9)), bool(np.isclose(res.errors[0, 0, 0, 0], -1.0))
    (True, True)
    """

    states: np.ndarray
    controller_states: np.ndarray
    inputs: np.ndarray
    outputs: np.ndarray
    reference: np.ndarray
    diverged: np.ndarray
    diverged_step: np.ndarray
    saturated_steps: np.ndarray
    dt: float

    @property
    def errors(self) -> np.ndarray:
        """The controller's input ``y - r``, shape (B, S, T, p)."""
        return self.outputs - self.reference

    @property
    def T(self) -> int:
        """Number of samples."""
        return self.states.shape[2]

    def __repr__(self) -> str:
        B, S, T, n = self.states.shape
        return (f"OutputFeedbackResult(B={B}, S={S}, T={T}, n={n}, nc={self.controller_states.shape[-1]}, "
                f"p={self.outputs.shape[-1]}, diverged={int(self.diverged.sum())}/{self.diverged.size})")


class OutputFeedbackSimulator:
    """Plants, reference and options of :func:`simulate_output_feedback`, checked once; then runs batches.

    Parameters
    ----------
    plants : sequence of Plant
        ``S`` discrete-time plants of one ``n``, ``m`` and ``dt`` (outputs: their own ``C``, ``D``, or the
        batch plant's for a plant without an output model).
    steps : int
        Samples ``T`` (``k = 0 .. T-1``).
    x0 : (n,) or (S, n) array_like, optional
        Initial plant state (default zero); the controller starts from ``x_c = 0``.
    reference : (T, p) or (S, T, p) array_like, optional
        Reference ``r`` of the outputs (default zero: regulation).
    u_limit : float or (m,) array_like, optional
        Saturation ``|u_j| <= u_limit_j`` (default none); refused for plants with ``D != 0``.
    bound : float
        Divergence bound on ``|x|``, ``|x_c|`` and ``|r|`` (:mod:`robustctl.sim.simulator`).

    Raises
    ------
    TypeError, ValueError
        Plants that are not discrete-time plants of one size and sampling time,
        ``x0`` or ``reference`` of the wrong shape or not finite, ``steps`` not a
        positive integer, ``u_limit`` not positive or given with ``D != 0``.

    See Also
    --------
    simulate_output_feedback : build and run in one call.

    Examples
    --------
    Checked once, run for two populations; a design that does not stabilise
    the plant leaves the divergence bound and is flagged:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.sim import OutputFeedbackSimulator
    >>> plant = rc.Plant([[1.2]], [[1.0]], 0.1, C=[[1.0]])
    >>> sim = OutputFeedbackSimulator([plant, rc.Plant([[1.1]], [[1.0]], 0.1)], 200, x0=[1.0])
    >>> static = np.zeros((2, 0, 0)), np.zeros((2, 0, 1)), np.zeros((2, 1, 0))
    >>> res = sim.run(rc.ControllerBatch(plant, *static, [[[-0.7]], [[-0.05]]]))
    >>> res.diverged.tolist()
    [[False, False], [True, True]]
    >>> bool(np.isclose(res.outputs[0, 0, 3, 0], 0.5**3))            # x[k] = (1.2 - 0.7)^k
    True
    """

    def __init__(self, plants: Sequence[Plant], steps: int, *, x0=None, reference=None, u_limit=None,
                 bound: float = DEFAULT_BOUND):
        self.plants = tuple(check_plants(plants, "plants", discrete_for="simulation"))
        self.T = check_int(steps, "steps")
        first = self.plants[0]
        self.S, self.n, self.m = len(self.plants), first.n, first.m
        x = np.zeros(self.n) if x0 is None else as_float_array(x0, "x0")
        if x.shape not in ((self.n,), (self.S, self.n)) or not np.all(np.isfinite(x)):
            raise ValueError(f"x0 must be a finite ({self.n},) or ({self.S}, {self.n}) array (states; scenarios, "
                             f"states), got shape {x.shape}")
        self.x0 = np.broadcast_to(x, (self.S, self.n)).copy()
        self._reference = None if reference is None else as_float_array(reference, "reference")
        if self._reference is not None and (self._reference.ndim not in (2, 3) or self._reference.shape[-2] != self.T
                                            or not np.all(np.isfinite(self._reference))):
            raise ValueError(f"reference must be a finite (T, p) or (S, T, p) array with T={self.T}, got shape "
                             f"{self._reference.shape}")
        if self._reference is not None and self._reference.ndim == 3 and self._reference.shape[0] != self.S:
            raise ValueError(f"reference must have {self.S} scenarios along axis 0, got shape "
                             f"{self._reference.shape}")
        self.u_limit = None if u_limit is None else _limits(u_limit, self.m)
        if self.u_limit is not None and any(p.has_outputs and np.any(p.D) for p in self.plants):
            raise ValueError("u_limit: saturation with a plant feedthrough D != 0 is not supported (the measured y "
                             "would depend on the saturated u implicitly)")
        self.bound = check_positive_scalar(bound, "bound", allow_inf=True)

    def _outputs_of(self, batch: ControllerBatch) -> list[tuple[np.ndarray, np.ndarray]]:
        mats = []
        for i, p in enumerate(self.plants):
            C, D = (p if p.has_outputs else batch.plant).output_matrices()
            if C.shape[0] != batch.plant.p:
                raise ValueError(f"plants[{i}] has p={C.shape[0]} outputs, the controllers read {batch.plant.p}")
            mats.append((C, D))
        return mats

    def run(self, batch: ControllerBatch, *, backend: Literal["numba", "numpy"] = "numba") -> OutputFeedbackResult:
        """Every controller of ``batch`` on every plant (see the module docstring).

        Parameters
        ----------
        batch : ControllerBatch
            ``B`` controllers of a plant of the simulator's ``n``, ``m`` (and ``p``).
        backend : {"numba", "numpy"}
            The compiled kernel (default) or the numpy reference of :mod:`robustctl.sim.simulator`.

        Returns
        -------
        OutputFeedbackResult
        """
        if not isinstance(batch, ControllerBatch):
            raise TypeError(f"batch must be a robustctl.ControllerBatch, got {type(batch).__name__}")
        if (batch.plant.n, batch.plant.m) != (self.n, self.m):
            raise ValueError(f"batch is for n={batch.plant.n}, m={batch.plant.m}, the plants have n={self.n}, "
                             f"m={self.m}")
        check_choice(backend, "backend", BACKENDS)
        B, n, m, nc, p, S, T = len(batch), self.n, self.m, batch.order, batch.plant.p, self.S, self.T
        if self._reference is None:
            r = np.zeros((S, T, p))
        elif self._reference.shape[-1] == p:
            r = np.broadcast_to(self._reference, (S, T, p))
        else:
            raise ValueError(f"reference must have p={p} columns (the outputs), got shape {self._reference.shape}")
        mats = self._outputs_of(batch)
        X = np.empty((B, S, T, n))
        Xc = np.empty((B, S, T, nc))
        U = np.empty((B, S, T, m))
        Y = np.empty((B, S, T, p))
        div = np.empty((B, S), dtype=bool)
        div_step = np.empty((B, S), dtype=np.int64)
        sat = np.empty((B, S), dtype=np.int64)
        groups: dict[int, list[int]] = {}
        for s, (C, D) in enumerate(mats):       # plants of one (C, D) share the gains, hence one run
            key = next((g for g in groups if np.array_equal(mats[g][0], C) and np.array_equal(mats[g][1], D)), s)
            groups.setdefault(key, []).append(s)
        N = n + p + nc
        lim = None if self.u_limit is None else np.r_[self.u_limit, np.full(nc, np.inf)]
        for key, idx in groups.items():
            C, D = mats[key]
            # the reference as p more plant states rho with the output y - r = [C, -I] (x, rho) + D u
            gains, ok = augmented_gain(np.hstack([C, -np.eye(p)]), D, batch.Ac, batch.Bc, batch.Cc, batch.Dc)
            gains = np.where((ok & np.isfinite(gains).all(axis=(1, 2)))[:, None, None], gains, np.nan)
            Fa = np.zeros((len(idx), N, N))
            Ga = np.zeros((len(idx), N, m + nc))
            for j, s in enumerate(idx):
                Fa[j, :n, :n] = self.plants[s].F
                Ga[j, :n, :m] = self.plants[s].G
            Ga[:, n + p:, m:] = np.eye(nc)
            w = np.zeros((len(idx), T, N))
            w[:, :-1, n:n + p] = r[idx, 1:]                                          # rho[k+1] = r[k+1]
            x0 = np.concatenate([self.x0[idx], r[idx, 0], np.zeros((len(idx), nc))], axis=1)
            sim = LinearSimulator(Fa, Ga, np.zeros((T, N)), w=w, x0=x0, bound=self.bound, u_limit=lim)
            res = sim.run(gains, nan_gains="flag", backend=backend)
            assert res.errors is not None and res.inputs is not None
            xa, ua = res.errors, res.inputs                                          # x_ref = 0: errors are x_a
            X[:, idx], Xc[:, idx], U[:, idx] = xa[..., :n], xa[..., n + p:], ua[..., :m]
            Y[:, idx] = np.einsum("pn,bstn->bstp", C, xa[..., :n]) + np.einsum("pm,bstm->bstp", D, ua[..., :m])
            div[:, idx], div_step[:, idx], sat[:, idx] = res.diverged, res.diverged_step, res.saturated_steps
        return OutputFeedbackResult(states=X, controller_states=Xc, inputs=U, outputs=Y, reference=np.array(r),
                                    diverged=div, diverged_step=div_step, saturated_steps=sat,
                                    dt=float(self.plants[0].dt))  # type: ignore[arg-type]

    def __repr__(self) -> str:
        return (f"OutputFeedbackSimulator(S={self.S}, n={self.n}, m={self.m}, T={self.T}, "
                f"saturation={self.u_limit is not None})")


def simulate_output_feedback(batch: ControllerBatch, plants: Sequence[Plant], steps: int, *, x0=None,
                             reference=None, u_limit=None, bound: float = DEFAULT_BOUND,
                             backend: Literal["numba", "numpy"] = "numba") -> OutputFeedbackResult:
    r"""Run every controller of ``batch`` on every plant: ``u = K(z) (y - r)`` from ``x0`` and ``x_c = 0``.

    One call of ``OutputFeedbackSimulator(plants, steps, ...).run(batch)``
    (the module docstring has the loop and how it is run).

    Parameters
    ----------
    batch : ControllerBatch
        ``B`` controllers ``x_c^+ = A_c x_c + B_c e``, ``u = C_c x_c + D_c e``, ``e = y - r``.
    plants : sequence of Plant
        ``S`` discrete-time plants of the batch plant's ``n`` and ``m``.
    steps : int
        Samples ``T``.
    x0 : (n,) or (S, n) array_like, optional
        Initial plant state (default zero).
    reference : (T, p) or (S, T, p) array_like, optional
        Output reference (default zero).
    u_limit : float or (m,) array_like, optional
        Input saturation (plants with ``D = 0`` only).
    bound : float
        Divergence bound (:mod:`robustctl.sim.simulator`).
    backend : {"numba", "numpy"}
        The compiled kernel or the numpy reference.

    Returns
    -------
    OutputFeedbackResult
        States, controller states, inputs, outputs (``errors = outputs - reference``), divergence flags.

    Raises
    ------
    TypeError, ValueError
        See :class:`OutputFeedbackSimulator` and :meth:`OutputFeedbackSimulator.run`.

    See Also
    --------
    robustctl.sim.simulator.simulate_linear : the state-feedback runs it is built on.
    robustctl.systems.interconnect.augmented_gain : the augmented gain.

    Notes
    -----
    .. math::

        x_c[k+1] = A_c x_c[k] + B_c (y[k] - r[k]), \quad
        u[k] = \operatorname{sat}(C_c x_c[k] + D_c (y[k] - r[k])), \quad
        x[k+1] = F x[k] + G u[k], \quad y = C x + D u .

    References
    ----------
    .. [1] K. J. Astrom & R. M. Murray, *Feedback Systems*, 2nd ed., Princeton
       2021, Sec. 8.5 and 11.1.

    Examples
    --------
    An integral controller ``u = -0.25 / (z - 1) (y - r)`` (``0.25 / (z - 1)``
    acting on ``r - y``) of ``x+ = 0.5 x + u``, ``y = x``, tracks a unit step;
    python-control's step response of the same loop agrees:

    >>> import numpy as np, control
    >>> import robustctl as rc
    >>> from robustctl.sim import simulate_output_feedback
    >>> plant = rc.Plant([[0.5]], [[1.0]], 1.0, C=[[1.0]])
    >>> batch = rc.ControllerBatch(plant, [[[1.0]]], [[[-0.25]]], [[[1.0]]], [[[0.0]]])
    >>> res = simulate_output_feedback(batch, [plant], 100, reference=np.ones((100, 1)))
    >>> y = res.outputs[0, 0, :, 0]
    >>> loop = control.feedback(plant.to_statespace() * control.tf([0.25], [1, -1], 1.0))
    >>> _, y_pc = control.step_response(loop, np.arange(100.0))
    >>> bool(np.allclose(y, y_pc, atol=1e-12)), round(float(y[-1]), 4)
    (True, 1.0)
    """
    return OutputFeedbackSimulator(plants, steps, x0=x0, reference=reference, u_limit=u_limit,
                                   bound=bound).run(batch, backend=backend)
