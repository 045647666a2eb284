"""Output-feedback families and the goals on their loops, each against an independent construction (issue 35)."""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.linalg

import robustctl as rc
from moo import tuning
from robustctl.sim import simulate_output_feedback

DT = 0.1
# a lightly damped two-mass system with one measured output (the first position)
F0 = scipy.linalg.expm(DT * np.array([[0.0, 1.0, 0.0, 0.0], [-2.0, -0.2, 2.0, 0.0],
                                      [0.0, 0.0, 0.0, 1.0], [1.0, 0.0, -1.0, -0.1]]))
G0 = np.array([[0.0], [0.1], [0.0], [0.0]])
C0 = np.array([[1.0, 0.0, 0.0, 0.0]])
PLANT = rc.Plant(F0, G0, DT, C=C0)


def _poles(sys) -> np.ndarray:
    return np.sort_complex(np.asarray(sys.poles()))


def _random_plant(rng, n, m, p, dt=DT, feedthrough=False):
    F = rng.standard_normal((n, n))
    F *= (0.95 if dt else 1.0) / np.abs(np.linalg.eigvals(F)).max()
    if dt is None:
        F -= 1.2 * np.eye(n)
    return rc.Plant(F, rng.standard_normal((n, m)), dt, C=rng.standard_normal((p, n)),
                    D=0.2 * rng.standard_normal((p, m)) if feedthrough else None)


# -- families -------------------------------------------------------------------------------
@pytest.mark.parametrize("dt", [DT, None])
def test_static_output_feedback_loops_are_python_controls_feedback(dt):
    rng = np.random.default_rng(1)
    plant = _random_plant(rng, 4, 2, 3, dt, feedthrough=True)
    fam = tuning.StaticOutputFeedbackFamily(plant)
    assert fam.n_var == 6 and fam.feedback == "output"
    Z = 0.05 * rng.uniform(fam.xl, fam.xu, (5, fam.n_var))
    batch = fam.gains(Z).controllers
    A = batch.closed_loops()
    for z, a in zip(Z, A, strict=True):
        K = control.ss(np.zeros((0, 0)), np.zeros((0, 3)), np.zeros((2, 0)), z.reshape(2, 3), 0 if dt is None else dt)
        loop = control.feedback(plant.to_statespace(), K, sign=+1)
        np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(a)), _poles(loop), rtol=1e-9, atol=1e-10)


def _textbook_pid(Kp, Ki, Kd, Tf, h):
    """Forward-difference integral, backward-difference filtered derivative (Astrom & Murray, Sec. 11.5)."""
    return control.tf([Kp], [1], h) + control.tf([Ki * h], [1, -1], h) + control.tf([Kd, -Kd], [Tf + h, -Tf], h)


def test_pid_family_is_minus_the_textbook_pid_per_loop():
    rng = np.random.default_rng(2)
    plant = _random_plant(rng, 4, 2, 2)
    fam = tuning.PIDFamily(plant, loops=[(1, 0), (0, 1)], sign=[1, -1])
    assert fam.n_var == 8 and fam.parameters[:4] == ("Kp[0]", "Ki[0]", "Kd[0]", "Tf[0]")
    Z = rng.uniform(fam.xl, fam.xu, (3, fam.n_var))
    prm = fam.pid_parameters(Z)
    batch = fam.gains(Z).controllers
    w = np.exp(1j * np.linspace(0.05, 3.1, 9))
    for b in range(3):
        K = batch[b].controller_statespace()(w)                      # (m, p, len(w)): u_j from y_i
        for k, ((i, j), s) in enumerate(zip(fam.loops, fam.signs, strict=True)):
            C = _textbook_pid(*(prm[name][b, k] for name in ("Kp", "Ki", "Kd", "Tf")), DT)(w)
            np.testing.assert_allclose(K[j, i], -s * C, rtol=1e-9)
            np.testing.assert_allclose(K[j, 1 - i], 0.0, atol=1e-12)   # decentralised


