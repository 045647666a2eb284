"""A user's TuningProblem through run -> experiment -> stats -> plot -> select, from the CLI and from Python (issue 26).

The user module (written to ``tmp_path``, importable by the subprocess through
``PYTHONPATH``) is an LQR family on a 2-state plant, three scenarios, two
objectives written as plain callables. The choice of ``python -m moo select``
is checked against :meth:`moo.tuning.TuningResult.select` with the same seeds
and against the counting rule recomputed here from the record's ``X`` (gains
from scipy's DARE, errors from the objectives' formulas); the certified
margin against a small-gain value on a frequency grid.
"""

from __future__ import annotations

import json
import os
import textwrap
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg
from conftest import main_many

REPO = Path(__file__).resolve().parents[1]

USER_MODULE = '''
import numpy as np
import robustctl as rc
from moo import tuning

PLANT = rc.Plant([[1.1, 0.1], [0.0, 0.9]], [[0.0], [0.1]], dt=0.1)
SCALES = (0.95, 1.0, 1.05)


def radius(K, plants):
    """Worst closed-loop spectral radius over the plants."""
    return np.max([rc.spectral_radius(p.F + p.G @ K) for p in plants], axis=0)


def effort(K, plants):
    """Frobenius norm of the gain."""
    return np.sqrt((K ** 2).sum(axis=(1, 2)))


def problem():
    scenarios = [rc.Plant(PLANT.F * s, PLANT.G, dt=0.1) for s in SCALES]
    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), scenarios, [radius, effort])
    prob.uncertainty = rc.NormBounded(np.eye(2), 0.05 * PLANT.F, np.zeros((2, 1)))
    return prob


def not_tuning():
    from moo.problems import make_problem
    return make_problem("zdt1")
'''

RUN = ["--problem", "userplant:problem", "--algorithm", "nsga2", "--molsp", "--seed", "1", "--evals", "400",
       "--pop-size", "20"]


def _user():
    """The user module's names, run here (no sys.path edit)."""
    ns: dict = {}
    exec(compile(textwrap.dedent(USER_MODULE), "userplant.py", "exec"), ns)
    return ns


def _dlqr(F, G, z):
    """``u = K x`` of the DLQR with Q = diag(10^z[:n]), R = diag(10^z[n:]) (scipy's DARE)."""
    n = F.shape[0]
    Q, R = np.diag(10.0 ** z[:n]), np.diag(10.0 ** z[n:])
    P = scipy.linalg.solve_discrete_are(F, G, Q, R)
    return -np.linalg.solve(R + G.T @ P @ G, G.T @ P @ F)


def _counting_rule(ns, X, F_front, n_sims, seed):
    """The selection recomputed: draws of scenarios, weighted errors, winners, counts, most frequent winner."""
    plant = ns["PLANT"]
    K = np.stack([_dlqr(plant.F, plant.G, z) for z in X])
    w = 1.0 / (F_front.max(axis=0) - F_front.min(axis=0))
    draws = np.random.default_rng(seed).integers(0, len(ns["SCALES"]), size=n_sims)
    E = np.empty((len(X), len(ns["SCALES"])))
    for s, scale in enumerate(ns["SCALES"]):
        rho = np.array([np.max(np.abs(np.linalg.eigvals(scale * plant.F + plant.G @ k))) for k in K])
        eff = np.linalg.norm(K, axis=(1, 2))
        E[:, s] = np.where(rho < 1, w[0] * rho + w[1] * eff, np.inf)
    winners = np.argmin(E[:, draws], axis=0)
    counts = np.bincount(winners, minlength=len(X))
    return int(np.argmax(counts)), counts, K


def _nondominated(F):
    """Rows of ``F`` not dominated by another, of equal rows the first (a plain O(n^2) filter)."""
    keep = []
    for i, f in enumerate(F):
        dominated = np.any(np.all(f >= F, axis=1) & np.any(f > F, axis=1))
        duplicate = np.any(np.all(F[:i] == f, axis=1))
        keep.append(not dominated and not duplicate)
    return np.flatnonzero(keep)


def _small_gain_margin(plant, unc, K, n_grid=20001):
    """``1 / max_w ||E (e^{jw} I - A)^-1 H||`` on a frequency grid (A = F + G K, E = EF + EG K)."""
    A, E = plant.F + plant.G @ K, unc.EF + unc.EG @ K
    w = np.linspace(0.0, np.pi, n_grid)
    T = E @ np.linalg.solve(np.exp(1j * w)[:, None, None] * np.eye(A.shape[0]) - A, unc.H)
    return 1.0 / np.linalg.svd(T, compute_uv=False)[:, 0].max()


@pytest.fixture
def user_env(tmp_path):
    (tmp_path / "userplant.py").write_text(textwrap.dedent(USER_MODULE))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), str(REPO)]), OMP_NUM_THREADS="1",
               OPENBLAS_NUM_THREADS="1")
    return tmp_path, env


