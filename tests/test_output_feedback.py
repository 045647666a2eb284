"""Full-order output-feedback ``hinf`` and ``h2`` (LMI and Riccati paths) against independent references.

References, none sharing code with the synthesis:

* python-control's ``hinfsyn`` and ``h2syn`` (SLICOT SB10AD / SB10HD) on the
  generalised plant ``[[Dzw, Dzu], [Dyw, D]]`` (continuous time);
* the closed loop of the returned controller, assembled by python-control
  (``P.lft(K)``, positive feedback ``u = K y`` as ours) and measured by its
  ``linfnorm`` (SLICOT AB13DD) and ``norm(., 2)``;
* the H2 optimum of Scherer, Gahinet & Chilali (1997), Example 7, as
  python-control's example ``scherer_etal_ex7_H2_h2syn.py`` quotes it;
* discrete time: the Tustin image of a continuous problem has the same
  optimal level (the bilinear map preserves every closed-loop H-infinity
  norm), and the discrete H2 optimum is the LQG controller with the
  current-measurement estimate assembled from python-control's ``dlqr`` and
  ``dlqe``;
* singular problems (no measurement noise, ``Dyw = 0``): the limit of
  ``hinfsyn`` with the noise regularised to ``1e-4``.
"""

from __future__ import annotations

import warnings

import control
import numpy as np
import pytest
import scipy.linalg

import robustctl as rc
from robustctl.errors import InfeasibleError, NotDetectableError, NotStabilizableError

RTOL = 1e-4


def regular_case(n: int, seed: int, *, m: int = 2, p: int = 2, q: int = 2, D: bool = False):
    """A slightly unstable continuous plant; ``w = (process noise, measurement noise)``, ``z = (2 states, u)``."""
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n)) / np.sqrt(n)
    A += (0.1 - np.max(np.linalg.eigvals(A).real)) * np.eye(n)
    G, C = rng.normal(size=(n, m)), rng.normal(size=(p, n))
    Bw = np.hstack([rng.normal(size=(n, q)), np.zeros((n, p))])
    Cz = np.vstack([rng.normal(size=(2, n)), np.zeros((m, n))])
    Dzu = np.vstack([np.zeros((2, m)), np.eye(m)])
    Dyw = np.hstack([np.zeros((p, q)), np.eye(p)])
    Dyu = 0.3 * rng.normal(size=(p, m)) if D else np.zeros((p, m))
    return rc.Plant(A, G, None, C=C, D=Dyu), dict(Bw=Bw, Cz=Cz, Dzu=Dzu, Dyw=Dyw)


def generalised(plant: rc.Plant, Bw, Cz, Dzu, Dzw=None, Dyw=None):
    """python-control's generalised plant ``[w; u] -> [z; y]``."""
    C, D = plant.output_matrices()
    Dzw = np.zeros((Cz.shape[0], Bw.shape[1])) if Dzw is None else Dzw
    Dyw = np.zeros((C.shape[0], Bw.shape[1])) if Dyw is None else Dyw
    return control.ss(plant.F, np.hstack([Bw, plant.G]), np.vstack([Cz, C]), np.block([[Dzw, Dzu], [Dyw, D]]),
                      0 if plant.dt is None else plant.dt)


def loop(P, ctrl):
    """The closed loop ``w -> z`` of ``ctrl`` assembled by python-control."""
    return P.lft(ctrl.controller_statespace())


def assert_stable(sys):
    poles = sys.poles()
    assert (np.max(np.abs(poles)) < 1.0) if sys.dt else (np.max(poles.real) < 0.0)


CASES = [(3, 0), (4, 1), (6, 2), (8, 3)]


@pytest.mark.parametrize("n,seed", CASES)
@pytest.mark.parametrize("synthesis", ["lmi", "riccati"])
def test_hinf_matches_hinfsyn(n, seed, synthesis):
    plant, ch = regular_case(n, seed)
    P = generalised(plant, **ch)
    gam = control.hinfsyn(P, plant.p, plant.m)[2]
    ctrl = rc.hinf(plant, **ch, synthesis=synthesis)
    assert ctrl.K is None and ctrl.order == n and ctrl.info["feedback"] == "output"
    assert ctrl.info["synthesis"] == synthesis
    assert ctrl.gamma_opt == pytest.approx(gam, rel=RTOL)
    assert ctrl.gamma == pytest.approx((1 + 1e-3) * ctrl.gamma_opt, rel=1e-12)
    cl = loop(P, ctrl)
    assert_stable(cl)
    assert control.linfnorm(cl, tol=1e-10)[0] < ctrl.gamma


