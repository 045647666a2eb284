"""``python -m moo run``: the JSON record, progress output, and argument errors (exit code 2)."""

from __future__ import annotations

import importlib
import itertools
import json
import subprocess
import sys

import numpy as np
import pytest
from pymoo.problems import get_problem

from moo.__main__ import main


def run_cli(tmp_path, *args, name="out.json"):
    out = tmp_path / name
    code = main(["run", *args, "--out", str(out)])
    return code, (json.loads(out.read_text()) if out.exists() else None)


def hv_2d(F, r):
    """2-D hypervolume by a sweep over the points sorted by the first objective."""
    F = sorted(map(tuple, F))
    total, best_f2 = 0.0, r[1]
    for f1, f2 in F:
        if f1 < r[0] and f2 < best_f2:
            total += (r[0] - f1) * (best_f2 - f2)
            best_f2 = f2
    return total


REQUIRED = {"problem", "algorithm", "molsp", "seed", "n_evals", "F", "X", "hv_history", "wall_time_s",
            "versions"}


def test_run_zdt1_nsga2_record(tmp_path):
    code, rec = run_cli(tmp_path, "--problem", "zdt1", "--algorithm", "nsga2", "--seed", "3",
                        "--evals", "500", "--pop-size", "20")
    assert code == 0
    assert rec.keys() >= REQUIRED
    assert (rec["problem"], rec["algorithm"], rec["molsp"], rec["seed"]) == ("zdt1", "nsga2", False, 3)
    assert 500 <= rec["n_evals"] < 500 + 20
    F, X = np.array(rec["F"]), np.array(rec["X"])
    assert F.shape[1] == 2 and X.shape == (len(F), 30)
    assert np.all((X >= 0) & (X <= 1))
    # the objectives are those of the decision vectors (pymoo's own ZDT1)
    assert np.allclose(get_problem("zdt1").evaluate(X), F, rtol=1e-12, atol=0)
    # the final set is non-dominated, without repeated objective vectors
    assert len(np.unique(F, axis=0)) == len(F)
    for i in range(len(F)):
        dominated = np.all(F[i] >= F, axis=1) & np.any(F[i] > F, axis=1)
        assert not dominated.any()
    hist = rec["hv_history"]
    evals, hv = hist["evaluations"], hist["hypervolume"]
    assert evals[0] == 20 and evals[-1] == rec["n_evals"]
    assert all(b > a for a, b in itertools.pairwise(evals))
    assert hv[-1] == pytest.approx(hv_2d(F, rec["hv_ref_point"]), rel=1e-12)
    assert rec["hv_ref_point"] == [1.1, 1.1]
    assert {"numpy", "pymoo", "moocore", "python"} <= rec["versions"].keys()


def test_run_dtlz2_with_molsp_and_cap(tmp_path):
    code, rec = run_cli(tmp_path, "--problem", "dtlz2", "--n-obj", "4", "--algorithm", "nsga2", "--molsp",
                        "--max-leaders", "5", "--seed", "1", "--evals", "400", "--pop-size", "20")
    assert code == 0
    assert rec["molsp"] is True and rec["max_leaders"] == 5 and rec["n_obj"] == 4
    assert 0 < rec["molsp_evals"] <= 5 * len(rec["hv_history"]["evaluations"])
    assert 400 <= rec["n_evals"] < 420
    F, X = np.array(rec["F"]), np.array(rec["X"])
    assert F.shape[1] == 4
    assert np.allclose(get_problem("dtlz2", n_var=13, n_obj=4).evaluate(X), F, rtol=1e-12, atol=0)


def test_same_seed_same_record(tmp_path):
    args = ["--problem", "zdt2", "--algorithm", "nsga2", "--molsp", "--seed", "9", "--evals", "300",
            "--pop-size", "20"]
    _, a = run_cli(tmp_path, *args, name="a.json")
    _, b = run_cli(tmp_path, *args, name="b.json")
    assert a["F"] == b["F"] and a["X"] == b["X"] and a["hv_history"] == b["hv_history"]


