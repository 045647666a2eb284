"""moo.problems.selection (the paper's Monte Carlo design selection) and paper_repro/design_selection.py.

References are independent of the code under test: a brute-force counting
loop, a per-design per-Delta numpy recursion written here from the paper's
matrices, direct truck simulations with the Bryson weight written as a
quadratic form, and python-control's dlqr.
"""

import json
import sys

import control
import design_selection
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import moo.problems.selection as selection
import robustctl as rc
from moo.problems.applied import AppliedRLQRProblem
from moo.problems.generic import GenericRLQRProblem
from moo.problems.selection import (
    BRYSON_SCALES,
    applied_errors,
    build_designs,
    draw_deltas,
    error_scales,
    generic_errors,
    monte_carlo_selection,
    overload_from_delta,
    select_design,
)
from robustctl.models import morais2022, truck
from robustctl.models.path import default_route
from robustctl.models.pathfollow import simulate

# the generic plant of the paper's Section 4.4, typed in again (not imported from the problem)
F_G = np.array([[0.9, 0.8, 0.7], [0.01, 0.1, 0.3], [0.0, 0.25, 0.1]])
G_G = np.array([[0.6], [0.1], [0.25]])
H_G = np.ones((3, 1))
EF_G = np.array([[0.1, 0.2, 0.2]])
EG_G = np.array([[0.1]])


@pytest.fixture(scope="module")
def generic():
    return GenericRLQRProblem(horizon=40)


@pytest.fixture(scope="module")
def applied():
    return AppliedRLQRProblem(path=default_route(duration=12.0))


# ---------------------------------------------------------------------------
# the counting rule
# ---------------------------------------------------------------------------

def test_hand_made_winners_ties_and_counts():
    E = np.array([[1.0, 5.0, 2.0, 3.0, 7.0],
                  [2.0, 1.0, 2.0, 4.0, 7.0],
                  [3.0, 3.0, 1.0, 3.0, 7.0]])
    res = monte_carlo_selection(E)
    # column 3 ties designs 0 and 2 -> 0; column 4 ties all three -> 0
    np.testing.assert_array_equal(res.winners, [0, 1, 2, 0, 0])
    np.testing.assert_array_equal(res.counts, [3, 1, 1])
    assert res.best == 0 and res.counts.sum() == res.n_simulations == 5
    assert res.n_designs == 3 and res.n_no_winner == 0
    np.testing.assert_array_equal(res.ranking(), [0, 1, 2])


def test_equal_counts_select_the_lowest_index():
    res = monte_carlo_selection([[2.0, 0.0, 1.0, 9.0], [1.0, 5.0, 0.0, 9.0], [0.0, 5.0, 5.0, 0.0]])
    np.testing.assert_array_equal(res.counts, [1, 1, 2])
    assert res.best == 2
    res = monte_carlo_selection([[0.0, 1.0], [1.0, 0.0]])
    np.testing.assert_array_equal(res.counts, [1, 1])
    assert res.best == 0
    np.testing.assert_array_equal(res.ranking(), [0, 1])


def test_infinite_errors_never_win_and_all_infinite_columns_have_no_winner():
    inf = np.inf
    res = monte_carlo_selection([[inf, 3.0, inf], [inf, inf, 2.0], [inf, 4.0, 9.0]])
    np.testing.assert_array_equal(res.winners, [-1, 0, 1])
    np.testing.assert_array_equal(res.counts, [1, 1, 0])
    assert res.n_no_winner == 1 and res.counts.sum() == 2
    with pytest.raises(ValueError, match="errors: no design"):
        monte_carlo_selection(np.full((2, 3), inf))


@settings(max_examples=60, deadline=None)
@given(arrays(np.int64, st.tuples(st.integers(1, 6), st.integers(1, 12)), elements=st.integers(0, 3)))
def test_counting_matches_a_brute_force_loop(E):
    """Small integer errors produce many ties; compare with a plain Python loop."""
    D, S = E.shape
    winners = []
    for s in range(S):
        best = 0
        for d in range(1, D):
            if E[d, s] < E[best, s]:
                best = d
        winners.append(best)
    counts = [winners.count(d) for d in range(D)]
    best = max(range(D), key=lambda d: (counts[d], -d))
    res = monte_carlo_selection(E)
    assert res.winners.tolist() == winners
    assert res.counts.tolist() == counts
    assert res.best == best
    assert res.counts.sum() == S


