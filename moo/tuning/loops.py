r"""The closed loops of a population on the scenarios: what every goal reads, for state and output feedback.

A population reaches the goals as *controllers*: a (B, m, n) array of state
feedbacks ``u = K x`` (state-feedback families), or an
:class:`robustctl.ControllerBatch` of dynamic output feedbacks ``u = K(z) y``
(output-feedback families). :func:`closed_loops` turns either into the loops
on ``S`` scenario plants, in the states ``(x, x_c)``
(:mod:`robustctl.systems.interconnect`):

.. math::

    \begin{bmatrix} x \\ x_c \end{bmatrix}^+ = A_{cl} \begin{bmatrix} x \\ x_c \end{bmatrix} + B_v v,
    \qquad u = K_u \begin{bmatrix} x \\ x_c \end{bmatrix} + E v ,

with ``v`` an input added at ``u``; for a state feedback ``A_cl = F + G K``,
``B_v = G`` and ``K_u = K``. A scenario without an output model reads the
batch plant's ``C`` and ``D`` (the problem attaches them). The last result is
kept: the goals of one population, which get the same controllers object and
the same plant tuple, build the loops once.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

import robustctl as rc
from robustctl.systems.interconnect import augmented_gain, closed_loop
from robustctl.systems.stability import spectral_abscissa

from ..validation import as_float_array

if TYPE_CHECKING:
    from typing_extensions import TypeIs

__all__ = ["Loops", "closed_loops", "stability", "check_controllers", "take", "count", "is_output_feedback",
           "plant_outputs", "with_outputs"]

Controllers = np.ndarray | rc.ControllerBatch


@dataclass(frozen=True, eq=False)
class Loops:
    """Closed loops of ``B`` designs on ``S`` scenarios (module docstring).

    Attributes
    ----------
    A : (B, S, N, N) ndarray
        Closed-loop state matrices (``N = n + nc``; NaN for an ill-posed loop).
    Bv : (B, S, N, m) ndarray
        Input matrices of ``v`` added at ``u``.
    Ku : (B, S, m, N) ndarray
        ``u`` as a function of the loop state.
    E : (B, S, m, m) ndarray
        ``(I - D_c D)^{-1}``: ``u`` as a function of ``v`` (``I`` for a state feedback).
    well_posed : (B, S) bool ndarray
    n, order : int
        Plant states and controller states ``nc``.
    discrete : bool
    """

    A: np.ndarray
    Bv: np.ndarray
    Ku: np.ndarray
    E: np.ndarray
    well_posed: np.ndarray
    n: int
    order: int
    discrete: bool


def is_output_feedback(controllers) -> TypeIs[rc.ControllerBatch]:
    """Whether ``controllers`` is a batch of output feedbacks (an :class:`robustctl.ControllerBatch`)."""
    return isinstance(controllers, rc.ControllerBatch)


def count(controllers: Controllers) -> int:
    """Number of designs B."""
    return len(controllers) if is_output_feedback(controllers) else int(np.shape(controllers)[0])


def take(controllers: Controllers, idx) -> Controllers:
    """The designs ``idx`` (an index array or a boolean mask) of a population, read-only."""
    if is_output_feedback(controllers):
        c = controllers
        return rc.ControllerBatch(c.plant, c.Ac[idx], c.Bc[idx], c.Cc[idx], c.Dc[idx])
    out = np.array(np.asarray(controllers)[idx], dtype=float)
    out.flags.writeable = False
    return out


def with_outputs(plant: rc.Plant, source: rc.Plant) -> rc.Plant:
    """``plant`` itself if it has an output model, else ``plant`` with ``source``'s ``C`` and ``D``."""
    if plant.has_outputs:
        return plant
    C, D = source.output_matrices()
    return replace(plant, C=C, D=D)


def plant_outputs(plant: rc.Plant, controllers: Controllers) -> tuple[np.ndarray, np.ndarray]:
    """``(C, D)`` the controllers read on ``plant``: ``(I, 0)`` for a state feedback, else the plant's (or batch's)."""
    if not is_output_feedback(controllers):
        return np.eye(plant.n), np.zeros((plant.n, plant.m))
    return (plant if plant.has_outputs else controllers.plant).output_matrices()


