"""The compiled RLQR step and plain recursion (robustctl/rlqr/_kernel.py) against the numpy reference.

What is guaranteed, and tested here:

* one step: ``P``, ``K``, ``L`` agree to ``max(1e-13, 1e-15 cond(KKT))``
  (relative) on random data (measured: a few 1e-16 where the KKT matrix is
  well conditioned);
* the recursion on the generic MOP's designs (its search space, ``max_iter``
  50, also ``mu = inf`` only, and diverging ones): the same number of steps,
  the same ``settled`` flags, and ``P`` to 1e-12 relative where ``|P| < 1e6``
  (measured 1.6e-13), 1e-11 beyond (4.6e-12: the error grows with the
  conditioning; numpy with OpenBLAS's SkylakeX kernels differs from numpy
  with its Zen kernels by as much, 2.2e-12);
* elsewhere the counts may differ where the change at the stopping step lies
  within rounding of ``tol``: the two stopping decisions are then those of
  the two trajectories (the changes straddle ``tol`` and differ by no more
  than the trajectories do). On the truck's doubled steering column
  (``|P|`` up to 1e17) that is one design in 200, by one step; on random
  2-input models whose transients round to 1e-9, 1 % of the designs;
* singular systems give NaN for that design only; ``mu = inf`` (``lam_inv = 0``),
  soft and hard batches, ``H = 0``.

Not guaranteed (and not by numpy either): designs whose step has a rounding
error above ``tol`` (random ill-conditioned 2-input models with ``mu ~ 1e10``,
or ``mu = inf`` recursions diverging to ``|P| ~ 1e150``) stop wherever the
rounding lets them; there numpy with SkylakeX kernels disagrees with numpy
with Zen kernels on more verdicts than the kernel does.
"""

from __future__ import annotations

import importlib
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

import numpy as np
import pytest
from conftest import GENERIC_F, GENERIC_G

import robustctl as rc
from robustctl.models.truck import lqr_weights, truck_plant
from robustctl.rlqr._model import build
from robustctl.rlqr._step import kkt_step

steady = importlib.import_module("robustctl.rlqr._steady")   # robustctl.rlqr is also a function's name
kernel = importlib.import_module("robustctl.rlqr._kernel")

TOL = 1e-10


def _numpy_recursion(d, P0, tol, max_iter, diverged):
    """The reference in the kernel's calling convention: ``(P, iterations, active)``."""
    P, iterations, settled = steady.recursion(d, kkt_step, P0, tol, max_iter)
    return P, iterations, ~settled        # settled implies healthy, so ~active & healthy(P) == settled


def _rel(a, b):
    with np.errstate(all="ignore"):
        return np.linalg.norm(a - b, axis=(-2, -1)) / np.linalg.norm(b, axis=(-2, -1))


def _generic(z, mu=None):
    plant = rc.Plant(GENERIC_F, GENERIC_G, 1.0)
    mu = 10 ** np.sqrt(z[:, 4]) if mu is None else mu
    return build(plant, z[:, None, :3], z[:, None, 3:4], mu, Q=None, R=None, H=np.ones((3, 1)), alpha=0.1,
                 batch=True)


def _random(rng, B, n=4, m=2, l=1, mu_range=(-1, 8), H=True):
    plant = rc.Plant(0.6 * rng.standard_normal((n, n)), rng.standard_normal((n, m)), 1.0)
    mu = 10 ** rng.uniform(*mu_range, B)
    mu[::4] = np.inf
    Hm = rng.standard_normal((n, 1)) if H else np.zeros((n, 1))
    return build(plant, rng.standard_normal((B, l, n)), rng.standard_normal((B, l, m)), mu,
                 Q=np.diag(rng.uniform(0.5, 2, n)), R=np.diag(rng.uniform(0.5, 2, m)), H=Hm, alpha=0.1, batch=True)


