"""Experiment grid: problem x algorithms x {plain, MO-LSP} x independent runs, resumable, on any executor.

:func:`run_experiment` runs every cell of the grid with :func:`moo.runner.run`
and stores one JSON record per run (:mod:`moo.store`)::

    <out>/<problem>/<algorithm>/seed_<s>.json          plain MOEA
    <out>/<problem>/<algorithm>+molsp/seed_<s>.json    the same MOEA wrapped by MO-LSP

(``<problem>`` carries the number of objectives for DTLZ, e.g. ``dtlz2-m5``.)
It is :func:`prepare` (check every argument, build the problem once, scan the
results directory) followed by :meth:`PreparedExperiment.run`.

Resuming
--------
A rerun skips every run whose file holds the expected record: the same
problem, its set-up (``applied``: ``ours`` or ``authors``; a record written
before set-ups existed counts as the default), objectives, algorithm, variant,
seed, budget, population size (the one the algorithm uses) and MO-LSP cap.
An interrupted experiment therefore
continues where it stopped and never recomputes a finished run. A file that
holds a run with *other* settings (say another budget) is an error naming the
file and the setting, raised before any run starts: results of two settings
are never mixed. Beyond the grid's own cells, the directory's
``settings.json`` (written by its first grid, see :mod:`moo.store`) must
hold the grid's budget, population size, MO-LSP cap and base seed, and for
its problem directory the problem, objectives and set-up; a directory from
before ``settings.json`` is checked against all its records. The directory
is locked while a grid scans and writes it (a second writer is refused). A
file that cannot be read or holds a corrupt record (not written by us: the
writes are atomic) is recomputed and replaced, with a line on stderr. Runs
recorded as failed are retried.

Seeds
-----
Run ``i`` (0-based) uses the integer seed
``np.random.SeedSequence(base_seed).spawn(runs)[i].generate_state(1)[0]``
(a 32-bit integer; child ``i`` depends only on ``base_seed`` and ``i``, so
raising ``runs`` later extends the grid with new seeds and keeps the old
ones). The same seed serves every algorithm and both variants of run ``i``:
common random numbers, so the plain MOEA and its MO-LSP version start from the
same initial population.

Executors
---------
The runs are independent and deterministic, so the records do not depend on
where they run. ``executor=None`` runs them in this process (or, with
``workers > 1``, in a pool of spawned processes); any
:class:`concurrent.futures.Executor` can be given instead: a
:class:`~concurrent.futures.ProcessPoolExecutor`, a Dask cluster's
``Client.get_executor()``, mpi4py's ``MPIPoolExecutor``
(:func:`moo.executors.open_executor` opens the first two). Workers compute and
*return* records; only this process (the driver) writes them, atomically, so
the workers need no shared file system. A Dask worker lost mid-grid has its
runs recomputed on the others by the scheduler; a process of the ``"process"``
pool of :func:`~moo.executors.open_executor` killed mid-grid breaks the pool,
and the driver starts a fresh pool and resubmits the runs lost with it (at
most :data:`~moo.executors.POOL_RESTARTS` times, with a message on stderr).
Either way the driver keeps every record that arrived.

Failures
--------
A run that raises is recorded beside its cell as ``seed_<s>.failed.json``
(settings, error, traceback). Without ``keep_going`` the first failure stops
the grid (:class:`RunFailedError`; queued runs are cancelled, the records
already written stay, and a rerun resumes); with ``keep_going`` the grid goes
on and the report lists the failures. A failure of the executor itself
(``BrokenProcessPool`` when the pool broke once more after its last restart,
or when a pool that cannot restart - an executor passed in - lost a process;
Dask's ``KilledWorker`` when a run has killed several workers) stops the grid
in the same way.
"""

from __future__ import annotations

