"""loop_margins against python-control (stability_margins, disk_margins on fine grids and at our peak),
the disk-margin literature (Seiler, Packard & Gahinet 2020; MATLAB's diskmargin and dm2gm pages), closed
forms, loops built by hand with python-control (the sign convention), stacks against single calls, bad input."""

from __future__ import annotations

import sys
import warnings

import control
import numpy as np
import pytest

import robustctl as rc
from robustctl.analysis import _loop_kernels

s = control.tf("s")
HAS_SLYCOT = control.exception.slycot_check()
needs_slycot = pytest.mark.skipif(not HAS_SLYCOT, reason="python-control's MIMO disk_margins needs slycot (AB13MD)")


def pc_disk_margin(L, w, skew=0.0) -> float:
    """python-control's disk margin at the frequencies ``w`` (its minimum over them)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return float(control.disk_margins(L, np.atleast_1d(np.asarray(w, dtype=float)), skew=skew)[0])


def grid(L, points: int = 4000) -> np.ndarray:
    """A fine frequency grid for ``L``: log-spaced (continuous) or up to the Nyquist frequency (discrete)."""
    if L.isdtime(strict=True):
        return np.linspace(1e-6, np.pi / L.dt, points)
    return np.logspace(-4, 4, points)


def random_loop(rng, n: int, m: int, discrete: bool, gain: float = 1.0):
    """A random m x m loop of order n: stable open loop (poles in the left half plane or inside 0.95 of the unit
    circle), unit-variance B and C, scaled by ``gain`` (its closed loop may be unstable)."""
    A = rng.standard_normal((n, n))
    if discrete:
        A *= 0.95 / np.max(np.abs(np.linalg.eigvals(A)))
    else:
        A -= (np.max(np.linalg.eigvals(A).real) + rng.uniform(0.05, 1.0)) * np.eye(n)
    B, C = rng.standard_normal((n, m)), gain * rng.standard_normal((m, n))
    return control.ss(A, B, C, np.zeros((m, m)), 0.05 if discrete else 0)


def random_siso(seed: int, discrete: bool):
    rng = np.random.default_rng(seed)
    return random_loop(rng, int(rng.integers(1, 7)), 1, discrete, float(rng.choice([0.3, 1.0, 3.0])))


# ---------------------------------------------------------------- SISO: python-control
# python-control's own margin fixtures (control/tests/margin_test.py) and the two SISO loops of Seiler et al.
SISO = [control.tf([1, 2], [1, 2, 3]), control.tf([1], [1, 2, 3, 4]),
        control.ss([[1.0, 4.0], [3.0, 2.0]], [[1.0], [-4.0]], [[1.0, 0.0]], [[0.0]]),
        8.75 * (4 * s**2 + 0.4 * s + 1) / ((100 * s + 1) * (s**2 + 0.22 * s + 1)) / (s**2 / 100 + 0.008 * s + 1),
        1 / (1 + s), 3 * (10 + s) / (2 + s), 0.01 * (10 - s) / (2 + s) / (1 + s),
        control.tf(25, [1, 10, 10, 10]),
        6.25 * (s + 3) * (s + 5) / (s * (s + 1) ** 2 * (s**2 + 0.18 * s + 100))]


@pytest.mark.parametrize("L", SISO)
def test_classical_margins_match_python_control(L):
    ours = rc.loop_margins(L)
    gm, pm, sm, wg, wp, _ = control.stability_margins(L)
    np.testing.assert_allclose([ours.gain_margin, ours.phase_margin], [gm, pm], rtol=1e-7)
    np.testing.assert_allclose([ours.gain_margin_freq, ours.phase_margin_freq], [wg, wp], rtol=1e-7)
    if ours.stable and np.isfinite(sm):   # python-control's stability margin: the distance of L(jw), w > 0, to -1
        assert 1.0 / ours.S_peak == pytest.approx(sm, rel=1e-6)


@pytest.mark.parametrize("discrete", [False, True])
def test_random_siso_classical_margins(discrete):
    """Random loops; in discrete time python-control's polynomial method is sometimes wrong (its crossing does not
    have |L| = 1 or Im L = 0), so the comparison keeps the loops where its answer checks out."""
    compared = 0
    for seed in range(60):
        L = random_siso(seed, discrete)
        with warnings.catch_warnings():     # "Falling back to 'frd' method": then its answer is checked below
            warnings.simplefilter("ignore")
            gm, pm, _, wg, wp, _ = control.stability_margins(L)
        if discrete:
            at_wp, at_wg = (L(np.exp(1j * w * L.dt)) if np.isfinite(w) else 1.0 for w in (wp, wg))
            if abs(abs(at_wp) - 1) > 1e-6 or abs(at_wg.imag) > 1e-6 * abs(at_wg):
                continue
        ours = rc.loop_margins(L)
        if discrete and ours.gain_margin_freq == pytest.approx(np.pi / L.dt):
            continue    # python-control leaves out theta = pi (checked in test_gain_margin_at_nyquist_frequency)
        np.testing.assert_allclose([ours.gain_margin, ours.phase_margin], [gm, pm], rtol=1e-6)
        np.testing.assert_allclose([ours.gain_margin_freq, ours.phase_margin_freq], [wg, wp], rtol=1e-6, atol=1e-9)
        compared += 1
    assert compared >= 30


def test_crossings_against_a_dense_grid():
    """Every sign change of Im S and Re S - 1/2 on a 200001-point grid is found, and nothing else (S = 1/(1+L))."""
    for seed in range(24):
        discrete = seed % 2 == 1
        L = random_siso(seed, discrete)
        A, B, C, D, _ = _loop_kernels.sensitivity(*(np.asarray(M, dtype=float)[None] for M in (L.A, L.B, L.C, L.D)))
        w_real, w_half = _loop_kernels.crossings(A, B, C, D, discrete=discrete)
        x = np.linspace(1e-7, np.pi - 1e-7, 200001) if discrete else np.logspace(-5, 4, 200001)
        S = _loop_kernels.response(A, B, C, D, (np.exp(1j * x) if discrete else 1j * x)[None])[0, :, 0, 0]
        for w, f in ((w_real[0], S.imag), (w_half[0], S.real - 0.5)):
            change = np.flatnonzero((np.sign(f[:-1]) != np.sign(f[1:])) & (np.abs(S[:-1]) < 1e6))
            found = np.unique(np.round(w[np.isfinite(w) & (w > 1e-7) & (w < x[-1])], 9))
            assert found.size == change.size, (seed, found, x[change])
            assert np.all((x[change] <= found) & (found <= x[change + 1]))


def test_gain_margin_at_nyquist_frequency():
    """The LQR of a sampled double integrator crosses the negative real axis at theta = pi (python-control, which
    leaves theta = pi out, reports a spurious 7e-10): with the gain scaled by the margin the closed loop has a pole
    at z = -1."""
    plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    ctrl = rc.lqr(plant)
    m = rc.loop_margins(ctrl)
    assert m.gain_margin_freq == pytest.approx(np.pi / 0.1, rel=1e-12)
    poles = np.linalg.eigvals(plant.F + plant.G @ (m.gain_margin * ctrl.K))
    assert np.min(np.abs(poles + 1.0)) < 1e-9
    assert np.max(np.abs(np.linalg.eigvals(plant.F + plant.G @ (0.999 * m.gain_margin * ctrl.K)))) < 1.0
    assert np.max(np.abs(np.linalg.eigvals(plant.F + plant.G @ (1.001 * m.gain_margin * ctrl.K)))) > 1.0


# ---------------------------------------------------------------- SISO disk margins: python-control
@pytest.mark.parametrize("skew", [0.0, 1.0, -1.0, 0.5])
@pytest.mark.parametrize("L", [L for L in SISO if rc.loop_margins(L).stable])
def test_disk_margin_exact_at_the_peak(L, skew):
    ours = rc.loop_margins(L, skew=skew)
    w = ours.alpha_freq
    if np.isfinite(w):      # python-control evaluates |S + (skew - 1)/2| there: the same number
        assert pc_disk_margin(L, w, skew) == pytest.approx(ours.alpha, rel=1e-8)
    else:                   # the peak is at w = inf: 1 / |S(inf) + (skew - 1)/2| with S(inf) = 1 / (1 + L(inf))
        d = float(control.ss(L).D[0, 0])
        assert ours.alpha == pytest.approx(1.0 / abs(1.0 / (1.0 + d) + 0.5 * (skew - 1.0)), rel=1e-12)
    assert pc_disk_margin(L, grid(L), skew) >= ours.alpha * (1.0 - 1e-10)
    assert ours.alpha_loops == ours.alpha and ours.alpha_exact


@pytest.mark.parametrize("discrete", [False, True])
def test_random_siso_disk_margins(discrete):
    checked = 0
    for seed in range(60):
        L = random_siso(seed, discrete)
        ours = rc.loop_margins(L, skew=0.3)
        if not ours.stable:
            assert ours.alpha == 0.0 and ours.S_peak == np.inf
            continue
        if np.isfinite(ours.alpha_freq):
            assert pc_disk_margin(L, ours.alpha_freq, 0.3) == pytest.approx(ours.alpha, rel=1e-8)
        assert pc_disk_margin(L, grid(L), 0.3) >= ours.alpha * (1.0 - 1e-10)
        w = grid(L, 2000)
        resp = L(np.exp(1j * w * L.dt) if discrete else 1j * w)
        assert np.max(np.abs(1 / (1 + resp))) <= ours.S_peak * (1 + 1e-10)
        assert np.max(np.abs(resp / (1 + resp))) <= ours.T_peak * (1 + 1e-10)
        checked += 1
    assert checked >= 10


# ---------------------------------------------------------------- the literature
def test_seiler_packard_gahinet_siso_example():
    """L = 25 / (s^3 + 10 s^2 + 10 s + 10): balanced disk margin 0.46, 4.05 dB, 25.8 degrees (the paper);
    MATLAB's diskmargin gives the gain ranges [0.6273, 1.5942] (skew 0) and [0.5136, 1.4864] (skew -1).
    Classical: Im L(jw) = 0 at w^2 = 10, where L = -25/90: gain margin 3.6 exactly."""
    L = control.tf(25, [1, 10, 10, 10])
    m = rc.loop_margins(L)
    assert round(m.alpha, 2) == 0.46
    assert 20 * np.log10(m.gain_range[1]) == pytest.approx(4.05, abs=0.005)
    assert m.phase_range == pytest.approx(25.8, abs=0.05)
    np.testing.assert_allclose(m.gain_range, [0.6273, 1.5942], atol=5e-5)
    np.testing.assert_allclose(rc.loop_margins(L, skew=-1.0).gain_range, [0.5136, 1.4864], atol=5e-5)
    assert m.gain_margin == pytest.approx(3.6, rel=1e-12)
    assert m.gain_margin_freq == pytest.approx(np.sqrt(10.0), rel=1e-12)


@pytest.mark.parametrize(("alpha", "skew", "gain", "phase"), [
    (0.5, 0.0, [1 / 1.6667, 1.6667], 28.0725),
    (0.6, 0.75, [0.6066, 2.2632], 34.2267),
    (0.75, -0.5, [0.3684, 1.9231], 41.7908),
    (0.75, 0.0, [0.4545, 2.2000], None),
    (0.75, 0.5, [0.5200, 2.7143], None),
    (2.0, 0.0, [0.0, np.inf], 90.0)])
def test_disk_ranges_against_matlab_dm2gm(alpha, skew, gain, phase):
    g, p = rc.disk_ranges(alpha, skew)
    np.testing.assert_allclose(g, gain, atol=5e-5)
    if phase is not None:
        assert p == pytest.approx(phase, abs=5e-5)


@pytest.mark.parametrize(("alpha", "skew"), [(0.3, 0.0), (0.8, 0.75), (1.2, -0.4), (1.5, 1.0), (3.0, 0.0), (0.9, 1.5)])
def test_disk_ranges_phase_from_the_definition(alpha, skew):
    """The phase range is the largest phi with every e^{j psi}, |psi| <= phi, in the disk: f = e^{j psi} is in it
    iff delta = (f - 1) / ((1 - skew)/2 + (1 + skew)/2 f) has |delta| <= alpha."""
    psi = np.linspace(0.0, np.pi, 200001)
    f = np.exp(1j * psi)
    inside = np.abs((f - 1) / ((1 - skew) / 2 + (1 + skew) / 2 * f)) <= alpha
    first_out = psi[np.argmin(inside)] if not inside.all() else np.pi
    assert rc.disk_ranges(alpha, skew)[1] == pytest.approx(np.degrees(first_out), abs=2e-3)


def matlab_plant(c):
    return control.ss([[0, 10], [-10, 0]], np.eye(2), c, 0)


@pytest.mark.parametrize(("c", "at", "bounds", "freq"), [
    ([[1, 10], [-10, 1]], "output", (0.3754, 0.3762), 0.0),
    ([[1, 8], [-10, 1]], "output", (0.4890, 0.4899), None)])
def test_matlab_diskmargin_mimo_examples(c, at, bounds, freq):
    """MATLAB's diskmargin page: the loop-at-a-time margins are 2 (frequencies inf and 0 for the first plant) and the
    multi-loop margin lies between its LowerBound and UpperBound (0.3754 / 0.3762 at w = 0; 0.4890 / 0.4899)."""
    K = control.ss([], [], [], [[1, -2], [0, 1]])
    m = rc.loop_margins(matlab_plant(c) * K)
    np.testing.assert_allclose(m.alpha_loops, [2.0, 2.0], rtol=1e-9)
    assert bounds[0] <= m.alpha <= bounds[1] + 5e-5     # the page's bounds to 4 digits
    assert not m.alpha_exact
    if freq is not None:
        assert m.alpha_freq == freq
        assert list(m.alpha_loops_freq) == [np.inf, 0.0]


@needs_slycot
def test_spinning_satellite():
    """The spinning satellite with unit feedback (MATLAB's example, from Doyle): each loop alone has an infinite gain
    margin and 90 degrees of phase margin, but together they tolerate only about 10 % of simultaneous variation."""
    L = matlab_plant([[1, 10], [-10, 1]]) * control.ss([], [], [], np.eye(2))
    m = rc.loop_margins(L)
    np.testing.assert_allclose(m.gain_margin, [np.inf, np.inf])
    np.testing.assert_allclose(m.phase_margin, [90.0, 90.0], rtol=1e-9)
    np.testing.assert_allclose(m.alpha_loops, [2.0, 2.0], rtol=1e-9)
    assert pc_disk_margin(L, m.alpha_freq) == pytest.approx(m.alpha, rel=1e-8)
    assert pc_disk_margin(L, np.logspace(-3, 3, 3001)) >= m.alpha * (1 - 1e-10)
    assert 0.099 < m.alpha < 0.1


# ---------------------------------------------------------------- MIMO disk margins: python-control (AB13MD)
@needs_slycot
@pytest.mark.parametrize("discrete", [False, True])
@pytest.mark.parametrize("loops", [2, 3])
def test_random_mimo_disk_margins(discrete, loops):
    """python-control's disk margin uses SLICOT AB13MD's mu bound: ours agrees at our peak and is never above its grid
    minimum; for two loops the bound is mu itself (closed form); alpha <= each loop-at-a-time margin."""
    rng = np.random.default_rng(loops + 10 * discrete)
    tol = 1e-8 if loops == 2 else 1e-6       # AB13MD's bound for three loops is up to ~2e-7 above ours (both bounds)
    checked = 0
    while checked < 6:
        L = random_loop(rng, int(rng.integers(2, 6)), loops, discrete, 0.3)
        m = rc.loop_margins(L, skew=0.2)
        if not m.stable:
            continue
        w = m.alpha_freq if np.isfinite(m.alpha_freq) else 1e9
        assert pc_disk_margin(L, w, 0.2) == pytest.approx(m.alpha, rel=tol)
        assert pc_disk_margin(L, grid(L, 400), 0.2) >= m.alpha * (1 - tol)
        assert np.all(m.alpha <= m.alpha_loops * (1 + 1e-12))
        assert m.alpha >= 1.0 / _balanced_norm(L, 0.2) * (1 - 1e-9)
        checked += 1


def _balanced_norm(L, skew):
    """||S + (skew - 1)/2 I||_inf by python-control (the unstructured bound: alpha is at least its inverse)."""
    S = control.feedback(control.ss([], [], [], np.eye(L.ninputs)), L)
    return control.linfnorm(S + 0.5 * (skew - 1) * control.ss([], [], [], np.eye(L.ninputs)))[0]


def test_mu_bound_against_ab13md():
    pytest.importorskip("slycot")
    from slycot import ab13md
    rng = np.random.default_rng(0)
    for m, tol in ((2, 1e-12), (3, 1e-6), (4, 1e-3)):
        M = rng.standard_normal((60, m, m)) + 1j * rng.standard_normal((60, m, m))
        bound, x = _loop_kernels.mu_upper(M)
        ref = np.array([ab13md(Mi, np.ones(m, dtype=int), 2 * np.ones(m, dtype=int))[0] for Mi in M])
        np.testing.assert_allclose(bound, ref, rtol=tol)
        assert np.all(bound >= ref * (1 - 1e-10))           # an upper bound, never below the optimum
        scaled = M * np.exp(x[:, :, None] - x[:, None, :])
        np.testing.assert_allclose(np.linalg.svd(scaled, compute_uv=False)[:, 0], bound, rtol=1e-12)


# ---------------------------------------------------------------- the sign convention, loops by hand
def _integrator_plant():
    return rc.Plant([[1.0, 0.1, 0.0], [0.0, 1.0, 0.1], [0.0, 0.0, 0.9]], [[0.0, 0.0], [0.01, 0.0], [0.1, 0.1]], dt=0.1)


def test_state_feedback_loop_by_hand():
    """u = K x broken at the input is L = -K (zI - F)^-1 G, python-control's K_pc = -K in L = K_pc (zI - F)^-1 G:
    every margin of each loop (the other closed, by python-control's feedback) and the multi-loop disk margin."""
    plant = _integrator_plant()
    ctrl = rc.lqr(plant, Q=np.diag([1.0, 0.5, 0.1]), R=np.diag([1.0, 3.0]))
    K_pc = control.dlqr(plant.F, plant.G, np.diag([1.0, 0.5, 0.1]), np.diag([1.0, 3.0]))[0]
    np.testing.assert_allclose(ctrl.K, -K_pc, rtol=1e-8)
    L = control.ss(plant.F, plant.G, K_pc, 0, 0.1)
    ours = rc.loop_margins(ctrl)
    assert ours.at == "input"
    for i in range(2):
        others = np.diag([0.0 if j == i else 1.0 for j in range(2)])
        li = control.feedback(L, others)[i, i]          # loop i with the other one closed
        gm, pm, _, _, wp, _ = control.stability_margins(li)
        np.testing.assert_allclose([ours.phase_margin[i], ours.phase_margin_freq[i]], [pm, wp], rtol=1e-7)
        if ours.gain_margin_freq[i] < np.pi / 0.1 * (1 - 1e-9):   # python-control leaves theta = pi out
            assert ours.gain_margin[i] == pytest.approx(gm, rel=1e-7)
        assert pc_disk_margin(li, ours.alpha_loops_freq[i]) == pytest.approx(ours.alpha_loops[i], rel=1e-8)
    if HAS_SLYCOT:
        assert pc_disk_margin(L, ours.alpha_freq) == pytest.approx(ours.alpha, rel=1e-8)
    # the sign trap: the loop with +K is a different (here unstable) loop
    wrong = rc.loop_margins(control.ss(plant.F, plant.G, ctrl.K, 0, 0.1))
    assert not wrong.stable and wrong.reason == "unstable" and wrong.alpha == 0.0


def test_state_feedback_broken_at_the_state():
    """at="output" for a state feedback: L = -(zI - F)^-1 G K (n loops), python-control's P K_pc."""
    plant = _integrator_plant()
    ctrl = rc.lqr(plant)
    L = control.ss(plant.F, plant.G, np.eye(3), 0, 0.1) * control.ss([], [], [], -ctrl.K, 0.1)
    ours = rc.loop_margins(ctrl, at="output")
    given = rc.loop_margins(L)
    assert ours.at == "output" and np.shape(ours.alpha_loops) == (3,)
    for key in ("alpha", "alpha_loops", "gain_margin", "phase_margin", "S_peak", "T_peak"):
        np.testing.assert_allclose(getattr(ours, key), getattr(given, key), rtol=1e-9)
    if HAS_SLYCOT:
        assert pc_disk_margin(L, ours.alpha_freq) == pytest.approx(ours.alpha, rel=1e-6)


def test_continuous_lqr_guaranteed_margins():
    """Continuous LQR with a diagonal R: |S(jw)| <= 1 at the input (Kalman's inequality), so S_peak = 1 (at w = inf),
    the S-based disk margin is 1: gains in (1/2, inf) and at least 60 degrees of phase (Safonov & Athans 1977). The
    classical margins agree with python-control (a gain reduction below 1/2 may destabilise)."""
    rng = np.random.default_rng(5)
    A, B = rng.standard_normal((4, 4)), rng.standard_normal((4, 1))
    K_pc = control.lqr(A, B, np.eye(4), np.eye(1))[0]
    m = rc.loop_margins((rc.Plant(A, B, None), -K_pc), skew=1.0)
    assert m.S_peak == pytest.approx(1.0, rel=1e-9)
    assert m.alpha == pytest.approx(1.0, rel=1e-9)
    assert m.phase_margin >= 60.0 and not 0.5 < m.gain_margin < np.inf
    gm, pm = control.stability_margins(control.ss(A, B, K_pc, 0))[:2]
    np.testing.assert_allclose([m.gain_margin, m.phase_margin], [gm, pm], rtol=1e-7)
    assert m.gain_range[1] == np.inf and m.gain_range[0] == pytest.approx(0.5, rel=1e-9)


def _observer_controller(discrete: bool):
    """A plant with one measured output and an observer-based controller built with python-control alone:
    xh+ = F xh + G u + Lk (y - C xh), u = -K_pc xh, i.e. u = K(z) y with Ac = F - G K_pc - Lk C, Bc = Lk,
    Cc = -K_pc, Dc = 0 (our sign: no minus in u = K(z) y)."""
    F = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-0.5, -1.0, -1.2]])
    G, C = np.array([[0.0], [0.0], [1.0]]), np.array([[1.0, 0.0, 0.0]])
    if discrete:
        sysd = control.c2d(control.ss(F, G, C, 0), 0.1)
        F, G = sysd.A, sysd.B
        K_pc = control.dlqr(F, G, np.eye(3), np.eye(1))[0]
        Lk = control.dlqr(F.T, C.T, np.eye(3), np.eye(1))[0].T
    else:
        K_pc = control.lqr(F, G, np.eye(3), np.eye(1))[0]
        Lk = control.lqr(F.T, C.T, np.eye(3), np.eye(1))[0].T
    dt = 0.1 if discrete else None
    plant = rc.Plant(F, G, dt, C=C)
    ctrl = rc.Controller.dynamic(F - G @ K_pc - Lk @ C, Lk, -K_pc, np.zeros((1, 1)), "observer", plant)
    P = control.ss(F, G, C, 0, 0 if dt is None else dt)
    Kss = control.ss(F - G @ K_pc - Lk @ C, Lk, -K_pc, 0, 0 if dt is None else dt)
    return plant, ctrl, P, Kss