def _both(d, P0, max_iter):
    with np.errstate(all="ignore"):
        P_ref, it_ref, settled_ref = steady.recursion(d, kkt_step, P0, TOL, max_iter)
    P, it, active = kernel.recursion(d, P0, TOL, max_iter, steady.DIVERGED)
    return (P_ref, it_ref, settled_ref), (P, it, ~active & steady.healthy(P))


# -- one step ------------------------------------------------------------------------------------
CASES = ["generic soft", "generic hard", "random 4x2, l=2", "random 3x4, l=3", "H=0"]


@pytest.mark.parametrize("case", CASES)
def test_step_matches_numpy(case):
    rng = np.random.default_rng(CASES.index(case))
    B = 200
    if case.startswith("generic"):
        d = _generic(rng.uniform(0, 200, (B, 5)), mu=np.inf if case.endswith("hard") else None)
    elif case == "H=0":
        d = _random(rng, B, H=False)
    else:
        n, m, l = {"random 4x2, l=2": (4, 2, 2), "random 3x4, l=3": (3, 4, 3)}[case]
        d = _random(rng, B, n, m, l)
    assert d.soft == (case != "generic hard")
    n = d.F.shape[0]
    X = rng.standard_normal((B, n, n))
    P = X @ X.swapaxes(1, 2) + np.eye(n)
    ref, new = kkt_step(P, d), kernel.kkt_step(P, d)
    bound = np.maximum(1e-13, 1e-15 * _kkt_cond(P, d))     # a backward-stable solve: error ~ eps x condition
    for a, b in zip(new, ref, strict=True):
        assert np.isfinite(b).all()
        assert (_rel(a, b) < bound).all()


def _kkt_cond(P, d):
    """Condition numbers of the step's KKT matrices (the numpy step's, rebuilt)."""
    m, l = d.G.shape[1], d.EF.shape[1]
    Pt = np.linalg.solve(np.eye(d.F.shape[0]) + P @ d.S, P) if d.soft else P
    kkt = np.zeros((P.shape[0], m + l, m + l))
    kkt[:, :m, :m] = d.R + d.G.T @ Pt @ d.G
    kkt[:, :m, m:], kkt[:, m:, :m] = d.EG.swapaxes(1, 2), d.EG
    kkt[:, m:, m:] = -d.lam_inv[:, None, None] * np.eye(l)
    return np.linalg.cond(kkt)


def test_lu_solve_matches_numpy_and_reports_exact_singularity():
    rng = np.random.default_rng(0)
    for k in (1, 2, 3, 5):
        A, b = rng.standard_normal((k, k)), rng.standard_normal((k, 4))
        A_, x = A.copy(), b.copy()
        assert kernel._lu_solve(A_, x)
        np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=1e-12, atol=1e-12)
    A = np.array([[1.0, 2.0], [2.0, 4.0]])                       # exactly singular: zero pivot
    assert not kernel._lu_solve(A.copy(), np.ones((2, 1)))
    with pytest.raises(np.linalg.LinAlgError):
        np.linalg.solve(A, np.ones((2, 1)))