@pytest.mark.parametrize("bad, exc, match", [
    ("abc", TypeError, "errors"),
    (None, TypeError, "errors"),
    ([1.0, 2.0], ValueError, r"errors must be a non-empty 2-D array .* shape \(2,\)"),
    (np.zeros((0, 3)), ValueError, "errors"),
    ([[1.0, np.nan]], ValueError, "errors must not contain NaN"),
    ([[1.0, -np.inf]], ValueError, "errors must not contain NaN or -inf"),
    ([["a", "b"]], TypeError, "errors"),
])
def test_selection_rejects_bad_errors(bad, exc, match):
    with pytest.raises(exc, match=match):
        monte_carlo_selection(bad)


# ---------------------------------------------------------------------------
# scenarios
# ---------------------------------------------------------------------------

def test_draw_deltas_is_seeded_uniform_on_minus_one_one():
    a = draw_deltas(2000, 7)
    np.testing.assert_array_equal(a, draw_deltas(2000, 7))
    np.testing.assert_array_equal(a, np.random.default_rng(7).uniform(-1, 1, 2000))
    assert a.min() >= -1 and a.max() <= 1 and abs(a.mean()) < 0.05
    assert not np.array_equal(a, draw_deltas(2000, 8))


def test_overload_mapping_covers_the_papers_range():
    np.testing.assert_allclose(overload_from_delta([-1.0, -0.5, 0.0, 1.0]), [0.0, 75.0, 150.0, 300.0])
    with pytest.raises(ValueError, match="deltas must lie in"):
        overload_from_delta([1.5])


# ---------------------------------------------------------------------------
# generic sampler
# ---------------------------------------------------------------------------

def _reference_generic(K, delta, N):
    """Sum over states and unit initial states of sum_{k=0}^{N} x_j[k]^2, by a plain recursion."""
    Fd = F_G + H_G * delta @ EF_G
    Gd = G_G + H_G * delta @ EG_G
    if np.max(np.abs(np.linalg.eigvals(Fd + Gd @ K))) >= 1:
        return np.inf
    total = 0.0
    for i in range(3):
        x = np.eye(3)[:, i]
        for _ in range(N + 1):
            total += float(x @ x)
            x = Fd @ x + Gd @ (K @ x)
    return total


def test_generic_errors_match_an_independent_loop(generic):
    K_lqr = -control.dlqr(F_G, G_G, np.eye(3), np.eye(1))[0]
    K_star = generic.gains(generic.paper_optimum).K[0]
    # 0.4 K_lqr is stable for delta <= 0.5 and unstable at delta = 1 (spectral radius 1.015)
    K = np.stack([K_lqr, K_star, 0.4 * K_lqr, 2.5 * K_lqr])
    deltas = np.array([-1.0, -0.3, 0.2, 0.5, 1.0])
    E = generic_errors(K, deltas, problem=generic)
    assert E.shape == (4, 5)
    ref = np.array([[_reference_generic(k, d, generic.horizon) for d in deltas] for k in K])
    assert np.isinf(ref[2, -1]) and np.isinf(E[2, -1])
    np.testing.assert_allclose(E, ref, rtol=1e-12)
    # a NaN gain (failed design) cannot win
    E2 = generic_errors(np.concatenate([K[:1], np.full((1, 1, 3), np.nan)]), deltas, problem=generic)
    assert np.all(np.isinf(E2[1])) and np.allclose(E2[0], ref[0], rtol=1e-12)


# ---------------------------------------------------------------------------
# applied sampler
# ---------------------------------------------------------------------------

