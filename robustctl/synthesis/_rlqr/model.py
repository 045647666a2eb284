"""The one validation of the RLQR's arguments, and the batched problem data it builds."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._kkt import check_penalty
from ..._validation import as_batch, as_float_array, as_matrix, check_positive_scalar
from ...errors import RankConditionError
from ...systems.plant import check_plant
from ...systems.uncertainty import check_norm_bounded
from ..lqr import _weights

#: ``EG`` has full row rank when its smallest singular value exceeds this times its largest.
RANK_TOL = 1e-12


@dataclass(frozen=True, eq=False)
class Model:
    """Batched RLQR data: ``F, G, Q, R, H`` shared, one uncertainty and penalty per design.

    ``S = mu^-1 I - lambda^-1 H H'`` and ``lam_inv = 1 / lambda`` with
    ``lambda = (1 + alpha) mu ||H'H||``; with ``H = 0`` (no uncertainty) the
    ``lambda -> 0`` limit: ``EF = EG = 0`` and ``S = mu^-1 I``.
    """

    F: np.ndarray        # (n, n)
    G: np.ndarray        # (n, m)
    Q: np.ndarray        # (n, n)
    R: np.ndarray        # (m, m)
    H: np.ndarray        # (n, p)
    alpha: float
    mu: np.ndarray       # (B,)
    EF: np.ndarray       # (B, l, n)
    EG: np.ndarray       # (B, l, m)
    S: np.ndarray        # (B, n, n)
    lam_inv: np.ndarray  # (B,)
    soft: bool           # some mu of the batch is finite (S != 0); a selection keeps its batch's value
    h_norm2: float       # ||H'H||_2

    @property
    def size(self) -> int:
        """Number of designs (the batch size ``B``)."""
        return self.mu.shape[0]

    def lam(self) -> np.ndarray:
        """``lambda`` per design (0 without uncertainty, ``inf`` at ``mu = inf``).

        Reported only (the recursion uses ``lam_inv``, computed from ``1 / mu``):
        where ``(1 + alpha) mu ||H'H||`` exceeds the float range, ``inf``.
        """
        if self.h_norm2 == 0.0:
            return np.zeros_like(self.mu)
        with np.errstate(over="ignore"):
            return (1.0 + self.alpha) * self.mu * self.h_norm2

    def select(self, mask: np.ndarray) -> Model:
        """The designs selected by the boolean ``mask`` (or index array)."""
        if mask.dtype == bool and mask.all():
            return self
        return Model(self.F, self.G, self.Q, self.R, self.H, self.alpha, self.mu[mask], self.EF[mask],
                     self.EG[mask], self.S[mask], self.lam_inv[mask], self.soft, self.h_norm2)

    def rank_ok(self) -> np.ndarray:
        """Per design: unless ``mu = inf`` with ``H != 0``, True; else ``EG`` (l x m) has full row rank l."""
        ok = np.ones(self.size, dtype=bool)
        inf = np.isinf(self.mu)
        if inf.any() and self.h_norm2 > 0:
            l, m = self.EG.shape[1:]
            if l > m:
                ok[inf] = False
            else:
                sv = np.linalg.svd(self.EG[inf], compute_uv=False)
                ok[inf] = sv[:, -1] > RANK_TOL * np.maximum(sv[:, 0], 1e-300)
        return ok

    def rank_error(self) -> RankConditionError:
        """The error for the first design of the batch (what :func:`rlqr` raises), with the numbers of the test."""
        l, m = self.EG.shape[1:]
        head = f"mu = inf needs EG ({l}x{m}) to have full row rank {l} (equivalently [I -G; 0 -EG] of full row rank)"
        tail = "; use a finite mu or change EG"
        if l > m:
            return RankConditionError(f"{head}, but it has more rows than columns (rank at most {m}){tail}")
        sv = np.linalg.svd(self.EG[0], compute_uv=False)
        rank = int(np.sum(sv > RANK_TOL * max(float(sv[0]), 1e-300)))
        cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else np.inf
        return RankConditionError(
            f"{head}, got numerical rank {rank}: its singular values are {np.array2string(sv, precision=3)}, "
            f"condition number {cond:.3g}, and full rank needs the smallest above {RANK_TOL:g} times the largest "
            f"(condition number below {1 / RANK_TOL:.3g}){tail}")


def _norm2(H: np.ndarray) -> float:
    """``||H'H||_2 = ||H||_2^2``."""
    return float(np.linalg.norm(H, 2) ** 2) if H.size else 0.0