import os
import sys
import time
import traceback
from collections.abc import Sequence
from concurrent.futures import Executor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from moo.algorithms import ALGORITHMS
from moo.algorithms.operators import POP_SIZE
from moo.executors import POOL_RESTARTS, RestartingPool, open_executor
from moo.factories import build_problem, check_algorithm_name, check_problem_name
from moo.progress import ProgressBar
from moo.store import (
    FAILED_SUFFIX,
    CorruptRecordError,
    check_settings,
    load_records,
    lock_results_dir,
    prepare_results_dir,
    problem_dir,
    read_record,
    read_settings,
    settings_mismatch,
    validate_record,
    variant_dir,
    write_json_atomic,
    write_settings,
)
from moo.validation import check_int

__all__ = ["RunSpec", "ExperimentReport", "PreparedExperiment", "RunFailedError", "plan", "run_seeds",
           "prepare", "run_experiment", "load_records", "write_json_atomic", "problem_dir"]

# Fields of a record that must match its RunSpec for the file to count as done.
_MATCH = ("problem", "n_obj", "algorithm", "molsp", "seed", "budget", "pop_size", "max_leaders")


@dataclass(frozen=True)
class RunSpec:
    """One cell of the grid: everything :func:`moo.runner.run` needs, and where the record goes."""

    problem: str
    n_obj: int | None
    algorithm: str
    molsp: bool
    run_index: int
    seed: int
    evals: int
    pop_size: int = POP_SIZE
    max_leaders: int | None = None
    setup: str | None = None

    @property
    def variant(self) -> str:
        """Directory name of the algorithm variant: ``name`` or ``name+molsp`` (``:`` written ``~``)."""
        return variant_dir(self.algorithm, self.molsp)

    @property
    def label(self) -> str:
        """``problem/variant run i (seed s)``, for messages."""
        return f"{problem_dir(self.problem, self.n_obj)}/{self.variant} run {self.run_index} (seed {self.seed})"

    def path(self, out: str | os.PathLike) -> Path:
        """``<out>/<problem>/<variant>/seed_<seed>.json``."""
        return Path(out) / problem_dir(self.problem, self.n_obj) / self.variant / f"seed_{self.seed}.json"

    def failed_path(self, out: str | os.PathLike) -> Path:
        """``<out>/<problem>/<variant>/seed_<seed>.failed.json``: the record of a failed run."""
        return self.path(out).with_name(f"seed_{self.seed}{FAILED_SUFFIX}")


@dataclass(frozen=True)
class ExperimentReport:
    """What a grid run did: its size, runs skipped (already done), run now, and the failures."""

    out: Path
    total: int
    skipped: int
    completed: int
    wall_time: float
    failed: tuple[Path, ...] = ()

    def __repr__(self) -> str:
        fails = f", {len(self.failed)} failed" if self.failed else ""
        return (f"ExperimentReport({self.out}: {self.total} runs, {self.skipped} already done, "
                f"{self.completed} run now{fails} in {self.wall_time:.1f} s)")

    def summary(self) -> str:
        """One line: the runs done now, before and failed, and where the records are."""
        fails = f", {len(self.failed)} failed" if self.failed else ""
        return (f"experiment: {self.completed} of {self.total} runs done now, {self.skipped} already done{fails}, "
                f"in {self.wall_time:.1f} s; records in {self.out}")


class RunFailedError(RuntimeError):
    """A run of the grid raised; ``path`` is its failure record (with the traceback)."""

    def __init__(self, spec: RunSpec, path: Path, error: str):
        super().__init__(f"run {spec.label} failed: {error} (traceback in {path})")
        self.spec, self.path, self.error = spec, path, error


def run_seeds(runs: int, base_seed: int = 0) -> list[int]:
    """The integer seeds of runs ``0`` to ``runs - 1`` (see the module docstring)."""
    runs = check_int(runs, "runs", 1)
    base_seed = check_int(base_seed, "base_seed", 0)
    return [int(child.generate_state(1)[0]) for child in np.random.SeedSequence(base_seed).spawn(runs)]


def _algorithms(algorithms: str | Sequence[str]) -> list[str]:
    if isinstance(algorithms, str):
        names = list(ALGORITHMS) if algorithms.lower() == "all" else [a.strip() for a in algorithms.split(",")]
    else:
        names = list(algorithms)
    if not names:
        raise ValueError("algorithms must name at least one algorithm")
    out = []
    for name in names:
        key = check_algorithm_name(name)
        if key not in out:
            out.append(key)
    return out


