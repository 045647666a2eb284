"""Experiment grids on a real Dask cluster: worker processes on 127.0.0.1, one killed mid-grid, and the CLI
against a `dask scheduler` with two `dask worker` processes. Small grids (ZDT1, a few thousand evaluations)."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import threading
import time
from concurrent.futures import Executor
from pathlib import Path

import pytest

distributed = pytest.importorskip("distributed")

from moo.executors import open_executor  # noqa: E402
from moo.experiment import run_experiment  # noqa: E402
from moo.store import load_records  # noqa: E402

GRID = dict(problem="zdt1", algorithms="nsga2", runs=3, evals=6000, pop_size=20)
CLI_GRID = ["--problem", "zdt1", "--algorithms", "nsga2", "--runs", "3", "--evals", "6000", "--pop-size", "20"]
REPO = Path(__file__).resolve().parents[1]
# What a run computes; wall_time_s and versions legitimately differ between machines.
SAME = ("problem", "n_obj", "algorithm", "molsp", "seed", "run_index", "pop_size", "budget", "n_evals", "n_gen",
        "molsp_evals", "hv", "F", "X", "hv_history", "hv_ref_point", "molsp_ref_point", "max_leaders")


def _content(out):
    return [{k: rec[k] for k in SAME} | {"file": Path(rec["_path"]).relative_to(out).as_posix()}
            for rec in load_records(out)]


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("serial")
    run_experiment(out=out, progress=False, **GRID)
    return _content(out)


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=":0") as lc, distributed.Client(lc) as client:
        yield lc, client


class _Counting(Executor):
    """Counts the runs submitted to an executor."""

    def __init__(self, inner):
        self.inner, self.submitted = inner, 0

    def submit(self, fn, /, *args, **kwargs):
        self.submitted += 1
        return self.inner.submit(fn, *args, **kwargs)


def test_local_cluster_gives_the_serial_records_and_a_rerun_computes_nothing(tmp_path, serial, cluster):
    lc, _ = cluster
    with open_executor("dask", scheduler=lc.scheduler_address) as ex:
        report = run_experiment(out=tmp_path, executor=ex, progress=False, **GRID)
        assert (report.total, report.skipped, report.completed) == (6, 0, 6)
        assert _content(tmp_path) == serial
        stamps = {p: p.stat().st_mtime_ns for p in tmp_path.rglob("seed_*.json")}
        counting = _Counting(ex)
        again = run_experiment(out=tmp_path, executor=counting, progress=False, **GRID)
    assert (again.skipped, again.completed, counting.submitted) == (6, 0, 0)
    assert {p: p.stat().st_mtime_ns for p in tmp_path.rglob("seed_*.json")} == stamps


def test_worker_killed_mid_grid_loses_nothing(tmp_path, serial, cluster):
    _lc, client = cluster
    client.wait_for_workers(2, timeout=60)
    pids = client.run(os.getpid)
    done = {}
    driver = threading.Thread(target=lambda: done.setdefault(
        "report", run_experiment(out=tmp_path, executor=client.get_executor(), progress=False, **GRID)))
    driver.start()
    deadline = time.monotonic() + 60
    while not any(tmp_path.rglob("seed_*.json")) and time.monotonic() < deadline:
        time.sleep(0.01)
    busy = {w: ts for w, ts in client.processing().items() if ts}
    assert busy, "no worker was running a run when the first record arrived"
    victim = next(iter(busy))
    os.kill(pids[victim], signal.SIGKILL)                    # mid-grid, while it runs
    driver.join(timeout=120)
    assert not driver.is_alive()
    assert done["report"].completed == 6
    assert _content(tmp_path) == serial                      # every record, each the serial one


@contextlib.contextmanager
def _dask_cluster(tmp_path, n_workers: int):
    """A `dask scheduler` and ``n_workers`` `dask worker` processes on 127.0.0.1: yields (address, scheduler)."""
    sched_file = tmp_path / "scheduler.json"
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    procs = [subprocess.Popen([sys.executable, "-m", "dask", "scheduler", "--host", "127.0.0.1", "--port", "0",
                               "--no-dashboard", "--scheduler-file", str(sched_file)],
                              cwd=REPO, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        deadline = time.monotonic() + 60
        while not sched_file.exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        procs += [subprocess.Popen([sys.executable, "-m", "dask", "worker", "--scheduler-file", str(sched_file),
                                    "--nthreads", "1", "--no-dashboard", "--host", "127.0.0.1"], cwd=REPO, env=env,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for _ in range(n_workers)]
        with distributed.Client(scheduler_file=str(sched_file), timeout=60) as client:
            client.wait_for_workers(n_workers, timeout=60)
            address = client.scheduler.address
        yield address, procs[0]
    finally:
        for proc in procs[1:]:
            proc.kill()                      # the workers: no graceful shutdown needed
        procs[0].terminate()
        for proc in procs:
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()


@pytest.fixture
def dask_processes(tmp_path):
    """A `dask scheduler` and two `dask worker` processes on 127.0.0.1; yields the scheduler's address."""
    with _dask_cluster(tmp_path, 2) as (address, _):
        yield address


