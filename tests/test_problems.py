"""Tests of the two control-design MOPs (moo.problems.generic / moo.problems.applied).

References used (independent of the batched code under test):

* a plain loop over individuals calling ``robustctl.design("rlqr", ...)`` and a
  straightforward per-scenario, per-initial-state, per-step simulation written here;
* for long horizons, scipy's discrete Lyapunov solver (the infinite-horizon
  regulation error from the unit initial states is ``diag(X)``, ``X = A X A^T + I``);
* hand-built populations whose designs are known to be unstable / not computable.
"""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import robustctl as rc
from moo.problems.generic import GenericRLQRProblem

F = np.array([[0.9, 0.8, 0.7], [0.01, 0.1, 0.3], [0.0, 0.25, 0.1]])
G = np.array([[0.6], [0.1], [0.25]])
H = np.ones((3, 1))
EF_TRUE = np.array([[0.1, 0.2, 0.2]])
EG_TRUE = np.array([[0.1]])

# stabilising designs of the generic MOP (checked in the tests)
GENERIC_Z = np.array([
    [19.933888, 19.999998, 20.000000, 16.339275, 20.000000],   # the paper's z*
    [0.1, 0.2, 0.2, 0.1, 16.0],                                 # the true uncertainty, mu = 1e4
    [35.1, 172.6, 108.3, 59.9, 84.5],
    [50.0, 120.0, 10.0, 150.0, 4.0],
    [1.0, 1.0, 1.0, 1.0, 1.0],
])
# a random population (seed 0): 4 of its 10 designs are unstable on the true plant
RANDOM_Z = np.random.default_rng(0).uniform(0.0, 200.0, (10, 5))


def _generic_reference(z, *, deltas, x0s, horizon, Q=None, R=None, aggregate="mean", penalty=1e6):
    """One individual at a time: design with robustctl.design, simulate with plain loops.

    Applies the documented penalty rule: not computable -> 2 penalty; unstable for
    some delta (spectral radius rho >= 1) -> penalty * min(rho, 2); else min(error, penalty).
    """
    Q = np.eye(3) if Q is None else Q
    R = np.eye(1) if R is None else R
    out = []
    for zi in np.atleast_2d(z):
        try:
            ctrl = rc.design("rlqr", rc.Plant(F, G, dt=1.0), zi[None, :3], zi[None, 3:4],
                             10.0 ** np.sqrt(zi[4]), Q=Q, R=R, H=H, check_stability=False)
        except (rc.ConvergenceError, rc.RankConditionError):
            out.append(np.full(3, 2 * penalty))
            continue
        closed = [F + d * H @ EF_TRUE + (G + d * H @ EG_TRUE) @ ctrl.K for d in deltas]
        rho = max(np.max(np.abs(np.linalg.eigvals(A))) for A in closed)
        if rho >= 1.0:
            out.append(np.full(3, penalty * min(rho, 2.0)))
            continue
        per_delta = []
        for A in closed:
            e = np.zeros(3)
            for x0 in x0s:
                x = np.array(x0, dtype=float)
                for _ in range(horizon + 1):
                    e += x**2
                    x = A @ x
            per_delta.append(e)
        per_delta = np.array(per_delta)
        e = per_delta.mean(0) if aggregate == "mean" else per_delta.max(0)
        out.append(np.minimum(e, penalty))
    return np.array(out)


@pytest.fixture(scope="module")
def generic():
    return GenericRLQRProblem()


# ------------------------------------------------------------------ generic --
def test_generic_shape_and_bounds(generic):
    assert generic.n_var == 5 and generic.n_obj == 3
    np.testing.assert_array_equal(generic.xl, np.zeros(5))
    np.testing.assert_array_equal(generic.xu, np.full(5, 200.0))
    assert generic.hv_ref_point.shape == (3,) and generic.molsp_ref_point.shape == (3,)


def test_generic_deltas_are_seeded_and_include_extremes():
    a, b = GenericRLQRProblem(), GenericRLQRProblem()
    np.testing.assert_array_equal(a.deltas, b.deltas)
    assert -1.0 in a.deltas and 1.0 in a.deltas and a.deltas.size == 8
    assert np.all(np.abs(a.deltas) <= 1.0)
    c = GenericRLQRProblem(seed=7)
    assert not np.array_equal(a.deltas, c.deltas)


