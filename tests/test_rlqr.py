"""RLQR: block system vs closed form, steady state vs independent Riccati references, batch, limits."""

import control
import numpy as np
import pytest
import scipy.linalg
from conftest import GENERIC_F, GENERIC_G, GENERIC_Z_STAR, random_plant

import robustctl as rc
from robustctl import rlqr_step, rlqr_step_block


def _random_case(rng, n=None, m=None, l=None, p=None):
    n = n or int(rng.integers(2, 6))
    m = m or int(rng.integers(1, 4))
    l = l or int(rng.integers(1, m + 1))
    p = p or int(rng.integers(1, 3))
    plant = random_plant(rng, n, m, scale=1.2)
    X = rng.standard_normal((n, n))
    Q = X @ X.T + 0.5 * np.eye(n)
    R = np.diag(rng.uniform(0.5, 2.0, m))
    return plant, Q, R, rng.standard_normal((l, n)), rng.standard_normal((l, m)), rng.standard_normal((n, p))


def _w_form(P_next, F, G, EF, EG, Q, R, H, mu, alpha):
    """PAPER_NOTES' closed form: W = Sigma + Ihat P^-1 Ihat' + Ghat R^-1 Ghat' (independent reference)."""
    n, l = F.shape[0], EF.shape[0]
    lam = (1 + alpha) * mu * np.linalg.norm(H.T @ H, 2)
    Sigma = scipy.linalg.block_diag(np.eye(n) / mu - H @ H.T / lam, np.eye(l) / lam)
    Fh, Gh, Ih = np.vstack([F, EF]), np.vstack([G, EG]), np.vstack([np.eye(n), np.zeros((l, n))])
    W = Sigma + Ih @ np.linalg.inv(P_next) @ Ih.T + Gh @ np.linalg.inv(R) @ Gh.T
    WF = np.linalg.solve(W, Fh)
    return np.linalg.solve(P_next, Ih.T @ WF), -np.linalg.solve(R, Gh.T @ WF), Q + Fh.T @ WF


def _rel(a, b):
    return np.abs(a - b).max() / max(1.0, np.abs(b).max())


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("mu", [0.5, 10.0, 1e4, np.inf])
def test_one_step_block_equals_closed_form(seed, mu):
    rng = np.random.default_rng(seed)
    plant, Q, R, EF, EG, H = _random_case(rng)
    X = rng.standard_normal((plant.n, plant.n))
    P_next = X @ X.T + np.eye(plant.n)
    args = (P_next, plant.F, plant.G, EF, EG, Q, R, H, mu)
    L_b, K_b, P_b = rlqr_step_block(*args)
    L_c, K_c, P_c = rlqr_step(*args)
    assert _rel(K_c, K_b) < 1e-10 and _rel(L_c, L_b) < 1e-10 and _rel(P_c, P_b) < 1e-10
    if np.isfinite(mu):
        L_w, K_w, P_w = _w_form(*args, 0.1)
        assert _rel(K_c, K_w) < 1e-9 and _rel(L_c, L_w) < 1e-9 and _rel(P_c, P_w) < 1e-9
    else:  # Algorithm 1: EF + EG K = 0 and L = F + G K
        assert np.abs(EF + EG @ K_c).max() < 1e-10 * max(1, np.abs(EF).max())
        np.testing.assert_allclose(L_c, plant.F + plant.G @ K_c, atol=1e-10)


def _stable_case(rng, mu):
    """A random case whose steady state exists (resample until the block recursion converges)."""
    for _ in range(50):
        plant, Q, R, EF, EG, H = _random_case(rng)
        try:
            ref = rc.rlqr(plant, EF, EG, mu, Q=Q, R=R, H=H, implementation="block", tol=1e-14, max_iter=20000)
        except rc.ConvergenceError:
            continue
        return plant, Q, R, EF, EG, H, ref
    raise AssertionError("no convergent case found")


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("mu", [3.0, 1e3, np.inf])
def test_steady_state_doubling_equals_block_recursion(seed, mu):
    rng = np.random.default_rng(100 + seed)
    plant, Q, R, EF, EG, H, ref = _stable_case(rng, mu)
    fast = rc.design("rlqr", plant, EF, EG, mu, Q=Q, R=R, H=H)
    assert _rel(fast.K, ref.K) < 1e-10
    assert _rel(fast.info["P"], ref.info["P"]) < 1e-10
    assert fast.info["iterations"] < ref.info["iterations"] or ref.info["iterations"] < 20


