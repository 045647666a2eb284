"""The paper's published MSE table (Morais et al. 2022, Table "MSE values", Section 4.5.2) as data.

``PAPER_MSE[objective][controller]`` is the tuple of MSE values at overloads
0, 100, 200 and 300 %. Objectives: f1 lateral displacement (rho), f2 yaw-rate
error, f3 lateral-velocity error, f4 orientation error (theta). Controllers:
RLQR_MOP (RLQR with the NSGA-II/MO-LSP uncertainty z*), RLQR_A (RLQR with the
algebraic uncertainty of Barbosa et al. 2019), Hinf (standard H-infinity), LQR.
The H-infinity f1 value at 0 % is printed as "0.83135E-3".
"""

OVERLOADS = (0, 100, 200, 300)
OBJECTIVES = ("f1", "f2", "f3", "f4")
CONTROLLERS = ("RLQR_MOP", "RLQR_A", "Hinf", "LQR")

PAPER_MSE = {
    "f1": {
        "RLQR_MOP": (2.72161e-3, 9.52776e-3, 2.02697e-2, 3.46455e-2),
        "RLQR_A": (6.72252e-3, 1.29370e-2, 2.06950e-2, 3.00461e-2),
        "Hinf": (0.83135e-3, 1.08787e-3, 1.09022e-2, 4.19582e-2),
        "LQR": (3.92518e-3, 6.95036e-3, 1.10944e-2, 1.61736e-2),
    },
    "f2": {
        "RLQR_MOP": (1.44405e-3, 1.67467e-3, 1.85903e-3, 1.99537e-3),
        "RLQR_A": (1.84585e-3, 3.01635e-3, 4.09464e-3, 4.98721e-3),
        "Hinf": (1.85683e-2, 1.03793e-2, 4.64690e-3, 5.18353e-3),
        "LQR": (5.54885e-3, 1.04151e-2, 1.56832e-2, 2.02004e-2),
    },
    "f3": {
        "RLQR_MOP": (1.17762e-2, 3.07187e-2, 5.65872e-2, 8.72447e-2),
        "RLQR_A": (1.67254e-2, 6.45166e-2, 1.34078e-1, 2.15567e-1),
        "Hinf": (1.09009e-1, 7.74970e-2, 9.98572e-2, 1.95922e-1),
        "LQR": (4.54013e-2, 1.71043e-1, 3.76471e-1, 6.23971e-1),
    },
    "f4": {
        "RLQR_MOP": (7.35717e-5, 1.00885e-4, 1.44767e-4, 2.02602e-4),
        "RLQR_A": (2.42387e-4, 4.22745e-4, 6.48997e-4, 8.95945e-4),
        "Hinf": (8.74106e-5, 1.94354e-4, 3.50360e-4, 1.29590e-3),
        "LQR": (4.59179e-4, 1.02236e-3, 1.82643e-3, 2.72205e-3),
    },
}


def paper_winner(objective: str, overload: int) -> str:
    """The controller with the smallest published MSE in one cell (the paper's bold entry)."""
    i = OVERLOADS.index(overload)
    return min(CONTROLLERS, key=lambda c: PAPER_MSE[objective][c][i])
