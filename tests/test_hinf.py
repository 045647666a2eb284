"""LMI H-infinity state feedback (robustctl.hinf) against independent references.

References used here, none of which shares code with the LMI synthesis:

* ``robustctl.synthesis.hinf_riccati``: bisection on the game Riccati equation (scipy's
  DARE with its residual checked; the continuous case through the
  Hamiltonian's ordered Schur form);
* python-control's ``linfnorm`` (SLICOT AB13DD) of the closed loop;
* closed forms (scalar plants) and a brute-force scalar minimisation;
* python-control's ``hinfsyn`` (SLICOT SB10AD, output feedback);
* the exact worst-case input over all disturbances of a given energy,
  ``sqrt(E k W k')`` with ``W`` the closed-loop controllability Gramian
  (scipy's Lyapunov solvers).
"""

from __future__ import annotations

import importlib

import control
import numpy as np
import pytest
import scipy.linalg
import scipy.optimize

import robustctl as rc
from robustctl import InfeasibleError, Plant
from robustctl.synthesis.hinf import HinfController, hinf
from robustctl.synthesis.hinf_riccati import hinf_riccati, riccati_level

RTOL = 1e-5


def cl_norm(plant: Plant, K, Bw, Cz, Dzu, Dzw=None) -> float:
    """||T_zw||_inf of the closed loop u = K x, by python-control (SLICOT AB13DD)."""
    Dzw = np.zeros((Cz.shape[0], Bw.shape[1])) if Dzw is None else Dzw
    sys = control.ss(plant.F + plant.G @ K, Bw, Cz + Dzu @ K, Dzw, 0 if plant.dt is None else plant.dt)
    return float(control.linfnorm(sys, tol=1e-10)[0])


def random_case(seed: int, n: int, m: int, q: int, discrete: bool, cross: bool = False):
    """A random plant; without ``cross``: Dzu' Cz = 0, Dzu = [0; I] (the textbook setting)."""
    rng = np.random.default_rng(seed)
    F = rng.normal(size=(n, n))
    if discrete:
        F *= 1.05 / np.max(np.abs(np.linalg.eigvals(F)))  # slightly unstable
    G = rng.normal(size=(n, m))
    Bw = rng.normal(size=(n, q))
    if cross:
        p = n
        Cz, Dzu, Dzw = rng.normal(size=(p, n)), rng.normal(size=(p, m)), 0.3 * rng.normal(size=(p, q))
    else:
        Cz = np.vstack([rng.normal(size=(n, n)), np.zeros((m, n))])
        Dzu = np.vstack([np.zeros((n, m)), np.eye(m)])
        Dzw = None
    return Plant(F, G, 0.1 if discrete else None), Bw, Cz, Dzu, Dzw


# ------------------------------------------------------------ optimum vs Riccati
@pytest.mark.parametrize("seed,n,m,q", [(0, 3, 1, 1), (1, 4, 2, 2), (2, 6, 2, 3)])
def test_discrete_gamma_matches_riccati_bisection(seed, n, m, q):
    plant, Bw, Cz, Dzu, _ = random_case(seed, n, m, q, discrete=True)
    ctrl = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    ref = hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, rtol=1e-9)
    assert ctrl.gamma_opt == pytest.approx(ref.gamma, rel=RTOL)
    assert ctrl.gamma == pytest.approx(ctrl.gamma_opt * (1 + ctrl.info["backoff"]), rel=1e-12)
    norm = cl_norm(plant, ctrl.K, Bw, Cz, Dzu)
    assert norm <= ctrl.gamma * (1 + RTOL)          # the guarantee
    assert norm >= ref.gamma_low * (1 - RTOL)       # no static gain beats the optimum
    assert ctrl.is_stabilizing()
    # the Riccati reference is itself checked by linfnorm
    assert cl_norm(plant, ref.K, Bw, Cz, Dzu) <= ref.gamma * (1 + 1e-8)


def test_discrete_with_cross_terms_and_dzw_matches_riccati():
    plant, Bw, Cz, Dzu, Dzw = random_case(5, 4, 2, 2, discrete=True, cross=True)
    ctrl = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw)
    ref = hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw)
    assert ctrl.gamma_opt == pytest.approx(ref.gamma, rel=RTOL)
    assert cl_norm(plant, ctrl.K, Bw, Cz, Dzu, Dzw) <= ctrl.gamma * (1 + RTOL)