def plan(problem: str, algorithms: str | Sequence[str], *, runs: int, evals: int, n_obj: int | None = None,
         base_seed: int = 0, pop_size: int = POP_SIZE, max_leaders: int | None = None,
         variants: Sequence[bool] = (False, True), setup: str | None = None) -> list[RunSpec]:
    """The grid as a list of :class:`RunSpec`, ordered run index first.

    Parameters
    ----------
    problem : str
        A name of :data:`moo.problems.PROBLEMS`, or the import path
        ``package.module:factory`` of a user's problem (:mod:`moo.factories`).
    algorithms : str or sequence of str
        ``"all"``, a comma-separated string or a list of registry names or
        import paths of a user's algorithm factories.
    runs : int
        Independent runs per algorithm and variant.
    evals : int
        Evaluation budget of each run.
    n_obj : int, optional
        Number of objectives (DTLZ).
    base_seed : int
        Root of the seed sequence (see the module docstring).
    pop_size : int
        Population size (the paper's 92).
    max_leaders : int, optional
        MO-LSP's cap on candidates per generation (MO-LSP runs only).
    variants : sequence of bool
        Which variants to run: ``False`` plain, ``True`` with MO-LSP.
    setup : str, optional
        The problem's set-up (``applied`` only, see :func:`moo.runner.prepare`).
    """
    problem = check_problem_name(problem)
    names = _algorithms(algorithms)
    evals = check_int(evals, "evals", 1)
    pop_size = check_int(pop_size, "pop_size", 4)
    if n_obj is not None:
        n_obj = check_int(n_obj, "n_obj", 2)
    if max_leaders is not None:
        max_leaders = check_int(max_leaders, "max_leaders", 1)
    variants = [bool(v) for v in variants]
    if not variants:
        raise ValueError("variants must hold at least one of False (plain), True (MO-LSP)")
    seeds = run_seeds(runs, base_seed)
    return [RunSpec(problem=problem, n_obj=n_obj, algorithm=name, molsp=v, run_index=i, seed=s,
                    evals=evals, pop_size=pop_size, max_leaders=max_leaders if v else None, setup=setup)
            for i, s in enumerate(seeds) for name in names for v in variants]


# ---------------------------------------------------------------------------- the store scan

def _is_done(spec: RunSpec, out: Path, expected: dict, legacy_setup=None,
             corrupt: list[tuple[Path, str]] | None = None) -> bool:
    """True if the spec's file holds its record; False if absent, unreadable or corrupt; error if another run.

    ``legacy_setup``: the set-up a record without a ``setup`` field (written before set-ups existed)
    stands for (the problem's default set-up when the grid asks for the default, else no match).
    A corrupt file (not written by us: the writes are atomic) is appended to ``corrupt`` with the reason.
    """
    path = spec.path(out)
    if not path.is_file():
        return False
    try:
        rec = read_record(path, required=(*_MATCH, "F"))
        validate_record(rec, path)
    except ValueError as exc:              # unreadable or corrupt: recompute and replace
        if corrupt is not None:
            corrupt.append((path, str(exc).splitlines()[0]))
        return False
    got = {k: rec.get(k, legacy_setup) if k == "setup" else rec[k] for k in expected}
    wrong = {k: (got[k], v) for k, v in expected.items() if got[k] != v}
    if wrong:
        raise settings_mismatch(f"{path} holds a run with other settings:", [(k, g, w) for k, (g, w) in wrong.items()],
                                "use another out directory or the settings of that run")
    return True


