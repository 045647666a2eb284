r"""The common result of every design: a state feedback ``u = K x`` or a dynamic output feedback ``u = K(z) y``.

Sign convention (the paper's): no minus sign in the feedback. A state
feedback is ``u = K x``; a dynamic output feedback of order ``nc`` is

.. math::

    x_c^+ = A_c x_c + B_c y, \qquad u = C_c x_c + D_c y

(``x_c'`` in continuous time), with ``y = C x + D u`` the plant's measured
outputs (the state itself for a plant without an output model). python-control
returns ``K_pc`` with ``u = -K_pc x``, so ``K == -K_pc``; its ``hinfsyn``
controller is used in a positive-feedback loop and equals ours. The closed
loop and its assembly are in :mod:`robustctl.systems.interconnect`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any

import numpy as np

from .._validation import as_batch, as_float_array, as_matrix, check_square, frozen
from . import interconnect
from .plant import Plant, check_plant
from .stability import STABILITY_MARGIN, is_stable, spectral_abscissa, spectral_radius

__all__ = ["Controller", "ControllerBatch"]


def _state_plant(plant: Plant) -> Plant:
    """``plant`` seen by a state feedback: the whole state measured (no output model)."""
    return plant if not plant.has_outputs else replace(plant, C=None, D=None)


def _controller_matrices(plant: Plant, Ac, Bc, Cc, Dc, batch: bool) -> tuple[np.ndarray, ...]:
    """``(Ac, Bc, Cc, Dc)`` checked against ``plant`` (stacks with a leading axis when ``batch``)."""
    m, p = plant.m, plant.p
    if not batch:
        Dc = as_matrix(Dc, "Dc", rows=m, cols=p, rows_what="the number of inputs", cols_what="the number of outputs")
        Ac = np.zeros((0, 0)) if np.size(Ac) == 0 else check_square(as_matrix(Ac, "Ac"), "Ac")
        nc = Ac.shape[0]
        Bc = np.zeros((0, p)) if nc == 0 and np.size(Bc) == 0 else as_matrix(
            Bc, "Bc", rows=nc, cols=p, rows_what="the controller order, from Ac", cols_what="the number of outputs")
        Cc = np.zeros((m, 0)) if nc == 0 and np.size(Cc) == 0 else as_matrix(
            Cc, "Cc", rows=m, cols=nc, rows_what="the number of inputs", cols_what="the controller order, from Ac")
        return Ac, Bc, Cc, Dc
    Dc = as_float_array(Dc, "Dc")
    if Dc.ndim != 3 or Dc.shape[0] == 0:
        raise ValueError(f"Dc must be a non-empty stack (B, {m}, {p}) (designs, inputs, outputs), got shape "
                         f"{Dc.shape}")
    B = Dc.shape[0]
    Ac = as_float_array(Ac, "Ac")
    nc = Ac.shape[-1] if Ac.ndim == 3 else 0
    out = []
    for name, value, shape, what in (
            ("Ac", Ac, (B, nc, nc), ("designs", "the controller order", "the controller order")),
            ("Bc", Bc, (B, nc, p), ("designs", "the controller order", "the number of outputs")),
            ("Cc", Cc, (B, m, nc), ("designs", "the number of inputs", "the controller order")),
            ("Dc", Dc, (B, m, p), ("designs", "the number of inputs", "the number of outputs"))):
        arr = as_float_array(value, name)
        if arr.shape != shape:
            raise ValueError(f"{name} must have shape {shape} ({', '.join(what)}), got shape {arr.shape}")
        out.append(arr)
    return tuple(out)


@dataclass(frozen=True, eq=False, repr=False)
class Controller:
    r"""A designed controller: state feedback ``u = K x`` or dynamic output feedback ``u = K(z) y``.

    Every design method returns one (or a subclass with more attributes,
    e.g. :class:`~robustctl.HinfController`). Build a state feedback as
    ``Controller(K, method, plant)`` and a dynamic one with
    :meth:`Controller.dynamic`.

    Parameters
    ----------
    K : (m, n) array_like or None
        State-feedback gain, ``u = K x``; None for a dynamic controller.
    method : str
        Name of the design method (``"lqr"``, ``"rlqr"``, ``"hinf"``, ...).
    plant : Plant
        The (nominal) plant it was designed for.
    info : Mapping, optional
        Diagnostics of the design, stored read-only.
    Ac, Bc, Cc, Dc : array_like, optional
        A dynamic controller ``xc+ = Ac xc + Bc y``, ``u = Cc xc + Dc y``
        (shapes ``(nc, nc)``, ``(nc, p)``, ``(m, nc)``, ``(m, p)``; ``nc = 0``
        is a static output feedback ``u = Dc y``); give all four and no ``K``.

    Attributes
    ----------
    K : (m, n) ndarray or None
    Ac, Bc, Cc, Dc : ndarray or None
        None for a state feedback.
    method : str
    plant : Plant
    info : Mapping

    Raises
    ------
    TypeError
        ``plant`` is not a :class:`~robustctl.Plant`.
    ValueError
        Shapes that do not match the plant (named), both ``K`` and the
        controller matrices, or neither.

    See Also
    --------
    ControllerBatch : a stack of controllers of one plant.
    robustctl.systems.interconnect : the closed loop and loop transfers.

    Notes
    -----
    The closed loop in the states ``(x, x_c)`` is, with ``E = (I - D_c D)^{-1}``,

    .. math::

        A_{cl} = \begin{bmatrix} F + G E D_c C & G E C_c \\
                 B_c (C + D E D_c C) & A_c + B_c D E C_c \end{bmatrix},

        \qquad F + G K \text{ for a state feedback.}

    Examples
    --------
    An observer-based controller of a scalar plant equals python-control's
    feedback of the plant and ``K(z)`` (positive feedback, our sign):

    >>> import numpy as np, control
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.2]], [[1.0]], 0.1, C=[[1.0]])
    >>> ctrl = rc.Controller.dynamic([[0.3]], [[0.9]], [[-0.5]], [[-0.4]], "manual", plant)
    >>> ctrl.order, ctrl.K is None, ctrl.is_stabilizing()
    (1, True, True)
    >>> ref = control.feedback(plant.to_statespace(), ctrl.controller_statespace(), sign=+1)
    >>> bool(np.allclose(np.sort(ctrl.closed_loop_poles()), np.sort(ref.poles())))
    True
    """

    K: np.ndarray | None
    method: str
    plant: Plant
    info: Mapping[str, Any] = field(default_factory=dict)
    Ac: np.ndarray | None = None
    Bc: np.ndarray | None = None
    Cc: np.ndarray | None = None
    Dc: np.ndarray | None = None

    def __post_init__(self):
        check_plant(self.plant)
        matrices = (self.Ac, self.Bc, self.Cc, self.Dc)
        if self.K is not None:
            if any(M is not None for M in matrices):
                raise ValueError("give either K (state feedback) or Ac, Bc, Cc, Dc (output feedback), not both")
            K = as_matrix(self.K, "K", rows=self.plant.m, cols=self.plant.n,
                          rows_what="the number of inputs", cols_what="the number of states")
            object.__setattr__(self, "K", frozen(K))
        else:
            if any(M is None for M in matrices):
                raise ValueError(f"K must be a gain ({self.plant.m}, {self.plant.n}) for a state feedback, or None "
                                 "with all of Ac, Bc, Cc, Dc for an output feedback (Controller.dynamic)")
            for name, M in zip(("Ac", "Bc", "Cc", "Dc"),
                               _controller_matrices(self.plant, *matrices, batch=False), strict=True):
                object.__setattr__(self, name, frozen(M))
        object.__setattr__(self, "info", MappingProxyType(dict(self.info)))

    @classmethod
    def dynamic(cls, Ac, Bc, Cc, Dc, method: str, plant: Plant, info: Mapping[str, Any] | None = None) -> Controller:
        """A dynamic output feedback ``xc+ = Ac xc + Bc y``, ``u = Cc xc + Dc y`` of ``plant``.

        Parameters
        ----------
        Ac, Bc, Cc, Dc : array_like
            ``(nc, nc)``, ``(nc, p)``, ``(m, nc)``, ``(m, p)``; ``nc = 0`` is ``u = Dc y``.
        method : str
        plant : Plant
        info : Mapping, optional

        Returns
        -------
        Controller

        Examples
        --------
        >>> import robustctl as rc
        >>> plant = rc.Plant([[0.5]], [[1.0]], 0.1, C=[[2.0]])
        >>> rc.Controller.dynamic([], [], [], [[-0.1]], "static output feedback", plant).order
        0
        """
        return cls(None, method, plant, {} if info is None else info, Ac=Ac, Bc=Bc, Cc=Cc, Dc=Dc)

    # -- what it is ----------------------------------------------------------
    @property
    def is_dynamic(self) -> bool:
        """Whether this is an output feedback ``u = K(z) y`` (False: a state feedback ``u = K x``)."""
        return self.K is None

    @property
    def order(self) -> int:
        """Number of controller states ``nc`` (0 for a state feedback or a static output feedback)."""
        return 0 if self.Ac is None else self.Ac.shape[0]

    def as_batch(self) -> ControllerBatch:
        """The controller as a :class:`ControllerBatch` of one (a state feedback reads the whole state)."""
        if self.K is not None:
            return ControllerBatch.from_gains(self.plant, self.K[None])
        return ControllerBatch(self.plant, *(M[None] for M in self._matrices()))

    def _matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(Ac, Bc, Cc, Dc)`` of a dynamic controller."""
        assert self.Ac is not None and self.Bc is not None and self.Cc is not None and self.Dc is not None
        return self.Ac, self.Bc, self.Cc, self.Dc

    # -- the loop ------------------------------------------------------------
    def __call__(self, x) -> np.ndarray:
        """``K @ x`` for one state (n,) or a stack of states (..., n); a state feedback only."""
        if self.K is None:
            raise TypeError("a dynamic controller has a state of its own: use controller_statespace(), or "
                            "simulate the closed loop (to_statespace())")
        x = as_float_array(x, "x")
        if x.shape[-1:] != (self.plant.n,):
            raise ValueError(f"x must have {self.plant.n} entries in its last axis "
                             f"(the number of states), got shape {x.shape}")
        if not np.all(np.isfinite(x)):
            raise ValueError("x must have finite entries (found NaN or inf)")
        return x @ self.K.T

    def closed_loop(self, plant: Plant | None = None) -> np.ndarray:
        """The closed-loop state matrix: ``F + G K``, or ``A_cl`` in the states ``(x, xc)`` (class Notes).

        ``plant`` (default: the design plant) may be another plant of the same
        sizes, e.g. a perturbed one; it keeps the design plant's outputs if it has none.
        """
        p = self._plant(plant)
        if self.K is not None:
            return p.F + p.G @ self.K
        return self._batch_loop(p).A[0]

    def closed_loop_poles(self, plant: Plant | None = None) -> np.ndarray:
        """Eigenvalues of :meth:`closed_loop`."""
        return np.linalg.eigvals(self.closed_loop(plant))

    def is_stabilizing(self, plant: Plant | None = None) -> bool:
        """Whether the closed loop is stable, with the margin of :mod:`robustctl.systems.stability`.

        Spectral radius below ``1 - 1e-9`` (discrete) or every real part below
        ``-1e-9`` (continuous); an ill-posed loop (``I - Dc D`` singular) is not.
        """
        p = self._plant(plant)
        A = self.closed_loop(p)
        return bool(np.all(np.isfinite(A))) and is_stable(A, discrete=p.is_discrete)

    def to_statespace(self, plant: Plant | None = None):
        """The closed loop as a python-control ``StateSpace``: input ``v`` added at ``u``, output ``x``.

        States ``x`` (and ``xc``); ``u = K x + v`` or ``u = Cc xc + Dc y + v``.
        Because python-control feeds back with a minus sign, for a state
        feedback this equals ``control.feedback(plant.to_statespace(), -K)``.

        Examples
        --------
        >>> import numpy as np, control
        >>> import robustctl as rc
        >>> plant = rc.Plant([[1.1]], [[1.0]], 0.1)
        >>> sys = rc.Controller([[-0.6]], "manual", plant).to_statespace()
        >>> float(sys.A[0, 0]), float(control.dcgain(sys))
        (0.5, 2.0)
        """
        import control

        p = self._plant(plant)
        if self.K is not None:
            A, Bv = self.closed_loop(p), p.G
        else:
            loop = self._batch_loop(p)
            A, Bv = loop.A[0], loop.B[0]
        N = A.shape[0]
        return control.ss(A, Bv, np.eye(p.n, N), np.zeros((p.n, p.m)), 0 if p.dt is None else p.dt)

    def controller_statespace(self):
        """``K(z)`` itself, from ``y`` to ``u``, as a python-control ``StateSpace`` (a static gain for ``u = K x``).

        Examples
        --------
        >>> import robustctl as rc
        >>> plant = rc.Plant([[0.5]], [[1.0]], 0.1)
        >>> rc.Controller([[-0.2]], "manual", plant).controller_statespace().D
        array([[-0.2]])
        """
        import control

        dt = 0 if self.plant.dt is None else self.plant.dt
        if self.K is not None:
            return control.ss(np.zeros((0, 0)), np.zeros((0, self.plant.n)), np.zeros((self.plant.m, 0)), self.K, dt)
        return control.ss(self.Ac, self.Bc, self.Cc, self.Dc, dt)

    def _batch_loop(self, plant: Plant) -> interconnect.ClosedLoop:
        Cm, Dm = (plant if plant.has_outputs else self.plant).output_matrices()
        return interconnect.closed_loop(plant.F, plant.G, Cm, Dm, *(M[None] for M in self._matrices()))

    def _plant(self, plant: Plant | None) -> Plant:
        if plant is None:
            return self.plant
        check_plant(plant)
        if (plant.n, plant.m) != (self.plant.n, self.plant.m):
            raise ValueError(f"plant must have n={self.plant.n} states and m={self.plant.m} inputs, "
                             f"got n={plant.n}, m={plant.m}")
        if self.K is None and plant.has_outputs and plant.p != self.plant.p:
            raise ValueError(f"plant must have p={self.plant.p} outputs like the design plant, got p={plant.p}")
        return plant

    def __repr__(self) -> str:
        with np.printoptions(precision=4, suppress=False, linewidth=100):
            if self.K is not None:
                body = "K=" + np.array2string(self.K, separator=", ", prefix="    K=")
            else:
                body = f"order={self.order}, Dc=" + np.array2string(self._matrices()[3], separator=", ",
                                                                    prefix="    Dc=")
        return (f"Controller(method={self.method!r}, plant={self.plant!r}, "
                f"stabilizing={self.is_stabilizing()},\n    {body})")