def _augmented_lq(plant, EF, EG, Q, R, H, mu, alpha=0.1):
    """Independent reference for finite mu: scipy's DARE for the LQ problem with inputs (u, v),
    x+ = F x + G u + v, cost x'Qx + u'Ru + lambda |EF x + EG u|^2 + v' S^-1 v."""
    n, m = plant.n, plant.m
    lam = (1 + alpha) * mu * np.linalg.norm(H, 2) ** 2
    S = np.eye(n) / mu - H @ H.T / lam
    Bt = np.hstack([plant.G, np.eye(n)])
    Rt = scipy.linalg.block_diag(R + lam * EG.T @ EG, np.linalg.inv(S))
    Nt = np.hstack([lam * EF.T @ EG, np.zeros((n, n))])
    P = scipy.linalg.solve_discrete_are(plant.F, Bt, Q + lam * EF.T @ EF, Rt, s=Nt)
    Kt = -np.linalg.solve(Rt + Bt.T @ P @ Bt, Bt.T @ P @ plant.F + Nt.T)
    return P, Kt[:m]


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("mu", [0.7, 5.0, 50.0])
def test_steady_state_equals_augmented_lq_dare(seed, mu):
    """The steady-state RLQR is the LQR of the augmented problem (module docstring)."""
    rng = np.random.default_rng(200 + seed)
    plant, Q, R, EF, EG, H, _ = _stable_case(rng, mu)
    c = rc.rlqr(plant, EF, EG, mu, Q=Q, R=R, H=H)
    P_ref, K_ref = _augmented_lq(plant, EF, EG, Q, R, H, mu)
    assert _rel(c.info["P"], P_ref) < 1e-7
    assert _rel(c.K, K_ref) < 1e-7


@pytest.mark.parametrize("seed", range(5))
def test_mu_inf_equals_nullspace_constrained_lqr(seed):
    """mu = inf: min sum x'Qx + u'Ru s.t. EF x + EG u = 0, solved independently as an LQR on the
    null space of EG (u = Kp x + N w, Kp = -EG^+ EF) with a cross term, by python-control's dare."""
    rng = np.random.default_rng(300 + seed)
    for _ in range(50):
        plant, Q, R, EF, EG, H = _random_case(rng, m=3, l=1)
        Kp = -np.linalg.pinv(EG) @ EF
        N = scipy.linalg.null_space(EG)
        A = plant.F + plant.G @ Kp
        Bn = plant.G @ N
        try:
            P, _, _ = control.dare(A, Bn, Q + Kp.T @ R @ Kp, N.T @ R @ N, S=Kp.T @ R @ N)
        except Exception:  # noqa: BLE001 - any refusal of control.dare (ControlArgument, LinAlgError, ...): draw again
            continue
        W = -np.linalg.solve(N.T @ R @ N + Bn.T @ P @ Bn, Bn.T @ P @ A + N.T @ R @ Kp)
        break
    c = rc.rlqr(plant, EF, EG, np.inf, Q=Q, R=R, H=H)
    np.testing.assert_allclose(c.K, Kp + N @ W, atol=1e-8 * max(1, np.abs(Kp).max()))
    np.testing.assert_allclose(c.info["P"], P, rtol=1e-8)


@pytest.mark.parametrize("seed", range(4))
def test_no_uncertainty_large_mu_is_lqr(seed):
    rng = np.random.default_rng(seed)
    plant, Q, R, EF, EG, H = _random_case(rng)
    K_pc = -control.dlqr(plant.F, plant.G, Q, R)[0]
    zero = rc.design("rlqr", plant, np.zeros_like(EF), np.zeros_like(EG), 1e12, Q=Q, R=R, H=H)
    np.testing.assert_allclose(zero.K, K_pc, atol=1e-8 * max(1, np.abs(K_pc).max()))
    # H = 0: EF, EG drop out (lambda -> 0 limit), also the LQR for large mu
    no_h = rc.design("rlqr", plant, EF, EG, 1e12, Q=Q, R=R, H=np.zeros_like(H))
    np.testing.assert_allclose(no_h.K, K_pc, atol=1e-8 * max(1, np.abs(K_pc).max()))
    assert no_h.info["lambda"] == 0.0


