"""moo.experiment: the grid, seeds, atomic writes, resumption, parallel runs, and the CLI end to end."""

from __future__ import annotations

import contextlib
import csv
import json
import multiprocessing
import os
import signal
import subprocess
import sys
import threading
import time
from concurrent.futures import Future, ThreadPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np
import pytest

import moo.runner
from moo.__main__ import main
from moo.experiment import load_records, plan, run_experiment, run_seeds, write_json_atomic
from moo.stats import INDICATORS

# ----------------------------------------------------------------------------- seeds and plan


def test_run_seeds_from_seed_sequence_and_prefix_stable():
    expected = [int(c.generate_state(1)[0]) for c in np.random.SeedSequence(5).spawn(4)]
    assert run_seeds(4, base_seed=5) == expected
    assert run_seeds(6, base_seed=5)[:4] == expected          # more runs extend the grid
    assert len(set(run_seeds(50))) == 50
    with pytest.raises(ValueError, match="runs"):
        run_seeds(0)
    with pytest.raises(TypeError, match="base_seed"):
        run_seeds(2, base_seed=1.5)


def test_plan_grid_and_paths(tmp_path):
    specs = plan("zdt1", "nsga2,nsga3", runs=3, evals=300, max_leaders=4)
    assert len(specs) == 3 * 2 * 2
    assert {(s.algorithm, s.molsp) for s in specs} == {(a, v) for a in ("nsga2", "nsga3") for v in (False, True)}
    assert all((s.max_leaders == 4) == s.molsp for s in specs)
    # common random numbers: run i has one seed for every algorithm and variant
    for i, seed in enumerate(run_seeds(3)):
        assert {s.seed for s in specs if s.run_index == i} == {seed}
    s = next(s for s in specs if s.molsp and s.algorithm == "nsga3")
    assert s.path(tmp_path) == tmp_path / "zdt1" / "nsga3+molsp" / f"seed_{s.seed}.json"
    d = plan("dtlz2", ["nsga2"], runs=1, evals=300, n_obj=5)[0]
    assert d.path(tmp_path).parent.parent.name == "dtlz2-m5"
    assert len(plan("zdt1", "all", runs=1, evals=300)) == 20


@pytest.mark.parametrize("kwargs, exc, match", [
    (dict(problem="nope"), ValueError, "unknown problem"),
    (dict(algorithms="nsga2,foo"), ValueError, "unknown algorithm 'foo'"),
    (dict(algorithms=[]), ValueError, "at least one"),
    (dict(runs=0), ValueError, "runs must be >= 1"),
    (dict(evals=2.5), TypeError, "evals must be an integer"),
    (dict(max_leaders=0), ValueError, "max_leaders"),
    (dict(variants=()), ValueError, "variants"),
])
def test_plan_bad_arguments(kwargs, exc, match):
    args = dict(problem="zdt1", algorithms="nsga2", runs=2, evals=300)
    args.update(kwargs)
    with pytest.raises(exc, match=match):
        plan(args.pop("problem"), args.pop("algorithms"), **args)


# ----------------------------------------------------------------------------- atomic writes

def test_write_json_atomic_writes_and_leaves_no_temp(tmp_path):
    path = tmp_path / "a" / "b" / "seed_1.json"
    write_json_atomic(path, {"x": [1, 2]})
    assert json.loads(path.read_text()) == {"x": [1, 2]}
    assert [p.name for p in path.parent.iterdir()] == ["seed_1.json"]


def test_write_json_atomic_failure_keeps_old_file(tmp_path):
    path = tmp_path / "seed_1.json"
    write_json_atomic(path, {"old": True})
    before = path.read_bytes()
    with pytest.raises(TypeError):
        write_json_atomic(path, {"big": list(range(10000)), "bad": object()})   # fails mid-dump
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["seed_1.json"]            # temp file removed


# ----------------------------------------------------------------------------- resumption

class _FakeResult:
    def __init__(self, problem, algorithm, seed, evals, n_obj, molsp, max_leaders, pop_size):
        self.wall_time = 0.0
        self._d = {"problem": problem, "n_obj": 2 if n_obj is None else n_obj, "algorithm": algorithm,
                   "molsp": molsp, "max_leaders": max_leaders, "seed": seed, "budget": evals,
                   "pop_size": pop_size,
                   "F": [[float(seed % 7), 1.0]], "hv_ref_point": [10.0, 10.0]}

    def to_dict(self):
        return dict(self._d)


