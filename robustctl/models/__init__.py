"""Plant models of the applications (the heavy truck: :mod:`robustctl.models.truck`).

The data and set-ups of the paper that the truck comes from (Morais et al.
2022, and its authors' code) are in :mod:`robustctl.models.morais2022`,
imported on its own (``from robustctl.models import morais2022``): no general
module of the library uses it.
"""

from . import truck

__all__ = ["truck"]