def test_pid_in_u_equals_K_of_y_minus_r_tracks_like_the_textbook_loop():
    # e = r - y, u = C(z) e: python-control's negative feedback of P C; ours u = K(z) (y - r), K = -C
    fam = tuning.PIDFamily(PLANT, terms="pi")
    z = np.array([[-1.75, -3.0]])                                         # a stable (slow) PI of the two masses
    batch = fam.gains(z).controllers
    prm = fam.pid_parameters(z)
    C = _textbook_pid(prm["Kp"][0, 0], prm["Ki"][0, 0], 0.0, 1.0, DT)
    loop = control.feedback(PLANT.to_statespace() * C)
    T = 4000
    _, y_pc = control.step_response(loop, np.arange(T) * DT)
    res = simulate_output_feedback(batch, [PLANT], T, reference=np.ones((T, 1)))
    np.testing.assert_allclose(res.outputs[0, 0, :, 0], y_pc, atol=1e-9)
    assert abs(res.outputs[0, 0, -1, 0] - 1.0) < 1e-2                   # integral action


def test_pid_sign_follows_the_plants_gain():
    assert tuning.PIDFamily(PLANT).signs.tolist() == [1.0]
    assert tuning.PIDFamily(rc.Plant(F0, -G0, DT, C=C0)).signs.tolist() == [-1.0]
    with pytest.raises(ValueError, match="loops must be given for a plant with p=1 outputs and m=2 inputs"):
        tuning.PIDFamily(rc.Plant(F0, np.hstack([G0, G0]), DT, C=C0))
    with pytest.raises(ValueError, match="loops must use each input once"):
        tuning.PIDFamily(rc.Plant(F0, G0, DT, C=np.eye(2, 4)), loops=[(0, 0), (1, 0)])
    with pytest.raises(ValueError, match="sign must be 'auto', \\+1, -1"):
        tuning.PIDFamily(PLANT, sign=2)
    with pytest.raises(ValueError, match="must be discrete-time"):
        tuning.PIDFamily(rc.Plant(-np.eye(4), G0, None, C=C0))


def test_fixed_order_family_against_its_own_parametrisation_and_python_control():
    rng = np.random.default_rng(3)
    plant = _random_plant(rng, 3, 2, 2)
    fam = tuning.FixedOrderFamily(plant, order=3, pole_radius=0.9)
    assert fam.n_var == 3 + 6 + 6 + 4
    Z = rng.uniform(fam.xl, fam.xu, (50, fam.n_var))
    batch = fam.gains(Z).controllers
    for z, b in zip(Z[:5], range(5), strict=False):
        # the Notes' parametrisation, written out: z^2 - t z + d with d = r^2 v, t = r u (1 + v); pole r u
        r = 0.9
        d, t = r * r * z[1], r * z[0] * (1 + z[1])
        want = np.sort_complex(np.r_[np.roots([1.0, -t, d]), r * z[2]])
        np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(batch.Ac[b])), want, atol=1e-12)
        K = control.ss(batch.Ac[b], z[3:9].reshape(3, 2), z[9:15].reshape(2, 3), z[15:].reshape(2, 2), DT)
        loop = control.feedback(plant.to_statespace(), K, sign=+1)
        np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(batch.closed_loops()[b])), _poles(loop),
                                   rtol=1e-8, atol=1e-10)
    assert np.abs(np.linalg.eigvals(batch.Ac)).max() <= 0.9 + 1e-12


# -- goals on dynamic loops ---------------------------------------------------------------------------
def _batch(seed=4, B=3):
    """Stabilising first-order controllers of PLANT (found by rejection)."""
    rng = np.random.default_rng(seed)
    fam = tuning.FixedOrderFamily(PLANT, order=2, pole_radius=0.9)
    while True:
        Z = 0.3 * rng.uniform(fam.xl, fam.xu, (400, fam.n_var))
        batch = fam.gains(Z).controllers
        good = batch.is_stabilizing()
        if good.sum() >= B:
            idx = np.flatnonzero(good)[:B]
            return rc.ControllerBatch(PLANT, batch.Ac[idx], batch.Bc[idx], batch.Cc[idx], batch.Dc[idx])


