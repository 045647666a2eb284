"""The stages of the LMI H-infinity synthesis (robustctl.synthesis.hinf._*) one by one, and every fallback path.

The references are independent of the LMI code: python-control's ``linfnorm``
of the closed loop, the game-Riccati bisection ``robustctl.synthesis.hinf_riccati``,
scipy's Riccati and Lyapunov solvers, and plain linear algebra (a similarity
keeps the spectrum, a compressed output keeps the Gram matrix). Solver
failures that no small test plant produces are injected by wrapping one
stage (``monkeypatch``); the result is then still checked against the
references.
"""

from __future__ import annotations

import dataclasses
import importlib
import sys

import numpy as np
import pytest
import scipy.linalg
from test_hinf import MSD_BW, MSD_CZ, MSD_DZU, cl_norm, msd, random_case, worst_case_input

from robustctl import ConvergenceError, InfeasibleError, Plant
from robustctl.synthesis._hinf import coordinates as _coordinates
from robustctl.synthesis._hinf import gains as _gains
from robustctl.synthesis._hinf import level as _level
from robustctl.synthesis._hinf import lmis as _lmis
from robustctl.synthesis._hinf import problem as _problem
from robustctl.synthesis._hinf import tolerances as tol
from robustctl.synthesis.hinf import hinf
from robustctl.synthesis.hinf_riccati import hinf_riccati

_synthesis = importlib.import_module("robustctl.synthesis.hinf")  # the module (the package's attribute is the function)

RTOL = 1e-5


def problem_of(plant, **kw) -> _problem.Problem:
    args = dict(Dzw=None, vertices=None, gamma=None, u_max=None, w_energy=None, backoff=1e-3, extended=False,
                solver="CLARABEL")
    args.update(kw)
    return _problem.validate(plant, **args)


def balanced_of(problem) -> _coordinates.Coordinates:
    w_scale = np.sqrt(problem.w_energy) if problem.u_max is not None else 1.0
    return _coordinates.normalised([p.F for p in problem.plants], [p.G for p in problem.plants], problem.Bw,
                                   problem.Cz, problem.Dzu, problem.Dzw, w_scale)


def optimum_of(problem) -> _level.Optimum:
    balanced = balanced_of(problem)
    lqr = None if problem.polytopic else _coordinates.lqr_coordinates(balanced, problem.discrete)
    return _level.minimise_level(problem, balanced, lqr)


def gain_of(gain: _gains.Gain) -> np.ndarray:
    return gain.data.to_original(gain.point.gain(), gain.point.nominal_lyapunov())[0]


@pytest.fixture(scope="module")
def discrete():
    plant, Bw, Cz, Dzu, _ = random_case(1, 4, 2, 2, discrete=True)
    problem = problem_of(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    return problem, optimum_of(problem)


@pytest.fixture(scope="module")
def polytope():
    problem = problem_of(msd(1.0), Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU, vertices=[msd(4.0)])
    return problem, optimum_of(problem)


def meets(problem, K, gamma) -> bool:
    """linfnorm of the closed loop at every vertex <= gamma (the guarantee)."""
    return all(cl_norm(p, K, problem.Bw, problem.Cz, problem.Dzu, problem.Dzw) <= gamma * (1 + RTOL)
               for p in problem.plants)


# ------------------------------------------------------------ coordinates
def test_normalised_is_a_similarity_with_unit_disturbance_gain():
    plant, Bw, Cz, Dzu, _ = random_case(2, 6, 2, 3, discrete=True)
    data = balanced_of(problem_of(plant, Bw=Bw, Cz=Cz, Dzu=Dzu))
    T = data.T
    assert np.allclose(T, np.diag(np.diag(T)))                      # diagonal balancing
    assert np.allclose(T @ data.F[0], plant.F @ T) and np.allclose(T @ data.G[0], plant.G)
    assert np.linalg.norm(data.Bw, 2) == pytest.approx(1.0, rel=1e-12)
    assert np.allclose(data.Cz, Cz @ T)


def test_output_compression_keeps_the_gram_matrix_and_the_level():
    """z = [Cz; Cz] x + [Dzu; Dzu] u has rank-deficient rows: the factor has fewer rows, same z'z."""
    plant, Bw, Cz, Dzu, _ = random_case(1, 4, 2, 2, discrete=True)
    C2, D2 = np.vstack([Cz, Cz]), np.vstack([Dzu, Dzu])
    data = balanced_of(problem_of(plant, Bw=Bw, Cz=C2, Dzu=D2))
    assert data.p == np.linalg.matrix_rank(np.hstack([C2, D2])) < C2.shape[0]
    R = np.hstack([data.Cz @ np.linalg.inv(data.T), data.Dzu, data.Dzw])
    CD = np.hstack([C2, D2, np.zeros((C2.shape[0], Bw.shape[1]))])
    assert np.allclose(R.T @ R, CD.T @ CD)
    ctrl = hinf(plant, Bw=Bw, Cz=C2, Dzu=D2)
    assert ctrl.gamma_opt == pytest.approx(hinf_riccati(plant, Bw=Bw, Cz=C2, Dzu=D2).gamma, rel=RTOL)


def test_without_slycot_there_is_no_balancing_and_the_level_is_unchanged(monkeypatch):
    monkeypatch.setitem(sys.modules, "slycot", None)               # import slycot now raises ImportError
    plant, Bw, Cz, Dzu, _ = random_case(0, 3, 1, 1, discrete=True)
    d = _coordinates._balance(plant.F, Bw, plant.G, Cz)
    assert np.array_equal(d, np.ones(3))
    ctrl = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    assert ctrl.gamma_opt == pytest.approx(hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu).gamma, rel=RTOL)


