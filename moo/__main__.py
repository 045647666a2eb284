"""Command line: ``python -m moo run | experiment | stats | plot | select``.

::

    python -m moo run --problem {generic,applied,zdt1..6,dtlz1..7} [--n-obj M] [--setup S]
                      --algorithm NAME [--molsp [--max-leaders K]] --seed S
                      --evals N [--pop-size P] --out FILE.json [--quiet]
    python -m moo experiment --problem P [--n-obj M] [--setup S] [--algorithms all|a,b] --runs N
                      --evals E [--max-leaders K] [--pop-size P] [--seed BASE] --out DIR
                      [--executor {process,dask}] [--workers W] [--scheduler ADDRESS]
                      [--keep-going] [--quiet]
    python -m moo stats DIR [--out FILE.csv|.md|.tex] [--ranks-out FILE.csv|.md|.tex]
                      [--runs-out FILE.csv] [--alpha A]
    python -m moo plot DIR --out FIGDIR [--format png,pdf]
    python -m moo select SOURCE --problem P [--n-obj M] [--setup S] [--algorithm NAME [--molsp]]
                      [--n-sims N] --seed S [--out FILE.json] [--quiet]

``--problem`` and ``--algorithm``/``--algorithms`` take a registry name or the
import path ``package.module:factory`` of a user's problem or MOEA (see
:mod:`moo.factories`: the problem factory is called with no argument, or with
``n_obj=`` given ``--n-obj``, and returns a pymoo Problem carrying
``hv_ref_point`` and ``molsp_ref_point``; the algorithm factory is called as
``factory(n_obj=M, pop_size=P)`` and returns a pymoo Algorithm). The module
must be importable by the driver and by every worker (the current directory
or ``PYTHONPATH``; a Dask cluster's workers need it installed).

``run`` runs :func:`moo.runner.run` and writes its record (the fields are
listed in :mod:`moo.runner`) as JSON. ``experiment`` runs a resumable grid
(:func:`moo.experiment.run_experiment`; one record per run under DIR) in this
process, a local process pool, or on a Dask cluster (:mod:`moo.executors`).
``stats`` computes the indicators per run and the comparisons of
:mod:`moo.stats`, prints the tables as Markdown and writes them in the format
of the file's extension. ``plot`` draws the figures of :mod:`moo.plots`.
``select`` picks one design of a recorded front by the Monte Carlo selection
(:func:`moo.record_selection.select_from_records`): SOURCE is a run record or
a results directory (the non-dominated union of the fronts of its runs of
the problem, or of one algorithm's with ``--algorithm``); the problem, which
must be a ``moo.tuning.TuningProblem``, is rebuilt from ``--problem``.

The CLI is a thin layer: every check is the library's (:func:`moo.runner.prepare`,
:func:`moo.experiment.prepare`, :func:`moo.executors.open_executor`,
:mod:`moo.store`), done before any work; its messages name the flag.

Exit codes (the same for every command):

* 0 - done;
* 1 - the work failed: a run raised (``experiment``: without ``--keep-going``
  the grid stops there; with it, the grid finishes and the failed runs are
  listed), or the executor failed (pool processes killed more often than
  the pool restarts, the scheduler unreachable). One line on stderr says
  what and where the traceback is; the records already written stay, and
  rerunning the command resumes;
  An output that cannot be written (a full disk, ``OSError``) is also 1,
  with one line naming the file; nothing is left half-written (every output
  is written atomically), and ``run`` keeps its finished run: its record
  goes to a file in the temporary directory, or to stdout, and the message
  says where;
* 2 - bad arguments (a one-line message on stderr; nothing was run or written),
  including an unusable ``--out``, a results directory in use by another
  ``experiment`` (one writer at a time) or holding runs with other settings
  (its ``settings.json`` or a record, named with the setting), a ``--problem``
  or ``--algorithm`` import path that does not import or whose factory
  returns something else, an unparsable ``--scheduler``, and a corrupt
  record, a duplicate run or a directory mixing two settings read by
  ``stats``, ``plot`` or ``select`` (the file is named), and a ``select``
  whose problem is not a ``moo.tuning.TuningProblem`` or whose SOURCE holds
  no run of it;
* 130 - interrupted (Ctrl-C); the records already written stay.

On a terminal (stderr), ``run``, ``experiment`` and ``select`` show a progress
bar (tqdm) while they work, and ``run`` and ``experiment`` end with one summary
line (the front's size, its hypervolume and the reference point's source,
the best value of each objective, where the results were written); with
``--quiet``, or when stderr is not a terminal (a log, a pipe), they print
nothing but errors (``select`` prints its choice on stdout in any case).

Algorithm names (``--algorithm``, ``--algorithms``; ``all`` is the ten MOEAs
of the study): ``nsga2`` is NSGA-II with the paper's operators, not pymoo's
defaults; ``pymoo-nsga2`` is pymoo's own NSGA-II; ``ga`` is a single-objective
genetic algorithm for problems with one objective (``python -m moo run -h``
lists every name with its meaning).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import sys
import traceback
from collections.abc import Iterator, Sequence
from contextlib import contextmanager, nullcontext

from moo.algorithms import ALGORITHM_NOTES, ALGORITHMS, MORE_ALGORITHMS
from moo.algorithms.operators import POP_SIZE
from moo.problems import PROBLEMS
from moo.progress import ProgressBar, front_summary
from moo.store import DISK_ERRORS, SettingsMismatchError

__all__ = ["main"]

_PROG = "python -m moo"

_SETUP_HELP = "set-up of the applied problem: ours (default) or authors (the authors' published code)"
_QUIET_HELP = "no progress bar and no summary line (the default when stderr is not a terminal)"
_ALGORITHM_NAMES = "algorithms (all: the ten of the study):\n" + "\n".join(
    f"  {name:<12} {note}" for name, note in ALGORITHM_NOTES.items())
_EXIT_CODES = """exit codes: 0 done; 1 the work failed (a run raised, or the executor failed; records
already written stay, rerun to resume); 2 bad arguments (nothing run); 130 interrupted"""


class _UsageError(Exception):
    pass


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit code 2 (handled in main)
        raise _UsageError(message)


def _subparser(sub, name: str, help_text: str, example: str, more: str = "") -> argparse.ArgumentParser:
    return sub.add_parser(name, help=help_text, description=help_text,
                          epilog=f"example:\n  {example}\n\n{more + chr(10) * 2 if more else ''}{_EXIT_CODES}",
                          formatter_class=argparse.RawDescriptionHelpFormatter)


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(prog=_PROG, description="Multiobjective tuning with MOEAs and MO-LSP.",
                     formatter_class=argparse.RawDescriptionHelpFormatter,
                     epilog="examples:\n"
                            f"  {_PROG} run --problem zdt1 --algorithm nsga2 --seed 0 --evals 2000 --out run.json\n"
                            f"  {_PROG} experiment --problem generic --runs 50 --evals 10000 --out results/generic\n"
                            f"  {_PROG} stats results/generic --out table.md\n"
                            f"  {_PROG} plot results/generic --out figures\n"
                            f"  {_PROG} select results/generic --problem generic --seed 0 --out design.json\n\n"
                            + _EXIT_CODES)
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    r = _subparser(sub, "run", "one run of a MOEA on a problem, recorded as JSON",
                   f"{_PROG} run --problem applied --algorithm nsga3 --molsp --seed 1 --evals 10000 --out run.json",
                   _ALGORITHM_NAMES)
    r.add_argument("--problem", required=True, help=f"one of {', '.join(PROBLEMS)}, or package.module:factory")
    r.add_argument("--n-obj", type=int, default=None, help="number of objectives (DTLZ; default 3)")
    r.add_argument("--setup", default=None, help=_SETUP_HELP)
    r.add_argument("--algorithm", required=True,
                   help=f"one of {', '.join([*ALGORITHMS, *MORE_ALGORITHMS])} (see below), or package.module:factory")
    r.add_argument("--molsp", action="store_true", help="add MO-LSP to the algorithm")
    r.add_argument("--max-leaders", type=int, default=None, help="MO-LSP cap on candidates per generation")
    r.add_argument("--seed", type=int, required=True, help="seed (integer >= 0)")
    r.add_argument("--evals", type=int, required=True, help="evaluation budget")
    r.add_argument("--pop-size", type=int, default=POP_SIZE, help=f"population size (default {POP_SIZE})")
    r.add_argument("--out", required=True, help="output JSON file (checked before the run)")
    r.add_argument("--quiet", action="store_true", help=_QUIET_HELP)

    e = _subparser(sub, "experiment", "a resumable grid of runs: algorithms x {plain, MO-LSP} x seeds",
                   f"{_PROG} experiment --problem generic --algorithms nsga2,nsga3 --runs 50 --evals 10000 "
                   "--out results/generic --executor dask --workers 2", _ALGORITHM_NAMES)
    e.add_argument("--problem", required=True, help=f"one of {', '.join(PROBLEMS)}, or package.module:factory")
    e.add_argument("--n-obj", type=int, default=None, help="number of objectives (DTLZ; default 3)")
    e.add_argument("--setup", default=None, help=_SETUP_HELP)
    e.add_argument("--algorithms", default="all",
                   help="'all' or a comma-separated list of names or package.module:factory (default all)")
    e.add_argument("--runs", type=int, required=True, help="independent runs per algorithm and variant")
    e.add_argument("--evals", type=int, required=True, help="evaluation budget of each run")
    e.add_argument("--max-leaders", type=int, default=None, help="MO-LSP cap on candidates per generation")
    e.add_argument("--molsp-max-leaders", type=int, default=None, help=argparse.SUPPRESS)  # deprecated alias
    e.add_argument("--pop-size", type=int, default=POP_SIZE, help=f"population size (default {POP_SIZE})")
    e.add_argument("--seed", type=int, default=0, help="base seed of the SeedSequence (default 0)")
    e.add_argument("--out", required=True, help="results directory (created; existing runs are kept)")
    e.add_argument("--executor", choices=("process", "dask"), default="process",
                   help="'process' (default): this process or a local pool; 'dask': a Dask cluster")
    e.add_argument("--workers", type=int, default=None,
                   help="processes of the local pool or local Dask cluster (default 1)")
    e.add_argument("--scheduler", default=None,
                   help="address of a running Dask scheduler (with --executor dask), e.g. tcp://HOST:8786")
    e.add_argument("--keep-going", action="store_true",
                   help="record a failed run (with its traceback) and go on; default: stop at the first failure")
    e.add_argument("--quiet", action="store_true", help=_QUIET_HELP)

    s = _subparser(sub, "stats", "indicators and statistics (ANOVA/Tukey, Wilcoxon-Holm, Friedman/Nemenyi)",
                   f"{_PROG} stats results/generic --out table.tex --ranks-out ranks.md --runs-out runs.csv")
    s.add_argument("dir", help="results directory written by 'experiment'")
    s.add_argument("--out", default=None, help="write the MOEA vs MO-LSP table to FILE (.csv, .md or .tex)")
    s.add_argument("--ranks-out", default=None, help="write the Friedman ranks table to FILE (.csv, .md or .tex)")
    s.add_argument("--runs-out", default=None, help="write the per-run indicators to FILE (.csv)")
    s.add_argument("--alpha", type=float, default=0.05, help="significance level (default 0.05)")

    p = _subparser(sub, "plot", "figures of a results directory (hypervolume, box plots, fronts, CD diagrams)",
                   f"{_PROG} plot results/generic --out figures --format png,pdf")
    p.add_argument("dir", help="results directory written by 'experiment'")
    p.add_argument("--out", required=True, help="figure directory (created)")
    p.add_argument("--format", default="png,pdf", help="comma-separated file formats (default png,pdf)")
    p.add_argument("--alpha", type=float, default=0.05, help="significance level of the CD diagrams")

    c = _subparser(sub, "select", "pick one design of a recorded front by the Monte Carlo selection over the "
                   "problem's scenarios (the paper's two problems: the paper's selection)",
                   f"{_PROG} select results/tune --problem mypkg.plant:problem --algorithm nsga2 --molsp "
                   f"--n-sims 1000 --seed 0 --out design.json\n"
                   f"  {_PROG} select run.json --problem mypkg.plant:problem --seed 0")
    c.add_argument("source", metavar="SOURCE",
                   help="a run record (from 'run --out') or a results directory (from 'experiment'): the "
                        "candidates are the non-dominated union of the final fronts of its runs of the problem")
    c.add_argument("--problem", required=True,
                   help="the problem of the runs (a moo.tuning.TuningProblem): generic, applied, or "
                        "package.module:factory")
    c.add_argument("--n-obj", type=int, default=None, help="number of objectives (as given to run/experiment)")
    c.add_argument("--setup", default=None, help=_SETUP_HELP)
    c.add_argument("--algorithm", default=None,
                   help="only this algorithm's runs (name or package.module:factory; default: every run)")
    c.add_argument("--molsp", action="store_true",
                   help="with --algorithm: its MO-LSP runs (default: its plain runs); alone: every MO-LSP run")
    c.add_argument("--n-sims", type=int, default=1000, help="number of simulations (default 1000, the paper's)")
    c.add_argument("--seed", type=int, required=True, help="seed of the draws (integer >= 0)")
    c.add_argument("--out", default=None, help="write the selection to FILE.json (checked before the work)")
    c.add_argument("--quiet", action="store_true", help="no progress bar (the default when stderr is not a terminal)")
    return parser


# ---------------------------------------------------------------------------- library errors -> usage errors

_FLAGS = {"seed": "--seed", "base_seed": "--seed", "evals": "--evals", "pop_size": "--pop-size",
          "max_leaders": "--max-leaders", "n_obj": "--n-obj", "runs": "--runs", "workers": "--workers",
          "scheduler": "--scheduler", "executor": "--executor", "alpha": "--alpha", "algorithms": "--algorithms",
          "out": "--out", "setup": "--setup", "n_sims": "--n-sims", "problem": "--problem",
          "algorithm": "--algorithm", "source": "SOURCE"}


def _flagged(message: str) -> str:
    """The library's message with its leading argument name spelled as the CLI flag."""
    message = str(message).splitlines()[0] if str(message) else type(message).__name__
    m = re.match(r"([a-z_]+)\b", message)
    if m and m.group(1) in _FLAGS:
        message = _FLAGS[m.group(1)] + message[m.end():]
    return message.replace("molsp=True", "--molsp")


