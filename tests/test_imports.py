"""Problems and MOEAs by import path (``package.module:factory``) through run, experiment, stats and plot (issue 26)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from conftest import main_many

from moo.__main__ import main

REPO = Path(__file__).resolve().parents[1]

USER_MODULE = '''
import numpy as np
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.core.problem import Problem


class Sphere2(Problem):
    """Two objectives: squared distances to the points 0 and 1 of the cube [0, 1]^3."""

    def __init__(self, n_obj=2):
        super().__init__(n_var=3, n_obj=n_obj, xl=0.0, xu=1.0)
        self.hv_ref_point = np.full(n_obj, 3.3)
        self.molsp_ref_point = np.full(n_obj, 3.3)

    def _evaluate(self, x, out, *args, **kwargs):
        out["F"] = np.column_stack([((x - c) ** 2).sum(axis=1) for c in np.linspace(0.0, 1.0, self.n_obj)])


def problem():
    return Sphere2()


def problem_m(n_obj=2):
    return Sphere2(n_obj)


def plain_nsga2(n_obj, pop_size):
    return NSGA2(pop_size=pop_size)


def not_a_problem():
    return 42


def no_reference_point():
    p = Sphere2()
    del p.molsp_ref_point
    return p


def not_an_algorithm(n_obj, pop_size):
    return "nsga2"


def broken():
    raise RuntimeError("the user's bug")
'''


@pytest.fixture
def user_module(tmp_path, monkeypatch):
    """``usermoo`` in ``tmp_path``, importable by this process's subprocesses (PYTHONPATH)."""
    (tmp_path / "usermoo.py").write_text(textwrap.dedent(USER_MODULE))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), str(REPO)]), OMP_NUM_THREADS="1",
               OPENBLAS_NUM_THREADS="1")
    return tmp_path, env


def _moo(args, env, cwd):
    return subprocess.run([sys.executable, "-m", "moo", *args], env=env, cwd=cwd, capture_output=True, text=True,
                          timeout=300, check=False)



def _front_of(F):
    """The non-dominated rows of ``F`` (a plain O(n^2) filter: an independent check of moocore)."""
    F = np.unique(np.asarray(F, dtype=float), axis=0)
    keep = [not np.any(np.all(f >= F, axis=1) & np.any(f > F, axis=1)) for f in F]
    return F[keep]


@pytest.mark.slow
def test_user_problem_and_moea_through_run_experiment_stats_and_plot(user_module):
    tmp, env = user_module
    out, res = tmp / "run.json", tmp / "res"
    results = main_many([
        ["run", "--problem", "usermoo:problem", "--algorithm", "usermoo:plain_nsga2", "--molsp", "--seed", "1",
         "--evals", "400", "--pop-size", "20", "--out", str(out)],
        # on a process pool: the user's MOEA beside a registry one, plain and with MO-LSP
        ["experiment", "--problem", "usermoo:problem", "--algorithms", "usermoo:plain_nsga2,nsga2", "--runs", "2",
         "--evals", "200", "--pop-size", "20", "--workers", "2", "--out", str(res)],
        ["stats", str(res), "--runs-out", str(tmp / "runs.csv")],
        ["plot", str(res), "--out", str(tmp / "fig"), "--format", "png"],
        ["run", "--problem", "usermoo:problem_m", "--n-obj", "3", "--algorithm", "nsga2", "--seed", "0",
         "--evals", "60", "--pop-size", "20", "--out", str(tmp / "m3.json")],
        ["run", "--problem", "usermoo:problem", "--n-obj", "3", "--algorithm", "nsga2", "--seed", "0",
         "--evals", "60", "--out", str(tmp / "no.json")],
    ], env, tmp)
    assert [code for code, _, _ in results] == [0, 0, 0, 0, 0, 2], results
    # run: the record names both by their paths, and its F is the problem's own values at X
    rec = json.loads(out.read_text())
    assert (rec["problem"], rec["algorithm"], rec["molsp"], rec["n_obj"]) == \
           ("usermoo:problem", "usermoo:plain_nsga2", True, 2)
    X, F = np.array(rec["X"]), np.array(rec["F"])
    direct = np.column_stack([(X ** 2).sum(axis=1), ((X - 1.0) ** 2).sum(axis=1)])   # the objectives, by hand
    np.testing.assert_allclose(F, direct, rtol=1e-12)
    np.testing.assert_array_equal(_front_of(F), np.unique(F, axis=0))
    assert rec["hv_ref_point"] == [3.3, 3.3] and rec["molsp_ref_point"] == [3.3, 3.3]
    # experiment
    files = sorted(p.relative_to(res).as_posix() for p in res.glob("*/*/seed_*.json"))
    assert len(files) == 8 and all(f.startswith("usermoo~problem/") for f in files)
    assert {f.split("/")[1] for f in files} == {"usermoo~plain_nsga2", "usermoo~plain_nsga2+molsp", "nsga2",
                                               "nsga2+molsp"}
    settings = json.loads((res / "settings.json").read_text())
    assert settings["problems"] == {"usermoo~problem": {"problem": "usermoo:problem", "n_obj": 2, "setup": None}}
    # stats and plot
    assert "usermoo:plain_nsga2" in results[2][2] and "usermoo:problem" in (tmp / "runs.csv").read_text()
    assert (tmp / "fig" / "hv_usermoo~problem.png").stat().st_size > 0
    # n_obj goes to a factory that takes it, and is refused by one that does not
    assert json.loads((tmp / "m3.json").read_text())["n_obj"] == 3
    assert "takes no n_obj argument" in results[5][1] and results[5][1].count("\n") == 1