def test_generic_batched_equals_per_individual_loop(generic):
    got = generic.evaluate(GENERIC_Z)
    want = _generic_reference(GENERIC_Z, deltas=generic.deltas, x0s=np.eye(3), horizon=generic.horizon)
    assert np.all(want < 10)                   # the chosen designs are stable and computable
    np.testing.assert_allclose(got, want, rtol=1e-8)


def test_generic_random_population_equals_per_individual_loop(generic):
    got = generic.evaluate(RANDOM_Z)
    want = _generic_reference(RANDOM_Z, deltas=generic.deltas, x0s=np.eye(3), horizon=generic.horizon)
    n_penalised = int(np.sum(want[:, 0] >= generic.penalty))
    assert 2 <= n_penalised <= 8               # the population mixes stable and unstable designs
    np.testing.assert_allclose(got, want, rtol=1e-8)


def test_generic_options_match_reference():
    """Non-default Q, R, initial states, horizon, deltas and the worst-case aggregate."""
    Q = np.diag([2.0, 1.0, 0.5])
    R = np.array([[3.0]])
    x0s = np.array([[1.0, -1.0, 0.5], [0.0, 2.0, 0.0]])
    deltas = [-1.0, -0.2, 0.7, 1.0]
    p = GenericRLQRProblem(Q=Q, R=R, initial_states=x0s, horizon=40, deltas=deltas, aggregate="max")
    z = GENERIC_Z[:3]
    want = _generic_reference(z, deltas=deltas, x0s=x0s, horizon=40, Q=Q, R=R, aggregate="max")
    np.testing.assert_allclose(p.evaluate(z), want, rtol=1e-8)


def test_generic_long_horizon_equals_lyapunov_gramian():
    """N -> inf: f_j = mean_s [X_s]_jj with X_s = A_s X_s A_s^T + I (scipy, independent)."""
    p = GenericRLQRProblem(horizon=3000)
    z = GENERIC_Z[:2]
    K = np.stack([rc.design("rlqr", p.plant, zi[None, :3], zi[None, 3:4], 10.0 ** np.sqrt(zi[4]),
                            H=H, check_stability=False).K for zi in z])
    want = []
    for Ki in K:
        diag = [np.diag(scipy.linalg.solve_discrete_lyapunov(
            F + d * H @ EF_TRUE + (G + d * H @ EG_TRUE) @ Ki, np.eye(3))) for d in p.deltas]
        want.append(np.mean(diag, axis=0))
    np.testing.assert_allclose(p.evaluate(z), np.array(want), rtol=1e-9)


def test_generic_paper_optimum_is_finite_and_sensible(generic):
    f = generic.evaluate(generic.paper_optimum[None])[0]
    assert np.all(np.isfinite(f))
    assert np.all(f >= 1.0)                      # the k = 0 term of the unit initial states
    assert np.all(f < generic.hv_ref_point)      # dominates both reference points
    assert np.all(f < generic.molsp_ref_point)
    # the nominal LQR (python-control's dlqr, u = -K_pc x) regulates x1 much worse; z* is not dominated by it
    K_pc, _, _ = control.dlqr(F, G, np.eye(3), np.eye(1))
    e_lqr, _ = generic.regulation_errors(-K_pc[None])
    f_lqr = e_lqr.mean(axis=1)[0]
    assert f[0] < 0.6 * f_lqr[0]
    assert not np.all(f_lqr <= f)


def test_generic_unstable_designs_get_finite_penalties(generic):
    # mu = 1e14 forces EF + EG K ~ 0, i.e. K ~ -EF/EG = [-200, 0, 0]: violently unstable
    z = np.array([[200.0, 0.0, 0.0, 1.0, 196.0]])
    K = generic.gains(z).K[0]
    rho = max(np.max(np.abs(np.linalg.eigvals(F + d * H @ EF_TRUE + (G + d * H @ EG_TRUE) @ K)))
              for d in generic.deltas)
    assert rho > 1.0
    f = generic.evaluate(z)
    assert np.all(np.isfinite(f)) and np.all(f >= generic.penalty) and np.all(f <= 2 * generic.penalty)


def test_generic_slowly_converging_design_is_penalised(generic):
    """A design (found by an MO-LSP run) whose RLQR recursion does not converge in 20000 steps."""
    z = np.array([[47.8069, 103.7683, 181.5866, 53.6425, 117.4085]])
    assert not generic.gains(z).ok[0]                     # capped at max_iter = 50
    f = generic.evaluate(z)
    np.testing.assert_array_equal(f, np.full((1, 3), 2 * generic.penalty))


