"""Registry of the MOEAs by name, and the one constructor shape they share.

``make_algorithm(name, n_obj=M)`` builds a configured pymoo algorithm with the
paper's settings; modules are imported on first use.

Constructor shape (every entry of :data:`ALGORITHMS`; checked for each by
``tests/test_moea_common.py``)::

    factory(*, n_obj, pop_size=POP_SIZE, operators="paper", **options) -> pymoo GeneticAlgorithm

* every argument is keyword-only and has the paper's default, except
  ``n_obj`` (no default);
* ``n_obj`` (>= 2) and ``pop_size`` (>= 4, default
  :data:`~moo.algorithms.operators.POP_SIZE` = 92): ``TypeError`` if not an
  integer (``bool`` refused), ``ValueError`` if too small; an unknown option
  is a ``TypeError`` (Python's own);
* ``operators``: ``"paper"`` (the reproduced study's SBX pc = 1 / eta 20 and
  polynomial mutation with 0.5 expected mutated variables / eta 20, the same
  for all ten), ``"original"`` (the algorithm's own paper, the constant
  ``ORIGINAL_OPERATORS`` of its module, e.g. theta-DEA's SBX eta 30 and
  pm = 1/n) or an :class:`~moo.algorithms.operators.OperatorSettings`;
  another string is a ``ValueError``, another type a ``TypeError``;
* the reference-direction algorithms (nsga3, theta-dea, mombi2, efr-rr,
  spea-r) also take ``ref_dirs`` (default
  :func:`~moo.algorithms.operators.reference_directions`: 91 directions for
  3 objectives, 84 for 4), ``ValueError`` when its columns are not ``n_obj``;
* options of the algorithm itself (theta-DEA's ``theta``, SPEA/R's
  ``k_mating``, ...) are documented in its factory;
* the returned algorithm passes its initial population through its survival
  before the first mating (``advance_after_initial_infill=True``), so the
  first mating sees ranked individuals, and its survival resets its state
  when a run is set up (NSGA-II and NSGA-III are pymoo's; the other eight
  are subclasses of :class:`moo.algorithms.base.MOEA`, which wires a survival
  and a mating selection into pymoo's genetic algorithm this way).
"""

from __future__ import annotations

from importlib import import_module

from .base import MIN_POP_SIZE
from .operators import POP_SIZE

__all__ = ["ALGORITHMS", "MORE_ALGORITHMS", "ALGORITHM_NOTES", "MIN_POP_SIZE", "POP_SIZE", "make_algorithm"]

ALGORITHMS: dict[str, str] = {
    "nsga2": "moo.algorithms.nsga:make_nsga2",
    "nsga3": "moo.algorithms.nsga:make_nsga3",
    "theta-dea": "moo.algorithms.theta_dea:make_theta_dea",
    "mombi2": "moo.algorithms.mombi2:make_mombi2",
    "moea-igd-ns": "moo.algorithms.moea_igd_ns:make_moea_igd_ns",
    "efr-rr": "moo.algorithms.efr_rr:make_efr_rr",
    "maoea-ddfc": "moo.algorithms.maoea_ddfc:make_maoea_ddfc",
    "spea-r": "moo.algorithms.spea_r:make_spea_r",
    "spea2-sde": "moo.algorithms.spea2_sde:make_spea2_sde",
    "bige": "moo.algorithms.bige:make_bige",
}

#: Algorithms beyond the ten of the study (``"all"`` of an experiment does not include them):
#: the single-objective genetic algorithm and pymoo's own NSGA-II (pymoo's operators, not the paper's).
MORE_ALGORITHMS: dict[str, str] = {
    "ga": "moo.algorithms.ga:make_ga",
    "pymoo-nsga2": "moo.algorithms.nsga:make_pymoo_nsga2",
}