def test_mu_inf_single_input_single_row_gain_is_fixed():
    rng = np.random.default_rng(7)
    EF, EG = rng.uniform(0.5, 2, (1, 3)), np.array([[0.8]])
    # a plant for which the forced closed loop F - G EF / EG is stable
    G = GENERIC_G
    F = 0.3 * np.eye(3) + G @ (EF / EG[0, 0])
    c = rc.design("rlqr", rc.Plant(F, G, 0.1), EF, EG, np.inf)
    np.testing.assert_allclose(c.K, -EF / EG[0, 0], rtol=1e-12)
    np.testing.assert_allclose(c.info["L"], F + G @ c.K, atol=1e-12)


def test_generic_model_printed_z_star_is_stabilising(generic_plant):
    z = GENERIC_Z_STAR
    c = rc.design("rlqr", generic_plant, z[None, :3], [[z[3]]], 10 ** np.sqrt(z[4]))
    assert c.is_stabilizing()
    # the paper's uncertainty realisations too: F + H Delta EF, Delta in [-1, 1]
    unc = rc.NormBounded(np.ones(3), [[0.1, 0.2, 0.2]], [[0.1]])
    for delta in (-1.0, 0.0, 1.0):
        assert c.is_stabilizing(unc.perturb(generic_plant, delta))


def test_finite_horizon_schedule():
    rng = np.random.default_rng(11)
    plant, Q, R, EF, EG, H, steady = _stable_case(rng, 100.0)
    sch = rc.rlqr_schedule(plant, EF, EG, 100.0, Q=Q, R=R, H=H, horizon=400)
    assert sch.K.shape == (400, plant.m, plant.n) and sch.P.shape == (401, plant.n, plant.n)
    np.testing.assert_allclose(sch.P[-1], Q)
    assert _rel(sch.K[0], steady.K) < 1e-8  # long horizon: K_0 -> steady state
    blk = rc.rlqr_schedule(plant, EF, EG, 100.0, Q=Q, R=R, H=H, horizon=5, implementation="block")
    short = rc.rlqr_schedule(plant, EF, EG, 100.0, Q=Q, R=R, H=H, horizon=5)
    assert _rel(short.K, blk.K) < 1e-10 and _rel(short.L, blk.L) < 1e-10
    c3 = short.controller(3)
    np.testing.assert_array_equal(c3.K, short.K[3])
    # step 4 (the last) from P_N by hand with the block system
    _L4, K4, P4 = rlqr_step_block(Q, plant.F, plant.G, EF, EG, Q, R, H, 100.0)
    assert _rel(short.K[4], K4) < 1e-10 and _rel(short.P[4], P4) < 1e-10


def test_rlqr_has_no_horizon_argument(generic_plant):
    """The finite-horizon form is rlqr_schedule only (the deprecated rlqr(..., horizon=N) is gone)."""
    with pytest.raises(TypeError, match="horizon"):
        rc.rlqr(generic_plant, [[0.1, 0.2, 0.2]], [[0.1]], 1e3, horizon=7)


def test_errors_single_design(generic_plant):
    with pytest.raises(rc.RankConditionError, match=r"full row rank .*\[I -G; 0 -EG\]"):
        rc.design("rlqr", generic_plant, [[1.0, 2.0, 3.0]], [[0.0]], np.inf)
    EF, EG = np.array([[0.1, 0.2, 0.3]]), np.array([[-2.0]])  # forced gain destabilises
    with pytest.raises(rc.ConvergenceError, match="diverged"):
        rc.design("rlqr", rc.Plant(np.diag([1.5, 0.5, 0.2]), [[1.0], [0.0], [0.0]], 0.1),
                  [[0.0, 1.0, 0.0]], [[1.0]], np.inf)
    with pytest.raises(rc.ConvergenceError, match="did not reach a stabilising steady state in max_iter=3"):
        rc.design("rlqr", generic_plant, EF, EG, 10.0, accelerate=False, max_iter=3)