@pytest.mark.parametrize("discrete", [False, True])
@pytest.mark.parametrize("at", ["input", "output"])
def test_output_feedback_loop_by_hand(discrete, at):
    """u = K(z) y: L = -K(z) P(z) at the input and -P(z) K(z) at the output, built by python-control's series."""
    _, ctrl, P, Kss = _observer_controller(discrete)
    L = -(Kss * P) if at == "input" else -(P * Kss)
    ours = rc.loop_margins(ctrl, at=at)
    assert ours.stable
    assert np.all(np.abs(control.poles(control.feedback(P, Kss, sign=1))) < 1) if discrete \
        else np.all(control.poles(control.feedback(P, Kss, sign=1)).real < 0)
    with warnings.catch_warnings():     # discrete: its 'frd' fallback, still within 1e-7 here
        warnings.simplefilter("ignore")
        gm, pm, _, wg, wp, _ = control.stability_margins(L)
    if not (discrete and ours.gain_margin_freq == pytest.approx(np.pi / 0.1)):
        np.testing.assert_allclose([ours.gain_margin, ours.gain_margin_freq], [gm, wg], rtol=1e-7)
    np.testing.assert_allclose([ours.phase_margin, ours.phase_margin_freq], [pm, wp], rtol=1e-7)
    if np.isfinite(ours.alpha_freq):
        assert pc_disk_margin(L, ours.alpha_freq) == pytest.approx(ours.alpha, rel=1e-8)
    assert pc_disk_margin(L, grid(L)) >= ours.alpha * (1 - 1e-10)
    assert ours.S_peak == pytest.approx(control.linfnorm(control.feedback(control.ss([], [], [], 1.0), L))[0],
                                        rel=1e-7)
    # the sign trap: K(z) used as python-control's negative-feedback controller is another loop
    assert rc.loop_margins(Kss * P).alpha != pytest.approx(ours.alpha, rel=1e-3)


