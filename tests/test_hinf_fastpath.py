"""``hinf(..., synthesis="riccati")``: the game-Riccati fast path against independent references.

References, none sharing code with the fast path:

* the SDP path of the same function (cvxpy + Clarabel, the LMI optimum);
* a game-Riccati level test written here on python-control's ``dare``
  (SLICOT SG02AD): a static gain with ``||T_zw|| < gamma`` exists iff the
  stabilising solution exists, is >= 0, its closed loop is stable and
  ``Bw'PBw + Dzw'Dzw < gamma^2 I``;
* python-control's ``hinfsyn`` (SLICOT SB10AD) on the measured state
  ``y = x + eps v`` (an upper bound converging to the state-feedback optimum,
  see ``test_hinf.py``);
* python-control's ``linfnorm`` (SLICOT AB13DD) of the closed loop.
"""

from __future__ import annotations

import warnings

import control
import numpy as np
import pytest

import robustctl as rc
from robustctl import Plant
from robustctl.synthesis._hinf import riccati_path as _riccati_path
from robustctl.systems.uncertainty import NormBounded

RTOL = 1e-5


def cl_norm(plant: Plant, K, Bw, Cz, Dzu) -> float:
    sys = control.ss(plant.F + plant.G @ K, Bw, Cz + Dzu @ K, np.zeros((Cz.shape[0], Bw.shape[1])),
                     0 if plant.dt is None else plant.dt)
    return float(control.linfnorm(sys, tol=1e-10)[0])


def dare_feasible(plant: Plant, Bw, Cz, Dzu, gamma: float) -> bool:
    """The game-Riccati level test on python-control's dare (discrete, Dzw = 0)."""
    m, q = plant.m, Bw.shape[1]
    B = np.hstack([plant.G, Bw])
    D = np.hstack([Dzu, np.zeros((Cz.shape[0], q))])
    R = D.T @ D - np.diag(np.r_[np.zeros(m), np.full(q, gamma**2)])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            X, L, _ = control.dare(plant.F, B, Cz.T @ Cz, R, Cz.T @ D)
    except (ArithmeticError, ValueError, RuntimeError, Warning):
        return False
    return bool(np.max(np.abs(L)) < 1 and np.linalg.eigvalsh(X).min() > -1e-8 * np.abs(X).max()
                and np.linalg.eigvalsh(Bw.T @ X @ Bw - gamma**2 * np.eye(q)).max() < 0)


def random_case(seed: int, n: int, m: int = 2, q: int = 2, discrete: bool = True):
    rng = np.random.default_rng(seed)
    F = rng.normal(size=(n, n))
    if discrete:
        F *= 1.05 / np.max(np.abs(np.linalg.eigvals(F)))
    G, Bw = rng.normal(size=(n, m)), rng.normal(size=(n, q))
    Cz = np.vstack([rng.normal(size=(2, n)), np.zeros((m, n))])
    Dzu = np.vstack([np.zeros((2, m)), np.eye(m)])
    return Plant(F, G, 0.1 if discrete else None), Bw, Cz, Dzu


@pytest.mark.parametrize("seed,n", [(0, 3), (1, 6), (2, 12)])
def test_discrete_fast_path_equals_sdp_and_the_dare_level_test(seed, n):
    plant, Bw, Cz, Dzu = random_case(seed, n)
    fast = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, synthesis="riccati")
    sdp = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    assert fast.info["synthesis"] == "riccati" and fast.info["fallback"] is None
    assert sdp.info["synthesis"] == "lmi" and "fallback" not in sdp.info
    assert fast.gamma_opt == pytest.approx(sdp.gamma_opt, rel=RTOL)
    # python-control's dare brackets the level
    assert dare_feasible(plant, Bw, Cz, Dzu, fast.gamma_opt * (1 + 1e-6))
    assert not dare_feasible(plant, Bw, Cz, Dzu, fast.gamma_opt * (1 - 1e-6))
    assert fast.gamma == pytest.approx(fast.gamma_opt * (1 + fast.info["backoff"]), rel=1e-12)
    assert cl_norm(plant, fast.K, Bw, Cz, Dzu) <= fast.gamma
    assert min(fast.info["certificate"].values()) > 0
    assert fast.info["certificate"]["hinf[0]"] > 0 and fast.info["gain_from"] == "riccati"
    assert fast.is_stabilizing()


