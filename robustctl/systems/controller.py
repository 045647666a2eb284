"""The common result of every design method: a static state feedback ``u = K x``."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from .._validation import as_float_array, as_matrix, frozen
from .plant import Plant, check_plant
from .stability import is_stable

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
        check_plant(self.plant)
        K = as_matrix(self.K, "K", rows=self.plant.m, cols=self.plant.n,
                      rows_what="the number of inputs", cols_what="the number of states")
        object.__setattr__(self, "K", frozen(K))
        object.__setattr__(self, "info", MappingProxyType(dict(self.info)))

    def __call__(self, x) -> np.ndarray:
        """``K @ x`` for one state (n,) or a stack of states (..., n); the states must be finite."""
        x = as_float_array(x, "x")
        if x.shape[-1:] != (self.plant.n,):
            raise ValueError(f"x must have {self.plant.n} entries in its last axis "
                             f"(the number of states), got shape {x.shape}")
        if not np.all(np.isfinite(x)):
            raise ValueError("x must have finite entries (found NaN or inf)")
        return x @ self.K.T

    def closed_loop(self, plant: Plant | None = None) -> np.ndarray:
        """``F + G K`` for the nominal plant, or for ``plant`` (e.g. a perturbed one)."""
        p = self._plant(plant)
        return p.F + p.G @ self.K

    def closed_loop_poles(self, plant: Plant | None = None) -> np.ndarray:
        """Eigenvalues of :meth:`closed_loop`."""
        return np.linalg.eigvals(self.closed_loop(plant))

    def is_stabilizing(self, plant: Plant | None = None) -> bool:
        """Whether ``F + G K`` is stable, with the margin of :mod:`robustctl.systems.stability`.

        Spectral radius below ``1 - 1e-9`` (discrete) or every real part below ``-1e-9`` (continuous).
        """
        p = self._plant(plant)
        return is_stable(self.closed_loop(p), discrete=p.is_discrete)

    def to_statespace(self, plant: Plant | None = None):
        """The closed loop as a python-control ``StateSpace``: ``x+ = (F + G K) x + G v``, output ``x``.

        ``v`` is an input added to the feedback (``u = K x + v``). Because
        python-control feeds back with a minus sign, this equals
        ``control.feedback(plant.to_statespace(), -K)`` for our ``u = K x``.
        ``plant`` defaults to the design plant (give a perturbed one to close
        the loop around it).
        """
        import control

        p = self._plant(plant)
        return control.ss(self.closed_loop(p), p.G, np.eye(p.n), np.zeros((p.n, p.m)),
                          0 if p.dt is None else p.dt)

    def _plant(self, plant: Plant | None) -> Plant:
        if plant is None:
            return self.plant
        check_plant(plant)
        if (plant.n, plant.m) != (self.plant.n, self.plant.m):
            raise ValueError(f"plant must have n={self.plant.n} states and m={self.plant.m} inputs, "
                             f"got n={plant.n}, m={plant.m}")
        return plant

    def __repr__(self) -> str:
        with np.printoptions(precision=4, suppress=False, linewidth=100):
            k = np.array2string(self.K, separator=", ", prefix="    K=")
        return (f"Controller(method={self.method!r}, plant={self.plant!r}, "
                f"stabilizing={self.is_stabilizing()},\n    K={k})")
