"""The stages of the robust LQR (private; the maths is in ``robustctl.synthesis.rlqr``).

``model`` (the checked data of a batch of designs), ``step`` (one recursion
step: the penalty/KKT form and the paper's block system), ``steady`` (the
steady state: doubling, Newton, the plain recursion) and ``kernel`` (their
compiled numba forms).
"""
