"""Plant models of the applications (the paper's heavy truck: :mod:`robustctl.models.truck`)."""

from . import truck

__all__ = ["truck"]
