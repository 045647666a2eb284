"""robust_stability on stacks of gains and its Riccati path: margins against python-control's linfnorm
(SLICOT AB13DD), certificates recomputed here, batch against single calls, the SDP fallback, bad input."""

from __future__ import annotations

import dataclasses
import pickle

import control
import numpy as np
import pytest
import scipy.linalg

import robustctl as rc
from robustctl import analysis
from robustctl.analysis import _hinfnorm
from robustctl.errors import InfeasibleError


@pytest.fixture(params=["ab13dd", "level-set"])
def norm(request, monkeypatch) -> str:
    """The H-infinity norm of single-loop calls: SLICOT AB13DD (slycot) or the pure numpy/scipy level-set path."""
    if request.param == "level-set":
        monkeypatch.setattr(_hinfnorm, "slicot_ab13dd", lambda: None)
    elif _hinfnorm.slicot_ab13dd() is None:
        pytest.skip("slycot is not installed")
    return request.param


def random_loop(seed: int, n: int, discrete: bool, margin: float | None = None, p: int = 2, l: int = 3, m: int = 2):
    """A random plant, its LQR gain (u = K x, from python-control) and a NormBounded; with ``margin`` the
    channel H is scaled so that the small-gain margin (by linfnorm) is that value."""
    rng = np.random.default_rng(seed)
    F, G = rng.standard_normal((n, n)) / np.sqrt(n), rng.standard_normal((n, m))
    K = -np.asarray((control.dlqr if discrete else control.lqr)(F, G, np.eye(n), np.eye(m))[0])
    plant = rc.Plant(F, G, 0.1 if discrete else None)
    unc = rc.NormBounded(rng.standard_normal((n, p)), rng.standard_normal((l, n)), 0.3 * rng.standard_normal((l, m)))
    if margin is not None:
        unc = rc.NormBounded(unc.H / (margin * linf(plant, K, unc)), unc.EF, unc.EG)
    return plant, K, unc


def linf(plant, K, unc) -> float:
    """``||E (zI - A)^-1 H||_inf`` by python-control (SLICOT AB13DD), tight tolerance."""
    A, E = plant.F + plant.G @ K, unc.EF + unc.EG @ K
    sys = control.ss(A, unc.H, E, np.zeros((E.shape[0], unc.p)), plant.dt if plant.is_discrete else 0)
    return float(control.linfnorm(sys, tol=1e-12)[0])


def lmi(plant, K, unc, P, r: float = 1.0) -> np.ndarray:
    """The certificate LMI of robustctl.analysis at radius r, written out here."""
    A, H, E = plant.F + plant.G @ K, r * unc.H, unc.EF + unc.EG @ K
    p = unc.p
    if plant.is_discrete:
        return np.block([[P - A.T @ P @ A - E.T @ E, -A.T @ P @ H], [-H.T @ P @ A, np.eye(p) - H.T @ P @ H]])
    return np.block([[-(A.T @ P + P @ A) - E.T @ E, -P @ H], [-H.T @ P, np.eye(p)]])


def spectral(A, discrete: bool) -> float:
    """Spectral radius (discrete) or abscissa (continuous) by numpy."""
    lam = np.linalg.eigvals(A)
    return float(np.abs(lam).max() if discrete else lam.real.max())