def test_riccati_reference_rejects_levels_below_the_optimum():
    plant, Bw, Cz, Dzu, _ = random_case(1, 4, 2, 2, discrete=True)
    ref = hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    assert riccati_level(plant, 0.99 * ref.gamma, Bw=Bw, Cz=Cz, Dzu=Dzu) is None
    K, P = riccati_level(plant, 1.01 * ref.gamma, Bw=Bw, Cz=Cz, Dzu=Dzu)
    assert np.linalg.eigvalsh(P).min() >= 0
    assert cl_norm(plant, K, Bw, Cz, Dzu) < 1.01 * ref.gamma


def test_riccati_reference_gain_meets_its_level_on_a_larger_plant():
    """Just below the optimum scipy's DARE still returns a matrix (residual 1e-9..1e-7, not ~1e-14).

    On this n = 20 plant (the benchmark's second one) a 1e-7 residual
    tolerance let the bisection settle 8e-6 below the level its own gain
    reaches; linfnorm (SLICOT) of that gain is the independent check.
    """
    rng = np.random.default_rng(1)
    F = rng.normal(size=(20, 20))
    F *= 1.05 / np.max(np.abs(np.linalg.eigvals(F)))
    G, Bw = rng.normal(size=(20, 2)), rng.normal(size=(20, 2))
    Cz = np.vstack([rng.normal(size=(2, 20)), np.zeros((2, 20))])
    Dzu = np.vstack([np.zeros((2, 2)), np.eye(2)])
    plant = Plant(F, G, 0.1)
    ref = hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, rtol=1e-10)
    assert cl_norm(plant, ref.K, Bw, Cz, Dzu) <= ref.gamma * (1 + 1e-7)
    assert hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu).gamma_opt == pytest.approx(ref.gamma, rel=1e-6)


def test_discrete_scalar_against_brute_force():
    """x+ = a x + w + b u, z = [x; rho u]: ||T|| = sqrt(1 + rho^2 k^2) / (1 - |a + b k|)."""
    a, b, rho = 1.2, 0.5, 0.3

    def norm(k):
        c = a + b * k
        return np.sqrt(1 + (rho * k) ** 2) / (1 - abs(c))

    best = scipy.optimize.minimize_scalar(norm, bounds=((-1 - a) / b + 1e-9, (1 - a) / b - 1e-9),
                                          method="bounded", options={"xatol": 1e-12})
    ctrl = hinf(Plant([[a]], [[b]], 1.0), Bw=[[1.0]], Cz=[[1.0], [0.0]], Dzu=[[0.0], [rho]])
    assert ctrl.gamma_opt == pytest.approx(best.fun, rel=RTOL)
    assert ctrl.K[0, 0] == pytest.approx(best.x, rel=1e-2)


# ------------------------------------------------------------ continuous time
def test_continuous_scalar_closed_form():
    """x' = a x + w + b u, z = [x; rho u]; ||T|| = sqrt(1 + rho^2 k^2) / |a + b k|.

    For a < 0 the optimum is attained: gamma* = rho / sqrt(b^2 + rho^2 a^2).
    For a > 0 it is only approached as k -> -inf: gamma* = rho / |b|; the
    backoff then gives a finite gain whose norm is below (1 + backoff) gamma*.
    """
    b, rho = 1.5, 0.7
    stable = hinf(Plant([[-2.0]], [[b]], None), Bw=[[1.0]], Cz=[[1.0], [0.0]], Dzu=[[0.0], [rho]])
    assert stable.gamma_opt == pytest.approx(rho / np.sqrt(b**2 + rho**2 * 4.0), rel=RTOL)
    unstable = hinf(Plant([[1.0]], [[b]], None), Bw=[[1.0]], Cz=[[1.0], [0.0]], Dzu=[[0.0], [rho]])
    assert unstable.gamma_opt == pytest.approx(rho / b, rel=RTOL)
    k = unstable.K[0, 0]
    assert np.isfinite(k) and 1.0 + b * k < 0
    assert np.sqrt(1 + (rho * k) ** 2) / abs(1.0 + b * k) <= unstable.gamma * (1 + 1e-9)


