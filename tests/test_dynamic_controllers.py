"""Dynamic output feedback behind the common Controller interface (issue 33, item 4), against python-control."""

from __future__ import annotations

import control
import numpy as np
import pytest

import robustctl as rc
from robustctl.systems import interconnect

RNG = np.random.default_rng(7)


def _plant(dt=0.1, D=None):
    F = np.array([[1.05, 0.1, 0.0], [0.0, 0.9, 0.2], [0.1, 0.0, 0.7]])
    G = np.array([[0.0, 0.1], [1.0, 0.0], [0.0, 1.0]])
    C = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    if dt is None:
        F = F - np.eye(3)
    return rc.Plant(F, G, dt, C=C, D=D)


def _observer_controller(plant):
    """An LQG-like controller built by hand with python-control (u = K(z) y, our sign)."""
    Kx = -control.dlqr(plant.F, plant.G, np.eye(3), np.eye(2))[0]
    L = control.dlqe(plant.F, np.eye(3), plant.C, np.eye(3), np.eye(2))[0]   # predictor gain
    Ac = plant.F + plant.G @ Kx - L @ plant.C - L @ plant.D @ Kx
    return rc.Controller.dynamic(Ac, L, Kx, np.zeros((2, 2)), "observer", plant)


@pytest.mark.parametrize("D", [None, np.array([[0.0, 0.3], [0.2, 0.0]])])
def test_closed_loop_equals_python_controls_positive_feedback(D):
    plant = _plant(D=D)
    ctrl = _observer_controller(rc.Plant(plant.F, plant.G, 0.1, C=plant.C))
    ctrl = rc.Controller.dynamic(*(ctrl.Ac, ctrl.Bc, ctrl.Cc, 0.1 * RNG.standard_normal((2, 2))), "x", plant)
    ref = control.feedback(plant.to_statespace(), ctrl.controller_statespace(), sign=+1)
    np.testing.assert_allclose(np.sort_complex(ctrl.closed_loop_poles()), np.sort_complex(ref.poles()), atol=1e-10)
    ours = ctrl.to_statespace()
    # the closed loop from v (added at u) to x: compare frequency responses with python-control's
    # interconnection of the same loop (u = v + K y): inputs v, outputs x
    P = control.ss(plant.F, plant.G, np.vstack([plant.C, np.eye(3)]), np.vstack([plant.D, np.zeros((3, 2))]), 0.1)
    loop = control.feedback(P, control.ss(ctrl.Ac, np.hstack([ctrl.Bc, np.zeros((ctrl.order, 3))]), ctrl.Cc,
                                          np.hstack([ctrl.Dc, np.zeros((2, 3))]), 0.1), sign=+1)
    for z in np.exp(1j * np.array([0.1, 0.7, 2.0])):
        np.testing.assert_allclose(ours(z), loop(z)[2:], atol=1e-9)
    assert ctrl.is_stabilizing() == bool(np.all(np.abs(ref.poles()) < 1 - 1e-9))


def test_separation_principle_poles():
    plant = _plant()
    ctrl = _observer_controller(plant)
    Kx = ctrl.Cc
    L = control.dlqe(plant.F, np.eye(3), plant.C, np.eye(3), np.eye(2))[0]
    expected = np.concatenate([np.linalg.eigvals(plant.F + plant.G @ Kx), np.linalg.eigvals(plant.F - L @ plant.C)])
    np.testing.assert_allclose(np.sort_complex(ctrl.closed_loop_poles()), np.sort_complex(expected), atol=1e-10)
    assert ctrl.is_stabilizing() and ctrl.is_dynamic and ctrl.order == 3 and ctrl.K is None


def test_state_feedback_keeps_its_interface_on_a_plant_with_outputs():
    plant = _plant()
    K = -control.dlqr(plant.F, plant.G, np.eye(3), np.eye(2))[0]
    ctrl = rc.Controller(K, "lqr", plant)
    np.testing.assert_allclose(ctrl.closed_loop(), plant.F + plant.G @ K)
    assert not ctrl.is_dynamic and ctrl.order == 0
    np.testing.assert_allclose(ctrl.controller_statespace().D, K)
    np.testing.assert_allclose(ctrl([1.0, 0.0, 0.0]), K[:, 0])
    with pytest.raises(TypeError, match="dynamic controller has a state"):
        _observer_controller(plant)([1.0, 0.0, 0.0])