def test_applied_errors_match_direct_simulations(applied, monkeypatch):
    Q, R = truck.lqr_weights(doubled=True)
    K_lqr2 = -control.dlqr(applied.plant.F, applied.plant.G, Q, R)[0]
    K_mop = applied.gains(np.array(morais2022.RLQR_MOP_Z)).K[0]
    K = np.stack([K_lqr2, K_mop, 0.3 * K_lqr2])
    deltas = np.array([-1.0, 0.0, 0.6])                        # 0, 150, 240 % overload
    path = applied.path
    E = applied_errors(K, deltas, path=path)
    Qx = truck.lqr_weights()[0]                                # Bryson: diag(1 / MAX_ERRORS^2), model order
    ref = np.empty((3, 3))
    for d in range(3):
        for s, ov in enumerate([0.0, 150.0, 240.0]):
            e = simulate(K[d], path, ov, input_map=truck.DOUBLED_INPUT_MAP).errors[0, 0]   # (T, 4): x - x_ref
            ref[d, s] = np.einsum("ti,ij,tj->", e, Qx, e)
    np.testing.assert_allclose(E, ref, rtol=1e-9)
    # scenario chunks do not change the numbers
    monkeypatch.setattr(selection, "_SCENARIO_CHUNK", 2)
    np.testing.assert_allclose(applied_errors(K, deltas, path=path), E, rtol=1e-12)


def test_applied_errors_scales_and_plain_truck_gains(applied):
    K1 = -control.dlqr(truck.truck_plant().F, truck.truck_plant().G, *truck.lqr_weights())[0]
    K2 = np.concatenate([K1, K1]) / 2                           # same steering on the doubled column
    deltas = [-0.2, 0.9]
    E1 = applied_errors(K1[None], deltas, path=applied.path)
    np.testing.assert_allclose(E1, applied_errors(K2[None], deltas, path=applied.path), rtol=1e-12)
    sigma = np.array([1.0, 2.0, 3.0, 4.0])
    res = simulate(K1, applied.path, [overload_from_delta([-0.2])[0], overload_from_delta([0.9])[0]])
    ref = (res.mse() * res.T / sigma**2).sum(axis=2)
    np.testing.assert_allclose(applied_errors(K1[None], deltas, path=applied.path, scales=sigma), ref,
                               rtol=1e-12)
    assert BRYSON_SCALES == (0.25, 0.1, 0.5, 0.05)
    np.testing.assert_array_equal(error_scales("ours"), BRYSON_SCALES)


def test_applied_errors_in_the_authors_setup(applied):
    """The authors' loop and 1 / sqrt(Q_ii) of their Q as scales: E = sum_k e' Q e, from a direct run."""
    Q, R = morais2022.authors_weights()
    K = -control.dlqr(truck.truck_plant().F, truck.truck_plant().G, Q, R)[0]
    deltas = [-1.0, 0.3]
    E = applied_errors(K[None], deltas, path=applied.path, setup="authors")
    res = simulate(K, applied.path, list(overload_from_delta(deltas)), setup=morais2022.SETUPS["authors"])
    ref = np.einsum("stj,jk,stk->s", res.errors[0], Q, res.errors[0])
    np.testing.assert_allclose(E[0], ref, rtol=1e-10)
    np.testing.assert_allclose(error_scales("authors"), [1 / np.sqrt(25000.0), 1.0, 1.0, 0.1])
    assert not np.allclose(E, applied_errors(K[None], deltas, path=applied.path))


def test_select_design_uses_the_problems_setup():
    prob = AppliedRLQRProblem(setup="authors", path=default_route(duration=15.0))
    X = np.array([morais2022.RLQR_MOP_Z, [10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 100.0]])
    sel = select_design(prob, X, n_sims=5, seed=2)
    np.testing.assert_allclose(sel.errors, applied_errors(sel.designs.K, sel.deltas, path=prob.path,
                                                          setup="authors"), rtol=1e-12)
    Q, R = morais2022.authors_weights(doubled=True)
    np.testing.assert_allclose(sel.designs.K[sel.designs.index("nominal")], rc.lqr(prob.plant, Q=Q, R=R).K)


# ---------------------------------------------------------------------------
# design set
# ---------------------------------------------------------------------------

