"""The common result of every design method: a static state feedback ``u = K x``."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from ._validation import as_matrix
from .plant import Plant, _frozen

__all__ = ["Controller"]


@dataclass(frozen=True, eq=False, repr=False)
class Controller:
    """State feedback ``u = K x`` designed for ``plant``.

    Sign convention: ``u = K x`` (the paper's). python-control's ``lqr`` and
    ``dlqr`` return ``K_pc`` with ``u = -K_pc x``, so ``K == -K_pc``.

    Attributes
    ----------
    K : (m, n) ndarray
        The gain.
    method : str
        Name of the design method (``"lqr"``, ``"rlqr"``, ``"hinf"``).
    plant : Plant
        The (nominal) plant the gain was designed for.
    info : Mapping
        Read-only diagnostics of the design (iterations, residuals, solver status, ...).
    """

    K: np.ndarray
    method: str
    plant: Plant
    info: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        K = as_matrix(self.K, "K", rows=self.plant.m, cols=self.plant.n,
                      rows_what="the number of inputs", cols_what="the number of states")
        object.__setattr__(self, "K", _frozen(K))
        object.__setattr__(self, "info", MappingProxyType(dict(self.info)))

    def __call__(self, x) -> np.ndarray:
        """``K @ x`` for one state (n,) or a stack of states (..., n)."""
        x = np.asarray(x, dtype=float)
        if x.shape[-1:] != (self.plant.n,):
            raise ValueError(f"x must have {self.plant.n} entries in its last axis "
                             f"(the number of states), got shape {x.shape}")
        return x @ self.K.T

    def closed_loop(self, plant: Plant | None = None) -> np.ndarray:
        """``F + G K`` for the nominal plant, or for ``plant`` (e.g. a perturbed one)."""
        p = self._plant(plant)
        return p.F + p.G @ self.K

    def closed_loop_poles(self, plant: Plant | None = None) -> np.ndarray:
        return np.linalg.eigvals(self.closed_loop(plant))

    def is_stabilizing(self, plant: Plant | None = None) -> bool:
        """Spectral radius of ``F + G K`` below 1 (discrete) or all real parts < 0 (continuous)."""
        p = self._plant(plant)
        poles = self.closed_loop_poles(p)
        if p.is_discrete:
            return bool(np.max(np.abs(poles)) < 1.0)
        return bool(np.max(poles.real) < 0.0)

    def _plant(self, plant: Plant | None) -> Plant:
        if plant is None:
            return self.plant
        if not isinstance(plant, Plant):
            raise TypeError(f"plant must be a robustctl.Plant, got {type(plant).__name__}")
        if (plant.n, plant.m) != (self.plant.n, self.plant.m):
            raise ValueError(f"plant must have n={self.plant.n} states and m={self.plant.m} inputs, "
                             f"got n={plant.n}, m={plant.m}")
        return plant

    def __repr__(self) -> str:
        with np.printoptions(precision=4, suppress=False, linewidth=100):
            k = np.array2string(self.K, separator=", ", prefix="    K=")
        return (f"Controller(method={self.method!r}, plant={self.plant!r}, "
                f"stabilizing={self.is_stabilizing()},\n    K={k})")