def test_singular_systems_give_nan_for_that_design_only():
    """Design 1: mu = inf with EG = 0 (KKT singular); design 2: P = -I with S = I (I + P S = 0)."""
    rng = np.random.default_rng(1)
    plant = rc.Plant(GENERIC_F, GENERIC_G, 1.0)
    EF, EG = rng.uniform(0, 5, (4, 1, 3)), rng.uniform(0.5, 5, (4, 1, 1))
    EG[1] = 0.0
    d = build(plant, EF, EG, np.array([1e3, np.inf, 1.0, 1e6]), Q=None, R=None, H=np.zeros((3, 1)),
              alpha=0.1, batch=True)                             # H = 0: S = I / mu, EF and EG drop out
    d_hard = build(plant, EF, EG, np.inf, Q=None, R=None, H=np.ones((3, 1)), alpha=0.1, batch=True)
    eye = np.broadcast_to(np.eye(3), (4, 3, 3))
    P = eye.copy()
    P[2] = -np.eye(3)
    with np.errstate(all="ignore"):
        for dd, PP, bad in ((d, P, [2]), (d_hard, eye, [1])):
            ref, new = kkt_step(PP, dd), kernel.kkt_step(PP, dd)
            for a, b in zip(new, ref, strict=True):
                np.testing.assert_array_equal(np.isnan(a).all(axis=(1, 2)), np.isin(np.arange(4), bad))
                good = ~np.isin(np.arange(4), bad)
                assert _rel(a[good], b[good]).max() < 1e-13
            np.testing.assert_array_equal(np.isnan(ref.P).all(axis=(1, 2)), np.isin(np.arange(4), bad))
        ref, new = _both(d_hard, np.eye(3), 50)
        assert new[1][1] == ref[1][1] == 1 and not new[2][1] and not ref[2][1]
        np.testing.assert_array_equal(new[1], ref[1])
        np.testing.assert_array_equal(new[2], ref[2])


# -- the recursion --------------------------------------------------------------------------------
def _check_recursion(d, P0, max_iter):
    (P_ref, it_ref, s_ref), (P, it, s) = _both(d, P0, max_iter)
    np.testing.assert_array_equal(it, it_ref)
    np.testing.assert_array_equal(s, s_ref)
    healthy = steady.healthy(P_ref)
    np.testing.assert_array_equal(steady.healthy(P), healthy)
    size = np.abs(P_ref).max(axis=(1, 2))
    rel = _rel(P, P_ref)
    assert rel[healthy & (size < 1e6)].max(initial=0) < 1e-12
    assert rel[healthy].max(initial=0) < 1e-11
    return it_ref, s_ref, healthy


@pytest.mark.parametrize("seed", [1, 2])
def test_recursion_matches_numpy_on_the_generic_designs(seed):
    """The generic MOP's search space, its max_iter = 50: converged, capped and mu = inf designs."""
    rng = np.random.default_rng(seed)
    z = rng.uniform(0, 200, (2000, 5))
    mu = 10 ** np.sqrt(z[:, 4])
    mu[::5] = np.inf
    it, settled, _ = _check_recursion(_generic(z, mu), np.eye(3), 50)
    assert (it == 50).sum() > 200 and settled.sum() > 1500 and (~settled & (it < 50)).sum() >= 1
    assert np.isinf(mu[settled]).sum() > 100


def test_recursion_matches_numpy_on_hard_and_diverging_batches():
    """All mu = inf (no soft part: Pt = P, L = F + G K), many of them diverging; and no uncertainty (H = 0)."""
    rng = np.random.default_rng(3)
    z = rng.uniform(0, 200, (2000, 5))
    d = _generic(z, mu=np.inf)
    assert not d.soft
    it, settled, healthy = _check_recursion(d, np.eye(3), 200)
    assert (~healthy).sum() > 200 and settled.sum() > 1000 and (it == 200).sum() > 100
    _check_recursion(_random(rng, 500, H=False), np.eye(4), 300)


def _check_stops_within_rounding_of_tol(d, P0, it, it_ref):
    """Where the counts differ, the two stopping decisions are those of the two trajectories: at the
    earlier stop ``k`` the changes ``c`` (numpy) and ``c'`` (kernel) lie on either side of tol, and
    ``|c - tol| <= |c - c'|``, which is bounded by the trajectories' rounding difference
    ``|P_k - P'_k| + |P_{k-1} - P'_{k-1}|`` (relative; the triangle inequality)."""
    differ = np.flatnonzero(it != it_ref)
    if not differ.size:
        return 0
    sub, first = d.select(differ), np.minimum(it, it_ref)[differ]
    X = np.broadcast_to(P0, (differ.size, *P0.shape)).copy()
    Y = X.copy()
    with np.errstate(all="ignore"):
        for k in range(1, first.max() + 1):
            X_new, Y_new = kkt_step(X, sub).P, kernel.kkt_step(Y, sub).P
            at = first == k
            c, c_ = steady.relchange(X_new[at], X[at]), steady.relchange(Y_new[at], Y[at])
            gap = _rel(Y_new[at], X_new[at]) + _rel(Y[at], X[at]) * np.linalg.norm(X[at], axis=(1, 2)) / \
                np.linalg.norm(X_new[at], axis=(1, 2))
            np.testing.assert_array_equal(c < TOL, ~(c_ < TOL))
            assert (np.abs(c - TOL) <= 1.01 * gap + 1e-15).all(), (c / TOL, gap / TOL)
            X, Y = X_new, Y_new
    return differ.size