@pytest.mark.parametrize("n,seed", CASES[:3])
def test_h2_matches_h2syn(n, seed):
    plant, ch = regular_case(n, seed)
    P = generalised(plant, **ch)
    ref = control.norm(P.lft(control.h2syn(P, plant.p, plant.m)), 2)
    ctrl = rc.h2(plant, **ch)
    assert ctrl.K is None and ctrl.order == n
    assert ctrl.h2_opt == pytest.approx(ref, rel=RTOL)
    cl = loop(P, ctrl)
    assert_stable(cl)
    assert control.norm(cl, 2) <= ctrl.h2_bound


def scherer_example7():
    """Scherer, Gahinet & Chilali (1997), Example 7 (python-control's examples): plant and the two channels."""
    A = np.array([[0.0, 10.0, 2.0], [-1.0, 1.0, 0.0], [0.0, 2.0, -5.0]])
    B1, B2 = np.array([[1.0], [0.0], [1.0]]), np.array([[0.0], [1.0], [0.0]])
    plant = rc.Plant(A, B2, None, C=[[0.0, 1.0, 0.0]])
    hinf_ch = dict(Bw=B1, Cz=np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]), Dzu=np.array([[0.0], [1.0]]),
                   Dyw=np.array([[2.0]]))
    h2_ch = dict(Bw=B1, Cz=np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]]),
                 Dzu=np.array([[0.0], [0.0], [1.0]]), Dyw=np.array([[2.0]]))
    return plant, hinf_ch, h2_ch


def test_scherer_example7_h2_optimum():
    plant, _, ch = scherer_example7()
    ctrl = rc.h2(plant, **ch)
    assert ctrl.h2_opt == pytest.approx(7.748350599360575, rel=RTOL)   # the value python-control's example quotes
    cl = loop(generalised(plant, **ch), ctrl)
    assert control.norm(cl, 2) <= ctrl.h2_bound


def test_scherer_example7_hinf():
    plant, ch, _ = scherer_example7()
    P = generalised(plant, **ch)
    gam = control.hinfsyn(P, 1, 1)[2]
    for synthesis in ("lmi", "riccati"):
        ctrl = rc.hinf(plant, **ch, synthesis=synthesis)
        assert ctrl.gamma_opt == pytest.approx(gam, rel=RTOL)
        assert control.linfnorm(loop(P, ctrl), tol=1e-10)[0] < ctrl.gamma


@pytest.mark.parametrize("synthesis", ["lmi", "riccati"])
def test_plant_feedthrough_is_handled(synthesis):
    """``y = C x + D u`` with ``D != 0``: the loop shift against hinfsyn, which takes ``D22`` itself."""
    plant, ch = regular_case(4, 9, D=True)
    P = generalised(plant, **ch)
    gam = control.hinfsyn(P, plant.p, plant.m)[2]
    ctrl = rc.hinf(plant, **ch, synthesis=synthesis)
    assert ctrl.gamma_opt == pytest.approx(gam, rel=RTOL)
    cl = loop(P, ctrl)
    assert_stable(cl)
    assert control.linfnorm(cl, tol=1e-10)[0] < ctrl.gamma
    assert ctrl.is_stabilizing()


def tustin_image(plant: rc.Plant, ch: dict, dt: float = 0.1):
    """The discrete plant and channels of ``c2d(., 'tustin')`` of the generalised plant (with its ``D``)."""
    Pd = control.c2d(generalised(plant, **ch), dt, "tustin")
    nw, nz = ch["Bw"].shape[1], ch["Cz"].shape[0]
    A, B, C, D = Pd.A, Pd.B, Pd.C, Pd.D
    dplant = rc.Plant(A, B[:, nw:], dt, C=C[nz:], D=D[nz:, nw:])
    return dplant, dict(Bw=B[:, :nw], Cz=C[:nz], Dzu=D[:nz, nw:], Dzw=D[:nz, :nw], Dyw=D[nz:, :nw]), Pd


