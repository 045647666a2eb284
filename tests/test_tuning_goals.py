"""moo.tuning goals, each against an independent computation.

Time domain: python-control's forced_response of the closed loop (no
saturation) and a plain numpy loop ``x[k+1] = F x[k] + G sat(K x[k])``;
closed loop: eigenvalues, control.norm(sys, 2) and control.linfnorm (slycot).
"""

import control
import numpy as np
import pytest

import robustctl as rc
from moo.tuning.goals import at_least, at_most, check_scenarios
from moo.tuning.margins import RobustMargin
from moo.tuning.norms import H2Norm, HinfNorm
from moo.tuning.poles import PoleRegion, SpectralRadius
from moo.tuning.response import Response

A_C = np.array([[0.0, 1.0, 0.0], [-2.0, -0.5, 1.0], [0.0, 0.0, -1.0]])
B_C = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
DT = 0.1


@pytest.fixture(scope="module")
def plants():
    return [rc.Plant.from_continuous(A_C * s, B_C * (2.0 - s), DT) for s in (0.8, 1.0, 1.2)]


@pytest.fixture(scope="module")
def gains(plants):
    """Four LQR gains of the middle plant (u = K x, K = -K_control), stabilising every scenario."""
    Ks = [-control.dlqr(plants[1].F, plants[1].G, np.diag(q), np.eye(2))[0]
          for q in ([1, 1, 1], [10, 1, 1], [1, 10, 5], [100, 1, 1])]
    K = np.stack(Ks)
    assert max(np.abs(np.linalg.eigvals(p.F + p.G @ k)).max() for p in plants for k in K) < 1
    return K


def _trajectory(plant, K, x0, T, r=None):
    """States (T, n) of u = K (x - r) by python-control (no saturation)."""
    A = plant.F + plant.G @ K
    if r is None:
        res = control.forced_response(control.ss(A, np.zeros((3, 1)), np.eye(3), 0, DT), T=np.arange(T) * DT,
                                      U=np.zeros((1, T)), X0=x0)
    else:
        res = control.forced_response(control.ss(A, -plant.G @ K, np.eye(3), 0, DT), T=np.arange(T) * DT,
                                      U=r.T, X0=x0)
    return np.asarray(res.states).T


def _saturated_loop(plant, K, x0, T, lim):
    """States (T, n) and inputs (T, m) of x[k+1] = F x + G sat(K x), a plain loop."""
    x = np.array(x0, float)
    X, U = [], []
    for _ in range(T):
        u = np.clip(K @ x, -lim, lim)
        X.append(x)
        U.append(u)
        x = plant.F @ x + plant.G @ u
    return np.array(X), np.array(U)


# ---------------------------------------------------------------- time domain
def test_error_measures_vs_forced_response(plants, gains):
    x0, T = np.array([1.0, 0.0, 0.5]), 60
    resp = Response(x0=x0, steps=T)
    mse, ise, iae = (resp.error(states=[0, 2], measure=m) for m in ("mse", "ise", "iae"))
    mse_max = resp.error(states=[0, 2], measure="mse", over="max")
    weighted = resp.error(states=[0, 2], weights=[2.0, 0.5])
    X = np.array([[_trajectory(p, k, x0, T) for p in plants] for k in gains])      # (B, S, T, n)
    e = X[..., [0, 2]]
    np.testing.assert_allclose(mse(gains, plants), (e**2).mean(axis=2).sum(-1).mean(1), rtol=1e-10)
    np.testing.assert_allclose(mse_max(gains, plants), (e**2).mean(axis=2).sum(-1).max(1), rtol=1e-10)
    np.testing.assert_allclose(ise(gains, plants), (e**2).sum(axis=2).sum(-1).mean(1) * DT, rtol=1e-10)
    np.testing.assert_allclose(iae(gains, plants), np.abs(e).sum(axis=2).sum(-1).mean(1) * DT, rtol=1e-10)
    np.testing.assert_allclose(weighted(gains, plants), ((e**2).mean(axis=2) @ [2.0, 0.5]).mean(1), rtol=1e-10)


def test_tracking_error_vs_forced_response(plants, gains):
    T = 50
    r = np.zeros((T, 3))
    r[10:, 0] = 0.3
    x0 = np.array([0.2, 0.0, 0.0])
    resp = Response(x0=x0, steps=T, reference=r, backend="numpy")
    X = np.array([[_trajectory(p, k, x0, T, r) for p in plants] for k in gains])
    e = X[..., 0] - r[:, 0]
    np.testing.assert_allclose(resp.error(0)(gains, plants), (e**2).mean(axis=2).mean(1), rtol=1e-10)


