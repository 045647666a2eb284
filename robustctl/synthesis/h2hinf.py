r"""Mixed H2/H-infinity synthesis: the smallest H2 bound of one channel with an H-infinity bound on another.

Two channels of one plant (``y`` only for output feedback)::

    x+  = F x + Bw w + Bw2 w2 + G u
    z   = Cz x + Dzw w + Dzu u          ||T_zw||_inf < gamma      (the constraint)
    z2  = Cz2 x + Dzw2 w2 + Dzu2 u      ||T_z2w2||_2 minimised    (the objective)
    y   = C x + D u + Dyw w + Dyw2 w2

By default ``w2`` is ``w`` (``Bw2 = Bw``, ``Dyw2 = Dyw``), the common form of
MATLAB's ``h2hinfsyn``. Both conditions are imposed with *one* Lyapunov
matrix (Khargonekar & Rotea 1991 for state feedback; Scherer, Gahinet &
Chilali 1997 for output feedback, in the variables of
``robustctl.synthesis.hinf``), which makes the problem an LMI: the H2
bound is then an upper bound of the best H2 norm under the H-infinity
constraint, and the returned controller's H2 norm is at most the bound
(its own closed loop, certified).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .. import _cvx
from .._validation import check_positive_scalar, check_real
from ..errors import ConvergenceError, InfeasibleError
from ..systems.controller import Controller
from ..systems.plant import Plant
from ..systems.regions import Region
from ._hinf.generalised import Channel
from ._hinf.mixed_state import mixed_state
from ._hinf.output_problem import channel, dynamic_controller, output_problem, wants_output
from ._hinf.output_synthesis import synthesise
from ._hinf.problem import validate
from .hinf import hinf

__all__ = ["h2hinf", "H2HinfController"]


@dataclass(frozen=True, eq=False, repr=False)
class H2HinfController(Controller):
    """A mixed H2/H-infinity controller, state feedback ``u = K x`` or output feedback ``u = K(z) y``.

    What :func:`robustctl.h2hinf` returns; the constructor is that of
    :class:`~robustctl.Controller` with the bound and the two H2 values.

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
    gamma : float
        The H-infinity bound met: ``||T_zw||_inf < gamma``.
    h2_bound : float
        ``||T_z2w2||_2 <= h2_bound = (1 + backoff) h2_opt``.
    h2_opt : float
        The optimal value of the mixed LMI problem: an *upper bound* of the
        smallest H2 norm of any controller meeting the H-infinity bound (one
        Lyapunov matrix for both).

    See Also
    --------
    robustctl.h2hinf

    Examples
    --------
    The H-infinity optimum of a scalar plant with ``z = (x, u)``, then the
    mixed design at twice it: the H2 bound lies above the unconstrained H2
    optimum (the LQR cost):

    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.2]], [[1.0]], 0.1)
    >>> ch = dict(Bw=[[1.0]], Cz=[[1.0], [0.0]], Dzu=[[0.0], [1.0]])
    >>> g = rc.hinf(plant, **ch).gamma_opt
    >>> ctrl = rc.h2hinf(plant, gamma=2 * g, **ch, Cz2=ch["Cz"], Dzu2=ch["Dzu"])
    >>> isinstance(ctrl, rc.H2HinfController), bool(ctrl.h2_opt >= rc.h2(plant, **ch).h2_opt * (1 - 1e-6))
    (True, True)
    """

    gamma: float = float("nan")
    h2_bound: float = float("nan")
    h2_opt: float = float("nan")

    def __repr__(self) -> str:
        base = super().__repr__()
        return base.replace("Controller(", f"H2HinfController(gamma={self.gamma:.6g}, h2_bound={self.h2_bound:.6g}, "
                                           f"h2_opt={self.h2_opt:.6g}, ", 1)


def h2hinf(plant: Plant, *, gamma: float, Bw: ArrayLike, Cz: ArrayLike, Dzu: ArrayLike,
           Cz2: ArrayLike, Dzu2: ArrayLike, Dzw: ArrayLike | None = None, Dyw: ArrayLike | None = None,
           Bw2: ArrayLike | None = None, Dzw2: ArrayLike | None = None, Dyw2: ArrayLike | None = None,
           poles: Region | list[Region] | None = None, backoff: float = 1e-3, solver: str = "CLARABEL",
           feedback: str | None = None) -> H2HinfController:
    r"""Mixed H2/H-infinity synthesis: minimise an H2 bound of ``w2 -> z2`` subject to ``||T_zw||_inf < gamma``.

    Parameters
    ----------
    plant : Plant
        Discrete or continuous plant; with measured outputs (``C``, ``D``)
        the result is a full-order output feedback, otherwise (or with
        ``feedback="state"``) a state feedback ``u = K x``.
    gamma : float
        The H-infinity bound of the channel ``w -> z``.
    Bw, Cz, Dzu : array_like
        The H-infinity channel (``(n, q)``, ``(p, n)``, ``(p, m)``).
    Cz2, Dzu2 : array_like
        The H2 channel's output ``z2 = Cz2 x + Dzw2 w2 + Dzu2 u``.
    Dzw, Dyw : array_like, optional
        Feedthroughs of ``w`` to ``z`` and to ``y`` (default zero).
    Bw2, Dzw2, Dyw2 : array_like, optional
        The H2 channel's disturbance ``w2``: by default ``w`` itself
        (``Bw2 = Bw``, ``Dyw2 = Dyw``); ``Dzw2`` defaults to zero and must be
        zero for a continuous plant (the H2 norm is otherwise infinite).
    poles : Region or list of Region, optional
        Pole regions of the closed loop, with the same Lyapunov matrix.
    backoff : float, default 1e-3
        The controller is taken from a well-centred point at
        ``(1 + backoff) h2_opt``; it must be positive.
    solver : str, default "CLARABEL"
        cvxpy SDP solver.
    feedback : {None, "state", "output"}, optional
        As in :func:`robustctl.hinf`.

    Returns
    -------
    H2HinfController
        ``K`` (state feedback) or ``Ac``, ``Bc``, ``Cc``, ``Dc``, with
        ``gamma``, ``h2_bound``, ``h2_opt`` and ``info`` (``feedback``,
        ``certificate`` of the closed loop: ``stability``, ``hinf[0]`` the
        Hamiltonian test at ``gamma``, ``h2_norm_ratio`` the H2 norm from
        the closed loop's Gramian over ``h2_bound``; ``solves``,
        ``backoff``, ``status``, ``solve_time``, ``iterations``).

    Raises
    ------
    InfeasibleError
        No controller meets ``gamma`` (with the regions), or the plant is
        not stabilisable / detectable.
    ValueError, TypeError
        Bad arguments (named in the message).

    See Also
    --------
    robustctl.hinf, robustctl.h2

    Notes
    -----
    With one Lyapunov matrix ``P`` for both norms the conditions are
    convex; for state feedback, with ``Y = K X``,

    .. math::

        \begin{bmatrix} \operatorname{He}(F X + G Y) & B_w & (C_z X + D_{zu} Y)^T \\
        \star & -I & D_{zw}^T \\ \star & \star & -\gamma^2 I \end{bmatrix} \prec 0,
        \quad \operatorname{He}(F X + G Y) + B_{w2} B_{w2}^T \prec 0,
        \quad \begin{bmatrix} W & C_{z2} X + D_{zu2} Y \\ \star & X \end{bmatrix} \succ 0

    (continuous time), minimising ``trace(W)``. A common ``X`` is a
    restriction, so ``h2_opt`` is an upper bound of the true mixed optimum;
    as ``gamma`` grows it tends to the unconstrained H2 optimum.

    References
    ----------
    1. P. P. Khargonekar, M. A. Rotea, "Mixed H2/H-infinity control: a convex
       optimization approach", IEEE TAC 36(7), 1991.
    2. C. Scherer, P. Gahinet, M. Chilali, "Multiobjective output-feedback
       control via LMI optimization", IEEE TAC 42(7), 1997.

    Examples
    --------
    A loose H-infinity bound leaves the H2 optimum (the LQR's) unchanged;
    the returned gain meets both:

    >>> import numpy as np, control, robustctl as rc
    >>> plant = rc.Plant([[0.0, 1.0], [0.0, 0.0]], [[0.0], [1.0]], None)
    >>> Cz, Dzu = rc.lq_output(np.eye(2), np.eye(1))
    >>> ctrl = rc.h2hinf(plant, gamma=100.0, Bw=np.eye(2), Cz=Cz, Dzu=Dzu, Cz2=Cz, Dzu2=Dzu)
    >>> lq = rc.h2(plant, Bw=np.eye(2), Cz=Cz, Dzu=Dzu)
    >>> bool(abs(ctrl.h2_opt / lq.h2_opt - 1) < 1e-3)
    True
    >>> loop = control.ss(plant.F + plant.G @ ctrl.K, np.eye(2), Cz + Dzu @ ctrl.K, 0)
    >>> bool(control.linfnorm(loop)[0] < ctrl.gamma and control.norm(loop, 2) <= ctrl.h2_bound)
    True
    """
    gamma = check_positive_scalar(gamma, "gamma")
    output = wants_output(plant, feedback, Dyw if Dyw is not None else Dyw2)
    if Bw2 is None:           # w2 is w
        Bw2, Dyw2 = Bw, Dyw if Dyw2 is None else Dyw2
    if output:
        chans = (channel(plant, Bw, Cz, Dzu, Dzw, Dyw), channel(plant, Bw2, Cz2, Dzu2, Dzw2, Dyw2, suffix="2"))
        pb = output_problem(plant, "h2hinf", chans, gamma=gamma, backoff=backoff, poles=poles, solver=solver)
        res = synthesise(pb)
        return dynamic_controller(H2HinfController, "h2hinf", plant, res, pb, gamma=gamma, h2_bound=res.h2_bound,
                                  h2_opt=res.h2_opt)
    problem = validate(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw, vertices=None, gamma=gamma, u_max=None,
                       w_energy=None, backoff=backoff, extended=False, solver=solver, poles=poles)
    if not check_real(backoff, "backoff", minimum=0.0) > 0:
        raise ValueError("backoff must be > 0: the gain is taken from a well-centred point above the optimum")
    second = validate(plant, Bw=Bw2, Cz=Cz2, Dzu=Dzu2, Dzw=Dzw2, vertices=None, gamma=None, u_max=None,
                      w_energy=None, backoff=backoff, extended=False, solver=solver)
    if not plant.is_discrete and np.any(second.Dzw):
        raise ValueError("Dzw2 must be zero for a continuous-time plant: a feedthrough from white noise w2 to z2 "
                         "makes the H2 norm infinite")
    n = plant.n
    hinf_ch, h2_ch = (Channel(pr.Bw, pr.Cz, pr.Dzw, pr.Dzu, np.zeros((n, pr.Bw.shape[1]))) for pr in (problem, second))
    try:
        res_sf = mixed_state(plant, hinf_ch, h2_ch, gamma, regions=problem.regions, backoff=problem.backoff,
                             solver=problem.solver)
    except (ConvergenceError, InfeasibleError):
        # an empty feasible set often ends in a solver failure: the H-infinity bound alone decides (InfeasibleError
        # naming gamma when no gain meets it)
        hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw, gamma=gamma, poles=poles, solver=solver, feedback="state")
        raise
    info = {"feedback": "state", "certificate": res_sf.certificate, "solves": list(res_sf.solves),
            "backoff": res_sf.backoff, "status": res_sf.solves[-1]["status"], "poles": problem.regions,
            **_cvx.totals(res_sf.solves)}
    return H2HinfController(K=res_sf.K, method="h2hinf", plant=plant, info=info, gamma=gamma,
                            h2_bound=res_sf.h2_bound, h2_opt=res_sf.h2_opt)