BAD_PATHS = [
    ("--problem", "usermoo:not_a_problem",
     "problem factory 'usermoo:not_a_problem' returned a int, not a pymoo Problem"),
    ("--problem", "usermoo:no_reference_point", "returned a problem without the molsp_ref_point attribute"),
    ("--problem", "usermoo:broken", "problem factory 'usermoo:broken' raised RuntimeError: the user's bug"),
    ("--problem", "usermoo:missing", "problem 'usermoo:missing': module 'usermoo' has no attribute 'missing'"),
    ("--problem", "nosuchmodule.sub:f",
     "problem 'nosuchmodule.sub:f': cannot import module 'nosuchmodule.sub' (ModuleNotFoundError"),
    ("--problem", "usermoo:", "is not an import path of the form 'package.module:factory'"),
    ("--algorithm", "usermoo:not_an_algorithm",
     "algorithm factory 'usermoo:not_an_algorithm' returned a str, not a pymoo Algorithm"),
    ("--algorithm", "nosuchmodule:f", "algorithm 'nosuchmodule:f': cannot import module 'nosuchmodule'"),
]


def test_a_bad_import_path_is_one_line_exit_2_nothing_run(user_module):
    tmp, env = user_module
    argvs, messages = [], []
    for flag, path, message in BAD_PATHS:
        run = {"--problem": "zdt1", "--algorithm": "nsga2", flag: path}
        argvs.append(["run", "--problem", run["--problem"], "--algorithm", run["--algorithm"], "--seed", "0",
                      "--evals", "100", "--out", str(tmp / "run.json")])
        grid = {"--problem": "zdt1", "--algorithms": "nsga2", flag.replace("algorithm", "algorithms"): path}
        argvs.append(["experiment", "--problem", grid["--problem"], "--algorithms", grid["--algorithms"],
                      "--runs", "1", "--evals", "100", "--out", str(tmp / "res")])
        messages += [message, message]
    for argv, message, (code, err, _) in zip(argvs, messages, main_many(argvs, env, tmp), strict=True):
        assert code == 2 and err.count("\n") == 1 and message in err, (argv, err)
    assert not (tmp / "run.json").exists() and not (tmp / "res").exists()


def test_in_process_errors_name_the_path(capsys, tmp_path):
    # importable everywhere: a factory that returns something else, or needs arguments
    assert main(["run", "--problem", "builtins:dict", "--algorithm", "nsga2", "--seed", "0", "--evals", "60",
                 "--out", str(tmp_path / "r.json")]) == 2
    assert "problem factory 'builtins:dict' returned a dict, not a pymoo Problem" in capsys.readouterr().err
    assert main(["experiment", "--problem", "zdt1", "--algorithms", "nsga2,builtins:dict", "--runs", "1",
                 "--evals", "200", "--out", str(tmp_path / "res")]) == 2
    assert "algorithm factory 'builtins:dict' returned a dict, not a pymoo Algorithm" in capsys.readouterr().err
    assert not (tmp_path / "res").exists()


@pytest.mark.slow
def test_user_problem_and_moea_on_a_local_dask_cluster(user_module):
    pytest.importorskip("distributed")
    tmp, env = user_module
    grid = ["--problem", "usermoo:problem", "--algorithms", "usermoo:plain_nsga2", "--runs", "2", "--evals", "100",
            "--pop-size", "20"]
    proc = _moo(["experiment", *grid, "--out", str(tmp / "dask"), "--executor", "dask", "--workers", "1"], env, tmp)
    assert proc.returncode == 0, proc.stderr
    proc = _moo(["experiment", *grid, "--out", str(tmp / "serial")], env, tmp)
    assert proc.returncode == 0, proc.stderr
    for serial in sorted((tmp / "serial").glob("*/*/seed_*.json")):
        a, b = json.loads(serial.read_text()), json.loads((tmp / "dask" / serial.relative_to(tmp / "serial"))
                                                          .read_text())
        assert (a["algorithm"], a["F"], a["X"]) == (b["algorithm"], b["F"], b["X"])     # the same runs