# ---------------------------------------------------------------------------- batch
def _truck_like():
    """Four states, doubled steering column, dt = 0.1 (as the applied MOP)."""
    A = np.array([[-5.0, -10.0, 0, 0], [-2.0, -8.0, 0, 0], [1.0, 0, 0, 16.67], [0, 1.0, 0, 0]])
    p = rc.Plant.from_continuous(A, np.array([[6.6], [1.5], [0], [0]]), 0.1)
    return rc.Plant(p.F, np.hstack([p.G, p.G]), 0.1)


def test_batch_equals_single_designs():
    plant = _truck_like()
    rng = np.random.default_rng(5)
    z = rng.uniform(0.01, 500, (12, 7))
    mu = 10 ** np.sqrt(z[:, 6])
    mu[3] = np.inf
    batch = rc.rlqr_gains(plant, z[:, None, :4], z[:, None, 4:6], mu)
    assert batch.K.shape == (12, 2, 4) and batch.ok.all()
    for i in range(12):
        ref = rc.rlqr(plant, z[i, None, :4], z[i, None, 4:6], mu[i], accelerate=False, tol=1e-13,
                      max_iter=100_000, check_stability=False)
        assert _rel(batch.K[i], ref.K) < 1e-9, i


def test_batch_flags_instead_of_nan():
    plant = rc.Plant(GENERIC_F, GENERIC_G, 0.1)
    EF = np.array([[[0.1, 0.2, 0.2]], [[1.0, 1.0, 1.0]], [[0.1, 0.2, 0.3]]])
    EG = np.array([[[0.1]], [[0.0]], [[-2.0]]])
    mu = np.array([1e6, np.inf, np.inf])
    b = rc.rlqr_gains(plant, EF, EG, mu)
    assert list(b.reason) == ["ok", "rank", "ok" if b.ok[2] else b.reason[2]]
    assert b.ok[0] and not b.ok[1]
    assert b.stabilizing[0] == (np.abs(np.linalg.eigvals(GENERIC_F + GENERIC_G @ b.K[0])).max() < 1)
    assert not b.stabilizing[1]
    assert np.isfinite(b.K[b.ok]).all() and np.isnan(b.K[~b.ok]).all()
    bad = rc.rlqr_gains(rc.Plant(np.diag([1.5, 0.5, 0.2]), [[1.0], [0.0], [0.0]], 0.1),
                        [[0.0, 1.0, 0.0]], [[1.0]], np.inf)
    assert list(bad.reason) == ["diverged"] and "ok=0/1" in repr(bad)


def test_batch_whole_paper_search_space_is_sound():
    """z in (0, 500]^7 with mu = 10**sqrt(z7) up to ~2e22: every design finite or flagged, and the
    accepted ones are fixed points with a stable closed loop; a sample matches the plain recursion."""
    plant = _truck_like()
    rng = np.random.default_rng(42)
    z = rng.uniform(0, 500, (400, 7))
    z[:20, 6] = 500.0   # largest mu
    z[20:40, 6] = 1e-6  # mu ~ 1
    z[40:60, 4:6] *= 1e-4  # tiny EG
    b = rc.rlqr_gains(plant, z[:, None, :4], z[:, None, 4:6], 10 ** np.sqrt(z[:, 6]))
    assert np.isfinite(b.K[b.ok]).all() and np.isnan(b.K[~b.ok]).all()
    assert b.ok.mean() > 0.95
    assert (b.residual[b.ok] < 1e-10).all()
    rho = np.abs(np.linalg.eigvals(b.L[b.ok])).max(axis=1)
    assert (rho < 1).all()
    for i in [*list(range(0, 60, 7)), 100, 200, 300]:
        if b.ok[i]:
            ref = rc.rlqr(plant, z[i, None, :4], z[i, None, 4:6], 10 ** np.sqrt(z[i, 6]), accelerate=False,
                          max_iter=200_000, check_stability=False)
            assert _rel(b.K[i], ref.K) < 1e-7, i


