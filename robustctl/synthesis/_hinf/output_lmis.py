r"""The output-feedback LMIs in the linearising variables, and the controller they define.

Variables (Gahinet & Apkarian 1994; Scherer, Gahinet & Chilali 1997):
``X = X'``, ``Y = Y'`` (n x n), ``Ah`` (n x n), ``Bh`` (n x p), ``Ch`` (m x n),
``Dh`` (m x p). For a channel of :class:`.generalised.Generalised`::

    AA = [A X + B2 Ch,  A + B2 Dh C2;  Ah,  Y A + Bh C2]
    BB = [B1 + B2 Dh D21;  Y B1 + Bh D21]
    CC = [C1 X + D12 Ch,  C1 + D12 Dh C2]
    DD = D11 + D12 Dh D21,          P = [X I; I Y]

They are the closed-loop matrices after the congruence by
``Pi1 = [X I; M' 0]``, ``Pi2 = [I Y; 0 N']`` with ``Xcl Pi1 = Pi2``,
``Xcl = [Y N; N' *]`` the closed-loop Lyapunov matrix (``V = xi' Xcl xi``)
and ``M N' = I - X Y``: ``Pi2' Acl Pi1 = AA``, ``Pi2' Bcl = BB``,
``Ccl Pi1 = CC``, ``Pi1' Xcl Pi1 = P``. Every closed-loop condition written
with ``Xcl`` becomes linear (``level_sq = gamma^2``, ``He(M) = M + M'``):

* H-infinity, continuous: ``[He(AA), BB, CC'; *, -I, DD'; *, *, -level_sq I] < 0``;
* H-infinity, discrete: ``[P, AA, BB, 0; *, P, 0, CC'; *, *, I, DD'; *, *, *, level_sq I] > 0``;
* H2, continuous: ``[He(AA), BB; *, -I] < 0``, ``[P, CC'; CC, Z] > 0`` and
  ``DD = 0``; discrete: ``[P, AA, BB; *, P, 0; *, *, I] > 0``,
  ``[Z, CC, DD; *, P, 0; *, *, I] > 0``; then ``||T_zw||_2^2 < trace(Z)``;
* pole region ``{z : L + M z + M' conj(z) < 0}`` (Chilali & Gahinet 1996):
  ``L (x) P + M (x) AA' + M' (x) AA < 0`` (the region LMI of ``Acl'`` with
  ``Xcl``, which has the eigenvalues of ``Acl``);
* continuous: ``P > 0`` (discrete: implied by the blocks above).

Everything here is written in a :class:`.output_coordinates.Frame`: the
variables are ``X~ = S^-1 X S^-T``, ``Y~ = T' Y T``, ``Ah~ = T' Ah S^-T``,
``Bh~ = T' Bh``, ``Ch~ = Ch S^-T``, ``Dh``, and every block is the one above
after the congruence ``diag(S^-1, T')`` of its ``2 n`` rows (the plant
matrices of the frame; ``I`` in ``P`` becomes ``W = S^-1 T``). The blocks
take cvxpy variables (to solve) or arrays (a candidate), with the same code.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ... import _cvx
from ...systems.regions import region_lmi
from .generalised import DynamicGain
from .output_coordinates import Frame

__all__ = ["OFPoint", "variables", "products", "lyapunov", "hinf_block", "h2_blocks", "h2_equality",
           "h2_feedthrough_removed", "region_blocks", "controller"]


@dataclass(frozen=True, eq=False)
class OFPoint:
    """The linearising variables of a frame: cvxpy variables (to solve) or arrays (a candidate)."""

    X: Any
    Y: Any
    Ah: Any
    Bh: Any
    Ch: Any
    Dh: Any

    def values(self) -> OFPoint:
        """The solution held by the cvxpy variables, as arrays (``X``, ``Y`` symmetrised)."""
        X, Y = _cvx.value(self.X), _cvx.value(self.Y)
        return OFPoint(0.5 * (X + X.T), 0.5 * (Y + Y.T), _cvx.value(self.Ah), _cvx.value(self.Bh),
                       _cvx.value(self.Ch), _cvx.value(self.Dh))


def variables(n: int, m: int, p: int) -> OFPoint:
    """Fresh cvxpy variables for ``n`` states, ``m`` inputs and ``p`` measurements."""
    import cvxpy as cp

    return OFPoint(cp.Variable((n, n), symmetric=True, name="X"), cp.Variable((n, n), symmetric=True, name="Y"),
                   cp.Variable((n, n), name="Ah"), cp.Variable((n, p), name="Bh"), cp.Variable((m, n), name="Ch"),
                   cp.Variable((m, p), name="Dh"))


def _bmat(rows):
    """``np.block`` when every entry is an array (a candidate point), else ``cvxpy.bmat``."""
    if all(isinstance(x, (np.ndarray, float, int, np.floating)) for row in rows for x in row):
        return np.block(rows)
    import cvxpy as cp

    return cp.bmat(rows)


def products(f: Frame, V: OFPoint, k: int = 0):
    """``(AA, BB, CC, DD)`` of channel ``k`` in the frame ``f`` (module docstring)."""
    c = f.channels[k]
    AA = _bmat([[f.As @ V.X + f.B2s @ V.Ch, f.Ast + f.B2s @ V.Dh @ f.C2t], [V.Ah, V.Y @ f.At + V.Bh @ f.C2t]])
    BB = _bmat([[c.B1s + f.B2s @ V.Dh @ c.D21], [V.Y @ c.B1t + V.Bh @ c.D21]])
    CC = _bmat([[c.C1s @ V.X + c.D12 @ V.Ch, c.C1t + c.D12 @ V.Dh @ f.C2t]])
    return AA, BB, CC, c.D11 + c.D12 @ V.Dh @ c.D21


def lyapunov(f: Frame, V: OFPoint):
    """``P = [X W; W' Y]``, the closed-loop Lyapunov matrix after the congruence."""
    return _bmat([[V.X, f.W], [f.W.T, V.Y]])


def _zeros(r: int, c: int) -> np.ndarray:
    return np.zeros((r, c))


def hinf_block(f: Frame, V: OFPoint, level_sq, k: int = 0, margin=0.0) -> _cvx.LMI:
    """``hinf[k]``: the bounded-real block of channel ``k`` at ``level_sq = gamma^2`` (as ``M >= margin I``)."""
    AA, BB, CC, DD = products(f, V, k)
    n2, nw, nz = 2 * f.n, BB.shape[1], CC.shape[0]
    if f.discrete:
        P = lyapunov(f, V)
        M = _bmat([[P, AA, BB, _zeros(n2, nz)],
                   [AA.T, P, _zeros(n2, nw), CC.T],
                   [BB.T, _zeros(nw, n2), np.eye(nw), DD.T],
                   [_zeros(nz, n2), CC, DD, level_sq * np.eye(nz)]])
    else:
        M = _bmat([[-(AA + AA.T), -BB, -CC.T],
                   [-BB.T, np.eye(nw), -DD.T],
                   [-CC, -DD, level_sq * np.eye(nz)]])
    return _cvx.LMI(f"hinf[{k}]", M, margin)


def h2_blocks(f: Frame, V: OFPoint, Z, k: int = 0, margin=0.0) -> list[_cvx.LMI]:
    """``h2_gramian[k]`` and ``h2_cost[k]``: ``||T_zw||_2^2 < trace(Z)`` for channel ``k``.

    Continuous time also needs :func:`h2_equality` (``DD = 0``).
    """
    AA, BB, CC, DD = products(f, V, k)
    P = lyapunov(f, V)
    n2, nw = 2 * f.n, BB.shape[1]
    if f.discrete:
        gram = _bmat([[P, AA, BB], [AA.T, P, _zeros(n2, nw)], [BB.T, _zeros(nw, n2), np.eye(nw)]])
        cost = _bmat([[Z, CC, DD], [CC.T, P, _zeros(n2, nw)], [DD.T, _zeros(nw, n2), np.eye(nw)]])
    else:
        gram = _bmat([[-(AA + AA.T), -BB], [-BB.T, np.eye(nw)]])
        cost = _bmat([[P, CC.T], [CC, Z]])
    return [_cvx.LMI(f"h2_gramian[{k}]", gram, margin), _cvx.LMI(f"h2_cost[{k}]", cost, margin)]


def h2_equality(f: Frame, V: OFPoint, k: int = 0) -> list:
    """Continuous H2: ``D12 Dh D21 = 0`` (a finite norm; the validation asks ``D11 = 0``), as cvxpy constraints.

    Written as ``Q12' Dh Q21 = 0`` with orthonormal bases ``Q12`` of the row
    space of ``D12`` and ``Q21`` of the column space of ``D21``: the same
    set, without the identically zero rows that ``D12 Dh D21 = 0`` has when
    ``D12`` has more rows than columns (they made Clarabel stop with a
    numerical error at its first step). None where it is void.
    """
    c = f.channels[k]
    if f.discrete:
        return []
    Q12, Q21 = _range_basis(c.D12.T), _range_basis(c.D21)
    if not (Q12.shape[1] and Q21.shape[1]):
        return []
    return [Q12.T @ V.Dh @ Q21 == 0]


def _range_basis(M: np.ndarray) -> np.ndarray:
    """An orthonormal basis of the column space of ``M`` (rank to the SVD's default tolerance)."""
    U, s, _ = np.linalg.svd(M, full_matrices=False)
    return U[:, : int(np.sum(s > max(M.shape) * np.finfo(float).eps * (s[0] if s.size else 0.0)))]


def h2_feedthrough_removed(f: Frame, V: OFPoint, k: int = 0) -> OFPoint:
    """Continuous H2: ``Dh`` projected onto ``D12 Dh D21 = 0`` (the solver meets it only to its tolerance).

    ``Dh - D12^+ D12 Dh D21 D21^+`` (the validation asks ``D11 = 0``), and
    exactly zero when ``D12`` has full column rank and ``D21`` full row rank,
    so that the closed loop has no feedthrough and a finite H2 norm.
    """
    c = f.channels[k]
    if f.discrete:
        return V
    m, p = V.Dh.shape
    if np.linalg.matrix_rank(c.D12) == m and np.linalg.matrix_rank(c.D21) == p:
        Dh = np.zeros((m, p))
    else:
        Dh = V.Dh - np.linalg.pinv(c.D12) @ c.D12 @ V.Dh @ c.D21 @ np.linalg.pinv(c.D21)
    return OFPoint(V.X, V.Y, V.Ah, V.Bh, V.Ch, Dh)


def region_blocks(regions, f: Frame, V: OFPoint, margin=0.0) -> list[_cvx.LMI]:
    """``poles[j]``: every closed-loop pole in region ``j`` (with the Lyapunov matrix of the other blocks)."""
    if not regions:
        return []
    AA = products(f, V, 0)[0]
    P = lyapunov(f, V)
    return [_cvx.LMI(f"poles[{j}]", region_lmi(r, AA.T, P), margin) for j, r in enumerate(regions)]


def controller(f: Frame, V: OFPoint) -> DynamicGain:
    """The controller of the variables ``V`` (arrays): the change of variables inverted, in the frame.

    With ``M N' = W - X Wi' Y`` (textbook: ``I - X Y``), factored by the SVD
    ``U s V'`` as ``M = U s^1/2``, ``N = V s^1/2`` (both then have the
    condition number ``sqrt(cond(M N'))``; ``M = I`` would put it all on
    ``N``): ``Dk = Dh``, ``Ck = (Ch - Dk C2s X) M'^-1``,
    ``Bk = N^-1 (Bh - Y B2t Dk)`` and
    ``Ak = N^-1 (Ah - N Bk C2s X - Y B2t Ck M' - Y (Ats + B2t Dk C2s) X) M'^-1``.
    """
    X, Y, Dk = V.X, V.Y, V.Dh
    U, s, Vt = np.linalg.svd(f.W - X @ f.Wi.T @ Y)
    r = np.sqrt(s)
    M, N = U * r, Vt.T * r
    Ck = np.linalg.solve(M, (V.Ch - Dk @ f.C2s @ X).T).T
    Bk = np.linalg.solve(N, V.Bh - Y @ f.B2t @ Dk)
    inner = V.Ah - N @ Bk @ f.C2s @ X - Y @ f.B2t @ Ck @ M.T - Y @ (f.Ats + f.B2t @ Dk @ f.C2s) @ X
    Ak = np.linalg.solve(N, np.linalg.solve(M, inner.T).T)
    return DynamicGain(Ak, Bk, Ck, Dk)
