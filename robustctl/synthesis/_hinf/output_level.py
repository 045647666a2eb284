"""The SDP solves of output-feedback synthesis: an optimum, and a well-centred point at a fixed level.

A :class:`Spec` says which channel carries an H-infinity bound, which one an
H2 bound, and the pole regions. :func:`minimise` finds the optimum (the
H-infinity level when there is no H2 channel, else the H2 bound with the
H-infinity level fixed at 1 in the frame, its ``z`` scaled beforehand);
:func:`centre` maximises the common margin ``t <= 1`` of every block with
both levels fixed at 1 (a strictly feasible, well-centred point, from which
a moderate controller is reconstructed). Every solve goes through
:func:`robustctl._cvx.solve_sdp` (status, certificate of the blocks).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ... import _cvx
from .output_coordinates import Frame
from .output_lmis import OFPoint, h2_blocks, h2_equality, hinf_block, lyapunov, region_blocks, variables

__all__ = ["Spec", "Solved", "minimise", "centre", "LEVEL_TOL", "CENTRE_TOL"]

#: Solver tolerance of the optimum (the level agrees with the Riccati bisection to ~1e-7 in the frame's coordinates).
LEVEL_TOL = 1e-8
#: Solver tolerance of the centring problems (only their certificate matters).
CENTRE_TOL = 1e-7


@dataclass(frozen=True)
class Spec:
    """Channel of the H-infinity bound, channel of the H2 bound (``None``: absent) and the pole regions.

    ``shared_w``: both channels have the same disturbance input (``B1``,
    ``D21``); the H2 Gramian block is then a principal submatrix (discrete)
    or the Schur complement of the ``w`` block (continuous) of the
    H-infinity block and is left out: a redundant block becomes singular
    with the other at the optimum, which the solver measured as failures
    and false optima on Scherer, Gahinet & Chilali's Example 7.
    """

    hinf: int | None
    h2: int | None
    regions: tuple = ()
    what: str = "an output-feedback controller"
    shared_w: bool = False


class Solved(NamedTuple):
    """A solve: the point (arrays), the optimal value (level squared, trace Z or margin t) and the report."""

    point: OFPoint
    value: float
    report: _cvx.SolveReport


def _blocks(f: Frame, V: OFPoint, spec: Spec, level_sq, Z, margin) -> tuple[list, list]:
    lmis, cons = [], []
    if spec.hinf is not None:
        lmis.append(hinf_block(f, V, level_sq, spec.hinf, margin))
    if spec.h2 is not None:
        h2 = h2_blocks(f, V, Z, spec.h2, margin)
        lmis += h2[1:] if spec.shared_w and spec.hinf is not None else h2
        cons += h2_equality(f, V, spec.h2)
    if not f.discrete:
        lmis.append(_cvx.LMI("lyapunov", lyapunov(f, V), margin))
    lmis += region_blocks(spec.regions, f, V, margin)
    return lmis, cons


def minimise(f: Frame, spec: Spec, solver: str) -> Solved:
    """The optimum: ``min level_sq`` (H-infinity only) or ``min trace Z`` (an H2 channel; H-infinity level 1)."""
    import cvxpy as cp

    g = f.plant
    V = variables(g.n, g.m, g.p)
    if spec.h2 is None:
        level_sq = cp.Variable(name="level_sq")
        lmis, cons = _blocks(f, V, spec, level_sq, None, 0.0)
        objective, value = cp.Minimize(level_sq), level_sq
    else:
        nz = g.channels[spec.h2].nz
        Z = cp.Variable((nz, nz), symmetric=True, name="Z")
        lmis, cons = _blocks(f, V, spec, 1.0, Z, 0.0)
        objective, value = cp.Minimize(cp.trace(Z)), cp.trace(Z)
    rep = _cvx.solve_sdp(objective, lmis, cons, solver=solver, tol=LEVEL_TOL, fast=True, decompose=False,
                         infeasible_msg=f"no {spec.what}: the LMIs are infeasible")
    return Solved(V.values(), float(np.asarray(value.value)), rep)


def centre(f: Frame, spec: Spec, solver: str, infeasible_msg: str) -> Solved:
    """Maximise the common margin ``t <= 1`` of every block, both levels 1 (``trace Z <= 1``); value ``t``."""
    import cvxpy as cp

    g = f.plant
    V = variables(g.n, g.m, g.p)
    t = cp.Variable(name="t")
    cons: list = [t <= 1.0]
    Z = None
    if spec.h2 is not None:
        nz = g.channels[spec.h2].nz
        Z = cp.Variable((nz, nz), symmetric=True, name="Z")
        cons.append(cp.trace(Z) <= 1.0)
    lmis, extra = _blocks(f, V, spec, 1.0, Z, t)
    rep = _cvx.solve_sdp(cp.Maximize(t), lmis, cons + extra, solver=solver, tol=CENTRE_TOL, decompose=False,
                         infeasible_msg=infeasible_msg)
    return Solved(V.values(), float(np.asarray(_cvx.value(t))), rep)