def test_saturated_peak_settling_vs_loop(plants, gains):
    x0, T, lim = np.array([1.0, -0.5, 0.5]), 80, np.array([0.8, 0.3])
    resp = Response(x0=x0, steps=T, u_limit=lim)
    runs = [[_saturated_loop(p, k, x0, T, lim) for p in plants] for k in gains]
    X = np.array([[r[0] for r in row] for row in runs])
    U = np.array([[r[1] for r in row] for row in runs])
    assert np.any(np.abs(U) >= lim - 1e-12)                                  # the limit is active
    np.testing.assert_allclose(resp.error([0, 1])(gains, plants), (X[..., :2]**2).mean(2).sum(-1).mean(1),
                               rtol=1e-9)
    np.testing.assert_allclose(resp.peak_input()(gains, plants), np.abs(U).max(axis=(2, 3)).max(1), rtol=1e-12)
    np.testing.assert_allclose(resp.peak_input(1, over="mean")(gains, plants), np.abs(U[..., 1]).max(2).mean(1),
                               rtol=1e-12)
    # settling time of x0 into 5 % of its peak, by a plain scan
    tol = 0.05
    expect = np.zeros(X.shape[:2])
    for b in range(X.shape[0]):
        for s in range(X.shape[1]):
            x = np.abs(X[b, s, :, 0])
            k_star = 0
            for k in range(T):
                if x[k] > tol * x.max():
                    k_star = k + 1
            expect[b, s] = k_star * DT
    np.testing.assert_allclose(resp.settling_time(0, tol=tol)(gains, plants), expect.mean(1), rtol=1e-12)


def test_one_simulation_per_population(plants, gains, monkeypatch):
    from robustctl.sim.simulator import LinearSimulator

    calls = []
    run = LinearSimulator.run
    monkeypatch.setattr(LinearSimulator, "run", lambda self, K, **kw: calls.append(1) or run(self, K, **kw))
    resp = Response(x0=[1.0, 0.0, 0.0], steps=30, u_limit=1.0)
    goals = [resp.error(0), resp.error(1), resp.error(2, "iae"), resp.peak_input(), resp.settling_time()]
    [g(gains, plants) for g in goals]
    assert len(calls) == 1
    [g(gains.copy(), plants) for g in goals]          # equal gains: still one
    assert len(calls) == 1
    goals[0](gains[:2], plants)                        # new population: one more
    assert len(calls) == 2


def test_per_scenario_initial_state(plants, gains):
    x0 = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]])
    resp = Response(x0=x0, steps=40)
    X = np.array([[_trajectory(p, k, x0[s], 40) for s, p in enumerate(plants)] for k in gains])
    np.testing.assert_allclose(resp.error()(gains, plants), (X**2).mean(2).sum(-1).mean(1), rtol=1e-10)


# ---------------------------------------------------------------- closed loop
def _loops(plants, K):
    return np.array([[p.F + p.G @ k for p in plants] for k in K])


def test_spectral_radius_and_pole_region(plants, gains):
    eig = np.linalg.eigvals(_loops(plants, gains))                            # (B, S, n)
    np.testing.assert_allclose(SpectralRadius()(gains, plants), np.abs(eig).max(axis=(1, 2)), rtol=1e-12)
    np.testing.assert_allclose(SpectralRadius(over="mean")(gains, plants), np.abs(eig).max(2).mean(1), rtol=1e-12)
    disk = PoleRegion(rc.Disk(0.1, 0.8))
    np.testing.assert_allclose(disk(gains, plants), (np.abs(eig - 0.1) - 0.8).max(axis=(1, 2)), atol=1e-12)
    half = PoleRegion(rc.HalfPlane(0.5))
    np.testing.assert_allclose(half(gains, plants), 2 * (eig.real.max(axis=(1, 2)) - 0.5), atol=1e-12)
    both = PoleRegion([rc.Disk(0.1, 0.8), rc.HalfPlane(0.5)])
    np.testing.assert_allclose(both(gains, plants), np.maximum(disk(gains, plants), half(gains, plants)))
    # inside <=> <= 0, as robustctl's own region test says
    inside = rc.Disk(0.1, 0.8).contains(eig).all(axis=(1, 2))
    np.testing.assert_array_equal(disk(gains, plants) < 0, inside)


def test_h2_norm_vs_control(plants, gains):
    Bw = np.array([[0.0], [1.0], [0.3]])
    Cz = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 2.0]])
    Dzu = np.array([[0.0, 0.0], [0.5, 0.1]])
    ref = np.array([[control.norm(control.ss(p.F + p.G @ k, Bw, Cz + Dzu @ k, 0, DT), 2) for p in plants]
                    for k in gains])
    np.testing.assert_allclose(H2Norm(Bw, Cz, Dzu)(gains, plants), ref.max(1), rtol=1e-9)
    np.testing.assert_allclose(H2Norm(Bw[:, 0], Cz[0], over="mean")(gains, plants),
                               np.array([[control.norm(control.ss(p.F + p.G @ k, Bw, Cz[:1], 0, DT), 2)
                                          for p in plants] for k in gains]).mean(1), rtol=1e-9)


