"""Closed-loop simulator: exact cases, python-control forced_response, saturation, divergence, batching.

The reference tests run on both backends (the compiled kernel and the numpy
reference); the kernel is also compared with the numpy path directly, and its
compilation cache is checked in spawned and fresh processes.
"""

import json
import os
import shutil
import subprocess
import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path

import control
import numpy as np
import pytest

import robustctl as rc
from robustctl.models import truck
from robustctl.models.path import Curve, ReferencePath, Straight, default_route
from robustctl.models.pathfollow import PathFollowing, simulate
from robustctl.sim.simulator import LinearSimulator, SimulationResult, simulate_linear

Q = np.diag([1 / 0.5**2, 1 / 0.1**2, 1 / 0.25**2, 1 / 0.05**2])
R = np.array([[1 / 0.1**2]])


@pytest.fixture(scope="module")
def K_lqr():
    return rc.design("lqr", truck.truck_plant(0.0), Q=Q, R=R).K


@pytest.fixture(params=["numba", "numpy"])
def backend(request):
    return request.param


def test_zero_controller_straight_path_keeps_zero_error(backend):
    path = ReferencePath.straight(50.0)
    res = simulate(np.zeros((1, 4)), path, [0.0, 300.0], x0=np.zeros(4), backend=backend)
    assert res.errors.shape == (1, 2, 500, 4)
    np.testing.assert_array_equal(res.errors, 0.0)
    np.testing.assert_array_equal(res.steering, 0.0)
    np.testing.assert_array_equal(res.mse(), 0.0)


def test_feedforward_holds_nominal_plant_on_an_arc(backend):
    """Steady cornering is an equilibrium of the ZOH model: zero error with K = 0 on a constant arc."""
    path = ReferencePath.from_curvature(np.full(300, 1 / 250))
    res = simulate(np.zeros((1, 4)), path, 0.0, x0=np.zeros(4), backend=backend)
    np.testing.assert_allclose(res.errors, 0.0, atol=1e-10)
    _x_ss, a_ss = truck.steady_state_cornering(0.0)
    np.testing.assert_allclose(res.steering, a_ss / 250, rtol=1e-12)
    # a heavier truck with the nominal feedforward drifts off the path (more understeer)
    heavy = simulate(np.zeros((1, 4)), path, 100.0, x0=np.zeros(4), backend=backend)
    assert heavy.errors[0, 0, -1, 2] < -1.0


def test_open_loop_matches_forced_response(backend):
    """K = 0: alpha = alpha_ff; compare with python-control on x+ = F x + [G Gk] [alpha; kappa]."""
    path = ReferencePath.from_segments([Straight(30.0), Curve(200.0, 20.0, 40.0), Straight(30.0)])
    x0 = np.array([0.1, -0.02, 0.5, 0.01])
    ov = 150.0
    res = simulate(np.zeros((1, 4)), path, ov, x0=x0, steer_limit=None, backend=backend)
    F, G, Gk = truck.discretise(ov)
    sys = control.ss(F[0], np.column_stack([G[0], Gk[0]]), np.eye(4), 0, 0.1)
    x_ref, a_ff = truck.reference_states(path.kappa, 0.0)
    U = np.vstack([a_ff, path.kappa])
    resp = control.forced_response(sys, T=path.t, U=U, X0=x0 + x_ref[0])
    np.testing.assert_allclose(res.states[0, 0], resp.states.T, rtol=1e-10, atol=1e-12)


def test_linear_closed_loop_matches_matrix_powers(K_lqr, backend):
    """No saturation, straight path: e[k] = (F + G K)^k e[0]."""
    path = ReferencePath.straight(20.0)
    e0 = np.array([0.2, 0.01, 1.0, 0.02])
    res = simulate(K_lqr, path, 200.0, x0=e0, steer_limit=None, backend=backend)
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


def test_saturation_never_exceeded(K_lqr, backend):
    path = default_route(duration=60.0)
    K = np.stack([K_lqr * 20, K_lqr])
    res = simulate(K, path, [0.0, 300.0], x0=[0, 0, 3.0, 0.1], backend=backend)
    assert np.max(np.abs(res.steering)) <= 0.45
    assert res.saturated_steps[0].min() > 0                 # the aggressive gain does saturate
    np.testing.assert_array_equal(np.abs(res.steering[res.steering != 0]).max() <= 0.45, True)
    res2 = simulate(K, path, 0.0, x0=[0, 0, 3.0, 0.1], steer_limit=0.1, backend=backend)
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