def _rlqr_failing_at(row):
    """``rc.rlqr_gains`` reporting design ``row`` of the batch as failed (ok False, NaN gain)."""
    real = rc.rlqr_gains

    def failing(plant, EF, EG, mu, **kw):
        b = real(plant, EF, EG, mu, **kw)
        K = np.array(b.K, copy=True)
        ok = np.array(b.ok, copy=True)
        K[row] = np.nan
        ok[row] = False
        return type("Batch", (), {"K": K, "ok": ok, "P": b.P, "iterations": b.iterations})()

    return failing


def test_generic_not_computable_designs_get_finite_penalties(generic, monkeypatch):
    """A design the RLQR reports as failed (ok False, NaN gain) gets 2 * penalty, the others are untouched."""
    z = GENERIC_Z[:3]
    good = generic.evaluate(z)
    monkeypatch.setattr(rc, "rlqr_gains", _rlqr_failing_at(1))
    f = generic.evaluate(z)
    np.testing.assert_array_equal(f[1], np.full(3, 2 * generic.penalty))
    np.testing.assert_allclose(f[[0, 2]], good[[0, 2]], rtol=1e-12)


def test_generic_whole_random_population_is_finite(generic):
    z = np.random.default_rng(0).uniform(0.0, 200.0, (60, 5))
    z[:5, 3] = 0.0          # EG = 0: no gain can cancel EF when mu is large
    z[5] = 0.0
    z[6] = 200.0
    f = generic.evaluate(z)
    assert f.shape == (60, 3) and np.all(np.isfinite(f)) and np.all(f >= 1.0)
    assert np.all(f <= 2 * generic.penalty)


def test_generic_max_aggregate_dominates_mean():
    z = GENERIC_Z
    assert np.all(GenericRLQRProblem(aggregate="max").evaluate(z) >= GenericRLQRProblem().evaluate(z) - 1e-12)


def test_generic_decode():
    p = GenericRLQRProblem()
    EF, EG, mu = p.decode([1.0, 2.0, 3.0, 4.0, 9.0])
    np.testing.assert_array_equal(EF, [[[1.0, 2.0, 3.0]]])
    np.testing.assert_array_equal(EG, [[[4.0]]])
    np.testing.assert_allclose(mu, [1e3])


@pytest.mark.parametrize("kwargs, exc, words", [
    (dict(Q=np.eye(2)), ValueError, "Q"),
    (dict(Q=-np.eye(3)), ValueError, "Q"),
    (dict(R=np.eye(2)), ValueError, "R"),
    (dict(alpha=0.0), ValueError, "alpha"),
    (dict(max_iter=0), ValueError, "max_iter"),
    (dict(deltas=[0.5, 1.5]), ValueError, "deltas"),
    (dict(deltas=np.ones((2, 2))), ValueError, "deltas"),
    (dict(deltas=[np.nan]), ValueError, "deltas"),
    (dict(n_deltas=1), ValueError, "n_deltas"),
    (dict(n_deltas=2.5), TypeError, "n_deltas"),
    (dict(initial_states=np.ones((2, 4))), ValueError, "initial_states"),
    (dict(horizon=0), ValueError, "horizon"),
    (dict(horizon=10.0), TypeError, "horizon"),
    (dict(aggregate="median"), ValueError, "aggregate"),
    (dict(penalty=-1.0), ValueError, "penalty"),
    (dict(penalty=np.inf), ValueError, "penalty"),
    (dict(hv_ref_point=[1.0, 2.0]), ValueError, "hv_ref_point"),
    (dict(molsp_ref_point=[1.0, -2.0, 3.0]), ValueError, "molsp_ref_point"),
])
def test_generic_bad_arguments(kwargs, exc, words):
    with pytest.raises(exc, match=words):
        GenericRLQRProblem(**kwargs)


def test_generic_bad_population(generic):
    with pytest.raises(ValueError, match="K must have shape"):
        generic.regulation_errors(np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"\(B, 5\)"):
        generic.decode(np.zeros((2, 4)))
    with pytest.raises(ValueError, match="finite"):
        generic.decode(np.full(5, np.nan))
    with pytest.raises(ValueError, match="log10 mu"):
        generic.decode([1.0, 1.0, 1.0, 1.0, -1.0])


