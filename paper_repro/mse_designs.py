"""The controllers of the MSE table (``paper_repro/mse_table.py``): its two set-ups and the designs.

The set-ups (``TABLE_SETUPS``) and the designs are described in
``mse_table.py``'s docstring; the choices the paper leaves open are in
``docs/reproducing.rst``. Imported by ``mse_table.py`` as a sibling module
(run from the repository: ``python paper_repro/mse_table.py``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from paper_values import CONTROLLERS
from truck_margins import appendix_uncertainty

import robustctl as rc
from robustctl.models import morais2022, truck
from robustctl.models.morais2022 import CODE_GAMMA, SETUPS, code_manoeuvre
from robustctl.models.path import default_route
from robustctl.models.pathfollow import PathFollowingSetup
from robustctl.synthesis.hinf_game import hinf_game

# "ours" H-infinity disturbance channels (columns of Bw): a 1 m lateral-displacement
# impulse (the run's initial offset) and the path curvature scaled by the
# tightest curve of the route (1/200 m).
HINF_RHO_IMPULSE = 1.0
HINF_KAPPA_SCALE = 1.0 / 200.0
#: The uncertainty input ``H`` of the appendix and of the authors' code (``parameters.m``: ones).
H_ONES = np.ones((4, 1))


# -- set-ups ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class TableSetup:
    """The choices of one MSE-table set-up (module docstring).

    Attributes
    ----------
    name : str
    loop : PathFollowingSetup
        Reference, loop, initial state and the weights of every design.
    hinf : {"ours", "authors", "game"}
        The ``Hinf`` row: our formulation (impulse and curvature channels,
        input bound), the authors' (``Bw = H``, no bound), or the code's
        game-Riccati law.
    rlqr_a_eg : {"printed", "code"}
        ``E_G`` of the ``RLQR_A`` row: the paper's or the code's.
    course : {"route", "code"}
    """

    name: str
    loop: PathFollowingSetup
    hinf: str
    rlqr_a_eg: str
    course: str

    def __post_init__(self):
        for field, valid in (("hinf", HINF_LAWS), ("rlqr_a_eg", ("printed", "code")), ("course", COURSES)):
            if getattr(self, field) not in valid:
                raise ValueError(f"{field} must be one of {', '.join(valid)}, got {getattr(self, field)!r}")

    @property
    def authors_weights(self) -> bool:
        return self.loop.Q_diag == morais2022.AUTHORS_Q_DIAG and self.loop.r == morais2022.AUTHORS_R_DOUBLED / 2

    def path(self, duration: float | None = None):
        path = default_route() if self.course == "route" else code_manoeuvre()
        return path if duration is None else path.truncated(duration)

    def describe(self) -> str:
        s = self.loop
        return (f"set-up {self.name!r}: Q = diag({list(s.Q_diag)}), R = {s.r:g} (doubled column {2 * s.r:g} I2); "
                f"reference {s.reference!r}, feedforward {s.feedforward}, x0 = {list(s.x0)}; H-infinity "
                f"{self.hinf!r}; RLQR^A EG {self.rlqr_a_eg!r}; course {self.course!r}")


#: The set-up of ``make repro`` and ``design_selection.py`` (it reproduces the paper better: mse_table.py).
DEFAULT_SETUP = "authors"

HINF_LAWS = ("ours", "authors", "game")
COURSES = ("route", "code")
TABLE_SETUPS = {
    "authors": TableSetup("authors", SETUPS["authors"], "authors", "printed", "route"),
    "ours": TableSetup("ours", SETUPS["ours"], "ours", "printed", "route"),
}

#: One choice at a time (``--compare-setups``): how to give ``base`` the ``other`` set-up's choice.
CHOICES = {
    "weights": lambda b, o: dataclasses.replace(b, loop=dataclasses.replace(b.loop, Q_diag=o.loop.Q_diag,
                                                                            r=o.loop.r)),
    "loop": lambda b, o: dataclasses.replace(b, loop=dataclasses.replace(b.loop, reference=o.loop.reference,
                                                                         feedforward=o.loop.feedforward)),
    "x0": lambda b, o: dataclasses.replace(b, loop=dataclasses.replace(b.loop, x0=o.loop.x0)),
    "H-infinity law": lambda b, o: dataclasses.replace(b, hinf=o.hinf),
    "RLQR^A's EG": lambda b, o: dataclasses.replace(b, rlqr_a_eg="code" if b.rlqr_a_eg == "printed" else "printed"),
    "course": lambda b, o: dataclasses.replace(b, course="code" if b.course == "route" else "route"),
}


def get_table_setup(setup: str | TableSetup) -> TableSetup:
    if isinstance(setup, TableSetup):
        return setup
    if setup not in TABLE_SETUPS:
        raise ValueError(f"unknown setup {setup!r}; valid: {', '.join(TABLE_SETUPS)}")
    return TABLE_SETUPS[setup]


# -- designs ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class Design:
    """One controller of the comparison: ``u = K e`` (+ ``K_input alpha_prev``) and a one-line description."""

    name: str
    K: np.ndarray
    note: str
    K_input: np.ndarray | None = None

    @property
    def K_steer(self) -> np.ndarray:
        """The gain from error to steering angle, (1, 4): the sum of K's rows."""
        return self.K.sum(axis=0, keepdims=True)



    @property
    def law(self) -> rc.InputMemoryFeedback:
        """The steering law ``alpha = K_steer e (+ K_input alpha_prev)``, for the simulator and the margins."""
        return rc.InputMemoryFeedback(self.K_steer, self.K_input)