def test_time_varying_payload(K_lqr, backend):
    path = default_route(duration=40.0)
    const = simulate(K_lqr, path, [100.0], backend=backend)
    as_profile = simulate(K_lqr, path, [np.full(path.T, 100.0)], backend=backend)
    np.testing.assert_allclose(as_profile.errors, const.errors, rtol=1e-12, atol=1e-15)
    # unloading at t = 20 s equals a run at 300 % continued from its state at 20 s with 0 %
    prof = np.where(path.t < 20.0, 300.0, 0.0)
    tv = simulate(K_lqr, path, [prof], backend=backend)
    first = simulate(K_lqr, path, [300.0], backend=backend)
    np.testing.assert_allclose(tv.errors[0, 0, :201], first.errors[0, 0, :201], rtol=1e-12, atol=1e-15)
    assert not np.allclose(tv.errors[0, 0, 220:], first.errors[0, 0, 220:])


def test_divergence_is_flagged_without_warnings(backend):
    path = ReferencePath.straight(100.0)
    K_bad = np.array([[5.0, 0.0, 5.0, 0.0]])                 # positive feedback: unstable
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = simulate(K_bad, path, 0.0, steer_limit=None, bound=1e3, backend=backend)
        res_sat = simulate(K_bad, path, 0.0, backend=backend)                  # saturated: drifts away polynomially
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
    X, Y, _h = res.pose()
    np.testing.assert_allclose(Y[0, 0], res.states[0, 0, :, 2])
    np.testing.assert_allclose(X[0, 0], path.X)


def test_simulate_linear_generic(backend):
    """A scalar integrator with a unit step reference: e+ = e + g u, u = -k e."""
    res = simulate_linear(np.array([[-0.5]]), np.array([[1.0]]), np.array([[1.0]]),
                          np.ones((10, 1)), x0=[-1.0], backend=backend)
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


def test_nan_gains_flagged_or_rejected(K_lqr, backend):
    path = ReferencePath.straight(10.0)
    K = np.stack([K_lqr, np.full((1, 4), np.nan)])
    with pytest.raises(ValueError, match="finite"):
        simulate(K, path)
    res = simulate(K, path, [0.0, 100.0], nan_gains="flag", bound=50.0, backend=backend)
    assert res.diverged.tolist() == [[False, False], [True, True]]
    assert np.all(res.diverged_step[1] == 0)
    np.testing.assert_allclose(res.mse()[1], 50.0**2)
    ok = simulate(K_lqr, path, [0.0, 100.0], backend=backend)
    np.testing.assert_allclose(res.mse()[0], ok.mse()[0], rtol=1e-12)


# -- the compiled kernel against the numpy reference ---------------------------------------
def _applied_population(n, seed):
    """Stable RLQR gains of random applied-MOP designs (doubled column) and the MOP's simulator."""
    from moo.problems.applied import AppliedRLQRProblem

    prob = AppliedRLQRProblem()
    Z = np.random.default_rng(seed).uniform(prob.xl, prob.xu, (n, prob.n_var))
    batch = prob.gains(Z)
    K = batch.K[batch.ok]
    K = K[prob.closed_loop_radius(K).max(axis=1) < 1.0]
    return K, prob._sim


@pytest.fixture(scope="module")
def population():
    K, sim = _applied_population(400, seed=5)
    return K, sim, sim.run(K, keep_trajectories=False), sim.run(K, keep_trajectories=False, backend="numpy")


def test_kernel_equals_numpy_on_unsaturated_designs(population):
    """Designs saturated in under 1 % of the steps: sums, flags and trajectories agree to 1e-12."""
    K, sim, fast, ref = population
    calm = (ref.saturated_steps.max(axis=1) < 0.01 * sim.T) & ~ref.diverged.any(axis=1)
    assert calm.sum() > 300
    np.testing.assert_allclose(fast.sq_error_sum[calm], ref.sq_error_sum[calm], rtol=1e-12, atol=0)
    np.testing.assert_allclose(fast.sq_state_sum[calm], ref.sq_state_sum[calm], rtol=1e-12, atol=0)
    np.testing.assert_array_equal(fast.saturated_steps, ref.saturated_steps)
    some = K[calm][:12]
    a = sim.run(some)
    b = sim.run(some, backend="numpy")
    scale = np.abs(b.errors).max(axis=2, keepdims=True)               # per design, scenario and state
    assert np.max(np.abs(a.errors - b.errors) / scale) < 1e-12
    assert np.max(np.abs(a.steering - b.steering)) < 1e-12 * np.abs(b.steering).max()


