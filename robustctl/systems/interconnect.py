r"""A plant and a dynamic controller in one loop: closed-loop matrices, the augmented form, loop transfers.

Plant and controller (the library's sign convention: no minus sign in the
feedback)

.. math::

    x^+ = F x + G u, \quad y = C x + D u, \qquad
    x_c^+ = A_c x_c + B_c y, \quad u = C_c x_c + D_c y + v ,

(``x'`` in continuous time), with ``v`` an input added at ``u``. A static
state feedback ``u = K x`` is the case ``C = I``, ``D = 0``, no controller
state, ``D_c = K``. With ``E = (I - D_c D)^{-1}`` (the loop is well posed
when it exists) the closed loop in the states ``(x, x_c)`` is

.. math::

    A_{cl} = \begin{bmatrix} F + G E D_c C & G E C_c \\
                             B_c (C + D E D_c C) & A_c + B_c D E C_c \end{bmatrix},
    \qquad
    B_{cl} = \begin{bmatrix} G E \\ B_c D E \end{bmatrix} .

It is ``F_a + G_a K_a`` for the *augmented* plant ``F_a = diag(F, 0)``,
``G_a = diag(G, I)`` under the static gain ``K_a = [[E D_c C, E C_c],
[B_c (C + D E D_c C), A_c + B_c D E C_c]]`` (:func:`augmented_gain`), so that
every analysis written for state feedback ``(plant, K)`` applies to a dynamic
controller [1]_: a norm-bounded uncertainty ``[dF dG] = H Delta [EF EG]`` of the
plant becomes ``H_a = [H; 0]``, ``EF_a = [EF 0]``, ``EG_a = [EG 0]`` (the
controller is known exactly), and the uncertain closed loop is
``A_cl + H_a Delta (EF_a + EG_a K_a)``.

Loop transfers (python-control's negative-feedback convention, ``u = -L u``
closes the loop): breaking the loop at the plant input, ``L_i = -K(z) P(z)``;
at the plant output, ``L_o = -P(z) K(z)``, with ``P: u -> y`` and
``K: y -> u``.

Every function takes stacks: the controller matrices with a leading batch
axis ``(B, ., .)``, the plant matrices shared; all outputs then have that axis.

References
----------
.. [1] K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*,
   Prentice Hall 1996, Sec. 5.1 (well-posedness) and 5.3 (internal stability
   of a feedback loop).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._kkt import solve

__all__ = ["ClosedLoop", "closed_loop", "augmented_gain", "loop_transfer", "WELL_POSED_TOL"]

#: The loop is ill posed when ``I - Dc D`` has a smallest singular value below this (relative to 1 + ||Dc D||).
WELL_POSED_TOL = 1e-10


class ClosedLoop(NamedTuple):
    """The closed loop of a stack of controllers: ``A`` (B, N, N), ``B`` (B, N, m) from ``v``, ``well_posed`` (B,)."""

    A: np.ndarray
    B: np.ndarray
    well_posed: np.ndarray


def _inverse_loop_gain(D: np.ndarray, Dc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``E = (I - Dc D)^-1`` for every controller (B, m, m) and whether it is well posed (B,)."""
    B, m = Dc.shape[0], Dc.shape[1]
    eye = np.eye(m)
    if not D.any():
        return np.broadcast_to(eye, (B, m, m)).copy(), np.ones(B, dtype=bool)
    M = eye - Dc @ D
    smallest = np.linalg.svd(M, compute_uv=False)[:, -1]
    ok = np.isfinite(smallest) & (smallest > WELL_POSED_TOL * (1.0 + np.linalg.norm(Dc @ D, 2, axis=(1, 2))))
    E = solve(np.where(ok[:, None, None], M, eye), np.broadcast_to(eye, (B, m, m)).copy())
    E[~ok] = np.nan
    return E, ok


def _augmented(C, D, Ac, Bc, Cc, Dc) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(K_a, E, well_posed)`` of a stack of controllers (module docstring)."""
    E, ok = _inverse_loop_gain(D, Dc)
    EDc = E @ Dc                                         # (B, m, p)
    top = np.concatenate([EDc @ C, E @ Cc], axis=-1)     # u = E (Dc C x + Cc xc)
    y_of = np.concatenate([C + D @ EDc @ C, D @ E @ Cc], axis=-1)   # y = C x + D u
    bottom = Bc @ y_of
    bottom[..., C.shape[-1]:] += Ac
    return np.concatenate([top, bottom], axis=-2), E, ok


def augmented_gain(C: np.ndarray, D: np.ndarray, Ac: np.ndarray, Bc: np.ndarray, Cc: np.ndarray,
                   Dc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The static gain ``K_a`` (B, m + nc, n + nc) on the augmented plant, and the well-posed flags (B,).

    ``F_a + G_a K_a`` is the closed loop (module docstring); ill-posed loops get NaN gains.
    """
    Ka, _, ok = _augmented(C, D, Ac, Bc, Cc, Dc)
    return Ka, ok


