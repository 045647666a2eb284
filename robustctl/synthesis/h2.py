r"""H2 synthesis by LMI optimisation (cvxpy + Clarabel): state feedback and full-order output feedback.

Output feedback (a plant with measured outputs) uses the LMIs of Scherer,
Gahinet & Chilali (1997) in the variables, coordinates and reconstruction
described in ``robustctl.synthesis.hinf`` (Output feedback); the rest of
this docstring is the state feedback.

Plant and gain as in :func:`robustctl.hinf` (``u = K x``)::

    x+ = F x + Bw w + G u         (discrete; x' = ... for dt = None)
    z  = Cz x + Dzw w + Dzu u

With ``A_K = F + G K``, ``C_K = Cz + Dzu K`` the squared H2 norm of
``T_zw`` is ``trace(C_K W_c C_K') + trace(Dzw' Dzw)`` (discrete; the
impulse response is ``Dzw, C_K Bw, C_K A_K Bw, ...``) or
``trace(C_K W_c C_K')`` (continuous, where ``Dzw`` must be zero), ``W_c``
the controllability Gramian. Any ``X >= W_c`` bounds it, and with
``Y = K X`` both conditions are linear (e.g. Boyd, El Ghaoui, Feron &
Balakrishnan 1994, Sec. 7.2; de Oliveira, Geromel & Bernussou 2002)::

    discrete:    [ X - Bw Bw'   A X + G Y ]            [ W          Cz X + Dzu Y ]
                 [ *            X         ] >= 0,      [ *          X            ] >= 0
    continuous:  -(A X + G Y) - (.)' - Bw Bw' >= 0,    (the same W block), X >= 0

minimising ``trace(W)`` (plus ``trace(Dzw' Dzw)``). With ``vertices`` the
blocks are imposed at every vertex with one ``(X, Y)``: the bound holds for
every plant of the convex hull (guaranteed H2 cost). With ``poles`` the
closed-loop poles of every vertex lie in the LMI regions of
:mod:`robustctl.systems.regions`, with the same ``X``.

For one plant the optimum is the LQR with ``Q = Cz'Cz``, ``R = Dzu'Dzu``,
``N = Cz'Dzu`` (an optimal control minimises the cost from every initial
state at once, here ``x0 = Bw e_i``), value ``trace(Bw' P Bw)`` with ``P``
the stabilising Riccati solution: the tests check the LMI optimum against
scipy's DARE / CARE.

Numerics: the data go through the coordinates of :func:`robustctl.hinf`
(``w`` and ``z`` scaled to unit size, since ``||T_zw||_2`` is homogeneous
in both and the gain does not depend on them; balancing, ``||Bw|| = 1``,
``z`` compressed to a factor with the same Gram matrix, which is all the H2
norm depends on). The minimisation uses
non-strict LMIs (the infimum); unless ``backoff=0`` the gain comes from a
second problem at ``h2_bound = (1 + backoff) h2_opt`` that maximises the
smallest eigenvalue of every block (a strictly feasible, well-centred point),
so that its poles lie strictly inside the regions. The H2 norm of the
returned closed loop at every vertex is computed from its Gramian and
reported (``info["h2_norms"]``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike

from .. import _cvx
from ..errors import ConvergenceError, InfeasibleError
from ..systems.controller import Controller
from ..systems.plant import Plant
from ..systems.regions import Region, describe_regions
from ._hinf import tolerances as tol
from ._hinf.coordinates import Coordinates, channel_scales, normalised, recentred
from ._hinf.lmis import Point, region_blocks, variables
from ._hinf.output_problem import channel, dynamic_controller, output_problem, refuse, wants_output
from ._hinf.output_synthesis import synthesise
from ._hinf.problem import validate
from .hinf import check_closed_loop

__all__ = ["h2", "H2Controller"]


@dataclass(frozen=True, eq=False, repr=False)
class H2Controller(Controller):
    """An H2 controller, state feedback ``u = K x`` or output feedback ``u = K(z) y``, with its guaranteed cost.

    What :func:`robustctl.h2` returns; the constructor is that of
    :class:`~robustctl.Controller` with the two bounds.

    Parameters
    ----------
    K : (m, n) array_like or None
        State-feedback gain ``u = K x``; None for an output feedback.
    method : str
        Name of the design method.
    plant : Plant
        The plant it was designed for.
    info : Mapping, optional
        Diagnostics of the design (see the design function), stored read-only.
    Ac, Bc, Cc, Dc : array_like, optional
        Output feedback ``xc+ = Ac xc + Bc y``, ``u = Cc xc + Dc y`` (as in
        :class:`~robustctl.Controller`).
    h2_bound : float
        ``||T_zw||_2 <= h2_bound`` for the plant (and every plant of the hull
        of ``vertices``): ``(1 + backoff) h2_opt``.
    h2_opt : float
        The optimal value of the LMI problem (for one plant without pole
        regions: the H2-optimal cost, the LQR's for state feedback and the
        LQG controller's for output feedback).

    See Also
    --------
    robustctl.h2

    Examples
    --------
    The H2-optimal state feedback of a scalar plant is the LQR, whose cost
    ``sqrt(P)`` comes from the scalar Riccati equation
    ``P = 1 + 1.44 P - 1.44 P^2 / (1 + P)``, i.e. ``P^2 - 1.44 P - 1 = 0``,
    of ``x+ = 1.2 x + u + w`` with unit weights:

    >>> import numpy as np, robustctl as rc
    >>> plant = rc.Plant([[1.2]], [[1.0]], 0.1)
    >>> ctrl = rc.h2(plant, Bw=[[1.0]], Cz=[[1.0], [0.0]], Dzu=[[0.0], [1.0]])
    >>> P = 0.72 + np.sqrt(0.72**2 + 1)     # the positive root
    >>> isinstance(ctrl, rc.H2Controller), bool(abs(ctrl.h2_opt / np.sqrt(P) - 1) < 1e-5)
    (True, True)
    """

    h2_bound: float = float("nan")
    h2_opt: float = float("nan")

    def __repr__(self) -> str:
        base = super().__repr__()
        return base.replace("Controller(", f"H2Controller(h2_bound={self.h2_bound:.6g}, "
                                           f"h2_opt={self.h2_opt:.6g}, ", 1)


def h2(plant: Plant, *, Bw: ArrayLike, Cz: ArrayLike, Dzu: ArrayLike, Dzw: ArrayLike | None = None,
       Dyw: ArrayLike | None = None, vertices: Sequence[Plant] | None = None,
       poles: Region | Sequence[Region] | None = None, backoff: float = 1e-3, solver: str = "CLARABEL",
       feedback: str | None = None) -> H2Controller:
    r"""H2 synthesis by LMI optimisation, state feedback ``u = K x`` or output feedback ``u = K(z) y``.

    Minimises ``||T_zw||_2``. When the plant declares measured outputs
    (``Plant(..., C=..., D=...)``), ``y = C x + D u + Dyw w`` and the result
    is a full-order dynamic controller (``ctrl.Ac``, ``Bc``, ``Cc``, ``Dc``;
    ``ctrl.K`` is None) from the LMIs of Scherer, Gahinet & Chilali (1997)
    (see ``robustctl.synthesis.hinf`` for the variables and the
    reconstruction); otherwise, or with ``feedback="state"``, the state
    feedback below.

    Parameters
    ----------
    plant : Plant
        The nominal plant ``(F, G)``; continuous time for ``dt=None``.
    Bw : (n, q) array_like
        Disturbance input matrix (unit-intensity white noise, or impulses).
    Cz : (p, n) array_like
        Performance output matrix.
    Dzu : (p, m) array_like
        Feedthrough from ``u`` to ``z`` (``Dzu'Dzu > 0`` for an attained optimum).
    Dzw : (p, q) array_like, optional
        Feedthrough from ``w`` to ``z`` (default zero; must be zero in
        continuous time, where it makes the H2 norm infinite).
    Dyw : (plant.p, q) array_like, optional
        Output feedback: feedthrough from ``w`` to the measured outputs
        (measurement noise; default zero).
    vertices : list of Plant, optional
        Further plants: the bound holds for every plant of the convex hull.
        State feedback only.
    poles : Region or list of Region, optional
        Pole regions (:mod:`robustctl.systems.regions`) for the closed loop of every vertex.
    backoff : float, default 1e-3
        The gain is computed at ``(1 + backoff) h2_opt`` from a well-centred
        strictly feasible point; ``0`` returns the optimal point's gain
        (state feedback only).
    solver : str, default "CLARABEL"
        cvxpy SDP solver.
    feedback : {None, "state", "output"}, optional
        ``None``: output feedback when the plant declares outputs, state
        feedback otherwise; ``"state"`` asks for ``u = K x`` on a plant with
        outputs.

    Returns
    -------
    H2Controller
        Output feedback: ``Ac``, ``Bc``, ``Cc``, ``Dc`` (``K`` None),
        ``h2_bound``, ``h2_opt`` and ``info`` with ``feedback``,
        ``h2_norm_ratio`` inside ``certificate`` (the closed loop's H2 norm,
        from its Gramian, over ``h2_bound``), ``gain_from``, ``margin``,
        ``solves``, ``poles``, ``status``, ``solve_time``, ``iterations``,
        ``backoff``. State feedback:
        ``K``, ``h2_bound``, ``h2_opt`` and ``info`` with ``h2_norms`` (the
        H2 norm of the closed loop at every vertex, from its Gramian),
        ``certificate``, ``margin``, ``solves``, ``X`` (the Lyapunov matrix,
        ``X >= `` the closed-loop controllability Gramian at every vertex),
        ``poles``, ``status``, ``solve_time``, ``iterations``, ``backoff``.

    Raises
    ------
    InfeasibleError
        A vertex is not stabilisable (:class:`~robustctl.errors.NotStabilizableError`,
        an ``InfeasibleError``), the pole regions cannot be reached
        (with the reason), or no common Lyapunov matrix exists.
    ValueError, TypeError
        Bad arguments (named in the message).

    Examples
    --------
    For one plant with ``z = [Q^1/2 x; R^1/2 u]`` and ``w`` entering through
    ``Bw``, the H2-optimal state feedback is the LQR (python-control's
    ``dlqr`` returns ``-K``), and its ``||T_zw||_2`` is python-control's
    ``h2norm`` of the closed loop:

    >>> import numpy as np, control, robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> Cz, Dzu = rc.lq_output(np.eye(2), np.eye(1))
    >>> ctrl = rc.h2(plant, Bw=np.eye(2), Cz=Cz, Dzu=Dzu)
    >>> K_lqr = -control.dlqr(plant.F, plant.G, np.eye(2), np.eye(1))[0]
    >>> bool(np.allclose(ctrl.K, K_lqr, rtol=1e-3, atol=1e-3))
    True
    >>> loop = control.ss(plant.F + plant.G @ ctrl.K, np.eye(2), Cz + Dzu @ ctrl.K, 0, 0.1)
    >>> bool(np.isclose(control.norm(loop, 2), ctrl.h2_opt, rtol=1e-3))
    True

    Output feedback: the H2 optimum of Example 7 of Scherer, Gahinet &
    Chilali (1997), 7.7484 (the value python-control's example quotes),
    and the H2 norm of python-control's closed loop is below the bound:

    >>> A = [[0.0, 10.0, 2.0], [-1.0, 1.0, 0.0], [0.0, 2.0, -5.0]]
    >>> plant = rc.Plant(A, [[0.0], [1.0], [0.0]], None, C=[[0.0, 1.0, 0.0]])
    >>> Bw, Cz, Dzu = [[1.0], [0.0], [1.0]], [[0.0, 1, 0], [0, 0, 1], [0, 0, 0]], [[0.0], [0.0], [1.0]]
    >>> ctrl = rc.h2(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dyw=[[2.0]])
    >>> round(ctrl.h2_opt, 4)
    7.7484
    >>> P = control.ss(A, np.hstack([Bw, plant.G]), np.vstack([Cz, plant.C]), [[0, 0], [0, 0], [0, 1], [2, 0]])
    >>> bool(control.norm(P.lft(ctrl.controller_statespace()), 2) <= ctrl.h2_bound)
    True
    """
    if wants_output(plant, feedback, Dyw):
        refuse(vertices=vertices)
        pb = output_problem(plant, "h2", (channel(plant, Bw, Cz, Dzu, Dzw, Dyw),), gamma=None, backoff=backoff,
                            poles=poles, solver=solver)
        res = synthesise(pb)
        return dynamic_controller(H2Controller, "h2", plant, res, pb, h2_bound=res.h2_bound, h2_opt=res.h2_opt)
    # the validation stage of the H-infinity synthesis, without its H-infinity-only options
    problem = validate(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw, vertices=vertices, gamma=None, u_max=None,
                       w_energy=None, backoff=backoff, extended=False, solver=solver, poles=poles)
    plants, regions, solver, backoff = problem.plants, problem.regions, problem.solver, problem.backoff
    Bw, Cz, Dzu, Dzw = problem.Bw, problem.Cz, problem.Dzu, problem.Dzw
    if not plant.is_discrete and np.any(Dzw):
        raise ValueError("Dzw must be zero for a continuous-time plant: a feedthrough from white noise w to z "
                         "makes the H2 norm infinite")

    w_scale, z_unit = channel_scales(Bw, Cz, Dzu, Dzw)
    data = normalised([p.F for p in plants], [p.G for p in plants], Bw, Cz, Dzu, Dzw, w_scale, z_unit=z_unit)
    what = _infeasibility(plants, regions)
    const = float(np.sum(data.Dzw**2))          # trace(Dzw' Dzw), invariant under the compression
    point, cost, rep = _minimise(data, plant.is_discrete, regions, solver, what)
    scaled_opt = float(np.sqrt(max(cost, 0.0) + const))     # ||T_zw||_2 of the scaled channels
    solves = [rep.as_dict()]
    if backoff == 0:
        cert, margin = dict(rep.certificate), 0.0
    else:
        home = recentred(data, point.X, tol.RECENTRE_REG)
        data = data if home is None else home[0]
        point, margin, rep, backoff, centring = _centre(data, plant.is_discrete, regions, solver, scaled_opt,
                                                        const, backoff)
        cert = dict(rep.certificate)
        solves += centring
    K, X = data.to_original(point.gain(), point.X)
    X = X / w_scale**2                           # the Gramian bound of the caller's w
    check_closed_loop(K, plants, regions)
    h2_opt = scaled_opt / data.level_scale
    h2_bound = (1.0 + backoff) * h2_opt
    norms = np.array([_h2_norm(p, K, Bw, Cz, Dzu, Dzw) for p in plants])
    if np.any(norms > h2_bound * (1.0 + tol.U_BOUND_CHECK)):
        raise ConvergenceError(f"internal check failed: the closed-loop H2 norms {norms.tolist()} exceed the "
                               f"guaranteed {h2_bound:.6g} (solver inaccuracy); increase backoff")
    info = {
        "h2_bound": h2_bound, "h2_opt": h2_opt, "h2_norms": norms, "backoff": backoff, "margin": margin,
        "certificate": cert, "solves": solves, "X": 0.5 * (X + X.T), "poles": regions, "vertices": len(plants),
        "status": solves[-1]["status"], **_cvx.totals(solves), "solver": solver,
    }
    return H2Controller(K=K, method="h2", plant=plant, info=info, h2_bound=h2_bound, h2_opt=h2_opt)


def _infeasibility(plants, regions) -> str:
    what = ("no stabilising gain satisfies the H2 LMI" if len(plants) == 1 else
            f"no common Lyapunov matrix and gain satisfy the H2 LMI at all {len(plants)} vertices")
    if regions:
        what += f" with every closed-loop pole in {describe_regions(regions)} (the same Lyapunov matrix)"
    return what


def h2_blocks(data: Coordinates, V: Point, W, discrete: bool, margin=0.0, z_scale: float = 1.0) -> list[_cvx.LMI]:
    """The Gramian block of every vertex (``gramian[i]``), the cost block ``cost`` and, continuous, ``X``.

    ``z_scale`` multiplies ``z`` (the cost ``trace(W)`` by its square).
    """
    import cvxpy as cp

    X, Y = V.X, V.Y
    BB = data.Bw @ data.Bw.T
    out = []
    for i, (F, G) in enumerate(zip(data.F, data.G, strict=True)):
        AX = F @ X + G @ Y
        M = cp.bmat([[X - BB, AX], [AX.T, X]]) if discrete else -(AX + AX.T) - BB
        out.append(_cvx.LMI(f"gramian[{i}]", M, margin))
    CX = z_scale * (data.Cz @ X + data.Dzu @ Y)
    out.append(_cvx.LMI("cost", cp.bmat([[W, CX], [CX.T, X]]), margin))
    if not discrete:
        out.append(_cvx.LMI("X", X, margin))
    return out


def _minimise(data: Coordinates, discrete: bool, regions, solver: str, what: str):
    """Minimise ``trace(W)``: ``(point, trace W, report)``."""
    import cvxpy as cp

    V = variables(data.n, data.m, len(data.F), False)
    W = cp.Variable((data.p, data.p), symmetric=True, name="W")
    lmis = h2_blocks(data, V, W, discrete) + region_blocks(regions, data, V)
    rep = _cvx.solve_sdp(cp.Minimize(cp.trace(W)), lmis, solver=solver, tol=tol.LEVEL_TOL,
                         infeasible_msg=f"no H2 state feedback: {what}")
    return V.values(), float(np.trace(_cvx.value(W))), rep


def _centre(data: Coordinates, discrete: bool, regions, solver: str, h2_opt: float, const: float,
            backoff: float):
    """A well-centred strictly feasible point at ``(1 + backoff) h2_opt``, the backoff raised if needed.

    ``h2_opt`` and ``const`` in ``data``'s units. Maximises the common
    margin ``t <= 1`` of every block with ``z`` scaled so that the bound on
    ``trace(W)`` is 1 (``data``: coordinates where the optimal ``X`` is ~ I,
    so one margin suits every block). Returns ``(point, t, report, backoff
    used, solves)``.
    """
    import cvxpy as cp

    failure: Exception | None = None
    solves = []
    for factor in tol.BACKOFF_STEPS:
        used = backoff * factor
        z_scale = 1.0 / float(np.sqrt(((1.0 + used) * h2_opt) ** 2 - const))
        V = variables(data.n, data.m, len(data.F), False)
        W = cp.Variable((data.p, data.p), symmetric=True, name="W")
        t = cp.Variable(name="t")
        lmis = h2_blocks(data, V, W, discrete, margin=t, z_scale=z_scale) + region_blocks(regions, data, V, margin=t)
        msg = f"could not find a strictly feasible gain at (1 + {used:g}) h2_opt; increase backoff"
        try:
            rep = _cvx.solve_sdp(cp.Maximize(t), lmis, [t <= 1.0, cp.trace(W) <= 1.0], solver=solver,
                                 tol=tol.CENTRE_TOL, infeasible_msg=msg)
        except (ConvergenceError, InfeasibleError) as exc:
            failure = exc
            continue
        solves.append({**rep.as_dict(), "centring": "margin"})
        if all(v > 0 for v in rep.certificate.values()):
            return V.values(), float(_cvx.value(t)), rep, used, solves
        failure = ConvergenceError(f"{msg} (smallest eigenvalues {dict(rep.certificate)})")
    raise failure or ConvergenceError("no centring attempt")


def _h2_norm(plant: Plant, K, Bw, Cz, Dzu, Dzw) -> float:
    """``||T_zw||_2`` of the closed loop from its controllability Gramian (scipy's Lyapunov solvers)."""
    A, C = plant.F + plant.G @ K, Cz + Dzu @ K
    if plant.is_discrete:
        Wc = scipy.linalg.solve_discrete_lyapunov(A, Bw @ Bw.T)
        return float(np.sqrt(np.trace(C @ Wc @ C.T) + np.sum(Dzw**2)))
    Wc = scipy.linalg.solve_continuous_lyapunov(A, -Bw @ Bw.T)
    return float(np.sqrt(np.trace(C @ Wc @ C.T)))
