"""LQG and robust LQG (issue 33 item 5) against python-control's lqr + lqe and the estimator's own recursion."""

from __future__ import annotations

import control
import numpy as np
import pytest

import robustctl as rc

F = np.array([[1.02, 0.1, 0.0], [0.0, 0.95, 0.1], [0.0, 0.0, 0.9]])
G = np.array([[0.0], [0.05], [0.1]])
C = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
W, V = np.diag([1e-3, 1e-3, 2e-3]), np.diag([1e-2, 2e-2])
Q, R = np.diag([1.0, 0.1, 0.1]), np.array([[0.5]])


def _plant(D=None):
    return rc.Plant(F, G, 0.1, C=C, D=D, Bw=np.eye(3))


def test_predictor_lqg_is_python_controls_lqr_and_lqe_assembled():
    plant = _plant()
    ctrl = rc.lqg(plant, Q=Q, R=R, W=W, V=V, form="predictor")
    K = -control.dlqr(F, G, Q, R)[0]
    Lp = control.dlqe(F, np.eye(3), C, W, V)[0]
    np.testing.assert_allclose(ctrl.Ac, F + G @ K - Lp @ C, atol=1e-10)
    np.testing.assert_allclose(ctrl.Bc, Lp, atol=1e-10)
    np.testing.assert_allclose(ctrl.Cc, K, atol=1e-10)
    np.testing.assert_array_equal(ctrl.Dc, 0.0)
    poles = np.concatenate([np.linalg.eigvals(F + G @ K), np.linalg.eigvals(F - Lp @ C)])   # separation
    np.testing.assert_allclose(np.sort_complex(ctrl.closed_loop_poles()), np.sort_complex(poles), atol=1e-9)


def test_filter_lqg_separation_and_the_current_estimator():
    plant = _plant()
    ctrl = rc.lqg(plant, Q=Q, R=R, W=W, V=V)
    K = -control.dlqr(F, G, Q, R)[0]
    Lp, P, _ = control.dlqe(F, np.eye(3), C, W, V)
    Lf = P @ C.T @ np.linalg.inv(C @ P @ C.T + V)
    np.testing.assert_allclose(ctrl.Dc, K @ Lf, atol=1e-10)                  # u = K x[k|k] uses y[k]
    np.testing.assert_allclose(ctrl.Ac, (F + G @ K) @ (np.eye(3) - Lf @ C), atol=1e-10)
    poles = np.concatenate([np.linalg.eigvals(F + G @ K), np.linalg.eigvals(F - Lp @ C)])
    np.testing.assert_allclose(np.sort_complex(ctrl.closed_loop_poles()), np.sort_complex(poles), atol=1e-9)


@pytest.mark.parametrize("form", ["filter", "predictor"])
def test_controller_runs_the_estimators_own_recursion_with_a_feedthrough(form):
    """u = K xhat with the estimator's step, simulated by hand, equals the controller's state-space (D != 0)."""
    plant = _plant(D=np.array([[0.2], [0.0]]))
    ctrl = rc.lqg(plant, Q=Q, R=R, W=W, V=V, form=form)
    est, K = ctrl.info["estimator"], ctrl.info["K"]
    rng = np.random.default_rng(1)
    x, xhat, xc = rng.standard_normal(3), np.zeros(3), np.zeros(3)
    w, v = rng.standard_normal((40, 3)) * 0.03, rng.standard_normal((40, 2)) * 0.1
    for k in range(40):
        # the estimator's own loop: u = K (xhat + Lf (y - C xhat - D u)) with y = C x + D u + v
        if form == "filter":   # y - D u does not depend on u: the plant's loop has no algebraic loop
            u = K @ (xhat + est.L_filter @ (plant.C @ x + v[k] - plant.C @ xhat))
        else:
            u = K @ xhat
        y = plant.C @ x + plant.D @ u + v[k]
        xhat_next, x_used = est.step(xhat, u, y)
        np.testing.assert_allclose(u, K @ x_used, atol=1e-12)
        u_ctrl = ctrl.Cc @ xc + ctrl.Dc @ y                       # the controller state-space
        np.testing.assert_allclose(u_ctrl, u, atol=1e-10)
        xc = ctrl.Ac @ xc + ctrl.Bc @ y
        xhat = xhat_next
        np.testing.assert_allclose(xc, xhat, atol=1e-10)
        x = F @ x + G @ u + w[k]


