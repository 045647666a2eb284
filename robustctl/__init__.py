"""robustctl: robust control design (LQR, RLQR, LMI H-infinity and H2), estimation and robust analysis.

The package is laid out by role (``docs/architecture.rst``); every public
name is importable from here:

* :mod:`robustctl.systems` - plants, uncertainty, pole regions, plant sets, controllers;
* :mod:`robustctl.estimation` - Kalman and robust filters;
* :mod:`robustctl.synthesis` - the design methods and :func:`design`;
* :mod:`robustctl.analysis` - robust stability, guaranteed cost, worst case, reports;
* :mod:`robustctl.sim` - the batched closed-loop simulator;
* :mod:`robustctl.models` - the heavy truck, paths and path following (imported on their own).

>>> import robustctl as rc
>>> from robustctl.models.truck import truck_plant
>>> plant = truck_plant(0.0)            # the paper's truck, zero-order hold at dt = 0.1 s
>>> plant
Plant(n=4, m=1, dt=0.1)
>>> EF, EG = [[0.0, 0.0, 0.0, 0.05]], [[0.05]]
>>> ctrl = rc.design("rlqr", plant, EF, EG, mu=1e8)
>>> ctrl.K.round(3), ctrl.is_stabilizing()
(array([[-0.001, -0.007, -0.001, -1.015]]), True)
>>> rc.robust_stability(ctrl, rc.NormBounded(plant.G, EF, EG)).certified
True

Sign convention everywhere: ``u = K x``.
"""

from . import _moved, analysis, errors, estimation, synthesis, systems
from .analysis import *  # noqa: F403
from .errors import *  # noqa: F403
from .estimation import *  # noqa: F403
from .synthesis import *  # noqa: F403
from .systems import *  # noqa: F403

# The public names, by role (each subpackage's __all__; python-control's control/__init__.py does the same).
# robustctl.sim and robustctl.models keep their names in their own namespaces.
__all__ = systems.__all__ + estimation.__all__ + synthesis.__all__ + analysis.__all__ + errors.__all__
__version__ = "0.1.0"

_moved.install()
del _moved
