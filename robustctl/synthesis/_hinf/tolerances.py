"""Every tolerance of the LMI state-feedback syntheses, in one place.

Each constant says what it is relative to. The LMI data are normalised
(:mod:`.coordinates`: ``||Bw~|| = 1``, ``||[Cz~ Dzu~ Dzw~]|| = 1``, level 1 or unit
energy), so the absolute ones are on a known scale.
"""

from __future__ import annotations

# The validation's stabilisability and pole-region reachability (PBH test)
# and the closed-loop stability check use the tolerances of
# robustctl.systems.stability (UNSTABLE_TOL, PBH_TOL, STABILITY_MARGIN).

# ---------------------------------------------------------------- coordinates
#: Range of the channel scales ``1 / ||Bw||`` (``sqrt(w_energy)``) and
#: ``||[Cz Dzu Dzw]||``: the level and the Lyapunov matrix scale with their
#: squares, which must stay finite and nonzero in float64 (about 1e+-308).
CHANNEL_RANGE = (1e-150, 1e150)
#: Singular values of ``[Cz Dzu Dzw]`` below ``Z_RANK * sigma_max`` are
#: dropped when ``z`` is replaced by a factor with the same Gram matrix.
Z_RANK = 1e-13
#: Both weights of the preconditioning LQR Riccati equation get
#: ``LQR_REG * max(1, ||W||)`` added on the diagonal (so that it is solvable).
LQR_REG = 1e-9
#: Regularisation, relative to ``lambda_max``, of a Lyapunov matrix before it
#: defines new coordinates (the recentred centring).
RECENTRE_REG = 1e-3
#: The same for the LQR coordinates of one plant (:func:`.coordinates.lqr_coordinates`):
#: the inverse LQR solution may be conditioned up to ``1 / LQR_SHIFT``. With a
#: rank-deficient weight the LQR solution has eigenvalues near ``LQR_REG``;
#: keeping more of its shape than ``RECENTRE_REG`` would gives the level
#: minimisation of larger plants fewer interior-point iterations and a level
#: closer to the Riccati bisection's (measured in the documentation, Validation: Benchmarks).
LQR_SHIFT = 1e-6
#: The same for polishing an inaccurate level minimisation (a pure similarity).
POLISH_REG = 1e-6

# ---------------------------------------------------------------- solves
#: Solver tolerance of the level minimisation in the LQR coordinates of one
#: plant (the level then agrees with the Riccati bisection to 1e-8-1e-7
#: relative; the first attempt skips iterative refinement) ...
LEVEL_TOL = 1e-8
#: ... and otherwise (several vertices, e.g. the truck polytope with an input
#: bound, are badly conditioned: a looser first solve there ends 1e-3 above
#: the level that the tighter one and its polish reach).
LEVEL_TOL_GENERAL = 1e-10
#: Largest number of states whose level is minimised over the projected
#: blocks (:func:`.level.projected_form`): beyond it the full block solves
#: faster (measured in the documentation, Validation: Benchmarks).
PROJECTED_MAX_N = 40
#: The gain of a projected-blocks optimum (:func:`.lmis.projected_gain`)
#: weighs with ``Phi`` lifted to at least ``PHI_FLOOR`` of its largest
#: eigenvalue: at the optimum ``Phi`` can be singular, and eigenvalues below
#: the accuracy of the level minimisation (``LEVEL_TOL``) are rounding noise
#: of either sign (as for ``OPTIMUM_X_FLOOR``). A larger floor moves the gain
#: away from the optimum's (1e-6: the truck's closed-loop norm 1.1e-4 above
#: ``gamma_opt`` instead of 1e-6).
PHI_FLOOR = 1e-8
#: Solver tolerance of the centring and fixed-level problems (their optimum
#: need not be exact: only their certificate matters).
CENTRE_TOL = 1e-7

# ---------------------------------------------------------------- gains
#: Smallest acceptable strictness margin (smallest eigenvalue of every
#: H-infinity block and of the Lyapunov or slack matrix) of a gain's
#: certificate. The level minimisation uses the non-strict LMIs: an infimum.
STRICT = 1e-8
#: The "conditioned" centring keeps ``X <= X_UPPER * lambda_max(X_opt) I``.
X_UPPER = 10.0
#: ... and the H-infinity blocks at least ``max(STRICT, CONDITIONED_MARGIN * backoff)``.
CONDITIONED_MARGIN = 1e-2
#: The Riccati-built certificate of the optimum's gain tries these margins
#: ``eps``, relative to the backoff.
CERTIFY_EPS = (1e-2, 1e-1)
#: If no gain is found at ``(1 + backoff) gamma_opt``, the backoff is
#: multiplied by these factors in turn.
BACKOFF_STEPS = (1.0, 10.0, 100.0)
#: ``backoff=0``: eigenvalues of the optimal ``X`` (solver coordinates) below
#: ``OPTIMUM_X_FLOOR * lambda_max(X)`` are below the accuracy of the level
#: minimisation (``LEVEL_TOL``) and are raised to it before ``K = Y X^-1``.
OPTIMUM_X_FLOOR = 1e-8

# ---------------------------------------------------------------- input bound
#: The input-bound LMIs use ``u_max^2 (1 - U_SLACK)``, so that solver rounding
#: cannot exceed ``u_max`` (the bound is conservative by 0.005 %).
U_SLACK = 1e-4
#: The guaranteed bound of the returned gain may exceed ``u_max`` by this
#: relative amount before the internal check fails.
U_BOUND_CHECK = 1e-6
