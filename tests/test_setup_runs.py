"""The applied problem's set-up through moo.runner, moo.experiment and the CLI: recorded, and never mixed."""

import json

import numpy as np
import pytest

from moo import runner
from moo.__main__ import main
from moo.experiment import plan, run_experiment

TINY = dict(seed=0, evals=20, pop_size=20)


@pytest.fixture(scope="module")
def authors_run():
    return runner.run("applied", "nsga2", setup="authors", **TINY)


def test_run_records_the_setup(authors_run):
    assert authors_run.setup == "authors" and authors_run.to_dict()["setup"] == "authors"
    assert runner.prepare("applied", "nsga2", **TINY).setup == "ours"        # the default, by name
    assert runner.prepare("zdt1", "nsga2", **TINY).setup is None
    np.testing.assert_allclose(authors_run.hv_ref_point, np.square([0.25, 0.035, 0.35, 0.0125]))


def test_run_with_the_setup_equals_the_problem_built_directly(authors_run):
    from moo.problems.applied import AppliedRLQRProblem

    F = AppliedRLQRProblem(setup="authors").evaluate(authors_run.X)
    np.testing.assert_allclose(F, authors_run.F, rtol=1e-12)


def test_setup_of_a_problem_without_one_is_an_error():
    with pytest.raises(ValueError, match="setup applies to the 'applied' problem only"):
        runner.prepare("zdt1", "nsga2", setup="authors", **TINY)


def test_experiment_store_does_not_mix_setups(tmp_path):
    kw = dict(runs=1, evals=20, pop_size=20, out=tmp_path, progress=False, variants=(False,))
    report = run_experiment("applied", "nsga2", setup="authors", **kw)
    assert report.completed == 1
    spec = plan("applied", "nsga2", runs=1, evals=20, pop_size=20, variants=(False,), setup="authors")[0]
    assert json.loads(spec.path(tmp_path).read_text())["setup"] == "authors"
    assert run_experiment("applied", "nsga2", setup="authors", **kw).skipped == 1       # resumes
    with pytest.raises(ValueError, match="other settings: setup 'authors' \\(this grid: 'ours'\\)"):
        run_experiment("applied", "nsga2", **kw)
    with pytest.raises(ValueError, match="other settings: setup 'authors' \\(this grid: 'ours'\\)"):
        run_experiment("applied", "nsga2", setup="ours", **kw)


def test_records_from_before_setups_count_as_the_default(tmp_path):
    kw = dict(runs=1, evals=20, pop_size=20, out=tmp_path, progress=False, variants=(False,))
    run_experiment("applied", "nsga2", **kw)
    path = plan("applied", "nsga2", runs=1, evals=20, pop_size=20, variants=(False,))[0].path(tmp_path)
    rec = json.loads(path.read_text())
    assert rec["setup"] == "ours"
    del rec["setup"]                                       # as written before set-ups existed
    path.write_text(json.dumps(rec))
    assert run_experiment("applied", "nsga2", **kw).skipped == 1
    assert run_experiment("applied", "nsga2", setup="ours", **kw).skipped == 1
    with pytest.raises(ValueError, match="other settings: setup 'ours' \\(this grid: 'authors'\\)"):
        run_experiment("applied", "nsga2", setup="authors", **kw)


def test_cli_setup(tmp_path, capsys):
    out = tmp_path / "run.json"
    assert main(["run", "--problem", "applied", "--setup", "authors", "--algorithm", "nsga2", "--seed", "0",
                 "--evals", "20", "--pop-size", "20", "--out", str(out)]) == 0
    assert json.loads(out.read_text())["setup"] == "authors"
    assert main(["run", "--problem", "zdt1", "--setup", "authors", "--algorithm", "nsga2", "--seed", "0",
                 "--evals", "20", "--pop-size", "20", "--out", str(tmp_path / "z.json")]) == 2
    assert "--setup applies to the 'applied' problem only" in capsys.readouterr().err
    assert main(["experiment", "--problem", "applied", "--setup", "theirs", "--algorithms", "nsga2", "--runs", "1",
                 "--evals", "20", "--pop-size", "20", "--out", str(tmp_path / "grid")]) == 2
    assert "unknown setup 'theirs'" in capsys.readouterr().err