def test_cli_on_dask_scheduler_and_two_workers(tmp_path, serial, dask_processes, capsys, monkeypatch):
    out = tmp_path / "res"
    cmd = [sys.executable, "-m", "moo", "experiment", *CLI_GRID, "--out", str(out), "--executor", "dask",
           "--scheduler", dask_processes]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=REPO, timeout=180, check=False)
    assert proc.returncode == 0, proc.stderr
    assert _content(out) == serial
    assert proc.stderr == ""                             # stderr is not a terminal: quiet
    from moo.__main__ import main  # the rerun in-process (no second start-up), on a terminal

    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    assert main(cmd[3:]) == 0
    err = capsys.readouterr().err
    assert "6 of 6 runs already done" in err and "0 of 6 runs done now, 6 already done" in err


def test_cli_dask_argument_errors(tmp_path, capsys):
    from moo.__main__ import main

    base = ["experiment", *CLI_GRID, "--out", str(tmp_path / "r")]
    for extra, message in ((["--scheduler", "tcp://127.0.0.1:1"], "--scheduler needs the 'dask' executor"),
                           (["--executor", "dask", "--scheduler", "tcp://127.0.0.1:1", "--workers", "2"],
                            "--workers sizes a local cluster"),
                           (["--executor", "dask", "--workers", "0"], "--workers must be >= 1"),
                           (["--executor", "mpi"], "invalid choice")):
        assert main([*base, *extra]) == 2
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1, err
    assert not (tmp_path / "r").exists()


@pytest.fixture
def scheduler_and_worker(tmp_path):
    """A `dask scheduler` and one `dask worker` (processes); yields (address, scheduler process)."""
    with _dask_cluster(tmp_path, 1) as cluster:
        yield cluster


@pytest.mark.slow
def test_lost_scheduler_is_one_short_message_and_the_records_stay(tmp_path, scheduler_and_worker):
    address, scheduler = scheduler_and_worker
    out = tmp_path / "res"
    cmd = [sys.executable, "-m", "moo", "experiment", "--problem", "zdt1", "--algorithms", "nsga2", "--runs", "3",
           "--evals", "3000000", "--pop-size", "20", "--out", str(out), "--executor", "dask", "--scheduler", address]
    env = dict(os.environ, OMP_NUM_THREADS="1", DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT="3s")
    proc = subprocess.Popen(cmd, cwd=REPO, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        time.sleep(8)                                    # the runs are submitted and running
        scheduler.kill()
        _, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 1, err
    assert "Traceback" not in err and "CancelledError" not in err, err
    last = err.strip().splitlines()[-1]
    assert f"lost the Dask scheduler at {address}" in last and "the records written are kept" in last
    assert "rerun the same command to resume" in last
    assert len(err.strip().splitlines()) <= 5, err


def test_unparsable_scheduler_is_a_usage_error(tmp_path, capsys):
    from moo.__main__ import main

    for bad in ("not an address", "http://host:8786", "tcp://host:port"):
        assert main(["experiment", *CLI_GRID, "--out", str(tmp_path / "r"), "--executor", "dask",
                     "--scheduler", bad]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "--scheduler must be an address such as 'tcp://HOST:8786'" in err, err
    assert not (tmp_path / "r").exists()


def test_full_disk_under_dask_is_a_disk_error_not_a_lost_scheduler(tmp_path, capsys, monkeypatch):
    """The driver's record write failing for lack of room is reported as such (exit 1), not as a lost scheduler."""
    import errno

    from moo.__main__ import main

    def no_space(*args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", no_space)             # every atomic write's last step (the driver writes)
    out = tmp_path / "res"
    code = main(["experiment", "--problem", "zdt1", "--algorithms", "nsga2", "--runs", "1", "--evals", "40",
                 "--pop-size", "20", "--out", str(out), "--executor", "dask", "--workers", "1"])
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert code == 1, err
    assert f"cannot write a record in {out} (No space left on device)" in err and "scheduler" not in err
