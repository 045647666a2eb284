"""The results store: one writer, one setting per directory, validated records, atomic outputs (issue 23)."""

from __future__ import annotations

import errno
import json
import os
import shutil
import stat

import pytest

from moo.__main__ import main
from moo.experiment import plan, run_experiment
from moo.store import (
    CorruptRecordError,
    ResultsDirBusyError,
    lock_results_dir,
    read_settings,
    validate_record,
    write_json_atomic,
)

TINY = dict(runs=2, evals=40, pop_size=20, progress=False)
CLI = ["--runs", "2", "--evals", "40", "--pop-size", "20"]


def _one_line(err: str) -> str:
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


def _records(out):
    return sorted(out.glob("*/*/seed_*.json"))


# ----------------------------------------------------------------------------- 1. one owner, settings once

def test_a_second_writer_is_refused_with_one_line_exit_2(tmp_path, capsys):
    out = tmp_path / "res"
    out.mkdir()
    with lock_results_dir(out):                    # another `experiment` holds the directory
        code = main(["experiment", "--problem", "zdt1", "--algorithms", "nsga2", *CLI, "--out", str(out)])
        err = _one_line(capsys.readouterr().err)
        assert code == 2 and "is in use by another writer" in err and f"process {os.getpid()}" in err
        with pytest.raises(ResultsDirBusyError):
            run_experiment("zdt1", "nsga2", out=out, **TINY)
    assert not _records(out)
    assert main(["experiment", "--problem", "zdt1", "--algorithms", "nsga2", *CLI, "--out", str(out)]) == 0
    assert len(_records(out)) == 4                 # the lock is released at the end of the block


def test_settings_are_recorded_once_and_another_budget_is_refused(tmp_path, capsys):
    out = tmp_path / "res"
    base = ["experiment", "--problem", "zdt1", "--runs", "1", "--pop-size", "20", "--out", str(out)]
    assert main([*base, "--algorithms", "nsga2", "--evals", "40"]) == 0
    assert read_settings(out) == {"budget": 40, "pop_size": 20, "max_leaders": None, "base_seed": 0,
                                  "problems": {"zdt1": {"problem": "zdt1", "n_obj": 2, "setup": None}}}
    capsys.readouterr()
    # nsga3 at another budget in the nsga2 directory: its cells are empty, the directory is not
    assert main([*base, "--algorithms", "nsga3", "--evals", "60"]) == 2
    err = _one_line(capsys.readouterr().err)
    assert f"{out / 'settings.json'}: the directory holds runs with other settings: --evals 40 (this grid: 60)" in err
    assert main([*base, "--algorithms", "nsga3", "--evals", "40", "--seed", "7"]) == 2
    assert "--seed 0 (this grid: 7)" in capsys.readouterr().err
    assert not (out / "zdt1" / "nsga3").exists()
    assert main([*base, "--algorithms", "nsga3", "--evals", "40"]) == 0      # the same settings: added


# ----------------------------------------------------------------------------- 2. never two settings

def test_a_directory_from_before_settings_json_is_checked_from_its_records(tmp_path, capsys):
    out = tmp_path / "res"
    run_experiment("zdt1", "nsga2", out=out, **TINY)
    (out / "settings.json").unlink()               # as written before settings.json existed
    with pytest.raises(ValueError, match=r"seed_\d+\.json holds a run with other settings: budget 40 "
                                         r"\(this grid: 60\)"):
        run_experiment("zdt1", "nsga3", out=out, **{**TINY, "evals": 60})
    assert run_experiment("zdt1", "nsga3", out=out, **TINY).completed == 4      # same settings: fine
    assert read_settings(out)["budget"] == 40                                  # and recorded now