def test_h2_norm_slow_loop():
    # spectral radius 0.999: the Gramian needs many doublings
    plant = rc.Plant([[0.999, 0.1], [0.0, 0.5]], [[0.0], [1.0]], 1.0)
    K = np.zeros((1, 1, 2))
    ref = control.norm(control.ss(plant.F, [[1.0], [0.0]], [[1.0, 0.0]], 0, 1.0), 2)
    np.testing.assert_allclose(H2Norm([1.0, 0.0], [1.0, 0.0])(K, [plant]), [ref], rtol=1e-9)


def test_hinf_norm_vs_linfnorm(plants, gains):
    Bw = np.array([[0.0], [1.0], [0.3]])
    Cz = np.array([[1.0, 0.0, 0.0]])
    Dzu = np.array([[0.2, 0.0]])
    K, P = gains[:2], plants[::2]
    ref = np.array([[control.linfnorm(control.ss(p.F + p.G @ k, Bw, Cz + Dzu @ k, 0, DT))[0] for p in P]
                    for k in K])
    np.testing.assert_allclose(HinfNorm(Bw, Cz, Dzu)(K, P), ref.max(1), rtol=1e-5)


def test_robust_margin_vs_linfnorm(plants, gains):
    nominal = plants[1]
    unc = rc.NormBounded.from_plants(nominal, plants)
    K = gains[:3]
    ref = np.array([1.0 / control.linfnorm(control.ss(nominal.F + nominal.G @ k, unc.H, unc.EF + unc.EG @ k,
                                                     0, DT))[0] for k in K])
    goal = RobustMargin(unc, nominal=nominal)
    margin = goal.measure(K, plants)
    np.testing.assert_allclose(margin, ref, rtol=1e-5)
    np.testing.assert_allclose(goal(K, plants), 1.0 / margin)                 # minimised as 1 / margin
    cert = at_least(goal, 1.0)
    np.testing.assert_allclose(cert(K, plants), 1.0 - margin)
    assert cert.name == "robust margin >= 1"
    # the default nominal is the first scenario
    np.testing.assert_allclose(RobustMargin(unc).measure(K, [nominal, *plants]), margin)


# ---------------------------------------------------------------- constraints
def test_bounds_on_goals_and_callables(plants, gains):
    rho = SpectralRadius()(gains, plants)
    c = at_most(SpectralRadius(), 0.9)
    np.testing.assert_allclose(c(gains, plants), rho - 0.9)
    assert c.name == "spectral radius <= 0.9"
    assert repr(c) == "at_most(SpectralRadius(name='spectral radius', over='max'), 0.9)"

    def norm_of_gain(K, P):
        return np.linalg.norm(K, axis=(1, 2))

    d = at_least(norm_of_gain, 2.0, name="big gain")
    np.testing.assert_allclose(d(gains, plants), 2.0 - np.linalg.norm(gains, axis=(1, 2)))
    assert d.name == "big gain"
    d.check(plants)                                    # a callable without check: nothing to do
    with pytest.raises(TypeError, match="goal must be"):
        at_most(3.0, 1.0)
    with pytest.raises(TypeError, match="bound must be"):
        at_most(SpectralRadius(), "1")