@pytest.mark.slow
def test_user_tuning_problem_run_experiment_stats_plot_select(user_env):
    from moo.tuning import tune

    tmp, env = user_env
    run, res = tmp / "run.json", tmp / "res"
    sel = ["--problem", "userplant:problem", "--n-sims", "300"]
    results = main_many([
        ["run", *RUN, "--out", str(run)],
        ["experiment", "--problem", "userplant:problem", "--algorithms", "nsga2", "--runs", "2", "--evals", "200",
         "--pop-size", "20", "--workers", "2", "--out", str(res)],
        ["stats", str(res), "--out", str(tmp / "table.md")],
        ["plot", str(res), "--out", str(tmp / "figures"), "--format", "png"],
        ["select", str(run), *sel, "--seed", "3", "--out", str(tmp / "sel_run.json")],
        ["select", str(res), *sel, "--seed", "4", "--out", str(tmp / "sel_dir.json")],
        ["select", str(res), *sel, "--seed", "4", "--algorithm", "nsga2", "--molsp", "--out", str(tmp / "sel_m.json")],
    ], env, tmp)
    for code, err, _ in results:
        assert code == 0, err
    assert (tmp / "table.md").is_file() and list((tmp / "figures").glob("*.png"))
    out_run = results[4][2]
    assert "selected design" in out_run and "wins:" in out_run and "certified robust margin" in out_run

    ns = _user()
    problem = ns["problem"]()

    # the run record: the same choice as TuningResult.select (same run, same selection seed) ...
    rec = json.loads(run.read_text())
    X, F = np.array(rec["X"]), np.array(rec["F"])
    got = json.loads((tmp / "sel_run.json").read_text())
    py = tune(problem, "nsga2", molsp=True, evals=400, seed=1, pop_size=20)
    np.testing.assert_array_equal(py.X, X)
    chosen = py.select(n_sims=300, seed=3)
    assert got["index"] == chosen.index and got["record_row"] == chosen.index
    np.testing.assert_allclose(got["K"], chosen.K, rtol=1e-12)
    # ... and as the counting rule recomputed from the record's X
    best, counts, K_ref = _counting_rule(ns, X, F, 300, 3)
    assert got["index"] == best and got["counts"] == counts.tolist() and got["wins"] == counts[best]
    assert got["share"] == pytest.approx(counts[best] / 300)
    np.testing.assert_allclose(got["K"], K_ref[best], rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(got["z"], X[best])
    assert got["rule"] == "scenarios" and got["n_front"] == len(X)
    margin = _small_gain_margin(ns["PLANT"], problem.uncertainty, K_ref[best])
    assert got["margin"] == pytest.approx(margin, rel=1e-4)

    # the results directory: the non-dominated union of its runs' fronts (records in path order)
    recs = [json.loads(p.read_text()) for p in sorted(res.glob("*/*/seed_*.json"))]
    assert len(recs) == 4
    for name, keep in (("sel_dir.json", lambda r: True), ("sel_m.json", lambda r: r["molsp"])):
        mine = [r for r in recs if keep(r)]
        X_all = np.concatenate([np.array(r["X"]) for r in mine])
        F_all = np.concatenate([np.array(r["F"]) for r in mine])
        rows = _nondominated(F_all)
        got = json.loads((tmp / name).read_text())
        assert got["n_front"] == rows.size and len(got["records"]) == len(mine)
        best, counts, _ = _counting_rule(ns, X_all[rows], F_all[rows], 300, 4)
        assert got["counts"] == counts.tolist()
        np.testing.assert_allclose(got["z"], X_all[rows][best])
        src = json.loads(Path(got["record"]).read_text())
        np.testing.assert_array_equal(src["X"][got["record_row"]], got["z"])


def test_select_bad_source_or_problem_is_a_one_line_error(user_env):
    tmp, env = user_env
    run = tmp / "run.json"
    mixed = tmp / "mixed"
    results = main_many([
        ["run", *RUN[:-4], "--evals", "40", "--pop-size", "20", "--out", str(run)],
        ["select", str(run), "--problem", "userplant:not_tuning", "--seed", "0"],
        ["select", str(run), "--problem", "zdt1", "--seed", "0"],
        ["select", str(tmp / "missing.json"), "--problem", "userplant:problem", "--seed", "0"],
        ["select", str(tmp / "userplant.py"), "--problem", "userplant:problem", "--seed", "0"],
        ["select", str(run), "--problem", "userplant:problem", "--algorithm", "nsga3", "--seed", "0"],
        ["select", str(run), "--problem", "userplant:problem", "--seed", "0", "--n-sims", "0"],
        ["select", str(tmp), "--problem", "userplant:problem", "--seed", "0"],
    ], env, tmp)
    assert results[0][0] == 0, results[0][1]
    messages = ["select needs a moo.tuning.TuningProblem", "select needs a moo.tuning.TuningProblem",
                "does not exist", "is not a readable run record", "no run of nsga3", "--n-sims must be >= 1",
                "no run records"]
    for (code, err, out), message in zip(results[1:], messages, strict=True):
        assert code == 2 and message in err and len(err.strip().splitlines()) == 1 and out == "", (message, err)

    # a directory mixing two settings (load_records' check): exit 2 naming the file
    rec = json.loads(run.read_text())
    for seed, budget in ((1, 40), (2, 80)):
        path = mixed / "userplant~problem" / "nsga2+molsp" / f"seed_{seed}.json"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(dict(rec, seed=seed, budget=budget)))
    (code, err, _), = main_many([["select", str(mixed), "--problem", "userplant:problem", "--seed", "0"]], env, tmp)
    assert code == 2 and "mixes two settings" in err and "seed_2.json" in err