def test_lqr_coordinates_make_the_lqr_storage_nearly_the_identity(discrete):
    problem, _ = discrete
    data = balanced_of(problem)
    lqr = _coordinates.lqr_coordinates(data, True)
    C, D = problem.Cz, problem.Dzu
    P = scipy.linalg.solve_discrete_are(problem.plants[0].F, problem.plants[0].G, C.T @ C, D.T @ D, s=C.T @ D)
    Ph = lqr.T.T @ P @ lqr.T                                       # the same storage in the new coordinates
    assert np.linalg.cond(Ph) < 1.1 / tol.RECENTRE_REG
    assert np.linalg.norm(lqr.Bw, 2) == pytest.approx(1.0, rel=1e-12)


def test_lqr_coordinates_give_up_cleanly(discrete, monkeypatch):
    problem, _ = discrete
    data = balanced_of(problem)
    # no stabilising Riccati solution (the data bypass validation: G = 0 with an unstable F)
    stuck = dataclasses.replace(data, F=(2.0 * np.eye(4),), G=(np.zeros((4, 2)),))
    assert _coordinates.lqr_coordinates(stuck, True) is None
    # no disturbance: nothing to normalise by
    no_bw = (*data.original[:2], np.zeros((4, 2)), *data.original[3:])
    assert _coordinates.lqr_coordinates(dataclasses.replace(data, Bw=np.zeros_like(data.Bw), original=no_bw),
                                        True) is None
    # a Riccati solver returning a matrix that is not positive
    monkeypatch.setattr(scipy.linalg, "solve_discrete_are", lambda *a, **k: -np.eye(4))
    assert _coordinates.lqr_coordinates(data, True) is None


def test_recentred_makes_the_matrix_the_identity_and_rejects_unusable_ones(discrete):
    problem, _opt = discrete
    data = balanced_of(problem)
    rng = np.random.default_rng(0)
    M = rng.normal(size=(4, 4))
    X = M @ M.T + 0.1 * np.eye(4)
    new, lam_max = _coordinates.recentred(data, X, 1e-9)
    Xh = np.linalg.solve(new.T, data.T @ X @ data.T.T) @ np.linalg.inv(new.T).T
    assert np.allclose(Xh, np.eye(4), atol=1e-7) and lam_max == pytest.approx(1.0, rel=1e-7)
    assert np.allclose(np.sort_complex(np.linalg.eigvals(new.F[0])),
                       np.sort_complex(np.linalg.eigvals(problem.plants[0].F)))
    assert _coordinates.recentred(data, -np.eye(4), 1e-3) is None
    assert _coordinates.recentred(data, np.full((4, 4), np.nan), 1e-3) is None