# ------------------------------------------------------------------ applied --
from moo.problems.applied import AppliedRLQRProblem  # noqa: E402
from robustctl.models import morais2022, truck  # noqa: E402
from robustctl.models.path import default_route  # noqa: E402

SHORT_PATH_S = 120.0      # a 2-minute stretch of the default route keeps the plain-loop reference quick
APPLIED_Z = np.random.default_rng(0).uniform(1e-6, 500.0, (12, 7))   # seed 0: one unstable design


def _zoh_truck(overload):
    """Exact ZOH of x' = A x + B alpha + E kappa (scipy expm of the augmented matrix)."""
    A, B, E = truck.continuous_model(overload)
    dt = truck.PAPER_PARAMETERS.dt
    M = np.zeros((6, 6))
    M[:4, :4], M[:4, 4], M[:4, 5] = A * dt, B[:, 0] * dt, E * dt
    Phi = scipy.linalg.expm(M)
    return Phi[:4, :4], Phi[:4, 4], Phi[:4, 5]


def _applied_reference(z, problem, *, aggregate="mean", setup="ours"):
    """One individual, one payload, one time step at a time (no batching anywhere).

    ``setup="authors"``: the open-loop reference (the nominal ZOH truck driven by the steady-cornering
    steering, step by step), velocities regulated to zero, no feedforward, start at [0, 0, 0.3, -0.1].
    """
    pen = problem.penalty
    kappa = problem.path.kappa
    T = kappa.size
    x_ref, alpha_ff = truck.reference_states(kappa, 0.0)
    x0 = np.array([0.0, 0.0, 1.0, 0.0])                        # start 1 m left of the path
    if setup == "authors":
        F0, G0, Gk0 = _zoh_truck(0.0)
        u_ref = alpha_ff.copy()                                 # the steady-cornering steering command
        x_ref = np.zeros((T, 4))
        for k in range(T - 1):
            x_ref[k + 1] = F0 @ x_ref[k] + G0 * u_ref[k] + Gk0 * kappa[k]
        x_ref[:, :2] = 0.0
        alpha_ff = np.zeros(T)
        x0 = np.array([0.0, 0.0, 0.3, -0.1])
    plants = [_zoh_truck(ov) for ov in problem.overloads]
    out = []
    for zi in np.atleast_2d(z):
        try:
            K = rc.design("rlqr", truck.truck_plant(0.0, doubled=True), zi[None, :4], zi[None, 4:6],
                          10.0 ** np.sqrt(zi[6]), Q=problem.Q, R=problem.R, H=np.ones((4, 1)),
                          check_stability=False).K
        except (rc.ConvergenceError, rc.RankConditionError):
            out.append(np.full(4, 2 * pen))
            continue
        k_steer = K[0] + K[1]                          # alpha = u1 + u2
        rho = max(np.max(np.abs(np.linalg.eigvals(Fd + np.outer(Gd, k_steer)))) for Fd, Gd, _ in plants)
        if rho >= 1.0:
            out.append(np.full(4, pen * min(rho, 2.0)))
            continue
        per_payload = []
        for Fd, Gd, Gk in plants:
            x = x_ref[0] + x0
            sq = np.zeros(4)
            for k in range(T):
                e = x - x_ref[k]
                assert np.max(np.abs(e)) < 1e3                # no run of the chosen designs diverges
                sq += e**2
                alpha = np.clip(k_steer @ e + alpha_ff[k], -0.45, 0.45)
                x = Fd @ x + Gd * alpha + Gk * kappa[k]
            per_payload.append(sq[[2, 1, 0, 3]] / T)          # f1..f4 = rho, psidot, ydot, theta
        per_payload = np.array(per_payload)
        out.append(per_payload.mean(0) if aggregate == "mean" else per_payload.max(0))
    return np.array(out)


@pytest.fixture(scope="module")
def applied_short():
    return AppliedRLQRProblem(path=default_route(duration=SHORT_PATH_S))