#: The settings of a results directory (:mod:`moo.store`) by the flags that set them.
_SETTING_FLAGS = {"budget": "--evals", "pop_size": "--pop-size", "max_leaders": "--max-leaders",
                  "base_seed": "--seed", "seed": "--seed", "problem": "--problem", "n_obj": "--n-obj",
                  "setup": "--setup", "algorithm": "--algorithms", "molsp": "the MO-LSP variant"}


def _settings_message(exc: SettingsMismatchError) -> str:
    """A settings mismatch with the settings named by their flags (``--evals 40 (this grid: 60)``)."""
    return exc.message(_SETTING_FLAGS)


@contextmanager
def _usage() -> Iterator[None]:
    """Turn the library's argument errors (raised before any work) into usage errors."""
    try:
        yield
    except SettingsMismatchError as exc:
        raise _UsageError(_settings_message(exc)) from None
    except (ValueError, TypeError, NotImplementedError) as exc:
        raise _UsageError(_flagged(str(exc))) from None


def _error(message: str, code: int) -> int:
    print(f"{_PROG}: error: {message}", file=sys.stderr)
    return code


def _failure(exc: BaseException, what: str) -> int:
    """Exit 1 for an exception during the work: its traceback, then one line naming it."""
    traceback.print_exception(exc, file=sys.stderr)
    return _error(f"{what}: {type(exc).__name__}: {_flagged(str(exc)) if str(exc) else ''}".rstrip(": "), 1)