def _loop_system(batch, b, plant, Bw=None, Cz=None, Dzu=None, V=False):
    """The closed loop from (w[, v]) to z by control.interconnect (states: plant, then controller)."""
    dt = plant.dt or 0
    n, m, p = plant.n, plant.m, plant.p
    C, D = plant.output_matrices()
    Bw = np.zeros((n, 1)) if Bw is None else Bw
    Cz, Dzu = (C, D) if Cz is None else (Cz, np.zeros((Cz.shape[0], m)) if Dzu is None else Dzu)
    q, l = Bw.shape[1], Cz.shape[0]
    P = control.ss(plant.F, np.hstack([plant.G, Bw]), np.vstack([C, Cz]),
                   np.block([[D, np.zeros((p, q))], [Dzu, np.zeros((l, q))]]), dt,
                   inputs=[*(f"u[{i}]" for i in range(m)), *(f"w[{i}]" for i in range(q))],
                   outputs=[*(f"y[{i}]" for i in range(p)), *(f"z[{i}]" for i in range(l))])
    ctrl = batch[b]
    K = control.ss(ctrl.Ac, ctrl.Bc, ctrl.Cc, ctrl.Dc, dt, inputs=[f"ym[{i}]" for i in range(p)],
                   outputs=[f"u[{i}]" for i in range(m)])
    noise = control.summing_junction(inputs=["y", "v"], output="ym", dimension=p)
    inputs = [f"w[{i}]" for i in range(q)] + ([f"v[{i}]" for i in range(p)] if V else [])
    return control.interconnect([P, K, noise], inplist=inputs, outlist=[f"z[{i}]" for i in range(l)],
                                check_unused=False)


def test_spectral_radius_pole_region_and_controller_poles_of_dynamic_loops():
    batch = _batch()
    rho = tuning.SpectralRadius()(batch, [PLANT])
    Acl = batch.closed_loops()
    for b in range(len(batch)):
        loop = control.feedback(PLANT.to_statespace(), batch[b].controller_statespace(), sign=+1)
        assert rho[b] == pytest.approx(np.abs(loop.poles()).max(), rel=1e-10)
        np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(Acl[b])), _poles(loop), atol=1e-10)
    disk = tuning.PoleRegion(rc.Disk(0.0, 0.97))(batch, [PLANT])
    np.testing.assert_allclose(disk, rho - 0.97, atol=1e-12)
    np.testing.assert_allclose(tuning.ControllerPoles()(batch, [PLANT]),
                               np.abs(np.linalg.eigvals(batch.Ac)).max(axis=1), rtol=1e-12)


def test_h2_hinf_and_variance_of_dynamic_loops_against_python_control():
    batch = _batch()
    Bw = np.array([[0.0], [1.0], [0.0], [0.5]])
    Cz = np.array([[0.0, 0.0, 1.0, 0.0]])
    Dzu = np.array([[0.3]])
    h2 = tuning.H2Norm(Bw, Cz, Dzu)(batch, [PLANT])
    hinf = tuning.HinfNorm(Bw, Cz, Dzu)(batch, [PLANT])
    W, V = np.array([[2.0]]), np.array([[0.01]])
    var = tuning.Variance(Bw, W=W, V=V, Cz=Cz, Dzu=Dzu)(batch, [PLANT])
    for b in range(len(batch)):
        sys = _loop_system(batch, b, PLANT, Bw, Cz, Dzu)
        assert h2[b] == pytest.approx(control.norm(sys, 2), rel=1e-8)
        assert hinf[b] == pytest.approx(control.norm(sys, "inf"), rel=1e-6)
        noisy = _loop_system(batch, b, PLANT, Bw, Cz, Dzu, V=True) * control.ss([], [], [], scipy.linalg.block_diag(
            np.sqrt(W), np.sqrt(V)), DT)
        assert var[b] == pytest.approx(control.norm(noisy, 2) ** 2, rel=1e-8)


def test_variance_of_a_continuous_static_output_feedback():
    rng = np.random.default_rng(5)
    plant = _random_plant(rng, 3, 1, 2, dt=None)
    fam = tuning.StaticOutputFeedbackFamily(plant)
    batch = fam.gains(0.02 * rng.uniform(fam.xl, fam.xu, (4, fam.n_var))).controllers
    assert batch.is_stabilizing().all()
    Bw = rng.standard_normal((3, 2))
    var = tuning.Variance(Bw, V=0.1 * np.eye(2), Cz=np.eye(3))(batch, [plant])
    for b in range(4):
        sys = _loop_system(batch, b, plant, Bw, np.eye(3), V=True) * control.ss([], [], [], scipy.linalg.block_diag(
            np.eye(2), np.sqrt(0.1) * np.eye(2)))
        assert var[b] == pytest.approx(control.norm(sys, 2) ** 2, rel=1e-8)