def test_static_output_feedback_mimo():
    """u = Dc y on a plant with two measured outputs (static output feedback), at the input and at the output."""
    rng = np.random.default_rng(11)
    F = np.diag([0.9, 0.5, -0.3, 0.7]) + 0.05 * rng.standard_normal((4, 4))
    G, C = rng.standard_normal((4, 2)), rng.standard_normal((2, 4))
    plant = rc.Plant(F, G, 0.05, C=C, D=0.1 * rng.standard_normal((2, 2)))
    Dc = -0.02 * rng.standard_normal((2, 2))
    ctrl = rc.Controller.dynamic([], [], [], Dc, "static", plant)
    P = control.ss(F, G, C, plant.D, 0.05)
    for at, L in (("input", -(control.ss([], [], [], Dc, 0.05) * P)), ("output", -(P * Dc))):
        ours = rc.loop_margins(ctrl, at=at)
        assert ours.stable
        if HAS_SLYCOT:
            assert pc_disk_margin(L, ours.alpha_freq) == pytest.approx(ours.alpha, rel=1e-8)
        for i in range(2):
            li = control.feedback(L, np.diag([0.0 if j == i else 1.0 for j in range(2)]))[i, i]
            assert pc_disk_margin(li, ours.alpha_loops_freq[i]) == pytest.approx(ours.alpha_loops[i], rel=1e-8)
            with warnings.catch_warnings():     # its 'frd' fallback: still within 1e-7 here
                warnings.simplefilter("ignore")
                pm, _, _, wp = control.stability_margins(li)[1:5]
            np.testing.assert_allclose([ours.phase_margin[i], ours.phase_margin_freq[i]], [pm, wp], rtol=1e-7)