@pytest.fixture
def fake_run(monkeypatch):
    """Replace moo.runner.run by a counting stub; ``calls`` lists (algorithm, molsp, seed)."""
    calls = []
    state = {"fail_after": None}

    def run(problem, algorithm, *, seed, evals, n_obj=None, molsp=False, pop_size=92, max_leaders=None,
            setup=None):  # runner.run's signature
        if state["fail_after"] is not None and len(calls) >= state["fail_after"]:
            raise KeyboardInterrupt
        calls.append((algorithm, molsp, seed))
        return _FakeResult(problem, algorithm, seed, evals, n_obj, molsp, max_leaders, pop_size)

    monkeypatch.setattr(moo.runner, "run", run)
    return calls, state


def test_resume_after_interrupt_computes_only_missing_runs(tmp_path, fake_run):
    calls, state = fake_run
    state["fail_after"] = 5
    with pytest.raises(KeyboardInterrupt):
        run_experiment("zdt1", "nsga2,nsga3", runs=3, evals=300, out=tmp_path, progress=False)
    assert len(calls) == 5 and len(load_records(tmp_path)) == 5
    done_before = set(calls)
    state["fail_after"] = None
    report = run_experiment("zdt1", "nsga2,nsga3", runs=3, evals=300, out=tmp_path, progress=False)
    assert (report.total, report.skipped, report.completed) == (12, 5, 7)
    assert len(calls) == 12 and not done_before & set(calls[5:])     # nothing recomputed
    assert len(load_records(tmp_path)) == 12
    # nothing left to do; raising --runs only adds the new seeds
    assert run_experiment("zdt1", "nsga2,nsga3", runs=3, evals=300, out=tmp_path).completed == 0
    report = run_experiment("zdt1", "nsga2,nsga3", runs=4, evals=300, out=tmp_path, progress=False)
    assert (report.skipped, report.completed) == (12, 4) and {c[2] for c in calls[12:]} == {run_seeds(4)[3]}


def test_resume_rejects_other_settings_and_redoes_corrupt_files(tmp_path, fake_run):
    _calls, _ = fake_run
    run_experiment("zdt1", "nsga2", runs=1, evals=300, out=tmp_path, progress=False)
    with pytest.raises(ValueError, match=r"other settings.*budget"):
        run_experiment("zdt1", "nsga2", runs=1, evals=400, out=tmp_path, progress=False)
    spec = plan("zdt1", "nsga2", runs=1, evals=300)[0]
    spec.path(tmp_path).write_text('{"problem": "zdt1", "F": [[1')         # truncated by hand
    report = run_experiment("zdt1", "nsga2", runs=1, evals=300, out=tmp_path, progress=False)
    assert report.completed == 1 and json.loads(spec.path(tmp_path).read_text())["seed"] == spec.seed


def test_resume_real_runs_keep_their_files(tmp_path):
    kw = dict(runs=2, evals=60, pop_size=20, out=tmp_path, progress=False)
    run_experiment("zdt1", "nsga2", variants=(False,), **kw)           # the plain half of the grid first
    first = {p: p.stat().st_mtime_ns for p in tmp_path.rglob("seed_*.json")}
    assert len(first) == 2
    report = run_experiment("zdt1", "nsga2", **kw)
    assert (report.skipped, report.completed) == (2, 2)
    assert all(p.stat().st_mtime_ns == t for p, t in first.items())
    recs = load_records(tmp_path)
    assert sorted((r["molsp"], r["seed"]) for r in recs) == sorted((v, s) for v in (False, True)
                                                                    for s in run_seeds(2))
    # same seed, same result: the record equals a direct call of the runner
    r = moo.runner.run("zdt1", "nsga2", seed=run_seeds(2)[0], evals=60, pop_size=20)
    rec = next(x for x in recs if not x["molsp"] and x["seed"] == r.seed)
    assert np.array_equal(np.array(rec["F"]), r.F)