# ---------------------------------------------------------------------------- commands

def _cmd_run(args) -> int:
    from moo.runner import prepare
    from moo.store import check_output_file, write_json_atomic

    with _usage():
        out = check_output_file(args.out, "--out")
        job = prepare(args.problem, args.algorithm, seed=args.seed, evals=args.evals, n_obj=args.n_obj,
                      molsp=args.molsp, pop_size=args.pop_size, max_leaders=args.max_leaders, setup=args.setup)
    bar = ProgressBar(f"{args.algorithm}{'+molsp' if args.molsp else ''} {args.problem} s{args.seed}",
                      unit="evals", total=args.evals, enabled=False if args.quiet else None)
    try:
        with bar:
            result = job.run(progress=bar)
    except Exception as exc:  # noqa: BLE001 - the CLI's boundary: traceback, then one line naming it
        return _failure(exc, "the run failed")
    record = result.to_dict()
    try:
        write_json_atomic(out, record)
    except OSError as exc:
        return _error(f"cannot write {out} ({_os_reason(exc)}); {_keep_elsewhere(record, out)}", 1)
    if bar.enabled:
        names = getattr(job.problem, "objective_names", None) or [f"f{j + 1}" for j in range(result.F.shape[1])]
        source = getattr(job.problem, "hv_ref_source", "the problem's hv_ref_point")
        print(front_summary(result.F, names, result.hv, source, str(out)), file=sys.stderr)
    return 0