def gain_stack(plant, K, count: int, seed: int, spread: float = 0.3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return K + spread * np.abs(K).max() * rng.standard_normal((count, *K.shape))


# ---------------------------------------------------------------- margins against linfnorm
@pytest.mark.parametrize("discrete", [True, False])
def test_margins_equal_one_over_linfnorm(discrete):
    for seed in range(4):
        for n in (1, 3, 6):
            plant, K, unc = random_loop(seed, n, discrete)
            Ks = gain_stack(plant, K, 6, seed, 0.2)
            res = rc.robust_stability((plant, Ks), unc)
            assert res.margin.shape == res.certified.shape == (6,) and res.P.shape == (6, n, n)
            for b in range(6):
                if res.reason[b] == "unstable":
                    assert res.margin[b] == 0.0
                    continue
                assert res.reason[b] == "ok"
                assert res.margin[b] * linf(plant, Ks[b], unc) == pytest.approx(1.0, rel=1e-8)
                if abs(res.margin[b] - 1.0) > 1e-6:
                    assert res.certified[b] == (res.margin[b] > 1.0)
                if res.certified[b]:
                    assert res.certificate["P"][b] > 0 and res.certificate["lyapunov"][b] > 0


@pytest.mark.parametrize("discrete", [True, False])
def test_single_loop_margins_equal_one_over_linfnorm(discrete, norm):
    """One loop per call, each norm path: margins to 1e-8 (n up to 20), the path named in info."""
    for seed in range(3):
        for n in (1, 4, 10, 20):
            plant, K, unc = random_loop(seed, n, discrete)
            res = rc.robust_stability((plant, K), unc)
            assert res.info["norm"] == norm
            assert res.margin * linf(plant, K, unc) == pytest.approx(1.0, rel=1e-8)
            assert res.info["path"] == "riccati" and min(res.certificate.values()) > 0
            assert res.certified == (res.margin > 1.0)


@pytest.mark.parametrize("discrete", [True, False])
def test_doubling_certificate_near_the_boundary_and_for_slow_loops(discrete):
    """n >= 14 (the doubling algorithm): margins either side of 1 and a loop with a pole near the boundary."""
    for seed, margin in ((0, 0.5), (1, 1.0 - 1e-4), (2, 1.0 + 1e-4), (3, 3.0)):
        plant, K, unc = random_loop(seed, 16, discrete, margin)
        res = rc.robust_stability((plant, K), unc)
        assert res.margin == pytest.approx(margin, rel=1e-8) and res.certified == (margin > 1)
        assert res.info["riccati"] == "doubling" and min(res.certificate.values()) > 0
        assert np.linalg.eigvalsh(lmi(plant, K, unc, res.P, res.radius))[0] > 0
    n = 16
    slow = (1.0 - 1e-5) if discrete else -1e-5
    F = np.diag(np.linspace(0.2, slow, n)) if discrete else np.diag(np.linspace(-3.0, slow, n))
    plant = rc.Plant(F, np.ones((n, 1)), 0.1 if discrete else None)
    unc = rc.NormBounded(np.ones((n, 1)), 1e-6 * np.ones((1, n)), [[0.0]])
    K = np.zeros((1, n))
    res = rc.robust_stability((plant, K), unc)
    assert res.margin * linf(plant, K, unc) == pytest.approx(1.0, rel=1e-8)
    assert res.info["path"] == "riccati" and min(res.certificate.values()) > 0


@pytest.mark.parametrize("discrete", [True, False])
def test_riccati_solvers_match_scipy(discrete):
    """The doubling algorithm and the Hamiltonian eigenvectors give scipy's stabilising ARE solution
    (the bounded-real equation is the LQ one with R = -gamma^2 I)."""
    for n in (3, 16):
        plant, K, unc = random_loop(0, n, discrete, 2.0)   # ||E (zI - A)^-1 H||_inf = 0.5
        A, H, E = plant.F + plant.G @ K, unc.H, unc.EF + unc.EG @ K
        gamma = 0.7
        are = scipy.linalg.solve_discrete_are if discrete else scipy.linalg.solve_continuous_are
        X = are(A, H, E.T @ E, -gamma**2 * np.eye(unc.p))
        P_sda = _hinfnorm.riccati_doubling(A, H, E, gamma, np.linalg.eigvals(A), discrete=discrete)
        P_eig = _hinfnorm.riccati_one(A, H, E, gamma, discrete=discrete)
        for P in (P_sda, P_eig):
            assert np.abs(P - X).max() <= 1e-8 * np.abs(X).max()


def test_a_failing_ab13dd_falls_back_to_the_level_set_norm(monkeypatch):
    plant, K, unc = random_loop(2, 6, True, 1.7)

    def failing(*args):
        raise ArithmeticError("AB13DD did not converge")

    monkeypatch.setattr(_hinfnorm, "slicot_ab13dd", lambda: failing)
    res = rc.robust_stability((plant, K), unc)
    assert res.info["norm"] == "level-set" and res.margin == pytest.approx(1.7, rel=1e-8) and res.certified


@pytest.mark.parametrize("discrete", [True, False])
def test_certified_matches_the_small_gain_test_and_the_certificate_holds(discrete, norm):
    for seed in range(3):
        for margin in (0.2, 0.9, 1.1, 5.0):
            plant, K, unc = random_loop(seed, 5, discrete, margin)
            res = rc.robust_stability((plant, K), unc)
            assert res.margin == pytest.approx(margin, rel=1e-8) and res.info["norm"] == norm
            assert res.certified == (margin > 1) and res.info["path"] == "riccati"
            # the reported eigenvalues are those of the LMI at radius, recomputed here
            M = lmi(plant, K, unc, res.P, res.radius)
            assert res.certificate["lyapunov"] == pytest.approx(np.linalg.eigvalsh(M)[0], rel=1e-6, abs=1e-13)
            assert res.certificate["P"] == pytest.approx(np.linalg.eigvalsh(res.P)[0], rel=1e-6, abs=1e-13)
            assert min(res.certificate.values()) > 0
            assert res.radius == (1.0 if margin > 1 else pytest.approx(res.margin / (1 + 1e-3), rel=1e-12))


@pytest.mark.parametrize("discrete", [True, False])
def test_boundary(discrete, norm):
    for margin, certified in ((1.0 + 1e-5, True), (1.0 - 1e-5, False)):
        plant, K, unc = random_loop(7, 4, discrete, margin)
        res = rc.robust_stability((plant, K), unc)
        assert res.margin == pytest.approx(margin, rel=1e-8)
        assert res.certified == certified and min(res.certificate.values()) > 0


@pytest.mark.parametrize("discrete", [True, False])
def test_marginally_stable_and_unstable_loops(discrete, norm):
    # a pole exactly on the boundary (integrator / unit delay left in place): margin 0, reason "unstable"
    F = np.diag([1.0, 0.5]) if discrete else np.diag([0.0, -1.0])
    plant = rc.Plant(F, [[0.0], [1.0]], 0.1 if discrete else None)
    unc = rc.NormBounded([[1.0], [1.0]], [[0.1, 0.1]], [[0.0]])
    res = rc.robust_stability((plant, np.zeros((3, 1, 2))), unc)
    assert (res.margin == 0).all() and not res.certified.any() and (res.reason == "unstable").all()
    assert np.isnan(res.P).all() and (res.info["path"] == "").all()
    single = rc.robust_stability((plant, [[0.0, 0.0]]), unc)
    assert single.margin == 0.0 and single.P is None and not single.certified
    # just inside the boundary: a small margin, still exact
    eps = 1e-5
    F = np.diag([1.0 - eps, 0.5]) if discrete else np.diag([-eps, -1.0])
    plant = rc.Plant(F, [[0.0], [1.0]], 0.1 if discrete else None)
    res = rc.robust_stability((plant, np.zeros((1, 2))), unc)
    assert res.margin == pytest.approx(1.0 / linf(plant, np.zeros((1, 2)), unc), rel=1e-8)
    assert res.margin < 1e-3 and not res.certified and min(res.certificate.values()) > 0


# ---------------------------------------------------------------- batch against single calls
@pytest.mark.parametrize("discrete", [True, False])
def test_batch_equals_single_calls_and_flags_bad_designs(discrete, norm):
    # the batch always runs the level-set norm: the same one, or AB13DD's, both to 2e-10 relative
    rel = 1e-12 if norm == "level-set" else 1e-9
    plant, K, unc = random_loop(3, 4, discrete, 1.5)
    Ks = gain_stack(plant, K, 8, 0, 0.4)
    Ks[2] = 0.0 * K + 10.0          # destabilising
    Ks[5, 0, 1] = np.nan            # a failed design upstream
    res = rc.robust_stability((plant, Ks), unc)
    assert isinstance(res, analysis.RobustStabilityBatch) and len(res) == 8
    assert res.reason[5] == "not finite" and np.isnan(res.margin[5]) and not res.certified[5]
    assert res.reason[2] == "unstable" and res.margin[2] == 0.0
    assert 0 < res.certified.sum() < 6   # both answers occur
    for b in range(8):
        if b == 5:
            continue
        one = rc.robust_stability((plant, Ks[b]), unc)
        assert one.certified == res.certified[b] and one.radius == pytest.approx(res.radius[b], rel=rel)
        assert one.margin == pytest.approx(res.margin[b], rel=rel, abs=0)
        assert one.info["nominal_radius"] == pytest.approx(res.info["nominal_radius"][b], rel=1e-12)
        if one.P is None:
            assert np.isnan(res.P[b]).all()
        else:
            assert np.allclose(one.P, res.P[b], rtol=1e3 * rel, atol=0)
            assert res.info["path"][b] == one.info["path"] == "riccati"
            for key, value in one.certificate.items():
                assert res.certificate[key][b] == pytest.approx(value, rel=1e-6, abs=1e-13)


def test_a_stack_of_one_is_a_batch():
    """The call form of a tuning goal: (B,) margins for a (B, m, n) stack, also for B = 1."""
    plant, K, unc = random_loop(1, 3, False, 3.0)
    res = rc.robust_stability((plant, K[None]), unc)
    assert isinstance(res, analysis.RobustStabilityBatch) and res.margin.shape == (1,)
    assert res.margin[0] == pytest.approx(3.0, rel=1e-8) and res.certified[0]


def test_uncertainty_outside_the_loop_in_a_batch():
    plant, K, unc = random_loop(2, 3, True, 2.0)
    Ks = np.stack([K, K])
    for u in (rc.NormBounded(np.zeros_like(unc.H), unc.EF, unc.EG), rc.NormBounded(unc.H, -unc.EG @ K, unc.EG)):
        res = rc.robust_stability((plant, Ks), u)
        assert (res.margin == np.inf).all() and res.certified.all() and (res.certificate["lyapunov"] > 0).all()


def test_sdp_fallback_when_the_riccati_certificate_fails(monkeypatch, norm):
    plant, K, unc = random_loop(4, 3, True, 2.0)
    reference = rc.robust_stability((plant, K), unc)

    def failing(A, B, C, gamma, *, discrete):
        return np.full(A.shape, np.nan), np.zeros(A.shape[0], dtype=bool)

    monkeypatch.setattr(_hinfnorm, "bounded_real_riccati", failing)
    monkeypatch.setattr(_hinfnorm, "riccati_one", lambda A, B, C, gamma, *, discrete: None)
    res = rc.robust_stability((plant, np.stack([K, K])), unc)
    assert (res.info["path"] == "sdp").all() and res.info["sdp_solves"] == 2 and res.certified.all()
    assert np.allclose(res.margin, reference.margin, rtol=1e-12 if norm == "level-set" else 1e-9)
    for b in range(2):
        assert np.linalg.eigvalsh(lmi(plant, K, unc, res.P[b]))[0] == pytest.approx(res.certificate["lyapunov"][b],
                                                                                   rel=1e-6, abs=1e-13)
        assert res.certificate["lyapunov"][b] > 0
    assert rc.robust_stability((plant, K), unc).info["path"] == "sdp"


def test_polytope_batch_is_the_single_calls():
    plant = rc.Plant([[0.5, 0.1], [0.0, 0.3]], [[0.0], [1.0]], 0.1)
    vertex = rc.Plant([[0.6, 0.1], [0.0, 0.4]], [[0.0], [1.2]], 0.1)
    Ks = np.array([[[0.0, -0.1]], [[np.nan, 0.0]], [[0.0, -3.0]]])
    res = rc.robust_stability((plant, Ks), vertices=[vertex])
    assert res.kind == "polytope" and list(res.reason) == ["ok", "not finite", "unstable"]
    one = rc.robust_stability((plant, Ks[0]), vertices=[vertex])
    assert res.certified[0] == one.certified and res.margin[0] == one.margin and np.allclose(res.P[0], one.P)
    assert res.margin[2] == 0.0 and np.isnan(res.margin[1])


def test_batch_result_is_frozen_and_readable():
    plant, K, unc = random_loop(0, 3, True, 2.0)
    res = rc.robust_stability((plant, np.stack([K, 0 * K + 9.0])), unc)
    assert repr(res).startswith("RobustStabilityBatch(B=2, kind='norm-bounded', certified=1/2, unstable=1")
    with pytest.raises(dataclasses.FrozenInstanceError):
        res.margin = np.zeros(2)
    for arr in (res.margin, res.certified, res.P, res.reason, res.certificate["P"], res.info["path"]):
        with pytest.raises(ValueError, match="read-only"):
            arr[0] = arr[1]
    fresh = rc.robust_stability((plant, np.stack([K, 0 * K + 9.0])), unc)
    back = pickle.loads(pickle.dumps(fresh))   # certificates computed on the way
    assert np.array_equal(back.certified, res.certified) and np.allclose(back.P[0], res.P[0])


# ---------------------------------------------------------------- bad input
def test_bad_input_names_the_argument():
    plant, K, unc = random_loop(0, 3, True, 2.0)
    with pytest.raises(ValueError, match=r"K must be a gain \(2, 3\) or a non-empty stack of gains \(B, 2, 3\).*"
                                         r"got shape \(4, 3, 3\)"):
        rc.robust_stability((plant, np.zeros((4, 3, 3))), unc)
    with pytest.raises(ValueError, match=r"K must be a gain .*got shape \(0, 2, 3\)"):
        rc.robust_stability((plant, np.zeros((0, 2, 3))), unc)
    with pytest.raises(ValueError, match=r"K must be a gain \(2, 3\) or a stack of gains.*shape \(1, 1, 2, 3\)"):
        rc.robust_stability((plant, np.zeros((1, 1, 2, 3))), unc)
    with pytest.raises(ValueError, match="K must have finite entries"):
        rc.robust_stability((plant, np.where(np.eye(2, 3) > 0, np.nan, K)), unc)
    with pytest.raises(TypeError, match="K must contain real numbers"):
        rc.robust_stability((plant, np.zeros((2, 2, 3), dtype=complex)), unc)
    other = rc.NormBounded(np.ones((4, 1)), np.ones((1, 4)), np.ones((1, 2)))
    with pytest.raises(ValueError, match="uncertainty is for n=4 states"):
        rc.robust_stability((plant, np.stack([K, K])), other)
    with pytest.raises(TypeError, match=r"uncertainty must be a robustctl\.NormBounded"):
        rc.robust_stability((plant, np.stack([K, K])), "big")


# ---------------------------------------------------------------- guaranteed cost on stacks
@pytest.mark.parametrize("discrete", [True, False])
def test_guaranteed_cost_batch_equals_the_sdp_of_each_design(discrete):
    """The Riccati search gives, design for design, the optimum of the single-gain SDP (Clarabel)."""
    plant, K, unc = random_loop(1, 4, discrete, 2.0)
    Ks = gain_stack(plant, K, 4, 1, 0.1)
    Q, R = np.diag([1.0, 2.0, 0.5, 1.0]), 0.3 * np.eye(2)
    for x0 in (None, np.array([1.0, -0.5, 0.2, 2.0])):
        res = rc.guaranteed_cost((plant, Ks), unc, Q, R, x0)
        assert isinstance(res, analysis.CostBoundBatch) and len(res) == 4 and res.P.shape == (4, 4, 4)
        assert (res.reason == "ok").sum() >= 3
        for b in range(4):
            try:
                one = rc.guaranteed_cost((plant, Ks[b]), unc, Q, R, x0)
            except InfeasibleError:
                assert res.reason[b] == "not robustly stable" and res.bound[b] == np.inf
                continue
            assert res.reason[b] == "ok" and res.bound[b] == pytest.approx(one.bound, rel=1e-6)
            assert res.multiplier[b] == pytest.approx(one.multiplier, rel=1e-2)
            P, lam = res.P[b], res.multiplier[b]
            bound = x0 @ P @ x0 if x0 is not None else np.linalg.eigvalsh(P)[-1]
            assert res.bound[b] == pytest.approx(bound, rel=1e-12)
            # the LMI of the module docstring at (P, lam), written out here: PSD up to rounding
            A, H, E = plant.F + plant.G @ Ks[b], unc.H, unc.EF + unc.EG @ Ks[b]
            QK = Q + Ks[b].T @ R @ Ks[b]
            if discrete:
                M = np.block([[P - A.T @ P @ A - QK - lam * E.T @ E, -A.T @ P @ H],
                               [-H.T @ P @ A, lam * np.eye(unc.p) - H.T @ P @ H]])
            else:
                M = np.block([[-(A.T @ P + P @ A) - QK - lam * E.T @ E, -P @ H], [-H.T @ P, lam * np.eye(unc.p)]])
            ev = np.linalg.eigvalsh(M)
            assert ev[0] >= -1e-9 * ev[-1] and np.linalg.eigvalsh(P)[0] > 0
            assert res.certificate["cost"][b] == pytest.approx(ev[0], abs=1e-9 * ev[-1])


@pytest.mark.parametrize("discrete", [True, False])
def test_guaranteed_cost_batch_flags_designs_without_a_bound(discrete):
    plant, K, unc = random_loop(2, 3, discrete, 1.5)
    limit = 1.0 if discrete else 0.0
    bad = next(c for c in (10.0, -10.0, 30.0, -30.0)
               if spectral(plant.F + plant.G @ (0.0 * K + c), discrete) > limit)   # destabilising
    Ks = np.stack([K, K, 0.0 * K + bad, K])
    Ks[3, 0, 0] = np.nan
    big = rc.NormBounded(3.0 * unc.H, unc.EF, unc.EG)      # margin 0.5: no bound
    res = rc.guaranteed_cost((plant, Ks), unc, np.eye(3), np.eye(2))
    assert list(res.reason) == ["ok", "ok", "unstable", "not finite"]
    assert np.isfinite(res.bound[:2]).all() and res.bound[2] == np.inf and np.isnan(res.bound[3])
    assert np.isnan(res.P[2:]).all() and res.info["path"] == "riccati"
    res = rc.guaranteed_cost((plant, Ks[:2]), big, np.eye(3), np.eye(2))
    assert (res.reason == "not robustly stable").all() and (res.bound == np.inf).all()


@pytest.mark.parametrize("discrete", [True, False])
def test_guaranteed_cost_batch_without_uncertainty_is_the_lyapunov_cost(discrete):
    plant, K, unc = random_loop(3, 3, discrete)
    Ks = gain_stack(plant, K, 3, 3, 0.05)
    Q, R, x0 = np.eye(3), np.eye(2), np.array([1.0, 2.0, -1.0])
    res = rc.guaranteed_cost((plant, Ks), rc.NormBounded(np.zeros_like(unc.H), unc.EF, unc.EG), Q, R, x0)
    for b in range(3):
        A, QK = plant.F + plant.G @ Ks[b], Q + Ks[b].T @ R @ Ks[b]
        if discrete:
            P = scipy.linalg.solve_discrete_lyapunov(A.T, QK)
        else:
            P = scipy.linalg.solve_continuous_lyapunov(A.T, -QK)
        assert res.bound[b] == pytest.approx(x0 @ P @ x0, rel=1e-9) and res.multiplier[b] == 0.0


def test_guaranteed_cost_batch_bad_input_names_the_argument():
    plant, K, unc = random_loop(0, 3, True, 2.0)
    Ks = np.stack([K, K])
    with pytest.raises(ValueError, match=r"K must be a gain \(2, 3\) or a non-empty stack"):
        rc.guaranteed_cost((plant, np.zeros((2, 3, 3))), unc, np.eye(3), np.eye(2))
    with pytest.raises(ValueError, match="Q must have 3 rows"):
        rc.guaranteed_cost((plant, Ks), unc, np.eye(2), np.eye(2))
    with pytest.raises(ValueError, match="R must"):
        rc.guaranteed_cost((plant, Ks), unc, np.eye(3), -np.eye(2))
    with pytest.raises(ValueError, match="x0"):
        rc.guaranteed_cost((plant, Ks), unc, np.eye(3), np.eye(2), np.ones(2))
    with pytest.raises(ValueError, match="uncertainty is for n=4 states"):
        rc.guaranteed_cost((plant, Ks), rc.NormBounded(np.ones((4, 1)), np.ones((1, 4)), np.ones((1, 2))),
                           np.eye(3), np.eye(2))