def test_workers_give_the_same_records(tmp_path):
    kw = dict(runs=2, evals=60, pop_size=20, progress=False)
    run_experiment("zdt1", "nsga2", out=tmp_path / "serial", **kw)
    report = run_experiment("zdt1", "nsga2", out=tmp_path / "parallel", workers=2, **kw)
    assert report.completed == 4
    serial, parallel = load_records(tmp_path / "serial"), load_records(tmp_path / "parallel")
    assert [(r["molsp"], r["seed"], r["F"], r["n_evals"]) for r in serial] == \
           [(r["molsp"], r["seed"], r["F"], r["n_evals"]) for r in parallel]


def test_progress_goes_to_stderr_only_when_asked(tmp_path, fake_run, capsys):
    run_experiment("zdt1", "nsga2", runs=1, evals=300, out=tmp_path / "a", progress=True)
    err = capsys.readouterr().err
    assert "/2 [" in err and "runs/s" in err and "zdt1/nsga2" in err         # tqdm: done/total [elapsed<ETA, rate]
    run_experiment("zdt1", "nsga2", runs=1, evals=300, out=tmp_path / "b")   # stderr not a TTY under pytest
    assert capsys.readouterr().err == ""


# ----------------------------------------------------------------------------- CLI

def test_cli_experiment_and_stats_end_to_end(tmp_path):
    out = tmp_path / "res"
    code = main(["experiment", "--problem", "zdt1", "--algorithms", "nsga2,nsga3", "--runs", "2",
                 "--evals", "300", "--out", str(out)])
    assert code == 0
    files = sorted(p.relative_to(out).parent.as_posix() for p in out.rglob("seed_*.json"))
    assert files == ["zdt1/nsga2"] * 2 + ["zdt1/nsga2+molsp"] * 2 + ["zdt1/nsga3"] * 2 + ["zdt1/nsga3+molsp"] * 2
    for rec in load_records(out):
        assert rec["budget"] == 300 and 300 <= rec["n_evals"] < 300 + 92
    table, runs_csv = tmp_path / "t.csv", tmp_path / "runs.csv"
    assert main(["stats", str(out), "--out", str(table), "--runs-out", str(runs_csv)]) == 0
    rows = list(csv.DictReader(table.open()))
    assert len(rows) == 2 * len(INDICATORS) and {r["algorithm"] for r in rows} == {"nsga2", "nsga3"}
    assert all(int(r["n_plain"]) == 2 and int(r["n_molsp"]) == 2 for r in rows if r["indicator"] == "hv")
    per_run = list(csv.DictReader(runs_csv.open()))
    assert len(per_run) == 8 and all(float(r["igd"]) > 0 and float(r["igd_plus"]) > 0 for r in per_run)
    for ext in (".md", ".tex"):
        assert main(["stats", str(out), "--out", str(tmp_path / f"t{ext}")]) == 0
    assert "nsga2/MO-LSP" in (tmp_path / "t.md").read_text()
    assert r"\begin{tabular}" in (tmp_path / "t.tex").read_text()


@pytest.mark.parametrize("args, message", [
    (["experiment", "--problem", "zdt1", "--algorithms", "nsga2,foo", "--runs", "2", "--evals", "300"],
     "unknown algorithm 'foo'"),
    (["experiment", "--problem", "nope", "--runs", "2", "--evals", "300"], "unknown problem"),
    (["experiment", "--problem", "zdt1", "--runs", "0", "--evals", "300"], "--runs must be >= 1"),
    (["experiment", "--problem", "zdt1", "--runs", "1", "--evals", "50"], "population size"),
    (["experiment", "--problem", "zdt1", "--runs", "1", "--evals", "300", "--workers", "0"], "--workers"),
    (["experiment", "--problem", "zdt1", "--runs", "1", "--evals", "300", "--max-leaders", "0"],
     "--max-leaders must be >= 1"),
    (["experiment", "--problem", "zdt1", "--runs", "x", "--evals", "300"], "invalid int value"),
    (["experiment", "--problem", "zdt1", "--evals", "300"], "required: --runs"),
])
def test_cli_experiment_bad_arguments(tmp_path, capsys, args, message):
    code = main([*args, "--out", str(tmp_path / "res")])
    err = capsys.readouterr().err
    assert code == 2 and message in err and err.count("\n") == 1
    assert not (tmp_path / "res").exists()


