"""robustctl.analysis: LMI certificates against python-control's linfnorm, scipy's Lyapunov
solvers, closed forms and sampled perturbations; the worst-case search; bad input."""

from __future__ import annotations

import dataclasses

import control
import numpy as np
import pytest
import scipy.linalg
import scipy.optimize

import robustctl as rc
from robustctl.errors import InfeasibleError
from robustctl.models import morais2022, truck


# ---------------------------------------------------------------- helpers
def random_case(seed: int, n: int, discrete: bool, size: float, p: int = 2, l: int = 3, m: int = 2):
    """A random plant, its LQR gain (u = K x, from python-control) and a NormBounded of ``size``."""
    rng = np.random.default_rng(seed)
    F, G = rng.standard_normal((n, n)) / np.sqrt(n), rng.standard_normal((n, m))
    K_pc = (control.dlqr if discrete else control.lqr)(F, G, np.eye(n), np.eye(m))[0]
    plant = rc.Plant(F, G, 0.1 if discrete else None)
    unc = rc.NormBounded(size * rng.standard_normal((n, p)), rng.standard_normal((l, n)),
                         0.3 * rng.standard_normal((l, m)))
    return plant, -np.asarray(K_pc), unc


def case_with_margin(seed: int, n: int, discrete: bool, margin: float):
    """``random_case`` with H scaled so that the small-gain margin is ``margin`` (linfnorm)."""
    plant, K, unc = random_case(seed, n, discrete, 1.0)
    scale = 1.0 / (margin * small_gain(plant, K, unc))
    return plant, K, rc.NormBounded(scale * unc.H, unc.EF, unc.EG)


def loop(plant, K, unc):
    return plant.F + plant.G @ K, unc.H, unc.EF + unc.EG @ K


def small_gain(plant, K, unc) -> float:
    """``||E (zI - A)^-1 H||_inf`` by python-control (SLICOT AB13DD)."""
    A, H, E = loop(plant, K, unc)
    sys = control.ss(A, H, E, np.zeros((E.shape[0], H.shape[1])), plant.dt if plant.is_discrete else 0)
    return float(control.linfnorm(sys)[0])