@pytest.mark.parametrize("seed", [3, 4])
def test_continuous_gamma_matches_hamiltonian_bisection(seed):
    plant, Bw, Cz, Dzu, _ = random_case(seed, 4, 2, 2, discrete=False)
    ctrl = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    ref = hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    assert ctrl.gamma_opt == pytest.approx(ref.gamma, rel=RTOL)
    norm = cl_norm(plant, ctrl.K, Bw, Cz, Dzu)
    assert ref.gamma_low * (1 - RTOL) <= norm <= ctrl.gamma * (1 + RTOL)


# Scherer, Gahinet & Chilali (1997), Example 7, as in python-control's
# examples/scherer_etal_ex7_Hinf_hinfsyn.py.
EX7_A = np.array([[0.0, 10, 2], [-1, 1, 0], [0, 2, -5]])
EX7_B1 = np.array([[1.0], [0], [1]])
EX7_B2 = np.array([[0.0], [1], [0]])
EX7_C1 = np.array([[1.0, 0, 0], [0, 0, 0]])
EX7_D12 = np.array([[0.0], [1]])


def test_scherer_gahinet_chilali_example7_against_hinfsyn():
    """SGC97 Ex. 7 with state feedback, against the Hamiltonian bisection and hinfsyn.

    Our problem is static *state* feedback, u = K x. python-control's
    ``hinfsyn`` (SLICOT SB10AD) solves the *output*-feedback problem and
    needs a measurement with a full-rank noise feedthrough (D21), so it cannot
    take y = x directly. We give it y = x + eps v, with v an extra disturbance
    input. Its optimum gamma(eps) is then an upper bound of ours (it sees a
    noisy state, and v adds to the disturbance channel) and converges to it as
    eps -> 0; in continuous time the full-information, dynamic and static
    state-feedback optima coincide, so the limit is exactly our gamma. With
    the example's own measurement (y = x2 + 2 w) hinfsyn's gamma is far
    larger: output feedback cannot do better than state feedback.
    The state-feedback optimum of this plant is reached only as |K| -> inf
    (the Riccati solution blows up), so the backoff is what keeps K finite.
    """
    plant = Plant(EX7_A, EX7_B2, None)
    ctrl = hinf(plant, Bw=EX7_B1, Cz=EX7_C1, Dzu=EX7_D12)
    ref = hinf_riccati(plant, Bw=EX7_B1, Cz=EX7_C1, Dzu=EX7_D12)
    assert ctrl.gamma_opt == pytest.approx(ref.gamma, rel=RTOL)
    assert cl_norm(plant, ctrl.K, EX7_B1, EX7_C1, EX7_D12) <= ctrl.gamma * (1 + RTOL)

    gammas = []
    for eps in (1e-1, 1e-2, 1e-3):
        B = np.hstack([EX7_B1, np.zeros((3, 3)), EX7_B2])
        C = np.vstack([EX7_C1, np.eye(3)])
        D = np.block([[np.zeros((2, 4)), EX7_D12], [np.zeros((3, 1)), eps * np.eye(3), np.zeros((3, 1))]])
        gammas.append(float(control.hinfsyn(control.ss(EX7_A, B, C, D), 3, 1)[2]))
    assert all(g >= ctrl.gamma_opt * (1 - RTOL) for g in gammas)
    assert gammas[0] > gammas[1] > gammas[2]
    assert gammas[2] == pytest.approx(ctrl.gamma_opt, rel=2e-3)

    D = np.array([[0.0, 0], [0, 1], [2, 0]])
    g_of = float(control.hinfsyn(control.ss(EX7_A, np.hstack([EX7_B1, EX7_B2]),
                                            np.vstack([EX7_C1, [[0, 1, 0]]]), D), 1, 1)[2])
    assert g_of > 10 * ctrl.gamma_opt