def _os_reason(exc: OSError) -> str:
    """``strerror`` of a disk error (``No space left on device``), else its first line."""
    if exc.strerror:
        return exc.strerror
    return str(exc).splitlines()[0] if str(exc) else type(exc).__name__


def _keep_elsewhere(record: dict, out) -> str:
    """Save a finished run's record that could not go to ``out``: a temporary file, else stdout."""
    import json
    import tempfile

    text = json.dumps(record, indent=1) + "\n"
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f"moo-run-{os.path.splitext(os.path.basename(out))[0]}-",
                                   suffix=".json")
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        return f"the finished run's record is kept in {tmp}"
    except OSError:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        sys.stdout.write(text)
        sys.stdout.flush()
        return "the finished run's record is printed on stdout"


def _cmd_experiment(args) -> int:
    from moo.executors import open_executor
    from moo.experiment import RunFailedError, prepare
    from moo.store import ResultsDirBusyError

    if args.molsp_max_leaders is not None:
        if args.max_leaders is not None:
            raise _UsageError("give --max-leaders only (--molsp-max-leaders is its deprecated alias)")
        print(f"{_PROG}: warning: --molsp-max-leaders is deprecated, use --max-leaders", file=sys.stderr)
        args.max_leaders = args.molsp_max_leaders
    with _usage():
        executor = open_executor(args.executor, workers=args.workers, scheduler=args.scheduler)
        grid = prepare(args.problem, args.algorithms, runs=args.runs, evals=args.evals, out=args.out,
                       n_obj=args.n_obj, base_seed=args.seed, pop_size=args.pop_size,
                       max_leaders=args.max_leaders, setup=args.setup)
    show = not args.quiet and sys.stderr.isatty()
    if grid.skipped and show:
        retry = f", {grid.retried} failed before and retried" if grid.retried else ""
        print(f"{grid.skipped} of {len(grid.specs)} runs already done in {grid.out} (skipped); "
              f"{len(grid.todo)} to run{retry}", file=sys.stderr)
    try:
        with executor if grid.todo else nullcontext() as ex:    # nothing to run: no cluster to start
            report = grid.run(ex, keep_going=args.keep_going, progress=show)
    except RunFailedError as exc:
        return _error(f"{exc}; the records written stay, rerun to resume", 1)
    except ConnectionError as exc:
        return _error(str(exc), 1)
    except OSError as exc:
        if exc.errno not in DISK_ERRORS and exc.filename is None:
            return _failure(exc, "the experiment stopped (the records written stay, rerun to resume)")
        return _error(f"cannot write a record in {grid.out} ({_os_reason(exc)}); the records "
                      "written stay: free the space and rerun the same command to resume", 1)
    except ResultsDirBusyError as exc:
        return _error(str(exc), 2)
    except SettingsMismatchError as exc:
        return _error(_settings_message(exc), 2)
    except Exception as exc:  # noqa: BLE001 - as in _cmd_run
        return _failure(exc, "the experiment stopped (the records written stay, rerun to resume)")
    if show:
        print(report.summary(), file=sys.stderr)
    if report.failed:
        more = f" and {len(report.failed) - 1} more" if len(report.failed) > 1 else ""
        return _error(f"{len(report.failed)} of {report.total} runs failed; tracebacks in "
                      f"{report.failed[0]}{more}", 1)
    return 0