def test_kernel_on_saturated_designs_is_bounded_and_close_to_numpy(population):
    """Designs at the steering limit in most steps are chaotic: a rounding difference can flip a
    saturation decision and move the rest of the run. The guarantees there are the invariants
    (finite, within the limit and the bound, frozen exactly at +-bound after divergence) and the
    flags; on this seeded sample the MSEs also agree to 1e-6 relative (measured: 2e-8; the numpy
    path itself moves by 1e-7 between a lone run and a batched one)."""
    K, sim, fast, ref = population
    wild = ref.saturated_steps.max(axis=1) > 0.9 * sim.T
    assert wild.sum() >= 5 and ref.diverged[wild].any()
    np.testing.assert_array_equal(fast.diverged_step, ref.diverged_step)
    np.testing.assert_allclose(fast.mse()[wild], ref.mse()[wild], rtol=1e-6)
    res = sim.run(K[wild])
    assert np.all(np.isfinite(res.errors)) and np.all(np.isfinite(res.steering))
    assert np.max(np.abs(res.steering)) <= truck.STEER_LIMIT
    assert np.max(np.abs(res.errors)) <= 1e3 and np.all(res.mse() <= 1e6)
    for b, s in zip(*np.nonzero(res.diverged), strict=True):
        np.testing.assert_array_equal(np.abs(res.errors[b, s, res.diverged_step[b, s]:]), 1e3)
    assert np.all(res.saturated_steps <= sim.T)


def test_kernel_result_does_not_depend_on_the_batch(population):
    """Each design is computed alone: bit-identical in any batch size or order."""
    K, sim, fast, _ = population
    idx = np.random.default_rng(3).permutation(K.shape[0])[:150]      # > MAX_BLOCK: two blocks
    shuffled = sim.run(K[idx], keep_trajectories=False)
    np.testing.assert_array_equal(shuffled.sq_error_sum, fast.sq_error_sum[idx])
    np.testing.assert_array_equal(shuffled.diverged_step, fast.diverged_step[idx])
    alone = sim.run(K[idx[0]], keep_trajectories=False)
    np.testing.assert_array_equal(alone.sq_error_sum[0], fast.sq_error_sum[idx[0]])
    kept = sim.run(K[idx[:3]])                                       # trajectories or not: same sums
    np.testing.assert_array_equal(kept.sq_error_sum, fast.sq_error_sum[idx[:3]])
    np.testing.assert_allclose(np.sum(kept.errors**2, axis=2), kept.sq_error_sum, rtol=1e-13)