# ---------------------------------------------------------------- bad input
def test_bad_input(plants, gains):
    resp = Response(x0=[1.0, 0.0, 0.0], steps=20)
    with pytest.raises(ValueError, match=r"states must be measured signal indices in \[0, 3\)"):
        resp.error(states=[0, 3]).check(plants)
    with pytest.raises(ValueError, match=r"states must be measured signal indices"):
        resp.settling_time(5).check(plants)
    with pytest.raises(ValueError, match=r"inputs must be input indices in \[0, 2\)"):
        resp.peak_input(2).check(plants)
    with pytest.raises(ValueError, match=r"x0 must have shape \(3,\)"):
        Response(x0=[1.0, 0.0], steps=20).error().check(plants)
    with pytest.raises(ValueError, match=r"x0 must have shape \(3,\) or \(3, 3\)"):
        Response(x0=np.zeros((2, 3)), steps=20).error()(gains, plants)
    with pytest.raises(ValueError, match="reference must have steps=20 samples"):
        Response(x0=[1.0, 0.0, 0.0], steps=20, reference=np.zeros((19, 3)))
    with pytest.raises(ValueError, match=r"reference must have shape \(20, 3\)"):
        Response(x0=[1.0, 0.0, 0.0], steps=20, reference=np.zeros((20, 2))).error().check(plants)
    with pytest.raises(ValueError, match="u_limit must be a number or have 2 entries"):
        Response(x0=[1.0, 0.0, 0.0], steps=20, u_limit=[1.0, 2.0, 3.0]).peak_input().check(plants)
    with pytest.raises(ValueError, match="u_limit must be a positive"):
        Response(x0=[1.0, 0.0, 0.0], steps=20, u_limit=-1.0)
    with pytest.raises(TypeError, match="steps must be"):
        Response(x0=[1.0, 0.0, 0.0], steps=2.5)
    with pytest.raises(ValueError, match="measure must be one of"):
        resp.error(measure="rms")
    with pytest.raises(ValueError, match="over must be one of"):
        resp.error(over="median")
    with pytest.raises(ValueError, match="tol must be in"):
        resp.settling_time(tol=1.5)
    with pytest.raises(ValueError, match="weights must be 2 finite"):
        resp.error([0, 1], weights=[1.0])
    with pytest.raises(ValueError, match="Bw must have 3 rows"):
        H2Norm(np.ones((2, 1)), np.ones((1, 3))).check(plants)
    with pytest.raises(ValueError, match="Cz must have 3 columns"):
        HinfNorm(np.ones((3, 1)), np.ones((1, 4))).check(plants)
    with pytest.raises(ValueError, match="Dzu must have 2 columns"):
        H2Norm(np.ones((3, 1)), np.ones((1, 3)), np.ones((1, 3))).check(plants)
    with pytest.raises(ValueError, match="Dzu must have 1 rows"):
        H2Norm(np.ones((3, 1)), np.ones((1, 3)), np.ones((2, 2)))
    with pytest.raises(ValueError, match="over must be one of"):
        SpectralRadius(over="min")
    with pytest.raises(TypeError, match="region must be"):
        PoleRegion(0.9)
    with pytest.raises(TypeError, match=r"uncertainty must be a robustctl\.NormBounded"):
        RobustMargin(np.eye(3))
    with pytest.raises(ValueError, match="uncertainty does not fit the plants"):
        RobustMargin(rc.NormBounded(np.ones((2, 1)), np.ones((1, 2)), np.ones((1, 1)))).check(plants)
    with pytest.raises(ValueError, match=r"plants\[1\] must have n=\d states .* like plants\[0\], got n=2"):
        check_scenarios([plants[0], rc.Plant(np.eye(2), np.ones((2, 2)), DT)])
    with pytest.raises(ValueError, match=r"SpectralRadius needs discrete-time plants; these are continuous"):
        SpectralRadius().check([rc.Plant(A_C, B_C, None)])
    with pytest.raises(TypeError, match=r"plants must be a non-empty list of robustctl\.Plant, got an empty list"):
        SpectralRadius().check([])
    with pytest.raises(ValueError, match=r"K must be a non-empty stack \(B, 2, 3\) of gains"):
        SpectralRadius()(np.zeros((2, 1, 3)), plants)
    with pytest.raises(ValueError, match=r"K must be a non-empty stack \(B, 2, 3\) .* got shape \(2, 2, 4\)"):
        SpectralRadius()(np.zeros((2, 2, 4)), plants)


# ---------------------------------------------------------------- inside a TuningProblem
def test_goals_in_a_tuning_problem(plants, gains):
    from moo.tuning import LQRFamily, TuningProblem

    resp = Response(x0=[1.0, 0.0, 0.5], steps=40, u_limit=2.0)
    objectives = [resp.error([0, 2]), resp.peak_input(), SpectralRadius()]
    constraints = [at_most(H2Norm([0.0, 1.0, 0.0], [1.0, 0.0, 0.0]), 5.0)]
    prob = TuningProblem(LQRFamily(plants[1]), plants, objectives, constraints)
    J, C = prob.evaluate_gains(gains)
    np.testing.assert_allclose(J, np.column_stack([g(gains, plants) for g in objectives]))
    np.testing.assert_allclose(C[:, 0], constraints[0](gains, plants))
    # a goal that does not fit the plants is refused when the problem is built
    with pytest.raises(ValueError, match=r"states must be measured signal indices in \[0, 3\)"):
        TuningProblem(LQRFamily(plants[1]), plants, [resp.error([3])])
    with pytest.raises(ValueError, match="Bw must have 3 rows"):
        TuningProblem(LQRFamily(plants[1]), plants, [SpectralRadius()], [at_most(H2Norm([1.0, 0.0], [1.0]), 1.0)])


def test_hinf_norm_of_a_zero_channel(plants, gains):
    np.testing.assert_array_equal(HinfNorm([0.0, 1.0, 0.0], [0.0, 0.0, 0.0])(gains[:1], plants[:1]), [0.0])
