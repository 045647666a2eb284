r"""Scenario sets: the plants of a model over a range of its uncertain parameters.

A tuning problem, a Monte Carlo selection and :meth:`NormBounded.from_plants
<robustctl.NormBounded.from_plants>` all take a list of plants (the
*scenarios*). :func:`sample_plants` builds one from a user function
``model(**params) -> Plant`` and a box of parameter ranges, on a full grid
(every combination of ``n`` evenly spaced values per parameter, ends
included: the corners of the box are scenarios) or on ``n`` Latin-hypercube
samples (McKay, Beckman & Conover 1979: each parameter's range cut into
``n`` equal strata, one sample in each, the strata paired at random).

References
----------
M. D. McKay, R. J. Beckman, W. J. Conover, "A comparison of three methods for
selecting values of input variables in the analysis of output from a computer
code", Technometrics 21(2), 239-245, 1979.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import overload

import numpy as np

from .._validation import as_float_array, as_rng, check_choice, check_int
from .plant import Plant

__all__ = ["PlantSamples", "sample_plants", "SAMPLING_METHODS"]

#: Names :func:`robustctl.sample_plants` accepts as ``method``.
SAMPLING_METHODS = ("grid", "lhs")


@dataclass(frozen=True, eq=False, repr=False)
class PlantSamples(Sequence[Plant]):
    """The plants of :func:`sample_plants` and the parameters behind each (a sequence of plants).

    A :class:`~collections.abc.Sequence` of the plants (iterating, indexing and
    ``len`` act on them), so it is a scenario list as it is.

    Parameters
    ----------
    plants : tuple of Plant
        The plants, one per sample.
    params : (N, d) ndarray
        Their parameter values, one row per plant.
    names : tuple of str
        The parameter names, in the order of ``params``' columns.

    Attributes
    ----------
    plants : tuple of Plant
        ``model(**dict(zip(names, params[i])))`` for each sample ``i``.
    params : (N, d) ndarray
        The parameter values, one row per plant, columns in the order of ``names``.
    names : tuple of str
        The parameters (the keys of ``ranges``).

    See Also
    --------
    sample_plants : builds it.

    Examples
    --------
    >>> import robustctl as rc
    >>> def plant_of(a):
    ...     return rc.Plant([[a]], [[1.0]], dt=0.1)
    >>> samples = rc.sample_plants(plant_of, {"a": (0.5, 1.5)}, n=3)
    >>> len(samples), samples.as_dicts()[2]
    (3, {'a': 1.5})
    >>> [float(p.F[0, 0]) for p in samples] == samples.params[:, 0].tolist()
    True
    """

    plants: tuple[Plant, ...]
    params: np.ndarray
    names: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.plants)

    @overload
    def __getitem__(self, i: int) -> Plant: ...
    @overload
    def __getitem__(self, i: slice) -> tuple[Plant, ...]: ...

    def __getitem__(self, i: int | slice) -> Plant | tuple[Plant, ...]:
        return self.plants[i]

    def __iter__(self) -> Iterator[Plant]:
        return iter(self.plants)

    def as_dicts(self) -> list[dict[str, float]]:
        """The parameters of each plant as ``{name: value}``.

        Returns
        -------
        list of dict
            One ``{name: value}`` per plant, in the order of the plants.
        """
        return [dict(zip(self.names, map(float, row), strict=True)) for row in self.params]

    def __repr__(self) -> str:
        p = self.plants[0]
        return f"PlantSamples(N={len(self)}, params={list(self.names)}, n={p.n}, m={p.m}, dt={p.dt})"


def _ranges(ranges) -> tuple[tuple[str, ...], np.ndarray]:
    """``(names, bounds (d, 2))`` from ``{name: (low, high)}``."""
    if not isinstance(ranges, Mapping) or len(ranges) == 0:
        raise TypeError(f"ranges must be a non-empty mapping {{name: (low, high)}}, got {type(ranges).__name__}")
    names, bounds = [], []
    for name, lohi in ranges.items():
        if not isinstance(name, str) or not name.isidentifier():
            raise ValueError(f"ranges keys must be parameter names (identifiers), got {name!r}")
        b = as_float_array(lohi, f"ranges[{name!r}]")
        if b.shape != (2,) or not np.all(np.isfinite(b)):
            raise ValueError(f"ranges[{name!r}] must be two finite numbers (low, high), got {lohi!r}")
        if b[0] > b[1]:
            raise ValueError(f"ranges[{name!r}] must have low <= high, got ({b[0]:g}, {b[1]:g})")
        names.append(name)
        bounds.append(b)
    return tuple(names), np.array(bounds)


def _unit_samples(method: str, d: int, n: int, rng: np.random.Generator) -> np.ndarray:
    """(N, d) points of the unit box: the grid (N = n^d, ends included) or a Latin hypercube (N = n)."""
    if method == "grid":
        axis = np.linspace(0.0, 1.0, n) if n > 1 else np.array([0.5])
        return np.array(list(itertools.product(axis, repeat=d)))
    strata = np.stack([rng.permutation(n) for _ in range(d)], axis=1)          # (n, d)
    return (strata + rng.random((n, d))) / n


def sample_plants(model: Callable[..., Plant], ranges: Mapping[str, tuple[float, float]], *, n: int = 5,
                  method: str = "grid", seed=None) -> PlantSamples:
    r"""The plants ``model(**params)`` over a box of parameter ranges.

    Parameters
    ----------
    model : callable
        ``model(**params)`` returns a :class:`~robustctl.Plant` (e.g. a
        continuous model discretised with :meth:`Plant.from_continuous
        <robustctl.Plant.from_continuous>`); every plant must have the same
        ``n``, ``m`` and ``dt``.
    ranges : mapping of str to (low, high)
        The range of each parameter (keyword of ``model``); ``low == high``
        fixes it.
    n : int
        ``"grid"``: values per parameter (evenly spaced, both ends included;
        ``n = 1`` is the middle), ``n ** d`` plants for ``d`` parameters.
        ``"lhs"``: the number of plants.
    method : {"grid", "lhs"}
        Full grid, or Latin-hypercube samples (module docstring).
    seed : None, int, SeedSequence or Generator
        Randomness of ``"lhs"`` (the grid does not use it).

    Returns
    -------
    PlantSamples
        The plants (a sequence: ``list(samples)`` is the scenario list) and their parameters.

    Raises
    ------
    TypeError
        ``model`` not callable or not returning a :class:`~robustctl.Plant`,
        ``ranges`` not a non-empty mapping, ``n`` not an integer.
    ValueError
        A range that is not two finite numbers ``low <= high``, a key that is
        not an identifier, plants of different sizes or sampling times (the
        message names the call), an unknown ``method``.

    See Also
    --------
    robustctl.NormBounded.from_plants : a norm-bounded model covering the plants.

    Notes
    -----
    With ``d`` parameters, ``"grid"`` gives the ``n ** d`` points of the
    grid with ``n`` evenly spaced values per parameter, ends included.
    ``"lhs"`` cuts each range into ``n`` equal strata and draws, for each
    parameter independently, a random permutation ``pi`` of the strata
    and uniform offsets ``U_ij``; sample ``i`` is [1]_

    .. math::

        \theta_{ij} = a_j + (b_j - a_j)\, \frac{\pi_j(i) + U_{ij}}{n},
        \qquad i = 1..n,

    one sample in each stratum of each parameter.

    References
    ----------
    .. [1] M. D. McKay, R. J. Beckman, W. J. Conover, "A comparison of three
       methods for selecting values of input variables in the analysis of
       output from a computer code", Technometrics 21(2), 239-245, 1979.

    Examples
    --------
    A mass on a spring, its mass between 1 and 2, on a grid of three:

    >>> import robustctl as rc
    >>> def spring_mass(mass):
    ...     return rc.Plant.from_continuous([[0.0, 1.0], [-1.0 / mass, 0.0]], [[0.0], [1.0 / mass]], dt=0.1)
    >>> samples = rc.sample_plants(spring_mass, {"mass": (1.0, 2.0)}, n=3)
    >>> samples
    PlantSamples(N=3, params=['mass'], n=2, m=1, dt=0.1)
    >>> samples.params.ravel().tolist()
    [1.0, 1.5, 2.0]

    The heaviest plant is the zero-order hold of the model at ``mass = 2``
    (scipy's ``cont2discrete``):

    >>> import numpy as np, scipy.signal
    >>> A, B = np.array([[0.0, 1.0], [-0.5, 0.0]]), np.array([[0.0], [0.5]])
    >>> F, G, *_ = scipy.signal.cont2discrete((A, B, np.eye(2), np.zeros((2, 1))), 0.1)
    >>> bool(np.allclose(samples[2].F, F) and np.allclose(samples[2].G, G))
    True

    Latin-hypercube samples put one sample in each quarter of the range:

    >>> lhs = rc.sample_plants(spring_mass, {"mass": (1.0, 2.0)}, n=4, method="lhs")
    >>> np.sort(np.floor((lhs.params[:, 0] - 1.0) * 4)).tolist()
    [0.0, 1.0, 2.0, 3.0]
    """
    if not callable(model):
        raise TypeError(f"model must be a callable params -> robustctl.Plant, got {type(model).__name__}")
    names, bounds = _ranges(ranges)
    n = check_int(n, "n")
    method = check_choice(method, "method", SAMPLING_METHODS)
    rng = as_rng(seed)
    params = bounds[:, 0] + _unit_samples(method, len(names), n, rng) * (bounds[:, 1] - bounds[:, 0])
    plants: list[Plant] = []
    for row in params:
        kwargs = dict(zip(names, map(float, row), strict=True))
        plant = model(**kwargs)
        call = f"model({', '.join(f'{k}={v:g}' for k, v in kwargs.items())})"
        if not isinstance(plant, Plant):
            raise TypeError(f"model must return a robustctl.Plant, {call} returned {type(plant).__name__}")
        first = plants[0] if plants else plant
        if (plant.n, plant.m, plant.dt) != (first.n, first.m, first.dt):
            raise ValueError(f"model must return plants of one size and sampling time: {call} has "
                             f"n={plant.n}, m={plant.m}, dt={plant.dt}, the first had "
                             f"n={first.n}, m={first.m}, dt={first.dt}")
        plants.append(plant)
    return PlantSamples(tuple(plants), params, names)