def test_stats_and_plot_refuse_a_directory_mixing_two_settings(tmp_path, capsys):
    a, b = tmp_path / "a", tmp_path / "b"
    run_experiment("zdt1", "nsga2", out=a, **TINY)
    run_experiment("zdt1", "nsga3", out=b, **{**TINY, "evals": 60})
    shutil.copytree(b / "zdt1" / "nsga3", a / "zdt1" / "nsga3")                # mixed by hand
    moved = min((a / "zdt1" / "nsga3").glob("seed_*.json"))
    for cmd in (["stats", str(a)], ["plot", str(a), "--out", str(tmp_path / "fig")]):
        assert main(cmd) == 2
        err = _one_line(capsys.readouterr().err)
        assert f"{moved} holds a run with budget 60, but {a / 'settings.json'} has 40" in err, err
    (a / "settings.json").unlink()                 # an old directory: the records disagree among themselves
    assert main(["stats", str(a)]) == 2
    err = _one_line(capsys.readouterr().err)
    assert "holds a run with budget 60, but" in err and "mixes two settings" in err
    assert not (tmp_path / "fig").exists()


def test_the_same_problem_under_two_directory_names_is_refused(tmp_path):
    out = tmp_path / "res"
    run_experiment("dtlz2", "nsga2", out=out, **{**TINY, "evals": 100, "pop_size": 40})
    with pytest.raises(ValueError, match=r"problem directory 'dtlz2' \(this grid: 'dtlz2-m3'\)"):
        run_experiment("dtlz2", "nsga2", n_obj=3, out=out, **{**TINY, "evals": 100, "pop_size": 40})


# ----------------------------------------------------------------------------- 3. records that parse but are wrong

@pytest.mark.parametrize("change, reason", [
    (lambda r: r.update(F=[]), "F is empty"),
    (lambda r: r.update(seed=r["seed"] + 1), "differs from its file name"),
    (lambda r: r.update(F=[[1.0, "a"]]), "F row 0 holds 'a', not a finite number"),
    (lambda r: r.update(F=[[1.0, 2.0, 3.0]]), "F row 0 must have 2 values (n_obj), got 3 values"),
    (lambda r: r.update(F=[[1.0, float("nan")]]), "F row 0 holds nan"),
    (lambda r: r.update(algorithm="nsga3"), "it holds a run of nsga3, not of its directory nsga2"),
])
def test_a_wrong_record_is_recomputed_by_experiment_and_refused_by_stats(tmp_path, capsys, change, reason):
    out = tmp_path / "res"
    run_experiment("zdt1", "nsga2", out=out, variants=(False,), **TINY)
    path = plan("zdt1", "nsga2", runs=2, evals=40, variants=(False,))[1].path(out)
    good = json.loads(path.read_text())
    bad = dict(good)
    change(bad)
    path.write_text(json.dumps(bad))
    capsys.readouterr()
    assert main(["stats", str(out)]) == 2
    err = _one_line(capsys.readouterr().err)
    assert f"{path} is a corrupt run record: " in err and reason in err and "numpy" not in err.lower()
    report = run_experiment("zdt1", "nsga2", out=out, variants=(False,), **TINY)
    assert (report.skipped, report.completed) == (1, 1)
    err = capsys.readouterr().err
    assert f"{path} is a corrupt run record: " in err and reason in err and err.endswith("; recomputing it\n")
    assert json.loads(path.read_text())["F"] == good["F"]                       # deterministic: the same run
    assert main(["stats", str(out)]) == 0


def test_a_duplicate_run_is_refused_naming_both_files(tmp_path, capsys):
    out = tmp_path / "res"
    run_experiment("dtlz2", "nsga2", out=out, **{**TINY, "evals": 100, "pop_size": 40})
    shutil.copytree(out / "dtlz2", out / "dtlz2-m3")           # the same runs under a second name
    assert main(["stats", str(out)]) == 2
    err = _one_line(capsys.readouterr().err)
    assert "is a corrupt run record: a duplicate of" in err and "dtlz2-m3" in err


def test_validate_record_messages_name_the_file():
    rec = {"problem": "zdt1", "n_obj": 2, "algorithm": "nsga2", "molsp": False, "seed": 3, "F": "oops"}
    with pytest.raises(CorruptRecordError, match=r"^x/nsga2/seed_3\.json is a corrupt run record: F must be a "
                                                 r"list of rows, got a JSON str$"):
        validate_record(rec, "x/nsga2/seed_3.json")
    with pytest.raises(CorruptRecordError, match="n_obj must be a positive integer"):
        validate_record({**rec, "n_obj": "2"}, "x/nsga2/seed_3.json")


