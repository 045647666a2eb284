"""Experiment grid: problem x algorithms x {plain, MO-LSP} x independent runs, resumable.

:func:`run_experiment` runs every cell of the grid with :func:`moo.runner.run`
and writes one JSON record (:meth:`moo.runner.RunResult.to_dict`) per run::

    <out>/<problem>/<algorithm>/seed_<s>.json          plain MOEA
    <out>/<problem>/<algorithm>+molsp/seed_<s>.json    the same MOEA wrapped by MO-LSP

(``<problem>`` carries the number of objectives for DTLZ, e.g. ``dtlz2-m5``.)

Writes are atomic: the record goes to a temporary file in the target
directory, is flushed to disk and renamed over the final name
(:func:`os.replace`), so a file under its final name is always complete. A
rerun with the same arguments skips every run whose file exists and holds the
expected record (problem, objectives, algorithm, variant, seed, budget,
population, MO-LSP cap); an interrupted experiment therefore continues where
it stopped and never recomputes a finished run. A file that holds a run with
*other* settings (say another budget) is an error, never silently mixed in.

Seeds
-----
Run ``i`` (0-based) uses the integer seed
``np.random.SeedSequence(base_seed).spawn(runs)[i].generate_state(1)[0]``
(a 32-bit integer; child ``i`` depends only on ``base_seed`` and ``i``, so
raising ``runs`` later extends the grid with new seeds and keeps the old
ones). The same seed serves every algorithm and both variants of run ``i``:
common random numbers, so the plain MOEA and its MO-LSP version start from the
same initial population.

Parallelism
-----------
``workers > 1`` runs the grid in a :class:`concurrent.futures.ProcessPoolExecutor`
(spawned processes); each run is independent and deterministic, so the result
files do not depend on ``workers``. If a run fails or the experiment is
interrupted, queued runs are cancelled and the error propagates; the records
already written stay and a rerun resumes from them.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from multiprocessing import get_context
from pathlib import Path

import numpy as np

from moo._validation import check_int
from moo.algorithms import ALGORITHMS

__all__ = ["RunSpec", "ExperimentReport", "plan", "run_seeds", "run_experiment", "load_records",
           "write_json_atomic"]

# Fields of a record that must match its RunSpec for the file to count as done.
_MATCH = ("problem", "n_obj", "algorithm", "molsp", "seed", "budget", "max_leaders")


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
    pop_size: int = 92
    max_leaders: int | None = None

    @property
    def variant(self) -> str:
        """Directory name of the algorithm variant: ``name`` or ``name+molsp``."""
        return f"{self.algorithm}+molsp" if self.molsp else self.algorithm

    def path(self, out: str | os.PathLike) -> Path:
        """``<out>/<problem>/<variant>/seed_<seed>.json``."""
        return Path(out) / problem_dir(self.problem, self.n_obj) / self.variant / f"seed_{self.seed}.json"


@dataclass(frozen=True)
class ExperimentReport:
    """What :func:`run_experiment` did: grid size, runs skipped (already done) and run now."""

    out: Path
    total: int
    skipped: int
    completed: int
    wall_time: float

    def __repr__(self) -> str:
        return (f"ExperimentReport({self.out}: {self.total} runs, {self.skipped} already done, "
                f"{self.completed} run now in {self.wall_time:.1f} s)")


def problem_dir(problem: str, n_obj: int | None) -> str:
    """Directory name of a problem: its name, plus ``-m<M>`` when ``n_obj`` is given for DTLZ."""
    key = problem.lower()
    return f"{key}-m{n_obj}" if (n_obj is not None and key.startswith("dtlz")) else key


def run_seeds(runs: int, base_seed: int = 0) -> list[int]:
    """The integer seeds of runs ``0 .. runs-1`` (see the module docstring)."""
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
        if not isinstance(name, str) or name.lower() not in ALGORITHMS:
            raise ValueError(f"unknown algorithm {name!r} in algorithms; valid: {', '.join(ALGORITHMS)}")
        if name.lower() not in out:
            out.append(name.lower())
    return out


def plan(problem: str, algorithms: str | Sequence[str], *, runs: int, evals: int, n_obj: int | None = None,
         base_seed: int = 0, pop_size: int = 92, max_leaders: int | None = None,
         variants: Sequence[bool] = (False, True)) -> list[RunSpec]:
    """The grid as a list of :class:`RunSpec`, ordered run index first.

    Parameters
    ----------
    problem : str
        A name of :data:`moo.problems.PROBLEMS`.
    algorithms : str or sequence of str
        ``"all"``, a comma-separated string or a list of registry names.
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
    """
    from moo.problems import PROBLEMS

    if not isinstance(problem, str) or problem.lower() not in PROBLEMS:
        raise ValueError(f"unknown problem {problem!r}; valid: {', '.join(PROBLEMS)}")
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
    return [RunSpec(problem=problem.lower(), n_obj=n_obj, algorithm=name, molsp=v, run_index=i, seed=s,
                    evals=evals, pop_size=pop_size, max_leaders=max_leaders if v else None)
            for i, s in enumerate(seeds) for name in names for v in variants]


def write_json_atomic(path: str | os.PathLike, data: dict) -> None:
    """Write ``data`` as JSON to ``path`` atomically (temp file in the same directory + rename).

    The directory is created if needed. On any failure the temporary file is
    removed and ``path`` is left as it was.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            json.dump(data, fh, indent=1)
            fh.write("\n")
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def _expected(spec: RunSpec) -> dict:
    return {"problem": spec.problem, "n_obj": spec.n_obj, "algorithm": spec.algorithm, "molsp": spec.molsp,
            "seed": spec.seed, "budget": spec.evals, "max_leaders": spec.max_leaders}


