"""The output-feedback synthesis driver on arrays: the stages in order.

1. :func:`.output_coordinates.standard` - unit channels, balanced states, unit ``u`` and ``y``
   (``D22`` was removed by the caller: the loop shift of :mod:`.generalised`);
2. ``synthesis="riccati"`` (H-infinity, regular channel): :func:`riccati_path`,
   the bisection of :mod:`.output_riccati`, the central controller at
   ``(1 + backoff / 2) gamma_opt`` and its certificate at
   ``(1 + backoff) gamma_opt``; any failure falls through to the LMIs;
3. the shapes (:mod:`.output_shapes`) and the frames
   (:func:`.output_coordinates.frame_of_shapes`): the shaped one, then the
   plain one if a solve fails there; ``z`` scaled so that the optimum is
   near 1;
4. :func:`.output_level.minimise` - the optimum (or, with a fixed level,
   straight to 5);
5. the controller of a centring solve (:func:`.output_level.centre`) at the
   backed-off level, reconstructed (:func:`.output_lmis.controller`) and
   accepted only if its closed loop is certified there
   (:mod:`.output_certificate`); otherwise the backoff is raised by
   ``BACKOFF_STEPS``. The optimum's own controller is not used: there
   ``I - X Y`` is nearly singular and the controller huge;
6. the controller mapped back to the caller's ``u`` and ``y`` and closed
   around ``D22``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ... import _cvx
from ...errors import ConvergenceError, InfeasibleError
from .generalised import DynamicGain, Generalised, loop_shift
from .output_certificate import h2_norm, hinf_certificate, poles_inside
from .output_coordinates import Frame, Standard, frame_of_shapes, standard
from .output_level import Solved, Spec, centre, minimise
from .output_lmis import controller, h2_feedthrough_removed
from .output_riccati import bisect_level, is_regular, normalise, regular_controller, tustin
from .output_shapes import h2_shapes, hinf_shapes
from .tolerances import BACKOFF_STEPS

__all__ = ["OFProblem", "OFResult", "synthesise", "riccati_path", "RICCATI_RTOL", "RICCATI_GAMMA_MAX"]

#: Relative width of the final bracket of the Riccati path's bisection.
RICCATI_RTOL = 1e-9
#: Largest level the Riccati path tries (unit-sized channels).
RICCATI_GAMMA_MAX = 1e10
#: A centring margin below this is no strictly feasible point (fixed levels: infeasible).
MARGIN_MIN = 1e-9


@dataclass(frozen=True, eq=False)
class OFProblem:
    """A validated output-feedback problem on arrays.

    ``kind``: ``"hinf"`` (channel 0), ``"h2"`` (channel 0) or ``"h2hinf"``
    (H-infinity bound ``gamma`` on channel 0, H2 minimised on channel 1).
    ``gamma``: the fixed level (``"hinf"``; ``None`` minimises) or the bound
    (``"h2hinf"``). ``plant`` has ``D22 = 0``; ``D22`` is put back on the
    controller.
    """

    plant: Generalised
    D22: np.ndarray
    kind: str
    gamma: float | None = None
    backoff: float = 1e-3
    regions: tuple = ()
    solver: str = "CLARABEL"
    synthesis: str = "lmi"


@dataclass(frozen=True, eq=False)
class OFResult:
    """The controller (caller's ``u``, ``y``; ``D22`` included) and its levels (``None`` where not asked)."""

    K: DynamicGain
    gamma: float | None = None
    gamma_opt: float | None = None
    h2_bound: float | None = None
    h2_opt: float | None = None
    info: dict = field(default_factory=dict)


def synthesise(pb: OFProblem) -> OFResult:
    """Stages 1-6 of the module docstring."""
    std = standard(pb.plant)
    fallback = None
    if pb.synthesis == "riccati":
        fast = riccati_path(pb, std)
        if isinstance(fast, OFResult):
            return fast
        fallback = fast
        _cvx.check_solver(pb.solver)    # the SDP is needed after all
    out = _lmi_path(pb, std)
    info = {**out.info, "synthesis": "lmi"}
    if pb.synthesis == "riccati":
        info["fallback"] = fallback
    return replace(out, info=info)


def riccati_path(pb: OFProblem, std: Standard) -> OFResult | str:
    """The gamma-iteration, the central controller and its certificate; the reason for the fallback if one fails."""
    plant = std.plant
    image = plant
    if plant.discrete:
        found = tustin(plant, np.zeros((plant.p, plant.m)))
        if found is None:
            return "the plant has an eigenvalue at z = -1 (no Tustin image)"
        image = found[0]
    if not is_regular(image.channels[0]):
        return ("the problem is singular (D12 without full column rank or D21 without full row rank"
                + (" in the Tustin image" if plant.discrete else "") + ")")
    hi, lo, its = bisect_level(normalise(image), rtol=RICCATI_RTOL, gamma_max=RICCATI_GAMMA_MAX)
    if not np.isfinite(hi):
        return "no level passes the Riccati conditions (an imaginary-axis rank condition may fail)"
    b = pb.backoff
    K = regular_controller(plant, np.zeros((plant.p, plant.m)), hi * (1.0 + 0.5 * b))
    cert = None if K is None else hinf_certificate(plant, K, hi * (1.0 + b))
    if K is None or cert is None:
        return "the central controller's closed loop is not certified at the backed-off level"
    scale = std.level_scales[0]
    info: dict = {"synthesis": "riccati", "riccati": {"iterations": its + 1, "gamma_low": lo / scale},
                  "fallback": None, "gain_from": "central", "certificate": cert, "backoff": b, "solves": [],
                  "status": "certified", "solve_time": 0.0, "iterations": 0}
    return OFResult(_back(pb, std, K), gamma=hi * (1.0 + b) / scale, gamma_opt=hi / scale, info=info)


def _back(pb: OFProblem, std: Standard, K: DynamicGain) -> DynamicGain:
    """The controller of the caller's ``u``, ``y`` and ``D22``; ConvergenceError if not finite."""
    K = loop_shift(std.caller_controller(K), pb.D22)
    if not K.is_finite():
        raise ConvergenceError("the reconstructed controller is not finite; increase backoff")
    return K


@dataclass(frozen=True, eq=False)
class _Setup:
    """The frames to try in order (shaped, then plain) and the factor from a caller's level to the frames'."""

    frames: tuple[Frame, ...]
    unit: tuple[float, ...]
    spec: Spec


def _setup(pb: OFProblem, std: Standard) -> _Setup:
    plant = std.plant
    unit = list(std.level_scales)
    chans = list(plant.channels)
    if pb.kind == "h2hinf":
        c0, c1 = pb.plant.channels
        shared = c0.B1.shape == c1.B1.shape and np.array_equal(c0.B1, c1.B1) and np.array_equal(c0.D21, c1.D21)
        spec = Spec(hinf=0, h2=1, regions=pb.regions, what="mixed H2/H-infinity output feedback", shared_w=shared)
        shapes, k = h2_shapes(plant, 1), 1
    elif pb.kind == "h2":
        spec = Spec(hinf=None, h2=0, regions=pb.regions, what="H2 output feedback")
        shapes, k = h2_shapes(plant, 0), 0
    else:
        spec = Spec(hinf=0, h2=None, regions=pb.regions, what="H-infinity output feedback")
        shapes, k = hinf_shapes(plant, 0), 0
    # z of the shaped channel scaled so that its optimum is near 1 (the shapes do not change: X_inf and the
    # level scale together, and a Gramian does not depend on z)
    est = shapes[2] if shapes is not None and np.isfinite(shapes[2]) and shapes[2] > 0 else 1.0
    chans[k] = chans[k].scaled(1.0, est)
    unit[k] /= est
    if pb.kind == "h2hinf":
        assert pb.gamma is not None     # the bound of the mixed problem is required
        lvl = pb.gamma * unit[0]           # the H-infinity bound becomes 1
        chans[0] = chans[0].scaled(1.0, lvl)
        unit[0] /= lvl
    g = Generalised(plant.A, plant.B2, plant.C2, tuple(chans), plant.discrete)
    plain = frame_of_shapes(g, None, None)
    frames = (plain,) if shapes is None else (frame_of_shapes(g, *shapes[:2]), plain)
    return _Setup(frames, tuple(unit), spec)


def _lmi_path(pb: OFProblem, std: Standard) -> OFResult:
    """Stages 4-5 in the first frame where the solver succeeds (the shapes may not suit a problem: then plain)."""
    s = _setup(pb, std)
    spec = s.spec
    solves: list[dict] = []
    if pb.kind == "hinf" and pb.gamma is not None:
        level = pb.gamma * s.unit[0]
        K, cert, margin = _centred(pb, s.frames, spec, (level, None), solves,
                                   f"no controller achieves gamma={pb.gamma:.6g}: the H-infinity output-feedback "
                                   "LMIs are infeasible at this level")
        if K is None:
            raise InfeasibleError(f"no controller achieves gamma={pb.gamma:.6g} (largest strictness margin "
                                  f"{margin:.3g} of the output-feedback LMIs at this level)")
        return OFResult(_back(pb, std, K), gamma=pb.gamma, info=_info(solves, cert, None, margin))
    try:
        opt, frames = _minimised(pb, s, solves)
    except (ConvergenceError, InfeasibleError):
        if pb.kind == "h2hinf":
            _check_bound(pb, s)     # an infeasible bound is a solver failure more often than a certificate
        raise
    best = float(np.sqrt(max(opt.value, 0.0)))       # the frames' optimal level (H-infinity) or H2 norm
    failure: Exception | None = None
    for factor in BACKOFF_STEPS:
        b = pb.backoff * factor
        try:
            K, cert, margin = _centred(pb, frames, spec, _targets(pb, best, b), solves,
                                       f"could not find a strictly feasible controller at {b:g} above the "
                                       "optimum; increase backoff")
        except (ConvergenceError, InfeasibleError) as exc:
            failure = exc
            continue
        if K is not None:
            return _result(pb, std, s, K, best, b, _info(solves, cert, b, margin))
        failure = ConvergenceError(f"the controller of the centred point at {b:g} above the optimum is not "
                                   "certified by its closed loop; increase backoff")
    raise failure or ConvergenceError("no controller strategy applied")


def _check_bound(pb: OFProblem, s: _Setup) -> None:
    """InfeasibleError naming ``gamma`` if no controller meets the mixed problem's H-infinity bound alone.

    The largest common margin of the H-infinity blocks at the bound (always
    feasible, so its sign decides, where the minimisation over an empty set
    may end in a solver failure instead).
    """
    spec = Spec(hinf=0, h2=None, regions=s.spec.regions)
    msg = f"no controller meets gamma={pb.gamma:.6g}"
    K, _, margin = _centred(pb, s.frames, spec, (1.0, None), [], msg)
    if K is None:
        raise InfeasibleError(f"{msg} on the H-infinity channel (largest strictness margin {margin:.3g} of its "
                              "output-feedback LMIs at this level), so the mixed problem has no solution")


def _minimised(pb: OFProblem, s: _Setup, solves: list) -> tuple[Solved, tuple[Frame, ...]]:
    """The optimum in the first frame that gives one, and the frames from that one on."""
    failure: Exception | None = None
    for i, f in enumerate(s.frames):
        try:
            opt = minimise(f, s.spec, pb.solver)
        except (ConvergenceError, InfeasibleError) as exc:   # an InfeasibleError may be a failed certificate
            failure = exc
            continue
        solves.append(opt.report.as_dict())
        return opt, s.frames[i:]
    assert failure is not None
    raise failure


def _targets(pb: OFProblem, best: float, b: float) -> tuple[float | None, float | None]:
    """``(H-infinity level, H2 bound)`` in the frame at backoff ``b``."""
    if pb.kind == "hinf":
        return (1.0 + b) * best, None
    if pb.kind == "h2":
        return None, (1.0 + b) * best
    return 1.0, (1.0 + b) * best


def _check(f: Frame, spec: Spec, K: DynamicGain, targets) -> dict | None:
    """The certificate of ``K`` at the targets (``None`` if any part fails)."""
    level, bound = targets
    cert: dict = {}
    if spec.hinf is not None:
        c = hinf_certificate(f.plant, K, level, spec.hinf)
        if c is None:
            return None
        cert.update(c)
    if spec.h2 is not None:
        norm = h2_norm(f.plant, K, spec.h2)
        if not norm <= bound:
            return None
        cert["h2_norm_ratio"] = norm / bound
    if spec.regions and not poles_inside(f.plant, K, spec.regions):
        return None
    return cert


def _centred(pb: OFProblem, frames: tuple[Frame, ...], spec: Spec, targets, solves: list, msg: str):
    """``(K, certificate, margin)`` of the centring solve at the targets (``K = None`` if uncertified).

    The first frame whose solve succeeds; the last failure is raised if none does.
    """
    level, bound = targets
    failure: Exception | None = None
    for frame in frames:
        f = frame
        if level is not None and spec.hinf is not None:
            f = f.with_channel(spec.hinf, f.plant.channels[spec.hinf].scaled(1.0, level))
        if bound is not None and spec.h2 is not None:
            f = f.with_channel(spec.h2, f.plant.channels[spec.h2].scaled(1.0, bound))
        try:
            sol: Solved = centre(f, spec, pb.solver, msg)
        except (ConvergenceError, InfeasibleError) as exc:
            failure = exc
            continue
        solves.append({**sol.report.as_dict(), "centring": "margin"})
        if not sol.value > MARGIN_MIN:
            return None, {}, sol.value
        point = sol.point if spec.h2 is None else h2_feedthrough_removed(f, sol.point, spec.h2)
        K = controller(f, point)
        cert = _check(f, spec, K, (None if level is None else 1.0, None if bound is None else 1.0))
        return (K if cert is not None else None), cert or {}, sol.value
    assert failure is not None
    raise failure


def _info(solves: list, cert: dict, backoff, margin: float) -> dict:
    return {"solves": list(solves), "gain_from": "centred", "certificate": cert, "backoff": backoff, "margin": margin,
            "status": solves[-1]["status"] if solves else "certified", **_cvx.totals(solves)}


def _result(pb: OFProblem, std: Standard, s: _Setup, K: DynamicGain, best: float, b: float, info: dict) -> OFResult:
    Kc = _back(pb, std, K)
    if pb.kind == "hinf":
        opt = best / s.unit[0]
        return OFResult(Kc, gamma=(1.0 + b) * opt, gamma_opt=opt, info=info)
    k = 0 if pb.kind == "h2" else 1
    opt = best / s.unit[k]
    return OFResult(Kc, gamma=pb.gamma, h2_bound=(1.0 + b) * opt, h2_opt=opt, info=info)
