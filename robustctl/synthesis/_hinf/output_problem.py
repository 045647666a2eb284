"""Stage 1 of output-feedback synthesis: which feedback is asked, the arguments checked, the problem on arrays.

:func:`wants_output` decides between state and output feedback; :func:`refuse`
names the options the output-feedback LMIs cannot take (with the reason);
:func:`output_problem` checks the channels, ``Dyw``, stabilisability and
detectability and the pole regions, and returns the
:class:`.output_synthesis.OFProblem`; :func:`dynamic_controller` builds the
public controller and checks its closed loop with the library's own
closed-loop assembly.
"""

from __future__ import annotations

import re
from typing import TypeVar

import numpy as np

from ... import _cvx
from ..._validation import as_matrix, check_choice, check_performance, check_positive_scalar, check_real
from ...errors import ConvergenceError, InfeasibleError
from ...systems.controller import Controller
from ...systems.plant import Plant, check_plant
from ...systems.regions import as_regions, describe_regions
from ...systems.stability import check_detectable, check_stabilizable, immovable_modes
from .generalised import Channel, Generalised
from .output_synthesis import OFProblem, OFResult
from .problem import check_poles_reachable

__all__ = ["wants_output", "refuse", "channel", "output_problem", "dynamic_controller", "REFUSED"]

C = TypeVar("C", bound=Controller)

#: The options the output-feedback LMIs do not take, and why.
REFUSED = {
    "vertices": "the output-feedback change of variables is not linear in the plant (Ah contains Y F X), so a "
                "controller common to the vertices of a polytope is not an LMI problem",
    "uncertainty": "the S-procedure multiplier of a norm-bounded uncertainty multiplies both Lyapunov variables of "
                   "the output-feedback LMIs, which are then no longer jointly convex",
    "u_max": "the reachable-set input bound needs u = K x; with u = K(z) y the input also depends on w directly "
             "(through Dc and Dyw)",
    "w_energy": "it is the disturbance energy of u_max, which output feedback does not take",
    "extended": "the slack-variable LMI is a state-feedback condition",
}


def wants_output(plant: Plant, feedback, Dyw) -> bool:
    """Whether output feedback is asked: ``feedback="output"``, or ``None`` and the plant declares outputs.

    ValueError for ``feedback="output"`` on a plant without outputs and for a
    ``Dyw`` given to a state-feedback synthesis.
    """
    check_plant(plant)
    if feedback is not None:
        check_choice(feedback, "feedback", ("state", "output"))
    if feedback == "output" and not plant.has_outputs:
        raise ValueError("feedback='output' needs a plant with measured outputs, Plant(F, G, dt, C=..., D=...); "
                         "plant has no output model (C is None), so only feedback='state' applies")
    out = plant.has_outputs if feedback is None else feedback == "output"
    if not out and Dyw is not None:
        raise ValueError("Dyw is the feedthrough from w to the measured outputs y of output feedback; the synthesis "
                         "asked here is state feedback" + (" (feedback='state')" if feedback == "state" else
                                                           " (plant has no outputs)") + ": drop Dyw")
    return out


def refuse(**given) -> None:
    """ValueError naming the first option given (not ``None``, not ``False``) that output feedback does not take."""
    for name, value in given.items():
        if value is not None and value is not False:
            raise ValueError(f"{name} is not supported by the output-feedback synthesis: {REFUSED[name]}; drop "
                             f"{name} or use feedback='state'")


def channel(plant: Plant, Bw, Cz, Dzu, Dzw, Dyw, suffix: str = "") -> Channel:
    """The checked channel ``(Bw, Cz, Dzw, Dzu, Dyw)`` of ``plant``; ``suffix`` names the arguments (``"2"``)."""
    try:
        Bw, Cz, Dzu, Dzw = check_performance(plant.n, plant.m, Bw, Cz, Dzu, Dzw)
    except (ValueError, TypeError) as exc:
        if not suffix:
            raise
        raise type(exc)(re.sub(r"\b(Bw|Cz|Dzu|Dzw)\b", r"\g<1>" + suffix, str(exc))) from None
    name = "Dyw" + suffix
    Dyw = np.zeros((plant.p, Bw.shape[1])) if Dyw is None else as_matrix(
        Dyw, name, rows=plant.p, cols=Bw.shape[1], rows_what="the number of measured outputs, plant.p",
        cols_what=f"the number of disturbances, the columns of Bw{suffix}")
    return Channel(Bw, Cz, Dzw, Dzu, Dyw)


def output_problem(plant: Plant, kind: str, channels: tuple[Channel, ...], *, gamma, backoff, poles, solver: str,
                   synthesis: str = "lmi") -> OFProblem:
    """The validated problem: stabilisable, detectable, regions reachable; continuous H2 channels without ``Dzw``."""
    if gamma is not None:
        gamma = check_positive_scalar(gamma, "gamma")
    backoff = check_real(backoff, "backoff", minimum=0.0)
    if not backoff > 0:
        raise ValueError("backoff must be > 0 for output feedback: the controller is reconstructed at "
                         "(1 + backoff) times the optimum, where the coupling I - X Y is invertible")
    solver = _cvx.check_solver(solver, installed=synthesis != "riccati")
    regions = as_regions(poles)
    h2 = {"h2": 0, "h2hinf": 1}.get(kind)
    if h2 is not None and not plant.is_discrete and np.any(channels[h2].D11):
        raise ValueError(f"Dzw{'2' if h2 else ''} must be zero for a continuous-time plant: a feedthrough from white "
                         "noise w to z makes the H2 norm infinite")
    check_stabilizable(plant)
    check_detectable(plant)
    if regions:
        check_poles_reachable([plant], regions)
        hidden = immovable_modes(plant.F.T, plant.output_matrices()[0].T,
                                 lambda z: ~np.all([r.contains(z) for r in regions], axis=0))
        if hidden.size:
            raise InfeasibleError(f"plant's mode lambda = {complex(hidden[0]):.6g} lies outside the pole region "
                                  f"{describe_regions(regions)} and is not seen by the outputs C (PBH rank test), "
                                  "so no output feedback places every closed-loop pole there")
    Cy, D = plant.output_matrices()
    g = Generalised(plant.F, plant.G, Cy, tuple(channels), plant.is_discrete)
    return OFProblem(g, D, kind, gamma=gamma, backoff=float(backoff), regions=regions, solver=solver,
                     synthesis=synthesis)


def dynamic_controller(cls: type[C], method: str, plant: Plant, result: OFResult, problem: OFProblem,
                       **levels) -> C:
    """The public controller of ``result``, its closed loop (the library's assembly, with ``D``) checked.

    ConvergenceError if it does not stabilise the plant or leaves a pole outside a region.
    """
    Ak, Bk, Ck, Dk = result.K
    info = {**result.info, "feedback": "output", "poles": problem.regions}
    ctrl = cls(None, method, plant, info, Ac=Ak, Bc=Bk, Cc=Ck, Dc=Dk, **levels)
    if not ctrl.is_stabilizing():
        raise ConvergenceError("internal check failed: the output-feedback controller does not stabilise plant; "
                               "increase backoff")
    poles = ctrl.closed_loop_poles()
    for r in problem.regions:
        if not np.all(r.contains(poles)):
            raise ConvergenceError(f"internal check failed: a closed-loop pole lies outside {r!r}; increase backoff")
    return ctrl