def test_loop_transfers_against_python_control_series():
    plant = _plant(D=np.array([[0.0, 0.3], [0.2, 0.0]]))
    base = _observer_controller(rc.Plant(plant.F, plant.G, 0.1, C=plant.C))
    ctrl = rc.Controller.dynamic(base.Ac, base.Bc, base.Cc, 0.05 * np.ones((2, 2)), "x", plant)
    P, K = plant.to_statespace(), ctrl.controller_statespace()
    for at, ref in (("input", -(K * P)), ("output", -(P * K))):
        A, B, C, D = interconnect.loop_transfer(plant.F, plant.G, plant.C, plant.D, *(M[None] for M in
                                                (ctrl.Ac, ctrl.Bc, ctrl.Cc, ctrl.Dc)), at=at)
        ours = control.ss(A[0], B[0], C[0], D[0], 0.1)
        for z in np.exp(1j * np.array([0.05, 0.5, 3.0])):
            np.testing.assert_allclose(ours(z), ref(z), atol=1e-10)
    with pytest.raises(ValueError, match="at must be 'input' or 'output'"):
        interconnect.loop_transfer(plant.F, plant.G, plant.C, plant.D, *(M[None] for M in
                                   (ctrl.Ac, ctrl.Bc, ctrl.Cc, ctrl.Dc)), at="middle")


def test_ill_posed_loop_is_flagged():
    plant = rc.Plant([[0.5]], [[1.0]], 0.1, C=[[1.0]], D=[[2.0]])
    bad = rc.Controller.dynamic([], [], [], [[0.5]], "x", plant)           # I - Dc D = 0
    assert not bad.is_stabilizing()
    batch = rc.ControllerBatch(plant, np.zeros((2, 0, 0)), np.zeros((2, 0, 1)), np.zeros((2, 1, 0)),
                               [[[0.5]], [[-0.1]]])
    loop = batch.closed_loop()
    assert loop.well_posed.tolist() == [False, True] and np.isnan(loop.A[0]).all()
    assert batch.is_stabilizing().tolist() == [False, True]
    with pytest.raises(ValueError, match="ill posed"):
        rc.robust_stability(bad, rc.NormBounded([[1.0]], [[0.1]], [[0.0]]))


def test_batch_equals_single_controllers():
    plant = _plant()
    ctrls = [rc.Controller.dynamic(0.5 * RNG.standard_normal((2, 2)), 0.1 * RNG.standard_normal((2, 2)),
                                   0.1 * RNG.standard_normal((2, 2)), 0.1 * RNG.standard_normal((2, 2)), "x", plant)
             for _ in range(4)]
    batch = rc.ControllerBatch(plant, *(np.stack([getattr(c, k) for c in ctrls]) for k in ("Ac", "Bc", "Cc", "Dc")))
    for b, c in enumerate(ctrls):
        np.testing.assert_array_equal(batch.closed_loops()[b], c.closed_loop())
        assert batch.is_stabilizing()[b] == c.is_stabilizing()
        np.testing.assert_array_equal(batch[b].Dc, c.Dc)
    assert len(batch) == 4 and batch.order == 2 and "B=4" in repr(batch)


def test_shapes_are_named():
    plant = _plant()
    with pytest.raises(ValueError, match=r"^Bc must have 2 rows \(the controller order, from Ac\)"):
        rc.Controller.dynamic(np.eye(2), np.ones((3, 2)), np.ones((2, 2)), np.ones((2, 2)), "x", plant)
    with pytest.raises(ValueError, match=r"^Dc must have 2 columns \(the number of outputs\)"):
        rc.Controller.dynamic(np.eye(2), np.ones((2, 2)), np.ones((2, 2)), np.ones((2, 3)), "x", plant)
    with pytest.raises(ValueError, match="not both"):
        rc.Controller(np.zeros((2, 3)), "x", plant, Ac=np.eye(1), Bc=np.ones((1, 2)), Cc=np.ones((2, 1)),
                      Dc=np.zeros((2, 2)))
    with pytest.raises(ValueError, match=r"^K must be a gain \(2, 3\) for a state feedback, or None with all of Ac"):
        rc.Controller(None, "x", plant, Ac=np.eye(1))
    with pytest.raises(ValueError, match=r"^Cc must have shape \(2, 2, 1\)"):
        rc.ControllerBatch(plant, np.zeros((2, 1, 1)), np.zeros((2, 1, 2)), np.zeros((2, 2, 2)), np.zeros((2, 2, 2)))