def test_module_entry_point_is_quiet_without_tty(tmp_path):
    out = tmp_path / "r.json"
    proc = subprocess.run([sys.executable, "-m", "moo", "run", "--problem", "zdt1", "--algorithm", "nsga2",
                           "--seed", "0", "--evals", "100", "--pop-size", "20", "--out", str(out)],
                          capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "" and proc.stderr == ""
    assert json.loads(out.read_text())["n_evals"] >= 100


def test_progress_bar_on_a_terminal(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    code, _ = run_cli(tmp_path, "--problem", "zdt1", "--algorithm", "nsga2", "--seed", "0", "--evals", "100",
                      "--pop-size", "20")
    err = capsys.readouterr().err
    assert code == 0
    assert "\r" in err and "/100 [" in err and "evals/s" in err             # the tqdm bar, then its line cleared
    summary = err.rsplit("\r", 1)[-1].strip()                             # one summary line at the end
    rec = json.loads((tmp_path / "out.json").read_text())
    assert summary.startswith(f"front: {len(rec['F'])} designs, hypervolume {rec['hv']:.6g} (reference: ")
    assert summary.endswith(f"written to {tmp_path / 'out.json'}") and summary.count("\n") == 0


def test_quiet_prints_nothing_on_a_terminal(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    code, _ = run_cli(tmp_path, "--problem", "zdt1", "--algorithm", "nsga2", "--seed", "0", "--evals", "100",
                      "--pop-size", "20", "--quiet")
    assert code == 0 and capsys.readouterr().err == ""


def test_help_explains_the_algorithm_names(capsys):
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    out = capsys.readouterr().out
    assert "nsga2        NSGA-II (Deb et al. 2002) with the paper's operators" in out and "not pymoo's defaults" in out
    assert "pymoo-nsga2  pymoo's own NSGA-II, pymoo's default operators" in out
    assert "ga           a single-objective genetic algorithm" in out


@pytest.mark.parametrize("args, message", [
    (["--problem", "zdt9", "--algorithm", "nsga2"], "unknown problem 'zdt9'"),
    (["--problem", "zdt1", "--algorithm", "nsga9"], "unknown algorithm 'nsga9'"),
    (["--problem", "zdt1", "--algorithm", "nsga2", "--evals", "50"], "--evals must be at least"),
    (["--problem", "zdt1", "--algorithm", "nsga2", "--pop-size", "2"], "--pop-size must be >= 4"),
    (["--problem", "zdt1", "--algorithm", "nsga2", "--seed", "-1"], "--seed must be >= 0"),
    (["--problem", "zdt1", "--n-obj", "3", "--algorithm", "nsga2"], "has 2 objectives"),
    (["--problem", "dtlz2", "--n-obj", "1", "--algorithm", "nsga2"], "--n-obj must be between 2"),
    (["--problem", "zdt1", "--algorithm", "nsga2", "--max-leaders", "3"], "--max-leaders needs --molsp"),
    (["--problem", "zdt1", "--algorithm", "nsga2", "--evals", "many"], "invalid int value"),
    (["--problem", "zdt1"], "required"),
])
def test_bad_arguments_exit_2_with_one_line(tmp_path, capsys, args, message):
    defaults = {"--seed": "0", "--evals": "200"}
    argv = list(args)
    for flag, value in defaults.items():
        if flag not in argv and "--algorithm" in argv:
            argv += [flag, value]
    code = main(["run", *argv, "--out", str(tmp_path / "x.json")])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and message in err
    assert not (tmp_path / "x.json").exists()


def test_missing_output_directory_is_a_usage_error(tmp_path, capsys):
    code = main(["run", "--problem", "zdt1", "--algorithm", "nsga2", "--seed", "0", "--evals", "200",
                 "--out", str(tmp_path / "nowhere" / "x.json")])
    assert code == 2 and "does not exist" in capsys.readouterr().err


@pytest.mark.parametrize("name, module, n_obj, evals", [("generic", "moo.problems.generic", 3, 60),
                                                        ("applied", "moo.problems.applied", 4, 40)])
def test_control_design_problems(tmp_path, name, module, n_obj, evals):
    importlib.import_module(module)  # a broken problem module must fail here, not skip
    code, rec = run_cli(tmp_path, "--problem", name, "--algorithm", "nsga2", "--molsp", "--seed", "0",
                        "--evals", str(evals), "--pop-size", "20")
    assert code == 0
    F = np.array(rec["F"])
    assert F.shape[1] == n_obj and rec["n_obj"] == n_obj
    assert evals <= rec["n_evals"] < evals + 20
    assert len(rec["hv_ref_point"]) == n_obj and len(rec["molsp_ref_point"]) == n_obj


# ----------------------------------------------------------------------------- the problems behind --problem


def _nondominated(F):
    import moocore
    return F[moocore.is_nondominated(F)]


@pytest.mark.parametrize("name, n_obj", [("zdt1", None), ("zdt2", None), ("zdt3", None), ("zdt4", None),
                                         ("zdt6", None), ("dtlz1", 2), ("dtlz1", 3), ("dtlz2", 3),
                                         ("dtlz3", 2), ("dtlz4", 3), ("dtlz5", 4), ("dtlz6", 5)])
def test_front_bounds_match_pymoo_fronts(name, n_obj):
    from moo.problems import make_problem, true_front_bounds
    ideal, nadir = true_front_bounds(name, n_obj)
    kwargs = {} if n_obj is None else {"n_obj": n_obj}
    pf = get_problem(name, **kwargs).pareto_front()
    tol = 2e-3 if name == "zdt3" else 1e-6          # pymoo samples ZDT3's front on a grid
    assert np.allclose(ideal, pf.min(axis=0), atol=tol) and np.allclose(nadir, pf.max(axis=0), atol=tol)
    problem = make_problem(name, n_obj)
    assert np.allclose(problem.hv_ref_point, nadir + 0.1 * (nadir - ideal))
    assert np.array_equal(problem.molsp_ref_point, problem.hv_ref_point)


@pytest.mark.parametrize("n_obj", [2, 3])
def test_dtlz7_front_bounds_by_sampling(n_obj):
    """DTLZ7's front (g = 1): f_M = 2 (M - sum_i f_i/2 (1 + sin 3 pi f_i)); filter a grid to its non-dominated part."""
    from moo.problems import true_front_bounds
    axis = np.linspace(0, 1, 20001 if n_obj == 2 else 301)
    grid = np.stack(np.meshgrid(*[axis] * (n_obj - 1), indexing="ij"), -1).reshape(-1, n_obj - 1)
    fM = 2 * (n_obj - np.sum(grid / 2 * (1 + np.sin(3 * np.pi * grid)), axis=1))
    front = _nondominated(np.column_stack([grid, fM]))
    ideal, nadir = true_front_bounds("dtlz7", n_obj)
    tol = 1e-3 if n_obj == 2 else 1e-2
    assert np.allclose(ideal, front.min(axis=0), atol=tol)
    assert np.allclose(nadir, front.max(axis=0), atol=tol)


def test_zdt5_real_coding_reads_bits():
    from moo.problems import make_problem
    rng = np.random.default_rng(0)
    X = rng.random((6, 80))
    bits = (X >= 0.5).astype(float)
    assert np.array_equal(make_problem("zdt5").evaluate(X), get_problem("zdt5").evaluate(bits))


def test_make_problem_names_and_objectives():
    from moo.problems import PROBLEMS, make_problem
    assert make_problem("DTLZ2").n_obj == 3
    assert make_problem("dtlz1", 5).n_var == 5 + 5 - 1
    assert make_problem("dtlz7", 3).n_var == 3 + 20 - 1
    assert len(PROBLEMS) == 24                       # 2 control, 6 ZDT, 7 DTLZ, 9 WFG
    with pytest.raises(ValueError, match="unknown problem 'foo'"):
        make_problem("foo")
    with pytest.raises(TypeError, match="n_obj must be an integer"):
        make_problem("dtlz2", 2.5)


# ----------------------------------------------------------------------------- --out checked before the run

@pytest.fixture
def no_run(monkeypatch):
    """Fail the test if a run starts (the checks must come first)."""
    import moo.runner

    def boom(self, progress=None):
        raise AssertionError("the run started before --out was checked")

    monkeypatch.setattr(moo.runner.PreparedRun, "run", boom)


@pytest.mark.parametrize("out, message", [("{tmp}", "is a directory, not a file"),
                                          ("", "--out must be a file path"),
                                          ("/proc/moo-test.json", "--out: cannot write in '/proc'"),
                                          ("{tmp}/missing/x.json", "does not exist")])
def test_run_out_is_checked_before_the_run(tmp_path, capsys, no_run, out, message):
    code = main(["run", "--problem", "zdt1", "--algorithm", "nsga2", "--seed", "0", "--evals", "200",
                 "--out", out.format(tmp=tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and message in err and err.count("\n") == 1, err


def test_run_failure_exits_1_with_the_traceback_and_one_line(tmp_path, capsys, monkeypatch):
    import moo.runner

    def fail(self, progress=None):
        raise RuntimeError("solver exploded")

    monkeypatch.setattr(moo.runner.PreparedRun, "run", fail)
    code = main(["run", "--problem", "zdt1", "--algorithm", "nsga2", "--seed", "0", "--evals", "200",
                 "--out", str(tmp_path / "r.json")])
    err = capsys.readouterr().err
    assert code == 1 and "Traceback" in err and not (tmp_path / "r.json").exists()
    assert err.strip().splitlines()[-1] == "python -m moo: error: the run failed: RuntimeError: solver exploded"


def test_prepared_run_is_repeatable_and_matches_run():
    from moo.runner import prepare, run

    job = prepare("zdt1", "nsga2", seed=4, evals=200, pop_size=20, molsp=True, max_leaders=3)
    a, b = job.run(), job.run()
    c = run("zdt1", "nsga2", seed=4, evals=200, pop_size=20, molsp=True, max_leaders=3)
    assert np.array_equal(a.F, b.F) and np.array_equal(a.F, c.F) and np.array_equal(a.hv_history, c.hv_history)
    with pytest.raises(TypeError, match="molsp must be a bool"):
        prepare("zdt1", "nsga2", seed=4, evals=200, molsp="yes")