def test_controller_batch_equals_single_controllers():
    plant, ctrl, _, _ = _observer_controller(True)
    scale = np.array([1.0, 0.7, 1.3, 25.0])[:, None, None]
    batch = rc.ControllerBatch(plant, np.repeat(ctrl.Ac[None], 4, axis=0), np.repeat(ctrl.Bc[None], 4, axis=0),
                               scale * ctrl.Cc, np.zeros((4, 1, 1)))
    many = rc.loop_margins(batch, at="output")
    assert many.alpha.shape == (4,) and many.reason[3] == "unstable"
    for b in range(4):
        one = rc.loop_margins(batch[b], at="output")
        for key in ("alpha", "gain_margin", "phase_margin", "S_peak", "T_peak"):
            np.testing.assert_allclose(getattr(many, key)[b], getattr(one, key), rtol=1e-9)


# ---------------------------------------------------------------- stacks
@pytest.mark.parametrize(("discrete", "at"), [(True, "input"), (False, "input"), (True, "output")])
def test_stack_equals_single_calls(discrete, at):
    rng = np.random.default_rng(2)
    plant = _integrator_plant() if discrete else rc.Plant(rng.standard_normal((3, 3)), rng.standard_normal((3, 2)),
                                                            None)
    K0 = rc.lqr(plant).K if discrete else -control.lqr(plant.F, plant.G, np.eye(3), np.eye(2))[0]
    Ks = K0 * rng.uniform(0.2, 3.0, size=(12, 1, 1)) + 0.05 * rng.standard_normal((12, 2, 3))
    Ks[3] = 0.0                                           # the open loop: unstable
    Ks[5, 0, 0] = np.nan
    batch = rc.loop_margins((plant, Ks), at=at)
    assert batch.reason[5] == "not finite" and np.isnan(batch.alpha[5])
    open_loop = np.linalg.eigvals(plant.F)
    assert (np.abs(open_loop).max() >= 1.0) if discrete else (open_loop.real.max() >= 0.0)
    assert batch.reason[3] == "unstable" and batch.alpha[3] == 0.0
    for b in range(len(Ks)):
        if b == 5:
            continue
        one = rc.loop_margins((plant, Ks[b]), at=at)
        assert one.reason == batch.reason[b]
        for key in ("alpha", "alpha_freq", "alpha_loops", "gain_margin", "gain_margin_freq", "phase_margin",
                    "phase_margin_freq", "S_peak", "S_peak_freq", "T_peak", "T_peak_freq"):
            # a peak's frequency is known to about sqrt(its value's accuracy): the rounding of one eigenvalue
            # routine against another (LAPACK directly for one loop) moves it more than the value
            np.testing.assert_allclose(getattr(batch, key)[b], getattr(one, key), atol=1e-12,
                                       rtol=1e-6 if key.endswith("freq") else 1e-9, err_msg=f"{key}[{b}]")