def test_continuous_fast_path_against_sdp_hinfsyn_and_linfnorm():
    """Scherer, Gahinet & Chilali (1997), Ex. 7 (state feedback, optimum only as |K| -> inf)."""
    A = np.array([[0.0, 10, 2], [-1, 1, 0], [0, 2, -5]])
    B1, B2 = np.array([[1.0], [0], [1]]), np.array([[0.0], [1], [0]])
    C1, D12 = np.array([[1.0, 0, 0], [0, 0, 0]]), np.array([[0.0], [1]])
    plant = Plant(A, B2, None)
    fast = rc.hinf(plant, Bw=B1, Cz=C1, Dzu=D12, synthesis="riccati", backoff=1e-2)
    sdp = rc.hinf(plant, Bw=B1, Cz=C1, Dzu=D12, backoff=1e-2)
    assert fast.info["synthesis"] == "riccati"
    assert fast.gamma_opt == pytest.approx(sdp.gamma_opt, rel=RTOL)
    B = np.hstack([B1, np.zeros((3, 3)), B2])
    C = np.vstack([C1, np.eye(3)])
    D = np.block([[np.zeros((2, 4)), D12], [np.zeros((3, 1)), 1e-3 * np.eye(3), np.zeros((3, 1))]])
    g_hinfsyn = float(control.hinfsyn(control.ss(A, B, C, D), 3, 1)[2])
    assert fast.gamma_opt <= g_hinfsyn * (1 + RTOL)
    assert g_hinfsyn == pytest.approx(fast.gamma_opt, rel=2e-3)
    assert cl_norm(plant, fast.K, B1, C1, D12) <= fast.gamma
    assert min(fast.info["certificate"].values()) > 0


def test_design_passes_synthesis_through_and_the_truck_agrees():
    from robustctl.models.truck import truck_plant

    plant = truck_plant(0.0)
    Bw, Cz, Dzu = plant.G, np.vstack([np.eye(4), np.zeros((1, 4))]), np.vstack([np.zeros((4, 1)), [[1.0]]])
    fast = rc.design("hinf", plant, Bw=Bw, Cz=Cz, Dzu=Dzu, synthesis="riccati")
    assert fast.method == "hinf" and fast.info["synthesis"] == "riccati"
    assert fast.gamma_opt == pytest.approx(1.2547432, rel=1e-6)   # the SDP's value (test_hinf's doctest)
    assert dare_feasible(plant, Bw, Cz, Dzu, fast.gamma_opt * (1 + 1e-6))
    assert not dare_feasible(plant, Bw, Cz, Dzu, fast.gamma_opt * (1 - 1e-6))
    assert cl_norm(plant, fast.K, Bw, Cz, Dzu) <= fast.gamma


def test_fallback_to_the_sdp_when_the_certificate_fails(monkeypatch):
    plant, Bw, Cz, Dzu = random_case(3, 4)
    monkeypatch.setattr(_riccati_path, "riccati_certified", lambda *a, **k: None)
    ctrl = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, synthesis="riccati")
    assert ctrl.info["synthesis"] == "lmi"
    assert "certificate" in ctrl.info["fallback"]
    assert ctrl.info["solves"] and ctrl.info["gain_from"] == "optimum-certified"
    assert ctrl.gamma_opt == pytest.approx(rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu).gamma_opt, rel=1e-9)
    assert cl_norm(plant, ctrl.K, Bw, Cz, Dzu) <= ctrl.gamma


def test_backoff_zero_falls_back_to_the_sdp_optimum():
    """No strictly positive certificate exists at the optimum itself: the SDP's optimal point is returned."""
    plant, Bw, Cz, Dzu = random_case(0, 5)
    ctrl = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, synthesis="riccati", backoff=0)
    assert ctrl.info["synthesis"] == "lmi" and ctrl.info["gain_from"] == "optimum"
    assert ctrl.gamma == ctrl.gamma_opt
    assert dare_feasible(plant, Bw, Cz, Dzu, ctrl.gamma_opt * (1 + 1e-6))
    assert cl_norm(plant, ctrl.K, Bw, Cz, Dzu) <= ctrl.gamma * (1 + 1e-6)