def test_generic_design_set(generic):
    X = np.array([generic.paper_optimum, [10.0, 20.0, 30.0, 40.0, 50.0], [1.0, 1.0, 1.0, 1.0, 4.0]])
    ds = build_designs(generic, X, seed=3)
    assert len(ds) == 5 and ds.n_front == 3
    assert ds.labels == ("1", "2", "3", "nominal", "random")
    assert ds.kinds == ("front",) * 3 + ("nominal", "random")
    np.testing.assert_array_equal(ds.z[:3], X)
    assert np.all(np.isnan(ds.z[3]))
    np.testing.assert_allclose(ds.K[:3], generic.gains(X).K, rtol=1e-12)
    K_nom = -control.dlqr(F_G, G_G, np.eye(3), np.eye(1))[0]
    np.testing.assert_allclose(ds.K[ds.index("nominal")], K_nom, rtol=1e-9, atol=1e-12)
    z_rand = ds.z[ds.index("random")]
    assert np.all((z_rand >= 0) & (z_rand <= 200))
    np.testing.assert_array_equal(z_rand, np.random.default_rng(3).uniform(0, 200, 5))
    np.testing.assert_allclose(ds.K[-1], generic.gains(z_rand).K[0], rtol=1e-12)
    with pytest.raises(ValueError, match="kind"):
        ds.index("rlqr_a")


def test_applied_design_set(applied):
    X = np.array([morais2022.RLQR_MOP_Z])
    ds = build_designs(applied, X, seed=0)
    assert ds.labels == ("1", "nominal", "RLQR^A", "random")
    assert ds.ok.all()
    Q, R = truck.lqr_weights(doubled=True)
    K_nom = -control.dlqr(applied.plant.F, applied.plant.G, Q, R)[0]
    np.testing.assert_allclose(ds.K[1], K_nom, rtol=1e-9, atol=1e-12)
    # the doubled-column LQR splits the plain truck's LQR steering gain in two equal halves
    K1 = -control.dlqr(truck.truck_plant().F, truck.truck_plant().G, *truck.lqr_weights())[0]
    np.testing.assert_allclose(ds.K[1].sum(axis=0), K1[0], rtol=1e-8)
    np.testing.assert_allclose(ds.z[2], [*morais2022.PRINTED_EF, *morais2022.PRINTED_EG, 81.0], rtol=1e-14)
    # RLQR^A's z decodes (H = 1, mu = 10**9) to the same gain as the problem's own decoding
    np.testing.assert_allclose(ds.K[2], applied.gains(ds.z[2]).K[0], rtol=1e-9, atol=1e-12)
    assert np.all((ds.z[3] > 0) & (ds.z[3] <= 500))


# ---------------------------------------------------------------------------
# everything together
# ---------------------------------------------------------------------------

def test_select_design_is_deterministic_and_consistent(generic):
    X = np.array([generic.paper_optimum, [10.0, 20.0, 30.0, 40.0, 50.0], [1.0, 1.0, 1.0, 1.0, 4.0]])
    a = select_design(generic, X, n_sims=60, seed=5)
    b = select_design(generic, X, n_sims=60, seed=5)
    np.testing.assert_array_equal(a.deltas, b.deltas)
    np.testing.assert_array_equal(a.errors, b.errors)
    np.testing.assert_array_equal(a.result.counts, b.result.counts)
    np.testing.assert_array_equal(a.designs.z[-1], b.designs.z[-1])
    c = select_design(generic, X, n_sims=60, seed=6)
    assert not np.array_equal(a.deltas, c.deltas)
    assert a.errors.shape == (5, 60) and a.result.counts.sum() == 60
    # the result is the counting rule applied to the sampled errors
    np.testing.assert_array_equal(a.result.winners, np.argmin(a.errors, axis=0))
    assert a.best == int(np.argmax(a.result.counts)) and a.label == a.designs.labels[a.best]
    np.testing.assert_allclose(a.errors, generic_errors(a.designs.K, a.deltas, problem=generic))


def test_select_design_applied_is_deterministic(applied):
    X = np.array([morais2022.RLQR_MOP_Z])
    path = applied.path.truncated(3.0)
    a = select_design(applied, X, n_sims=4, seed=2, path=path)
    b = select_design(applied, X, n_sims=4, seed=2, path=path)
    np.testing.assert_array_equal(a.errors, b.errors)
    assert a.errors.shape == (4, 4) and np.all(np.isfinite(a.errors))
    np.testing.assert_allclose(a.errors, applied_errors(a.designs.K, a.deltas, path=path))


