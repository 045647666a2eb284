"""Norm-bounded parametric uncertainty ``[dF dG] = H Delta [EF EG]``, ``||Delta|| <= 1``.

Reference: Cerri, Terra & Ishihara (2009), "Recursive robust regulator for
discrete-time state-space systems", and Sayed (2001), "A framework for
state-space estimation with uncertain models", IEEE TAC 46(7).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._validation import as_batch, as_float_array, as_matrix
from .plant import Plant, _frozen, check_plant

__all__ = ["NormBounded", "check_norm_bounded"]


@dataclass(frozen=True, eq=False, repr=False)
class NormBounded:
    """Uncertainty ``dF = H Delta EF``, ``dG = H Delta EG`` with ``||Delta||_2 <= 1``.

    Parameters
    ----------
    H : (n, p) array_like (1-D is read as a column)
    EF : (l, n) array_like (1-D is read as a row)
    EG : (l, m) array_like (1-D is read as a row)
    """

    H: np.ndarray
    EF: np.ndarray
    EG: np.ndarray

    def __init__(self, H, EF, EG):
        EF = as_matrix(EF, "EF")
        l, n = EF.shape
        H = as_matrix(H, "H", rows=n, vector="column", rows_what="the number of states, from EF's columns")
        EG = as_matrix(EG, "EG", rows=l, rows_what="the rows of EF")
        object.__setattr__(self, "H", _frozen(H))
        object.__setattr__(self, "EF", _frozen(EF))
        object.__setattr__(self, "EG", _frozen(EG))

    @property
    def n(self) -> int:
        """Columns of EF (the number of states)."""
        return self.EF.shape[1]

    @property
    def m(self) -> int:
        """Columns of EG (the number of inputs)."""
        return self.EG.shape[1]

    @property
    def p(self) -> int:
        """Columns of H (rows of Delta)."""
        return self.H.shape[1]

    @property
    def l(self) -> int:  # noqa: E743 - the paper's name
        """Rows of EF and EG (columns of Delta)."""
        return self.EF.shape[0]

    def check_plant(self, plant: Plant) -> None:
        """Raise ``TypeError`` if ``plant`` is not a :class:`Plant`, ``ValueError`` if the sizes do not match it."""
        check_plant(plant)
        if (plant.n, plant.m) != (self.n, self.m):
            raise ValueError(f"uncertainty is for n={self.n} states and m={self.m} inputs, "
                             f"plant has n={plant.n}, m={plant.m}")

    def _deltas(self, Delta) -> np.ndarray:
        D = as_float_array(Delta, "Delta")
        if D.ndim == 0 or (D.ndim == 1 and self.p == 1 and self.l == 1):
            D = D.reshape(-1, 1, 1) if D.ndim else D.reshape(1, 1, 1)
        elif D.ndim == 2:
            D = D[None]
        D = as_batch(D, "Delta", (None, self.p, self.l), ("", "columns of H", "rows of EF"))
        norms = np.linalg.norm(D, ord=2, axis=(1, 2))
        if np.any(norms > 1 + 1e-12):
            raise ValueError(f"Delta must be a contraction (||Delta||_2 <= 1), got norm {norms.max():.6g}")
        return D

    def perturb(self, plant: Plant, Delta) -> Plant:
        """The plant ``(F + H Delta EF, G + H Delta EG)`` for one ``Delta`` (p x l, or a scalar if p = l = 1)."""
        self.check_plant(plant)
        D = self._deltas(Delta)
        if D.shape[0] != 1:
            raise ValueError(f"perturb takes one Delta; got {D.shape[0]} (use perturbed_matrices)")
        F, G = self.perturbed_matrices(plant, D[0])
        return Plant(F[0], G[0], plant.dt)

    def perturbed_matrices(self, plant: Plant, Deltas) -> tuple[np.ndarray, np.ndarray]:
        """Stacked perturbed matrices for S realisations ``Deltas`` of shape (S, p, l).

        Returns ``F`` of shape (S, n, n) and ``G`` of shape (S, n, m).
        A 1-D array with p = l = 1 is read as S scalar realisations.
        """
        self.check_plant(plant)
        D = self._deltas(Deltas)
        HD = np.einsum("np,spl->snl", self.H, D)
        return plant.F + HD @ self.EF, plant.G + HD @ self.EG

    def __repr__(self) -> str:
        return f"NormBounded(n={self.n}, m={self.m}, p={self.p}, l={self.l})"


def check_norm_bounded(value, plant: Plant, name: str = "uncertainty") -> NormBounded:
    """``value`` if it is a :class:`~robustctl.NormBounded` of ``plant``'s size.

    Otherwise a ``TypeError`` or ``ValueError`` naming ``name``.
    """
    if not isinstance(value, NormBounded):
        raise TypeError(f"{name} must be a robustctl.NormBounded, got {type(value).__name__}")
    value.check_plant(plant)
    return value