@pytest.mark.parametrize("n,seed", CASES[:2])
@pytest.mark.parametrize("synthesis", ["lmi", "riccati"])
def test_tustin_image_has_the_same_optimal_level(n, seed, synthesis):
    plant, ch = regular_case(n, seed)
    gam = control.hinfsyn(generalised(plant, **ch), plant.p, plant.m)[2]
    dplant, dch, Pd = tustin_image(plant, ch)
    assert np.any(dplant.D) and np.any(dch["Dzw"])           # the image has D22 and D11
    ctrl = rc.hinf(dplant, **dch, synthesis=synthesis)
    assert ctrl.gamma_opt == pytest.approx(gam, rel=RTOL)
    cl = loop(Pd, ctrl)
    assert_stable(cl)
    assert control.linfnorm(cl, tol=1e-10)[0] < ctrl.gamma


def lqg_current_estimate(A, B, C, Q, R, W, V):
    """``u = -K x(k|k)``: dlqr's ``K``, the filter gain from dlqe's a-priori covariance; ``(Ac, Bc, Cc, Dc)``."""
    K = control.dlqr(A, B, Q, R)[0]
    _, P, _ = control.dlqe(A, np.eye(A.shape[0]), C, W, V)
    L = P @ C.T @ np.linalg.inv(C @ P @ C.T + V)
    E = np.eye(A.shape[0]) - L @ C
    return (A - B @ K) @ E, (A - B @ K) @ L, -K @ E, -K @ L


@pytest.mark.parametrize("n,seed", [(3, 0), (5, 1)])
def test_discrete_h2_is_the_lqg_controller(n, seed):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    A *= 1.05 / np.max(np.abs(np.linalg.eigvals(A)))
    G, C = rng.normal(size=(n, 1)), rng.normal(size=(1, n))
    Q, R, W, V = np.eye(n), np.array([[0.3]]), 0.5 * np.eye(n), np.array([[0.2]])
    ch = dict(Bw=np.hstack([scipy.linalg.sqrtm(W), np.zeros((n, 1))]), Cz=np.vstack([np.eye(n), np.zeros((1, n))]),
              Dzu=np.vstack([np.zeros((n, 1)), np.sqrt(R)]), Dyw=np.hstack([np.zeros((1, n)), np.sqrt(V)]))
    plant = rc.Plant(A, G, 0.1, C=C)
    P = generalised(plant, **ch)
    ref = control.norm(P.lft(control.ss(*lqg_current_estimate(A, G, C, Q, R, W, V), 0.1)), 2)
    ctrl = rc.h2(plant, **ch)
    assert ctrl.h2_opt == pytest.approx(ref, rel=RTOL)
    cl = loop(P, ctrl)
    assert_stable(cl)
    assert control.norm(cl, 2) <= ctrl.h2_bound


def singular_case(n: int, seed: int):
    """No measurement noise (``Dyw = 0``): the problem is singular, as in many COMPleib plants."""
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n)) / np.sqrt(n)
    A += (0.1 - np.max(np.linalg.eigvals(A).real)) * np.eye(n)
    plant = rc.Plant(A, rng.normal(size=(n, 1)), None, C=rng.normal(size=(1, n)))
    ch = dict(Bw=rng.normal(size=(n, 2)), Cz=np.vstack([rng.normal(size=(2, n)), np.zeros((1, n))]),
              Dzu=np.array([[0.0], [0.0], [1.0]]))
    return plant, ch


def hinfsyn_regularised(plant, ch, eps: float) -> float:
    """hinfsyn with measurement noise ``eps`` added (an extra disturbance column)."""
    n = plant.n
    Bw = np.hstack([ch["Bw"], np.zeros((n, 1))])
    Dyw = np.hstack([np.zeros((1, ch["Bw"].shape[1])), [[eps]]])
    return control.hinfsyn(generalised(plant, Bw, ch["Cz"], ch["Dzu"], Dyw=Dyw), 1, 1)[2]