def test_from_gains_is_state_feedback_even_with_outputs():
    plant = _plant()
    K = np.stack([-control.dlqr(plant.F, plant.G, q * np.eye(3), np.eye(2))[0] for q in (1.0, 10.0)])
    batch = rc.ControllerBatch.from_gains(plant, K)
    assert not batch.plant.has_outputs and batch.order == 0
    np.testing.assert_allclose(batch.closed_loops(), plant.F + plant.G @ K, atol=1e-14)


def _reference_margin(plant, ctrl, unc):
    """1 / ||q <- p||_inf of the loop built with python-control's interconnect (p enters through H, q = EF x + EG u)."""
    K = ctrl.controller_statespace()
    Psys = control.ss(plant.F, np.hstack([plant.G, unc.H]), np.vstack([plant.C, unc.EF]),
                      np.block([[plant.D, np.zeros((2, 1))], [unc.EG, np.zeros((1, 1))]]), plant.dt,
                      inputs=["u0", "u1", "p"], outputs=["y0", "y1", "q"], name="P")
    Ksys = control.ss(K.A, K.B, K.C, K.D, plant.dt, inputs=["y0", "y1"], outputs=["u0", "u1"], name="K")
    T = control.interconnect([Psys, Ksys], inplist=["p"], outlist=["q"])     # u = K(z) y: no minus sign
    return 1.0 / control.linfnorm(T)[0]


def test_robust_stability_of_a_dynamic_controller_against_python_control():
    plant = _plant()
    ctrl = _observer_controller(plant)
    unc = rc.NormBounded([[1.0], [0.0], [0.0]], [[0.05, 0.0, 0.0]], [[0.02, 0.0]])
    res = rc.robust_stability(ctrl, unc)
    assert res.certified
    np.testing.assert_allclose(res.margin, _reference_margin(plant, ctrl, unc), rtol=1e-6)
    # a stack: ControllerBatch, equal to the single analyses
    other = rc.Controller.dynamic(ctrl.Ac, 0.8 * ctrl.Bc, ctrl.Cc, ctrl.Dc, "x", plant)
    batch = rc.ControllerBatch(plant, *(np.stack([getattr(c, k) for c in (ctrl, other)]) for k in
                                        ("Ac", "Bc", "Cc", "Dc")))
    stacked = rc.robust_stability(batch, unc)
    np.testing.assert_allclose(stacked.margin, [res.margin, rc.robust_stability(other, unc).margin], rtol=1e-8)


def test_static_output_feedback_equals_the_state_feedback_dc_c():
    plant = _plant()
    Dc = np.array([[-0.3, 0.0], [0.0, -0.2]])
    sof = rc.Controller.dynamic([], [], [], Dc, "sof", plant)
    unc = rc.NormBounded([[1.0], [0.0], [0.0]], [[0.01, 0.0, 0.0]], [[0.005, 0.0]])
    a, b = rc.robust_stability(sof, unc), rc.robust_stability((plant, Dc @ plant.C), unc)
    np.testing.assert_allclose(a.margin, b.margin, rtol=1e-10)
    Q, R = np.eye(3), np.eye(2)
    np.testing.assert_allclose(rc.guaranteed_cost(sof, unc, Q, R, x0=[1.0, 0, 0]).bound,
                               rc.guaranteed_cost((plant, Dc @ plant.C), unc, Q, R, x0=[1.0, 0, 0]).bound, rtol=1e-5)
    poly = rc.robust_stability(sof, vertices=[unc.perturb(plant, 1.0)])
    assert poly.certified == rc.robust_stability((plant, Dc @ plant.C), vertices=[unc.perturb(plant, 1.0)]).certified
    worst = rc.worst_case(sof, unc, seed=0)
    np.testing.assert_allclose(worst.radius, rc.worst_case((plant, Dc @ plant.C), unc, seed=0).radius, rtol=1e-8)


def test_margins_report_takes_a_dynamic_controller():
    plant = _plant()
    ctrl = _observer_controller(plant)
    unc = rc.NormBounded([[1.0], [0.0], [0.0]], [[0.05, 0.0, 0.0]], [[0.02, 0.0]])
    report = rc.margins_report(plant, {"observer": ctrl}, {"unc": unc})
    np.testing.assert_allclose(report.margin[0, 0], rc.robust_stability(ctrl, unc).margin, rtol=1e-12)