def test_continuous_lqg_against_python_control():
    A, B = np.array([[0.0, 1.0], [0.0, -0.1]]), np.array([[0.0], [1.0]])
    plant = rc.Plant(A, B, None, C=[[1.0, 0.0]], Bw=np.eye(2))
    ctrl = rc.design("lqg", plant, Q=np.eye(2), R=[[0.3]], W=np.eye(2), V=[[0.05]])
    K = -control.lqr(A, B, np.eye(2), [[0.3]])[0]
    L = control.lqe(A, np.eye(2), plant.C, np.eye(2), [[0.05]])[0]
    ref = control.feedback(plant.to_statespace(), control.ss(A + B @ K - L @ plant.C, L, K, 0), sign=+1)
    np.testing.assert_allclose(np.sort_complex(ctrl.closed_loop_poles()), np.sort_complex(ref.poles()), atol=1e-9)
    assert ctrl.is_stabilizing() and ctrl.method == "lqg"


def test_robust_lqg_without_uncertainty_is_the_lqg_and_with_it_is_certified():
    plant = _plant()
    zero = rc.rlqg(plant, [[0.0, 0.0, 0.0]], [[0.0]], 1e12, Q=Q, R=R, H=np.zeros((3, 1)), W=W, V=V)
    lqg = rc.lqg(plant, Q=Q, R=R, W=W, V=V)
    for M in ("Ac", "Bc", "Cc", "Dc"):
        np.testing.assert_allclose(getattr(zero, M), getattr(lqg, M), atol=1e-7)
    H, EF, EG = np.array([[0.0], [1.0], [0.0]]), np.array([[0.0, 0.05, 0.0]]), np.array([[0.02]])
    ctrl = rc.design("rlqg", plant, EF, EG, 1e4, Q=Q, R=R, H=H, W=W, V=V)
    assert ctrl.method == "rlqg" and ctrl.is_stabilizing()
    # its parts are the robust LQR and the robust filter of the same uncertainty and mu
    np.testing.assert_array_equal(ctrl.info["K"], rc.rlqr(plant, EF, EG, 1e4, Q=Q, R=R, H=H).K)
    np.testing.assert_array_equal(ctrl.info["estimator"].L, rc.robust_kalman(plant, W, V, H=H, EF=EF, EG=EG, mu=1e4).L)
    # at mu = 1e6 the filter's pseudo-measurement EF x + EG u = 0 destabilises the loop: said, not returned
    with pytest.raises(rc.NotStabilizingError, match="use a smaller mu_filter"):
        rc.rlqg(plant, EF, EG, 1e6, Q=Q, R=R, H=H, W=W, V=V)
    ok = rc.rlqg(plant, EF, EG, 1e6, Q=Q, R=R, H=H, W=W, V=V, mu_filter=1e2)
    assert ok.is_stabilizing()
    assert not rc.rlqg(plant, EF, EG, 1e6, Q=Q, R=R, H=H, W=W, V=V, check_stability=False).is_stabilizing()


def test_observer_controller_refuses_bad_input():
    plant = _plant()
    est = rc.kalman(plant, W, V)
    with pytest.raises(TypeError, match="estimator must be"):
        rc.observer_controller(np.zeros((1, 3)), "kalman")
    with pytest.raises(ValueError, match=r"^K must have 3 columns"):
        rc.observer_controller(np.zeros((1, 2)), est)
    with pytest.raises(ValueError, match=r"C"):
        rc.lqg(rc.Plant(F, G, 0.1), W=W, V=V)               # no outputs: the filter names C
