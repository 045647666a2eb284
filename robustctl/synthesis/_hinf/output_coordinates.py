r"""The coordinates in which the output-feedback LMIs are posed (cf. :mod:`.coordinates` for state feedback).

Stage 1, :func:`standard`: changes that do not alter the optimum, only the
solver's path (each recorded and undone on the result):

1. every channel to unit size: ``w = w_scale w~`` with
   ``||[B1; D21] w_scale|| = 1`` and ``z = z_unit z~`` with
   ``||[C1 D11~ D12]|| = z_unit`` (its level scales by ``w_scale / z_unit``);
2. the states balanced (SLICOT ``TB01ID`` on ``[[A, [B1 B2]], [[C1; C2], 0]]``);
3. ``u`` and ``y`` to unit size: each column of ``[B2; D12]`` and each row
   of ``[C2 D21]`` of unit norm.

Stage 2, :class:`Frame`: *separate* coordinates for the two Lyapunov
variables. ``X`` transforms like a controllability Gramian and ``Y`` like
an observability one, and near the optimum ``X Y`` has eigenvalues from 1
(where the coupling ``[X I; I Y] >= 0`` is active) to ``1e10`` and more
(states that ``w`` hardly excites or ``z`` hardly sees: the Riccati
solutions of the regular problem, ``gamma X_inf^-1`` and ``gamma
Y_inf^-1``, are nearly singular there). No similarity makes both well
conditioned (it keeps the eigenvalues of ``X Y``), and the interior-point
solver then stops with the level ``1e-5`` to ``1e-4`` above the optimum
while reporting ``optimal`` (measured on random plants with 10 states).
The LMIs stay linear under the congruence ``diag(S^-1, T')`` of their
``2 n`` rows with the change of variables ``X = S X~ S'``,
``Y = T^-T Y~ T^-1``, ``Ah = T^-T Ah~ S'``, ``Bh = T^-T Bh~``,
``Ch = Ch~ S'`` for *any* invertible ``S``, ``T`` (``S = T`` is a
similarity): the ``X`` part then sees the plant in ``x = S x_s``, the ``Y``
part in ``x = T x_t``, the cross terms become ``S^-1 A T`` and the identity
of the coupling ``W = S^-1 T``. With ``S S' ~ X0`` and ``T^-T T^-1 ~ Y0``
(shapes of the optimal ``X`` and ``Y`` from the two Riccati equations,
:mod:`.output_shapes`) both variables are ~ I and the level comes out
within ``1e-7`` of the Riccati bisection's in about 20 iterations.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .coordinates import _balance as balance
from .coordinates import lifted
from .generalised import Channel, DynamicGain, Generalised

__all__ = ["Standard", "Frame", "FrameChannel", "standard", "frame_of_shapes", "SHAPE_FLOOR"]

#: The shapes ``X0``, ``Y0`` are lifted to at least ``SHAPE_FLOOR`` of their largest eigenvalue before factoring.
SHAPE_FLOOR = 1e-12


@dataclass(frozen=True, eq=False)
class Standard:
    """Stage 1: the plant in unit channels, balanced states and unit ``u``, ``y``; and how to map back.

    ``level_scales[k]``: a level of channel ``k`` in the caller's units times
    this is its level in ``plant``; ``u = diag(su) u~``, ``y~ = diag(sy) y``;
    ``d``: the balancing ``x = diag(d) x~``.
    """

    plant: Generalised
    level_scales: tuple[float, ...]
    su: np.ndarray
    sy: np.ndarray
    d: np.ndarray

    def caller_controller(self, K: DynamicGain) -> DynamicGain:
        """The controller of the caller's ``u`` and ``y`` (a controller's states are its own)."""
        return K.io_scaled(self.su, self.sy)


def _unit(x: float) -> float:
    return x if x > 0 and np.isfinite(x) else 1.0


def standard(plant: Generalised) -> Standard:
    """Stage 1 of the module docstring."""
    chans, scales = [], []
    for c in plant.channels:
        w = 1.0 / _unit(float(np.linalg.norm(np.vstack([c.B1, c.D21]), 2)))
        z = _unit(float(np.linalg.norm(np.hstack([c.C1, c.D11 * w, c.D12]), 2)))
        chans.append(c.scaled(w, z))
        scales.append(w / z)
    data = Generalised(plant.A, plant.B2, plant.C2, tuple(chans), plant.discrete)
    d = balance(data.A, np.hstack([c.B1 for c in chans]), data.B2, np.vstack([*[c.C1 for c in chans], data.C2]))
    data = data.to(np.diag(d))
    su = 1.0 / np.array([_unit(v) for v in np.linalg.norm(
        np.vstack([data.B2, *[c.D12 for c in data.channels]]), axis=0)])
    sy = 1.0 / np.array([_unit(v) for v in np.linalg.norm(
        np.hstack([data.C2, *[c.D21 for c in data.channels]]), axis=1)])
    return Standard(data.with_io_scaling(su, sy), tuple(scales), su, sy, d)


@dataclass(frozen=True, eq=False)
class FrameChannel:
    """A channel seen by the ``X`` part (``B1s = S^-1 B1``, ``C1s = C1 S``) and the ``Y`` part (``T``)."""

    B1s: np.ndarray
    C1s: np.ndarray
    B1t: np.ndarray
    C1t: np.ndarray
    D11: np.ndarray
    D12: np.ndarray
    D21: np.ndarray


@dataclass(frozen=True, eq=False)
class Frame:
    """Stage 2: the plant (standard coordinates) as ``X~`` (``x = S x_s``) and ``Y~`` (``x = T x_t``) see it.

    Derived: ``As = S^-1 A S``, ``B2s = S^-1 B2``, ``C2s = C2 S``; ``At``,
    ``B2t``, ``C2t`` likewise with ``T``; the cross terms ``Ast = S^-1 A T``,
    ``Ats = T^-1 A S``; ``W = S^-1 T`` and ``Wi = T^-1 S``; and each channel
    (:class:`FrameChannel`). ``S = T = I`` is the textbook form.
    """

    plant: Generalised
    S: np.ndarray
    T: np.ndarray
    As: np.ndarray = field(init=False)
    B2s: np.ndarray = field(init=False)
    C2s: np.ndarray = field(init=False)
    At: np.ndarray = field(init=False)
    B2t: np.ndarray = field(init=False)
    C2t: np.ndarray = field(init=False)
    Ast: np.ndarray = field(init=False)
    Ats: np.ndarray = field(init=False)
    W: np.ndarray = field(init=False)
    Wi: np.ndarray = field(init=False)
    channels: tuple[FrameChannel, ...] = field(init=False)

    def __post_init__(self):
        g, S, T = self.plant, self.S, self.T
        Si, Ti = np.linalg.inv(S), np.linalg.inv(T)
        AS, AT = g.A @ S, g.A @ T
        derived = dict(As=Si @ AS, B2s=Si @ g.B2, C2s=g.C2 @ S, At=Ti @ AT, B2t=Ti @ g.B2, C2t=g.C2 @ T,
                       Ast=Si @ AT, Ats=Ti @ AS, W=Si @ T, Wi=Ti @ S,
                       channels=tuple(FrameChannel(Si @ c.B1, c.C1 @ S, Ti @ c.B1, c.C1 @ T, c.D11, c.D12, c.D21)
                                      for c in g.channels))
        for k, v in derived.items():
            object.__setattr__(self, k, v)

    @property
    def discrete(self) -> bool:
        return self.plant.discrete

    @property
    def n(self) -> int:
        return self.plant.n

    def with_channel(self, k: int, channel: Channel) -> Frame:
        """The frame with channel ``k`` of the plant replaced (e.g. ``z`` scaled to a level of 1)."""
        chans = list(self.plant.channels)
        chans[k] = channel
        g = self.plant
        return Frame(Generalised(g.A, g.B2, g.C2, tuple(chans), g.discrete), self.S, self.T)


def frame_of_shapes(plant: Generalised, X0: np.ndarray | None, Y0: np.ndarray | None) -> Frame:
    """The frame with ``S S' = X0`` and ``T^-T T^-1 = Y0`` (Cholesky; both lifted by ``SHAPE_FLOOR``).

    ``S = T = I`` when a shape is missing or not usable.
    """
    eye = np.eye(plant.n)
    X0 = None if X0 is None else lifted(X0, SHAPE_FLOOR)
    Y0 = None if Y0 is None else lifted(Y0, SHAPE_FLOOR)
    if X0 is None or Y0 is None:
        return Frame(plant, eye, eye)
    return Frame(plant, np.linalg.cholesky(X0), np.linalg.inv(np.linalg.cholesky(Y0)).T)