def test_robust_margin_of_dynamic_loops_is_the_inverse_norm_of_the_uncertainty_channel():
    batch = _batch()
    scenarios = [rc.Plant(F0 + d * np.outer(G0[:, 0], [0.5, 0.0, -0.5, 0.0]), G0, DT, C=C0) for d in (-1.0, 1.0)]
    unc = rc.NormBounded.from_plants(PLANT, scenarios)
    margin = tuning.RobustMargin(unc, nominal=PLANT).measure(batch, [PLANT])
    for b in range(len(batch)):
        sys = _loop_system(batch, b, PLANT, unc.H, unc.EF, unc.EG)
        assert margin[b] == pytest.approx(1.0 / control.norm(sys, "inf"), rel=1e-6)


def test_response_goals_of_dynamic_loops_against_forced_response():
    batch = _batch()
    T = 120
    step = tuning.StepTracking(T, signal=0, amplitude=0.5, width=1, n=4)
    mse, over, peak = step.error(), step.overshoot(), step.peak_input()
    values = [goal(batch, [PLANT]) for goal in (mse, over, peak)]
    for b in range(len(batch)):
        loop = control.interconnect(
            [control.ss(F0, G0, np.vstack([C0, np.zeros((1, 4))]), [[0.0], [1.0]], DT, inputs="u",
                        outputs=["y", "uo"]),
             control.ss(batch.Ac[b], batch.Bc[b], batch.Cc[b], batch.Dc[b], DT, inputs="e", outputs="u"),
             control.summing_junction(inputs=["y", "-r"], output="e")], inplist="r", outlist=["y", "uo"])
        resp = control.forced_response(loop, np.arange(T) * DT, 0.5 * np.ones(T))
        y, u = resp.outputs
        assert values[0][b] == pytest.approx(np.mean((y - 0.5) ** 2), rel=1e-9)
        assert values[1][b] == pytest.approx(max(0.0, (y.max() - 0.5) / 0.5), abs=1e-9)
        assert values[2][b] == pytest.approx(np.abs(u).max(), rel=1e-9)


def test_a_user_goal_of_a_dynamic_family_gets_a_controller_batch():
    seen = []

    def looks(K, plants):
        seen.append(type(K).__name__)
        assert isinstance(K, rc.ControllerBatch) and all(p.has_outputs for p in plants)
        return np.abs(K.Dc).sum(axis=(1, 2))

    scenarios = [rc.Plant(F0, G0 * s, DT) for s in (0.9, 1.1)]          # no outputs: the family's C is read
    prob = tuning.TuningProblem(tuning.StaticOutputFeedbackFamily(PLANT), scenarios, [looks, tuning.SpectralRadius()],
                                hv_ref_point=[100.0, 1.0])
    F = prob.evaluate(np.array([[-0.5], [-30.0], [5.0]]))
    assert seen and set(seen) == {"ControllerBatch"}
    rho = tuning.SpectralRadius()(prob.gains(np.array([[-0.5]])).controllers, prob.scenarios)
    assert F[0, 0] == pytest.approx(0.5) and F[0, 1] == pytest.approx(rho[0])
    assert prob.last_flags[1:].tolist() == ["unstable", "unstable"] and np.all(F[1:] >= prob.penalty)


def test_output_feedback_problems_refuse_mismatched_outputs_by_name():
    fam = tuning.StaticOutputFeedbackFamily(PLANT)
    other = rc.Plant(F0, G0, DT, C=np.eye(2, 4))
    with pytest.raises(ValueError, match=r"scenarios\[1\] has p=2 outputs, the family's controllers read p=1"):
        tuning.TuningProblem(fam, [PLANT, other], [tuning.SpectralRadius()])
    cont = rc.Plant(-np.eye(4), G0, None, C=C0)
    with pytest.raises(ValueError, match="SpectralRadius needs discrete-time plants"):
        tuning.TuningProblem(tuning.StaticOutputFeedbackFamily(cont), [cont], [tuning.SpectralRadius()])


