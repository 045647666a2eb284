"""moo.tuning core: design families, TuningProblem (screen, penalty, bad input), tune, select, plot."""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.linalg

import robustctl as rc
from moo import tuning
from moo.tuning.families import FamilyGains

PLANT = rc.Plant([[1.1, 0.1], [0.0, 0.9]], [[0.0], [0.1]], dt=0.1)
SCENARIOS = [rc.Plant(PLANT.F * s, PLANT.G, dt=0.1) for s in (0.95, 1.0, 1.05)]


def effort(K, plants):
    """Sum of absolute gains (a test goal)."""
    return np.abs(K).sum(axis=(1, 2))


def radius(K, plants):
    """Largest closed-loop spectral radius over the plants (a test goal, eigenvalues per design)."""
    return np.array([max(np.abs(np.linalg.eigvals(p.F + p.G @ k)).max() for p in plants) for k in K])


# -- families ------------------------------------------------------------------------------
def test_lqr_family_matches_control_dlqr():
    rng = np.random.default_rng(0)
    plant = rc.Plant(rng.standard_normal((4, 4)) / 2, rng.standard_normal((4, 2)), dt=0.1)
    fam = tuning.LQRFamily(plant, log_bound=2.0)
    assert fam.n_var == 6 and fam.xl.shape == (6,)
    Z = rng.uniform(fam.xl, fam.xu, (12, fam.n_var))
    g = fam.gains(Z)
    assert g.K.shape == (12, 2, 4) and g.ok.all()
    for z, K in zip(Z, g.K, strict=True):
        Kpc, _, _ = control.dlqr(plant.F, plant.G, np.diag(10 ** z[:4]), np.diag(10 ** z[4:]))
        np.testing.assert_allclose(K, -Kpc, rtol=1e-8, atol=1e-10)     # u = K x = -K_pc x


def test_dlqr_gains_riccati_residual():
    rng = np.random.default_rng(1)
    F, G = rng.standard_normal((3, 3)), rng.standard_normal((3, 1))
    Q = np.stack([np.diag(rng.uniform(0.1, 10, 3)) for _ in range(5)])
    R = np.stack([np.diag(rng.uniform(0.1, 10, 1)) for _ in range(5)])
    _, X, ok = tuning.dlqr_gains(F, G, Q, R)
    assert ok.all()
    for b in range(5):
        np.testing.assert_allclose(X[b], scipy.linalg.solve_discrete_are(F, G, Q[b], R[b]), rtol=1e-9)


def test_rlqr_family_matches_single_designs_and_flags():
    H = np.array([[1.0, 0.0], [0.0, 1.0]])
    fam = tuning.RLQRFamily(PLANT, H=H)
    assert fam.n_var == 2 * (2 + 1) + 1 and fam.l == 2
    assert np.all(fam.xl == 0) and fam.xu[-1] == 100.0
    rng = np.random.default_rng(2)
    Z = rng.uniform(0, 2, (4, fam.n_var))
    Z[:, -1] = rng.uniform(1, 16, 4)
    g = fam.gains(Z)
    for z, K, ok in zip(Z, g.K, g.ok, strict=True):
        EF, EG = z[:4].reshape(2, 2), z[4:6].reshape(2, 1)
        want = rc.design("rlqr", PLANT, EF, EG, 10 ** np.sqrt(z[-1]), H=H, alpha=0.1, check_stability=False).K
        assert ok
        np.testing.assert_allclose(K, want, rtol=1e-7, atol=1e-9)
    with pytest.raises(ValueError, match=r"\(log10 mu\)\^2"):
        fam.gains(np.r_[Z[0, :-1], -1.0])