_TABLE_FORMATS = (".csv", ".md", ".tex")


def _check_table_path(flag: str, path: str | None, formats: tuple[str, ...]) -> None:
    from moo.store import check_output_file

    if path is None:
        return
    if os.path.splitext(path)[1].lower() not in formats:
        raise ValueError(f"{flag} must end in {', '.join(formats)}, got {path!r}")
    check_output_file(path, flag)


def _write_table(path: str, csv_text: str, markdown: str, latex: str) -> None:
    from moo.store import write_text_atomic

    write_text_atomic(path, {".csv": csv_text, ".md": markdown, ".tex": latex}[os.path.splitext(path)[1].lower()])


def _write_failed(exc: OSError, what: str) -> int:
    return _error(f"cannot write {what} ({_os_reason(exc)}); no partial file is left", 1)


def _results_dir(path: str) -> None:
    if not os.path.isdir(path):
        raise ValueError(f"results directory {path!r} does not exist")


def _cmd_stats(args) -> int:
    from moo import stats

    with _usage():
        _results_dir(args.dir)
        if not 0 < args.alpha < 1:
            raise ValueError(f"alpha must be in (0, 1), got {args.alpha}")
        _check_table_path("--out", args.out, _TABLE_FORMATS)
        _check_table_path("--ranks-out", args.ranks_out, _TABLE_FORMATS)
        _check_table_path("--runs-out", args.runs_out, (".csv",))
        runs, table = stats.analyse(args.dir, alpha=args.alpha)
    ranks = stats.friedman(runs, alpha=args.alpha)
    md, ranks_md = stats.to_markdown(table), stats.ranks_to_markdown(ranks)
    print(md)
    print(ranks_md)
    outputs = ((args.out, lambda p: _write_table(p, stats.to_csv(table), md, stats.to_latex(table))),
               (args.ranks_out, lambda p: _write_table(p, stats.ranks_to_csv(ranks), ranks_md,
                                                       stats.ranks_to_latex(ranks))),
               (args.runs_out, lambda p: stats.to_csv(runs, p)))
    for path, write in outputs:
        if path is None:
            continue
        try:
            write(path)
        except OSError as exc:
            return _write_failed(exc, path)
    return 0