def test_recursion_matches_numpy_on_random_models():
    """Random 4-state, 2-input models, one uncertainty row, mu up to 1e8 and inf. Some of them round
    much worse than the generic designs (the two trajectories differ by up to 2e-9 relative on the
    way), so a change near tol can fall on either side: the counts agree on 98 % of the designs (the
    others stop within rounding of tol), the flags on all, P to 1e-12 on 90 % and to ~tol on all."""
    rng = np.random.default_rng(4)
    for _ in range(3):
        d = _random(rng, 300)
        P0 = np.diag(rng.uniform(0.5, 2, 4))
        (P_ref, it_ref, s_ref), (P, it, s) = _both(d, P0, 300)
        np.testing.assert_array_equal(s, s_ref)
        assert s_ref.mean() > 0.9 and np.mean(it == it_ref) > 0.98
        _check_stops_within_rounding_of_tol(d, P0, it, it_ref)
        same = s & (it == it_ref)
        rel = _rel(P[same], P_ref[same])
        assert np.mean(rel < 1e-12) > 0.9 and rel.max() < 3 * TOL


def test_recursion_on_the_truck_stops_within_rounding_of_tol():
    """Ill-conditioned designs of the doubled steering column (|P| up to 1e17): the counts differ by
    one step on a few designs, whose change at the earlier stop is within rounding of tol."""
    plant = truck_plant(0.0, doubled=True)
    Q, R = lqr_weights(doubled=True)
    rng = np.random.default_rng(0)
    z = rng.uniform(1e-9, 500, (200, 7))
    z[:, 5] = z[:, 4] * (1 + rng.uniform(-0.002, 0.002, 200))
    d = build(plant, z[:, None, :4], z[:, None, 4:6], 10 ** np.sqrt(z[:, 6]), Q=Q, R=R, H=np.ones((4, 1)),
              alpha=0.1, batch=True)
    (P_ref, it_ref, s_ref), (P, it, s) = _both(d, Q, 2000)
    np.testing.assert_array_equal(s, s_ref)
    assert s.all() and np.abs(P_ref).max() > 1e16
    same = it == it_ref
    assert (np.abs(it - it_ref) <= 1).all()
    assert _check_stops_within_rounding_of_tol(d, Q, it, it_ref) <= 0.05 * it.size
    assert _rel(P[same], P_ref[same]).max() < 1e-10            # |P| 1e17: conditioning, not tol
    assert _rel(P[~same], P_ref[~same]).max(initial=0) < 3 * TOL


