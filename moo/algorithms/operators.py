"""Variation operators (the paper's and each algorithm's original ones) and reference directions.

The paper ran on PlatEMO with population 92, SBX ``pc = 1.0``, polynomial
mutation ``pm = 0.5`` and ``eta_m = 20``, other parameters at their defaults.
Readings (see PAPER_NOTES.md):

* PlatEMO's ``proM`` is the *expected number of mutated variables*, so
  ``pm = 0.5`` is a per-variable probability ``0.5 / n_var``
  (:class:`PaperPM`); every offspring goes through mutation.
* SBX distribution index 20 (PlatEMO's default ``disC``), each variable
  crossed with probability 0.5 and the two children's values swapped with
  probability 0.5, as in PlatEMO's ``OperatorGA`` (pymoo's ``prob_bin``).
  PlatEMO's SBX is the unbounded form with the children clipped to the box
  (:class:`ClippedSBX`), pymoo's the bound-aware form of Deb's NSGA-II code;
  the default stays pymoo's (``crossover_form="bounded"``;
  ``OperatorSettings(..., crossover_form="clipped")`` selects PlatEMO's). The
  two differ at the bounds of the box: only the clipped form puts variables
  exactly on a bound, and so points exactly on the faces of a DTLZ front.
  What that changes on DTLZ2, DTLZ4, at 8 objectives and on the paper's two
  MOPs is measured in the documentation's Validation pages
  (:ref:`validation-operators`, :ref:`validation-dtlz4`).
* Reference directions: Das & Dennis with 12 divisions for 3 objectives
  (91 directions). For 4 objectives the paper is silent and 92 directions are
  impossible with one layer; we take the largest one-layer Das-Dennis set with
  at most 92 points, 6 divisions = 84 directions (what PlatEMO's
  ``UniformPoint(92, 4)`` returns); the population stays 92. For M objectives
  in general: the largest one-layer set of size <= pop_size, which gives
  ``pop_size - 1`` directions for 2 objectives.

Every factory of :mod:`moo.algorithms` takes ``operators="paper"`` (the
default: :data:`PAPER_OPERATORS` above, shared by all ten algorithms as in the
reproduced study) or ``operators="original"``: the SBX / polynomial mutation
settings of the algorithm's own paper, an :class:`OperatorSettings` constant
``ORIGINAL_OPERATORS`` in its module. An :class:`OperatorSettings` instance
may also be passed.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import comb

import numpy as np
from pymoo.core.crossover import Crossover
from pymoo.core.variable import Real
from pymoo.operators.crossover.sbx import SBX
from pymoo.operators.mutation.pm import PM
from pymoo.util.ref_dirs import get_reference_directions

__all__ = ["ClippedSBX", "OPERATOR_CHOICES", "OperatorSettings", "PAPER_OPERATORS", "POP_SIZE", "PaperPM",
           "paper_crossover", "paper_mutation", "reference_directions", "variation_operators"]

POP_SIZE = 92


@dataclass(frozen=True)
class OperatorSettings:
    """SBX and polynomial-mutation parameters, with where they come from.

    ``mutation_rate`` is the expected number of mutated variables of an
    offspring (PlatEMO's ``proM``): each variable mutates with probability
    ``mutation_rate / n_var``, so ``1.0`` is the usual ``pm = 1/n``.
    ``crossover_form``: ``"bounded"`` (pymoo's SBX) or ``"clipped"``
    (:class:`ClippedSBX`).
    """

    crossover_prob: float
    crossover_eta: float
    mutation_rate: float
    mutation_eta: float
    source: str
    crossover_form: str = "bounded"


#: The reproduced paper's settings (Morais et al. 2022, Sec. 4.1.2, read as above).
PAPER_OPERATORS = OperatorSettings(crossover_prob=1.0, crossover_eta=20.0, mutation_rate=0.5, mutation_eta=20.0,
                                   source="Morais et al. (2022), Sec. 4.1.2 (PlatEMO's pm = 0.5 expected mutations)")

#: Accepted names of the ``operators`` argument of the factories.
OPERATOR_CHOICES = ("paper", "original")


class ClippedSBX(Crossover):
    """SBX with the unbounded spread of Deb & Agrawal (1995), children clipped to the bounds.

    For each variable, with ``u ~ U(0, 1)``,
    ``beta = (2u)^(1/(eta+1))`` if ``u <= 1/2`` else ``(2 - 2u)^(-1/(eta+1))``,
    the children are ``(p1 + p2)/2 +- beta (p1 - p2)/2`` (the sign drawn at
    random, i.e. the children swapped with probability 1/2), each variable is
    crossed with probability 1/2 (otherwise copied), and values outside the
    box are clipped to its bounds. This is PlatEMO's ``OperatorGA``, on which
    the reproduced paper ran; pymoo's :class:`~pymoo.operators.crossover.sbx.SBX`
    is the bound-aware form of Deb's NSGA-II code instead, whose spread
    shrinks near a bound and never reaches it. A mating is crossed with
    probability ``prob`` (pymoo's ``Crossover``), else the parents are copied.
    """

    def __init__(self, prob: float = 1.0, eta: float = 20.0):
        super().__init__(2, 2, prob=prob)
        self.eta = Real(eta, bounds=(3.0, 30.0), strict=(1.0, None))

    def _do(self, problem, X, *args, random_state=None, **kwargs):
        p1, p2 = X[0].astype(float), X[1].astype(float)
        eta = float(self.eta.value)
        u = random_state.random(p1.shape)
        beta = np.where(u <= 0.5, (2 * u) ** (1 / (eta + 1)), (2 - 2 * np.minimum(u, 1 - 1e-16)) ** (-1 / (eta + 1)))
        beta *= np.where(random_state.random(p1.shape) < 0.5, -1.0, 1.0)
        copied = random_state.random(p1.shape) < 0.5
        mid, half = (p1 + p2) / 2, (p1 - p2) / 2
        c1 = np.where(copied, p1, mid + beta * half)           # copied exactly, not through the formula
        c2 = np.where(copied, p2, mid - beta * half)
        return np.clip(np.stack([c1, c2]), problem.xl, problem.xu)


class PaperPM(PM):
    """Polynomial mutation with a per-variable probability ``expected / n_var``."""

    def __init__(self, expected_mutations: float = 0.5, eta: float = 20.0):
        super().__init__(prob=1.0, eta=eta)
        if not expected_mutations > 0:
            raise ValueError(f"expected_mutations must be > 0, got {expected_mutations}")
        self.expected_mutations = float(expected_mutations)

    def get_prob_var(self, problem, **kwargs):
        """The per-variable mutation probability ``min(1, expected_mutations / n_var)``, one per individual."""
        return np.full(kwargs.get("size", 1), min(1.0, self.expected_mutations / problem.n_var))


def paper_crossover(eta: float = 20.0, prob: float = 1.0, form: str = "bounded") -> Crossover:
    """SBX with ``pc = prob``, ``eta_c = eta``: pymoo's bound-aware form or :class:`ClippedSBX` (``form``)."""
    if form == "clipped":
        return ClippedSBX(prob=prob, eta=eta)
    if form != "bounded":
        raise ValueError(f"form must be 'bounded' or 'clipped', got {form!r}")
    return SBX(prob=prob, eta=eta, prob_var=0.5, prob_bin=0.5)


def paper_mutation(expected_mutations: float = 0.5, eta: float = 20.0) -> PaperPM:
    """Polynomial mutation as the paper configured it (pm = 0.5, eta_m = 20)."""
    return PaperPM(expected_mutations=expected_mutations, eta=eta)


def variation_operators(settings: OperatorSettings) -> dict:
    """``{"crossover": SBX, "mutation": PaperPM}`` built from ``settings``."""
    return {"crossover": paper_crossover(eta=settings.crossover_eta, prob=settings.crossover_prob,
                                         form=settings.crossover_form),
            "mutation": paper_mutation(expected_mutations=settings.mutation_rate, eta=settings.mutation_eta)}


def reference_directions(n_obj: int, pop_size: int = POP_SIZE) -> np.ndarray:
    """Das-Dennis directions: 12 divisions for 3 objectives, else the largest one-layer set <= pop_size."""
    if n_obj < 2:
        raise ValueError(f"n_obj must be >= 2, got {n_obj}")
    if n_obj == 3 and pop_size >= 91:
        divisions = 12
    else:
        divisions = 1
        while comb(divisions + 1 + n_obj - 1, n_obj - 1) <= pop_size:
            divisions += 1
    return get_reference_directions("das-dennis", n_obj, n_partitions=divisions)