def test_cli_stats_bad_arguments(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    cases = [(["stats", str(tmp_path / "missing")], "does not exist"),
             (["stats", str(tmp_path / "empty"), "--out", str(tmp_path / "t.xlsx")], "--out must end in"),
             (["stats", str(tmp_path / "empty")], "no run records"),
             (["stats", str(tmp_path / "empty"), "--alpha", "2"], "--alpha")]
    for args, message in cases:
        code = main(args)
        err = capsys.readouterr().err
        assert code == 2 and message in err and err.count("\n") == 1, (args, err)


def test_cli_out_is_a_file(tmp_path, capsys):
    (tmp_path / "f").write_text("")
    code = main(["experiment", "--problem", "zdt1", "--runs", "1", "--evals", "300", "--out", str(tmp_path / "f")])
    assert code == 2 and "not a directory" in capsys.readouterr().err


def test_python_dash_m_exit_code_and_one_line(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "moo", "experiment", "--problem", "zdt1", "--runs", "-1",
                           "--evals", "300", "--out", str(tmp_path / "r")], capture_output=True, text=True,
                          cwd=Path(__file__).resolve().parents[1], check=False)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.strip().splitlines() == ["python -m moo: error: --runs must be >= 1, got -1"]


# ----------------------------------------------------------------------------- run store: settings, failures

def test_rerun_with_another_pop_size_is_an_error_not_a_skip(tmp_path, fake_run):
    run_experiment("zdt1", "nsga2", runs=1, evals=300, out=tmp_path, progress=False)
    with pytest.raises(ValueError, match=r"settings\.json: the directory holds runs with other settings: "
                                         r"pop_size 92 \(this grid: 50\)"):
        run_experiment("zdt1", "nsga2", runs=1, evals=300, pop_size=50, out=tmp_path, progress=False)
    (tmp_path / "settings.json").unlink()          # a directory from before settings.json: its records say
    with pytest.raises(ValueError, match=r"seed_\d+\.json holds a run with other settings: pop_size 92 "
                                         r"\(this grid: 50\)"):
        run_experiment("zdt1", "nsga2", runs=1, evals=300, pop_size=50, out=tmp_path, progress=False)