def _rlqr(name: str, ts: TableSetup, EF, EG, mu, note: str) -> Design:
    Q, R2 = ts.loop.weights(doubled=True)
    # check_stability=False: the Appendix A designs leave the nominal truck unstable (the table shows how they
    # fare, see rlqr_a_limit); rlqr raises NotStabilizingError for them by default
    ctrl = rc.design("rlqr", truck.truck_plant(0.0, doubled=True), np.atleast_2d(EF), np.atleast_2d(EG),
                     float(mu), Q=Q, R=R2, H=H_ONES, check_stability=False)
    return Design(name, ctrl.K, note)


def _hinf(name: str, ts: TableSetup, note: str, *, vertices=(), uncertainty=None, input_bound=None) -> Design:
    """The set-up's LMI H-infinity (``ts.hinf`` "ours" or "authors"; "game" uses the authors' formulation)."""
    Q, R = ts.loop.weights()
    ours = ts.hinf == "ours"
    if ours:
        _, _, Gk = truck.discretise(0.0)
        Bw = np.column_stack([[0.0, 0.0, HINF_RHO_IMPULSE, 0.0], Gk[0] * HINF_KAPPA_SCALE])
    else:
        Bw = H_ONES
    Cz, Dzu = rc.lq_output(Q, R)                                   # z = [sqrt(Q) x; sqrt(R) u]
    bound = ours if input_bound is None else input_bound
    extra = dict(u_max=truck.STEER_LIMIT, w_energy=1.0) if bound else {}
    ctrl = rc.design("hinf", truck.truck_plant(0.0), Bw=Bw, Cz=Cz, Dzu=Dzu, vertices=list(vertices) or None,
                     uncertainty=uncertainty, **extra)
    text = f"{note}; gamma = {ctrl.gamma:.5g}"
    if bound:
        text += f", guaranteed |alpha| <= {float(np.max(ctrl.info['u_bound'])):.3g} rad for unit-energy w"
    return Design(name, ctrl.K, text)


def _hinf_game(name: str, ts: TableSetup) -> Design:
    Q, R = ts.loop.weights()
    g = hinf_game(truck.truck_plant(0.0), Bw=H_ONES, Q=Q, R=R, gamma=CODE_GAMMA, P_final=np.eye(4))
    return Design(name, g.K_e, f"game-Riccati H-infinity (barbosafilipe/robust_lqr h_infinity.m), gamma = "
                               f"{CODE_GAMMA:g}, Bw = H, P_N = I, stationary after {g.iterations} steps; "
                               f"delayed full-information law u = K e + K_input alpha_prev, "
                               f"K_input = {float(g.K_u[0, 0]):.4g}", K_input=g.K_u)



def available_controllers(setup: str | TableSetup, uncertainty: str = "printed") -> tuple[str, ...]:
    """Names :func:`design_controllers` accepts: the paper's four, then the extra rows of ``setup``."""
    ts = get_table_setup(setup)
    extras = ["RLQR_A_code_EG" if ts.rlqr_a_eg == "printed" else "RLQR_A_printed_EG",
              "RLQR_A_computed" if uncertainty == "printed" else "RLQR_A_printed", "Hinf_polytopic", "Hinf_robust"]
    if ts.hinf == "ours":
        extras.append("Hinf_unbounded")
    if ts.authors_weights and ts.hinf != "game":
        extras.append("Hinf_game")
    return CONTROLLERS + tuple(extras)