def test_rlqr_family_input_map_is_the_doubled_column():
    M = np.array([[1.0, 1.0]])
    fam = tuning.RLQRFamily(PLANT, input_map=M)
    assert fam.design_plant.m == 2 and fam.n_inputs == 1 and fam.n_var == 2 + 2 + 1
    z = np.array([0.3, 0.2, 0.5, 0.7, 9.0])
    K = fam.gains(z).K[0]
    doubled = rc.Plant(PLANT.F, np.hstack([PLANT.G, PLANT.G]), dt=0.1)
    Kd = rc.design("rlqr", doubled, z[None, :2], z[None, 2:4], 1e3, alpha=0.1, check_stability=False).K
    np.testing.assert_allclose(K, Kd.sum(axis=0, keepdims=True), rtol=1e-7)
    with pytest.raises(ValueError, match="input_map must have 1 rows"):
        tuning.RLQRFamily(PLANT, input_map=np.ones((2, 2)))


def test_user_family_protocol():
    class DirectGain:
        n_states, n_inputs, n_var = 2, 1, 2
        xl, xu = np.full(2, -30.0), np.full(2, 0.0)

        def gains(self, Z):
            return FamilyGains(Z.reshape(-1, 1, 2).copy(), np.ones(len(Z), bool), np.full(len(Z), "", object))

    def only_stable(K, plants):          # the screen: user goals never see a design unstable somewhere
        assert np.all(radius(K, plants) < 1.0) and np.all(np.isfinite(K))
        return effort(K, plants)

    assert isinstance(DirectGain(), tuning.DesignFamily)
    prob = tuning.TuningProblem(DirectGain(), SCENARIOS, [only_stable])
    F = prob.evaluate(np.array([[-10.0, -5.0], [0.0, 0.0]]))
    np.testing.assert_allclose(F[0], 15.0)
    assert F[1, 0] == pytest.approx(1e6 * 1.05 * 1.1)            # unstable open loop: p * rho
    assert list(prob.last_flags) == ["", "unstable"]


# -- TuningProblem -------------------------------------------------------------------------
def test_problem_penalty_rule_and_reference_points():
    F0 = np.array([[0.9, 0.8, 0.7], [0.01, 0.1, 0.3], [0.0, 0.25, 0.1]])      # the paper's generic plant
    G0 = np.array([[0.6], [0.1], [0.25]])
    plants = [rc.Plant(F0 + d * np.ones((3, 1)) @ [[0.1, 0.2, 0.2]], G0 + d * 0.1, dt=1.0) for d in (-1, 0, 1)]
    fam = tuning.RLQRFamily(plants[1])
    prob = tuning.TuningProblem(fam, plants, [effort, radius], penalty=1e3)
    assert (prob.n_var, prob.n_obj, prob.n_ieq_constr) == (fam.n_var, 2, 0)
    # the default reference points: from 500 designs sampled within the bounds (seed 0), not the penalty
    hv, ms = prob.sample_reference_points(500, seed=0)
    np.testing.assert_array_equal(prob.hv_ref_point, hv)
    np.testing.assert_array_equal(prob.molsp_ref_point, ms)
    assert prob.hv_ref_source == "sampled designs" and np.all(hv < 1e3)
    Z = np.random.default_rng(3).uniform(0.0, 200.0, (30, fam.n_var))
    F = prob.evaluate(Z)
    K = fam.gains(Z).K
    for f, k, flag in zip(F, K, prob.last_flags, strict=True):
        if not np.all(np.isfinite(k)):
            assert flag != "" and np.all(f == 2e3)
            continue
        rho = max(np.abs(np.linalg.eigvals(p.F + p.G @ k)).max() for p in plants)
        if rho >= 1:
            np.testing.assert_allclose(f, 1e3 * min(rho, 2.0))
        else:
            np.testing.assert_allclose(f, [np.abs(k).sum(), rho], rtol=1e-12)
    assert np.any(F[:, 0] < 1e3) and np.any(F[:, 0] >= 1e3)