# ----------------------------------------------------------------------------- 4. atomic outputs, disk errors, mode

def test_records_and_outputs_get_the_usual_mode(tmp_path):
    old = os.umask(0o022)
    try:
        run_experiment("zdt1", "nsga2", out=tmp_path / "res", **TINY)
        write_json_atomic(tmp_path / "x.json", {})
    finally:
        os.umask(old)
    for path in [*_records(tmp_path / "res"), tmp_path / "res" / "settings.json", tmp_path / "x.json"]:
        assert stat.S_IMODE(path.stat().st_mode) == 0o644, path


@pytest.fixture
def full_disk(monkeypatch):
    """Call it to fill the disk: every fsync (the last step of an atomic write) and savefig then fail."""
    from matplotlib.figure import Figure

    def no_space(*args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    real_savefig = Figure.savefig

    def savefig(self, fname, *args, **kwargs):
        real_savefig(self, fname, *args, **kwargs)        # half a file is on disk ...
        no_space()                                        # ... when the disk fills

    def fill():
        monkeypatch.setattr(os, "fsync", no_space)
        monkeypatch.setattr(Figure, "savefig", savefig)

    return fill


def test_run_on_a_full_disk_keeps_its_finished_run(tmp_path, capsys, monkeypatch, full_disk):
    monkeypatch.setenv("TMPDIR", str(tmp_path / "spare"))
    (tmp_path / "spare").mkdir()
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", None)         # re-read TMPDIR
    full_disk()
    out = tmp_path / "run.json"
    code = main(["run", "--problem", "zdt1", "--algorithm", "nsga2", "--seed", "0", "--evals", "40",
                 "--pop-size", "20", "--out", str(out)])
    err = _one_line(capsys.readouterr().err)
    assert code == 1 and f"cannot write {out} (No space left on device)" in err
    assert not out.exists() and [p.name for p in tmp_path.iterdir() if p.is_file()] == []
    kept = list((tmp_path / "spare").glob("moo-run-run-*.json"))
    assert len(kept) == 1 and str(kept[0]) in err
    rec = json.loads(kept[0].read_text())
    assert rec["problem"] == "zdt1" and rec["seed"] == 0 and len(rec["F"]) > 0


def test_stats_plot_and_experiment_on_a_full_disk_one_line_exit_1_no_partial_file(tmp_path, capsys, full_disk):
    res = tmp_path / "res"
    run_experiment("zdt1", "nsga2", out=res, **TINY)
    full_disk()
    capsys.readouterr()
    out = tmp_path / "tables"
    out.mkdir()
    assert main(["stats", str(res), "--out", str(out / "t.md"), "--runs-out", str(out / "runs.csv")]) == 1
    err = _one_line(capsys.readouterr().err)
    assert f"cannot write {out / 't.md'} (No space left on device)" in err
    assert list(out.iterdir()) == []
    assert main(["plot", str(res), "--out", str(tmp_path / "fig"), "--format", "png"]) == 1
    err = _one_line(capsys.readouterr().err)
    assert "cannot write a figure in" in err and "No space left on device" in err
    assert list((tmp_path / "fig").iterdir()) == []
    before = sorted(p.name for p in _records(res))
    assert main(["experiment", "--problem", "zdt1", "--algorithms", "nsga2", "--runs", "3", "--evals", "40",
                 "--pop-size", "20", "--out", str(res)]) == 1
    err = _one_line(capsys.readouterr().err.splitlines(keepends=True)[-1])
    assert f"cannot write a record in {res} (No space left on device)" in err and "rerun" in err
    assert sorted(p.name for p in _records(res)) == before
    assert not [p for p in res.rglob("*") if p.is_file() and p.stat().st_size == 0 and p.name != ".lock"]