def test_coordinates_round_trip(discrete):
    _, opt = discrete
    data = opt.data
    X = opt.point.X
    K, Xo = data.to_original(opt.point.gain(), X)
    assert np.allclose(data.from_original(Xo), X)
    assert np.allclose(K @ data.T, opt.point.gain())


# ------------------------------------------------------------ blocks
def test_blocks_at_the_riccati_built_point_are_positive_exactly_above_the_gains_norm(discrete):
    """Discrete BRL: blocks(level) > 0 at a point built for K iff ||T_zw(K)|| < level (linfnorm)."""
    problem, opt = discrete
    plant = problem.plants[0]
    attempt = _gains.optimum_certified(problem, opt, 1e-3)
    K = gain_of(attempt.gain)
    norm = cl_norm(plant, K, problem.Bw, problem.Cz, problem.Dzu)
    assert norm <= opt.gamma_opt * (1 + 1e-3)
    assert min(attempt.gain.certificate.values()) > tol.STRICT
    # the same point is not a certificate at a level below the norm
    z_scale = 1.0 / (opt.data.w_scale * 0.999 * norm)
    cert = _lmis_certificate(problem, opt.data, attempt.gain.point, z_scale)
    assert cert["hinf[0]"] < 0


def _lmis_certificate(problem, data, point, z_scale):
    from robustctl import _cvx

    return _cvx.certificate(_lmis.blocks(problem, data, point, 1.0, z_scale=z_scale))


def test_lyapunov_bounds_and_strictness(polytope):
    _, opt = polytope
    from robustctl import _cvx

    X = opt.point.X
    lam = np.linalg.eigvalsh(X)
    cert = _cvx.certificate(_lmis.lyapunov_blocks(opt.point, 0.5 * lam[0], 2.0 * lam[-1]))
    assert cert["X"] == pytest.approx(lam[0]) and cert["X_upper"] == pytest.approx(2.0 * lam[-1] - lam[-1])
    assert _lmis.is_strict({"hinf[0]": 1e-9, "X": 1e-3, "X_upper": -1.0, "u_max[0]": -1.0})
    assert not _lmis.is_strict({"hinf[0]": -1e-12, "X": 1.0})


def test_guaranteed_input_bound_is_above_the_exact_worst_case_input():
    plant, Bw, Cz, Dzu, _ = random_case(1, 4, 2, 2, discrete=True)
    ctrl = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, u_max=100.0)
    exact = worst_case_input(plant, ctrl.K, Bw, 1.0)
    assert np.all(ctrl.info["u_bound"] >= exact * (1 - 1e-9))
    X = ctrl.info["X"]
    assert np.allclose(ctrl.info["u_bound"], np.sqrt(np.einsum("ij,jk,ik->i", ctrl.K, X, ctrl.K)), rtol=1e-9)


# ------------------------------------------------------------ level minimisation
def test_level_falls_back_to_balanced_coordinates(discrete, monkeypatch):
    problem, _ = discrete
    real = _level.solve_level

    def lqr_coordinates_fail(problem, data, **kw):
        if kw.get("preconditioned"):
            raise ConvergenceError("injected")
        return real(problem, data, **kw)

    monkeypatch.setattr(_level, "solve_level", lqr_coordinates_fail)
    opt = optimum_of(problem)
    assert not opt.preconditioned and opt.solves[0]["tol"] == tol.LEVEL_TOL_GENERAL
    plant = problem.plants[0]
    assert opt.gamma_opt == pytest.approx(hinf_riccati(plant, Bw=problem.Bw, Cz=problem.Cz, Dzu=problem.Dzu).gamma,
                                          rel=RTOL)
    monkeypatch.setattr(_level, "solve_level", lambda *a, **k: (_ for _ in ()).throw(ConvergenceError("both")))
    with pytest.raises(ConvergenceError, match="both"):
        optimum_of(problem)


def test_extended_level_restarts_from_the_standard_solution(polytope, monkeypatch):
    problem, std = polytope
    ext = dataclasses.replace(problem, extended=True)
    real = _level.solve_level
    calls = []

    def extended_fails_once(problem, data, **kw):
        calls.append(kw.get("extended"))
        if kw.get("extended") is None and len(calls) == 1:
            raise ConvergenceError("injected")
        return real(problem, data, **kw)

    monkeypatch.setattr(_level, "solve_level", extended_fails_once)
    opt = _level.minimise_level(ext, balanced_of(ext), None)
    assert calls[:3] == [None, False, None]                   # extended, standard, extended again
    assert opt.centring is not None and opt.point.extended
    assert opt.gamma_opt <= std.gamma_opt * (1 + 1e-6)         # never worse than the standard LMI
    gain, backoff, _ = _gains.gain_near_optimum(ext, opt)
    assert meets(ext, gain_of(gain), opt.gamma_opt * (1 + backoff))