def test_backoff_keeps_the_gain_finite():
    plant = Plant(EX7_A, EX7_B2, None)
    at_opt = hinf(plant, Bw=EX7_B1, Cz=EX7_C1, Dzu=EX7_D12, backoff=0)
    backed = hinf(plant, Bw=EX7_B1, Cz=EX7_C1, Dzu=EX7_D12, backoff=1e-2)
    assert at_opt.gamma == at_opt.gamma_opt
    assert backed.gamma == pytest.approx(1.01 * backed.gamma_opt, rel=1e-12)
    assert np.linalg.norm(backed.K) < 1e-3 * np.linalg.norm(at_opt.K)
    assert cl_norm(plant, backed.K, EX7_B1, EX7_C1, EX7_D12) <= backed.gamma
    # the optimum is singular here (X -> singular, |K| -> inf): the floored X gives a
    # stabilising gain whose norm is the infimum up to the accuracy of the minimisation
    assert at_opt.is_stabilizing()
    assert cl_norm(plant, at_opt.K, EX7_B1, EX7_C1, EX7_D12) <= at_opt.gamma * (1 + 1e-6)


def test_discrete_gain_is_certified_at_the_backed_off_level_without_a_second_solve():
    """One plant, discrete time: the optimum's gain is kept with a Riccati-built certificate.

    Checked independently of the LMI code: the returned X satisfies the
    bounded-real Riccati *inequality* of the transposed closed loop (the
    Schur complement of the LMI, written out here), and linfnorm <= gamma.
    """
    plant, Bw, Cz, Dzu, Dzw = random_case(5, 6, 2, 2, discrete=True, cross=True)
    ctrl = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw)
    assert ctrl.info["gain_from"] == "optimum-certified"
    assert len(ctrl.info["solves"]) == 1
    A, C = plant.F + plant.G @ ctrl.K, Cz + Dzu @ ctrl.K
    X, g2 = ctrl.info["X"], ctrl.gamma**2
    W = g2 * np.eye(Cz.shape[0]) - C @ X @ C.T - Dzw @ Dzw.T
    assert np.linalg.eigvalsh(X).min() > 0 and np.linalg.eigvalsh(W).min() > 0
    N = A @ X @ C.T + Bw @ Dzw.T
    ric = A @ X @ A.T - X + Bw @ Bw.T + N @ np.linalg.solve(W, N.T)
    assert np.linalg.eigvalsh(0.5 * (ric + ric.T)).max() < 0
    assert cl_norm(plant, ctrl.K, Bw, Cz, Dzu, Dzw) <= ctrl.gamma


def test_preconditioning_is_a_similarity(monkeypatch):
    """The LQR coordinates change the solver's path, not the level: same gamma_opt without them."""
    synthesis = importlib.import_module("robustctl.synthesis.hinf")

    plant, Bw, Cz, Dzu, _ = random_case(2, 6, 2, 3, discrete=True)
    with_pre = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    monkeypatch.setattr(synthesis, "lqr_coordinates", lambda data, discrete: None)
    without = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    assert with_pre.info["solves"][0]["tol"] == 1e-8 and without.info["solves"][0]["tol"] == 1e-10
    ref = hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, rtol=1e-9)
    assert with_pre.gamma_opt == pytest.approx(ref.gamma, rel=RTOL)
    assert without.gamma_opt == pytest.approx(ref.gamma, rel=RTOL)


# ------------------------------------------------------------ fixed gamma
def test_fixed_gamma_feasible_and_infeasible():
    plant, Bw, Cz, Dzu, _ = random_case(1, 4, 2, 2, discrete=True)
    ref = hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    ctrl = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, gamma=1.05 * ref.gamma)
    assert ctrl.gamma_opt is None and ctrl.gamma == 1.05 * ref.gamma
    assert cl_norm(plant, ctrl.K, Bw, Cz, Dzu) < ctrl.gamma
    with pytest.raises(InfeasibleError, match=r"gamma=\d"):
        hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, gamma=0.95 * ref.gamma)


# ------------------------------------------------------------ polytopic
def msd(mass: float, dt: float = 0.05) -> Plant:
    """Mass-spring-damper, forward Euler: affine in 1/mass, so intermediate masses lie in the hull."""
    A = np.array([[0.0, 1.0], [-2.0 / mass, -0.3 / mass]])
    return Plant(np.eye(2) + dt * A, dt * np.array([[0.0], [1.0 / mass]]), dt)


MSD_BW, MSD_CZ, MSD_DZU = np.array([[0.0], [0.05]]), np.array([[1.0, 0.0], [0.0, 0.0]]), np.array([[0.0], [0.5]])


