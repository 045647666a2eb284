"""The paper's published MSE table (Morais et al. 2022, Table "MSE values", Section 4.5.2), for the scripts.

The data are :data:`robustctl.models.morais2022.PRINTED_MSE`:
``PAPER_MSE[objective][controller]`` is the tuple of MSE values at overloads
0, 100, 200 and 300 %. Objectives: f1 lateral displacement (rho), f2 yaw-rate
error, f3 lateral-velocity error, f4 orientation error (theta). Controllers:
RLQR_MOP (RLQR with the NSGA-II/MO-LSP uncertainty z*), RLQR_A (RLQR with the
algebraic uncertainty of Barbosa et al. 2019), Hinf (standard H-infinity), LQR.
"""

from robustctl.models.morais2022 import MSE_CONTROLLERS as CONTROLLERS
from robustctl.models.morais2022 import MSE_OBJECTIVES as OBJECTIVES
from robustctl.models.morais2022 import MSE_OVERLOADS as OVERLOADS
from robustctl.models.morais2022 import PRINTED_MSE as PAPER_MSE

__all__ = ["OVERLOADS", "OBJECTIVES", "CONTROLLERS", "PAPER_MSE", "paper_winner"]


def paper_winner(objective: str, overload: int) -> str:
    """The controller with the smallest published MSE in one cell (the paper's bold entry)."""
    i = OVERLOADS.index(overload)
    return min(CONTROLLERS, key=lambda c: PAPER_MSE[objective][c][i])
