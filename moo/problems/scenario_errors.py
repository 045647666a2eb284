r"""Errors of a population of gains on a set of scenarios, computed once and read column by column.

Package-internal: :mod:`moo.problems.generic` and :mod:`moo.problems.applied`
share it; :mod:`moo.problems` does not re-export it.

The objectives of the paper's two MOPs (:mod:`moo.problems.generic`,
:mod:`moo.problems.applied`) are the ``k`` columns of one array: the errors
``e`` (B, S, k) of ``B`` gains on ``S`` scenario plants, combined over the
scenarios,

.. math::

    f_{b,j} = \frac{1}{S} \sum_{s=1}^{S} e_{b,s,j}
    \quad (\texttt{aggregate="mean"}) \qquad\text{or}\qquad
    f_{b,j} = \max_{s} e_{b,s,j} \quad (\texttt{aggregate="max"}).

:class:`ScenarioErrors` computes ``f`` (B, k) with one simulation of the
population and keeps it; the ``k`` goals are :class:`ErrorColumn` objects,
each returning its column ``j``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from typing import Literal, cast

import numpy as np

import robustctl as rc
from robustctl.sim.simulator import BACKENDS

from ..tuning.goals import OVER
from ..validation import check_choice

__all__ = ["ScenarioErrors", "ErrorColumn", "same_plants"]


class ScenarioErrors(ABC):
    r"""Errors of gains on scenario plants, combined over the scenarios; the last population's are kept.

    Subclasses define :meth:`per_scenario`, the errors ``e`` (B, S, k) of
    gains ``K`` (B, m, n) on ``S`` plants. Calling the object with ``(K,
    plants)`` returns ``f`` (B, k), ``f_{b,j} = mean_s e_{b,s,j}`` or
    ``max_s e_{b,s,j}``.

    The last ``(K, plants)`` pair, compared by identity (``is``), and its
    ``f`` are memoised. A :class:`moo.tuning.TuningProblem` calls each of its
    ``k`` goals (:class:`ErrorColumn`) with the same ``K`` array and the same
    plants list, so a population costs one simulation shared by the ``k``
    goals instead of ``k``. Identity is what makes the check free (no
    comparison of arrays); it assumes ``K`` is not modified in place between
    two calls.

    Parameters
    ----------
    plants : list of robustctl.Plant
        The own scenarios: ``per_scenario(K)`` is computed on them. The
        problem sets this to its ``scenarios`` list (the one its goals are
        called with).
    aggregate : {"mean", "max"}
        How the scenarios are combined (case-insensitive).
    backend : {"numba", "numpy"}
        Simulator of :mod:`robustctl.sim.simulator`: the compiled kernel or the
        numpy reference.

    Raises
    ------
    TypeError
        ``aggregate`` or ``backend`` not a string.
    ValueError
        ``aggregate`` or ``backend`` not one of the choices (naming the argument).
    """

    def __init__(self, plants: list[rc.Plant], aggregate: str = "mean",
                 backend: Literal["numba", "numpy"] = "numba"):
        self.plants = plants
        self.aggregate = check_choice(aggregate, "aggregate", OVER)
        self.backend = cast(Literal["numba", "numpy"], check_choice(backend, "backend", BACKENDS))
        self._last: tuple = (None, None, None)

    @abstractmethod
    def per_scenario(self, K: np.ndarray, plants: Sequence[rc.Plant] | None = None) -> np.ndarray:
        """Errors ``e`` (B, S, k) of gains ``K`` (B, m, n) on ``plants`` (default: the own scenarios)."""

    def __call__(self, K: np.ndarray, plants: Sequence[rc.Plant]) -> np.ndarray:
        """Combined errors ``f`` (B, k), ``mean_s`` or ``max_s`` of :meth:`per_scenario` (memoised)."""
        last_K, last_plants, last_value = self._last
        if K is last_K and same_plants(plants, last_plants):
            return last_value
        e = self.per_scenario(K) if same_plants(plants, self.plants) else self.per_scenario(K, plants)
        value = e.mean(axis=1) if self.aggregate == "mean" else e.max(axis=1)
        self._last = (K, plants, value)
        return value


def same_plants(a: Sequence[rc.Plant] | None, b: Sequence[rc.Plant] | None) -> bool:
    """Whether ``a`` and ``b`` hold the same plant objects in the same order (a list and its tuple copy do)."""
    return a is not None and b is not None and len(a) == len(b) and all(x is y for x, y in zip(a, b, strict=True))


class ErrorColumn:
    """Goal: column ``j`` of shared :class:`ScenarioErrors`, ``errors(K, plants)[:, j]``.

    Parameters
    ----------
    errors : ScenarioErrors
        The errors shared by the goals of one problem (one simulation per population).
    j : int
        The column (objective) index.

    Attributes
    ----------
    name : str
        The objective's name, :meth:`column_name` of ``j``.
    """

    def __init__(self, errors: ScenarioErrors, j: int):
        self.errors, self.j = errors, j
        self.name = self.column_name(j)

    def column_name(self, j: int) -> str:
        """The name of column ``j`` (subclasses name their objectives)."""
        return f"error {j + 1}"

    def __call__(self, K: np.ndarray, plants: list[rc.Plant]) -> np.ndarray:
        """``errors(K, plants)[:, j]``, shape (B,)."""
        return self.errors(K, plants)[:, self.j]

    def __repr__(self) -> str:
        return f"{type(self).__name__}(j={self.j})"