def _check_legacy_dir(out: Path, settings: dict, legacy_setup) -> None:
    """A directory without ``settings.json``: every valid record in it must have the grid's settings."""
    try:
        records = load_records(out, check=False)
    except ValueError:
        records = []                       # an unreadable file: the per-cell scan recomputes or names it
    seeds: list[int] = []
    for rec in records:
        try:
            validate_record(rec, rec["_path"])
        except CorruptRecordError:
            continue                       # recomputed if in the grid; named by stats otherwise
        want = {"budget": settings["budget"]}
        if rec["_problem_dir"] == settings["problem_dir"]:
            want.update(problem=settings["problem"], n_obj=settings["n_obj"])
            if "setup" in rec or legacy_setup != settings["setup"]:
                want["setup"] = settings["setup"]
        if rec["molsp"]:
            want["max_leaders"] = settings["max_leaders"]
        got = {k: rec.get(k, legacy_setup if k == "setup" else None) for k in want}
        if rec["_problem_dir"] != settings["problem_dir"] and \
                (rec["problem"], rec["n_obj"]) == (settings["problem"], settings["n_obj"]):
            got["problem directory"], want["problem directory"] = rec["_problem_dir"], settings["problem_dir"]
        idx = rec.get("run_index")
        if isinstance(idx, int) and idx >= 0:
            if idx >= len(seeds):
                seeds = run_seeds(idx + 1, settings["base_seed"])
            if seeds[idx] != rec["seed"]:
                got["base_seed"], want["base_seed"] = f"giving seed {rec['seed']} to run {idx}", \
                    settings["base_seed"]
        wrong = {k: (got[k], v) for k, v in want.items() if got[k] != v}
        if wrong:
            raise settings_mismatch(f"{rec['_path']} holds a run with other settings:",
                                    [(k, g, w) for k, (g, w) in wrong.items()],
                                    "a results directory holds one setting: use another out directory or the "
                                    "settings of that run")


def _expected(spec: RunSpec, n_obj: int, pop_sizes: dict[str, int], setup: str | None) -> dict:
    return {"problem": spec.problem, "setup": setup, "n_obj": n_obj, "algorithm": spec.algorithm,
            "molsp": spec.molsp,
            "seed": spec.seed, "budget": spec.evals, "pop_size": pop_sizes[spec.algorithm],
            "max_leaders": spec.max_leaders}


# ---------------------------------------------------------------------------- one run (worker side)

def _execute(spec: RunSpec) -> dict:
    """Run one spec and return its record, or a failure record (worker entry point; writes nothing)."""
    from moo import runner

    try:
        result = runner.run(spec.problem, spec.algorithm, seed=spec.seed, evals=spec.evals, n_obj=spec.n_obj,
                            molsp=spec.molsp, pop_size=spec.pop_size, max_leaders=spec.max_leaders,
                            setup=spec.setup)
    except Exception as exc:  # noqa: BLE001 - recorded by the driver; KeyboardInterrupt etc. propagate
        return {"status": "failed", "problem": spec.problem, "setup": spec.setup, "n_obj": spec.n_obj,
                "algorithm": spec.algorithm,
                "molsp": spec.molsp, "seed": spec.seed, "run_index": spec.run_index, "budget": spec.evals,
                "pop_size": spec.pop_size, "max_leaders": spec.max_leaders,
                "error": f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}".rstrip(": "),
                "traceback": traceback.format_exc()}
    rec = result.to_dict()
    rec["run_index"] = spec.run_index
    return rec


# ---------------------------------------------------------------------------- the driver

@dataclass
class _Recorder:
    """Writes what the runs return (records, failure records) and keeps count."""

    out: Path
    keep_going: bool
    bar: ProgressBar | None
    completed: int = 0
    failed: list[Path] = field(default_factory=list)

    def add(self, spec: RunSpec, rec: dict) -> None:
        failed = rec.get("status") == "failed"
        if failed:
            write_json_atomic(spec.failed_path(self.out), rec)
            self.failed.append(spec.failed_path(self.out))
        else:
            self.keep(spec, rec)
        if self.bar is not None:
            self.bar.postfix(f"{len(self.failed)} failed, last {spec.label}" if self.failed else spec.label)
            self.bar(self.bar.done + 1)
        if failed and not self.keep_going:
            raise RunFailedError(spec, self.failed[-1], rec["error"])

    def keep(self, spec: RunSpec, rec: dict) -> None:
        """Write a finished run's record (a failure record is left to :meth:`add`)."""
        if rec.get("status") == "failed":
            return
        write_json_atomic(spec.path(self.out), rec)
        spec.failed_path(self.out).unlink(missing_ok=True)
        self.completed += 1


