"""The cvxpy solve wrapper robustctl._cvx: status handling, symmetrisation, certificate."""

from __future__ import annotations

import pathlib
import re

import cvxpy as cp
import numpy as np
import pytest

from robustctl import _cvx
from robustctl import errors as rc_errors
from robustctl.errors import InfeasibleError


def test_margin_and_certificate_are_reported():
    X = cp.Variable((3, 3), symmetric=True)
    C = np.diag([1.0, 2.0, 3.0])
    rep = _cvx.solve_sdp(cp.Minimize(cp.trace(X)), [_cvx.LMI("X-C", X - C, 0.5)])
    assert rep.status == "optimal"
    # minimum of trace X subject to X >= C + 0.5 I is trace(C) + 1.5, at X = C + 0.5 I
    assert rep.value == pytest.approx(7.5, rel=1e-8)
    assert np.allclose(X.value, C + 0.5 * np.eye(3), atol=1e-7)
    assert rep.certificate["X-C"] == pytest.approx(np.linalg.eigvalsh(X.value - C).min(), abs=1e-9)
    assert rep.certificate["X-C"] == pytest.approx(0.5, abs=1e-7)
    assert rep.iterations > 0 and rep.solve_time >= 0


def test_fast_attempt_agrees_with_the_refined_solve():
    """fast=True (no iterative refinement first) gives the same optimum as the default path."""
    rng = np.random.default_rng(3)
    A = rng.normal(size=(6, 6))
    A *= 0.9 / np.max(np.abs(np.linalg.eigvals(A)))
    values = []
    for fast in (False, True):
        X, t = cp.Variable((6, 6), symmetric=True), cp.Variable()
        # smallest t with A X A' - X + I <= 0 and X <= t I: t = lambda_max of the Lyapunov solution
        lmis = [_cvx.LMI("lyap", X - A @ X @ A.T - np.eye(6)), _cvx.LMI("upper", t * np.eye(6) - X)]
        rep = _cvx.solve_sdp(cp.Minimize(t), lmis, tol=1e-9, fast=fast)
        values.append(rep.value)
    import scipy.linalg

    exact = np.linalg.eigvalsh(scipy.linalg.solve_discrete_lyapunov(A, np.eye(6))).max()
    assert values[0] == pytest.approx(exact, rel=1e-7)
    assert values[1] == pytest.approx(exact, rel=1e-7)


@pytest.fixture
def solve_settings(monkeypatch):
    """The keyword arguments of every ``cvxpy.Problem.solve`` call of the test, in order (the solve still runs)."""
    seen: list[dict] = []
    real = cp.Problem.solve

    def spy(self, *args, **kwargs):
        seen.append(kwargs)
        return real(self, *args, **kwargs)

    monkeypatch.setattr(cp.Problem, "solve", spy)
    return seen


@pytest.mark.parametrize("decompose", [True, False])
def test_whole_block_factorisation_gives_the_same_optimum(solve_settings, decompose):
    """decompose=False (no chordal decomposition in Clarabel) reaches the solver and the exact optimum.

    ``[[X - I, A X, 0], [X A', X, 0], [0, 0, t - 1]] >= 0`` (cliques ``2 n`` and 1) and ``X <= t I``: the
    Schur complement is ``X - I - A X A' >= 0``, so the smallest ``t`` is ``lambda_max`` of the
    solution of ``X = A X A' + I`` (it exceeds 1).
    """
    import scipy.linalg

    rng = np.random.default_rng(4)
    A = rng.normal(size=(5, 5))
    A *= 0.9 / np.max(np.abs(np.linalg.eigvals(A)))
    X, t = cp.Variable((5, 5), symmetric=True), cp.Variable()
    Z = np.zeros((5, 1))
    block = cp.bmat([[X - np.eye(5), A @ X, Z], [X @ A.T, X, Z], [Z.T, Z.T, cp.reshape(t - 1.0, (1, 1), order="F")]])
    rep = _cvx.solve_sdp(cp.Minimize(t), [_cvx.LMI("schur", block), _cvx.LMI("upper", t * np.eye(5) - X)],
                         tol=1e-9, decompose=decompose)
    exact = np.linalg.eigvalsh(scipy.linalg.solve_discrete_lyapunov(A, np.eye(5))).max()
    assert exact > 1.0 and rep.value == pytest.approx(exact, rel=1e-7)
    assert solve_settings and {k["chordal_decomposition_enable"] for k in solve_settings} == {decompose}


