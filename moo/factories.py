"""Problems and algorithms by name or by import path: the one place where the commands resolve them.

Package-internal: the runner, the experiment grid and the command line import
it; :mod:`moo` does not re-export it.

Every entry point (:func:`moo.runner.prepare`, :func:`moo.experiment.plan` and
:func:`~moo.experiment.prepare`, the workers of a process pool or a Dask
cluster, ``python -m moo run | experiment``) builds its problem with
:func:`build_problem` and its algorithm with :func:`build_algorithm`. A name
without a colon is a registry name (:data:`moo.problems.PROBLEMS`,
:data:`moo.algorithms.ALGORITHMS`, case-insensitive); a name with one is an
import path ``package.module:factory`` (case kept; the attribute may be dotted,
``package.module:Class.method``).

Problem factories
    Called with no argument, or with ``n_obj=`` when ``n_obj`` is given (the
    factory must then accept that keyword). It returns a pymoo
    :class:`~pymoo.core.problem.Problem` with two reference points,
    ``hv_ref_point`` and ``molsp_ref_point`` (each of ``n_obj`` finite
    numbers); a ``moo.tuning.TuningProblem`` carries both. A ``setup`` is
    the built-in ``applied`` problem's only.
Algorithm factories
    Called as ``factory(n_obj=M, pop_size=P)`` (the problem's number of
    objectives and the population size asked for), the signature of the
    registry's own factories; it returns a pymoo
    :class:`~pymoo.core.algorithm.Algorithm` not yet set up. With MO-LSP it is
    wrapped by :func:`moo.molsp.molsp`, which needs a
    :class:`~pymoo.algorithms.base.genetic.GeneticAlgorithm`-like MOEA (a
    ``survival`` operator and a ``pop_size``).

The record names the problem and the algorithm by the path as given. The
module must be importable wherever the runs go: in this process (the current
directory is on ``sys.path`` under ``python -m moo``) and in every worker:
a local process pool inherits this process's ``sys.path``, the workers of a
Dask scheduler need the module installed or on their ``PYTHONPATH``.

Errors (a path that does not import, an attribute that is not there or not
callable, a factory that raises or returns something else) are one-line
``ValueError``/``TypeError`` naming the path, raised before any run.
"""

from __future__ import annotations

import inspect
import re
from importlib import import_module
from typing import Any

import numpy as np
from pymoo.core.algorithm import Algorithm
from pymoo.core.problem import Problem

from moo.store import is_import_path

__all__ = ["load_factory", "build_problem", "build_algorithm", "check_algorithm_name", "check_problem_name"]

_PATH = re.compile(r"^[A-Za-z_][\w]*(\.[A-Za-z_][\w]*)*:[A-Za-z_][\w]*(\.[A-Za-z_][\w]*)*$")


def _first_line(exc: BaseException) -> str:
    text = str(exc).splitlines()[0] if str(exc) else ""
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def load_factory(path: str, what: str) -> Any:
    """The callable at ``path`` (``module.path:attr``); ``ValueError`` naming ``what`` and the path otherwise."""
    if not isinstance(path, str) or not _PATH.match(path.strip()):
        raise ValueError(f"{what} {path!r} is not an import path of the form 'package.module:factory'")
    module_name, attr = path.strip().split(":")
    try:
        obj: Any = import_module(module_name)
    except Exception as exc:  # noqa: BLE001 - any import failure is the user's module: one line naming it
        raise ValueError(f"{what} {path!r}: cannot import module {module_name!r} ({_first_line(exc)})") from None
    for part in attr.split("."):
        try:
            obj = getattr(obj, part)
        except AttributeError:
            raise ValueError(f"{what} {path!r}: module {module_name!r} has no attribute {attr!r}") from None
    if not callable(obj):
        raise TypeError(f"{what} {path!r} is not callable (a {type(obj).__name__})")
    return obj


def _accepts(func: Any, name: str) -> bool:
    try:
        params = inspect.signature(func).parameters.values()
    except (TypeError, ValueError):
        return True                     # builtins without a signature: let the call decide
    return any(p.name == name or p.kind is inspect.Parameter.VAR_KEYWORD for p in params)