def _run_on(executor: Executor, specs: Sequence[RunSpec], recorder: _Recorder) -> None:
    """Run every spec on ``executor``; resubmit the runs lost to a broken pool if the pool can restart."""
    todo = list(specs)
    while todo:
        lost, broken = _submit_and_record(executor, todo, recorder)
        if broken is None:
            return
        if not isinstance(executor, RestartingPool):
            raise broken
        if not executor.restart():
            raise BrokenProcessPool(f"a pool process died again after {POOL_RESTARTS} restarts of the pool "
                                    "(a run may be killing its process)") from broken
        restart = POOL_RESTARTS - executor.restarts_left
        print("\n" * (recorder.bar is not None) + f"moo.experiment: a pool process died; resubmitting the "
              f"{len(lost)} runs lost with it to a fresh pool (restart {restart} of {POOL_RESTARTS})",
              file=sys.stderr)
        todo = lost


def _submit_and_record(executor: Executor, specs: Sequence[RunSpec],
                       recorder: _Recorder) -> tuple[list[RunSpec], BrokenProcessPool | None]:
    """Submit every spec, record results as they arrive; on any error cancel the rest, keep what finished.

    Returns the specs lost to a broken process pool (every run in flight or queued when a pool process
    died) and the pool's error, or ``([], None)``.
    """
    futures = {executor.submit(_execute, spec): spec for spec in specs}
    lost, broken = [], None
    try:
        for fut in as_completed(list(futures)):
            spec = futures.pop(fut)
            exc = fut.exception()
            if isinstance(exc, BrokenProcessPool):
                lost.append(spec)
                broken = exc
            else:
                recorder.add(spec, fut.result())
    finally:
        for fut in futures:
            fut.cancel()
        for fut, spec in futures.items():          # finished while we were stopping: keep them
            if fut.done() and not fut.cancelled() and fut.exception() is None:
                recorder.keep(spec, fut.result())
    return lost, broken


@dataclass(frozen=True, repr=False)
class PreparedExperiment:
    """A checked grid and the state of its results directory (see :func:`prepare`)."""

    specs: tuple[RunSpec, ...]
    out: Path
    todo: tuple[RunSpec, ...]
    retried: int
    settings: dict = field(default_factory=dict)
    expected: dict = field(default_factory=dict)
    corrupt: tuple[tuple[Path, str], ...] = ()

    @property
    def skipped(self) -> int:
        """Runs already recorded."""
        return len(self.specs) - len(self.todo)

    def __repr__(self) -> str:
        return (f"PreparedExperiment({self.out}: {len(self.specs)} runs, {self.skipped} already done, "
                f"{len(self.todo)} to run)")

    def run(self, executor: Executor | None = None, *, keep_going: bool = False,
            progress: bool | None = None) -> ExperimentReport:
        """Run the runs not yet recorded and write their records.

        Parameters
        ----------
        executor : concurrent.futures.Executor, optional
            Where the runs go (see the module docstring); ``None``: one after
            the other in this process. The executor is not shut down.
        keep_going : bool
            Record a failed run and go on (default: stop at the first failure).
        progress : bool, optional
            A progress bar of the runs (tqdm: done/total, the failures, an
            ETA) on stderr; default: only when stderr is a terminal.

        Raises
        ------
        RunFailedError
            A run raised (without ``keep_going``).
        ResultsDirBusyError
            Another process writes in the directory (a ``ValueError``; nothing run).
        ValueError
            Since :func:`prepare`, the directory got other settings (nothing run).
        OSError
            A record could not be written (a full disk); the records written stay.
        """
        if executor is not None and not isinstance(executor, Executor):
            raise TypeError(f"executor must be a concurrent.futures.Executor, got {type(executor).__name__}")
        with lock_results_dir(self.out):
            if self.settings:
                recorded = read_settings(self.out)
                if recorded is None or check_settings(self.out, recorded, self.settings):
                    write_settings(self.out, recorded, self.settings)
            # another writer may have added runs between prepare() and the lock
            todo = [s for s in self.todo if s not in self.expected or not _is_done(s, self.out, self.expected[s])]
            skipped = len(self.specs) - len(todo)
            bar = ProgressBar("experiment", unit="runs", total=len(self.specs), initial=skipped,
                              enabled=None if progress is None else bool(progress))
            recorder = _Recorder(self.out, bool(keep_going), bar if bar.enabled else None)
            start = time.perf_counter()
            try:
                bar(skipped)
                if executor is None:
                    for spec in todo:
                        recorder.add(spec, _execute(spec))
                else:
                    _run_on(executor, todo, recorder)
            finally:
                bar.close()
        return ExperimentReport(out=self.out, total=len(self.specs), skipped=skipped,
                                completed=recorder.completed, wall_time=time.perf_counter() - start,
                                failed=tuple(recorder.failed))