def test_fallback_when_the_bisection_finds_no_level(monkeypatch):
    plant, Bw, Cz, Dzu = random_case(4, 4)
    def no_level(*args, **kwargs):
        raise rc.InfeasibleError("no stabilising game-Riccati solution for gamma up to 1e+10")

    monkeypatch.setattr(_riccati_path, "bisect_level", no_level)
    ctrl = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, synthesis="riccati")
    assert ctrl.info["synthesis"] == "lmi" and "no stabilising game-Riccati" in ctrl.info["fallback"]
    assert cl_norm(plant, ctrl.K, Bw, Cz, Dzu) <= ctrl.gamma


def _vertex(plant):
    return Plant(plant.F * 1.01, plant.G, plant.dt)


@pytest.mark.parametrize("name,extra", [
    ("vertices", lambda p: {"vertices": [_vertex(p)]}),
    ("u_max", lambda p: {"u_max": 10.0}),
    ("poles", lambda p: {"poles": rc.Disk(0.0, 0.99)}),
    ("uncertainty", lambda p: {"uncertainty": NormBounded(np.ones((p.n, 1)), 0.1 * np.ones((1, p.n)),
                                                          np.zeros((1, p.m)))}),
    ("gamma", lambda p: {"gamma": 100.0}),
    ("extended", lambda p: {"extended": True}),
])
def test_riccati_with_a_constrained_variant_is_a_value_error_naming_it(name, extra):
    plant, Bw, Cz, Dzu = random_case(0, 3)
    with pytest.raises(ValueError, match=rf"synthesis='riccati' .* drop {name} or use synthesis='lmi'"):
        rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, synthesis="riccati", **extra(plant))


def test_bad_synthesis_names_the_argument():
    plant, Bw, Cz, Dzu = random_case(0, 3)
    with pytest.raises(ValueError, match=r"^synthesis must be one of 'lmi', 'riccati', got 'fast'"):
        rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, synthesis="fast")
    with pytest.raises(TypeError, match=r"^synthesis must be one of"):
        rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, synthesis=1)
    # the fast path checks the solver's name without importing cvxpy
    with pytest.raises(ValueError, match=r"^solver must name a cvxpy SDP solver, one of \['CLARABEL'"):
        rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, synthesis="riccati", solver="clarabell")
    with pytest.raises(TypeError, match=r"^solver must be a string"):
        rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, synthesis="riccati", solver=3)


@pytest.mark.parametrize("synthesis", ["lmi", "riccati"])
def test_channels_scaled_out_of_float64_range_name_the_argument(synthesis):
    """Issue 23 item 11: Bw scaled 1e-300 raised a bare OverflowError (34, 'Numerical result out of range')."""
    plant, Bw, Cz, Dzu = random_case(0, 3)
    with pytest.raises(ValueError, match=r"^Bw is scaled out of range: 1 / \|\|Bw\|\|_2 = .*e\+(299|300)"):
        rc.hinf(plant, Bw=1e-300 * Bw, Cz=Cz, Dzu=Dzu, synthesis=synthesis)
    with pytest.raises(ValueError, match=r"^Cz, Dzu, Dzw is scaled out of range"):
        rc.hinf(plant, Bw=Bw, Cz=1e-300 * Cz, Dzu=1e-300 * Dzu, synthesis=synthesis)
    # a large but representable scaling is fine, and the level scales with it
    ref = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, synthesis=synthesis)
    small = rc.hinf(plant, Bw=1e-100 * Bw, Cz=Cz, Dzu=Dzu, synthesis=synthesis)
    assert small.gamma_opt == pytest.approx(1e-100 * ref.gamma_opt, rel=RTOL)


def test_input_bound_energy_out_of_range_names_w_energy():
    plant, Bw, Cz, Dzu = random_case(0, 3)
    with pytest.raises(ValueError, match=r"^w_energy is scaled out of range"):
        rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, u_max=1.0, w_energy=1e-305)


def test_riccati_bisection_without_slycot_agrees(monkeypatch):
    """The bisection's DARE: SLICOT SG02AD when installed, scipy otherwise; same level."""
    from robustctl.synthesis import hinf_riccati as module

    plant, Bw, Cz, Dzu = random_case(5, 5)
    with_slycot = module.hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, rtol=1e-9)
    monkeypatch.setattr(module, "_SG02AD", None)
    scipy_only = module.hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, rtol=1e-9)
    assert with_slycot.gamma == pytest.approx(scipy_only.gamma, rel=1e-8)
    assert dare_feasible(plant, Bw, Cz, Dzu, scipy_only.gamma * (1 + 1e-6))
    assert not dare_feasible(plant, Bw, Cz, Dzu, scipy_only.gamma * (1 - 1e-6))