@pytest.mark.parametrize("extended", [False, True])
def test_polytopic_bound_holds_on_a_mass_grid(extended):
    ctrl = hinf(msd(1.0), Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU, vertices=[msd(4.0)], extended=extended)
    for mass in np.linspace(1.0, 4.0, 13):
        assert cl_norm(msd(mass), ctrl.K, MSD_BW, MSD_CZ, MSD_DZU) <= ctrl.gamma * (1 + RTOL)
    # the polytopic level is at least the worst vertex's own optimum
    own = max(hinf_riccati(msd(mm), Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU).gamma for mm in (1.0, 4.0))
    assert ctrl.gamma_opt >= own * (1 - RTOL)


def test_extended_lmi_is_never_worse_and_equal_without_vertices():
    std = hinf(msd(1.0), Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU, vertices=[msd(4.0)])
    ext = hinf(msd(1.0), Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU, vertices=[msd(4.0)], extended=True)
    assert ext.gamma_opt <= std.gamma_opt * (1 + 1e-6)
    plant, Bw, Cz, Dzu, _ = random_case(2, 4, 1, 2, discrete=True)
    a = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    b = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, extended=True)
    assert b.gamma_opt == pytest.approx(a.gamma_opt, rel=RTOL)
    assert b.info["lmi"] == "extended-discrete"


# ------------------------------------------------------------ input bound
def worst_case_input(plant: Plant, K, Bw, energy: float) -> np.ndarray:
    """Exact sup over all disturbances with energy <= E of |u_j(t)|, x0 = 0: sqrt(E k_j W k_j')."""
    A = plant.F + plant.G @ K
    if plant.is_discrete:
        W = scipy.linalg.solve_discrete_lyapunov(A, Bw @ Bw.T)
    else:
        W = scipy.linalg.solve_continuous_lyapunov(A, -Bw @ Bw.T)
    return np.sqrt(energy * np.einsum("ij,jk,ik->i", K, W, K))


def test_input_bound_holds_for_worst_and_random_disturbances():
    plant, Bw, Cz, Dzu, _ = random_case(1, 4, 2, 2, discrete=True)
    free = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    free_peak = worst_case_input(plant, free.K, Bw, 1.0)
    u_max = 0.5 * free_peak                  # binding for both inputs
    ctrl = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, u_max=u_max, w_energy=1.0)
    assert ctrl.gamma_opt >= free.gamma_opt * (1 - RTOL)   # the bound costs performance
    assert np.all(worst_case_input(plant, ctrl.K, Bw, 1.0) <= u_max)
    assert np.all(ctrl.info["u_bound"] <= u_max * (1 + 1e-9))
    # random unit-energy disturbances, simulated for all draws at once
    rng = np.random.default_rng(0)
    n_draws, horizon = 2000, 60
    w = rng.normal(size=(n_draws, horizon, Bw.shape[1])) * rng.exponential(size=(n_draws, horizon, 1)) ** 3
    w /= np.sqrt(np.sum(w**2, axis=(1, 2), keepdims=True))
    A = plant.F + plant.G @ ctrl.K
    x = np.zeros((n_draws, plant.n))
    peak = np.zeros(plant.m)
    for k in range(horizon):
        x = x @ A.T + w[:, k] @ Bw.T
        peak = np.maximum(peak, np.abs(x @ ctrl.K.T).max(axis=0))
    assert np.all(peak <= u_max)
    assert np.all(peak > 0.3 * u_max)        # the draws do push the input


def test_input_bound_continuous_time():
    plant, Bw, Cz, Dzu, _ = random_case(3, 3, 1, 1, discrete=False)
    free = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    u_max = 0.7 * worst_case_input(plant, free.K, Bw, 2.0)[0]
    ctrl = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, u_max=u_max, w_energy=2.0)
    assert worst_case_input(plant, ctrl.K, Bw, 2.0)[0] <= u_max