def prepare(problem: str, algorithms: str | Sequence[str], *, runs: int, evals: int, out: str | os.PathLike,
            n_obj: int | None = None, base_seed: int = 0, pop_size: int = POP_SIZE,
            max_leaders: int | None = None, variants: Sequence[bool] = (False, True),
            setup: str | None = None) -> PreparedExperiment:
    """Check the grid of :func:`~moo.experiment.plan`, create ``out`` and find the runs already recorded there.

    Every check happens here, before any run: the arguments of :func:`~moo.experiment.plan`,
    the budget against each algorithm's population (the problem is built
    once), ``out`` (a directory that can be written, not locked by another
    writer), the directory's settings (``settings.json``, or for a directory
    from before it, every record in it) against the grid's, and the records
    of the grid's runs. A corrupt record of the grid (see
    :func:`moo.store.validate_record`) is recomputed, with a line on stderr
    (listed in ``corrupt``).

    Raises
    ------
    ValueError, TypeError
        A bad argument, an unusable or busy ``out``, or ``out`` holding runs
        with other settings (the message names the file and the setting).
    """
    from moo.runner import check_budget, setup_name

    specs = plan(problem, algorithms, runs=runs, evals=evals, n_obj=n_obj, base_seed=base_seed,
                 pop_size=pop_size, max_leaders=max_leaders, variants=variants, setup=setup)
    key = specs[0].problem
    prob = build_problem(key, n_obj, setup=setup)
    name = setup_name(prob)
    # a record without a set-up was written before set-ups existed, with the problem's default one
    legacy = name if setup is None else setup_name(build_problem(key, n_obj))
    pop_sizes = {alg: int(check_budget(prob, alg, evals=specs[0].evals, pop_size=specs[0].pop_size).pop_size)
                 for alg in dict.fromkeys(s.algorithm for s in specs)}
    out = prepare_results_dir(out)
    settings = {"problem": key, "problem_dir": problem_dir(key, n_obj), "n_obj": int(prob.n_obj), "setup": name,
                "budget": specs[0].evals, "pop_size": specs[0].pop_size,
                "max_leaders": max_leaders,
                "base_seed": check_int(base_seed, "base_seed", 0)}
    with lock_results_dir(out):            # refuse now (before any work) if another writer holds it
        recorded = read_settings(out)
        if recorded is not None:
            check_settings(out, recorded, settings)
        else:
            _check_legacy_dir(out, settings, legacy)
        expected = {s: _expected(s, prob.n_obj, pop_sizes, name) for s in specs}
        corrupt: list[tuple[Path, str]] = []
        todo = tuple(s for s in specs if not _is_done(s, out, expected[s], legacy, corrupt))
    for _path, reason in corrupt:
        print(f"moo.experiment: {reason}; recomputing it", file=sys.stderr)
    retried = sum(s.failed_path(out).is_file() for s in todo)
    return PreparedExperiment(specs=tuple(specs), out=out, todo=todo, retried=retried, settings=settings,
                              expected={s: expected[s] for s in todo}, corrupt=tuple(corrupt))