def test_bad_arguments_name_the_argument(generic, applied):
    X = np.array([generic.paper_optimum])
    with pytest.raises(ValueError, match="n_sims"):
        draw_deltas(0)
    with pytest.raises(TypeError, match="n_sims"):
        select_design(generic, X, n_sims=2.5)
    with pytest.raises(ValueError, match=r"K must have shape \(D, 1, 3\).*got shape \(2, 3\)"):
        generic_errors(np.zeros((2, 3)), [0.0])
    with pytest.raises(TypeError, match="K"):
        generic_errors("K", [0.0])
    with pytest.raises(ValueError, match="deltas must lie in"):
        generic_errors(np.zeros((1, 1, 3)), [0.0, -1.2])
    with pytest.raises(TypeError, match="problem"):
        generic_errors(np.zeros((1, 1, 3)), [0.0], problem=applied)
    with pytest.raises(ValueError, match="K must have shape"):
        applied_errors(np.zeros((1, 3, 4)), [0.0], path=applied.path)
    with pytest.raises(ValueError, match="scales must have 4 columns"):
        applied_errors(np.zeros((1, 2, 4)), [0.0], path=applied.path, scales=[1.0, 2.0])
    with pytest.raises(ValueError, match="scales must be positive"):
        applied_errors(np.zeros((1, 2, 4)), [0.0], path=applied.path, scales=[1.0, 2.0, 0.0, 1.0])
    with pytest.raises(TypeError, match="path"):
        applied_errors(np.zeros((1, 2, 4)), [0.0], path="route")
    with pytest.raises(TypeError, match="problem"):
        build_designs(object(), X)
    with pytest.raises(ValueError, match=r"X_front must have 5 columns.*got shape \(1, 7\)"):
        build_designs(generic, np.ones((1, 7)))
    with pytest.raises(ValueError, match="X_front"):
        build_designs(generic, [[1.0, 1.0, 1.0, 1.0, -1.0]])
    with pytest.raises(ValueError, match="seed"):
        draw_deltas(3, -1)
    with pytest.raises(TypeError, match="seed"):
        select_design(generic, X, n_sims=3, seed="one")
    with pytest.raises(ValueError, match="path and scales"):
        select_design(generic, X, path=applied.path)