def _cmd_plot(args) -> int:
    from moo import plots
    from moo.store import load_records, prepare_results_dir

    with _usage():
        _results_dir(args.dir)
        formats = plots.check_formats(args.format)
        if not 0 < args.alpha < 1:
            raise ValueError(f"alpha must be in (0, 1), got {args.alpha}")
        records = load_records(args.dir)
        if not records:
            raise ValueError(f"no run records (*/*/seed_*.json) under {args.dir!r}")
        out = prepare_results_dir(args.out, "--out")
    try:
        for path in plots.plot_results(records, out, formats=formats, alpha=args.alpha):
            print(path)
    except OSError as exc:
        return _write_failed(exc, f"a figure in {out}")
    return 0


def _vector(values) -> str:
    import numpy as np

    return np.array2string(np.asarray(values, dtype=float), precision=6, max_line_width=100, separator=", ")


def _cmd_select(args) -> int:
    from moo.factories import build_problem, check_algorithm_name, check_problem_name
    from moo.record_selection import front_from_records, load_source, select_on_front
    from moo.runner import setup_name
    from moo.store import check_output_file, write_json_atomic
    from moo.tuning import TuningProblem
    from moo.validation import check_int

    with _usage():
        out = None if args.out is None else check_output_file(args.out, "--out")
        check_int(args.seed, "seed", 0)
        check_int(args.n_sims, "n_sims", 1)
        name = check_problem_name(args.problem)
        algorithm = None if args.algorithm is None else check_algorithm_name(args.algorithm)
        molsp = True if args.molsp else (False if algorithm is not None else None)
        problem = build_problem(name, args.n_obj, setup=args.setup)
        if not isinstance(problem, TuningProblem):
            raise TypeError(f"select needs a moo.tuning.TuningProblem; --problem {args.problem!r} is a "
                            f"{type(problem).__name__}")
        records = load_source(args.source)
        front = front_from_records(records, problem, problem_name=name, algorithm=algorithm, molsp=molsp)
    try:
        with ProgressBar("select", unit="plants", enabled=False if args.quiet else None) as bar:
            sel = select_on_front(problem, front, n_sims=args.n_sims, seed=args.seed, progress=bar)
    except Exception as exc:  # noqa: BLE001 - as in _cmd_run
        return _failure(exc, "the selection failed")
    where = "" if sel.index is None else f" ({sel.front.origin[sel.index][0]}, row {sel.front.origin[sel.index][1]})"
    rule = ("the paper's (moo.problems.selection.select_design)" if sel.rule == "paper"
            else "the problem's scenarios (moo.tuning.selection)")
    print(f"selected design {sel.label} of {len(sel.labels)} candidates{where}")
    print(f"  front: {len(sel.front)} non-dominated designs of {len(sel.front.records)} run record(s)")
    print(f"  rule: {rule}; {args.n_sims} simulations, seed {args.seed}")
    print(f"  wins: {sel.wins}/{sel.n_sims} ({100 * sel.share:.1f} %)")
    print(f"  z = {_vector(sel.z)}")
    if sel.K is not None:
        print(f"  K = {_vector(sel.K).replace(chr(10), chr(10) + '      ')}")
    elif sel.controller is not None:
        print(f"  K(z): order {sel.controller.order}, "
              f"Dc = {_vector(sel.controller.Dc).replace(chr(10), chr(10) + '      ')}")
    if sel.margin is not None:
        print(f"  certified robust margin (NormBounded uncertainty): {sel.margin:.6g}")
    if out is not None:
        data = {"source": str(args.source), "problem": name, "n_obj": problem.n_obj, "setup": setup_name(problem),
                "algorithm": algorithm, "molsp": molsp, "seed": args.seed, **sel.to_dict()}
        try:
            write_json_atomic(out, data)
        except OSError as exc:
            return _write_failed(exc, str(out))
    return 0


_COMMANDS = {"run": _cmd_run, "experiment": _cmd_experiment, "stats": _cmd_stats, "plot": _cmd_plot,
             "select": _cmd_select}


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit code (see the module docstring)."""
    try:
        args = _parser().parse_args(argv)
        return _COMMANDS[args.command](args)
    except _UsageError as exc:
        return _error(str(exc), 2)
    except KeyboardInterrupt:
        return _error("interrupted; the records written stay, rerun the same command to resume", 130)


if __name__ == "__main__":
    sys.exit(main())