@pytest.mark.parametrize("n,seed", [(4, 0), (4, 1), (6, 2)])
def test_singular_problem_reaches_the_regularised_limit(n, seed):
    plant, ch = singular_case(n, seed)
    ref = hinfsyn_regularised(plant, ch, 1e-4)
    ctrl = rc.hinf(plant, **ch)
    assert abs(ctrl.gamma_opt / ref - 1) < 1e-2
    cl = loop(generalised(plant, **ch), ctrl)
    assert_stable(cl)
    assert control.linfnorm(cl, tol=1e-10)[0] < ctrl.gamma
    fast = rc.hinf(plant, **ch, synthesis="riccati")           # singular: the Riccati path falls back
    assert fast.info["synthesis"] == "lmi" and "singular" in fast.info["fallback"]
    assert fast.gamma_opt == pytest.approx(ctrl.gamma_opt, rel=1e-6)


def test_singular_control_weight():
    """``Dzu`` without full column rank (``z`` does not weigh ``u``): within 1 % of hinfsyn with ``u`` weighed 1e-4."""
    plant, ch = singular_case(4, 3)
    ch = dict(ch, Cz=ch["Cz"][:2], Dzu=np.zeros((2, 1)), Dyw=np.array([[0.0, 0.0, 0.5]]),
              Bw=np.hstack([ch["Bw"], np.zeros((4, 1))]))
    P = generalised(plant, ch["Bw"], np.vstack([ch["Cz"], np.zeros((1, 4))]), np.array([[0.0], [0.0], [1e-4]]),
                    Dyw=ch["Dyw"])
    ref = control.hinfsyn(P, 1, 1)[2]
    ctrl = rc.hinf(plant, **ch)
    assert abs(ctrl.gamma_opt / ref - 1) < 1e-2
    assert control.linfnorm(loop(generalised(plant, **ch), ctrl), tol=1e-10)[0] < ctrl.gamma


def test_pole_region():
    plant, ch = regular_case(4, 1)
    free = rc.hinf(plant, **ch)
    region = rc.HalfPlane(-0.8)
    ctrl = rc.hinf(plant, **ch, poles=region)
    poles = loop(generalised(plant, **ch), ctrl).poles()
    assert np.all(poles.real < -0.8)
    assert np.min(-np.linalg.eigvals(free.closed_loop()).real) < 0.8    # the region is active
    assert ctrl.gamma_opt >= free.gamma_opt * (1 - 1e-6)
    assert control.linfnorm(loop(generalised(plant, **ch), ctrl), tol=1e-10)[0] < ctrl.gamma


def test_fixed_level():
    plant, ch = regular_case(4, 1)
    opt = rc.hinf(plant, **ch).gamma_opt
    ctrl = rc.hinf(plant, **ch, gamma=1.2 * opt)
    assert ctrl.gamma == 1.2 * opt and ctrl.gamma_opt is None
    assert control.linfnorm(loop(generalised(plant, **ch), ctrl), tol=1e-10)[0] < ctrl.gamma
    with pytest.raises(InfeasibleError, match="gamma"):
        rc.hinf(plant, **ch, gamma=0.9 * opt)


def test_feedback_state_on_a_plant_with_outputs():
    plant, ch = regular_case(4, 1)
    state_plant = rc.Plant(plant.F, plant.G, None)
    ref = rc.hinf(state_plant, Bw=ch["Bw"], Cz=ch["Cz"], Dzu=ch["Dzu"])
    ctrl = rc.hinf(plant, Bw=ch["Bw"], Cz=ch["Cz"], Dzu=ch["Dzu"], feedback="state")
    assert ctrl.K is not None and ctrl.gamma_opt == pytest.approx(ref.gamma_opt, rel=1e-6)
    h2 = rc.h2(plant, Bw=ch["Bw"], Cz=ch["Cz"], Dzu=ch["Dzu"], feedback="state")
    assert h2.K is not None


def test_design_dispatches_output_feedback():
    plant, ch = regular_case(3, 0)
    ctrl = rc.design("hinf", plant, **ch, synthesis="riccati")
    assert isinstance(ctrl, rc.HinfController) and ctrl.is_dynamic
    assert rc.design("h2", plant, **ch).is_dynamic


# ---------------------------------------------------------------- bad input
@pytest.fixture
def case3():
    return regular_case(3, 0)