@pytest.mark.parametrize("standard", ["raises", "zero level"])
def test_extended_level_gives_up_with_the_original_error(polytope, monkeypatch, standard):
    problem, _std = polytope
    ext = dataclasses.replace(problem, extended=True)
    real = _level.solve_level

    def fake(problem, data, **kw):
        if kw.get("extended") is None:
            raise ConvergenceError("extended failed")
        if standard == "raises":
            raise InfeasibleError("standard failed")
        return real(problem, data, **kw)._replace(level_sq=0.0)

    monkeypatch.setattr(_level, "solve_level", fake)
    with pytest.raises(ConvergenceError, match="extended failed"):
        _level.minimise_level(ext, balanced_of(ext), None)


def test_inaccurate_level_is_polished_and_the_lower_kept(polytope):
    problem, opt = polytope
    assert [s["status"] for s in opt.solves] == ["optimal_inaccurate", "optimal"]
    assert opt.report.status == "optimal" and opt.data is not balanced_of(problem)


def test_failed_polish_keeps_the_inaccurate_solution(polytope, monkeypatch):
    problem, ref = polytope
    real = _level.solve_level
    calls = []

    def polish_fails(problem, data, **kw):
        calls.append(1)
        if len(calls) > 1:
            raise ConvergenceError("injected")
        return real(problem, data, **kw)

    monkeypatch.setattr(_level, "solve_level", polish_fails)
    opt = optimum_of(problem)
    assert len(calls) == 2 and [s["status"] for s in opt.solves] == ["optimal_inaccurate"]
    assert opt.gamma_opt == pytest.approx(ref.gamma_opt, rel=1e-5)
    # an unusable inaccurate solution is not polished at all
    monkeypatch.setattr(_level, "recentred", lambda *a: None)
    calls.clear()
    assert len(optimum_of(problem).solves) == 1 and len(calls) == 1


# ------------------------------------------------------------ gain strategies
def test_optimum_certified_applies_to_one_discrete_plant_only(discrete, polytope):
    problem, opt = discrete
    attempt = _gains.optimum_certified(problem, opt, 1e-3)
    assert attempt.gain.route == "optimum-certified" and attempt.solves == ()
    assert np.allclose(gain_of(attempt.gain), opt.data.to_original(opt.point.gain(), opt.point.X)[0])
    assert meets(problem, gain_of(attempt.gain), opt.gamma_opt * (1 + 1e-3))
    assert _gains.optimum_certified(*polytope, 1e-3).gain is None
    cont, _, _, _, _ = random_case(3, 4, 2, 2, discrete=False)
    assert _gains.optimum_certified(dataclasses.replace(problem, plants=(cont,)), opt, 1e-3).gain is None


@pytest.mark.parametrize("backoff", [1e-12, -0.1])
def test_optimum_certified_fails_without_room(discrete, backoff):
    """Margin eps * backoff below STRICT, or a level below the gain's norm (no stabilising Riccati solution)."""
    problem, opt = discrete
    attempt = _gains.optimum_certified(problem, opt, backoff)
    assert attempt.gain is None and attempt.failure is None and attempt.solves == ()


@pytest.mark.parametrize("strategy", _gains.STRATEGIES, ids=lambda s: s.__name__)
@pytest.mark.parametrize("case", ["discrete", "polytope"])
def test_each_centring_strategy_certifies_its_gain(strategy, case, request):
    problem, opt = request.getfixturevalue(case)
    attempt = strategy(problem, opt, 1e-3)
    gain = attempt.gain
    assert gain is not None and len(attempt.solves) == 1 and attempt.solves[0]["centring"] == gain.route
    assert _lmis.is_strict(gain.certificate) and gain.margin > 0
    assert meets(problem, gain_of(gain), opt.gamma_opt * (1 + 1e-3))