def _call(factory: Any, path: str, what: str, **kwargs: Any) -> Any:
    try:
        return factory(**kwargs)
    except Exception as exc:  # noqa: BLE001 - the user's factory: one line naming it
        raise ValueError(f"{what} {path!r} raised {_first_line(exc)}") from None


def build_problem(name: str, n_obj: int | None = None, *, setup: str | None = None) -> Problem:
    """The problem ``name``: :func:`moo.problems.make_problem` or a user's factory (module docstring)."""
    from moo.problems import make_problem

    if not is_import_path(name):
        return make_problem(name, n_obj, setup=setup)
    if setup is not None:
        raise ValueError(f"setup applies to the 'applied' problem only, got setup={setup!r} for {name!r}")
    factory = load_factory(name, "problem")
    if n_obj is None:
        problem = _call(factory, name, "problem factory")
    else:
        if not _accepts(factory, "n_obj"):
            raise ValueError(f"problem factory {name!r} takes no n_obj argument, so n_obj cannot be given")
        problem = _call(factory, name, "problem factory", n_obj=n_obj)
    if not isinstance(problem, Problem):
        raise TypeError(f"problem factory {name!r} returned a {type(problem).__name__}, "
                        "not a pymoo Problem")
    if n_obj is not None and problem.n_obj != n_obj:
        raise ValueError(f"problem factory {name!r} returned a problem with {problem.n_obj} objectives, "
                         f"asked for n_obj={n_obj}")
    for attr in ("hv_ref_point", "molsp_ref_point"):
        point = getattr(problem, attr, None)
        if point is None:
            raise ValueError(f"problem factory {name!r} returned a problem without the {attr} attribute "
                             "(a reference point of n_obj numbers)")
        try:
            arr = np.asarray(point, dtype=float)
        except (TypeError, ValueError):
            arr = np.empty(0)
        if arr.shape != (problem.n_obj,) or not np.all(np.isfinite(arr)):
            raise ValueError(f"problem factory {name!r}: {attr} must be {problem.n_obj} finite numbers "
                             f"(one per objective), got {point!r}")
    return problem


def build_algorithm(name: str, *, n_obj: int, pop_size: int) -> Algorithm:
    """The algorithm ``name``: :func:`moo.algorithms.make_algorithm` or a user's factory (module docstring)."""
    from moo.algorithms import make_algorithm

    if not is_import_path(name):
        return make_algorithm(name, n_obj=n_obj, pop_size=pop_size)
    factory = load_factory(name, "algorithm")
    alg = _call(factory, name, "algorithm factory", n_obj=n_obj, pop_size=pop_size)
    if not isinstance(alg, Algorithm):
        raise TypeError(f"algorithm factory {name!r} returned a {type(alg).__name__}, not a pymoo Algorithm")
    if not hasattr(alg, "pop_size"):
        raise TypeError(f"algorithm factory {name!r} returned an algorithm without a pop_size")
    return alg


def _record_key(name: object, registry, unknown: str) -> str:
    """A registry name in lower case, or an import path as given (stripped); ``ValueError(unknown; valid: ...)``."""
    if is_import_path(name):
        assert isinstance(name, str)
        return name.strip()
    if not isinstance(name, str) or name.lower() not in registry:
        raise ValueError(f"{unknown}; valid: {', '.join(registry)} or module.path:factory")
    return name.lower()


def check_problem_name(name: object) -> str:
    """The record key of a problem: a registry name in lower case, an import path as given."""
    from moo.problems import PROBLEMS

    return _record_key(name, PROBLEMS, f"unknown problem {name!r}")


def check_algorithm_name(name: object) -> str:
    """The record key of an algorithm: a registry name in lower case, an import path as given."""
    from moo.algorithms import ALGORITHMS, MORE_ALGORITHMS

    return _record_key(name, {**ALGORITHMS, **MORE_ALGORITHMS}, f"unknown algorithm {name!r} in algorithms")