def test_batch_broadcasting_and_shapes():
    plant = rc.Plant(GENERIC_F, GENERIC_G, 0.1)
    b = rc.rlqr_gains(plant, [0.1, 0.2, 0.2], [[0.1]], [1e2, 1e4, np.inf])
    assert b.K.shape == (3, 1, 3) and len(b) == 3
    with pytest.raises(ValueError, match="batch sizes differ"):
        rc.rlqr_gains(plant, np.ones((2, 1, 3)), np.ones((3, 1, 1)), 1.0)
    with pytest.raises(ValueError, match=r"EF must have size 3 along axis 2 \(the number of states\)"):
        rc.rlqr_gains(plant, np.ones((2, 1, 4)), np.ones((2, 1, 1)), 1.0)
    with pytest.raises(ValueError, match="mu must be > 0"):
        rc.rlqr_gains(plant, np.ones((1, 3)), np.ones((1, 1)), [1.0, -1.0])


# ---------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    "kw,err,match",
    [
        ({"mu": 0.0}, ValueError, "mu must be > 0"),
        ({"mu": np.nan}, ValueError, "mu must not be NaN"),
        ({"mu": "big"}, TypeError, "mu must be"),
        ({"alpha": 0.0}, ValueError, "alpha must be > 0"),
        ({"alpha": -1}, ValueError, "alpha must be > 0"),
        ({"EF": [[1.0, 2.0]]}, ValueError, r"EF must have 3 columns \(the number of states\), got shape \(1, 2\)"),
        ({"EG": [[1.0], [2.0]]}, ValueError, r"EG must have 1 rows \(the rows of EF\)"),
        ({"EF": [[np.nan, 1.0, 1.0]]}, ValueError, "EF must have finite entries"),
        ({"H": np.ones((2, 1))}, ValueError, "H must have 3 rows"),
        ({"Q": np.ones((3, 3)) - 2 * np.eye(3)}, ValueError, "Q must be positive semidefinite"),
        ({"R": [[-1.0]]}, ValueError, "R must be positive definite"),
        ({"tol": 0.0}, ValueError, "tol must be > 0"),
        ({"max_iter": 0}, ValueError, "max_iter must be a positive integer"),
        ({"implementation": "fast"}, ValueError, "implementation must be"),
    ],
)
def test_rlqr_bad_input(generic_plant, kw, err, match):
    args = {"EF": [[0.1, 0.2, 0.2]], "EG": [[0.1]], "mu": 1e3}
    args.update(kw)
    EF, EG, mu = args.pop("EF"), args.pop("EG"), args.pop("mu")
    with pytest.raises(err, match=match):
        rc.design("rlqr", generic_plant, EF, EG, mu, **args)


def test_rlqr_rejects_continuous_and_non_plants():
    with pytest.raises(ValueError, match="discrete-time"):
        rc.rlqr(rc.Plant(np.eye(2), np.ones((2, 1)), None), [[1.0, 0.0]], [[1.0]], 1.0)
    with pytest.raises(TypeError, match=r"plant must be a robustctl\.Plant"):
        rc.rlqr_gains(np.eye(2), [[1.0, 0.0]], [[1.0]], 1.0)


# ---------------------------------------------------------------------------- ill-conditioned designs
def _ill_conditioned_truck_designs(count, seed=2026):
    """The doubled-column truck with the applied MOP's weights; EG2 / EG1 = 1 +- 0.002 (nearly dependent
    split of the steering column: P reaches 1e15 and doubling misses the acceptance test on ~1/4)."""
    from robustctl.models.truck import lqr_weights, truck_plant

    rng = np.random.default_rng(seed)
    z = rng.uniform(0, 500, (count, 7))
    z[:, 5] = z[:, 4] * (1 + rng.uniform(-0.002, 0.002, count))
    Q, R = lqr_weights(doubled=True)
    return truck_plant(0.0, doubled=True), z[:, None, :4], z[:, None, 4:6], 10 ** np.sqrt(z[:, 6]), Q, R


