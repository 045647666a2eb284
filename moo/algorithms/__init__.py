"""Registry of the MOEAs by name.

``make_algorithm(name, n_obj=M)`` builds a configured pymoo algorithm with the
paper's settings (population 92, SBX pc = 1 / eta 20, polynomial mutation
pm = 0.5 / eta 20; see :mod:`moo.algorithms.operators`). Each entry points to
a factory ``factory(*, n_obj, pop_size=92, **options) -> pymoo Algorithm``;
modules are imported on first use.
"""

from __future__ import annotations

from importlib import import_module

__all__ = ["ALGORITHMS", "make_algorithm"]

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


def make_algorithm(name: str, *, n_obj: int, pop_size: int = 92, **options):
    """A pymoo algorithm by registry name, configured with the paper's defaults.

    ``options`` are the factory's keyword arguments (each algorithm's own
    parameters, documented in its module).
    """
    key = name.lower() if isinstance(name, str) else name
    if key not in ALGORITHMS:
        raise ValueError(f"unknown algorithm {name!r}; valid: {', '.join(ALGORITHMS)}")
    if not isinstance(n_obj, int) or n_obj < 2:
        raise ValueError(f"n_obj must be an integer >= 2, got {n_obj!r}")
    if not isinstance(pop_size, int) or pop_size < 4:
        raise ValueError(f"pop_size must be an integer >= 4, got {pop_size!r}")
    module, func = ALGORITHMS[key].split(":")
    try:
        factory = getattr(import_module(module), func)
    except (ImportError, AttributeError) as exc:  # an algorithm not built yet
        raise NotImplementedError(f"algorithm {name!r} is registered but not available: {exc}") from exc
    return factory(n_obj=n_obj, pop_size=pop_size, **options)