def run_experiment(problem: str, algorithms: str | Sequence[str], *, runs: int, evals: int,
                   out: str | os.PathLike, n_obj: int | None = None, base_seed: int = 0, pop_size: int = POP_SIZE,
                   max_leaders: int | None = None, variants: Sequence[bool] = (False, True),
                   workers: int = 1, executor: Executor | None = None, keep_going: bool = False,
                   progress: bool | None = None, setup: str | None = None) -> ExperimentReport:
    """Run the grid of :func:`~moo.experiment.plan` into ``out``, skipping runs already recorded.

    Every cell (algorithm, variant) runs ``runs`` times with the seeds of
    :func:`run_seeds`; each run is written as
    ``out/<problem>/<algorithm>[+molsp]/seed_<s>.json`` as soon as it ends, so
    a grid interrupted and started again runs only what is missing.

    Parameters
    ----------
    problem : str
        A name of :data:`moo.problems.PROBLEMS`, or the import path
        ``package.module:factory`` of a user's problem (:mod:`moo.factories`).
    algorithms : str or sequence of str
        ``"all"``, a comma-separated string or a list of registry names or
        import paths of a user's algorithm factories.
    runs : int
        Independent runs per algorithm and variant.
    evals : int
        Evaluation budget of each run.
    out : path-like
        Results directory (created if needed).
    n_obj : int, optional
        Number of objectives (DTLZ, WFG).
    base_seed : int
        Root of the seed sequence (see the module docstring).
    pop_size : int
        Population size (the paper's 92).
    max_leaders : int, optional
        MO-LSP's cap on candidates per generation (MO-LSP runs only).
    variants : sequence of bool
        Which variants to run: ``False`` plain, ``True`` with MO-LSP (default both).
    workers : int
        Without ``executor``: processes running the grid (1: in this process).
    executor : concurrent.futures.Executor, optional
        Run the grid there instead (a Dask ``Client.get_executor()``, a
        ``ProcessPoolExecutor``, mpi4py's ``MPIPoolExecutor``, ...); it is
        not shut down.
    keep_going : bool
        Record a failed run (``seed_<s>.failed.json``, with its traceback)
        and go on; default: stop at the first failure.
    progress : bool, optional
        Show ``runs done/total`` and an ETA on stderr; default: only when
        stderr is a terminal.
    setup : str, optional
        The problem's set-up (``applied`` only, see :func:`moo.runner.prepare`).

    Returns
    -------
    ExperimentReport
        The grid's size, the runs skipped (already recorded) and run now, the failures.

    Raises
    ------
    ValueError, TypeError
        Bad arguments, or ``out`` holds a run of the same cell with other
        settings; raised before any run starts.
    RunFailedError
        A run raised (without ``keep_going``); the records written stay.

    See Also
    --------
    plan : the grid as a list of runs.
    load_records : read the records back.
    moo.analyse : the statistics of a results directory.

    Examples
    --------
    Three runs of NSGA-II and of NSGA-II with MO-LSP; started again, the
    grid finds every run recorded:

    >>> import tempfile
    >>> import moo
    >>> from moo.experiment import load_records
    >>> with tempfile.TemporaryDirectory() as out:
    ...     first = moo.run_experiment("zdt1", "nsga2", runs=3, evals=200, pop_size=20, out=out)
    ...     again = moo.run_experiment("zdt1", "nsga2", runs=3, evals=200, pop_size=20, out=out)
    ...     records = load_records(out)
    >>> first.completed, again.skipped, len(records)
    (6, 6, 6)
    """
    workers = check_int(workers, "workers", 1)
    if executor is not None and workers != 1:
        raise ValueError("give workers (a local process pool) or executor, not both")
    grid = prepare(problem, algorithms, runs=runs, evals=evals, out=out, n_obj=n_obj, base_seed=base_seed,
                   pop_size=pop_size, max_leaders=max_leaders, variants=variants, setup=setup)
    if executor is not None:
        return grid.run(executor, keep_going=keep_going, progress=progress)
    with open_executor("process", workers=workers if len(grid.todo) > 1 else 1) as pool:
        return grid.run(pool, keep_going=keep_going, progress=progress)
