r"""The generalised plant of output-feedback synthesis, on plain arrays.

Plant (discrete, ``x+``; continuous, ``x'``), with one or more performance
*channels* ``w_k -> z_k`` sharing the state, the control input and the
measurement::

    x+  = A x + B1_k w_k + B2 u
    z_k = C1_k x + D11_k w_k + D12_k u
    y   = C2 x + D21_k w_k + D22 u

A controller ``K = (Ak, Bk, Ck, Dk)``: ``xc+ = Ak xc + Bk y``,
``u = Ck xc + Dk y`` (no minus sign). With ``D22 = 0`` the closed loop of
channel ``k`` in the states ``(x, xc)`` is

.. math::

    A_{cl} = \begin{bmatrix} A + B_2 D_k C_2 & B_2 C_k \\ B_k C_2 & A_k \end{bmatrix},\;
    B_{cl} = \begin{bmatrix} B_1 + B_2 D_k D_{21} \\ B_k D_{21} \end{bmatrix},\;
    C_{cl} = [C_1 + D_{12} D_k C_2,\ D_{12} C_k],\; D_{cl} = D_{11} + D_{12} D_k D_{21}.

A ``D22 != 0`` is removed first (:func:`loop_shift`): the synthesis sees
``y~ = y - D22 u`` and the controller designed for ``y~`` is closed around
``D22`` afterwards.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from ...errors import InfeasibleError

__all__ = ["Channel", "Generalised", "DynamicGain", "loop_shift", "closed_loop"]


@dataclass(frozen=True, eq=False)
class Channel:
    """One performance channel ``w -> z``: ``B1`` (n, nw), ``C1`` (nz, n), ``D11``, ``D12`` (nz, m), ``D21`` (p, nw)."""

    B1: np.ndarray
    C1: np.ndarray
    D11: np.ndarray
    D12: np.ndarray
    D21: np.ndarray

    @property
    def nw(self) -> int:
        return self.B1.shape[1]

    @property
    def nz(self) -> int:
        return self.C1.shape[0]

    def scaled(self, w: float, z: float) -> Channel:
        """The channel of ``w = w w~`` and ``z = z z~``: its level is multiplied by ``w / z``."""
        return Channel(self.B1 * w, self.C1 / z, self.D11 * (w / z), self.D12 / z, self.D21 * w)


@dataclass(frozen=True, eq=False)
class Generalised:
    """``A``, ``B2``, ``C2`` (``D22 = 0``) and the channels; ``discrete`` for ``x+``."""

    A: np.ndarray
    B2: np.ndarray
    C2: np.ndarray
    channels: tuple[Channel, ...]
    discrete: bool

    @property
    def n(self) -> int:
        return self.A.shape[0]

    @property
    def m(self) -> int:
        return self.B2.shape[1]

    @property
    def p(self) -> int:
        return self.C2.shape[0]

    def to(self, T: np.ndarray) -> Generalised:
        """The same plant in the state coordinates ``x = T x^``."""
        Ti = np.linalg.inv(T)
        return replace(self, A=Ti @ self.A @ T, B2=Ti @ self.B2, C2=self.C2 @ T,
                       channels=tuple(replace(c, B1=Ti @ c.B1, C1=c.C1 @ T) for c in self.channels))

    def with_io_scaling(self, su: np.ndarray, sy: np.ndarray) -> Generalised:
        """The plant of ``u = diag(su) u~`` and ``y~ = diag(sy) y`` (a controller of it is ``diag(su) K~ diag(sy)``)."""
        return replace(self, B2=self.B2 * su, C2=sy[:, None] * self.C2,
                       channels=tuple(replace(c, D12=c.D12 * su, D21=sy[:, None] * c.D21) for c in self.channels))


class DynamicGain(NamedTuple):
    """A controller ``xc+ = Ak xc + Bk y``, ``u = Ck xc + Dk y`` (arrays; ``Ak`` may be empty)."""

    Ak: np.ndarray
    Bk: np.ndarray
    Ck: np.ndarray
    Dk: np.ndarray

    def io_scaled(self, su: np.ndarray, sy: np.ndarray) -> DynamicGain:
        """``diag(su) K diag(sy)``: the controller of the plant before :meth:`Generalised.with_io_scaling`."""
        return DynamicGain(self.Ak, self.Bk * sy, su[:, None] * self.Ck, su[:, None] * self.Dk * sy)

    def is_finite(self) -> bool:
        return all(np.all(np.isfinite(M)) for M in self)


def closed_loop(plant: Generalised, K: DynamicGain, k: int = 0) -> tuple[np.ndarray, ...]:
    """``(Acl, Bcl, Ccl, Dcl)`` of channel ``k`` (module docstring; ``D22 = 0``)."""
    c = plant.channels[k]
    A, B2, C2 = plant.A, plant.B2, plant.C2
    Ak, Bk, Ck, Dk = K
    Acl = np.block([[A + B2 @ Dk @ C2, B2 @ Ck], [Bk @ C2, Ak]])
    Bcl = np.vstack([c.B1 + B2 @ Dk @ c.D21, Bk @ c.D21])
    Ccl = np.hstack([c.C1 + c.D12 @ Dk @ C2, c.D12 @ Ck])
    return Acl, Bcl, Ccl, c.D11 + c.D12 @ Dk @ c.D21


def loop_shift(K: DynamicGain, D22: np.ndarray) -> DynamicGain:
    """The controller of ``y = y~ + D22 u`` that acts as ``K`` does on ``y~``.

    ``u = K (y - D22 u)``: with ``Z = (I + Dk D22)^-1``, ``Ak - Bk D22 Z Ck``,
    ``Bk (I - D22 Z Dk)``, ``Z Ck``, ``Z Dk``. InfeasibleError if the loop
    is ill-posed (``I + Dk D22`` singular).
    """
    if not np.any(D22):
        return K
    Ak, Bk, Ck, Dk = K
    m = Dk.shape[0]
    S = np.eye(m) + Dk @ D22
    if np.linalg.cond(S) > 1e12:
        raise InfeasibleError("the controller's feedthrough Dk makes the loop with the plant's D ill-posed "
                              "(I + Dk D singular)")
    Z = np.linalg.inv(S)
    return DynamicGain(Ak - Bk @ D22 @ Z @ Ck, Bk @ (np.eye(D22.shape[0]) - D22 @ Z @ Dk), Z @ Ck, Z @ Dk)