def test_applied_shape_and_bounds(applied_short):
    p = applied_short
    assert p.n_var == 7 and p.n_obj == 4
    assert np.all(p.xl > 0) and np.all(p.xl <= 1e-6) and np.all(p.xu == 500.0)
    assert p.plant.G.shape == (4, 2)
    np.testing.assert_array_equal(p.plant.G[:, 0], p.plant.G[:, 1])    # doubled steering column
    assert p.hv_ref_point.shape == (4,) and p.molsp_ref_point.shape == (4,)
    np.testing.assert_array_equal(p.overloads, [0.0, 100.0])


def test_applied_batched_equals_per_individual_loop(applied_short):
    got = applied_short.evaluate(APPLIED_Z)
    want = _applied_reference(APPLIED_Z, applied_short)
    n_penalised = int(np.sum(want[:, 0] >= applied_short.penalty))
    assert 1 <= n_penalised <= 6
    np.testing.assert_allclose(got, want, rtol=1e-7)


def test_applied_options_match_reference():
    Q = np.diag([1.0, 10.0, 5.0, 50.0])
    R = np.diag([20.0, 5.0])
    p = AppliedRLQRProblem(Q=Q, R=R, path=default_route(duration=60.0), overloads=[0.0, 50.0, 300.0],
                           aggregate="max")
    z = APPLIED_Z[[0, 1, 3]]
    np.testing.assert_allclose(p.evaluate(z), _applied_reference(z, p, aggregate="max"), rtol=1e-7)


def test_applied_paper_optimum_is_finite_and_sensible():
    p = AppliedRLQRProblem()                    # the full default route
    f = p.evaluate(p.paper_optimum[None])[0]
    assert np.all(np.isfinite(f)) and np.all(f > 0)
    assert np.all(f < p.hv_ref_point) and np.all(f < p.molsp_ref_point)
    # stable at every payload of the paper's comparison, 0 to 300 % overload
    K = p.gains(p.paper_optimum[None]).K[0]
    F_s, G_s, _ = truck.discretise([0.0, 100.0, 200.0, 300.0])
    for Fd, Gd in zip(F_s, G_s, strict=True):
        assert np.max(np.abs(np.linalg.eigvals(Fd + Gd @ K.sum(axis=0, keepdims=True)))) < 1.0
    # the truck ends up on the path: RMS lateral error well below the 1 m start offset
    assert np.sqrt(f[0]) < 0.5


def test_applied_not_computable_designs_get_finite_penalties(applied_short, monkeypatch):
    z = APPLIED_Z[[0, 1, 3]]
    good = applied_short.evaluate(z)
    monkeypatch.setattr(rc, "rlqr_gains", _rlqr_failing_at(0))
    f = applied_short.evaluate(z)
    np.testing.assert_array_equal(f[0], np.full(4, 2 * applied_short.penalty))
    np.testing.assert_allclose(f[1:], good[1:], rtol=1e-12)


def test_applied_extreme_population_is_finite(applied_short):
    z = np.random.default_rng(3).uniform(1e-6, 500.0, (16, 7))
    z[0] = 1e-6                 # the lower corner of the box
    z[1] = 500.0                # the upper corner: mu = 10**sqrt(500) ~ 2.5e22
    z[2, 4:6] = 1e-6            # EG ~ 0 with EF large
    f = applied_short.evaluate(z)
    assert f.shape == (16, 4) and np.all(np.isfinite(f)) and np.all(f > 0)
    assert np.all(f <= 2 * applied_short.penalty)


@pytest.mark.parametrize("kwargs, exc, words", [
    (dict(Q=np.eye(3)), ValueError, "Q"),
    (dict(R=np.eye(1)), ValueError, "R"),
    (dict(R=np.diag([1.0, -1.0])), ValueError, "R"),
    (dict(alpha=-0.1), ValueError, "alpha"),
    (dict(max_iter=10.5), TypeError, "max_iter"),
    (dict(path="default"), TypeError, "path"),
    (dict(overloads=[]), ValueError, "overloads"),
    (dict(overloads=[0.0, -10.0]), ValueError, "overloads"),
    (dict(overloads=50.0), ValueError, "overloads"),
    (dict(aggregate="min"), ValueError, "aggregate"),
    (dict(penalty=1e5), ValueError, "penalty"),
    (dict(hv_ref_point=[1.0, 1.0, 1.0]), ValueError, "hv_ref_point"),
    (dict(molsp_ref_point=[0.0, 1.0, 1.0, 1.0]), ValueError, "molsp_ref_point"),
])
def test_applied_bad_arguments(kwargs, exc, words):
    with pytest.raises(exc, match=words):
        AppliedRLQRProblem(path=default_route(duration=10.0), **kwargs) if "path" not in kwargs \
            else AppliedRLQRProblem(**kwargs)