@pytest.mark.parametrize("strategy", _gains.STRATEGIES, ids=lambda s: s.__name__)
def test_each_centring_strategy_reports_why_it_failed(discrete, strategy):
    problem, opt = discrete
    attempt = strategy(problem, opt, 1e-13)       # far below the accuracy of gamma_opt: no strict point
    assert attempt.gain is None and isinstance(attempt.failure, (ConvergenceError, InfeasibleError))
    assert "increase backoff" in str(attempt.failure)
    below = strategy(problem, opt, -1e-3)         # below the optimum: infeasible
    assert below.gain is None and isinstance(below.failure, (ConvergenceError, InfeasibleError))


def test_recentred_strategy_needs_a_usable_optimum(discrete):
    problem, opt = discrete
    broken = dataclasses.replace(opt, point=_lmis.Point(X=-np.eye(4), Y=opt.point.Y))
    attempt = _gains.conditioned_recentred(problem, broken, 1e-3)
    assert attempt.gain is None and attempt.failure is None and attempt.solves == ()


def test_gain_strategies_are_tried_in_order_with_rising_backoff(discrete, monkeypatch):
    problem, opt = discrete
    calls = []

    def fake(name, succeed_at=None):
        def strategy(problem, opt, backoff):
            calls.append((name, backoff))
            if (name, backoff) == succeed_at:
                return _gains.Attempt(_gains.Gain(opt.point, opt.data, {}, 1.0, name), ({"name": name},))
            return _gains.Attempt(solves=({"name": name},), failure=ConvergenceError(f"{name} at {backoff:g}"))
        strategy.__name__ = name
        return strategy

    b = problem.backoff
    monkeypatch.setattr(_gains, "optimum_certified", lambda *a: calls.append(("certified", a[2])) or _gains.Attempt())
    monkeypatch.setattr(_gains, "STRATEGIES", (fake("a"), fake("b", ("b", 10 * b)), fake("c")))
    gain, backoff, solves = _gains.gain_near_optimum(problem, opt)
    assert calls == [("certified", b), ("a", b), ("b", b), ("c", b), ("a", 10 * b), ("b", 10 * b)]
    assert gain.route == "b" and backoff == 10 * b and [s["name"] for s in solves] == ["a", "b", "c", "a", "b"]

    calls.clear()
    monkeypatch.setattr(_gains, "STRATEGIES", (fake("a"), fake("b")))
    with pytest.raises(ConvergenceError, match=r"b at 0\.1"):   # the last failure, at 100 x backoff
        _gains.gain_near_optimum(problem, opt)
    assert len(calls) == 1 + 2 * len(tol.BACKOFF_STEPS)


def test_raised_backoff_end_to_end(monkeypatch):
    """Centring fails at the requested backoff only: the gain comes from 10 x backoff, and meets that level."""
    plant, Bw, Cz, Dzu, _ = random_case(3, 4, 2, 2, discrete=False)
    real = _gains._centring

    def first_step_fails(problem, data, opt, backoff, variant):
        if backoff == 1e-3:
            return _gains.Attempt(failure=ConvergenceError("injected"))
        return real(problem, data, opt, backoff, variant)

    monkeypatch.setattr(_gains, "_centring", first_step_fails)
    ctrl = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    assert ctrl.info["backoff"] == pytest.approx(1e-2) and ctrl.gamma == pytest.approx(1.01 * ctrl.gamma_opt)
    assert cl_norm(plant, ctrl.K, Bw, Cz, Dzu) <= ctrl.gamma


def test_tiny_backoff_escalates_or_says_increase_backoff():
    """Near the solver's accuracy: either a gain at a raised backoff that meets its level, or a clear error."""
    plant, Bw, Cz, Dzu, _ = random_case(1, 4, 2, 2, discrete=True)
    for backoff in (1e-11, 1e-9):
        try:
            ctrl = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, backoff=backoff)
        except (ConvergenceError, InfeasibleError) as exc:
            assert "increase backoff" in str(exc)  # noqa: PT017 - either outcome is valid
            continue
        assert ctrl.info["backoff"] >= backoff
        assert ctrl.gamma == pytest.approx(ctrl.gamma_opt * (1 + ctrl.info["backoff"]), rel=1e-12)
        assert cl_norm(plant, ctrl.K, Bw, Cz, Dzu) <= ctrl.gamma * (1 + 1e-9)