def closed_loop(F: np.ndarray, G: np.ndarray, C: np.ndarray, D: np.ndarray, Ac: np.ndarray, Bc: np.ndarray,
                Cc: np.ndarray, Dc: np.ndarray) -> ClosedLoop:
    """The closed loop of a plant and a stack of controllers (module docstring).

    Parameters
    ----------
    F, G, C, D : ndarray
        The plant, ``(n, n)``, ``(n, m)``, ``(p, n)``, ``(p, m)``.
    Ac, Bc, Cc, Dc : ndarray
        The controllers, ``(B, nc, nc)``, ``(B, nc, p)``, ``(B, m, nc)``, ``(B, m, p)`` (``nc`` may be 0).

    Returns
    -------
    ClosedLoop
        ``A`` (B, n + nc, n + nc), ``B`` (B, n + nc, m) from the input ``v``
        added at ``u``, and ``well_posed`` (B,): where False (``I - Dc D``
        singular) the matrices are NaN.

    Examples
    --------
    A static state feedback is the case ``C = I``, ``D = 0``, ``nc = 0``:

    >>> import numpy as np
    >>> F, G, K = np.array([[1.1]]), np.array([[1.0]]), np.array([[[-0.6]]])
    >>> cl = closed_loop(F, G, np.eye(1), np.zeros((1, 1)), np.zeros((1, 0, 0)), np.zeros((1, 0, 1)),
    ...                  np.zeros((1, 1, 0)), K)
    >>> bool(np.allclose(cl.A[0], F + G @ K[0])), bool(cl.well_posed[0])
    (True, True)
    """
    n, m = G.shape
    Ka, E, ok = _augmented(C, D, Ac, Bc, Cc, Dc)
    A = np.concatenate([G @ Ka[:, :m], Ka[:, m:]], axis=-2)     # F_a + G_a K_a, G_a = diag(G, I)
    A[:, :n, :n] += F
    return ClosedLoop(A, np.concatenate([G @ E, Bc @ D @ E], axis=-2), ok)


def loop_transfer(F: np.ndarray, G: np.ndarray, C: np.ndarray, D: np.ndarray, Ac: np.ndarray, Bc: np.ndarray,
                  Cc: np.ndarray, Dc: np.ndarray, at: str = "input") -> tuple[np.ndarray, ...]:
    """State-space matrices ``(A, B, C, D)`` of the loop transfer, in the negative-feedback convention.

    At the plant input ``L_i = -K(z) P(z)`` (``m x m``), at the output
    ``L_o = -P(z) K(z)`` (``p x p``); the states are ``(x, xc)``. Shapes as
    in :func:`closed_loop`; the results have the batch axis ``B``.

    Examples
    --------
    >>> import numpy as np
    >>> F, G, K = np.array([[0.5]]), np.array([[1.0]]), np.array([[[-0.2]]])
    >>> A, B, C, D = loop_transfer(F, G, np.eye(1), np.zeros((1, 1)), np.zeros((1, 0, 0)),
    ...                            np.zeros((1, 0, 1)), np.zeros((1, 1, 0)), K)
    >>> z = 1.0                                       # L(1) = -K (1 - 0.5)^-1 G = 0.4
    >>> float((C[0] @ np.linalg.solve(z * np.eye(1) - A[0], B[0]) + D[0])[0, 0])
    0.4
    """
    Bn, n, nc = Dc.shape[0], F.shape[0], Ac.shape[-1]
    A = np.zeros((Bn, n + nc, n + nc))
    A[:, :n, :n] = F
    A[:, n:, n:] = Ac
    if at == "input":        # u_in -> P -> y -> K -> u_out;  L = -K P
        A[:, n:, :n] = Bc @ C
        Bm = np.concatenate([np.broadcast_to(G, (Bn, *G.shape)), Bc @ D], axis=-2)
        Cm = -np.concatenate([Dc @ C, Cc], axis=-1)
        Dm = -(Dc @ D)
    elif at == "output":     # y_in -> K -> u -> P -> y_out;  L = -P K
        A[:, :n, n:] = G @ Cc
        Bm = np.concatenate([G @ Dc, Bc], axis=-2)
        Cm = -np.concatenate([np.broadcast_to(C, (Bn, *C.shape)), D @ Cc], axis=-1)
        Dm = -(D @ Dc)
    else:
        raise ValueError(f"at must be 'input' or 'output', got {at!r}")
    return A, Bm, Cm, Dm
