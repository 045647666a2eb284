"""A single-objective genetic algorithm for tuning problems with one goal: pymoo's GA with the paper's operators.

The MOEAs of :data:`moo.algorithms.ALGORITHMS` need at least two objectives
(their survival ranks by dominance and diversity); a problem with one
objective runs with :func:`make_ga` (registry name ``"ga"``): pymoo's
``GA`` (binary tournament on fitness, elitist survival of the best
``pop_size``), with the paper's SBX and polynomial mutation. MO-LSP wraps it
as it wraps a MOEA (with one objective its leaders are the best designs).
"""

from __future__ import annotations

from pymoo.algorithms.soo.nonconvex.ga import GA

from ..validation import check_choice, check_int
from .base import MIN_POP_SIZE
from .operators import OPERATOR_CHOICES, PAPER_OPERATORS, POP_SIZE, OperatorSettings, variation_operators

__all__ = ["make_ga"]


def make_ga(*, n_obj: int = 1, pop_size: int = POP_SIZE, operators: str | OperatorSettings = "paper") -> GA:
    """The single-objective ``GA`` of pymoo with the paper's variation operators (``n_obj`` must be 1).

    ``operators="original"`` is the same as ``"paper"`` here (a genetic
    algorithm has no operators of its own paper); an
    :class:`~moo.algorithms.operators.OperatorSettings` sets them.

    Examples
    --------
    >>> from moo.algorithms import make_algorithm
    >>> alg = make_algorithm("ga", n_obj=1, pop_size=20)
    >>> type(alg).__name__, alg.pop_size
    ('GA', 20)
    """
    if check_int(n_obj, "n_obj", 1) != 1:
        raise ValueError(f"n_obj must be 1 for the single-objective 'ga', got {n_obj}; use a MOEA such as "
                         "'nsga2' for several objectives")
    pop_size = check_int(pop_size, "pop_size", MIN_POP_SIZE)
    if not isinstance(operators, OperatorSettings):
        check_choice(operators, "operators", OPERATOR_CHOICES)
        operators = PAPER_OPERATORS
    return GA(pop_size=pop_size, eliminate_duplicates=True, **variation_operators(operators))
