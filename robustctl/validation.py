"""Argument checks of :mod:`robustctl`, public for packages built on it (e.g. ``moo.problems``).

Every helper raises ``ValueError``/``TypeError`` whose message names the
argument (and, for shapes, the expected and the actual shape). Numbers are
real numbers: booleans, strings, complex values and ``None`` are refused, and
so are nested lists of unequal lengths. See each function's docstring.
"""

from ._validation import (
    as_batch,
    as_float_array,
    as_matrix,
    as_rng,
    check_bool,
    check_choice,
    check_int,
    check_positive_scalar,
    check_positive_vector,
    check_real,
    check_spd,
    check_square,
)
from .systems.plant import check_plant, check_plants, check_vertices

__all__ = ["as_float_array", "as_matrix", "as_batch", "check_square", "check_spd", "check_positive_scalar",
           "check_real", "check_positive_vector", "check_int", "check_bool", "check_choice", "as_rng",
           "check_plant", "check_plants", "check_vertices"]