def test_applied_path_must_match_the_model():
    with pytest.raises(ValueError, match="path speed"):
        AppliedRLQRProblem(path=default_route(speed=10.0, duration=10.0))


def test_applied_bad_population(applied_short):
    with pytest.raises(ValueError, match=r"\(B, 7\)"):
        applied_short.decode(np.ones((3, 5)))
    with pytest.raises(ValueError, match="K must have shape"):
        applied_short.mse(np.zeros((2, 1, 4)))


# ------------------------------------------------------------ both, property --
def _boxed(n_var, high):
    """Populations of 1-6 designs in [0, high]^n_var, often with entries on the bounds."""
    value = st.one_of(st.just(0.0), st.just(high), st.floats(0.0, high))
    return st.integers(1, 6).flatmap(lambda b: arrays(np.float64, (b, n_var), elements=value))


@settings(max_examples=25, deadline=None)
@given(z=_boxed(5, 200.0))
def test_generic_any_population_in_the_box_gives_finite_objectives(generic, z):
    f = generic.evaluate(z)
    assert f.shape == (z.shape[0], 3)
    assert np.all(np.isfinite(f)) and np.all(f >= 1.0) and np.all(f <= 2 * generic.penalty)


@pytest.fixture(scope="module")
def applied_tiny():
    return AppliedRLQRProblem(path=default_route(duration=10.0))


@settings(max_examples=25, deadline=None)
@given(z=_boxed(7, 500.0))
def test_applied_any_population_in_the_box_gives_finite_objectives(applied_tiny, z):
    f = applied_tiny.evaluate(np.maximum(z, 1e-6))
    assert f.shape == (z.shape[0], 4)
    assert np.all(np.isfinite(f)) and np.all(f > 0) and np.all(f <= 2 * applied_tiny.penalty)


# ------------------------------------------------------------ engine, API --
def test_backends_agree_on_both_problems(applied_short, generic):
    """The compiled simulator (default) and the numpy reference give the same objectives."""
    numpy_generic = GenericRLQRProblem(backend="numpy")
    np.testing.assert_allclose(generic.evaluate(RANDOM_Z), numpy_generic.evaluate(RANDOM_Z), rtol=1e-12)
    numpy_applied = AppliedRLQRProblem(path=applied_short.path, backend="numpy")
    np.testing.assert_allclose(applied_short.evaluate(APPLIED_Z), numpy_applied.evaluate(APPLIED_Z), rtol=1e-12)
    with pytest.raises(ValueError, match="backend"):
        GenericRLQRProblem(backend="cuda")


@pytest.mark.parametrize("make", [GenericRLQRProblem, lambda: AppliedRLQRProblem(path=default_route(duration=5.0))])
def test_evaluate_names_the_bad_argument(make):
    """Not pymoo's AssertionError: an error that names X and its expected shape."""
    p = make()
    with pytest.raises(ValueError, match=rf"X must have shape \(B, {p.n_var}\).*got shape \(2, {p.n_var + 1}\)"):
        p.evaluate(np.ones((2, p.n_var + 1)))
    with pytest.raises(TypeError, match="X must be an array of numbers"):
        p.evaluate("x")
    with pytest.raises(ValueError, match="X must have finite entries"):
        p.evaluate(np.full((1, p.n_var), np.nan))
    one = p.evaluate(p.paper_optimum)                       # a single vector still gives one row
    assert one.shape == (p.n_obj,)
    np.testing.assert_array_equal(one, p.evaluate(p.paper_optimum[None])[0])


def test_stability_screen_uses_the_public_spectral_radius(applied_short):
    K = applied_short.gains(APPLIED_Z).K
    rho = applied_short.closed_loop_radius(np.where(np.isfinite(K), K, np.nan))
    F_s, G_s, _ = truck.discretise(applied_short.overloads)
    for b in range(K.shape[0]):
        for s in range(F_s.shape[0]):
            if np.all(np.isfinite(K[b])):
                A = F_s[s] + G_s[s] @ K[b].sum(axis=0, keepdims=True)
                assert rho[b, s] == pytest.approx(np.max(np.abs(np.linalg.eigvals(A))), rel=1e-12)
    K_nan = K[:2].copy()
    K_nan[0, 0, 0] = np.nan
    assert np.isinf(applied_short.closed_loop_radius(K_nan)[0]).all()