def test_fixed_level_just_below_the_optimum_is_infeasible_with_the_margin(discrete):
    problem, opt = discrete
    data = balanced_of(problem)
    for factor in (1 - 1e-9, 1 - 1e-3):
        with pytest.raises(InfeasibleError, match=r"no gain achieves gamma=\d"):
            _gains.gain_at_level(problem, data, factor * opt.gamma_opt)
    gain, solves = _gains.gain_at_level(problem, data, 1.01 * opt.gamma_opt)
    assert gain.margin > tol.STRICT and len(solves) == 1
    assert meets(problem, gain_of(gain), 1.01 * opt.gamma_opt)


def test_at_optimum_floors_only_the_unresolvable_eigenvalues(discrete):
    problem, opt = discrete
    gain = _gains.at_optimum(problem, opt)
    assert np.allclose(gain.point.X, opt.point.X, rtol=1e-12, atol=0)   # well conditioned: unchanged
    lam, U = np.linalg.eigh(opt.point.X)
    singular = dataclasses.replace(opt, point=_lmis.Point(X=(U * np.r_[-1e-11, lam[1:]]) @ U.T, Y=opt.point.Y))
    floored = np.linalg.eigvalsh(_gains.at_optimum(problem, singular).point.X)
    assert floored[0] == pytest.approx(tol.OPTIMUM_X_FLOOR * lam[-1], rel=1e-6)
    assert np.allclose(floored[1:], lam[1:], rtol=1e-9)


# ------------------------------------------------------------ internal checks
def test_closed_loop_check_names_the_vertex():
    with pytest.raises(ConvergenceError, match="not finite"):
        _synthesis.check_closed_loop(np.array([[np.inf, 0.0]]), [msd(1.0)])
    # strong velocity feedback: stable for mass 1 (|pole| 0.997), Euler-unstable for mass 0.5 (2.93)
    K = np.array([[0.0, -39.0]])
    assert np.max(np.abs(np.linalg.eigvals(msd(1.0).F + msd(1.0).G @ K))) < 1
    with pytest.raises(ConvergenceError, match=r"does not stabilise vertices\[0\]"):
        _synthesis.check_closed_loop(K, [msd(1.0), msd(0.5)])
    with pytest.raises(ConvergenceError, match="does not stabilise plant"):
        _synthesis.check_closed_loop(np.zeros((1, 1)), [Plant([[1.5]], [[1.0]], 1.0)])


def test_input_bound_check_catches_solver_inaccuracy(monkeypatch):
    plant = Plant([[1.1, .2], [0, .9]], [[0], [1]], .1)
    monkeypatch.setattr(_synthesis, "guaranteed_input_bound", lambda gain: np.array([2.0]))
    with pytest.raises(ConvergenceError, match=r"guaranteed input bound \[2\.0\] exceeds u_max"):
        hinf(plant, Bw=[[0], [1]], Cz=[[1, 0], [0, 1], [0, 0]], Dzu=[[0], [0], [1]], u_max=1.5)


# ------------------------------------------------------------ validation details
def test_problem_statement_and_its_errors():
    plant = msd(1.0)
    problem = problem_of(plant, Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU, vertices=[msd(4.0)], u_max=2.0)
    assert problem.polytopic and problem.discrete and problem.w_energy == 1.0
    assert "common Lyapunov matrix" in problem.infeasibility() and "try extended=True" in problem.infeasibility()
    assert "u_max = [2.0]" in problem.infeasibility()
    with pytest.raises(TypeError, match="extended must be a bool"):
        problem_of(plant, Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU, extended="yes")
    with pytest.raises(TypeError, match="u_max must be a positive number"):
        problem_of(plant, Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU, u_max="1")
    with pytest.raises(TypeError, match="u_max must be a positive number"):
        problem_of(plant, Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU, u_max=[object()])


def test_bad_balancing_from_slycot_is_ignored(monkeypatch):
    import types

    fake = types.SimpleNamespace(tb01id=lambda n, *a, **k: (None, None, None, None, np.zeros(n)))
    monkeypatch.setitem(sys.modules, "slycot", fake)
    plant, Bw, Cz, _, _ = random_case(0, 3, 1, 1, discrete=True)
    assert np.array_equal(_coordinates._balance(plant.F, Bw, plant.G, Cz), np.ones(3))