# ---------------------------------------------------------------------------
# the script
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("problem, extra", [
    ("generic", ["--sims", "30", "--horizon-steps", "30"]),
    ("applied", ["--sims", "4", "--horizon-steps", "25"]),
])
def test_script_end_to_end(problem, extra, tmp_path, capsys):
    out = tmp_path / problem
    argv = ["--problem", problem, "--evals", "24", "--pop-size", "12", "--seed", "3", "--out", str(out), *extra]
    assert design_selection.main(argv) == 0
    text = capsys.readouterr().out
    rec = json.loads((out / "selection.json").read_text())
    png = (out / "selection_histogram.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000
    n_extra = 2 if problem == "generic" else 3
    assert len(rec["designs"]) == len(rec["front"]["X"]) + n_extra
    assert sum(d["wins"] for d in rec["designs"]) + rec["no_winner"] == rec["sims"]
    win = rec["winner"]
    assert win["wins"] == max(d["wins"] for d in rec["designs"])
    assert rec["designs"][win["index"] - 1]["label"] == win["label"]
    assert rec["horizon_steps"] == int(extra[-1])
    assert f"winner: design {win['label']}" in text
    if problem == "applied":
        assert [d["label"] for d in rec["designs"][-3:]] == ["nominal", "RLQR^A", "random"]
        if win["kind"] != "nominal":
            # the default set-up is mse_table's (authors); the command runs with this interpreter, not a bare python
            line = next(t for t in text.splitlines() if "mse_table.py --setup authors --z" in t)
            assert line.split()[0] == sys.executable and rec["setup"] == "authors"
            z = [float(v) for v in line.split("--z")[1].split()]
            np.testing.assert_allclose(z, win["z"], rtol=1e-7)


def test_script_authors_setup_records_setup_and_margins(tmp_path, capsys):
    out = tmp_path / "authors"
    argv = ["--problem", "applied", "--setup", "authors", "--evals", "24", "--pop-size", "12", "--seed", "3",
            "--sims", "4", "--horizon-steps", "25", "--out", str(out)]
    assert design_selection.main(argv) == 0
    text = capsys.readouterr().out
    rec = json.loads((out / "selection.json").read_text())
    assert rec["setup"] == "authors" and "(set-up authors)" in text
    np.testing.assert_allclose(rec["scales"], [1 / np.sqrt(25000.0), 1.0, 1.0, 0.1])
    m = rec["winner"]["margins"]
    assert set(m) == {"polytope 0-300 %", "appendix (printed)", "appendix (computed)"}
    assert "winner's certified robust-stability margin" in text
    # the margin of the winner's steering gain, recomputed with the analysis engine
    Q, R = morais2022.authors_weights()
    if rec["winner"]["kind"] == "nominal":
        K = rc.lqr(truck.truck_plant(), Q=Q, R=R).K
    else:
        prob = AppliedRLQRProblem(setup="authors", path=default_route(duration=5.0))
        K = prob.gains(np.array(rec["winner"]["z"])).K[0].sum(axis=0, keepdims=True)
    ref = rc.robust_stability((truck.truck_plant(), K),
                              vertices=[truck.truck_plant(k) for k in (100.0, 200.0, 300.0)])
    assert m["polytope 0-300 %"] == pytest.approx(ref.margin, rel=1e-6)
    with pytest.raises(SystemExit):
        design_selection.main(["--problem", "generic", "--setup", "authors", "--out", str(tmp_path / "g")])


def test_script_rejects_bad_options(tmp_path):
    with pytest.raises(SystemExit):
        design_selection.main(["--problem", "generic", "--sims", "0", "--out", str(tmp_path)])
    with pytest.raises(SystemExit):
        design_selection.main(["--problem", "other", "--out", str(tmp_path)])


# ------------------------------------------------------------ any TuningProblem --
def test_select_design_on_a_user_tuning_problem():
    from moo import tuning

    plant = rc.Plant([[1.1, 0.1], [0.0, 0.9]], [[0.0], [0.1]], dt=0.1)
    scenarios = [rc.Plant(plant.F * s, plant.G, dt=0.1) for s in (0.95, 1.0, 1.05)]

    def effort(K, plants):
        return np.abs(K).sum(axis=(1, 2))

    def decay(K, plants):          # the largest closed-loop spectral radius, by eigenvalues per design
        return np.array([max(np.abs(np.linalg.eigvals(p.F + p.G @ k)).max() for p in plants) for k in K])

    prob = tuning.TuningProblem(tuning.LQRFamily(plant), scenarios, [effort, decay])
    X = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, -1.0], [2.0, 0.0, -2.0]])
    sel = select_design(prob, X, n_sims=40, seed=2)
    assert sel.designs.labels == ("1", "2", "3", "random") and sel.deltas.shape == (40,)
    assert set(np.unique(sel.deltas)) <= {0, 1, 2}
    K = sel.designs.K
    Ffront = np.stack([effort(K[:3], scenarios), decay(K[:3], scenarios)], axis=1)
    w = 1.0 / (Ffront.max(axis=0) - Ffront.min(axis=0))
    # per plant alone: a design unstable on that plant cannot win there
    unstable = np.array([[max(np.abs(np.linalg.eigvals(p.F + p.G @ k))) >= 1 for p in scenarios] for k in K])
    per = np.where(unstable, np.inf, np.stack([np.stack([effort(K, [p]), decay(K, [p])], 1) @ w
                                                   for p in scenarios], 1))
    np.testing.assert_allclose(sel.errors, per[:, sel.deltas], rtol=1e-12)
    assert sel.best == int(np.argmax(np.bincount(sel.errors.argmin(axis=0), minlength=4)))
    # an RLQR family adds its nominal design, the LQR of its weights
    fam = tuning.RLQRFamily(plant)
    prob2 = tuning.TuningProblem(fam, scenarios, [effort, decay])
    d = build_designs(prob2, [[0.1, 0.1, 0.1, 36.0]], seed=0)
    assert d.labels == ("1", "nominal", "random")
    K_pc, _, _ = control.dlqr(plant.F, plant.G, np.eye(2), np.eye(1))
    np.testing.assert_allclose(d.K[d.index("nominal")], -K_pc, rtol=1e-9)
    with pytest.raises(ValueError, match="path and scales"):
        select_design(prob, X, n_sims=3, scales=[1, 1, 1, 1])