def check_input_bound_sweep(plant, Bw, Cz, Dzu, u_maxes, **kw):
    """Every u_max from far too tight to absurdly loose, against the unbounded design (issue 12).

    At least as loose as the unbounded design's guaranteed peak input
    sqrt(k X k') (X its Lyapunov matrix): the unbounded level, and the bound
    holds. Tighter: either a clear infeasibility or a design that pays for
    the bound and meets it (exact worst-case input by the Gramian).
    """
    free = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, **kw)
    peak = np.sqrt(np.einsum("ij,jk,ik->i", free.K, free.info["X"], free.K))
    assert np.all(worst_case_input(plant, free.K, Bw, 1.0) <= peak * (1 + 1e-9))
    loose = 0
    for u_max in u_maxes:
        try:
            ctrl = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, u_max=u_max, **kw)
        except (InfeasibleError, rc.ConvergenceError) as exc:
            # either outcome is valid: a clear error for an active bound, or a design meeting it
            assert np.any(u_max < peak), f"u_max={u_max:g} is inactive (peak {peak}) but: {exc}"  # noqa: PT017
            assert "u_max" in str(exc) or "backoff" in str(exc)  # noqa: PT017
            continue
        assert np.all(ctrl.info["u_bound"] <= u_max * (1 + 1e-9))
        for p in [plant, *list(kw.get("vertices", []))]:
            assert np.all(worst_case_input(p, ctrl.K, Bw, 1.0) <= u_max * (1 + 1e-9))
        assert ctrl.gamma_opt >= free.gamma_opt * (1 - RTOL)
        if np.all(u_max >= peak):
            loose += 1
            assert ctrl.gamma_opt == pytest.approx(free.gamma_opt, rel=RTOL)
            assert np.allclose(ctrl.K, free.K, rtol=1e-3, atol=0)
    return loose


def test_a_loose_input_bound_gives_the_unbounded_design():
    """Issue 12: u_max = 1e5 raised InfeasibleError and 1e8, 1e12 a solver failure on this plant."""
    plant = Plant([[1.1, .2], [0, .9]], [[0], [1]], .1)
    Bw, Cz, Dzu = np.array([[0.0], [1]]), np.array([[1.0, 0], [0, 1], [0, 0]]), np.array([[0.0], [0], [1]])
    assert check_input_bound_sweep(plant, Bw, Cz, Dzu, 10.0 ** np.arange(-1, 13)) == 12   # 1e1 .. 1e12


def test_too_tight_input_bound_is_infeasible():
    plant = Plant([[1.5]], [[1.0]], 1.0)       # unstable: needs |k| > 0.5
    with pytest.raises((InfeasibleError, rc.ConvergenceError), match="u_max"):
        hinf(plant, Bw=[[1.0]], Cz=[[1.0], [0.0]], Dzu=[[0.0], [1.0]], u_max=0.01, w_energy=1.0)