def _is_done(spec: RunSpec, out: Path) -> bool:
    """True if the spec's file holds its record; False if absent or unreadable; error if another run."""
    path = spec.path(out)
    if not path.is_file():
        return False
    try:
        rec = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False                      # unreadable (not written by us): recompute and replace
    if not isinstance(rec, dict) or not {*_MATCH, "F"} <= rec.keys():
        return False
    expected = _expected(spec)
    if expected["n_obj"] is None:
        expected.pop("n_obj")
    wrong = {k: rec[k] for k, v in expected.items() if rec[k] != v}
    if wrong:
        raise ValueError(f"{path} holds a run with other settings ({wrong}, expected "
                         f"{ {k: expected[k] for k in wrong} }); use another out directory")
    return True


def _execute(spec: RunSpec, out: str) -> tuple[str, float]:
    """Run one spec and write its record (worker entry point; importable for spawned processes)."""
    from moo.runner import run

    result = run(spec.problem, spec.algorithm, seed=spec.seed, evals=spec.evals, n_obj=spec.n_obj,
                 molsp=spec.molsp, pop_size=spec.pop_size, max_leaders=spec.max_leaders)
    rec = result.to_dict()
    rec["run_index"] = spec.run_index
    write_json_atomic(spec.path(out), rec)
    return str(spec.path(out)), result.wall_time


class _Progress:
    """``runs done/total, elapsed, ETA`` on one stderr line."""

    def __init__(self, total: int, skipped: int):
        self.total, self.skipped, self.start = total, skipped, time.perf_counter()

    def update(self, done_now: int, label: str) -> None:
        elapsed = time.perf_counter() - self.start
        remaining = self.total - self.skipped - done_now
        eta = elapsed / done_now * remaining if done_now else float("nan")
        eta_txt = "?" if not np.isfinite(eta) else f"{eta:.0f} s"
        sys.stderr.write(f"\r[{self.skipped + done_now}/{self.total} runs] elapsed {elapsed:.0f} s, "
                         f"ETA {eta_txt}  {label:<30.30}")
        sys.stderr.flush()

    def close(self) -> None:
        sys.stderr.write("\n")
        sys.stderr.flush()


def run_experiment(problem: str, algorithms: str | Sequence[str], *, runs: int, evals: int,
                   out: str | os.PathLike, n_obj: int | None = None, base_seed: int = 0, pop_size: int = 92,
                   max_leaders: int | None = None, variants: Sequence[bool] = (False, True),
                   workers: int = 1, progress: bool | None = None) -> ExperimentReport:
    """Run the grid of :func:`plan` into ``out``, skipping runs already recorded.

    Parameters are those of :func:`plan`, plus:

    out : path-like
        Results directory (created if needed).
    workers : int
        Processes running the grid (1: in this process).
    progress : bool, optional
        Show ``runs done/total`` and an ETA on stderr; default: only when
        stderr is a terminal.

    Returns
    -------
    ExperimentReport

    Raises
    ------
    ValueError
        Bad arguments, or ``out`` holds a run of the same cell with other
        settings.
    """
    specs = plan(problem, algorithms, runs=runs, evals=evals, n_obj=n_obj, base_seed=base_seed,
                 pop_size=pop_size, max_leaders=max_leaders, variants=variants)
    workers = check_int(workers, "workers", 1)
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"out must be a directory, {str(out)!r} is a file")
    out.mkdir(parents=True, exist_ok=True)
    todo = [s for s in specs if not _is_done(s, out)]
    show = sys.stderr.isatty() if progress is None else bool(progress)
    bar = _Progress(len(specs), len(specs) - len(todo)) if show else None
    start = time.perf_counter()
    done = 0
    try:
        if bar is not None:
            bar.update(0, "")
        if workers == 1 or len(todo) <= 1:
            for spec in todo:
                _execute(spec, str(out))
                done += 1
                if bar is not None:
                    bar.update(done, f"{spec.variant} s{spec.run_index}")
        else:
            pool = ProcessPoolExecutor(max_workers=workers, mp_context=get_context("spawn"))
            try:
                futures = {pool.submit(_execute, spec, str(out)): spec for spec in todo}
                for fut in as_completed(futures):
                    fut.result()
                    done += 1
                    if bar is not None:
                        spec = futures[fut]
                        bar.update(done, f"{spec.variant} s{spec.run_index}")
            except BaseException:
                # interrupted or a run failed: drop the queued runs (finished files stay) and re-raise
                pool.shutdown(wait=False, cancel_futures=True)
                raise
            pool.shutdown()
    finally:
        if bar is not None:
            bar.close()
    return ExperimentReport(out=out, total=len(specs), skipped=len(specs) - len(todo), completed=done,
                            wall_time=time.perf_counter() - start)


def load_records(out: str | os.PathLike) -> list[dict]:
    """Every run record under ``out`` (``*/*/seed_*.json``), sorted by path; temp files ignored."""
    out = Path(out)
    if not out.is_dir():
        raise ValueError(f"results directory {str(out)!r} does not exist")
    records = []
    for path in sorted(out.glob("*/*/seed_*.json")):
        rec = json.loads(path.read_text(encoding="utf-8"))
        rec["_path"] = str(path)
        rec["_problem_dir"] = path.parent.parent.name
        records.append(rec)
    return records
