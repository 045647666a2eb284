"""Closed-loop simulator: exact cases, python-control forced_response, saturation, divergence, batching."""

import time
import warnings

import control
import numpy as np
import pytest

import robustctl as rc
from robustctl.models import truck
from robustctl.path import Curve, ReferencePath, Straight, default_route
from robustctl.simulate import simulate, simulate_linear

Q = np.diag([1 / 0.5**2, 1 / 0.1**2, 1 / 0.25**2, 1 / 0.05**2])
R = np.array([[1 / 0.1**2]])


@pytest.fixture(scope="module")
def K_lqr():
    return rc.design("lqr", truck.truck_plant(0.0), Q=Q, R=R).K


def test_zero_controller_straight_path_keeps_zero_error():
    path = ReferencePath.straight(50.0)
    res = simulate(np.zeros((1, 4)), path, [0.0, 300.0], x0=np.zeros(4))
    assert res.errors.shape == (1, 2, 500, 4)
    np.testing.assert_array_equal(res.errors, 0.0)
    np.testing.assert_array_equal(res.steering, 0.0)
    np.testing.assert_array_equal(res.mse(), 0.0)


def test_feedforward_holds_nominal_plant_on_an_arc():
    """Steady cornering is an equilibrium of the ZOH model: zero error with K = 0 on a constant arc."""
    path = ReferencePath.from_curvature(np.full(300, 1 / 250))
    res = simulate(np.zeros((1, 4)), path, 0.0, x0=np.zeros(4))
    np.testing.assert_allclose(res.errors, 0.0, atol=1e-10)
    x_ss, a_ss = truck.steady_state_cornering(0.0)
    np.testing.assert_allclose(res.steering, a_ss / 250, rtol=1e-12)
    # a heavier truck with the nominal feedforward drifts off the path (more understeer)
    heavy = simulate(np.zeros((1, 4)), path, 100.0, x0=np.zeros(4))
    assert heavy.errors[0, 0, -1, 2] < -1.0


def test_open_loop_matches_forced_response():
    """K = 0: alpha = alpha_ff; compare with python-control on x+ = F x + [G Gk] [alpha; kappa]."""
    path = ReferencePath.from_segments([Straight(30.0), Curve(200.0, 20.0, 40.0), Straight(30.0)])
    x0 = np.array([0.1, -0.02, 0.5, 0.01])
    ov = 150.0
    res = simulate(np.zeros((1, 4)), path, ov, x0=x0, steer_limit=None)
    F, G, Gk = truck.discretise(ov)
    sys = control.ss(F[0], np.column_stack([G[0], Gk[0]]), np.eye(4), 0, 0.1)
    x_ref, a_ff = truck.reference_states(path.kappa, 0.0)
    U = np.vstack([a_ff, path.kappa])
    resp = control.forced_response(sys, T=path.t, U=U, X0=x0 + x_ref[0])
    np.testing.assert_allclose(res.states[0, 0], resp.states.T, rtol=1e-10, atol=1e-12)


def test_linear_closed_loop_matches_matrix_powers(K_lqr):
    """No saturation, straight path: e[k] = (F + G K)^k e[0]."""
    path = ReferencePath.straight(20.0)
    e0 = np.array([0.2, 0.01, 1.0, 0.02])
    res = simulate(K_lqr, path, 200.0, x0=e0, steer_limit=None)
    F, G, _ = truck.discretise(200.0)
    Acl = F[0] + G[0] @ K_lqr
    expect = np.stack([np.linalg.matrix_power(Acl, k) @ e0 for k in range(path.T)])
    np.testing.assert_allclose(res.errors[0, 0], expect, rtol=1e-9, atol=1e-13)
    np.testing.assert_allclose(res.steering[0, 0], expect @ K_lqr[0], rtol=1e-9, atol=1e-13)


def test_mse_order_is_f1_to_f4(K_lqr):
    res = simulate(K_lqr, default_route(duration=60.0), [0.0, 300.0])
    e = res.errors
    manual = np.mean(e**2, axis=2)[..., [2, 1, 0, 3]]       # rho, psidot, ydot, theta
    np.testing.assert_allclose(res.mse(), manual, rtol=1e-12)
    assert res.mse().shape == (1, 2, 4)


def test_saturation_never_exceeded(K_lqr):
    path = default_route(duration=60.0)
    K = np.stack([K_lqr * 20, K_lqr])
    res = simulate(K, path, [0.0, 300.0], x0=[0, 0, 3.0, 0.1])
    assert np.max(np.abs(res.steering)) <= 0.45
    assert res.saturated_steps[0].min() > 0                 # the aggressive gain does saturate
    np.testing.assert_array_equal(np.abs(res.steering[res.steering != 0]).max() <= 0.45, True)
    res2 = simulate(K, path, 0.0, x0=[0, 0, 3.0, 0.1], steer_limit=0.1)
    assert np.max(np.abs(res2.steering)) <= 0.1 + 1e-15