_PAPER = "the paper's operators (SBX pc 1, eta 20; polynomial mutation, 0.5 expected mutated variables, eta 20)"
#: What each registry name means: one line each (the command line's help and :func:`moo.tuning.tune` list them).
ALGORITHM_NOTES: dict[str, str] = {
    "nsga2": f"NSGA-II (Deb et al. 2002) with {_PAPER}, not pymoo's defaults",
    "pymoo-nsga2": "pymoo's own NSGA-II, pymoo's default operators (SBX pc 0.9, eta 15; mutation 1/n, eta 20)",
    "nsga3": f"NSGA-III (Deb & Jain 2014) with {_PAPER}",
    "theta-dea": f"theta-DEA (Yuan et al. 2016) with {_PAPER}",
    "mombi2": f"MOMBI-II (Hernandez Gomez & Coello 2015) with {_PAPER}",
    "moea-igd-ns": f"MOEA/IGD-NS (Tian et al. 2016) with {_PAPER}",
    "efr-rr": f"EFR-RR (Yuan et al. 2016) with {_PAPER}",
    "maoea-ddfc": f"MaOEA-DDFC (Cheng et al. 2015) with {_PAPER}",
    "spea-r": f"SPEA/R (Jiang & Yang 2017) with {_PAPER}",
    "spea2-sde": f"SPEA2+SDE (Li et al. 2014) with {_PAPER}",
    "bige": f"BiGE (Li et al. 2015) with {_PAPER}",
    "ga": f"a single-objective genetic algorithm (pymoo's GA) with {_PAPER}: for problems with one objective",
}


def _single_objective_hint(key: str, n_obj) -> str | None:
    """The message for a MOEA of :data:`ALGORITHMS` asked for one objective (else None)."""
    if key in ALGORITHMS and isinstance(n_obj, int) and not isinstance(n_obj, bool) and n_obj == 1:
        return (f"n_obj must be >= 2 for the MOEA {key!r}, got 1: a problem with one objective runs with "
                "algorithm 'ga' (a single-objective genetic algorithm with the paper's operators)")
    return None


def make_algorithm(name: str, *, n_obj: int, pop_size: int = POP_SIZE, **options):
    """A pymoo algorithm by registry name, configured with the paper's defaults.

    Parameters
    ----------
    name : str
        A name of :data:`ALGORITHMS` or :data:`MORE_ALGORITHMS`
        (case-insensitive; :data:`ALGORITHM_NOTES` says what each means).
    n_obj : int
        Number of objectives (>= 2; 1 for ``"ga"``).
    pop_size : int
        Population size, at least :data:`MIN_POP_SIZE` (default
        :data:`POP_SIZE`, the paper's 92; the reference-direction
        algorithms may enlarge it to their number of directions).
    **options
        The factory's own keyword arguments: ``operators`` (``"paper"``,
        ``"original"`` or an :class:`~moo.algorithms.operators.OperatorSettings`),
        ``ref_dirs`` and each algorithm's parameters, documented in its module.

    Returns
    -------
    pymoo.algorithms.base.genetic.GeneticAlgorithm
        Not yet set up (``minimize`` or :func:`moo.run` sets it up).

    Raises
    ------
    ValueError, TypeError
        An unknown name (the message lists the valid ones), or a bad argument
        of the factory (the shape of the module docstring).
    NotImplementedError
        A registered algorithm whose module is not available.

    See Also
    --------
    moo.run : one run of a registered algorithm.
    moo.algorithms.base.MOEA : the base of the package's own algorithms.

    Examples
    --------
    theta-DEA for 3 objectives has the project's 91 directions and
    population 92:

    >>> from moo.algorithms import make_algorithm
    >>> alg = make_algorithm("theta-dea", n_obj=3)
    >>> type(alg).__name__, alg.pop_size, alg.ref_dirs.shape
    ('ThetaDEA', 92, (91, 3))
    """
    key = name.lower() if isinstance(name, str) else name
    registry = {**ALGORITHMS, **MORE_ALGORITHMS}
    if key not in registry:
        raise ValueError(f"unknown algorithm {name!r}; valid: {', '.join(registry)}")
    hint = _single_objective_hint(key, n_obj)
    if hint is not None:
        raise ValueError(hint)
    module, func = registry[key].split(":")
    try:
        factory = getattr(import_module(module), func)
    except (ImportError, AttributeError) as exc:  # an algorithm not built yet
        raise NotImplementedError(f"algorithm {name!r} is registered but not available: {exc}") from exc
    return factory(n_obj=n_obj, pop_size=pop_size, **options)