def test_optimum_certified_skips_a_non_finite_riccati_solution(discrete, monkeypatch):
    problem, opt = discrete
    monkeypatch.setattr(scipy.linalg, "solve_discrete_are", lambda *a, **k: np.full((4, 4), np.nan))
    attempt = _gains.optimum_certified(problem, opt, 1e-3)
    assert attempt.gain is None and attempt.failure is None


def test_closed_loop_check_of_the_pole_regions():
    from robustctl import Disk

    K = np.array([[0.0, -39.0]])                      # |pole| 0.997 for mass 1: stable, far outside Disk(0, 0.5)
    with pytest.raises(ConvergenceError, match=r"a closed-loop pole of plant lies outside Disk\(center=0.0"):
        _synthesis.check_closed_loop(K, [msd(1.0)], (Disk(0.0, 0.5),))
    _synthesis.check_closed_loop(K, [msd(1.0)], (Disk(0.0, 1.0),))


# ------------------------------------------------------------ projected blocks (Y eliminated)
def _projected_optimum(problem):
    """The level minimisation over the projected blocks in the LQR coordinates (what ``minimise_level`` runs)."""
    lqr = _coordinates.lqr_coordinates(balanced_of(problem), problem.discrete)
    assert _level.projected_form(problem, lqr.n)
    return lqr, _level.solve_level(problem, lqr, preconditioned=True)


def test_projected_blocks_hold_at_every_point_of_the_full_block(discrete):
    """Necessity (projection lemma): a strictly feasible ``(X, K X)`` of the full block makes both projections
    positive at the same ``X`` and level."""
    from robustctl import _cvx

    problem, opt = discrete
    gain = _gains.optimum_certified(problem, opt, 1e-3).gain
    z_scale = 1.0 / (gain.data.level_scale * opt.gamma_opt * (1 + 1e-3))
    cert = _cvx.certificate(_lmis.projected_blocks(gain.data, gain.point.X, 1.0, z_scale))
    assert set(cert) == {"hinf_projected[0]", "hinf_phi[0]"} and min(cert.values()) > 0


@pytest.mark.parametrize("seed,n,m,q,cross", [(1, 4, 2, 2, False), (2, 6, 2, 3, False), (4, 5, 2, 2, True)])
def test_projected_level_and_gain_match_the_riccati_bisection_and_linfnorm(seed, n, m, q, cross):
    """The projected optimum is the Riccati bisection's level, and the recovered gain reaches it (linfnorm)."""
    plant, Bw, Cz, Dzu, Dzw = random_case(seed, n, m, q, discrete=True, cross=cross)
    problem = problem_of(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw)
    lqr, found = _projected_optimum(problem)
    assert set(found.report.certificate) == {"hinf_projected[0]", "hinf_phi[0]"}
    gamma_opt = np.sqrt(found.level_sq) / lqr.level_scale
    ref = hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw, rtol=1e-9)
    assert gamma_opt == pytest.approx(ref.gamma, rel=RTOL)
    K = lqr.to_original(found.point.gain(), found.point.X)[0]
    assert cl_norm(plant, K, Bw, Cz, Dzu, Dzw) <= gamma_opt * (1 + RTOL)


def test_projected_gain_of_a_singular_phi_is_the_limit_of_the_least_squares_gains(discrete):
    """``X - Bw Bw'`` singular: the floored weight gives the gain that the vanishing regularisation converges to."""
    _, opt = discrete
    data, X = opt.data, opt.point.X
    Bw = data.Bw
    lam, U = np.linalg.eigh(X - Bw @ Bw.T)
    Xs = Bw @ Bw.T + (U * np.r_[0.0, lam[1:]]) @ U.T            # Phi singular along U[:, 0]
    level_sq = (data.level_scale * opt.gamma_opt) ** 2 * 1.1
    K = _lmis.projected_gain(data, Xs, level_sq)
    Abar, Bbar = np.vstack([data.F[0], data.Cz]), np.vstack([data.G[0], data.Dzu])
    v = np.r_[U[:, 0], np.zeros(data.p)]
    assert abs(v @ (Abar + Bbar @ K)).max() < 1e-4 * np.abs(Abar).max()   # the singular direction is respected
    def weighted(eps):
        W = np.linalg.inv(_lmis._phi(np.vstack([Bw, data.Dzw]), Xs, level_sq) + eps * np.eye(data.n + data.p))
        return -np.linalg.solve(Bbar.T @ W @ Bbar, Bbar.T @ W @ Abar)
    assert np.allclose(K, weighted(1e-9), rtol=0, atol=1e-5 * np.abs(K).max())
    assert _lmis.projected_gain(data, np.full_like(X, np.nan), level_sq) is None
    assert _lmis.projected_gain(data, -np.eye(data.n) - Bw @ Bw.T, -1.0) is None