def test_shapes_and_repr():
    plant = _integrator_plant()
    K = rc.lqr(plant).K
    one = rc.loop_margins((plant, K))
    many = rc.loop_margins((plant, np.stack([K, 0.5 * K])))
    assert isinstance(one.alpha, float) and np.shape(one.alpha_loops) == (2,) and one.gain_range.shape == (2,)
    assert many.alpha.shape == (2,) and many.alpha_loops.shape == (2, 2) and many.gain_range.shape == (2, 2)
    assert "alpha=" in repr(one) and "2 loops, 2 stable" in repr(many)
    siso = rc.loop_margins(control.tf(25, [1, 10, 10, 10]))
    assert isinstance(siso.gain_margin, float) and isinstance(siso.alpha_loops, float)
    assert siso.at == "loop" and siso.dt is None


# ---------------------------------------------------------------- bad input and unstable loops
def test_unstable_loop_says_what_the_margins_mean():
    """An unstable closed loop: alpha 0, infinite peaks, reason "unstable"; the classical margins are still those of
    the frequency response (python-control's)."""
    L = control.tf([1], [1, 2, 3, 4]) * 5      # closed loop s^3 + 2s^2 + 3s + 9: unstable
    m = rc.loop_margins(L)
    assert not m.stable and m.reason == "unstable"
    assert m.alpha == 0.0 and m.S_peak == np.inf and m.T_peak == np.inf
    assert m.gain_range.tolist() == [1.0, 1.0] and m.phase_range == 0.0
    gm = control.stability_margins(L)[0]
    assert m.gain_margin == pytest.approx(gm, rel=1e-9) and m.gain_margin < 1