def test_kernel_general_shapes_match_numpy():
    """Two plant inputs with an input map, per-scenario time-varying plants, per-scenario
    references, feedforward and disturbances, per-scenario initial errors, a saturation
    that is sometimes active, a flagged NaN gain and a divergent gain."""
    rng = np.random.default_rng(11)
    n, p, m, S, T, B = 3, 2, 3, 4, 60, 7
    F = 0.6 * np.eye(n) + 0.15 * rng.standard_normal((S, T, n, n))
    F[0] *= 1.6                                                         # scenario 0: some runs diverge
    G = rng.standard_normal((S, n, p))
    M = rng.standard_normal((p, m))
    K = -0.2 * rng.standard_normal((B, m, n))
    K[3] = np.nan
    kw = dict(u_ff=0.1 * rng.standard_normal((S, T, p)), w=0.05 * rng.standard_normal((T, n)),
              x0=rng.standard_normal((S, n)), u_limit=[0.8, 1.5], input_map=M, bound=50.0, nan_gains="flag",
              objectives=[2, 0])
    x_ref = np.cumsum(0.1 * rng.standard_normal((S, T, n)), axis=1)
    a = simulate_linear(K, F, G, x_ref, **kw)
    b = simulate_linear(K, F, G, x_ref, backend="numpy", **kw)
    assert a.diverged[3].all() and (a.diverged_step[3] == 0).all()
    assert 0 < a.diverged[:, 0].sum() < B and a.diverged_step[:, 0].max() > 0
    assert 0 < a.saturated_steps.sum() < B * S * T / 2
    for name in ("sq_error_sum", "sq_state_sum", "errors", "inputs"):
        np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=1e-12, atol=1e-14, err_msg=name)
    for name in ("diverged_step", "saturated_steps", "diverged"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    np.testing.assert_allclose(a.mse(), a.state_mse()[..., [2, 0]])
    assert a.objective_names == ("x2", "x0")


def test_bound_inf_never_freezes():
    res = simulate_linear(np.array([[0.5]]), np.array([[1.0]]), np.array([[1.0]]), np.zeros((40, 1)),
                          x0=[1.0], bound=np.inf)
    assert not res.diverged.any()
    np.testing.assert_allclose(res.errors[0, 0, :, 0], 1.5 ** np.arange(40), rtol=1e-14)


def test_prepared_simulator_equals_one_call(K_lqr):
    path = default_route(duration=30.0)
    sim = PathFollowing(path, [0.0, 200.0])
    np.testing.assert_array_equal(sim.run(K_lqr).errors, simulate(K_lqr, path, [0.0, 200.0]).errors)
    lin = LinearSimulator(np.eye(2), np.ones((2, 1)), np.zeros((5, 2)))
    assert (lin.n, lin.p, lin.m, lin.S, lin.T) == (2, 1, 1, 1, 5)
    with pytest.raises(ValueError, match="backend"):
        sim.run(K_lqr, backend="fortran")
    with pytest.raises(TypeError, match="keep_trajectories"):
        sim.run(K_lqr, keep_trajectories="no")


def test_named_objectives_and_state_order(K_lqr):
    res = simulate(K_lqr, default_route(duration=30.0), [0.0, 100.0])
    assert res.objective_names == ("rho", "psidot", "ydot", "theta")      # the paper's f1..f4
    assert res.state_names == truck.STATE_NAMES
    assert isinstance(res, SimulationResult)
    np.testing.assert_allclose(res.state_mse(), np.mean(res.errors**2, axis=2), rtol=1e-12)
    for j, name in enumerate(res.objective_names):
        np.testing.assert_array_equal(res.mse()[..., j], res.state_mse()[..., truck.STATE_NAMES.index(name)])


def test_input_map_is_explicit(K_lqr):
    path = ReferencePath.straight(5.0)
    split = np.array([[0.3, 0.7]]).T * K_lqr
    with pytest.warns(DeprecationWarning, match="input_map"):
        implicit = simulate(split, path)
    explicit = simulate(split, path, input_map=truck.DOUBLED_INPUT_MAP)
    np.testing.assert_array_equal(implicit.errors, explicit.errors)
    first_only = simulate(split, path, input_map=[[1.0, 0.0]])
    np.testing.assert_allclose(first_only.errors, simulate(split[:1], path).errors, rtol=1e-14)
    with pytest.raises(ValueError, match=r"K has 2 inputs.*input_map has 3 columns"):
        simulate(split, path, input_map=[[1.0, 1.0, 1.0]])
    with pytest.raises(ValueError, match="input_map"):
        simulate(split, path, input_map=[[1.0], [1.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        simulate(K_lqr, path)                                          # one row: no warning


# -- compilation cache ----------------------------------------------------------------------
def _kernel_stats_in_worker():
    """Run a tiny simulation in this (spawned) process; report where the kernel came from."""
    from robustctl.sim import _kernel as _simkernel

    res = simulate_linear(np.array([[-0.5]]), np.array([[1.0]]), np.array([[1.0]]), np.ones((10, 1)), x0=[-1.0])
    stats = _simkernel.closed_loop.stats
    return sum(stats.cache_hits.values()), sum(stats.cache_misses.values()), res.sq_error_sum


def test_spawned_workers_load_the_cached_kernel():
    _kernel_stats_in_worker()                                          # compiled (or loaded) here first
    with ProcessPoolExecutor(max_workers=2, mp_context=get_context("spawn")) as pool:
        results = [f.result() for f in [pool.submit(_kernel_stats_in_worker) for _ in range(2)]]
    here = _kernel_stats_in_worker()[2]
    for hits, misses, sq in results:
        assert hits >= 1 and misses == 0
        np.testing.assert_array_equal(sq, here)


_PROBE = """
import json, time, warnings, numpy as np
t0 = time.perf_counter()
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    from robustctl.sim import _kernel as _simkernel
    from robustctl.sim.simulator import simulate_linear
    res = simulate_linear(np.array([[-0.5]]), np.array([[1.0]]), np.array([[1.0]]), np.ones((10, 1)), x0=[-1.0])
s = _simkernel.closed_loop.stats
print(json.dumps(dict(hits=sum(s.cache_hits.values()), misses=sum(s.cache_misses.values()),
                      cached=_simkernel.cache_enabled(), seconds=time.perf_counter() - t0,
                      warnings=[str(w.message) for w in caught], e=res.errors[0, 0, :, 0].tolist())))
"""


def _probe(cwd: Path, **env) -> dict:
    out = subprocess.run([sys.executable, "-c", _PROBE], cwd=cwd, env={**os.environ, **env},
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.fixture
def fresh_copy(tmp_path):
    """The package as a fresh clone has it: no __pycache__, no numba cache."""
    src = Path(__file__).resolve().parents[1] / "robustctl"
    shutil.copytree(src, tmp_path / "robustctl", ignore=shutil.ignore_patterns("__pycache__"))
    return tmp_path


@pytest.mark.slow
def test_fresh_clone_compiles_once_then_loads_the_cache(fresh_copy):
    env = dict(NUMBA_CACHE_DIR="", PYTHONPATH=str(fresh_copy))
    first = _probe(fresh_copy, **env)
    assert first["cached"] and first["misses"] == 1 and first["hits"] == 0
    assert list((fresh_copy / "robustctl" / "sim" / "__pycache__").glob("_kernel.closed_loop*.nbi"))
    second = _probe(fresh_copy, **env)
    assert second["hits"] == 1 and second["misses"] == 0
    np.testing.assert_allclose(first["e"], -(0.5 ** np.arange(10)))
    assert second["e"] == first["e"]


@pytest.mark.slow
def test_unwritable_cache_falls_back_to_compiling_in_place(fresh_copy):
    (fresh_copy / "robustctl" / "sim" / "__pycache__").write_text("a file, so no cache directory can be made here")
    nowhere = "/proc/robustctl-no-cache"                              # not creatable, even by root
    res = _probe(fresh_copy, PYTHONPATH=str(fresh_copy), NUMBA_CACHE_DIR=nowhere, XDG_CACHE_HOME=nowhere,
                 HOME=nowhere)
    assert not res["cached"] and res["hits"] == 0
    assert any("compiled in every process" in w for w in res["warnings"])
    np.testing.assert_allclose(res["e"], -(0.5 ** np.arange(10)))


@pytest.mark.parametrize("bound", [1e3, np.inf])
def test_overflowing_gain_is_flagged_next_to_an_ordinary_diverging_one(backend, bound):
    """A gain so large that K e overflows (1e308 * 10 - 1e308 * 10 = inf - inf = NaN) diverges at step 1
    (its state is NaN), design by design: it must not hide the ordinary diverging design beside it (the
    numpy backend's batch-wide max was NaN), nor itself be left with a NaN MSE. The stable and the
    ordinary diverging designs keep the results they have alone (closed form: matrix powers)."""
    F, G = np.array([[1.0, 0.1], [0.0, 1.0]]), np.array([[0.0], [0.1]])
    K = np.array([[[-10.0, -5.0]], [[1.0, 1.0]], [[1e308, -1e308]]])   # stable, diverging, overflowing
    x_ref, x0 = np.zeros((200, 2)), np.array([10.0, 10.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = simulate_linear(K, F, G, x_ref, x0=x0, bound=bound, backend=backend)
    assert res.diverged[:, 0].tolist() == [False, bound < np.inf, True]
    assert res.diverged_step[2, 0] == 1
    mse = res.mse()
    assert not np.isnan(mse).any()
    assert np.all(mse[2] == (bound ** 2 * 199 + 100.0) / 200)          # step 0 at x0, then frozen at +bound
    for b in (0, 1):                                                   # x[k] = (F + G K)^k x0
        A = F + G @ K[b]
        xs = np.array([np.linalg.matrix_power(A, k) @ x0 for k in range(200)])
        k = res.diverged_step[b, 0] if res.diverged[b, 0] else 200
        np.testing.assert_allclose(res.errors[b, 0, :k], xs[:k], rtol=1e-9, atol=1e-12)