def design_controllers(setup: str | TableSetup, z=morais2022.RLQR_MOP_Z, uncertainty: str = "printed",
                       controllers: tuple[str, ...] | list[str] | None = None) -> list[Design]:
    """Design the named controllers (default: all of :func:`available_controllers`) on the nominal model."""
    if uncertainty not in ("printed", "computed"):
        raise ValueError(f"uncertainty must be 'printed' or 'computed', got {uncertainty!r}")
    ts = get_table_setup(setup)
    valid = available_controllers(ts, uncertainty)
    names = list(valid) if controllers is None else list(controllers)
    unknown = [c for c in names if c not in valid]
    if unknown or not names:
        raise ValueError(f"unknown controller name(s) {unknown or names}; valid: {', '.join(valid)}")
    Q, R = ts.loop.weights()
    lmi = ts if ts.hinf != "game" else dataclasses.replace(ts, hinf="authors")
    form = {"ours": "impulse and curvature channels", "authors": "Bw = H (the authors' formulation)"}[lmi.hinf]
    designs = []
    for name in valid:
        if name not in names:
            continue
        if name == "RLQR_MOP":
            EF, EG, mu = morais2022.uncertainty_from_z(z)
            designs.append(_rlqr(name, ts, EF[0], EG[0], mu[0], "RLQR, doubled column, z = "
                                 + np.array2string(np.asarray(z, float), precision=5)))
        elif name.startswith("RLQR_A"):
            src = {"RLQR_A_computed": "computed", "RLQR_A_printed": "printed"}.get(name, uncertainty)
            eg = {"RLQR_A_code_EG": "code", "RLQR_A_printed_EG": "printed"}.get(name, ts.rlqr_a_eg)
            u = morais2022.algebraic_uncertainty(src)
            EG = np.array([morais2022.CODE_EG]) if eg == "code" else u.EG
            designs.append(_rlqr(name, ts, u.EF, EG, u.mu,
                                 f"RLQR, doubled column, Appendix A uncertainty ({src}"
                                 f"{', the code' + chr(39) + 's EG' if eg == 'code' else ''}): "
                                 f"EF = {np.array2string(u.EF[0], precision=4)}, "
                                 f"EG = {np.array2string(EG[0], precision=4)}, mu = {u.mu:.3g}"))
        elif (name == "Hinf" and ts.hinf == "game") or name == "Hinf_game":
            designs.append(_hinf_game(name, ts))
        elif name == "Hinf":
            designs.append(_hinf(name, lmi, f"LMI H-infinity, nominal payload, {form}, "
                                            + ("|alpha| <= 0.45 rad input bound" if lmi.hinf == "ours"
                                               else "no input bound")))
        elif name == "Hinf_unbounded":
            designs.append(_hinf(name, lmi, f"LMI H-infinity, nominal payload, {form}, no input bound",
                                 input_bound=False))
        elif name == "Hinf_polytopic":
            designs.append(_hinf(name, lmi, f"LMI H-infinity over the 0-300 % payload polytope, {form}",
                                 vertices=[truck.truck_plant(300.0)]))
        elif name == "Hinf_robust":
            designs.append(_hinf(name, lmi, f"robust LMI H-infinity for the appendix's printed norm-bounded "
                                            f"model, {form}", uncertainty=appendix_uncertainty()))
        elif name == "LQR":
            designs.append(Design(name, rc.design("lqr", truck.truck_plant(0.0), Q=Q, R=R).K,
                                  "LQR, nominal model"))
    return designs


# -- the printed RLQR^A in the limit mu -> inf ------------------------------------------------
def rlqr_a_limit(ts: TableSetup) -> dict:
    """The printed RLQR^A: its gain at the printed mu and the gain ``mu -> inf`` forces.

    With ``mu -> inf`` the RLQR enforces ``EF + EG K = 0``; with the doubled
    column and equal ``EG`` entries ``e`` this fixes the steering gain
    ``K1 + K2 = -EF / e``, whose ``rho`` entry is ``-EF[2] / e = 0``: the
    closed loop ``F + G K`` keeps the column of ``rho`` of ``F``, the unit
    vector, so it has the eigenvalue 1 exactly (no lateral-displacement
    feedback). The printed mu (1e9) is that limit only where ``R`` is small
    against ``mu ||EG||^2``: returned are both gains, the eigenvalue of each
    closest to 1 and the spectral radii.
    """
    u = morais2022.algebraic_uncertainty("printed")
    e = float(u.EG[0, 0])
    p = truck.truck_plant(0.0)
    K_lim = -u.EF / e
    K_mu = _rlqr("RLQR_A", ts, u.EF, u.EG, u.mu, "").K_steer
    out = {"K_limit": K_lim, "K_printed_mu": K_mu}
    for key, K in (("limit", K_lim), ("printed_mu", K_mu)):
        ev = np.linalg.eigvals(p.F + p.G @ K)
        out[f"eig_nearest_1_{key}"] = complex(ev[np.argmin(np.abs(ev - 1.0))])
        out[f"radius_{key}"] = float(np.max(np.abs(ev)))
    return out



def limit_text(limit: dict) -> str:
    return ("Printed RLQR^A in the limit mu -> inf (equal EG entries e): steering gain -EF/e = "
            f"{np.array2string(limit['K_limit'][0], precision=4)}, no rho feedback, closed-loop eigenvalue "
            f"{limit['eig_nearest_1_limit'].real:.12g} (exactly 1). At the printed mu = 1e9 with this set-up's "
            f"weights: {np.array2string(limit['K_printed_mu'][0], precision=4)}, eigenvalue nearest 1 "
            f"{abs(limit['eig_nearest_1_printed_mu']):.5f}, spectral radius {limit['radius_printed_mu']:.5f}.")
