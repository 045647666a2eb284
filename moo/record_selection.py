"""One design from run records: the Monte Carlo selection on a recorded front (``python -m moo select``).

A run record (``python -m moo run --out``, :meth:`moo.runner.RunResult.to_dict`)
holds the final front's objectives ``F`` and decision vectors ``X``; a
results directory (``python -m moo experiment``) holds one record per run.
:func:`select_from_records` rebuilds the candidate set from them and picks one
design:

* **the front** - the records of the problem (optionally of one algorithm
  variant) are pooled and their non-dominated union is kept
  (:func:`front_from_records`: of equal objective vectors the first, in the
  order of the records' paths, is kept), so a directory of ``R`` runs gives one
  front, as good as the best of them;
* **the rule** - the paper's two problems (:class:`~moo.problems.generic.GenericRLQRProblem`,
  :class:`~moo.problems.applied.AppliedRLQRProblem`) use their own selection,
  :func:`moo.problems.selection.select_design` (the front plus the paper's
  extra designs, ``Delta ~ U(-1, 1)`` realisations, the paper's cumulative
  errors); any other :class:`~moo.tuning.TuningProblem` the general one,
  :func:`moo.tuning.tune.select_front` (each simulation draws one of the
  problem's scenarios, the cumulative error is the weighted sum of the
  objectives on it; :mod:`moo.tuning.selection`), i.e. what
  :meth:`moo.tuning.TuningResult.select` does with the same ``n_sims`` and
  ``seed``;
* **the certificate** - if the problem has an ``uncertainty`` attribute that
  is a :class:`robustctl.NormBounded`, the chosen gain's certified robust
  margin (:func:`robustctl.robust_stability`) on the family's design plant.

Errors (a source that is not a record or a results directory, records of
another problem or objective count, records without ``X``, a problem that is
not a ``TuningProblem``) are one-line ``ValueError``/``TypeError`` naming the
file or the argument, raised before any simulation.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import moocore
import numpy as np

import robustctl as rc

from .store import load_records, read_record, validate_record
from .tuning import TuningProblem
from .tuning.tune import design_plant
from .validation import check_int

__all__ = ["RecordFront", "RecordSelection", "load_source", "front_from_records", "select_from_records",
           "select_on_front"]


def load_source(source: str | os.PathLike) -> list[dict]:
    """The validated records of ``source``: one run record file, or every record of a results directory.

    A directory is read by :func:`moo.store.load_records` (corrupt records,
    duplicates and mixed settings refused, naming the file); a file by
    :func:`moo.store.read_record` and :func:`moo.store.validate_record`. Each
    record gets ``_path``, its file.
    """
    if not isinstance(source, (str, os.PathLike)) or not os.fspath(source):
        raise ValueError(f"source must be a run record file or a results directory, got {source!r}")
    path = Path(source)
    if path.is_dir():
        records = load_records(path)
        if not records:
            raise ValueError(f"no run records (*/*/seed_*.json) under {str(path)!r}")
        return records
    if not path.is_file():
        raise ValueError(f"source {str(path)!r} does not exist (a run record or a results directory)")
    rec = read_record(path)
    validate_record(rec, path)
    rec["_path"] = str(path)
    return [rec]


def _variant(rec: dict) -> str:
    return rec["algorithm"] + ("+molsp" if rec["molsp"] else "")


def _decisions(rec: dict, n_var: int) -> np.ndarray:
    """The record's ``X`` as a finite (len(F), n_var) array; ``ValueError`` naming the file otherwise."""
    path = rec.get("_path", "the record")
    X = rec.get("X")
    if X is None:
        raise ValueError(f"{path} holds no decision vectors X (a record of python -m moo run or experiment has them)")
    try:
        arr = np.asarray(X, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{path} is a corrupt run record: X is not a matrix of numbers") from None
    if arr.ndim != 2 or arr.shape != (len(rec["F"]), n_var):
        raise ValueError(f"{path}: X must have one row of {n_var} values (the problem's n_var) per row of F "
                         f"({len(rec['F'])}), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{path} is a corrupt run record: X holds NaN or inf")
    return arr


@dataclass(frozen=True, eq=False, repr=False)
class RecordFront:
    """The non-dominated union of the records' fronts (:func:`front_from_records`).

    Attributes
    ----------
    X : (N, n_var) ndarray
        Decision vectors.
    F : (N, n_obj) ndarray
        Their recorded objectives.
    origin : list of (str, int)
        Record file and row of each design.
    records : list of str
        The record files pooled.
    """

    X: np.ndarray
    F: np.ndarray
    origin: list[tuple[str, int]]
    records: list[str]

    def __len__(self) -> int:
        return int(self.X.shape[0])

    def __repr__(self) -> str:
        return f"RecordFront(N={len(self)}, records={len(self.records)})"


def front_from_records(records: list[dict], problem, *, problem_name: str, algorithm: str | None = None,
                       molsp: bool | None = None) -> RecordFront:
    """Pool the fronts of the records of ``problem_name`` and keep their non-dominated union.

    Parameters
    ----------
    records : list of dict
        Validated run records (:func:`load_source`).
    problem : pymoo Problem
        The built problem (its ``n_obj``, ``n_var`` and set-up must be the records').
    problem_name : str
        The records' ``problem`` field (a registry name in lower case, or an import path as given).
    algorithm : str, optional
        Keep only this algorithm's runs (the record's ``algorithm`` field).
    molsp : bool, optional
        Keep only the MO-LSP (True) or plain (False) runs.
    """
    mine = [r for r in records if r["problem"] == problem_name]
    if not mine:
        held = sorted({r["problem"] for r in records})
        raise ValueError(f"problem: the source holds no run of {problem_name!r} (it holds runs of "
                         f"{', '.join(map(repr, held))})")
    setup = getattr(getattr(problem, "setup", None), "name", None)
    for r in mine:
        if r["n_obj"] != problem.n_obj:
            raise ValueError(f"{r['_path']} is a run with n_obj {r['n_obj']}, but the problem built has "
                             f"{problem.n_obj} objectives (give n_obj)")
        if r.get("setup") is not None and r.get("setup") != setup:
            raise ValueError(f"{r['_path']} is a run with setup {r.get('setup')!r}, but the problem built has "
                             f"setup {setup!r} (give setup)")
    chosen = [r for r in mine if (algorithm is None or r["algorithm"] == algorithm)
              and (molsp is None or r["molsp"] == molsp)]
    if not chosen:
        want = (algorithm or "any algorithm") + {None: "", True: " with MO-LSP", False: " without MO-LSP"}[molsp]
        held = sorted({_variant(r) for r in mine})
        raise ValueError(f"algorithm: the source holds no run of {want} on {problem_name!r} (it holds "
                         f"{', '.join(held)})")
    Xs = [_decisions(r, problem.n_var) for r in chosen]
    F = np.concatenate([np.asarray(r["F"], dtype=float) for r in chosen])
    X = np.concatenate(Xs)
    origin = [(r["_path"], i) for r, x in zip(chosen, Xs, strict=True) for i in range(len(x))]
    keep = np.flatnonzero(moocore.is_nondominated(F, keep_weakly=False))
    return RecordFront(X=X[keep], F=F[keep], origin=[origin[i] for i in keep], records=[r["_path"] for r in chosen])


def _plain(value) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None


@dataclass(frozen=True, eq=False, repr=False)
class RecordSelection:
    """The design chosen from run records (:func:`select_from_records`).

    Attributes
    ----------
    front : RecordFront
        The candidate front.
    rule : str
        ``"paper"`` (:func:`moo.problems.selection.select_design`) or
        ``"scenarios"`` (:func:`moo.tuning.tune.select_front`).
    labels : tuple of str
        Label of every candidate: ``"1"`` .. ``"N"`` for the front's rows, then
        the paper's extra designs (``"nominal"``, ``"RLQR^A"``, ``"random"``).
    best : int
        Index of the chosen candidate in ``labels``/``counts``.
    index : int or None
        Its row of the front (None for an extra design of the paper's rule).
    z : (n_var,) ndarray
        Its decision vector (NaN for the paper's nominal LQR).
    K : (m, n) ndarray or None
        Its gain ``u = K x`` (None for an output feedback: see ``controller``).
    controller : robustctl.Controller or None
        The chosen controller of an output-feedback problem (None for a state feedback).
    counts : (D,) int ndarray
        Simulations won by each candidate.
    n_sims : int
        Number of simulations.
    margin : float or None
        Certified robust margin of ``K`` against the problem's ``uncertainty``
        (None when the problem has no :class:`robustctl.NormBounded` one).
    """

    front: RecordFront
    rule: str
    labels: tuple[str, ...]
    best: int
    index: int | None
    z: np.ndarray
    K: np.ndarray | None
    counts: np.ndarray
    n_sims: int
    margin: float | None
    controller: rc.Controller | None = None

    @property
    def wins(self) -> int:
        """Simulations won by the chosen design."""
        return int(self.counts[self.best])

    @property
    def share(self) -> float:
        """Its share of the simulations, ``wins / n_sims``."""
        return self.wins / self.n_sims

    @property
    def label(self) -> str:
        """Its label (``"12"``, ``"nominal"``, ...)."""
        return self.labels[self.best]

    def to_dict(self) -> dict:
        """Plain Python types (lists, None for NaN), ready for ``json.dump``."""
        origin = self.front.origin[self.index] if self.index is not None else None
        return {
            "rule": self.rule, "n_sims": self.n_sims, "records": list(self.front.records),
            "n_front": len(self.front), "n_designs": len(self.labels), "label": self.label, "index": self.index,
            "record": None if origin is None else origin[0], "record_row": None if origin is None else origin[1],
            "z": [_plain(v) for v in self.z],
            "K": None if self.K is None else [[_plain(v) for v in row] for row in self.K],
            "controller": None if self.controller is None else {
                name: np.asarray(getattr(self.controller, name)).tolist() for name in ("Ac", "Bc", "Cc", "Dc")},
            "F": None if self.index is None else self.front.F[self.index].tolist(),
            "wins": self.wins, "share": self.share, "margin": self.margin,
            "labels": list(self.labels), "counts": self.counts.tolist(),
        }

    def __repr__(self) -> str:
        return (f"RecordSelection(rule={self.rule!r}, label={self.label!r}, wins={self.wins}/{self.n_sims}, "
                f"front={len(self.front)})")


def _margin(problem, K: np.ndarray | rc.Controller) -> float | None:
    """The certified margin of a gain or of a dynamic controller against the problem's ``uncertainty``, if any."""
    uncertainty = getattr(problem, "uncertainty", None)
    if not isinstance(uncertainty, rc.NormBounded):
        return None
    if isinstance(K, rc.Controller):
        return _plain(rc.robust_stability(K, uncertainty).margin)
    if not np.all(np.isfinite(K)):
        return None
    return _plain(rc.robust_stability((design_plant(problem), K), uncertainty).margin)


def select_from_records(records: list[dict], problem, *, problem_name: str, algorithm: str | None = None,
                        molsp: bool | None = None, n_sims: int = 1000, seed=None) -> RecordSelection:
    """The Monte Carlo selection of one design from run records (module docstring).

    Parameters
    ----------
    records : list of dict
        Validated run records (:func:`load_source`).
    problem : TuningProblem
        The problem the records ran on, rebuilt (e.g. :func:`moo.factories.build_problem`).
    problem_name, algorithm, molsp
        Which records (:func:`front_from_records`).
    n_sims : int
        Number of simulations.
    seed : int or numpy Generator-compatible seed
        Seed of the draws.

    Returns
    -------
    RecordSelection
    """
    if not isinstance(problem, TuningProblem):
        raise TypeError(f"select needs a moo.tuning.TuningProblem, got a {type(problem).__name__}")
    n_sims = check_int(n_sims, "n_sims", 1)
    front = front_from_records(records, problem, problem_name=problem_name, algorithm=algorithm, molsp=molsp)
    return select_on_front(problem, front, n_sims=n_sims, seed=seed)


def select_on_front(problem, front: RecordFront, *, n_sims: int = 1000, seed=None,
                    progress: Callable[[int, int], None] | None = None) -> RecordSelection:
    """The selection of :func:`select_from_records` on a front already pooled (:func:`front_from_records`).

    ``progress(done, total)`` follows the simulated plants (the paper's rule: all at once).
    """
    if not isinstance(problem, TuningProblem):
        raise TypeError(f"select needs a moo.tuning.TuningProblem, got a {type(problem).__name__}")
    n_sims = check_int(n_sims, "n_sims", 1)
    from .problems.selection import is_paper_problem, select_design
    from .tuning.tune import select_front

    if is_paper_problem(problem):                                           # the paper's: their own rule
        if progress is not None:
            progress(0, n_sims)
        ds = select_design(problem, front.X, n_sims=n_sims, seed=seed)
        if progress is not None:
            progress(n_sims, n_sims)
        best = ds.best
        index = best if ds.designs.kinds[best] == "front" else None
        K, z, labels, counts, rule = ds.designs.K[best], ds.z, ds.designs.labels, ds.result.counts, "paper"
    else:
        sel = select_front(problem, front.X, front.F, n_sims=n_sims, seed=seed, progress=progress)
        best = index = sel.index
        K, z, counts, rule = sel.K, front.X[index].copy(), sel.counts, "scenarios"
        labels = tuple(str(i + 1) for i in range(len(front)))
        if K is None:
            return RecordSelection(front=front, rule=rule, labels=labels, best=int(best), index=index, z=z, K=None,
                                   counts=np.asarray(counts), n_sims=n_sims, margin=_margin(problem, sel.controller),
                                   controller=sel.controller)
    K = np.array(K, dtype=float)
    return RecordSelection(front=front, rule=rule, labels=tuple(labels), best=int(best), index=index, z=z, K=K,
                           counts=np.asarray(counts), n_sims=n_sims, margin=_margin(problem, K))
