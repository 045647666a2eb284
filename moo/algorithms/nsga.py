"""NSGA-II and NSGA-III from pymoo, configured with the paper's settings.

Deb, Pratap, Agarwal & Meyarivan (2002), IEEE TEVC 6(2), 182-197 (NSGA-II);
Deb & Jain (2014), IEEE TEVC 18(4), 577-601 (NSGA-III).
"""

from __future__ import annotations

from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.algorithms.moo.nsga3 import NSGA3

from .operators import POP_SIZE, paper_crossover, paper_mutation, reference_directions

__all__ = ["make_nsga2", "make_nsga3"]


def make_nsga2(*, n_obj: int, pop_size: int = POP_SIZE) -> NSGA2:
    """NSGA-II (binary tournament on rank and crowding, rank + crowding survival)."""
    return NSGA2(pop_size=pop_size, crossover=paper_crossover(), mutation=paper_mutation(),
                 eliminate_duplicates=True)


def make_nsga3(*, n_obj: int, pop_size: int = POP_SIZE) -> NSGA3:
    """NSGA-III with the directions of :func:`reference_directions` (91 for 3 objectives)."""
    ref_dirs = reference_directions(n_obj, pop_size)
    return NSGA3(ref_dirs=ref_dirs, pop_size=max(pop_size, len(ref_dirs)),
                 crossover=paper_crossover(), mutation=paper_mutation(), eliminate_duplicates=True)