# ------------------------------------------------------------ API and bad input
def test_design_dispatch_and_controller_type():
    plant, Bw, Cz, Dzu, _ = random_case(0, 3, 1, 1, discrete=True)
    ctrl = rc.design("hinf", plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    assert isinstance(ctrl, HinfController) and isinstance(ctrl, rc.Controller)
    assert rc.HinfController is HinfController
    assert ctrl.method == "hinf" and ctrl.K.shape == (1, 3)
    assert np.allclose(ctrl(np.ones(3)), ctrl.K @ np.ones(3))      # u = K x
    assert np.max(np.abs(np.linalg.eigvals(plant.F + plant.G @ ctrl.K))) < 1
    for key in ("status", "solve_time", "iterations", "certificate", "X_min_eig", "gamma_opt"):
        assert key in ctrl.info
    assert ctrl.info["X_min_eig"] > 0
    assert min(ctrl.info["certificate"].values()) > 0
    assert "gamma=" in repr(ctrl)
    with pytest.raises(AttributeError):
        ctrl.gamma = 1.0


def test_package_attribute_is_the_function():
    """Importing the module robustctl.synthesis.hinf does not shadow the function robustctl.hinf."""
    import robustctl.synthesis.hinf  # noqa: F401

    assert rc.hinf is hinf and callable(rc.hinf)


BASE = dict(Bw=np.ones((3, 1)), Cz=np.vstack([np.eye(3), np.zeros((1, 3))]), Dzu=np.array([[0.0], [0], [0], [1]]))
PLANT = Plant(np.diag([1.1, 0.5, 0.2]), np.ones((3, 1)), 0.1)


@pytest.mark.parametrize("kw,match", [
    (dict(Bw=np.ones((2, 1))), r"Bw must have 3 rows.*\(2, 1\)"),
    (dict(Cz=np.ones((4, 2))), r"Cz must have 3 columns.*\(4, 2\)"),
    (dict(Dzu=np.ones((3, 1))), r"Dzu must have 4 rows.*\(3, 1\)"),
    (dict(Dzw=np.ones((4, 2))), r"Dzw must have 1 columns.*\(4, 2\)"),
    (dict(Bw=np.array([[np.nan], [0], [0]])), "Bw must have finite"),
    (dict(Cz=np.full((4, 3), np.inf)), "Cz must have finite"),
    (dict(u_max=0.0), "u_max must be > 0"),
    (dict(u_max=-1.0), "u_max must be > 0"),
    (dict(u_max=[1.0, 2.0]), r"u_max must be a scalar or have 1 entry \(the number of inputs\), got shape \(2,\)"),
    (dict(u_max=np.inf), "u_max must be finite"),
    (dict(w_energy=1.0), "w_energy is only used together with u_max"),
    (dict(u_max=1.0, w_energy=0.0), "w_energy must be > 0"),
    (dict(gamma=-1.0), "gamma must be > 0"),
    (dict(gamma=np.nan), "gamma must be a number"),
    (dict(backoff=-0.1), "backoff must be"),
    (dict(solver="NOPE"), "solver must be"),
    (dict(vertices=[Plant(np.eye(2), np.ones((2, 1)), 0.1)]), r"vertices\[0\] must have n=3"),
    (dict(vertices=[Plant(np.eye(3), np.ones((3, 1)), 0.2)]), r"vertices\[0\] must have the sampling time"),
])
def test_bad_input_is_named(kw, match):
    with pytest.raises(ValueError, match=match):
        hinf(PLANT, **{**BASE, **kw})


def test_bad_types():
    with pytest.raises(TypeError, match="plant"):
        hinf(np.eye(3), **BASE)
    with pytest.raises(TypeError, match="vertices"):
        hinf(PLANT, **BASE, vertices=PLANT)
    with pytest.raises(TypeError, match=r"vertices\[0\]"):
        hinf(PLANT, **BASE, vertices=[np.eye(3)])
    with pytest.raises(ValueError, match="extended"):
        hinf(Plant(np.eye(3), np.ones((3, 1)), None), **BASE, extended=True)


def test_unstabilisable_plant_gives_a_plain_error():
    # mode 1.2 is unstable and not reached by G
    plant = Plant(np.diag([1.2, 0.5]), [[0.0], [1.0]], 0.1)
    with pytest.raises(InfeasibleError, match=r"not stabilisable.*lambda = 1\.2"):
        hinf(plant, Bw=np.eye(2), Cz=np.vstack([np.eye(2), [[0, 0]]]), Dzu=[[0.0], [0.0], [1.0]])
    cont = Plant(np.diag([0.3, -1.0]), [[0.0], [1.0]], None)
    with pytest.raises(InfeasibleError, match="not stabilisable"):
        hinf(cont, Bw=np.eye(2), Cz=np.vstack([np.eye(2), [[0, 0]]]), Dzu=[[0.0], [0.0], [1.0]])
    bad_vertex = Plant(np.diag([1.2, 0.5]), [[0.0], [1.0]], 0.1)
    good = Plant(np.diag([1.2, 0.5]), [[1.0], [1.0]], 0.1)
    with pytest.raises(InfeasibleError, match=r"vertices\[0\] is not stabilisable"):
        hinf(good, Bw=np.eye(2), Cz=np.vstack([np.eye(2), [[0, 0]]]), Dzu=[[0.0], [0.0], [1.0]],
             vertices=[bad_vertex])


def test_an_empty_vertex_list_is_named_not_read_as_no_polytope():
    """Issue 35's fault probe: vertices=[] was silently the plant alone."""
    plant = rc.Plant([[1.1]], [[1.0]], 0.1)
    with pytest.raises(TypeError, match=r"^vertices must be a non-empty list of robustctl\.Plant"):
        rc.hinf(plant, Bw=[[1.0]], Cz=[[1.0], [0.0]], Dzu=[[0.0], [1.0]], vertices=[])