def test_newton_fallback_on_ill_conditioned_designs_matches_the_recursion():
    plant, EF, EG, mu, Q, R = _ill_conditioned_truck_designs(60)
    kw = dict(Q=Q, R=R, max_iter=2000)
    rec = rc.rlqr_gains(plant, EF, EG, mu, **kw)
    new = rc.rlqr_gains(plant, EF, EG, mu, fallback="newton", **kw)
    refined = rec.iterations > 30                      # the designs the recursion had to redo
    assert refined.sum() >= 5
    # doubling-accepted designs are untouched
    np.testing.assert_array_equal(new.K[~refined], rec.K[~refined])
    assert (new.iterations[refined] <= 30).all()     # a few Newton steps instead of hundreds of recursion steps
    # same acceptance rule: residual of one more recursion step below tol, rho(L) < 1
    assert new.ok[rec.ok].all() and (new.residual[new.ok] < 1e-10).all()
    assert (np.abs(np.linalg.eigvals(new.L[new.ok])).max(axis=1) < 1).all()
    # reference: the plain recursion run to 3e-12 (on a few designs that is below its rounding floor)
    compared = 0
    for i in np.flatnonzero(refined):
        try:
            ref = rc.rlqr(plant, EF[i], EG[i], mu[i], Q=Q, R=R, accelerate=False, tol=3e-12, max_iter=20_000,
                          check_stability=False)
        except rc.ConvergenceError:
            continue
        compared += 1
        assert _rel(new.P[i], ref.info["P"]) < 1e-9, i  # the recursion stopped at tol 1e-10 is only ~1e-8 close
        assert _rel(new.K[i], ref.K) < 1e-6, i          # K = f(P) amplifies P's rounding by ~1e4 here
        if rec.ok[i]:
            assert _rel(rec.P[i], ref.info["P"]) < 1e-7, i
    assert compared >= 0.75 * refined.sum()


def test_newton_fallback_accepts_a_slow_design_the_capped_recursion_flags(generic_plant):
    """mu ~ 7e10 on the generic plant: rho(L) = 0.9986, the recursion needs ~10^4 steps."""
    z = np.array([47.8069, 103.7683, 181.5866, 53.6425, 117.4085])
    args = (generic_plant, z[None, None, :3], z[None, None, 3:4], 10 ** np.sqrt(z[4:]))
    assert list(rc.rlqr_gains(*args, max_iter=50).reason) == ["not converged"]
    new = rc.rlqr_gains(*args, max_iter=50, fallback="newton")
    ref = rc.rlqr(generic_plant, z[None, :3], z[None, 3:4], 10 ** np.sqrt(z[4]), accelerate=False,
                  max_iter=50_000, tol=1e-13, check_stability=False)
    assert new.ok[0] and new.iterations[0] < 50
    assert _rel(new.P[0], ref.info["P"]) < 1e-9 and _rel(new.K[0], ref.K) < 1e-9


def test_newton_fallback_keeps_failures_flagged():
    plant = rc.Plant(GENERIC_F, GENERIC_G, 0.1)
    EF = np.array([[[0.1, 0.2, 0.2]], [[1.0, 1.0, 1.0]], [[0.1, 0.2, 0.3]]])
    EG = np.array([[[0.1]], [[0.0]], [[-2.0]]])
    mu = np.array([1e6, np.inf, np.inf])
    for p, ef, eg, m in ((plant, EF, EG, mu),
                         (rc.Plant(np.diag([1.5, 0.5, 0.2]), [[1.0], [0.0], [0.0]], 0.1), [[0.0, 1.0, 0.0]],
                          [[1.0]], np.inf)):
        rec, new = rc.rlqr_gains(p, ef, eg, m), rc.rlqr_gains(p, ef, eg, m, fallback="newton")
        assert list(new.reason) == list(rec.reason)
    with pytest.raises(ValueError, match="fallback must be one of 'recursion', 'newton'"):
        rc.rlqr_gains(plant, EF, EG, mu, fallback="fast")
    with pytest.raises(ValueError, match="got 'Newton'"):           # exact, case-sensitive
        rc.rlqr_gains(plant, EF, EG, mu, fallback="Newton")
    with pytest.raises(TypeError, match="fallback must be one of 'recursion', 'newton', got int"):
        rc.rlqr_gains(plant, EF, EG, mu, fallback=1)