def test_problem_constraints_and_nan_flag():
    fam = tuning.LQRFamily(PLANT)

    def small(K, plants):
        return np.abs(K).sum(axis=(1, 2)) - 20.0

    def nan_for_big(K, plants):
        out = np.abs(K).sum(axis=(1, 2))
        out[out > 30] = np.nan
        return out

    prob = tuning.TuningProblem(fam, SCENARIOS, [nan_for_big], [small], penalty=1e4)
    Z = np.array([[0.0, 0.0, 0.0], [4.0, 4.0, -4.0]])      # a mild LQR and a very high-gain one
    out = prob.evaluate(Z, return_as_dictionary=True)
    K = fam.gains(Z).K
    assert np.abs(K[0]).sum() < 30 < np.abs(K[1]).sum()
    np.testing.assert_allclose(out["F"][0, 0], np.abs(K[0]).sum())
    np.testing.assert_allclose(out["G"][0, 0], np.abs(K[0]).sum() - 20.0)
    assert out["F"][1, 0] == 1e4 and out["G"][1, 0] > 0            # flagged: penalised and infeasible
    assert prob.last_flags[1] == "nan_for_big returned nan"


def test_problem_bad_input():
    fam = tuning.LQRFamily(PLANT)
    with pytest.raises(ValueError, match=r"scenarios\[1\] must have n=2 states and m=1 inputs like scenarios\[0\]"):
        tuning.TuningProblem(fam, [PLANT, rc.Plant(np.eye(3), np.ones((3, 1)), dt=0.1)], [effort])
    with pytest.raises(ValueError, match=r"scenarios\[1\] must have the sampling time of scenarios\[0\]"):
        tuning.TuningProblem(fam, [PLANT, rc.Plant(PLANT.F, PLANT.G, dt=0.2)], [effort])
    with pytest.raises(TypeError, match="scenarios must be a non-empty list"):
        tuning.TuningProblem(fam, PLANT, [effort])
    with pytest.raises(TypeError, match=r"scenarios must be a non-empty list of robustctl\.Plant, got an empty list"):
        tuning.TuningProblem(fam, [], [effort])
    with pytest.raises(ValueError, match=r"bounds inverted.*xl\[1\]"):
        tuning.TuningProblem(fam, SCENARIOS, [effort], xl=[0, 2, 0], xu=[1, 1, 1])
    with pytest.raises(ValueError, match="family gives controllers for n=3 states and m=1 inputs"):
        tuning.TuningProblem(tuning.LQRFamily(rc.Plant(0.5 * np.eye(3), np.ones((3, 1)), dt=0.1)), SCENARIOS, [effort])
    with pytest.raises(TypeError, match=r"objectives\[0\] must be callable"):
        tuning.TuningProblem(fam, SCENARIOS, ["x"])
    with pytest.raises(ValueError, match="hv_ref_point must have 1 columns"):
        tuning.TuningProblem(fam, SCENARIOS, [effort], hv_ref_point=[1, 2])

    def wrong_shape(K, plants):
        return np.zeros((K.shape[0], 2))

    prob = tuning.TuningProblem(fam, SCENARIOS, [effort, wrong_shape])
    with pytest.raises(ValueError, match=r"goal 'wrong_shape' must return shape \(2,\)"):
        prob.evaluate(np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"X must have shape \(B, 3\)"):
        prob.evaluate(np.zeros((2, 4)))

    class Checked:
        name = "checked"

        def check(self, plants):
            raise ValueError("states index 5 out of range")

        def __call__(self, K, plants):
            return np.zeros(len(K))

    with pytest.raises(ValueError, match="out of range"):
        tuning.TuningProblem(fam, SCENARIOS, [Checked()])