@pytest.mark.parametrize("failure", ["solver", "gain"])
def test_projected_failure_leaves_the_level_to_the_full_block(discrete, monkeypatch, failure):
    problem, _ = discrete
    if failure == "solver":
        real = _level._cvx.solve_sdp

        def projected_fails(objective, lmis, *a, **k):
            if lmis[0].name == "hinf_projected[0]":
                raise ConvergenceError("injected")
            return real(objective, lmis, *a, **k)

        monkeypatch.setattr(_level._cvx, "solve_sdp", projected_fails)
    else:
        monkeypatch.setattr(_level, "projected_gain", lambda *a: None)
    opt = optimum_of(problem)
    assert list(opt.report.certificate) == ["hinf[0]"] and opt.preconditioned
    plant = problem.plants[0]
    assert opt.gamma_opt == pytest.approx(hinf_riccati(plant, Bw=problem.Bw, Cz=problem.Cz, Dzu=problem.Dzu).gamma,
                                          rel=RTOL)


def test_projected_form_is_the_plain_discrete_problem_with_a_backoff_only(discrete, polytope):
    problem, _ = discrete
    n = problem.plants[0].n
    assert _level.projected_form(problem, n)
    assert not _level.projected_form(problem, tol.PROJECTED_MAX_N + 1)
    assert not _level.projected_form(dataclasses.replace(problem, backoff=0.0), n)
    assert not _level.projected_form(dataclasses.replace(problem, u_max=np.ones(2), w_energy=1.0), n)
    assert not _level.projected_form(polytope[0], 2)
    cont, Bw, Cz, Dzu, _ = random_case(3, 4, 2, 2, discrete=False)
    assert not _level.projected_form(problem_of(cont, Bw=Bw, Cz=Cz, Dzu=Dzu), n)
    # end to end: the full block where the projected form does not apply, with the same level
    full = hinf(problem.plants[0], Bw=problem.Bw, Cz=problem.Cz, Dzu=problem.Dzu, backoff=0.0)
    projected = hinf(problem.plants[0], Bw=problem.Bw, Cz=problem.Cz, Dzu=problem.Dzu)
    assert list(full.info["solves"][0]["certificate"]) == ["hinf[0]"]
    assert list(projected.info["solves"][0]["certificate"]) == ["hinf_projected[0]", "hinf_phi[0]"]
    assert projected.gamma_opt == pytest.approx(full.gamma_opt, rel=1e-6)


def test_projected_gain_is_the_full_blocks_optimal_gain_on_the_truck(monkeypatch):
    """The paper's nominal H-infinity design (authors' weights, rank-1 Bw): both forms give the gain that reaches
    gamma_opt (linfnorm), and the same gain."""
    from robustctl import lq_output
    from robustctl.models.truck import truck_plant

    plant, Bw = truck_plant(0.0), np.ones((4, 1))
    Cz, Dzu = lq_output(np.diag([1.0, 1.0, 25000.0, 100.0]), 33535.0)
    projected = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    monkeypatch.setattr(tol, "PROJECTED_MAX_N", 0)
    full = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    assert list(projected.info["solves"][0]["certificate"]) == ["hinf_projected[0]", "hinf_phi[0]"]
    assert list(full.info["solves"][0]["certificate"]) == ["hinf[0]"]
    for ctrl in (projected, full):
        assert cl_norm(plant, ctrl.K, Bw, Cz, Dzu) <= ctrl.gamma_opt * (1 + 1e-5)
    assert np.allclose(projected.K, full.K, rtol=1e-4)