def _uncertainty(plant, EF, EG, H, uncertainty):
    """``(EF, EG, H)`` from the explicit matrices or from ``uncertainty``, never both."""
    if uncertainty is None:
        for name, value in (("EF", EF), ("EG", EG)):
            if value is None:
                raise TypeError(f"{name} is required: give EF and EG (or uncertainty=NormBounded(H, EF, EG))")
        return EF, EG, H
    check_norm_bounded(uncertainty, plant)
    if EF is not None or EG is not None or H is not None:
        raise TypeError("give either uncertainty=NormBounded(...) or EF, EG (and H), not both")
    return uncertainty.EF, uncertainty.EG, uncertainty.H


def _as_designs(value, name: str, shape, what, batch: bool) -> np.ndarray:
    """One matrix (l, k) or, for a batch, also a stack (B, l, k), as a stack."""
    if not batch:
        return as_matrix(value, name, rows=shape[0], cols=shape[1], rows_what=what[0], cols_what=what[1])[None]
    arr = as_float_array(value, name)
    if arr.ndim < 3:
        arr = np.atleast_2d(arr)[None]
    return as_batch(arr, name, (None, *shape), ("", *what))


def build(plant, EF, EG, mu, *, Q, R, H, alpha, uncertainty=None, batch: bool) -> Model:
    """Check every argument shared by :func:`rlqr`, :func:`rlqr_schedule` and :func:`rlqr_gains`.

    ``batch``: ``EF``, ``EG`` may be stacks (B, l, n), (B, l, m) and ``mu``
    a 1-D array, any of them without the batch axis to be shared.
    """
    check_plant(plant, discrete_for="the RLQR")
    n, m = plant.n, plant.m
    EF, EG, H = _uncertainty(plant, EF, EG, H, uncertainty)
    EF = _as_designs(EF, "EF", (None, n), ("", "the number of states"), batch)
    l = EF.shape[1]
    EG = _as_designs(EG, "EG", (l, m), ("the rows of EF", "the number of inputs"), batch)
    mu = check_penalty(mu, batch=batch, what="rlqr (use rlqr_gains for batches)")
    sizes = {EF.shape[0], EG.shape[0], mu.shape[0]} - {1}
    if len(sizes) > 1:
        raise ValueError(f"batch sizes differ: EF {EF.shape[0]}, EG {EG.shape[0]}, mu {mu.shape[0]}")
    B = sizes.pop() if sizes else 1
    Q, R = _weights(plant, Q, R)
    H = np.ones((n, l)) if H is None else as_matrix(H, "H", rows=n, vector="column",
                                                   rows_what="the number of states")
    alpha = check_positive_scalar(alpha, "alpha")
    EF, EG, mu = (np.broadcast_to(a, (B, *a.shape[1:])) for a in (EF, EG, mu))
    with np.errstate(divide="ignore"):
        mu_inv = np.where(np.isinf(mu), 0.0, 1.0 / mu)
    hh = _norm2(H)
    if hh == 0.0:  # no uncertainty: the lambda -> 0 limit, EF and EG drop out
        EF, EG = np.zeros_like(EF), np.zeros_like(EG)
        lam_inv = np.ones_like(mu)
        S = mu_inv[:, None, None] * np.eye(n)
    else:  # S = mu^-1 (I - H H' / ((1 + alpha) ||H'H||)) >= 0
        lam_inv = mu_inv / ((1.0 + alpha) * hh)
        S = mu_inv[:, None, None] * (np.eye(n) - H @ H.T / ((1.0 + alpha) * hh))
    return Model(plant.F, plant.G, Q, R, H, alpha, mu, EF, EG, S, lam_inv, bool(np.any(mu_inv > 0)), hh)