def test_doubled_column_equals_single(K_lqr):
    path = default_route(duration=40.0)
    single = simulate(K_lqr, path, [0.0, 100.0])
    split = np.array([[0.3, 0.7]]).T * K_lqr               # u1 + u2 = K x
    doubled = simulate(split, path, [0.0, 100.0], input_map=truck.DOUBLED_INPUT_MAP)
    np.testing.assert_allclose(doubled.errors, single.errors, rtol=1e-10, atol=1e-14)


def test_batch_equals_individual_runs(K_lqr):
    rng = np.random.default_rng(1)
    Ks = K_lqr[None] * (1 + 0.2 * rng.standard_normal((5, 1, 4)))
    path = default_route(duration=30.0)
    batch = simulate(Ks, path, [0.0, 200.0])
    for b in range(5):
        for s, ov in enumerate([0.0, 200.0]):
            one = simulate(Ks[b], path, ov)
            np.testing.assert_allclose(batch.errors[b, s], one.errors[0, 0], rtol=1e-10, atol=1e-13)
    lean = simulate(Ks, path, [0.0, 200.0], keep_trajectories=False)
    assert lean.errors is None
    np.testing.assert_allclose(lean.mse(), batch.mse(), rtol=1e-12)


def test_time_varying_payload(K_lqr):
    path = default_route(duration=40.0)
    const = simulate(K_lqr, path, [100.0])
    as_profile = simulate(K_lqr, path, [np.full(path.T, 100.0)])
    np.testing.assert_allclose(as_profile.errors, const.errors, rtol=1e-12, atol=1e-15)
    # unloading at t = 20 s equals a run at 300 % continued from its state at 20 s with 0 %
    prof = np.where(path.t < 20.0, 300.0, 0.0)
    tv = simulate(K_lqr, path, [prof])
    first = simulate(K_lqr, path, [300.0])
    np.testing.assert_allclose(tv.errors[0, 0, :201], first.errors[0, 0, :201], rtol=1e-12, atol=1e-15)
    assert not np.allclose(tv.errors[0, 0, 220:], first.errors[0, 0, 220:])


def test_divergence_is_flagged_without_warnings():
    path = ReferencePath.straight(100.0)
    K_bad = np.array([[5.0, 0.0, 5.0, 0.0]])                 # positive feedback: unstable
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = simulate(K_bad, path, 0.0, steer_limit=None, bound=1e3)
        res_sat = simulate(K_bad, path, 0.0)                  # saturated: drifts away polynomially
    for r in (res, res_sat):
        assert r.diverged[0, 0]
        assert 0 < r.diverged_step[0, 0] < path.T
        mse = r.mse()
        assert np.all(np.isfinite(mse)) and np.all(mse <= 1e6)
        assert np.all(np.isfinite(r.errors)) and np.max(np.abs(r.errors)) <= 1e3
        k = r.diverged_step[0, 0]
        np.testing.assert_array_equal(np.abs(r.errors[0, 0, k:]), 1e3)    # every component at the bound
        assert np.all(mse >= (path.T - k) / path.T * 1e6)
    # earlier divergence -> larger error; the stable run is not flagged
    assert res.diverged_step[0, 0] < res_sat.diverged_step[0, 0]
    ok = simulate(np.zeros((1, 4)), path, 0.0, x0=np.zeros(4))
    assert not ok.diverged.any() and ok.diverged_step[0, 0] == -1


def test_pose_on_a_straight():
    path = ReferencePath.straight(5.0)
    res = simulate(np.zeros((1, 4)), path, 0.0, x0=[0, 0, 1.0, 0])
    X, Y, h = res.pose()
    np.testing.assert_allclose(Y[0, 0], res.states[0, 0, :, 2])
    np.testing.assert_allclose(X[0, 0], path.X)


def test_simulate_linear_generic():
    """A scalar integrator with a unit step reference: e+ = e + g u, u = -k e."""
    res = simulate_linear(np.array([[-0.5]]), np.array([[1.0]]), np.array([[1.0]]),
                          np.ones((10, 1)), x0=[-1.0])
    np.testing.assert_allclose(res.errors[0, 0, :, 0], -(0.5 ** np.arange(10)))