def test_ill_posed_loop():
    m = rc.loop_margins(control.ss([[-1.0]], [[1.0]], [[1.0]], [[-1.0]]))
    assert m.reason == "ill-posed" and np.isnan(m.alpha) and not m.stable


@pytest.mark.parametrize(("args", "kwargs", "error", "match"), [
    ((("plant", "K"),), {}, TypeError, "ctrl must be"),
    ((42,), {}, TypeError, "ctrl must be"),
    ((control.tf(1, [1, 1]),), {"at": "input"}, TypeError, "at applies to a controller"),
    ((control.ss([[-1.0]], [[1.0, 1.0]], [[1.0]], [[0.0, 0.0]]),), {}, ValueError, "L must be square"),
    ((control.tf(1, [1, 1]),), {"skew": float("nan")}, ValueError, "skew must be finite"),
    ((control.tf(1, [1, 1]),), {"skew": "0"}, TypeError, "skew"),
])
def test_bad_input(args, kwargs, error, match):
    with pytest.raises(error, match=match):
        rc.loop_margins(*args, **kwargs)


def test_bad_gains_and_at():
    plant = _integrator_plant()
    with pytest.raises(ValueError, match=r"K must have 2 rows \(the number of inputs\), got shape \(3, 2\)"):
        rc.loop_margins((plant, np.zeros((3, 2))))
    with pytest.raises(ValueError, match=r"K must be a gain \(2, 3\) or a non-empty stack.*got shape \(4, 3, 3\)"):
        rc.loop_margins((plant, np.zeros((4, 3, 3))))
    with pytest.raises(ValueError, match="at must be one of 'input', 'output', got 'middle'"):
        rc.loop_margins(rc.lqr(plant), at="middle")
    with pytest.raises(ValueError, match="alpha must be >= 0"):
        rc.disk_ranges(-0.1)


def test_module_and_function_names():
    """The word margin: robust_stability's margin is a radius; loop_margins' docstring says which is which."""
    doc = sys.modules["robustctl.analysis.loop_margins"].__doc__
    assert "robust-stability radius" in doc
    assert "robust_stability" in rc.loop_margins.__doc__


def test_disk_only_gives_the_same_disk_margins_and_leaves_the_rest():
    rng = np.random.default_rng(3)
    plant = rc.Plant(0.5 * rng.standard_normal((4, 4)), rng.standard_normal((4, 2)), 0.1)
    K = np.stack([rc.lqr(plant, Q=q * np.eye(4)).K for q in (0.1, 1.0, 10.0)])
    full, disk = rc.loop_margins((plant, K)), rc.loop_margins((plant, K), what="disk")
    np.testing.assert_array_equal(disk.alpha, full.alpha)
    np.testing.assert_array_equal(disk.alpha_loops, full.alpha_loops)
    assert np.isnan(disk.gain_margin).all() and np.isnan(disk.T_peak).all()
    with pytest.raises(ValueError, match=r"^what must be"):
        rc.loop_margins((plant, K), what="peaks")