def test_applied_experiment_is_the_same_with_workers(tmp_path):
    """Same seed, same records, whether the runs share one process or go to spawned workers
    (which load the compiled kernel from the cache)."""
    from moo.experiment import load_records, run_experiment

    kw = dict(runs=2, evals=40, pop_size=20, progress=False)
    run_experiment("applied", "nsga2", out=tmp_path / "serial", **kw)
    run_experiment("applied", "nsga2", out=tmp_path / "parallel", workers=2, **kw)
    serial, parallel = load_records(tmp_path / "serial"), load_records(tmp_path / "parallel")
    assert len(serial) == 4
    assert [(r["molsp"], r["seed"], r["F"]) for r in serial] == [(r["molsp"], r["seed"], r["F"]) for r in parallel]


# ------------------------------------------------------------ applied, the authors' set-up --
@pytest.fixture(scope="module")
def applied_authors():
    return AppliedRLQRProblem(setup="authors", path=default_route(duration=SHORT_PATH_S))


def test_applied_authors_setup_matches_reference(applied_authors):
    p = applied_authors
    Q, R = morais2022.authors_weights(doubled=True)
    np.testing.assert_array_equal(p.Q, Q)
    np.testing.assert_array_equal(p.R, R)
    z = APPLIED_Z[:4]
    np.testing.assert_allclose(p.evaluate(z), _applied_reference(z, p, setup="authors"), rtol=1e-8)
    assert p.setup.name == "authors" and "authors" in repr(p)


def test_applied_authors_reference_points():
    p = AppliedRLQRProblem(setup="authors", path=default_route(duration=10.0))
    np.testing.assert_allclose(p.hv_ref_point, np.square([0.25, 0.035, 0.35, 0.0125]))
    np.testing.assert_allclose(p.molsp_ref_point, np.square([1.0, 0.04, 0.4, 0.02]))
    ours = AppliedRLQRProblem(path=default_route(duration=10.0))
    np.testing.assert_allclose(ours.hv_ref_point, np.square([0.25, 0.0125, 0.15, 0.01]))
    assert ours.setup.name == "ours"


def test_make_problem_passes_the_setup_to_applied_only():
    from moo.problems import make_problem

    assert make_problem("applied", setup="authors").setup.name == "authors"
    assert make_problem("applied").setup.name == "ours"
    with pytest.raises(ValueError, match="setup applies to the 'applied' problem only"):
        make_problem("zdt1", setup="authors")
    with pytest.raises(ValueError, match="unknown setup"):
        make_problem("applied", setup="theirs")


# ------------------------------------------------------------ on the public moo.tuning API --
def test_paper_mops_are_tuning_problems_with_one_simulation_per_population(applied_short, generic, monkeypatch):
    from moo.tuning import RLQRFamily, TuningProblem

    for p in (generic, applied_short):
        assert isinstance(p, TuningProblem) and isinstance(p.family, RLQRFamily)
        assert len(p.objectives) == p.n_obj and p.n_ieq_constr == 0
    calls = []
    real = applied_short.errors.per_scenario
    monkeypatch.setattr(applied_short.errors, "per_scenario",
                        lambda K, plants=None: calls.append(len(K)) or real(K, plants))
    F = applied_short.evaluate(APPLIED_Z)
    assert len(calls) == 1                                     # four objectives, one simulation
    stable = F[:, 0] < applied_short.penalty
    np.testing.assert_allclose(F[stable], applied_short.mse(applied_short.gains(APPLIED_Z).K[stable]).mean(axis=1),
                               rtol=1e-12)
    with pytest.raises(ValueError, match="its own payload scenarios"):
        applied_short.evaluate_gains(applied_short.gains(APPLIED_Z[:1]).K, applied_short.scenarios[:1])


def test_generic_goals_on_other_plants(generic):
    """evaluate_gains on one scenario alone: the regulation errors of that scenario (its own simulator)."""
    K = generic.gains(generic.paper_optimum).K
    e, _ = generic.regulation_errors(K)
    for s in (0, 3):
        F, _ = generic.evaluate_gains(K, [generic.scenarios[s]])
        np.testing.assert_allclose(F[0], e[0, s], rtol=1e-12)
