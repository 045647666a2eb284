"""NSGA-II and NSGA-III from pymoo, configured with the paper's settings.

Deb, Pratap, Agarwal & Meyarivan (2002), IEEE TEVC 6(2), 182-197 (NSGA-II);
Deb & Jain (2014), IEEE TEVC 18(4), 577-601 (NSGA-III).
"""

from __future__ import annotations

import numpy as np
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.algorithms.moo.nsga3 import NSGA3

from .base import factory_arguments, factory_ref_dirs
from .operators import POP_SIZE, OperatorSettings

__all__ = ["make_nsga2", "make_nsga3", "make_pymoo_nsga2", "NSGA2_ORIGINAL_OPERATORS", "NSGA3_ORIGINAL_OPERATORS"]

#: NSGA-II's own settings (Deb et al. 2002, Sec. VI: SBX pc = 0.9, eta_c = 20; pm = 1/n, eta_m = 20).
NSGA2_ORIGINAL_OPERATORS = OperatorSettings(crossover_prob=0.9, crossover_eta=20.0, mutation_rate=1.0,
                                            mutation_eta=20.0, source="Deb et al. (2002), Sec. VI")
#: NSGA-III's own settings (Deb & Jain 2014, Table II: SBX pc = 1, eta_c = 30; pm = 1/n, eta_m = 20).
NSGA3_ORIGINAL_OPERATORS = OperatorSettings(crossover_prob=1.0, crossover_eta=30.0, mutation_rate=1.0,
                                            mutation_eta=20.0, source="Deb & Jain (2014), Table II")


def make_nsga2(*, n_obj: int, pop_size: int = POP_SIZE, operators: str | OperatorSettings = "paper") -> NSGA2:
    """NSGA-II (binary tournament on rank and crowding, rank + crowding survival).

    ``operators="original"``: :data:`NSGA2_ORIGINAL_OPERATORS`.
    """
    _, pop_size, variation = factory_arguments(n_obj, pop_size, operators, NSGA2_ORIGINAL_OPERATORS)
    return NSGA2(pop_size=pop_size, eliminate_duplicates=True, **variation)


def make_pymoo_nsga2(*, n_obj: int, pop_size: int = POP_SIZE) -> NSGA2:
    """The NSGA-II of pymoo itself, every operator at pymoo's default (registry name ``"pymoo-nsga2"``).

    pymoo 0.6's defaults: SBX with ``prob = 0.9``, ``eta = 15``; polynomial
    mutation with ``eta = 20`` at rate ``1 / n_var``; binary tournament on rank
    and crowding. ``"nsga2"`` is the same algorithm with the paper's
    operators (:data:`~moo.algorithms.operators.PAPER_OPERATORS`).

    Examples
    --------
    >>> from moo.algorithms import make_algorithm
    >>> alg = make_algorithm("pymoo-nsga2", n_obj=2, pop_size=40)
    >>> alg.mating.crossover.eta.value, alg.mating.crossover.prob.value
    (15, 0.9)
    """
    _, pop_size, _ = factory_arguments(n_obj, pop_size, "paper", NSGA2_ORIGINAL_OPERATORS)
    return NSGA2(pop_size=pop_size)


def make_nsga3(*, n_obj: int, pop_size: int = POP_SIZE, operators: str | OperatorSettings = "paper",
               ref_dirs: np.ndarray | None = None) -> NSGA3:
    """NSGA-III with ``ref_dirs``, by default :func:`~moo.algorithms.operators.reference_directions` (91 for M = 3).

    The population is ``max(pop_size, len(ref_dirs))``; ``operators="original"``:
    :data:`NSGA3_ORIGINAL_OPERATORS`.
    """
    n_obj, pop_size, variation = factory_arguments(n_obj, pop_size, operators, NSGA3_ORIGINAL_OPERATORS)
    ref_dirs = factory_ref_dirs(ref_dirs, n_obj, pop_size)
    return NSGA3(ref_dirs=ref_dirs, pop_size=max(pop_size, len(ref_dirs)), eliminate_duplicates=True, **variation)
