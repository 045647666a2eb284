"""Loop goals (disk margin, gain and phase margins, sensitivity peaks) against python-control (issue 35)."""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.linalg
from scipy.optimize import brentq

import robustctl as rc
from moo import tuning

DT = 0.1
F0 = scipy.linalg.expm(DT * np.array([[0.0, 1.0, 0.0, 0.0], [-2.0, -0.2, 2.0, 0.0],
                                      [0.0, 0.0, 0.0, 1.0], [1.0, 0.0, -1.0, -0.1]]))
G0 = np.array([[0.0], [0.1], [0.0], [0.0]])
C0 = np.array([[1.0, 0.0, 0.0, 0.0]])
PLANT = rc.Plant(F0, G0, DT, C=C0)
SCENARIOS = [rc.Plant(F0, G0 * s, DT, C=C0) for s in (0.8, 1.0, 1.25)]


def _pids(B=4, seed=0):
    """Stabilising PIDs of PLANT on every scenario (rejection sampling)."""
    fam = tuning.PIDFamily(PLANT)
    rng = np.random.default_rng(seed)
    while True:
        Z = rng.uniform(fam.xl, fam.xu, (2000, fam.n_var))
        batch = fam.gains(Z).controllers
        good = np.all([batch.is_stabilizing(p) for p in SCENARIOS], axis=0)
        if good.sum() >= B:
            idx = np.flatnonzero(good)[:B]
            return rc.ControllerBatch(PLANT, batch.Ac[idx], batch.Bc[idx], batch.Cc[idx], batch.Dc[idx])


def _loop_at_input(plant, ctrl):
    """``L = -K(z) P(z)`` by python-control (negative-feedback convention)."""
    P = control.ss(plant.F, plant.G, plant.C, plant.D, plant.dt)
    return -ctrl.controller_statespace() * P


def test_disk_margin_of_pid_loops_is_python_controls_at_our_peak():
    batch = _pids()
    goal = tuning.DiskMargin()
    alpha = np.stack([goal.measure(batch, [p]) for p in SCENARIOS], axis=1)         # (B, S)
    np.testing.assert_allclose(goal.measure(batch, SCENARIOS), alpha.min(axis=1), rtol=1e-12)
    for s, plant in enumerate(SCENARIOS):
        freq = rc.loop_margins(rc.ControllerBatch(plant, batch.Ac, batch.Bc, batch.Cc, batch.Dc)).alpha_freq
        for b in range(len(batch)):
            L = _loop_at_input(plant, batch[b])
            dm = control.disk_margins(L, np.array([freq[b]]))[0]
            assert alpha[b, s] == pytest.approx(float(dm), rel=1e-8)
            grid = control.disk_margins(L, np.logspace(-3, np.log10(0.999 * np.pi / DT), 2000))[0]
            assert alpha[b, s] <= float(grid) * (1 + 1e-9)                      # a grid only estimates from above
    np.testing.assert_allclose(goal(batch, SCENARIOS), 1.0 / alpha.min(axis=1), rtol=1e-12)


def _crossings(L, what):
    """Where ``|L| = 1`` (``"gain"``) or ``Im L = 0``, ``Re L < 0`` (``"phase"``): a dense grid, then brentq."""
    Lw = lambda w: L(np.exp(1j * w * DT))                                              # noqa: E731
    ws = np.linspace(1e-5, np.pi / DT, 100001)
    f = (lambda w: np.abs(Lw(w)) - 1.0) if what == "gain" else (lambda w: np.imag(Lw(w)))
    v = f(ws)
    roots = [brentq(f, ws[k], ws[k + 1], xtol=1e-15) for k in np.flatnonzero(np.sign(v[:-1]) != np.sign(v[1:]))]
    return [w for w in roots if what == "gain" or np.real(Lw(w)) < 0]