def check_controllers(controllers, plants: Sequence[rc.Plant], name: str = "K") -> Controllers:
    """A (B, m, n) array of finite gains or a :class:`robustctl.ControllerBatch` that fits ``plants``.

    ``ValueError``/``TypeError`` naming ``name`` otherwise (the goals' entry check).
    """
    n, m = plants[0].n, plants[0].m
    if is_output_feedback(controllers):
        plant = controllers.plant
        if (plant.n, plant.m) != (n, m):
            raise ValueError(f"{name}: the batch's plant has n={plant.n}, m={plant.m}; the plants have n={n}, m={m}")
        for i, p in enumerate(plants):
            if p.has_outputs and p.p != plant.p:
                raise ValueError(f"{name}: the controllers read p={plant.p} outputs, plants[{i}] has p={p.p}")
        return controllers
    if isinstance(controllers, np.ndarray) and controllers.dtype == np.float64 and controllers.ndim == 3:
        K = controllers                                  # no copy: a read-only stack keeps its identity
    else:
        K = as_float_array(controllers, name)
        K = K[None] if K.ndim == 2 else K
    if K.ndim != 3 or K.shape[0] == 0 or K.shape[1:] != (m, n):
        raise ValueError(f"{name} must be a non-empty stack (B, {m}, {n}) of gains (designs, inputs, states) or a "
                         f"robustctl.ControllerBatch, got shape {np.shape(controllers)}")
    if not np.all(np.isfinite(K)):
        raise ValueError(f"{name} must have finite entries (found NaN or inf)")
    return K


_LAST: list = [None, None, None]          # (controllers, plants, Loops) of the last call


def closed_loops(controllers: Controllers, plants: Sequence[rc.Plant]) -> Loops:
    """The :class:`Loops` of ``controllers`` (checked as in :func:`check_controllers`) on ``plants``."""
    last_c, last_p, last = _LAST
    if controllers is last_c and last_p is not None and len(last_p) == len(plants) \
            and all(a is b for a, b in zip(last_p, plants, strict=True)):
        return last
    given = controllers
    controllers = check_controllers(controllers, plants)
    F = np.stack([p.F for p in plants])
    G = np.stack([p.G for p in plants])
    S, n, m = F.shape[0], F.shape[1], G.shape[2]
    if not is_output_feedback(controllers):
        K = np.asarray(controllers)
        A = F[None] + G[None] @ K[:, None]
        B = K.shape[0]
        loops = Loops(A=A, Bv=np.broadcast_to(G[None], (B, S, n, m)), Ku=np.broadcast_to(K[:, None], (B, S, m, n)),
                      E=np.broadcast_to(np.eye(m), (B, S, m, m)), well_posed=np.ones((B, S), dtype=bool), n=n,
                      order=0, discrete=plants[0].is_discrete)
    else:
        c = controllers
        parts = []
        for p in plants:
            C, D = plant_outputs(p, c)
            cl = closed_loop(p.F, p.G, C, D, c.Ac, c.Bc, c.Cc, c.Dc)
            Ka, _ = augmented_gain(C, D, c.Ac, c.Bc, c.Cc, c.Dc)
            M = np.where(cl.well_posed[:, None, None], np.eye(m) - c.Dc @ D, np.eye(m))
            E = np.linalg.solve(M, np.broadcast_to(np.eye(m), M.shape))
            E[~cl.well_posed] = np.nan
            parts.append((cl.A, cl.B, Ka[:, :m], E, cl.well_posed))
        A, Bv, Ku, E, ok = (np.stack(x, axis=1) for x in zip(*parts, strict=True))
        loops = Loops(A=A, Bv=Bv, Ku=Ku, E=E, well_posed=ok, n=n, order=c.order, discrete=plants[0].is_discrete)
    # kept for the next goal: only immutable controllers (a batch, a read-only array) can be recognised safely
    frozen = is_output_feedback(given) or (isinstance(given, np.ndarray) and not given.flags.writeable)
    _LAST[:] = [given, tuple(plants), loops] if frozen else [None, None, None]
    return loops


def stability(loops: Loops) -> tuple[np.ndarray, np.ndarray]:
    """``(stable (B, S), rho (B,))``: stable loops, and the worst "radius" of the designs unstable somewhere.

    ``rho`` is the spectral radius (discrete) or ``exp(max Re lambda)`` (continuous: the radius of the
    loop sampled at 1 s) over the scenarios, NaN for the designs stable everywhere, inf for ill-posed loops.
    """
    A = loops.A
    finite = np.isfinite(A).all(axis=(-2, -1)) & loops.well_posed
    Af = np.where(finite[..., None, None], A, 0.0)
    if loops.discrete:
        stable = np.asarray(rc.is_schur_stable(Af)) & finite
    else:
        stable = (np.asarray(spectral_abscissa(Af)) < -rc.STABILITY_MARGIN) & finite
    rho = np.full(A.shape[0], np.nan)
    bad = ~stable.all(axis=1)
    if bad.any():
        Ab = Af[bad]
        r = np.asarray(rc.spectral_radius(Ab)) if loops.discrete else np.exp(np.asarray(spectral_abscissa(Ab)))
        rho[bad] = np.where(finite[bad], r, np.inf).max(axis=1)
    return stable, rho