@dataclass(frozen=True, eq=False, repr=False)
class ControllerBatch:
    r"""A stack of ``B`` controllers of one plant: ``xc+ = Ac[b] xc + Bc[b] y``, ``u = Cc[b] xc + Dc[b] y``.

    What a population of a tuning family is, and what the batched analyses
    (:func:`robustctl.robust_stability`, :func:`robustctl.loop_margins`, ...)
    take. A stack of state feedbacks ``u = K[b] x`` is
    :meth:`ControllerBatch.from_gains`; ``(plant, K)`` always means state feedback.

    Parameters
    ----------
    plant : Plant
        ``y = C x + D u`` (the state, for a plant without an output model).
    Ac, Bc, Cc, Dc : array_like
        ``(B, nc, nc)``, ``(B, nc, p)``, ``(B, m, nc)``, ``(B, m, p)``;
        ``nc = 0`` is a stack of static output feedbacks ``u = Dc[b] y``.
        Non-finite entries are allowed: such designs are not stabilising.

    Raises
    ------
    TypeError
        ``plant`` is not a :class:`~robustctl.Plant`.
    ValueError
        A shape that does not match (named).

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.1]], [[1.0]], 0.1, C=[[1.0]])
    >>> batch = rc.ControllerBatch(plant, np.zeros((3, 0, 0)), np.zeros((3, 0, 1)), np.zeros((3, 1, 0)),
    ...                            [[[-0.5]], [[-1.0]], [[-2.5]]])
    >>> len(batch), batch.is_stabilizing().tolist()
    (3, [True, True, False])
    >>> bool(np.allclose(batch.closed_loops()[:, 0, 0], [0.6, 0.1, -1.4]))
    True
    """

    plant: Plant
    Ac: np.ndarray
    Bc: np.ndarray
    Cc: np.ndarray
    Dc: np.ndarray

    def __post_init__(self):
        check_plant(self.plant)
        for name, M in zip(("Ac", "Bc", "Cc", "Dc"),
                           _controller_matrices(self.plant, self.Ac, self.Bc, self.Cc, self.Dc, batch=True),
                           strict=True):
            object.__setattr__(self, name, frozen(M))

    @classmethod
    def from_gains(cls, plant: Plant, K) -> ControllerBatch:
        """A stack of state feedbacks ``u = K[b] x`` (``K`` (B, m, n)) as a batch of static controllers.

        The batch's plant is ``plant`` with the whole state measured (its
        output model, if any, is not what a state feedback reads).

        Examples
        --------
        >>> import numpy as np
        >>> import robustctl as rc
        >>> batch = rc.ControllerBatch.from_gains(rc.Plant([[1.1]], [[1.0]], 0.1), np.full((2, 1, 1), -0.6))
        >>> batch.order, batch.closed_loops().ravel().round(6).tolist()
        (0, [0.5, 0.5])
        """
        check_plant(plant)
        K = as_batch(K, "K", (None, plant.m, plant.n), ("designs", "the number of inputs", "the number of states"))
        B = K.shape[0]
        return cls(_state_plant(plant), np.zeros((B, 0, 0)), np.zeros((B, 0, plant.n)), np.zeros((B, plant.m, 0)),
                   K)

    def __len__(self) -> int:
        return self.Dc.shape[0]

    def __getitem__(self, i: int) -> Controller:
        return Controller.dynamic(self.Ac[i], self.Bc[i], self.Cc[i], self.Dc[i], "batch", self.plant)

    @property
    def order(self) -> int:
        """Number of controller states ``nc`` (0: static feedbacks)."""
        return self.Ac.shape[-1]

    def closed_loop(self, plant: Plant | None = None) -> interconnect.ClosedLoop:
        """The closed loops (:func:`robustctl.systems.interconnect.closed_loop`) with ``plant`` (default: the batch's).

        ``plant`` may be another plant of the same sizes (e.g. a scenario); one
        without outputs keeps the batch plant's ``C`` and ``D``.
        """
        p = self._plant(plant)
        Cm, Dm = (p if p.has_outputs else self.plant).output_matrices()
        return interconnect.closed_loop(p.F, p.G, Cm, Dm, self.Ac, self.Bc, self.Cc, self.Dc)

    def closed_loops(self, plant: Plant | None = None) -> np.ndarray:
        """The closed-loop state matrices (B, n + nc, n + nc) (NaN for an ill-posed loop)."""
        return self.closed_loop(plant).A

    def is_stabilizing(self, plant: Plant | None = None) -> np.ndarray:
        """Stable closed loops (B,) bool, with the margin of :mod:`robustctl.systems.stability`."""
        p = self._plant(plant)
        A = self.closed_loops(p)
        finite = np.isfinite(A).all(axis=(1, 2))
        radius = np.full(len(self), np.inf)
        if finite.any():
            radius[finite] = (spectral_radius(A[finite]) if p.is_discrete else spectral_abscissa(A[finite]))
        return radius < (1.0 - STABILITY_MARGIN if p.is_discrete else -STABILITY_MARGIN)

    def _plant(self, plant: Plant | None) -> Plant:
        if plant is None:
            return self.plant
        check_plant(plant)
        if (plant.n, plant.m) != (self.plant.n, self.plant.m) or (plant.has_outputs and plant.p != self.plant.p):
            raise ValueError(f"plant must have n={self.plant.n}, m={self.plant.m}, p={self.plant.p} like the "
                             f"batch's plant, got n={plant.n}, m={plant.m}, p={plant.p}")
        if plant.dt != self.plant.dt:
            raise ValueError(f"plant must have the batch plant's sampling time dt={self.plant.dt}, got dt={plant.dt}")
        return plant

    def __repr__(self) -> str:
        return f"ControllerBatch(B={len(self)}, order={self.order}, plant={self.plant!r})"