@pytest.mark.parametrize("threshold,threads", [(_cvx.SINGLE_THREAD_PSD, 1), (20, 0)])
def test_small_problems_run_clarabel_on_one_thread(monkeypatch, solve_settings, threshold, threads):
    """Blocks of 6 + 15 = 21 free entries: one thread up to the threshold, Clarabel's default above; same optimum."""
    monkeypatch.setattr(_cvx, "SINGLE_THREAD_PSD", threshold)
    X, t = cp.Variable((5, 5), symmetric=True), cp.Variable()
    lmis = [_cvx.LMI("X-I", X - np.eye(5)), _cvx.LMI("upper", cp.bmat([[t * np.eye(2), np.ones((2, 1))],
                                                                         [np.ones((1, 2)), np.ones((1, 1))]]))]
    rep = _cvx.solve_sdp(cp.Minimize(cp.trace(X) + t), lmis)
    assert solve_settings and {k["max_threads"] for k in solve_settings} == {threads}
    assert rep.value == pytest.approx(5.0 + 2.0, rel=1e-7)   # X = I; [[t I, 1], [1', 1]] >= 0 iff t >= 2


def test_infeasible_lmi_raises_with_the_callers_message():
    X = cp.Variable((2, 2), symmetric=True)
    with pytest.raises(InfeasibleError, match="no X for the test"):
        _cvx.solve_sdp(cp.Minimize(0), [_cvx.LMI("pos", X, 1.0), _cvx.LMI("neg", -X, 1.0)],
                       infeasible_msg="no X for the test")


def test_non_symmetric_block_is_caught():
    x = cp.Variable()
    M = cp.bmat([[x, 1.0], [0.0, x]])   # only its symmetric part would be constrained
    with pytest.raises(ValueError, match="not symmetric"):
        _cvx.solve_sdp(cp.Minimize(x), [_cvx.LMI("M", M, 0.0)])


def test_unknown_solver_is_named():
    with pytest.raises(ValueError, match="solver must be an installed SDP solver"):
        _cvx.check_solver("GUROBI_DOES_NOT_EXIST")
    with pytest.raises(TypeError, match="solver"):
        _cvx.check_solver(3)


def test_only_the_wrapper_calls_solve():
    root = pathlib.Path(_cvx.__file__).parent
    pattern = re.compile(r"\.solve\(\s*(solver|verbose|\*\*|\))")
    offenders = [str(p.relative_to(root)) for p in root.rglob("*.py")
                 if p.name != "_cvx.py" and pattern.search(p.read_text())]
    assert offenders == []


def test_certificate_of_constant_blocks():
    """The same evaluation as after a solve, for a candidate point given as arrays."""
    M = np.array([[2.0, 1.0], [1.0, 2.0]])
    cert = _cvx.certificate([_cvx.LMI("M", M), _cvx.LMI("expr", cp.Constant(M) - 3.0 * np.eye(2))])
    assert cert == pytest.approx({"M": 1.0, "expr": -2.0}, abs=1e-12)
    with pytest.raises(rc_errors.ConvergenceError, match="non-finite values in LMI 'bad'"):
        _cvx.certificate([_cvx.LMI("bad", np.array([[np.nan]]))])
    with pytest.raises(ValueError, match="'skew' is not symmetric"):
        _cvx.certificate([_cvx.LMI("skew", np.array([[1.0, 1.0], [0.0, 1.0]]))])


def test_other_solvers_run_with_their_defaults():
    X = cp.Variable((2, 2), symmetric=True)
    rep = _cvx.solve_sdp(cp.Minimize(cp.trace(X)), [_cvx.LMI("X-I", X - np.eye(2))], solver="SCS")
    assert rep.solver == "SCS" and rep.value == pytest.approx(2.0, rel=1e-3)


def test_a_solver_crash_is_a_convergence_error(monkeypatch):
    class PanicException(BaseException):  # what pyo3 raises for a Rust panic inside Clarabel
        pass

    def crash(self, *args, **kwargs):
        raise PanicException("index out of bounds")

    monkeypatch.setattr(cp.Problem, "solve", crash)
    X = cp.Variable((2, 2), symmetric=True)
    with pytest.raises(rc_errors.ConvergenceError, match=r"crashed internally.*index out of bounds"):
        _cvx.solve_sdp(cp.Minimize(cp.trace(X)), [_cvx.LMI("X", X)])

    def interrupt(self, *args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(cp.Problem, "solve", interrupt)
    with pytest.raises(KeyboardInterrupt):   # anything else is not swallowed
        _cvx.solve_sdp(cp.Minimize(cp.trace(X)), [_cvx.LMI("X", X)])
