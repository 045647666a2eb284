"""moo: multiobjective evolutionary tuning of robust controllers.

MOEAs on top of pymoo (a registry of the paper's ten algorithms), the MO-LSP
local search that wraps any of them, quality indicators, the tuning of a
robust controller for a user's own plant set (:mod:`moo.tuning`), the paper's
two control-design problems, single runs (``python -m moo run``), resumable
experiment grids (``python -m moo experiment``) and the paper's statistics
(``python -m moo stats``: ANOVA and Tukey HSD, MOEA vs its MO-LSP version).

The main entry points are importable from the package itself, as pymoo users
expect; each is loaded on first use, so ``import moo`` stays cheap:

========================  =====================================================
``moo.tune``              :func:`moo.tuning.tune`: tune a controller, select one design
``moo.TuningProblem``     :class:`moo.tuning.TuningProblem`: a family, scenarios and goals
``moo.RLQRFamily``        :class:`moo.tuning.RLQRFamily` (and ``moo.LQRFamily``)
``moo.run``               :func:`moo.runner.run`: one MOEA run
``moo.run_experiment``    :func:`moo.experiment.run_experiment`: a resumable grid
``moo.analyse``           :func:`moo.stats.analyse`: the paper's statistics
``moo.make_algorithm``    :func:`moo.algorithms.make_algorithm` (names: ``moo.algorithms.ALGORITHMS``)
``moo.make_problem``      :func:`moo.problems.make_problem` (names: ``moo.problems.PROBLEMS``)
``moo.hypervolume``       :func:`moo.indicators.hypervolume` (and ``moo.igd``)
========================  =====================================================

The MO-LSP wrapper itself is :func:`moo.molsp.molsp` (the module keeps its name).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

# name -> module that defines it (loaded on first access, PEP 562)
_EXPORTS = {
    "tune": "moo.tuning", "TuningProblem": "moo.tuning", "TuningResult": "moo.tuning",
    "RLQRFamily": "moo.tuning", "LQRFamily": "moo.tuning",
    "run": "moo.runner", "run_experiment": "moo.experiment", "analyse": "moo.stats",
    "make_algorithm": "moo.algorithms", "make_problem": "moo.problems",
    "hypervolume": "moo.indicators", "igd": "moo.indicators",
}

__all__ = ["tune", "TuningProblem", "TuningResult", "RLQRFamily", "LQRFamily", "run", "run_experiment", "analyse",
           "make_algorithm", "make_problem", "hypervolume", "igd"]

if TYPE_CHECKING:
    from .algorithms import make_algorithm
    from .experiment import run_experiment
    from .indicators import hypervolume, igd
    from .problems import make_problem
    from .runner import run
    from .stats import analyse
    from .tuning import LQRFamily, RLQRFamily, TuningProblem, TuningResult, tune


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(importlib.import_module(_EXPORTS[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'moo' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *_EXPORTS])