def test_cli_rerun_with_other_evals_is_a_one_line_usage_error(tmp_path, fake_run, capsys):
    args = ["experiment", "--problem", "zdt1", "--algorithms", "nsga2", "--runs", "1", "--out", str(tmp_path)]
    assert main([*args, "--evals", "300"]) == 0
    capsys.readouterr()
    assert main([*args, "--evals", "400"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "holds runs with other settings: --evals 300 (this grid: 400)" in err
    assert "settings.json" in err and "Traceback" not in err


@pytest.fixture
def failing_run(fake_run, monkeypatch):
    """The counting stub, raising ValueError for the MO-LSP runs of seed index 1."""
    calls, _ = fake_run
    stub, bad_seed = moo.runner.run, run_seeds(2)[1]

    def run(problem, algorithm, *, seed, molsp=False, **kw):
        if molsp and seed == bad_seed:
            raise ValueError("boom in the run")
        return stub(problem, algorithm, seed=seed, molsp=molsp, **kw)

    monkeypatch.setattr(moo.runner, "run", run)
    return calls, bad_seed


def test_keep_going_records_the_failure_and_finishes_the_grid(tmp_path, failing_run):
    _calls, bad_seed = failing_run
    report = run_experiment("zdt1", "nsga2", runs=3, evals=300, out=tmp_path, keep_going=True, progress=False)
    assert (report.completed, len(report.failed)) == (5, 1) and len(load_records(tmp_path)) == 5
    failed = json.loads(report.failed[0].read_text())
    assert report.failed[0].name == f"seed_{bad_seed}.failed.json" and report.failed[0].parent.name == "nsga2+molsp"
    assert failed["status"] == "failed" and failed["error"] == "ValueError: boom in the run"
    assert "Traceback" in failed["traceback"] and "boom in the run" in failed["traceback"]
    assert (failed["seed"], failed["molsp"], failed["budget"]) == (bad_seed, True, 300)
    # a rerun retries the failed run only; its success removes the failure record
    from moo.experiment import prepare
    grid = prepare("zdt1", "nsga2", runs=3, evals=300, out=tmp_path)
    assert (grid.skipped, len(grid.todo), grid.retried) == (5, 1, 1)


def test_without_keep_going_the_first_failure_stops_the_grid(tmp_path, failing_run):
    from moo.experiment import RunFailedError

    calls, bad_seed = failing_run
    with pytest.raises(RunFailedError, match=r"zdt1/nsga2\+molsp run 1 .* failed: ValueError: boom in the run "
                                             r"\(traceback in .*failed\.json\)") as info:
        run_experiment("zdt1", "nsga2", runs=3, evals=300, out=tmp_path, progress=False)
    assert info.value.path.is_file() and info.value.spec.seed == bad_seed
    assert len(calls) == 3 and len(load_records(tmp_path)) == 3       # runs 0, 0+molsp, 1 kept; 2 not started


def test_retried_failure_is_replaced_by_the_record(tmp_path, failing_run, fake_run, monkeypatch):
    run_experiment("zdt1", "nsga2", runs=2, evals=300, out=tmp_path, keep_going=True, progress=False)
    assert len(list(tmp_path.rglob("*.failed.json"))) == 1
    _calls, _ = fake_run
    monkeypatch.setattr(moo.runner, "run", lambda problem, algorithm, **kw: _FakeResult(
        problem, algorithm, kw["seed"], kw["evals"], kw.get("n_obj"), kw["molsp"], kw["max_leaders"],
        kw["pop_size"]))
    report = run_experiment("zdt1", "nsga2", runs=2, evals=300, out=tmp_path, progress=False)
    assert (report.skipped, report.completed, report.failed) == (3, 1, ())
    assert not list(tmp_path.rglob("*.failed.json")) and len(load_records(tmp_path)) == 4


def test_cli_failures_exit_1_with_one_line(tmp_path, failing_run, capsys):
    args = ["experiment", "--problem", "zdt1", "--algorithms", "nsga2", "--runs", "3", "--evals", "300"]
    assert main([*args, "--out", str(tmp_path / "a")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("python -m moo: error: run zdt1/nsga2+molsp run 1") and "boom in the run" in err[-1]
    assert "rerun to resume" in err[-1]
    assert main([*args, "--out", str(tmp_path / "b"), "--keep-going"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("python -m moo: error: 1 of 6 runs failed; tracebacks in ")
    assert err[-1].endswith(".failed.json") and len(load_records(tmp_path / "b")) == 5


def test_any_executor_thread_pool_gives_the_serial_records(tmp_path):
    kw = dict(runs=2, evals=60, pop_size=20, progress=False)
    run_experiment("zdt1", "nsga2", out=tmp_path / "serial", **kw)
    with ThreadPoolExecutor(2) as pool:
        report = run_experiment("zdt1", "nsga2", out=tmp_path / "threads", executor=pool, **kw)
    assert report.completed == 4
    key = ("molsp", "seed", "F", "X", "hv_history", "n_evals")
    assert [[r[k] for k in key] for r in load_records(tmp_path / "serial")] == \
           [[r[k] for k in key] for r in load_records(tmp_path / "threads")]
    with pytest.raises(ValueError, match="not both"):
        run_experiment("zdt1", "nsga2", out=tmp_path / "x", executor=pool, workers=2, **kw)
    with pytest.raises(TypeError, match=r"executor must be a concurrent\.futures\.Executor"):
        run_experiment("zdt1", "nsga2", out=tmp_path / "x", executor="dask", **kw)


def test_executor_stops_at_a_failure_and_keeps_what_finished(tmp_path, failing_run, monkeypatch):
    from moo.experiment import RunFailedError

    calls, _ = failing_run
    stub = moo.runner.run
    monkeypatch.setattr(moo.runner, "run", lambda *a, **kw: (time.sleep(0.05), stub(*a, **kw))[1])
    with ThreadPoolExecutor(1) as pool, pytest.raises(RunFailedError):
        run_experiment("zdt1", "nsga2", runs=4, evals=300, out=tmp_path, executor=pool, progress=False)
    # the 4th run failed; the queued ones were cancelled (at most the one in flight ran on)
    assert len(list(tmp_path.rglob("*.failed.json"))) == 1 and len(calls) <= 4
    assert 3 <= len(load_records(tmp_path)) <= 4
    # with instant runs everything has finished when the failure is seen: all of it is kept
    monkeypatch.setattr(moo.runner, "run", stub)
    with ThreadPoolExecutor(1) as pool, pytest.raises(RunFailedError):
        run_experiment("zdt1", "nsga2", runs=4, evals=300, out=tmp_path / "b", executor=pool, progress=False)
    assert len(load_records(tmp_path / "b")) == 7


def test_killed_pool_process_is_replaced_and_its_runs_recomputed(tmp_path, capsys):
    """SIGKILL of a pool process mid-grid: a fresh pool reruns what the broken one lost; nothing is missing."""
    kw = dict(runs=2, evals=4000, pop_size=20, progress=False)
    run_experiment("zdt1", "nsga2", out=tmp_path / "serial", **kw)
    done = {}
    driver = threading.Thread(target=lambda: done.setdefault(
        "report", run_experiment("zdt1", "nsga2", out=tmp_path / "pool", workers=2, **kw)))
    driver.start()
    deadline = time.monotonic() + 120
    while not any((tmp_path / "pool").rglob("seed_*.json")) and time.monotonic() < deadline:
        time.sleep(0.01)
    victims = multiprocessing.active_children()              # the pool's two spawned processes
    assert len(victims) == 2, "the pool's processes were not found when the first record arrived"
    os.kill(victims[0].pid, signal.SIGKILL)                  # mid-grid: 3 of the 4 runs are not recorded yet
    driver.join(timeout=180)
    assert not driver.is_alive()
    assert done["report"].completed == 4
    err = capsys.readouterr().err
    assert "a pool process died; resubmitting the " in err and "(restart 1 of 3)" in err
    key = ("molsp", "seed", "F", "X", "hv_history", "n_evals")
    assert [[r[k] for k in key] for r in load_records(tmp_path / "serial")] == \
           [[r[k] for k in key] for r in load_records(tmp_path / "pool")]


def test_pool_restarts_are_bounded_and_other_executors_stop(tmp_path, capsys):
    from moo.executors import POOL_RESTARTS, RestartingPool

    def broken(*args, **kwargs) -> Future:
        fut: Future = Future()
        fut.set_exception(BrokenProcessPool("a process in the pool was terminated abruptly"))
        return fut

    class DiesEveryTime(RestartingPool):
        """Every run loses its process (a thread pool stands in for the processes)."""

        pools = 0

        def _new(self):
            DiesEveryTime.pools += 1
            return ThreadPoolExecutor(1)

        submit = staticmethod(broken)

    class CannotRestart(ThreadPoolExecutor):
        submit = staticmethod(broken)

    kw = dict(runs=1, evals=300, pop_size=20, progress=False)
    with pytest.raises(BrokenProcessPool, match=f"died again after {POOL_RESTARTS} restarts of the pool"):
        run_experiment("zdt1", "nsga2", out=tmp_path / "a", executor=DiesEveryTime(2), **kw)
    assert DiesEveryTime.pools == 1 + POOL_RESTARTS and not load_records(tmp_path / "a")
    assert capsys.readouterr().err.count("resubmitting the 2 runs lost with it") == POOL_RESTARTS
    with CannotRestart(1) as pool, pytest.raises(BrokenProcessPool, match="terminated abruptly"):
        run_experiment("zdt1", "nsga2", out=tmp_path / "b", executor=pool, **kw)
    assert "resubmitting" not in capsys.readouterr().err


# ----------------------------------------------------------------------------- CLI: --out, corrupt records, help

@pytest.mark.parametrize("where, message", [("file/sub", "--out: cannot create directory"),
                                            ("file", "--out: '{}' exists and is not a directory"),
                                            ("/proc/moo-results", "--out: cannot create directory"),
                                            ("", "--out must be a directory path")])
def test_cli_experiment_unusable_out(tmp_path, capsys, where, message):
    (tmp_path / "file").write_text("")
    out = "" if not where else (where if where.startswith("/") else str(tmp_path / where))
    code = main(["experiment", "--problem", "zdt1", "--runs", "1", "--evals", "300", "--out", out])
    err = capsys.readouterr().err
    assert code == 2 and message.format(out) in err and err.count("\n") == 1, err


def test_cli_stats_and_plot_name_a_corrupt_record(tmp_path, fake_run, capsys):
    run_experiment("zdt1", "nsga2", runs=2, evals=300, out=tmp_path / "res", progress=False)
    bad = sorted((tmp_path / "res").rglob("seed_*.json"))[1]
    bad.write_text('{"problem": "zdt1", "F": [[1')
    for cmd in (["stats", str(tmp_path / "res")], ["plot", str(tmp_path / "res"), "--out", str(tmp_path / "fig")]):
        assert main(cmd) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"{bad} is not a readable run record" in err, err
    bad.write_text('{"problem": "zdt1"}')
    assert main(["stats", str(tmp_path / "res")]) == 2
    assert f"{bad} is not a run record: missing field(s) n_obj" in capsys.readouterr().err


def test_cli_deprecated_molsp_max_leaders_alias(tmp_path, fake_run, capsys):
    _calls, _ = fake_run
    args = ["experiment", "--problem", "zdt1", "--algorithms", "nsga2", "--runs", "1", "--evals", "300"]
    assert main([*args, "--molsp-max-leaders", "3", "--out", str(tmp_path / "a")]) == 0
    assert "--molsp-max-leaders is deprecated, use --max-leaders" in capsys.readouterr().err
    assert {r["max_leaders"] for r in load_records(tmp_path / "a") if r["molsp"]} == {3}
    assert main([*args, "--molsp-max-leaders", "3", "--max-leaders", "3", "--out", str(tmp_path / "b")]) == 2
    assert "give --max-leaders only" in capsys.readouterr().err


@pytest.mark.parametrize("command", [[], ["run"], ["experiment"], ["stats"], ["plot"]])
def test_every_help_has_an_example_and_the_exit_codes(command, capsys):
    with pytest.raises(SystemExit) as info:
        main([*command, "--help"])
    out = capsys.readouterr().out
    assert info.value.code == 0 and "example" in out and "python -m moo " + " ".join(command) in out
    assert "exit codes: 0 done; 1 the work failed" in out and "2 bad arguments" in out


def _children(pid: int) -> list[int]:
    """Processes whose parent is ``pid`` (from /proc)."""
    kids = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                stat = Path(f"/proc/{entry}/stat").read_text()
            except OSError:
                continue
            fields = stat[stat.rindex(")") + 2:].split()
            if int(fields[1]) == pid and fields[0] != "Z":
                kids.append(int(entry))
    return kids


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat[stat.rindex(")") + 2:].split()[0] != "Z"          # a zombie has exited


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc")
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL])
def test_pool_processes_exit_with_a_killed_driver(tmp_path, sig):
    """SIGTERM or SIGKILL to the driver of --workers 2: its pool processes exit too (issue 23, item 5)."""
    cmd = [sys.executable, "-m", "moo", "experiment", "--problem", "zdt1", "--algorithms", "nsga2", "--runs", "2",
           "--evals", "10000000", "--pop-size", "20", "--workers", "2", "--out", str(tmp_path / "res")]
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    driver = subprocess.Popen(cmd, cwd=Path(__file__).resolve().parents[1], env=env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    pool: list[int] = []
    try:
        deadline = time.monotonic() + 60
        while len(pool) < 2 and time.monotonic() < deadline:
            time.sleep(0.2)
            pool = [p for p in _children(driver.pid)
                    if "resource_tracker" not in Path(f"/proc/{p}/cmdline").read_bytes().decode(errors="replace")]
        assert len(pool) >= 2, "the pool's processes did not start"
        time.sleep(2.0)                                  # the workers are in their runs
        os.kill(driver.pid, sig)
        driver.wait(timeout=30)
        deadline = time.monotonic() + 15
        while any(_alive(p) for p in pool) and time.monotonic() < deadline:
            time.sleep(0.1)
        left = [p for p in pool if _alive(p)]
        assert not left, f"pool processes {left} outlived their driver"
    finally:                                             # never leave a stray process behind
        for p in [driver.pid, *pool]:
            if p == driver.pid or _alive(p):
                with contextlib.suppress(ProcessLookupError):
                    os.kill(p, signal.SIGKILL)
        driver.wait(timeout=30)
