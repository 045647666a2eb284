"""Command line: ``python -m moo run | experiment | stats``.

::

    python -m moo run --problem {generic,applied,zdt1..6,dtlz1..7} [--n-obj M]
                      --algorithm NAME [--molsp [--max-leaders K]] --seed S
                      --evals N [--pop-size P] --out FILE.json
    python -m moo experiment --problem P [--n-obj M] --algorithms all|a,b --runs N
                      --evals E [--molsp-max-leaders K] [--pop-size P] [--seed BASE]
                      --out DIR [--workers W]
    python -m moo stats DIR [--out FILE.csv|.md|.tex] [--runs-out FILE.csv] [--alpha A]

``run`` runs :func:`moo.runner.run` and writes its record (:meth:`RunResult.to_dict`)
as JSON. ``experiment`` runs a resumable grid (:func:`moo.experiment.run_experiment`,
one JSON record per run under DIR; progress with an ETA on a terminal).
``stats`` computes the five indicators per run and the ANOVA/Tukey comparison of
each MOEA with its MO-LSP version (:mod:`moo.stats`), prints the table as
Markdown and writes it to FILE in the format of its extension. A progress bar goes to stderr when stderr is a terminal; nothing is
printed otherwise. Bad arguments give a one-line error on stderr and exit
code 2; a failure during the run raises (exit code 1).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Sequence

from moo.algorithms import ALGORITHMS
from moo.problems import PROBLEMS

__all__ = ["main"]


class _UsageError(Exception):
    pass


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit code 2 (handled in main)
        raise _UsageError(message)


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="python -m moo", description="Multiobjective tuning with MOEAs and MO-LSP.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    r = sub.add_parser("run", help="one run of a MOEA on a problem, recorded as JSON")
    r.add_argument("--problem", required=True, help=f"one of {', '.join(PROBLEMS)}")
    r.add_argument("--n-obj", type=int, default=None, help="number of objectives (DTLZ; default 3)")
    r.add_argument("--algorithm", required=True, help=f"one of {', '.join(ALGORITHMS)}")
    r.add_argument("--molsp", action="store_true", help="add MO-LSP to the algorithm")
    r.add_argument("--max-leaders", type=int, default=None, help="MO-LSP cap on candidates per generation")
    r.add_argument("--seed", type=int, required=True, help="seed (integer >= 0)")
    r.add_argument("--evals", type=int, required=True, help="evaluation budget")
    r.add_argument("--pop-size", type=int, default=92, help="population size (default 92)")
    r.add_argument("--out", required=True, help="output JSON file")

    e = sub.add_parser("experiment", help="a resumable grid of runs: algorithms x {plain, MO-LSP} x seeds")
    e.add_argument("--problem", required=True, help=f"one of {', '.join(PROBLEMS)}")
    e.add_argument("--n-obj", type=int, default=None, help="number of objectives (DTLZ; default 3)")
    e.add_argument("--algorithms", default="all", help="'all' or a comma-separated list (default all)")
    e.add_argument("--runs", type=int, required=True, help="independent runs per algorithm and variant")
    e.add_argument("--evals", type=int, required=True, help="evaluation budget of each run")
    e.add_argument("--molsp-max-leaders", type=int, default=None, help="MO-LSP cap on candidates per generation")
    e.add_argument("--pop-size", type=int, default=92, help="population size (default 92)")
    e.add_argument("--seed", type=int, default=0, help="base seed of the SeedSequence (default 0)")
    e.add_argument("--out", required=True, help="results directory (created; existing runs are kept)")
    e.add_argument("--workers", type=int, default=1, help="worker processes (default 1)")

    s = sub.add_parser("stats", help="indicators, ANOVA and Tukey HSD of a results directory")
    s.add_argument("dir", help="results directory written by 'experiment'")
    s.add_argument("--out", default=None, help="write the table to FILE (.csv, .md or .tex)")
    s.add_argument("--runs-out", default=None, help="write the per-run indicators to FILE (.csv)")
    s.add_argument("--alpha", type=float, default=0.05, help="significance level (default 0.05)")
    return parser


class _Progress:
    """A one-line progress bar on stderr."""

    def __init__(self, label: str, width: int = 30):
        self.label, self.width = label, width

    def __call__(self, done: int, total: int) -> None:
        frac = min(done / total, 1.0)
        bar = "#" * int(round(frac * self.width))
        sys.stderr.write(f"\r{self.label} [{bar:<{self.width}}] {done}/{total} evals")
        sys.stderr.flush()

    def close(self) -> None:
        sys.stderr.write("\n")
        sys.stderr.flush()


def _validate(args) -> None:
    if args.problem.lower() not in PROBLEMS:
        raise _UsageError(f"unknown problem {args.problem!r}; valid: {', '.join(PROBLEMS)}")
    if args.algorithm.lower() not in ALGORITHMS:
        raise _UsageError(f"unknown algorithm {args.algorithm!r}; valid: {', '.join(ALGORITHMS)}")
    if args.seed < 0:
        raise _UsageError(f"--seed must be >= 0, got {args.seed}")
    if args.pop_size < 4:
        raise _UsageError(f"--pop-size must be >= 4, got {args.pop_size}")
    if args.evals < args.pop_size:
        raise _UsageError(f"--evals must be at least the population size ({args.pop_size}), got {args.evals}")
    if args.max_leaders is not None and not args.molsp:
        raise _UsageError("--max-leaders needs --molsp")
    if args.max_leaders is not None and args.max_leaders < 1:
        raise _UsageError(f"--max-leaders must be >= 1, got {args.max_leaders}")
    out_dir = os.path.dirname(os.path.abspath(args.out))
    if not os.path.isdir(out_dir):
        raise _UsageError(f"--out: directory {out_dir!r} does not exist")
    # build problem and algorithm once, so that their own checks report as usage errors
    from moo.algorithms import make_algorithm
    from moo.problems import make_problem
    try:
        problem = make_problem(args.problem, args.n_obj)
        algorithm = make_algorithm(args.algorithm, n_obj=problem.n_obj, pop_size=args.pop_size)
    except (ValueError, TypeError, NotImplementedError) as exc:
        raise _UsageError(str(exc).splitlines()[0]) from None
    if args.evals < algorithm.pop_size:
        raise _UsageError(f"--evals must be at least the population size ({algorithm.pop_size}), "
                          f"got {args.evals}")


def _usage_error(message: str) -> int:
    print(f"python -m moo: error: {message}", file=sys.stderr)
    return 2


def _validate_experiment(args) -> None:
    from moo.experiment import plan

    if args.problem.lower() not in PROBLEMS:
        raise _UsageError(f"unknown problem {args.problem!r}; valid: {', '.join(PROBLEMS)}")
    for name, value, minimum in (("--runs", args.runs, 1), ("--evals", args.evals, 1),
                                 ("--workers", args.workers, 1), ("--seed", args.seed, 0),
                                 ("--pop-size", args.pop_size, 4)):
        if value < minimum:
            raise _UsageError(f"{name} must be >= {minimum}, got {value}")
    if args.molsp_max_leaders is not None and args.molsp_max_leaders < 1:
        raise _UsageError(f"--molsp-max-leaders must be >= 1, got {args.molsp_max_leaders}")
    if os.path.exists(args.out) and not os.path.isdir(args.out):
        raise _UsageError(f"--out: {args.out!r} exists and is not a directory")
    from moo.algorithms import make_algorithm
    from moo.problems import make_problem
    try:
        specs = plan(args.problem, args.algorithms, runs=args.runs, evals=args.evals, n_obj=args.n_obj,
                     base_seed=args.seed, pop_size=args.pop_size, max_leaders=args.molsp_max_leaders)
        problem = make_problem(args.problem, args.n_obj)
        for name in dict.fromkeys(s.algorithm for s in specs):
            algorithm = make_algorithm(name, n_obj=problem.n_obj, pop_size=args.pop_size)
            if args.evals < algorithm.pop_size:
                raise _UsageError(f"--evals must be at least the population size of {name} "
                                  f"({algorithm.pop_size}), got {args.evals}")
    except (ValueError, TypeError, NotImplementedError) as exc:
        raise _UsageError(str(exc).splitlines()[0]) from None


_STATS_FORMATS = (".csv", ".md", ".tex")


def _validate_stats(args) -> None:
    if not os.path.isdir(args.dir):
        raise _UsageError(f"results directory {args.dir!r} does not exist")
    if not 0 < args.alpha < 1:
        raise _UsageError(f"--alpha must be in (0, 1), got {args.alpha}")
    for flag, path, formats in (("--out", args.out, _STATS_FORMATS), ("--runs-out", args.runs_out, (".csv",))):
        if path is None:
            continue
        if os.path.splitext(path)[1].lower() not in formats:
            raise _UsageError(f"{flag} must end in {', '.join(formats)}, got {path!r}")
        if not os.path.isdir(os.path.dirname(os.path.abspath(path))):
            raise _UsageError(f"{flag}: directory of {path!r} does not exist")


def _main_experiment(args) -> int:
    from moo.experiment import run_experiment

    report = run_experiment(args.problem, args.algorithms, runs=args.runs, evals=args.evals, out=args.out,
                            n_obj=args.n_obj, base_seed=args.seed, pop_size=args.pop_size,
                            max_leaders=args.molsp_max_leaders, workers=args.workers)
    if sys.stderr.isatty():
        print(report, file=sys.stderr)
    return 0


def _main_stats(args) -> int:
    from moo.stats import analyse, to_csv, to_latex, to_markdown

    try:
        runs, table = analyse(args.dir, alpha=args.alpha)
    except ValueError as exc:
        return _usage_error(str(exc).splitlines()[0])
    text = to_markdown(table)
    print(text)
    if args.out is not None:
        ext = os.path.splitext(args.out)[1].lower()
        if ext == ".csv":
            to_csv(table, args.out)
        else:
            with open(args.out, "w", encoding="utf-8") as fh:
                fh.write(text if ext == ".md" else to_latex(table))
    if args.runs_out is not None:
        to_csv(runs, args.runs_out)
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit code (0 success, 1 run failure, 2 bad arguments)."""
    try:
        args = _parser().parse_args(argv)
        if args.command == "experiment":
            _validate_experiment(args)
        elif args.command == "stats":
            _validate_stats(args)
        else:
            _validate(args)
    except _UsageError as exc:
        return _usage_error(str(exc))
    if args.command == "experiment":
        return _main_experiment(args)
    if args.command == "stats":
        return _main_stats(args)

    from moo.runner import run  # heavy imports after argument checks

    bar = _Progress(f"{args.algorithm}{'+molsp' if args.molsp else ''} {args.problem} s{args.seed}") \
        if sys.stderr.isatty() else None
    try:
        result = run(args.problem, args.algorithm, seed=args.seed, evals=args.evals, n_obj=args.n_obj,
                     molsp=args.molsp, pop_size=args.pop_size, max_leaders=args.max_leaders, progress=bar)
    finally:
        if bar is not None:
            bar.close()
    with open(args.out, "w", encoding="utf-8") as fh:
        json.dump(result.to_dict(), fh, indent=1)
        fh.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