# -- tune, select, plot -------------------------------------------------------------------
def test_tune_select_plot():
    import matplotlib

    matplotlib.use("Agg")
    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [effort, radius], hv_ref_point=[100.0, 1.0])
    res = tuning.tune(prob, evals=300, seed=1, pop_size=20)
    again = tuning.tune(prob, evals=300, seed=1, pop_size=20)
    np.testing.assert_array_equal(res.F, again.F)
    assert res.X.shape[0] == res.F.shape[0] >= 2 and res.gains.shape == (len(res.X), 1, 2)
    np.testing.assert_allclose(prob.evaluate(res.X), res.F)
    ctrls = res.controllers()
    assert all(c.method == "lqr" and c.is_stabilizing() for c in ctrls)
    sel = res.select(n_sims=60, seed=0)
    assert sel.counts.sum() == 60 and sel.controller.K.shape == (1, 2)
    np.testing.assert_array_equal(sel.K, res.gains[sel.index])
    # the counting rule by hand: per-scenario objectives, weights 1 / spread of the front
    w = 1.0 / (res.F.max(axis=0) - res.F.min(axis=0))
    per = np.stack([np.stack([effort(res.gains, [p]), radius(res.gains, [p])], axis=1) @ w for p in SCENARIOS], 1)
    E = per[:, sel.draws]
    np.testing.assert_allclose(sel.errors, E, rtol=1e-12)
    assert sel.index == np.argmax(np.bincount(E.argmin(axis=0), minlength=len(E)))
    fig = res.plot(sel)
    assert len(fig.axes) == 2
    with pytest.raises(TypeError, match=r"problem must be a moo\.tuning\.TuningProblem"):
        tuning.tune("generic")


def test_select_with_sampler():
    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [effort, radius])
    K = tuning.LQRFamily(PLANT).gains(np.array([[0.0, 0.0, 0.0], [1.0, 1.0, -1.0]])).K

    def sampler(rng):
        return rc.Plant(PLANT.F * rng.uniform(0.9, 1.1), PLANT.G, dt=0.1)

    sel = tuning.select(prob, K, n_sims=20, seed=3, sampler=sampler, weights=[0.0, 1.0])
    assert np.all(sel.draws == -1) and sel.errors.shape == (2, 20)
    # the errors are the spectral radius on each drawn plant alone (weight 0 on the effort)
    rng = np.random.default_rng(3)
    plants = [sampler(rng) for _ in range(20)]
    np.testing.assert_allclose(sel.errors, np.stack([radius(K, [p]) for p in plants], 1), rtol=1e-12)


def test_tune_options_and_record():
    import json

    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [effort, radius])
    res = tuning.tune(prob, "spea2-sde", molsp=False, evals=60, seed=0, pop_size=20)
    assert not res.run.molsp and res.run.algorithm == "spea2-sde" and res.run.n_evals >= 60
    json.dumps(res.run.to_dict())
    assert "TuningResult(front=" in repr(res)
    with pytest.raises(ValueError, match="evals must be at least the population size"):
        tuning.tune(prob, evals=10, pop_size=20)
    with pytest.raises(ValueError, match="max_leaders needs molsp=True"):
        tuning.tune(prob, molsp=False, max_leaders=3, evals=40, pop_size=20)
    with pytest.raises(ValueError, match="unknown algorithm"):
        tuning.tune(prob, "nope", evals=40, pop_size=20)


def test_sample_reference_points_by_hand():
    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [effort, radius])
    hv, ms = prob.sample_reference_points(200, seed=4, margin=0.5)
    Z = np.random.default_rng(4).uniform(prob.xl, prob.xu, (200, prob.n_var))
    F = prob.evaluate(Z)
    ok = np.all(prob.penalty > F, axis=1)
    Fa = F[ok]
    nd = np.array([not np.any(np.all(Fa <= f, axis=1) & np.any(Fa < f, axis=1)) for f in Fa])
    lo, hi = Fa[nd].min(axis=0), Fa[nd].max(axis=0)
    np.testing.assert_allclose(hv, hi + 0.5 * (hi - lo))
    np.testing.assert_allclose(ms, np.maximum(Fa.max(axis=0), hi) + 0.5 * (hi - lo))
    assert np.all(Fa[nd] < hv) and np.all(Fa < ms)
    def huge(K, plants):                 # above the penalty: clipped, never acceptable
        return np.full(len(K), 2e6)

    tight = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [huge])
    with pytest.raises(ValueError, match="none of the 20 sampled designs is acceptable"):
        tight.sample_reference_points(20)