def test_dyw_shape_is_named(case3):
    plant, ch = case3
    with pytest.raises(ValueError, match=r"Dyw must have 2 rows.*got shape \(3, 4\)"):
        rc.hinf(plant, **dict(ch, Dyw=np.zeros((3, 4))))
    with pytest.raises(ValueError, match="Dyw"):
        rc.h2(plant, **dict(ch, Dyw=np.zeros((2, 3))))


def test_output_matrix_shape_is_named():
    with pytest.raises(ValueError, match="C"):
        rc.Plant(np.eye(3), np.ones((3, 1)), None, C=np.ones((1, 2)))


def test_output_feedback_needs_outputs():
    plant = rc.Plant(-np.eye(2), np.ones((2, 1)), None)
    with pytest.raises(ValueError, match="feedback='output'"):
        rc.hinf(plant, Bw=np.eye(2), Cz=np.eye(2), Dzu=np.zeros((2, 1)), feedback="output")
    with pytest.raises(ValueError, match="Dyw"):
        rc.hinf(plant, Bw=np.eye(2), Cz=np.eye(2), Dzu=np.zeros((2, 1)), Dyw=np.zeros((2, 2)))


def test_feedback_value_is_named(case3):
    plant, ch = case3
    with pytest.raises(ValueError, match="feedback"):
        rc.hinf(plant, **ch, feedback="dynamic")
    with pytest.raises(ValueError, match="Dyw"):
        rc.hinf(plant, **ch, feedback="state")


def test_not_stabilisable_or_detectable():
    A = np.diag([1.0, -1.0])
    ch = dict(Bw=np.eye(2), Cz=np.eye(2), Dzu=np.zeros((2, 1)), Dyw=np.ones((1, 2)))
    with pytest.raises(NotStabilizableError):
        rc.hinf(rc.Plant(A, [[0.0], [1.0]], None, C=[[1.0, 1.0]]), **ch)
    with pytest.raises(NotDetectableError):
        rc.hinf(rc.Plant(A, [[1.0], [1.0]], None, C=[[0.0, 1.0]]), **ch)
    with pytest.raises(NotDetectableError):
        rc.h2(rc.Plant(A, [[1.0], [1.0]], None, C=[[0.0, 1.0]]), **ch)


@pytest.mark.parametrize("option,value", [("vertices", "plant"), ("uncertainty", "nb"), ("u_max", 1.0),
                                          ("extended", True)])
def test_unsupported_options_are_named(case3, option, value):
    plant, ch = case3
    value = {"plant": [plant], "nb": rc.NormBounded(plant.G, np.eye(3), np.zeros((3, 2)))}.get(value, value)
    with pytest.raises(ValueError, match=f"{option} is not supported by the output-feedback synthesis"):
        rc.hinf(plant, **ch, **{option: value})


def test_riccati_path_refuses_poles_and_fixed_level(case3):
    plant, ch = case3
    with pytest.raises(ValueError, match="poles"):
        rc.hinf(plant, **ch, synthesis="riccati", poles=rc.HalfPlane(-1.0))
    with pytest.raises(ValueError, match="gamma"):
        rc.hinf(plant, **ch, synthesis="riccati", gamma=10.0)


def test_unreachable_region_names_the_mode():
    """A stable mode at -0.1 that the outputs do not see cannot be moved left of -0.5."""
    plant = rc.Plant(np.diag([0.5, -0.1]), [[1.0], [1.0]], None, C=[[1.0, 0.0]])
    with pytest.raises(InfeasibleError, match="not seen by the outputs"):
        rc.hinf(plant, Bw=np.eye(2), Cz=np.eye(2), Dzu=np.zeros((2, 1)), Dyw=[[0.0, 1.0]], poles=rc.HalfPlane(-0.5))


def test_continuous_h2_refuses_dzw_and_zero_backoff(case3):
    plant, ch = case3
    with pytest.raises(ValueError, match="Dzw must be zero"):
        rc.h2(plant, **ch, Dzw=np.ones((4, 4)))
    with pytest.raises(ValueError, match="backoff"):
        rc.hinf(plant, **ch, backoff=0.0)


def test_no_warnings_on_a_regular_problem(case3):
    plant, ch = case3
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rc.hinf(plant, **ch, synthesis="riccati")