def test_population_speed(K_lqr):
    """92 gains x 2 payloads x 5000 steps: one array recursion (about 0.2-0.3 s on a free core)."""
    rng = np.random.default_rng(0)
    K = K_lqr[None] * (1 + 0.1 * rng.standard_normal((92, 1, 4)))
    K2 = np.concatenate([K / 2, K / 2], axis=1)
    path = default_route(duration=500.0)
    t0 = time.perf_counter()
    res = simulate(K2, path, [0.0, 100.0], keep_trajectories=False, input_map=[[1.0, 1.0]])
    elapsed = time.perf_counter() - t0
    assert res.mse().shape == (92, 2, 4)
    assert elapsed < 5.0          # generous: the CI machine is shared


def test_bad_inputs(K_lqr):
    path = ReferencePath.straight(2.0)
    with pytest.raises(ValueError, match="K must have 4 columns"):
        simulate(np.zeros((1, 3)), path)
    with pytest.raises(ValueError, match=r"\(B, m, n\)"):
        simulate(np.zeros(4), path)
    with pytest.raises(ValueError, match="overload"):
        simulate(K_lqr, path, -10.0)
    with pytest.raises(ValueError, match=r"overloads\[1\]"):
        simulate(K_lqr, path, [0.0, -5.0])
    with pytest.raises(ValueError, match=r"overloads\[0\].*shape \(20,\)"):
        simulate(K_lqr, path, [np.zeros(7)])
    with pytest.raises(TypeError, match="path"):
        simulate(K_lqr, np.zeros(10))
    with pytest.raises(ValueError, match="speed"):
        simulate(K_lqr, ReferencePath.straight(2.0, speed=20.0))
    with pytest.raises(ValueError, match="x0"):
        simulate(K_lqr, path, x0=[0, 0, 1])
    with pytest.raises(ValueError, match="K has 2 inputs"):
        simulate_linear(np.zeros((2, 4)), np.eye(4), np.ones((4, 1)), np.zeros((5, 4)))
    with pytest.raises(ValueError, match="u_limit"):
        simulate_linear(np.zeros((1, 4)), np.eye(4), np.ones((4, 1)), np.zeros((5, 4)), u_limit=-1.0)
    with pytest.raises(ValueError, match="u_limit"):
        simulate_linear(np.zeros((1, 4)), np.eye(4), np.ones((4, 1)), np.zeros((5, 4)), u_limit=[1.0, 2.0])
    with pytest.raises(ValueError, match="u_limit"):
        simulate_linear(np.zeros((1, 4)), np.eye(4), np.ones((4, 1)), np.zeros((5, 4)), u_limit="big")
    with pytest.raises(ValueError, match="F"):
        simulate_linear(np.zeros((1, 4)), np.eye(3), np.ones((4, 1)), np.zeros((5, 4)))


def test_mse_regulation_target(K_lqr):
    res = simulate(K_lqr, default_route(duration=60.0), [0.0, 300.0])
    x = res.states
    np.testing.assert_allclose(res.mse("zero"), np.mean(x**2, axis=2)[..., [2, 1, 0, 3]], rtol=1e-12)
    np.testing.assert_allclose(res.mse("zero")[..., 0], res.mse()[..., 0], rtol=1e-12)   # rho_ref = 0
    lean = simulate(K_lqr, default_route(duration=60.0), [0.0, 300.0], keep_trajectories=False)
    np.testing.assert_allclose(lean.mse("zero"), res.mse("zero"), rtol=1e-12)
    with pytest.raises(ValueError, match="target"):
        res.mse("path")


def test_integrated_pose_agrees_with_path_frame(K_lqr):
    """Dead reckoning from the body velocities stays within a few cm of the path-frame pose."""
    path = ReferencePath.from_segments([Straight(100.0), Curve(250.0, 60.0, 60.0), Straight(100.0)])
    res = simulate(K_lqr, path, [0.0, 300.0])
    Xp, Yp, hp = res.pose()
    Xi, Yi, hi = res.pose("integrated")
    assert np.max(np.hypot(Xp - Xi, Yp - Yi)) < 0.3          # over 460 m of road
    assert np.max(np.abs(hp - hi)) < 1e-2
    np.testing.assert_allclose(Xi[..., 0], Xp[..., 0])
    with pytest.raises(ValueError, match="method"):
        res.pose("gps")


def test_nan_gains_flagged_or_rejected(K_lqr):
    path = ReferencePath.straight(10.0)
    K = np.stack([K_lqr, np.full((1, 4), np.nan)])
    with pytest.raises(ValueError, match="finite"):
        simulate(K, path)
    res = simulate(K, path, [0.0, 100.0], nan_gains="flag", bound=50.0)
    assert res.diverged.tolist() == [[False, False], [True, True]]
    assert np.all(res.diverged_step[1] == 0)
    np.testing.assert_allclose(res.mse()[1], 50.0**2)
    ok = simulate(K_lqr, path, [0.0, 100.0])
    np.testing.assert_allclose(res.mse()[0], ok.mse()[0], rtol=1e-12)