# -- steady_state and the MOPs -------------------------------------------------------------------------
def test_steady_state_verdicts_match_the_numpy_path(monkeypatch):
    """rlqr_gains / rlqr(accelerate=False) on generic designs: verdicts, iterations, gains."""
    rng = np.random.default_rng(5)
    z = rng.uniform(0, 200, (1500, 5))
    plant = rc.Plant(GENERIC_F, GENERIC_G, 1.0)
    args = (plant, z[:, None, :3], z[:, None, 3:4], 10 ** np.sqrt(z[:, 4]))
    new = rc.rlqr_gains(*args, max_iter=50)
    plain_new = [rc.rlqr(plant, z[i, None, :3], z[i, None, 3:4], 10 ** np.sqrt(z[i, 4]), accelerate=False)
                 for i in np.flatnonzero(new.ok)[:5]]
    monkeypatch.setattr(kernel, "recursion", _numpy_recursion)
    monkeypatch.setattr(kernel, "kkt_step", kkt_step)
    ref = rc.rlqr_gains(*args, max_iter=50)
    assert (ref.iterations > 10).sum() > 200                      # many designs went through the recursion
    np.testing.assert_array_equal(new.reason, ref.reason)
    np.testing.assert_array_equal(new.iterations, ref.iterations)
    np.testing.assert_array_equal(new.stabilizing, ref.stabilizing)
    ok, small = ref.ok, np.abs(ref.P).max(axis=(1, 2)) < 1e6
    for a, b in ((new.K, ref.K), (new.P, ref.P)):
        assert _rel(a[ok & small], b[ok & small]).max() < 1e-12 and _rel(a[ok], b[ok]).max() < 1e-10
    for c, i in zip(plain_new, np.flatnonzero(new.ok)[:5], strict=True):
        r = rc.rlqr(plant, z[i, None, :3], z[i, None, 3:4], 10 ** np.sqrt(z[i, 4]), accelerate=False)
        assert c.info["iterations"] == r.info["iterations"]
        assert _rel(c.K, r.K) < 1e-12


def test_generic_mop_objectives_match_the_numpy_path(monkeypatch):
    """A realistic population: the final X of a generic NSGA-II run plus random designs, ~20 % of
    which the doubling leaves to the recursion."""
    from moo.problems.generic import GenericRLQRProblem
    from moo.runner import run

    X = np.vstack([run("generic", "nsga2", seed=1, evals=1000).X,
                   np.random.default_rng(6).uniform(0, 200, (400, 5))])
    p = GenericRLQRProblem()
    calls = []
    recursion = kernel.recursion
    monkeypatch.setattr(kernel, "recursion", lambda d, *a: calls.append(d.size) or recursion(d, *a))
    F_new = p.evaluate(X)
    assert sum(calls) > 50
    monkeypatch.setattr(kernel, "recursion", _numpy_recursion)
    monkeypatch.setattr(kernel, "kkt_step", kkt_step)
    F_ref = p.evaluate(X)
    for level in (p.penalty, 2 * p.penalty):                     # unstable somewhere; not computable
        np.testing.assert_array_equal(F_new >= level, F_ref >= level)
    assert (F_ref == 2 * p.penalty).any(axis=1).sum() > 20 and (F_ref < p.penalty).all(axis=1).sum() > 200
    np.testing.assert_allclose(F_new, F_ref, rtol=1e-12, atol=0)


# -- compilation --------------------------------------------------------------------------------------
def _recursion_in_worker():
    """Run the compiled recursion in this (spawned) process; report where the kernel came from."""
    k = importlib.import_module("robustctl.rlqr._kernel")
    z = np.array([[50.0, 20.0, 80.0, 1.0, 150.0], [10.0, 10.0, 10.0, 10.0, 4.0]])
    out = rc.rlqr_gains(rc.Plant(GENERIC_F, GENERIC_G, 1.0), z[:, None, :3], z[:, None, 3:4],
                        [np.inf, 10 ** np.sqrt(z[1, 4])], max_iter=50)
    P, it, _ = k.recursion(_generic(z), np.eye(3), TOL, 50, steady.DIVERGED)
    stats = k._recursion.stats
    return sum(stats.cache_hits.values()), sum(stats.cache_misses.values()), P, it, out.K


def test_spawned_workers_load_the_cached_recursion_kernel():
    here = _recursion_in_worker()                                  # compiled (or loaded) here first
    with ProcessPoolExecutor(max_workers=1, mp_context=get_context("spawn")) as pool:
        hits, misses, *result = pool.submit(_recursion_in_worker).result()
    assert hits >= 1 and misses == 0
    for a, b in zip(result, here[2:], strict=True):
        np.testing.assert_array_equal(a, b)