def sample_deltas(seed: int, p: int, l: int, count: int = 200) -> np.ndarray:
    """Extreme points (all singular values 1), rank-one boundary points and interior points of the unit ball."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        M = rng.standard_normal((p, l))
        U, s, Vt = np.linalg.svd(M, full_matrices=False)
        if k % 3 == 0:
            out.append(U @ Vt)
        elif k % 3 == 1:
            out.append(np.outer(U[:, 0], Vt[0]))
        else:
            out.append(rng.uniform() * M / s[0])
    return np.array(out)


def worst_direction_vertices(plant, K, unc) -> list[np.ndarray]:
    """+- the unit-norm real part of the small-gain destabiliser at the peak frequency, +- its polar factor."""
    A, H, E = loop(plant, K, unc)
    sys = control.ss(A, H, E, np.zeros((E.shape[0], H.shape[1])), plant.dt if plant.is_discrete else 0)
    _, w = control.linfnorm(sys)
    z = np.exp(1j * w * plant.dt) if plant.is_discrete else 1j * w
    T = E @ np.linalg.solve(z * np.eye(plant.n) - A, H)
    U, _, Vh = np.linalg.svd(T)
    D = np.outer(Vh[0].conj(), U[:, 0].conj()).real
    Ud, _, Vtd = np.linalg.svd(D, full_matrices=False)
    return [s * M for M in (D / np.linalg.norm(D, 2), Ud @ Vtd) for s in (1.0, -1.0)]


def spectral(A, discrete) -> float:
    lam = np.linalg.eigvals(A)
    return float(np.max(np.abs(lam)) if discrete else np.max(lam.real))


def lq_cost(A, QK, x0, discrete) -> float:
    """``sum_k x'Q_K x`` (or the integral) of ``x+ = A x`` from ``x0`` by scipy's Lyapunov solvers."""
    if discrete:
        P = scipy.linalg.solve_discrete_lyapunov(A.T, QK)
    else:
        P = scipy.linalg.solve_continuous_lyapunov(A.T, -QK)
    return float(x0 @ P @ x0)


CASES = [(seed, n, discrete) for discrete in (True, False) for n in (2, 4, 7) for seed in range(3)]


# ---------------------------------------------------------------- robust_stability, norm-bounded
@pytest.mark.parametrize("seed,n,discrete", CASES)
def test_margin_equals_the_small_gain_value(seed, n, discrete):
    certified = []
    for size in (1e-3, 0.3, 30.0):
        plant, K, unc = random_case(seed, n, discrete, size)
        res = rc.robust_stability((plant, K), unc)
        gain = small_gain(plant, K, unc)
        assert res.margin == pytest.approx(1.0 / gain, rel=1e-4)
        if abs(res.margin - 1.0) > 1e-3:
            assert res.certified == (gain < 1.0)
        certified.append(res.certified)
    assert any(certified)  # the sizes put the margin on both sides of 1
    assert not all(certified)


@pytest.mark.parametrize("discrete", [True, False])
def test_certificate_proves_quadratic_stability(discrete):
    """The returned P decreases along every sampled perturbed loop (no S-procedure involved)."""
    plant, K, unc = random_case(5, 5, discrete, 0.05)
    res = rc.robust_stability(rc.Controller(K, "lqr", plant), unc)
    assert res.certified and res.radius == 1.0 and res.margin > 1.5
    P = res.P
    assert np.allclose(P, P.T) and np.linalg.eigvalsh(P).min() > 0
    assert min(res.certificate.values()) > 0
    A, H, E = loop(plant, K, unc)
    for D in sample_deltas(0, unc.p, unc.l):
        AD = A + H @ D @ E
        V = AD.T @ P @ AD - P if discrete else AD.T @ P + P @ AD
        assert np.linalg.eigvalsh(V).max() < 0
    # the certificate is the LMI of the module docstring, recomputed here
    p = unc.p
    if discrete:
        M = np.block([[P - A.T @ P @ A - E.T @ E, -A.T @ P @ H], [-H.T @ P @ A, np.eye(p) - H.T @ P @ H]])
    else:
        M = np.block([[-(A.T @ P + P @ A) - E.T @ E, -P @ H], [-H.T @ P, np.eye(p)]])
    assert res.certificate["lyapunov"] == pytest.approx(np.linalg.eigvalsh(M).min(), rel=1e-9, abs=1e-14)


@pytest.mark.parametrize("discrete", [True, False])
def test_uncertified_loop_gets_a_certificate_just_below_its_margin(discrete):
    plant, K, unc = random_case(1, 4, discrete, 3.0)
    res = rc.robust_stability((plant, K), unc)
    assert not res.certified and res.margin < 1
    assert res.radius == pytest.approx(res.margin / (1 + 1e-3), rel=1e-12)
    A, H, E = loop(plant, K, unc)
    for D in res.radius * sample_deltas(1, unc.p, unc.l, 60):
        AD = A + H @ D @ E
        V = AD.T @ res.P @ AD - res.P if discrete else AD.T @ res.P + res.P @ AD
        assert np.linalg.eigvalsh(V).max() < 0


@pytest.mark.parametrize("discrete", [True, False])
def test_scalar_loop_closed_form(discrete):
    """n = 1: x+ = (a + h d e) x is stable for |d| <= r iff |a| + r |h e| < 1 (continuous: a + r |h e| < 0)."""
    a, h, e = (0.6, -0.5, 0.4) if discrete else (-1.5, 0.5, 2.0)
    res = rc.robust_stability((rc.Plant([[a]], [[1.0]], 0.1 if discrete else None), [[0.0]]),
                              rc.NormBounded([[h]], [[e]], [[0.0]]))
    exact = (1 - abs(a)) / abs(h * e) if discrete else -a / abs(h * e)
    assert res.margin == pytest.approx(exact, rel=1e-8)
    assert res.certified == (exact > 1)


def test_unstable_nominal_loop_has_margin_zero():
    plant = rc.Plant([[1.2, 0.0], [0.0, 0.5]], [[1.0], [0.0]], 0.1)
    res = rc.robust_stability((plant, [[0.0, 0.0]]), rc.NormBounded(np.zeros((2, 1)), [[0.0, 0.0]], [[0.0]]))
    assert res.margin == 0.0 and not res.certified and res.P is None and res.radius == 0.0


@pytest.mark.parametrize("discrete", [True, False])
def test_uncertainty_outside_the_loop_has_infinite_margin(discrete):
    plant, K, unc = random_case(2, 3, discrete, 1.0)
    for u in (rc.NormBounded(np.zeros_like(unc.H), unc.EF, unc.EG),   # H = 0
              rc.NormBounded(unc.H, -unc.EG @ K, unc.EG)):             # EF + EG K = 0 (RLQR with mu = inf)
        res = rc.robust_stability((plant, K), u)
        assert res.margin == np.inf and res.certified and min(res.certificate.values()) > 0


# ---------------------------------------------------------------- robust_stability, polytope
def ray_root(A0, D, discrete) -> float:
    """Smallest r > 0 where A0 + r D loses stability (scipy brentq on the eigenvalues), inf if none below 100."""
    f = lambda r: spectral(A0 + r * D, discrete) - (1.0 if discrete else 0.0)  # noqa: E731
    grid = np.linspace(0, 100, 20001)
    bad = next((r for r in grid if f(r) >= 0), None)
    return np.inf if bad is None else scipy.optimize.brentq(f, grid[grid < bad][-1], bad, xtol=1e-12)


@pytest.mark.parametrize("discrete", [True, False])
def test_polytope_of_symmetric_loops_closed_form(discrete):
    """Symmetric vertices: P = I works iff every vertex is stable, so the margin is the first ray root."""
    rng = np.random.default_rng(4)
    n = 4

    def sym(scale):
        M = rng.standard_normal((n, n))
        return scale * (M + M.T) / 2

    A0 = sym(0.15) + (0.0 if discrete else -2.0) * np.eye(n)
    plants = [rc.Plant(A0 + sym(0.12), np.ones((n, 1)), 0.1 if discrete else None) for _ in range(3)]
    nominal = rc.Plant(A0, np.ones((n, 1)), 0.1 if discrete else None)
    res = rc.robust_stability((nominal, np.zeros((1, n))), vertices=plants)
    exact = min(ray_root(A0, p.F - A0, discrete) for p in plants)
    assert np.isfinite(exact)
    assert res.margin <= exact * (1 + 1e-9)          # the reported end of the bracket is certified
    assert res.margin == pytest.approx(exact, rel=2e-3)
    assert res.certified == (exact > 1)


@pytest.mark.parametrize("discrete", [True, False])
def test_polytope_certificate_holds_inside_the_hull(discrete):
    plant, K, _ = random_case(7, 4, discrete, 1.0)
    rng = np.random.default_rng(0)
    vertices = [rc.Plant(plant.F + 0.05 * rng.standard_normal((4, 4)), plant.G + 0.05 * rng.standard_normal((4, 2)),
                         plant.dt) for _ in range(3)]
    res = rc.robust_stability((plant, K), vertices=vertices)
    assert res.certified and res.margin > 1 and set(res.certificate) == {"P", "vertex[0]", "vertex[1]",
                                                                          "vertex[2]", "vertex[3]"}
    P = res.P
    loops = [p.F + p.G @ K for p in [plant, *vertices]]
    for _ in range(100):
        w = rng.dirichlet(np.ones(4))
        A = sum(wi * Ai for wi, Ai in zip(w, loops, strict=True))
        V = A.T @ P @ A - P if discrete else A.T @ P + P @ A
        assert np.linalg.eigvalsh(V).max() < 0
    # beyond the margin some vertex ray is (eventually) unstable or no common P exists: never above the ray roots
    A0 = loops[0]
    assert res.margin <= min(ray_root(A0, Ai - A0, discrete) for Ai in loops[1:]) * (1 + 1e-9)


def test_polytope_with_identical_vertices_has_infinite_margin():
    plant, K, _ = random_case(0, 3, True, 1.0)
    res = rc.robust_stability((plant, K), vertices=[plant])
    assert res.margin == np.inf and res.certified


# ---------------------------------------------------------------- the truck
@pytest.fixture(scope="module")
def truck_designs():
    plant = truck.truck_plant(0.0)
    Q, R = truck.lqr_weights()
    lqr = rc.design("lqr", plant, Q=Q, R=R)
    u = morais2022.algebraic_uncertainty("printed")
    Q2, R2 = truck.lqr_weights(doubled=True)
    rlqr = rc.design("rlqr", truck.truck_plant(0.0, doubled=True), u.EF, u.EG, u.mu, Q=Q2, R=R2, H=u.H)
    return plant, lqr, rlqr, u


def test_truck_norm_bounded_margin(truck_designs):
    """RLQR^A's norm-bounded model (appendix): the margin on the doubled-column plant equals that of
    its steering gain on the single-column plant, and the small-gain value of linfnorm."""
    plant, lqr, rlqr, u = truck_designs
    single = rc.NormBounded(u.H, u.EF, u.EG[:, :1])   # both printed EG entries are equal
    for ctrl in (lqr, rlqr):
        res = rc.robust_stability(ctrl, single if ctrl is lqr else rc.NormBounded(u.H, u.EF, u.EG))
        assert res.margin == pytest.approx(1.0 / small_gain(ctrl.plant, ctrl.K, single if ctrl is lqr else
                                                             rc.NormBounded(u.H, u.EF, u.EG)), rel=1e-4)
        assert res.certified and min(res.certificate.values()) > 0
    steer = rc.robust_stability((plant, rlqr.K.sum(axis=0, keepdims=True)), single)
    assert steer.margin == pytest.approx(rc.robust_stability(rlqr, rc.NormBounded(u.H, u.EF, u.EG)).margin,
                                         rel=1e-6)
    wc = rc.worst_case(lqr, single, seed=0)
    assert not wc.destabilizing and wc.radius > wc.nominal_radius


def test_truck_payload_polytope(truck_designs):
    plant, lqr, rlqr, _ = truck_designs
    vertices = [truck.truck_plant(k) for k in (100.0, 200.0, 300.0)]
    res = rc.robust_stability(lqr, vertices=vertices)
    assert res.certified and res.margin > 1
    P = res.P
    for k in np.linspace(0, 300, 7):     # the certified P on the vertices
        A = lqr.closed_loop(truck.truck_plant(k))
        if k in (0, 100, 200, 300):
            assert np.linalg.eigvalsh(A.T @ P @ A - P).max() < 0
    # RLQR^A: stable at every frozen payload, but no common quadratic Lyapunov function over the polytope
    K = rlqr.K.sum(axis=0, keepdims=True)
    assert all(spectral(truck.truck_plant(k).F + truck.truck_plant(k).G @ K, True) < 1
               for k in np.linspace(0, 300, 31))
    res_a = rc.robust_stability((plant, K), vertices=vertices)
    assert not res_a.certified and 0 < res_a.margin < 1
    A0 = plant.F + plant.G @ K
    assert res_a.margin <= min(ray_root(A0, v.F + v.G @ K - A0, True) for v in vertices)


# ---------------------------------------------------------------- guaranteed cost
@pytest.mark.parametrize("discrete", [True, False])
def test_guaranteed_cost_without_uncertainty_is_the_lyapunov_cost(discrete):
    plant, K, unc = random_case(3, 4, discrete, 1.0)
    rng = np.random.default_rng(1)
    Q, R, x0 = np.diag(rng.uniform(0.5, 2, 4)), np.eye(2) * 0.7, rng.standard_normal(4)
    none = rc.NormBounded(np.zeros_like(unc.H), unc.EF, unc.EG)
    A = plant.F + plant.G @ K
    QK = Q + K.T @ R @ K
    assert rc.guaranteed_cost((plant, K), none, Q, R, x0=x0).bound == pytest.approx(lq_cost(A, QK, x0, discrete),
                                                                                    rel=1e-6)
    P = (scipy.linalg.solve_discrete_lyapunov(A.T, QK) if discrete
         else scipy.linalg.solve_continuous_lyapunov(A.T, -QK))
    assert rc.guaranteed_cost((plant, K), none, Q, R).bound == pytest.approx(np.linalg.eigvalsh(P).max(), rel=1e-6)


@pytest.mark.parametrize("discrete", [True, False])
def test_guaranteed_cost_scalar_closed_form(discrete):
    """n = 1: the worst perturbation is constant, d = sign(a h e): J = q x0^2 / (1 - (|a| + |h e|)^2)."""
    a, h, e, k, q, r, x0 = (0.5, 0.6, 0.5, -0.1, 2.0, 1.0, 1.5) if discrete else (-1.0, 1.0, 0.8, -1.0, 2.0, 1.0, 1.5)
    res = rc.guaranteed_cost((rc.Plant([[a]], [[1.0]], 0.1 if discrete else None), [[k]]),
                             rc.NormBounded([[h]], [[e]], [[0.0]]), [[q]], [[r]], x0=[x0])
    acl = a + k
    worst = abs(acl) + abs(h * e) if discrete else acl + abs(h * e)
    qk = q + r * k**2
    exact = qk * x0**2 / (1 - worst**2) if discrete else qk * x0**2 / (-2 * worst)
    assert res.bound == pytest.approx(exact, rel=1e-7)


@pytest.mark.parametrize("seed,n,discrete", [(s, n, d) for d in (True, False) for n in (3, 6) for s in range(2)])
def test_guaranteed_cost_bounds_every_sampled_perturbation(seed, n, discrete):
    plant, K, unc = case_with_margin(seed, n, discrete, 1.25)
    rng = np.random.default_rng(seed)
    Q, R = np.eye(n), 0.5 * np.eye(2)
    QK = Q + K.T @ R @ K
    A, H, E = loop(plant, K, unc)
    x0 = rng.standard_normal(n)
    given = rc.guaranteed_cost((plant, K), unc, Q, R, x0=x0)
    worst_unit = rc.guaranteed_cost((plant, K), unc, Q, R)
    wc = rc.worst_case((plant, K), unc, seed=seed)
    deltas = [*sample_deltas(seed, unc.p, unc.l), *worst_direction_vertices(plant, K, unc), wc.Delta, -wc.Delta]
    units = rng.standard_normal((20, n))
    units /= np.linalg.norm(units, axis=1, keepdims=True)
    for D in deltas:
        AD = A + H @ D @ E
        assert lq_cost(AD, QK, x0, discrete) <= given.bound * (1 + 1e-7)
        P = (scipy.linalg.solve_discrete_lyapunov(AD.T, QK) if discrete
             else scipy.linalg.solve_continuous_lyapunov(AD.T, -QK))
        assert np.linalg.eigvalsh(P).max() <= worst_unit.bound * (1 + 1e-7)
    assert given.bound <= x0 @ x0 * worst_unit.bound * (1 + 1e-7)
    assert given.multiplier > 0 and np.allclose(given.P, given.P.T)


def test_guaranteed_cost_is_infeasible_without_robust_stability():
    plant, K, unc = random_case(1, 4, True, 3.0)
    with pytest.raises(InfeasibleError, match=r"not quadratically stable.*margin"):
        rc.guaranteed_cost((plant, K), unc, np.eye(4), np.eye(2))
    unstable = rc.Plant(np.diag([1.1, 0.5]), [[1.0], [0.0]], 0.1)
    with pytest.raises(InfeasibleError, match="nominal closed loop F \\+ G K is unstable"):
        rc.guaranteed_cost((unstable, [[0.0, 0.0]]), rc.NormBounded(np.ones((2, 1)), [[1.0, 0.0]], [[0.0]]),
                           np.eye(2), [[1.0]])


def test_bounds_do_not_depend_on_the_units_of_the_weights_and_channels():
    """Q, R times a^2 and x0 times b scale the cost by (a b)^2; z times a and w times b scale gamma by a b.

    With the weights of the authors' code (R = 33535) the guaranteed-cost LMI without x0 was infeasible,
    with Q, R times 1e3 the solver stopped (user_limit) and with x0 times 1e-6 the bound came out 4x too high.
    References: the LQ cost (scipy's Lyapunov solver) and linfnorm at every constant Delta of a grid.
    """
    plant = truck.truck_plant(0.0)
    Q, R = morais2022.authors_weights()
    ctrl = rc.lqr(plant, Q=Q, R=R)
    unc = rc.NormBounded(plant.G, [[0.1, 0.0, 0.0, 0.0]], [[0.1]])
    x0 = np.array([0.1, 0.0, 0.05, 0.01])
    Bw, (Cz, Dzu) = np.ones((4, 1)), rc.lq_output(Q, R)
    given, worst_unit = rc.guaranteed_cost(ctrl, unc, Q, R, x0), rc.guaranteed_cost(ctrl, unc, Q, R)
    hinf = rc.robust_hinf_bound(ctrl, unc, Bw=Bw, Cz=Cz, Dzu=Dzu)
    A, H, E = loop(plant, ctrl.K, unc)
    QK, C = Q + ctrl.K.T @ R @ ctrl.K, Cz + Dzu @ ctrl.K
    for d in np.linspace(-1.0, 1.0, 21):
        AD = A + d * H @ E
        assert lq_cost(AD, QK, x0, True) <= given.bound * (1 + 1e-7)
        assert np.linalg.eigvalsh(scipy.linalg.solve_discrete_lyapunov(AD.T, QK)).max() <= worst_unit.bound * (1 + 1e-7)
        assert hinf_norm(AD, Bw, C, np.zeros((5, 1)), plant) <= hinf.gamma * (1 + 1e-6)
    for a, b in [(1e-6, 1.0), (1e-3, 1e3), (1e3, 1e-3), (1e6, 1e6), (1.0, 1e-6), (1e-6, 1e6)]:
        res = rc.guaranteed_cost(ctrl, unc, a**2 * Q, a**2 * R, b * x0)
        assert res.bound / (a * b) ** 2 == pytest.approx(given.bound, rel=1e-6), (a, b)
        res = rc.guaranteed_cost(ctrl, unc, a**2 * Q, a**2 * R)
        assert res.bound / a**2 == pytest.approx(worst_unit.bound, rel=1e-6), (a, b)
        res = rc.robust_hinf_bound(ctrl, unc, Bw=b * Bw, Cz=a * Cz, Dzu=a * Dzu)
        assert res.gamma / (a * b) == pytest.approx(hinf.gamma, rel=1e-6), (a, b)


# ---------------------------------------------------------------- robust H-infinity bound
def hinf_norm(A, Bw, C, Dzw, plant) -> float:
    return float(control.linfnorm(control.ss(A, Bw, C, Dzw, plant.dt if plant.is_discrete else 0))[0])


@pytest.mark.parametrize("discrete", [True, False])
def test_hinf_bound_without_uncertainty_is_the_nominal_norm(discrete):
    plant, K, unc = random_case(4, 5, discrete, 1.0)
    rng = np.random.default_rng(2)
    Bw, Cz, Dzu, Dzw = (rng.standard_normal((5, 2)), rng.standard_normal((3, 5)), rng.standard_normal((3, 2)),
                        0.1 * rng.standard_normal((3, 2)))
    none = rc.NormBounded(unc.H, np.zeros_like(unc.EF), np.zeros_like(unc.EG))
    res = rc.robust_hinf_bound((plant, K), none, Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw)
    assert res.gamma == pytest.approx(hinf_norm(plant.F + plant.G @ K, Bw, Cz + Dzu @ K, Dzw, plant), rel=1e-5)


@pytest.mark.parametrize("discrete", [True, False])
def test_hinf_bound_scalar_closed_form(discrete):
    """n = 1, x+ = (a + h d e) x + b w, z = c x: sup over |d| <= 1 of |c b| / (1 - |a| - |h e|)."""
    a, h, e, b, c = (0.5, 0.6, 0.5, 0.7, 1.3) if discrete else (-2.0, 1.0, 0.8, 0.7, 1.3)
    res = rc.robust_hinf_bound((rc.Plant([[a]], [[1.0]], 0.1 if discrete else None), [[0.0]]),
                               rc.NormBounded([[h]], [[e]], [[0.0]]), Bw=[[b]], Cz=[[c]], Dzu=[[0.0]])
    exact = abs(b * c) / (1 - abs(a) - abs(h * e)) if discrete else abs(b * c) / -(a + abs(h * e))
    assert res.gamma == pytest.approx(exact, rel=1e-6)


@pytest.mark.parametrize("seed,n,discrete", [(s, n, d) for d in (True, False) for n in (3, 6) for s in range(2)])
def test_hinf_bound_covers_every_sampled_perturbation(seed, n, discrete):
    plant, K, unc = case_with_margin(seed, n, discrete, 1.25)
    rng = np.random.default_rng(seed + 10)
    Bw, Cz = rng.standard_normal((n, 2)), rng.standard_normal((2, n))
    Dzu = rng.standard_normal((2, 2))
    res = rc.robust_hinf_bound(rc.Controller(K, "lqr", plant), unc, Bw=Bw, Cz=Cz, Dzu=Dzu)
    A, H, E = loop(plant, K, unc)
    C = Cz + Dzu @ K
    nominal = hinf_norm(A, Bw, C, np.zeros((2, 2)), plant)
    wc = rc.worst_case((plant, K), unc, seed=seed)
    norms = [hinf_norm(A + H @ D @ E, Bw, C, np.zeros((2, 2)), plant)
             for D in [*sample_deltas(seed, unc.p, unc.l, 60), *worst_direction_vertices(plant, K, unc), wc.Delta]]
    assert max(norms) <= res.gamma * (1 + 1e-6)
    assert res.gamma >= nominal and max(norms) > nominal


# ---------------------------------------------------------------- worst case
@pytest.mark.parametrize("discrete", [True, False])
def test_worst_case_radius_is_the_reported_loop(discrete):
    plant, K, unc = random_case(2, 4, discrete, 0.5)
    ctrl = rc.Controller(K, "lqr", plant)
    wc = rc.worst_case(ctrl, unc, seed=3, n_starts=10)
    poles = ctrl.closed_loop_poles(unc.perturb(plant, wc.Delta))
    assert wc.radius == pytest.approx(np.max(np.abs(poles)) if discrete else np.max(poles.real), rel=1e-12)
    assert wc.destabilizing == (not ctrl.is_stabilizing(unc.perturb(plant, wc.Delta)))
    assert np.linalg.norm(wc.Delta, 2) <= 1 + 1e-12
    assert wc.nominal_radius == pytest.approx(spectral(plant.F + plant.G @ K, discrete), rel=1e-12)
    again = rc.worst_case(ctrl, unc, seed=3, n_starts=10)
    assert np.array_equal(again.Delta, wc.Delta)


@pytest.mark.parametrize("discrete", [True, False])
def test_worst_case_beats_a_dense_grid_for_a_scalar_delta(discrete):
    plant, K, unc = random_case(6, 5, discrete, 0.8, p=1, l=1)
    wc = rc.worst_case((plant, K), unc, seed=0, n_starts=0)
    A, H, E = loop(plant, K, unc)
    grid = max(spectral(A + d * H @ E, discrete) for d in np.linspace(-1, 1, 2001))
    assert wc.radius >= grid - 1e-12


@pytest.mark.parametrize("discrete", [True, False])
def test_worst_case_beats_random_samples(discrete):
    plant, K, unc = random_case(8, 4, discrete, 0.5)
    wc = rc.worst_case((plant, K), unc, seed=1)
    A, H, E = loop(plant, K, unc)
    sampled = max(spectral(A + H @ D @ E, discrete) for D in sample_deltas(5, unc.p, unc.l, 2000))
    assert wc.radius >= sampled - 1e-9


def test_worst_case_agrees_with_the_certificate():
    for seed in range(4):
        for size in (0.02, 3.0):
            plant, K, unc = random_case(seed, 4, True, size, p=1, l=1)
            res = rc.robust_stability((plant, K), unc)
            wc = rc.worst_case((plant, K), unc, seed=seed)
            if res.certified:
                assert not wc.destabilizing
    # a real destabiliser exists when the small-gain peak is at z = 1: x+ = (0.5 + 0.6 d) x
    plant = rc.Plant([[0.5]], [[1.0]], 0.1)
    unc = rc.NormBounded([[0.6]], [[1.0]], [[0.0]])
    wc = rc.worst_case((plant, [[0.0]]), unc, seed=0)
    assert wc.destabilizing and wc.radius == pytest.approx(1.1) and wc.Delta[0, 0] == pytest.approx(1.0)


# ---------------------------------------------------------------- results and bad input
def test_results_are_frozen_and_readable():
    plant, K, unc = random_case(0, 3, True, 0.05)
    res = rc.robust_stability((plant, K), unc)
    assert "RobustStability(certified=True" in repr(res)
    with pytest.raises(dataclasses.FrozenInstanceError):
        res.margin = 2.0
    with pytest.raises(ValueError, match="read-only"):
        res.P[0, 0] = 1.0
    assert "CostBound(bound=" in repr(rc.guaranteed_cost((plant, K), unc, np.eye(3), np.eye(2)))
    assert "HinfBound(gamma=" in repr(rc.robust_hinf_bound((plant, K), unc, Bw=np.eye(3), Cz=np.eye(3),
                                                           Dzu=np.zeros((3, 2))))
    assert "WorstCase(radius=" in repr(rc.worst_case((plant, K), unc, seed=0, n_starts=2))
    for name in ("robust_stability", "guaranteed_cost", "robust_hinf_bound", "worst_case", "RobustStability"):
        assert name in rc.__all__


def test_bad_input_names_the_argument():
    plant, K, unc = random_case(0, 3, True, 0.05)
    with pytest.raises(TypeError,
                       match=r"controller must be a robustctl\.Controller, a ControllerBatch or a \(Plant, K\) pair"):
        rc.robust_stability(K, unc)
    with pytest.raises(ValueError, match="K must have 2 rows \\(the number of inputs\\), got shape \\(3, 3\\)"):
        rc.robust_stability((plant, np.eye(3)), unc)
    with pytest.raises(TypeError, match=r"uncertainty must be a robustctl\.NormBounded"):
        rc.robust_stability((plant, K), "big")
    with pytest.raises(ValueError, match="uncertainty is for n=4 states"):
        rc.robust_stability((plant, K), rc.NormBounded(np.ones((4, 1)), np.ones((1, 4)), np.ones((1, 2))))
    with pytest.raises(ValueError, match="exactly one of uncertainty"):
        rc.robust_stability((plant, K))
    with pytest.raises(ValueError, match="exactly one of uncertainty"):
        rc.robust_stability((plant, K), unc, vertices=[plant])
    with pytest.raises(TypeError, match="vertices must be a non-empty list"):
        rc.robust_stability((plant, K), vertices=plant)
    with pytest.raises(TypeError, match=r"vertices\[0\] must be a robustctl\.Plant"):
        rc.robust_stability((plant, K), vertices=[np.eye(3)])
    with pytest.raises(ValueError, match="vertices\\[0\\] must have the sampling time"):
        rc.robust_stability((plant, K), vertices=[rc.Plant(plant.F, plant.G, 0.2)])
    with pytest.raises(ValueError, match="vertices\\[0\\] must have n=3 states and m=2 inputs"):
        rc.robust_stability((plant, K), vertices=[rc.Plant(np.eye(2), np.ones((2, 2)), 0.1)])
    with pytest.raises(ValueError, match="Q must have 3 rows \\(the number of states\\), got shape \\(2, 2\\)"):
        rc.guaranteed_cost((plant, K), unc, np.eye(2), np.eye(2))
    with pytest.raises(ValueError, match="R must be positive semidefinite"):
        rc.guaranteed_cost((plant, K), unc, np.eye(3), -np.eye(2))
    with pytest.raises(ValueError, match="x0 must have size 3 along axis 0 \\(the number of states\\)"):
        rc.guaranteed_cost((plant, K), unc, np.eye(3), np.eye(2), x0=[1.0, 2.0])
    with pytest.raises(ValueError, match="x0 must have finite entries"):
        rc.guaranteed_cost((plant, K), unc, np.eye(3), np.eye(2), x0=[1.0, np.nan, 0.0])
    with pytest.raises(ValueError, match="Bw must have 3 rows \\(the number of states\\)"):
        rc.robust_hinf_bound((plant, K), unc, Bw=np.eye(2), Cz=np.eye(3), Dzu=np.zeros((3, 2)))
    with pytest.raises(ValueError, match="Dzu must have 2 columns \\(the number of inputs\\)"):
        rc.robust_hinf_bound((plant, K), unc, Bw=np.eye(3), Cz=np.eye(3), Dzu=np.zeros((3, 3)))
    for bad in (-1, 2.5, True):
        with pytest.raises(ValueError, match="n_starts must be an integer >= 0"):
            rc.worst_case((plant, K), unc, n_starts=bad)
    with pytest.raises(TypeError, match=r"uncertainty must be a robustctl\.NormBounded"):
        rc.worst_case((plant, K), None)