# -- LQG families ----------------------------------------------------------------------------------------------
def test_lqg_family_is_dlqr_on_dlqe_by_the_separation_principle():
    rng = np.random.default_rng(6)
    plant = _random_plant(rng, 3, 2, 2)
    fam = tuning.LQGFamily(plant, Bw=np.eye(3), log_bound=2.0)
    assert fam.n_var == 3 + 2 + 3 + 2 and fam.order == 3
    Z = rng.uniform(fam.xl, fam.xu, (4, fam.n_var))
    res = fam.gains(Z)
    assert res.ok.all()
    Q, R, W, V = fam.weights(Z)
    for b in range(4):
        K = -control.dlqr(plant.F, plant.G, Q[b], R[b])[0]
        Lp = control.dlqe(plant.F, np.eye(3), plant.C, W[b], V[b])[0]
        want = np.r_[np.linalg.eigvals(plant.F + plant.G @ K), np.linalg.eigvals(plant.F - Lp @ plant.C)]
        got = np.linalg.eigvals(res.controllers.closed_loops()[b])
        np.testing.assert_allclose(np.sort_complex(got), np.sort_complex(want), rtol=1e-7, atol=1e-9)
        # the current estimator's control law: u = K (xc + Lf (y - C xc)), Lf = P C' (C P C' + V)^-1
        P = control.dlqe(plant.F, np.eye(3), plant.C, W[b], V[b])[1]
        Lf = P @ plant.C.T @ np.linalg.inv(plant.C @ P @ plant.C.T + V[b])
        np.testing.assert_allclose(res.controllers.Dc[b], K @ Lf, rtol=1e-7, atol=1e-10)
        one = rc.lqg(plant, Q=Q[b], R=R[b], W=W[b], V=V[b], Bw=np.eye(3))               # the single design
        for name in ("Ac", "Bc", "Cc", "Dc"):
            np.testing.assert_allclose(getattr(res.controllers, name)[b], getattr(one, name), rtol=1e-7, atol=1e-9)


def test_robust_lqg_family_equals_single_rlqr_and_robust_filter_designs():
    rng = np.random.default_rng(7)
    plant = rc.Plant(F0, G0, DT, C=C0)
    fam = tuning.RobustLQGFamily(plant, W=1e-3 * np.eye(4), V=[[1e-2]])
    assert fam.n_var == 4 + 1 + 2
    Z = np.c_[rng.uniform(0.0, 0.5, (6, 5)), rng.uniform(4.0, 36.0, (6, 2))]
    res = fam.gains(Z)
    EF, EG, mu, mu_f = fam.decode(Z)
    compared = 0
    for b in np.flatnonzero(res.ok):
        try:
            one = rc.rlqg(plant, EF[b], EG[b], mu[b], H=fam.H, W=1e-3 * np.eye(4), V=[[1e-2]], Bw=np.eye(4),
                          mu_filter=mu_f[b], check_stability=False)
        except rc.NotStabilizingError:          # rlqg refuses an RLQR gain that alone does not stabilise the plant
            continue
        for name in ("Ac", "Bc", "Cc", "Dc"):
            np.testing.assert_allclose(getattr(res.controllers, name)[b], getattr(one, name), rtol=1e-6, atol=1e-9)
        compared += 1
    assert compared >= 2
    # a design that cannot be computed is flagged (NaN controller, a reason), never raised for the population
    wide = fam.gains(np.random.default_rng(0).uniform(fam.xl, fam.xu, (200, fam.n_var)))
    failed = ~wide.ok
    assert failed.any() and wide.ok.sum() > 100
    assert set(wide.reason[failed]) == {"regulator: not converged"} and np.isnan(wide.controllers.Ac[failed]).all()


def test_lqg_families_refuse_plants_they_cannot_serve():
    with pytest.raises(ValueError, match="plant must have measured outputs"):
        tuning.LQGFamily(rc.Plant(F0, G0, DT))
    blind = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], DT, C=[[0.0, 1.0]])
    with pytest.raises(ValueError, match="plant must be detectable"):
        tuning.RobustLQGFamily(blind)


def test_a_tuned_output_feedback_result_gives_controllers_a_selection_and_a_figure():
    import matplotlib

    matplotlib.use("Agg")
    step = tuning.StepTracking(100, width=1, n=4)
    prob = tuning.TuningProblem(tuning.PIDFamily(PLANT, terms="pi"), [PLANT], [step.error(), step.peak_input()])
    res = tuning.tune(prob, evals=200, seed=0, pop_size=20)
    ctrls = res.controllers()
    assert len(ctrls) == len(res.X) and all(c.is_dynamic and c.method == "pid" and c.is_stabilizing() for c in ctrls)
    sel = res.select(n_sims=20, seed=0)
    assert sel.K is None and sel.controller.order == 1
    np.testing.assert_allclose(sel.controller.Dc, res.gains.Dc[sel.index])
    assert len(res.plot(sel).axes) == 2