# ---------------------------------------------------------------------------- uncertainty object, stabilisability
def test_uncertainty_object_equals_the_explicit_matrices(generic_plant):
    H, EF, EG = np.array([[1.0], [0.5], [0.2]]), np.array([[0.1, 0.2, 0.2]]), np.array([[0.1]])
    unc = rc.NormBounded(H, EF, EG)
    explicit = rc.rlqr(generic_plant, EF, EG, 1e4, H=H)
    for c in (rc.rlqr(generic_plant, mu=1e4, uncertainty=unc),
              rc.design("rlqr", generic_plant, mu=1e4, uncertainty=unc)):
        np.testing.assert_array_equal(c.K, explicit.K)
    b = rc.rlqr_gains(generic_plant, mu=[1e2, 1e4], uncertainty=unc)
    np.testing.assert_array_equal(b.K[1], explicit.K)
    sch = rc.rlqr_schedule(generic_plant, mu=1e4, uncertainty=unc, horizon=3)
    np.testing.assert_array_equal(sch.K, rc.rlqr_schedule(generic_plant, EF, EG, 1e4, H=H, horizon=3).K)
    with pytest.raises(TypeError, match="either uncertainty=NormBounded"):
        rc.rlqr(generic_plant, EF, EG, 1e4, uncertainty=unc)
    with pytest.raises(TypeError, match=r"uncertainty must be a robustctl\.NormBounded"):
        rc.rlqr(generic_plant, mu=1e4, uncertainty=(H, EF, EG))
    with pytest.raises(ValueError, match="uncertainty is for n=3"):
        rc.rlqr(rc.Plant(np.eye(2) * 0.5, np.ones((2, 1)), 0.1), mu=1e4, uncertainty=unc)
    with pytest.raises(TypeError, match="mu is required"):
        rc.rlqr(generic_plant, uncertainty=unc)
    with pytest.raises(TypeError, match="give EF and EG"):
        rc.rlqr(generic_plant, mu=1.0)


def _with_uncontrollable_mode(rng, n_c, mode):
    """F = T blkdiag(A_c, mode) T^-1, G = T [B_c; 0]: ``mode`` is uncontrollable by construction."""
    n = n_c + 1
    A_c = 0.5 * rng.standard_normal((n_c, n_c))
    F = np.zeros((n, n))
    F[:n_c, :n_c], F[n_c, n_c] = A_c, mode
    F[:n_c, n_c] = rng.standard_normal(n_c)        # coupling from the uncontrollable part
    G = np.vstack([rng.standard_normal((n_c, 1)), [[0.0]]])
    T = rng.standard_normal((n, n)) + n * np.eye(n)
    return rc.Plant(T @ F @ np.linalg.inv(T), T @ G, 0.1)


@pytest.mark.parametrize("mode,stabilisable", [(1.3, False), (-1.0, False), (1.0, False), (0.99, True), (0.2, True)])
def test_every_design_raises_the_same_error_on_an_unstabilisable_plant(mode, stabilisable):
    plant = _with_uncontrollable_mode(np.random.default_rng(4), 2, mode)
    assert plant.is_stabilizable == stabilisable
    EF, EG = [[0.1, 0.2, 0.1]], [[0.5]]
    if stabilisable:
        assert plant.unstabilizable_modes.size == 0
        assert rc.lqr(plant).is_stabilizing() and rc.rlqr(plant, EF, EG, 1e6).info["residual"] < 1e-10
        return
    np.testing.assert_allclose(plant.unstabilizable_modes, [mode], atol=1e-9)
    for design in (lambda: rc.lqr(plant), lambda: rc.rlqr(plant, EF, EG, 1e6), lambda: rc.rlqr(plant, EF, EG, 10.0)):
        with pytest.raises(rc.NotStabilizableError, match=rf"plant is not stabilisable: its mode lambda = {mode:g}"):
            design()
    # the same class serves handlers written for lqr (ConvergenceError) and hinf (InfeasibleError)
    assert issubclass(rc.NotStabilizableError, rc.ConvergenceError)
    assert issubclass(rc.NotStabilizableError, rc.InfeasibleError)
    b = rc.rlqr_gains(plant, np.array(EF)[None].repeat(3, 0), EG, [1.0, 1e6, np.inf])
    assert list(b.reason) == ["unstabilizable"] * 3 and np.isnan(b.K).all() and not b.stabilizing.any()
