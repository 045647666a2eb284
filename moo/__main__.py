"""Command line: ``python -m moo run``.

::

    python -m moo run --problem {generic,applied,zdt1..6,dtlz1..7} [--n-obj M]
                      --algorithm NAME [--molsp [--max-leaders K]] --seed S
                      --evals N [--pop-size P] --out FILE.json

Runs :func:`moo.runner.run` and writes its record (:meth:`RunResult.to_dict`)
as JSON. A progress bar goes to stderr when stderr is a terminal; nothing is
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


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit code (0 success, 1 run failure, 2 bad arguments)."""
    try:
        args = _parser().parse_args(argv)
        _validate(args)
    except _UsageError as exc:
        return _usage_error(str(exc))

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