def test_classical_margins_and_sensitivity_peaks_of_pid_loops():
    # python-control's stability_margins is off on these lightly damped loops (by up to 2e-5 relative, and on one
    # loop it reports a phase margin at no crossing at all): the references are the crossings found by brentq
    batch = _pids()
    ratio = tuning.Margins(gain_db=6.0, phase_deg=30.0, kind="classical")(batch, [PLANT])
    s_peak = tuning.SensitivityPeak()(batch, [PLANT])
    t_peak = tuning.SensitivityPeak("T")(batch, [PLANT])
    for b in range(len(batch)):
        L = _loop_at_input(PLANT, batch[b])
        Lw = lambda w: L(np.exp(1j * w * DT))                                          # noqa: E731, B023
        pms = [np.degrees(np.angle(Lw(w))) % 360 - 180 for w in _crossings(L, "gain")]
        gms = [1.0 / abs(Lw(w)) for w in _crossings(L, "phase")]
        pm = min(pms, key=abs)                                      # the crossing closest to the boundary
        gm = min(gms, key=lambda g: abs(np.log(g)))
        assert ratio[b] == pytest.approx(max(6.0 / abs(20 * np.log10(gm)), 30.0 / pm), rel=1e-9)
        S = control.feedback(control.ss([], [], [], [[1.0]], DT), L)
        assert s_peak[b] == pytest.approx(control.linfnorm(S, tol=1e-12)[0], rel=1e-9)     # SLICOT AB13DD
        assert t_peak[b] == pytest.approx(control.linfnorm(control.feedback(L), tol=1e-12)[0], rel=1e-9)
    # on a well-damped loop python-control's classical margins agree
    K = -control.dlqr([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], np.eye(2), [[1.0]])[0]
    plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], DT)
    gm, pm = control.stability_margins(control.ss(plant.F, plant.G, -K, 0, DT))[:2]
    value = tuning.Margins(gain_db=6.0, phase_deg=30.0, kind="classical")(K[None], [plant])
    assert value[0] == pytest.approx(max(6.0 / abs(20 * np.log10(gm)), 30.0 / pm), rel=1e-8)


def test_disk_based_margins_goal_and_its_requirement():
    batch = _pids()
    alpha = tuning.DiskMargin().measure(batch, [PLANT])
    value = tuning.Margins(gain_db=6.0, phase_deg=45.0)(batch, [PLANT])
    np.testing.assert_allclose(value, tuning.margins.required_disk_margin(6.0, 45.0) / alpha, rtol=1e-12)
    # the balanced disk of the required alpha guarantees the requirements (robustctl.disk_ranges, Seiler et al.)
    gain, phase = rc.disk_ranges(tuning.margins.required_disk_margin(6.0, 45.0))
    assert 20 * np.log10(gain[1]) >= 6.0 - 1e-9 and phase >= 45.0 - 1e-9
    with pytest.raises(ValueError, match="phase_deg must be in"):
        tuning.Margins(phase_deg=190.0)


def test_weighted_sensitivity_peak_against_python_controls_norm():
    batch = _pids(B=3)
    W = control.tf([0.5, 0.0], [1.0, -0.6], DT)                                  # a high-pass weight
    peak = tuning.SensitivityPeak(weight=W)(batch, [PLANT])
    for b in range(3):
        S = control.feedback(control.ss([], [], [], [[1.0]], DT), _loop_at_input(PLANT, batch[b]))
        assert peak[b] == pytest.approx(control.linfnorm(control.ss(W) * S, tol=1e-12)[0], rel=1e-9)
    with pytest.raises(ValueError, match="weight must be stable"):
        tuning.SensitivityPeak(weight=control.tf([1.0], [1.0, -1.5], DT))
    with pytest.raises(ValueError, match="weight must be of the plants' time domain"):
        tuning.SensitivityPeak(weight=control.tf([1.0], [1.0, 1.0])).check([PLANT])


def test_margin_goals_of_state_feedback_and_of_a_continuous_static_output_feedback():
    K = -control.dlqr(PLANT.F, PLANT.G, np.eye(4), [[1.0]])[0]
    alpha = tuning.DiskMargin().measure(K[None], [PLANT])
    L = control.ss(PLANT.F, PLANT.G, -K, 0, DT)
    w = rc.loop_margins((PLANT, K)).alpha_freq
    assert alpha[0] == pytest.approx(float(control.disk_margins(L, np.array([w]))[0]), rel=1e-8)
    # a continuous plant: no sampling needed
    A = np.array([[0.0, 1.0], [-1.0, -0.2]])
    plant = rc.Plant(A, [[0.0], [1.0]], None, C=[[1.0, 1.0]])
    batch = tuning.StaticOutputFeedbackFamily(plant).gains(np.array([[-0.5], [-2.0]])).controllers
    alpha = tuning.DiskMargin().measure(batch, [plant])
    for b in range(2):
        Lc = -batch[b].controller_statespace() * control.ss(plant.F, plant.G, plant.C, 0)
        wb = rc.loop_margins(batch[b]).alpha_freq
        assert alpha[b] == pytest.approx(float(control.disk_margins(Lc, np.array([wb]))[0]), rel=1e-8)


def test_margin_goals_in_a_tuning_problem():
    step = tuning.StepTracking(100, width=1, n=4)
    prob = tuning.TuningProblem(tuning.PIDFamily(PLANT), SCENARIOS, [tuning.DiskMargin(), step.error()],
                                [tuning.at_most(tuning.Margins(gain_db=3.0, phase_deg=20.0), 1.0)])
    res = tuning.tune(prob, evals=300, seed=0, pop_size=20)
    assert len(res.F) >= 1 and np.all(prob.penalty > res.F)
    _, G = prob.evaluate_gains(res.gains)
    assert np.all(G <= 1e-12)                                             # feasible: the margins are met
