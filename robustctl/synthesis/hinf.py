r"""H-infinity synthesis by LMI optimisation (cvxpy + Clarabel): state feedback and full-order output feedback.

Plant, with the gain ``u = K x`` (the paper's sign convention)::

    x+ = F x + Bw w + G u         (discrete, dt > 0; x' = ... for dt = None)
    z  = Cz x + Dzw w + Dzu u

The closed loop ``T_zw`` has ``A_K = F + G K``, ``C_K = Cz + Dzu K``. With the
change of variables ``Y = K X`` (Bernussou, Peres & Geromel 1989) the
bounded-real lemma becomes linear in ``(X, Y, gamma^2)``.

Discrete time (``X > 0``; storage ``V(x) = x' X^-1 x``)::

    [ X      A X + G Y   Bw   0               ]
    [ *      X           0    (Cz X + Dzu Y)' ]  > 0
    [ *      *           I    Dzw'            ]
    [ *      *           *    gamma^2 I       ]

Continuous time::

    [ He(F X + G Y)   Bw    (Cz X + Dzu Y)' ]
    [ *               -I    Dzw'            ]  < 0,   He(M) = M + M'
    [ *               *     -gamma^2 I      ]

Either inequality says ``V(x+) - V(x) <= |w|^2 - |z|^2 / gamma^2`` (or
``dV/dt <= ...``), hence ``||T_zw||_inf < gamma`` and internal stability.
This is the *gamma^2 form*: the same ``X`` bounds the reachable set,
``x' X^-1 x <= E`` for every disturbance of energy ``sum |w|^2 <= E``
(Boyd, El Ghaoui, Feron & Balakrishnan 1994, Sec. 6.1.3), so
``|u_j| = |k_j x| <= u_max_j`` holds whenever (Sec. 7.2.3)::

    [ u_max_j^2 / E   y_j ]
    [ y_j'            X   ]  >= 0       (y_j: row j of Y).

Polytopic plants: the LMI is imposed at every vertex ``(F_i, G_i)`` with one
common ``(X, Y)``; it is affine in ``(F, G)``, so the gain is guaranteed for
every plant in the convex hull (even time-varying). The *extended* (slack
variable) discrete-time condition of de Oliveira, Bernussou & Geromel (1999)
and de Oliveira, Geromel & Bernussou (2002) uses a vertex-dependent ``P_i``
and a common slack ``S`` (not symmetric), ``K = L S^-1``::

    [ P_i    F_i S + G_i L   Bw   0               ]
    [ *      S + S' - P_i    0    (Cz S + Dzu L)' ]  > 0
    [ *      *               I    Dzw'            ]
    [ *      *               *    gamma^2 I       ]

It reduces to the standard one for ``S = P_i = X`` (never more
conservative) and guarantees the bound for every *constant* plant of the
hull (storage ``x' P(a)^-1 x`` with ``P(a) = sum a_i P_i``). The input bound
then uses ``[[u_max_j^2/E, l_j], [l_j', S + S' - P_i]] >= 0`` at each vertex
(``S + S' - P <= S' P^-1 S``).

Robust synthesis (``uncertainty=NormBounded(H, EF, EG)``): every plant
``(F + H Delta EF, G + H Delta EG)`` with ``||Delta|| <= 1`` (also
time-varying). With ``q = (EF + EG K) x`` and ``p = Delta q`` the loop is
the nominal one with an extra input ``H p`` and ``|p| <= |q|``; the
S-procedure (a multiplier ``eps > 0``, one per vertex; equivalently the
scaled small-gain theorem) adds ``eps (|q|^2 - |p|^2) >= 0`` to the storage
inequality. In the gamma^2 form, with ``E X = EF X + EG Y`` (Xie, Fu & de
Souza 1992; Boyd et al. 1994, Sec. 7.5)::

    [ X - eps H H'   A X + G Y   Bw   0               0       ]
    [ *              X           0    (Cz X + Dzu Y)' (E X)'  ]
    [ *              *           I    Dzw'            0       ]  > 0     (discrete)
    [ *              *           *    gamma^2 I       0       ]
    [ *              *           *    *               eps I   ]

(continuous: ``He(F X + G Y) + eps H H'`` in the bounded-real LMI, with the
extra row ``[E X, 0, 0, -eps I]``). Linear in ``(X, Y, gamma^2, eps)``: the
convex counterpart of the RLQR (:func:`robustctl.rlqr`), whose penalty
parameter plays the part of ``1 / eps``.

Pole regions (``poles=Disk(...)``, :mod:`robustctl.systems.regions`): the LMI
``M_D(F X + G Y, X) < 0`` of Chilali & Gahinet (1996) at every vertex, with
the same ``X`` as the H-infinity bound.

Output feedback
---------------
A plant with measured outputs ``y = C x + D u + Dyw w`` gets a full-order
controller ``xc+ = Ac xc + Bc y``, ``u = Cc xc + Dc y``. ``D`` is removed
first by the loop shift ``y~ = y - D u`` and put back on the controller
(``robustctl.synthesis._hinf.generalised.loop_shift``). With the closed-loop
Lyapunov matrix ``Xcl = [Y N; N' *]``, ``Xcl^-1 = [X M; M' *]`` and the
linearising change of variables (Gahinet & Apkarian 1994; Scherer, Gahinet &
Chilali 1997) ``Ah = N Ac M' + N Bc C X + Y G Cc M' + Y (F + G Dc C) X``,
``Bh = N Bc + Y G Dc``, ``Ch = Cc M' + Dc C X``, ``Dh = Dc``, the
congruence by ``[X I; M' 0]`` turns every closed-loop condition into an LMI
in ``(X, Y, Ah, Bh, Ch, Dh)``; with
``AA = [F X + G Ch, F + G Dh C; Ah, Y F + Bh C]``,
``BB = [Bw + G Dh Dyw; Y Bw + Bh Dyw]``,
``CC = [Cz X + Dzu Ch, Cz + Dzu Dh C]``, ``DD = Dzw + Dzu Dh Dyw`` and
``P = [X I; I Y]``::

    continuous:  [ He(AA)  BB   CC'        ]
                 [ *       -I   DD'        ]  < 0,   P > 0
                 [ *       *    -gamma^2 I ]

    discrete:    [ P   AA   BB   0         ]
                 [ *   P    0    CC'       ]  > 0
                 [ *   *    I    DD'       ]
                 [ *   *    *    gamma^2 I ]

(H2: ``[He(AA), BB; *, -I] < 0`` and ``[P, CC'; CC, Z] > 0`` with
``trace Z`` minimised and ``DD = 0``, continuous; ``[P, AA, BB; *, P, 0; *, *,
I] > 0`` and ``[Z, CC, DD; *, P, 0; *, *, I] > 0``, discrete. Pole regions:
``L (x) P + M (x) AA' + M' (x) AA < 0``.) The numerics
(``robustctl.synthesis._hinf.output_synthesis`` lists the stages):

* Coordinates (``output_coordinates``): unit channels, balanced states,
  unit ``u`` and ``y``; then *separate* coordinates for ``X`` and ``Y``
  (a congruence ``diag(S^-1, T')`` and ``X = S X~ S'``, ``Y = T^-T Y~
  T^-1``: not a similarity, which keeps the eigenvalues of ``X Y``) with
  ``S S'`` and ``T^-T T^-1`` the shapes of the optimal ``X`` and ``Y``
  from the two Riccati equations of a coarse gamma-iteration (H-infinity:
  ``gamma^2 X_inf^-1`` and ``Y_inf^-1``; H2: the LQG closed loop's
  Gramian). Near the optimum ``X Y`` has eigenvalues from 1 to beyond
  ``1e10``; in one similarity Clarabel stopped 1e-5 to 1e-4 above the
  optimal level while reporting ``optimal``, in the two frames the level
  agrees with the Riccati bisection to 1e-8 in about 20 iterations (random
  plants, 4 to 20 states). The plain frame is tried when the shaped one
  fails.
* Level: ``gamma^2`` minimised (non-strict LMIs: the infimum; singular
  problems, ``Dzu`` or ``Dyw`` rank-deficient, need no regularisation).
* Controller: a centring solve at ``(1 + backoff) gamma_opt`` (the largest
  common margin of every block), where ``I - X Y`` is invertible, then the
  change of variables inverted with ``M N' = I - X Y`` factored by its SVD
  (both factors ``sqrt(cond)``-conditioned; ``M = I`` would put all of it
  on ``N``). The backoff is raised tenfold, at most twice, if needed.
* Certificate of the returned controller's closed loop, by eigenvalues:
  stability, and the bounded-real lemma in its frequency-domain form (the
  Hamiltonian of the closed loop at the returned level has no
  imaginary-axis eigenvalue; Boyd, Balakrishnan & Kabamba 1989). A
  Lyapunov-matrix certificate from the closed loop's bounded-real Riccati
  equation had margins at rounding level on near-optimal output-feedback
  loops (their Lyapunov matrices span many orders of magnitude).
* ``synthesis="riccati"``: the gamma-iteration on the two Riccati equations
  of Glover & Doyle (1988) in the general form with ``Dzw != 0`` (Zhou,
  Doyle & Glover 1996, Ch. 17), Brent's method on the coupling margin
  ``1 - rho(X_inf Y_inf) / gamma^2`` once both solutions exist; the central
  controller at ``(1 + backoff / 2) gamma_opt``, certified at
  ``(1 + backoff) gamma_opt`` as above. A discrete plant goes through its
  Tustin image ``s = (z - 1) / (z + 1)`` (it preserves every closed-loop
  H-infinity norm, so the levels and the certificate are those of the
  discrete loop). Singular problems and every failed check fall back to the
  LMIs.

Refused for output feedback, by name: ``vertices`` (``Ah`` contains ``Y F
X``: a controller common to a polytope of plants is not an LMI),
``uncertainty`` (its S-procedure multiplier multiplies both Lyapunov
variables), ``u_max`` / ``w_energy`` and ``extended``.

Numerics of state feedback
--------------------------
The synthesis is a sequence of pure stages (listed below; every tolerance is
named in ``robustctl.synthesis._hinf.tolerances``):

* Coordinates (``_hinf.coordinates``): ``w`` and ``z`` scaled to unit size
  first (``||Bw~|| = 1``, or unit energy when ``u_max`` is given, and
  ``||[Cz~ Dzu~ Dzw~]|| = 1``; the level scales with both, the gain does
  not), so that the solver's problem does not depend on the units the
  caller chose; states balanced (SLICOT ``TB01ID``) and scaled so that
  ``||Bw|| = 1``; ``z`` scaled further so that the fixed level of a
  centring problem is 1; ``[Cz Dzu Dzw]`` replaced by a factor with the same Gram
  matrix when that has fewer rows. A single plant is solved in coordinates
  where the inverse of its LQR Riccati solution (weight
  ``[Cz Dzu]'[Cz Dzu]``, kept to ``LQR_SHIFT`` of its largest eigenvalue)
  is ~ I: the optimal ``X`` has roughly that shape, so the optimum is well
  conditioned (fewer interior-point iterations, rarely
  ``optimal_inaccurate``; measured in the documentation, Validation: Benchmarks).
* Blocks (``_hinf.lmis``): the constant disturbance block ``I`` is
  eliminated by a Schur complement (e.g. the discrete block becomes
  ``[[X - Bw Bw', A X + G Y, -Bw Dzw'], [*, X, (Cz X + Dzu Y)'], [*, *,
  gamma^2 I - Dzw Dzw']] >= 0``): same set, ``q`` rows smaller. For the
  plain discrete problem (one plant, no input bound, pole region or
  uncertainty, a backoff) up to ``PROJECTED_MAX_N`` states the level is
  minimised with ``Y`` eliminated as well (projection lemma, Gahinet &
  Apkarian 1994; ``_hinf.lmis.projected_blocks``): with ``Abar = [F; Cz]``,
  ``Bbar = [G; Dzu]``, ``Phi = diag(X, gamma^2 I) - [Bw; Dzw][Bw; Dzw]'``
  and ``N`` a basis of the null space of ``Bbar'``, the blocks
  ``N'(Phi - Abar X Abar')N >= 0`` and ``Phi >= 0`` (orders ``n + p - m``
  and ``n + p``), and the gain is the weighted least-squares one,
  ``K = -(Bbar' Phi^-1 Bbar)^-1 Bbar' Phi^-1 Abar``
  (``_hinf.lmis.projected_gain``), certified like every other gain.
* Level (``_hinf.level``): ``gamma_opt`` minimises ``gamma^2`` (non-strict
  LMIs: the infimum), in the LQR coordinates of one plant at tolerance
  1e-8, first without Clarabel's iterative refinement (see
  ``robustctl._cvx.solve_sdp``), otherwise at 1e-10 with refinement
  (the truck polytope is badly conditioned), with fallbacks to the
  balanced coordinates, to a restart of the extended LMI from the standard
  one, and a polish of an ``optimal_inaccurate`` result.
* Gain (``_hinf.gains``): at the optimum ``X`` can be nearly singular and
  ``K = Y X^-1`` huge, so unless ``backoff=0`` the gain is certified at
  ``gamma = (1 + backoff) gamma_opt`` by the first of an ordered list of
  strategies (the optimum's own gain with a Riccati-built certificate for
  one discrete plant; centring re-solves; a raised backoff).
  ``info["gain_from"]`` names the route.
* Every solve goes through ``robustctl._cvx.solve_sdp``: status check,
  explicit symmetrisation, certificate eigenvalues; solver failures are
  retried with looser tolerances, the certificate is checked regardless.
* A fixed ``gamma`` is a feasibility problem posed as "maximise the common
  margin ``t <= 1``" (always feasible); ``t <= 0`` means infeasible.
* ``synthesis="riccati"`` (``_hinf.riccati_path``; the plain problem: one
  plant, free level, no input bound, pole region or uncertainty) replaces
  the SDP by a bisection on the game Riccati equation
  (:func:`robustctl.synthesis.hinf_riccati.bisect_level`, the library's one such
  bisection), takes the saddle-point gain at ``(1 + backoff / 2)
  gamma_opt`` and checks the same LMI blocks, by eigenvalues, at a point
  built from the closed loop's bounded-real Riccati equation at ``(1 +
  backoff) gamma_opt``; the SDP runs only if that check fails (always for
  ``backoff=0``). ``info["synthesis"]`` names the path.
* Certificates at a candidate point (arrays) are evaluated with numpy
  (``np.block``), without building cvxpy expressions.
* The level minimisation of one plant asks Clarabel to factor the
  H-infinity block whole (no chordal decomposition): its cliques are
  ``2 n`` and ``n + p`` of ``2 n + p`` rows, so the decomposition saves
  almost nothing in the dense front and its overlap variables couple the
  cliques in the KKT system (fewer iterations and a cheaper factorisation
  per iteration on the benchmark plants). Polytopes keep the decomposition.

Where the time goes: nearly all of it is Clarabel's interior-point
iterations, each a sparse LDL factorisation of a KKT system whose PSD part
is dense (``k (k + 1) / 2`` rows for a block of order ``k``); cvxpy's
compilation and Clarabel's setup are a small part from n = 20 on, and there
is no second solve in the default path of one discrete plant. The projected
blocks have about half the rows of the full one; their coefficient map is
dense (every entry depends on every entry of ``X``), so beyond about 40
states the full block, whose map stays sparse, factors faster. Small
problems run Clarabel on one thread (``robustctl._cvx.SINGLE_THREAD_PSD``).
Formulations tried and not kept, all exact: the Schur complement with
respect to the middle ``X`` block with ``Z >= Y X^-1 Y'`` lifted as
``[[Z, Y], [Y', X]] >= 0`` (blocks ``n + p`` and ``n + m``), in the modal or
real Schur coordinates of ``F``, or with a dense congruence of the second
block; ``Phi >= 0`` split into ``X >= Bw Bw'`` and ``gamma^2 >= 0`` when
``Dzw = 0`` (smaller, but Clarabel's ordering then factors it more slowly).
``benchmarks/investigations/benchmarks_hinf_sdp_forms.py`` times the full
and the projected blocks. Coordinates in which the solver's own optimal
``X`` is ``I`` save a few iterations only, and scaling the level,
Clarabel's step length, regularisation, equilibration and presolve settings
did not help.

Stages of :func:`hinf`, in order:

1. ``_hinf.problem.validate`` - every argument, and stabilisability (PBH);
2. ``_hinf.coordinates.channel_scales``, ``normalised`` and
   ``lqr_coordinates`` - the units of ``w`` and ``z``, the
   balanced coordinates, and for one plant the LQR ones;
3. ``_hinf.lmis`` - the named LMI blocks (used by every solve and every
   certificate);
4. ``_hinf.level.minimise_level`` - ``gamma_opt`` (or, with a fixed ``gamma``,
   ``_hinf.gains.gain_at_level``);
5. ``_hinf.gains.gain_near_optimum`` - the first of the gain strategies that
   returns a strictly feasible certificate at ``(1 + backoff) gamma_opt``;
6. :func:`check_closed_loop` and the input bound - internal checks of the
   returned gain.

References
----------
S. Boyd, L. El Ghaoui, E. Feron, V. Balakrishnan, *Linear Matrix Inequalities
in System and Control Theory*, SIAM 1994, Sec. 6.1.3, 7.2.3, 7.5.
M. C. de Oliveira, J. Bernussou, J. C. Geromel, "A new discrete-time robust
stability condition", Systems & Control Letters 37, 1999.
M. C. de Oliveira, J. C. Geromel, J. Bernussou, "Extended H2 and H-infinity
norm characterizations and controller parametrizations for discrete-time
systems", Int. J. Control 75(9), 2002.
L. Xie, M. Fu, C. E. de Souza, "H-infinity control and quadratic stabilization of systems with
parameter uncertainty via output feedback", IEEE TAC 37(8), 1992.
M. Chilali, P. Gahinet, "H-infinity design with pole placement constraints: an LMI approach",
IEEE TAC 41(3), 1996.
P. Gahinet, P. Apkarian, "A linear matrix inequality approach to
H-infinity control", Int. J. Robust Nonlinear Control 4, 1994.
C. Scherer, P. Gahinet, M. Chilali, "Multiobjective output-feedback control
via LMI optimization", IEEE TAC 42(7), 1997.
K. Glover, J. C. Doyle, "State-space formulae for all stabilizing controllers
that satisfy an H-infinity-norm bound and relations to risk sensitivity",
Systems & Control Letters 11, 1988.
K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*, Prentice Hall
1996, Ch. 14 and 17.
S. Boyd, V. Balakrishnan, P. Kabamba, "A bisection method for computing the
H-infinity norm of a transfer matrix and related problems", Mathematics of
Control, Signals and Systems 2(3), 1989.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike

from .. import _cvx
from .._validation import check_choice
from ..errors import ConvergenceError, InfeasibleError
from ..systems.controller import Controller
from ..systems.plant import Plant
from ..systems.regions import Region
from ..systems.stability import is_stable
from ..systems.uncertainty import NormBounded
from ._hinf import tolerances as tol
from ._hinf.coordinates import channel_scales, lqr_coordinates, normalised
from ._hinf.gains import Gain, gain_at_level, gain_near_optimum
from ._hinf.level import minimise_level
from ._hinf.output_problem import channel, dynamic_controller, output_problem, refuse, wants_output
from ._hinf.output_synthesis import synthesise
from ._hinf.problem import Problem, validate, vertex_name
from ._hinf.riccati_path import RiccatiPath, check_plain, riccati_synthesis

__all__ = ["hinf", "HinfController", "check_closed_loop", "guaranteed_input_bound"]


@dataclass(frozen=True, eq=False, repr=False)
class HinfController(Controller):
    """An H-infinity controller, state feedback ``u = K x`` or output feedback ``u = K(z) y``, with its level.

    What :func:`robustctl.hinf` returns; the constructor is that of
    :class:`~robustctl.Controller` with the two levels.

    Parameters
    ----------
    K : (m, n) array_like or None
        State-feedback gain ``u = K x``; None for an output feedback.
    method : str
        Name of the design method.
    plant : Plant
        The plant it was designed for.
    info : Mapping, optional
        Diagnostics of the design (see the design function), stored read-only.
    Ac, Bc, Cc, Dc : array_like, optional
        Output feedback ``xc+ = Ac xc + Bc y``, ``u = Cc xc + Dc y`` (as in
        :class:`~robustctl.Controller`).
    gamma : float
        Level guaranteed by the controller: ``||T_zw||_inf < gamma`` for the
        plant (and every plant of the hull of ``vertices``). Equals
        ``(1 + backoff) * gamma_opt``, or the requested ``gamma``.
    gamma_opt : float or None
        The optimal level of the LMI problem (``None`` when ``gamma`` was fixed);
        with ``synthesis="riccati"`` the upper end of the bisection's final
        bracket (relative width 1e-9), the same infimum.

    See Also
    --------
    robustctl.hinf

    Examples
    --------
    A scalar discrete plant, ``z = (x, u)``: the level is backed off by the
    default ``1e-3`` and the closed loop is stable:

    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.2]], [[1.0]], 0.1)
    >>> ctrl = rc.hinf(plant, Bw=[[1.0]], Cz=[[1.0], [0.0]], Dzu=[[0.0], [1.0]])
    >>> isinstance(ctrl, rc.HinfController), round(ctrl.gamma / ctrl.gamma_opt - 1, 9), ctrl.is_stabilizing()
    (True, 0.001, True)
    """

    gamma: float = float("nan")
    gamma_opt: float | None = None

    def __repr__(self) -> str:
        opt = "None" if self.gamma_opt is None else f"{self.gamma_opt:.6g}"
        base = super().__repr__()
        return base.replace("Controller(", f"HinfController(gamma={self.gamma:.6g}, gamma_opt={opt}, ", 1)


def hinf(plant: Plant, *, Bw: ArrayLike, Cz: ArrayLike, Dzu: ArrayLike, Dzw: ArrayLike | None = None,
         Dyw: ArrayLike | None = None, vertices: Sequence[Plant] | None = None, gamma: float | None = None,
         u_max: ArrayLike | None = None, w_energy: float | None = None, backoff: float = 1e-3,
         extended: bool = False, poles: Region | Sequence[Region] | None = None,
         uncertainty: NormBounded | None = None, solver: str = "CLARABEL", synthesis: str = "lmi",
         feedback: str | None = None) -> HinfController:
    r"""H-infinity synthesis by LMI optimisation: state feedback ``u = K x`` or output feedback ``u = K(z) y``.

    Finds the controller minimising ``gamma`` such that ``||T_zw||_inf < gamma`` for

    ``x+ = F x + Bw w + G u``, ``z = Cz x + Dzw w + Dzu u`` (discrete plant) or
    ``x' = F x + Bw w + G u`` (continuous plant, ``plant.dt is None``; ``F``,
    ``G`` are then ``A``, ``B``). When the plant declares measured outputs
    (``Plant(..., C=..., D=...)``), ``y = C x + D u + Dyw w`` and the result
    is a full-order dynamic controller ``xc+ = Ac xc + Bc y``,
    ``u = Cc xc + Dc y`` (``ctrl.K`` is None); otherwise, or with
    ``feedback="state"``, the state feedback ``u = K x``. The LMIs and the
    stages of both syntheses are given in the docstring of its module,
    ``robustctl.synthesis.hinf``.

    Parameters
    ----------
    plant : Plant
        The nominal plant ``(F, G)``.
    Bw : (n, q) array_like
        Disturbance input matrix.
    Cz : (p, n) array_like
        Performance output matrix.
    Dzu : (p, m) array_like
        Feedthrough from ``u`` to ``z``. With ``Dzu`` not of full column rank
        the optimum may need an unbounded gain (the backoff then matters).
    Dzw : (p, q) array_like, optional
        Feedthrough from ``w`` to ``z`` (default zero).
    Dyw : (plant.p, q) array_like, optional
        Output feedback: the feedthrough from ``w`` to the measured outputs
        (measurement noise; default zero). ``Dyw`` without full row rank (no
        noise on some output) makes the problem *singular*: the LMIs still
        solve it, the optimum then being an infimum (see ``backoff``).
    vertices : list of Plant, optional
        Further plants (same ``n``, ``m``, ``dt``). The bound then holds for
        every plant in the convex hull of ``[plant] + vertices``. State
        feedback only.
    gamma : float, optional
        Fixed level: solve the feasibility problem at this ``gamma`` (no
        minimisation). Raises :class:`~robustctl.errors.InfeasibleError`
        naming ``gamma`` if no gain achieves it.
    u_max : float or (m,) array_like, optional
        Bound on each ``|u_j|``, guaranteed (from ``x0 = 0``) for every
        disturbance with ``sum_k |w_k|^2 <= w_energy`` (continuous time:
        ``int |w|^2 dt <= w_energy``). Uses the reachable-set ellipsoid of
        the same Lyapunov matrix, so ``gamma_opt`` is then the best level
        *subject to* the bound. State feedback only.
    w_energy : float, optional
        Disturbance energy for ``u_max`` (default 1). Only valid with ``u_max``.
    backoff : float, default 1e-3
        The gain is computed at ``gamma = (1 + backoff) gamma_opt`` from a
        well-centred strictly feasible point. ``0`` returns the optimal
        point's gain (can be badly conditioned; eigenvalues of ``X`` below
        ``1e-8 lambda_max(X)``, the accuracy of the minimisation, are raised
        to that floor first, so that a singular optimum gives a stabilising,
        reproducible gain). If no strictly feasible point
        with a positive certificate is found at that level (nearly infeasible
        problems, e.g. a tight ``u_max``), the backoff is raised tenfold, at
        most twice; ``info["backoff"]`` and ``gamma`` report the value used.
        Output feedback needs ``backoff > 0``: the controller is
        reconstructed from a well-centred point at that level, where the
        coupling ``I - X Y`` of the two Lyapunov variables is well
        conditioned.
    extended : bool, default False
        Use the slack-variable condition of de Oliveira et al. (discrete time
        only): less conservative with ``vertices``, equal without. State
        feedback only.
    poles : Region or list of Region, optional
        Pole regions (:mod:`robustctl.systems.regions`: ``Disk``, ``HalfPlane``,
        ``ConicSector``; a list means their intersection): every pole of
        ``F + G K`` of every vertex lies in them (Chilali & Gahinet 1996),
        imposed with the same Lyapunov matrix as the H-infinity bound, so
        ``gamma_opt`` is the best level *subject to* the regions (a
        conservative bound: one ``X`` for both). Standard LMI only.
    uncertainty : NormBounded, optional
        Robust synthesis for ``[dF dG] = H Delta [EF EG]`` with every
        ``||Delta||_2 <= 1`` (also time-varying) around every vertex: the
        bound ``gamma`` then holds for every such plant (quadratic
        stability and performance, by the S-procedure with one multiplier
        per vertex; see ``robustctl.synthesis.hinf``). The convex counterpart of
        :func:`robustctl.rlqr`. ``H = 0`` or ``[EF EG] = 0`` is the nominal
        design. Pole regions apply to the nominal vertices. Standard LMI only.
        State feedback only.
    solver : str, default "CLARABEL"
        cvxpy SDP solver. Clarabel is run with explicit tolerances (1e-8 for
        the level of one plant, 1e-10 with vertices, 1e-7 for centring);
        other solvers use their defaults and may not reach 1e-5 accuracy.
    synthesis : {"lmi", "riccati"}, default "lmi"
        ``"lmi"``: the SDP (every variant). ``"riccati"``: the plain problem
        only (one plant, free level, no ``u_max``, ``poles`` or
        ``uncertainty``, standard LMI; anything else is a ValueError): the
        optimal level by bisection on the game Riccati equation, the gain of
        its saddle point at ``(1 + backoff / 2) gamma_opt``, and the same LMI
        certificate at ``(1 + backoff) gamma_opt`` checked by eigenvalues
        (:mod:`robustctl.synthesis._hinf.riccati_path`); if that certificate is not
        strictly positive the SDP is solved instead. ``info["synthesis"]``
        says which path returned the gain (``info["fallback"]`` why the SDP
        was needed). With ``"riccati"`` cvxpy is imported, and ``solver``
        checked to be installed, only if the SDP runs. Output feedback: the
        gamma-iteration on the two Riccati equations of Glover & Doyle (the
        discrete plant through its Tustin image), the central controller at
        ``(1 + backoff / 2) gamma_opt`` and its closed loop certified at
        ``(1 + backoff) gamma_opt``; a singular problem (``Dzu`` without full
        column rank or ``Dyw`` without full row rank) or any failed check
        falls back to the LMIs. ``poles`` and a fixed ``gamma`` are then a
        ValueError.
    feedback : {None, "state", "output"}, optional
        ``None``: output feedback when the plant declares outputs, state
        feedback otherwise. ``"state"`` asks for ``u = K x`` on a plant with
        outputs (the full state measured); ``"output"`` on a plant without
        outputs is a ValueError.

    Returns
    -------
    HinfController
        State feedback: ``K`` (``u = K x``); output feedback: ``Ac``,
        ``Bc``, ``Cc``, ``Dc`` (``K`` None). Both: ``gamma`` (guaranteed),
        ``gamma_opt`` and ``info``, read-only, with these keys ("SF": state
        feedback only, "OF": output feedback only):

        ====================  =============================================================
        key                   value
        ====================  =============================================================
        ``"synthesis"``       ``"lmi"`` or ``"riccati"``: the path that returned the controller
        ``"riccati"``         with ``synthesis="riccati"``: bisection ``iterations`` and
                              the bracket's ``gamma_low``
        ``"fallback"``        with ``synthesis="riccati"``: why the LMI path ran, or None
        ``"gain_from"``       the route of the controller: SF ``"optimum-certified"``,
                              ``"optimum"`` (``backoff=0``) or a centring variant;
                              OF ``"centred"`` (LMI) or ``"central"`` (Riccati)
        ``"certificate"``     SF: smallest eigenvalue of each LMI block at the returned
                              point; OF: the closed loop's ``stability`` margin and
                              ``hinf[0]``, the distance of its Hamiltonian's eigenvalues
                              from the imaginary axis at ``gamma`` (relative)
        ``"margin"``          the centring margin ``t`` (OF: LMI path only)
        ``"backoff"``         the backoff used
        ``"status"``          the solver's status of the last solve
        ``"solve_time"``      seconds, summed over the solves
        ``"iterations"``      interior-point iterations, summed
        ``"solves"``          per solve: ``status``, ``value``, ``tol``, ``solve_time``,
                              ``iterations``, ``certificate`` of the blocks it imposed
                              (``hinf_projected[0]``, ``hinf_phi[0]`` when ``Y`` was
                              eliminated), and ``centring`` for centring solves
        ``"poles"``           the pole regions
        ``"feedback"``        OF: ``"output"``
        ``"gamma"``           SF: the guaranteed level (as ``ctrl.gamma``)
        ``"gamma_opt"``       SF: the optimal level (as ``ctrl.gamma_opt``)
        ``"solver"``          SF: the SDP solver
        ``"X"``               SF: the Lyapunov matrix (``x' X^-1 x <= 1`` on the states
                              reached by disturbances of energy ``w_energy``; ``P`` of
                              the nominal vertex when ``extended``)
        ``"X_min_eig"``       SF: its smallest eigenvalue
        ``"u_bound"``         SF with ``u_max``: the guaranteed ``max |u_j|``, with the
                              ``"u_max"`` and ``"w_energy"`` it was given
        ``"scaling"``         SF: the state balancing
        ``"lmi"``             SF: the LMI form, e.g. ``"standard-discrete"``, ``"extended-continuous"``
        ``"vertices"``        SF: the number of plants (the polytope's vertices)
        ``"uncertainty"``     SF: the norm-bounded uncertainty given, or None
        ``"multipliers"``     SF with uncertainty: the S-procedure multipliers
        ====================  =============================================================

    Raises
    ------
    InfeasibleError
        A vertex is not stabilisable (:class:`~robustctl.errors.NotStabilizableError`,
        an ``InfeasibleError``), the fixed ``gamma`` or the input bound
        cannot be met, no common Lyapunov matrix exists for the vertices (or
        the uncertainty), or the pole regions cannot be reached (the reason:
        regions without a common stable point, a mode outside them that the
        input cannot move, or no common Lyapunov matrix).
    ValueError, TypeError
        Bad arguments (named in the message).

    Examples
    --------
    The truck of the paper with a disturbance entering like the steering
    input and ``z = (x, u)``; the optimal level agrees with the independent
    game-Riccati bisection of :mod:`robustctl.synthesis.hinf_riccati`:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.synthesis.hinf_riccati import hinf_riccati
    >>> from robustctl.models.truck import truck_plant
    >>> plant = truck_plant(0.0)
    >>> Bw, (Cz, Dzu) = plant.G, rc.lq_output(np.eye(4), 1.0)
    >>> ctrl = rc.design("hinf", plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    >>> round(ctrl.gamma_opt, 4), round(ctrl.gamma / ctrl.gamma_opt - 1, 6), ctrl.is_stabilizing()
    (1.2547, 0.001, True)
    >>> bool(abs(ctrl.gamma_opt / hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu).gamma - 1) < 1e-6)
    True

    Output feedback: Example 7 of Scherer, Gahinet & Chilali (1997), one
    measured output with noise; the optimal level agrees with
    python-control's ``hinfsyn``, and python-control's closed loop of the
    returned controller (``u = K(s) y``, positive feedback as its ``lft``)
    meets the guaranteed level:

    >>> import control
    >>> A = [[0.0, 10.0, 2.0], [-1.0, 1.0, 0.0], [0.0, 2.0, -5.0]]
    >>> plant = rc.Plant(A, [[0.0], [1.0], [0.0]], None, C=[[0.0, 1.0, 0.0]])
    >>> Bw, Cz, Dzu, Dyw = [[1.0], [0.0], [1.0]], [[1.0, 0, 0], [0, 0, 0]], [[0.0], [1.0]], [[2.0]]
    >>> ctrl = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dyw=Dyw, synthesis="riccati")
    >>> round(ctrl.gamma_opt, 4), ctrl.order, ctrl.K is None
    (9.5081, 3, True)
    >>> P = control.ss(A, np.hstack([Bw, plant.G]), np.vstack([Cz, plant.C]), [[0, 0], [0, 1], [2, 0]])
    >>> bool(abs(ctrl.gamma_opt / control.hinfsyn(P, 1, 1)[2] - 1) < 1e-6)
    True
    >>> bool(control.linfnorm(P.lft(ctrl.controller_statespace()))[0] < ctrl.gamma)
    True
    """
    synthesis = check_choice(synthesis, "synthesis", ("lmi", "riccati"))
    if wants_output(plant, feedback, Dyw):
        refuse(vertices=vertices, uncertainty=uncertainty, u_max=u_max, w_energy=w_energy, extended=extended)
        if synthesis == "riccati" and (poles is not None or gamma is not None):
            raise ValueError("synthesis='riccati' is the plain problem only (free level, no pole region); drop "
                             f"{'poles' if poles is not None else 'gamma'} or use synthesis='lmi'")
        pb = output_problem(plant, "hinf", (channel(plant, Bw, Cz, Dzu, Dzw, Dyw),), gamma=gamma, backoff=backoff,
                            poles=poles, solver=solver, synthesis=synthesis)
        res = synthesise(pb)
        return dynamic_controller(HinfController, "hinf", plant, res, pb, gamma=res.gamma, gamma_opt=res.gamma_opt)
    problem = validate(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw, vertices=vertices, gamma=gamma, u_max=u_max,
                       w_energy=w_energy, backoff=backoff, extended=extended, solver=solver, poles=poles,
                       uncertainty=uncertainty, defer_solver=synthesis == "riccati")
    if synthesis == "riccati":
        check_plain(problem)
    w_scale, z_unit = channel_scales(problem.Bw, problem.Cz, problem.Dzu, problem.Dzw, problem.w_energy)
    balanced = normalised([p.F for p in problem.plants], [p.G for p in problem.plants], problem.Bw, problem.Cz,
                          problem.Dzu, problem.Dzw, w_scale, problem.uncertainty, z_unit=z_unit)
    lqr = _lqr(problem, balanced)
    fast = _riccati(problem, balanced, lqr) if synthesis == "riccati" else None
    if fast is not None and fast.gain is None:  # the SDP is needed after all: check the solver now
        problem = replace(problem, solver=_cvx.check_solver(problem.solver))
    solves: tuple[dict, ...]
    if fast is not None and fast.gain is not None:
        gain, gamma_opt, used_backoff, solves = fast.gain, fast.gamma_opt, problem.backoff, ()
        level = gamma_opt * (1.0 + used_backoff)
    elif problem.gamma is not None:
        gain, solves = gain_at_level(problem, lqr or balanced, problem.gamma)
        level, gamma_opt, used_backoff = problem.gamma, None, None
    else:
        opt = minimise_level(problem, balanced, lqr)
        gain, used_backoff, centring = gain_near_optimum(problem, opt)
        level, gamma_opt, solves = opt.gamma_opt * (1.0 + used_backoff), opt.gamma_opt, opt.solves + centring
    K, X = gain.data.to_original(gain.point.gain(), gain.point.nominal_lyapunov())
    X = X * (problem.w_energy or 1.0) / w_scale / w_scale  # the reachable set of disturbances of energy w_energy
    check_closed_loop(K, problem.plants, problem.regions)
    info = _info(problem, gain, K, X, level, gamma_opt, used_backoff, solves)
    info["synthesis"] = "riccati" if fast is not None and fast.gain is not None else "lmi"
    if fast is not None:
        info["riccati"] = {"iterations": fast.iterations, "gamma_low": fast.gamma_low}
        info["fallback"] = None if fast.gain is not None else fast.reason
    return HinfController(K=K, method="hinf", plant=plant, info=info, gamma=float(level), gamma_opt=gamma_opt)


def _lqr(problem: Problem, balanced):
    """The LQR coordinates of a single plant (``None`` for a polytope or if they fail)."""
    return None if problem.polytopic else lqr_coordinates(balanced, problem.discrete)


def _riccati(problem: Problem, balanced, lqr) -> RiccatiPath:
    """The fast path; a bisection that finds no level becomes a fallback reason (the SDP then decides)."""
    try:
        return riccati_synthesis(problem, balanced, lqr)
    except InfeasibleError as exc:
        return RiccatiPath(None, float("nan"), float("nan"), 0, str(exc))


def check_closed_loop(K: np.ndarray, plants, regions: Sequence[Region] = ()) -> None:
    """ConvergenceError unless ``K`` is finite and stabilises every vertex with its poles in the regions.

    An internal check of the returned gain (the LMI certificate implies both);
    stable means :func:`robustctl.systems.stability.is_stable` (the library's one margin).
    """
    if not np.all(np.isfinite(K)):
        raise ConvergenceError("the gain K = Y X^-1 is not finite; increase backoff")
    for i, p in enumerate(plants):
        A = p.F + p.G @ K
        where = vertex_name(i)
        if not is_stable(A, discrete=p.is_discrete):
            raise ConvergenceError(f"internal check failed: the LMI gain does not stabilise {where}; "
                                   "increase backoff")
        poles = np.linalg.eigvals(A)
        for r in regions:
            if not np.all(r.contains(poles)):
                raise ConvergenceError(f"internal check failed: a closed-loop pole of {where} lies outside {r!r} "
                                       f"(poles {np.round(poles, 6).tolist()}); increase backoff")


def guaranteed_input_bound(gain: Gain) -> np.ndarray:
    """``max_i sqrt(k_j P_i k_j')`` over the Lyapunov matrices of the point (unit energy after scaling ``w``)."""
    Ks = gain.point.gain()
    return np.max([np.sqrt(np.einsum("ij,jk,ik->i", Ks, P, Ks)) for P in gain.point.lyapunov_matrices()], axis=0)


def _info(problem: Problem, gain: Gain, K, X, level, gamma_opt, backoff, solves) -> dict:
    Xs = 0.5 * (X + X.T)
    info = {
        "gamma": level, "gamma_opt": gamma_opt, "backoff": backoff,
        "lmi": ("extended" if problem.extended else "standard") + ("-discrete" if problem.discrete else "-continuous"),
        "vertices": len(problem.plants), "status": solves[-1]["status"] if solves else "certified",
        **_cvx.totals(solves),
        "certificate": gain.certificate, "gain_from": gain.route, "X_min_eig": float(np.linalg.eigvalsh(Xs).min()),
        "margin": float(gain.margin), "solves": list(solves), "X": Xs, "scaling": gain.data.balancing,
        "solver": problem.solver, "poles": problem.regions, "uncertainty": problem.uncertainty,
    }
    if problem.uncertainty is not None:
        info["multipliers"] = gain.point.eps   # S-procedure multipliers (solver coordinates)
    if problem.u_max is not None:
        u_bound = guaranteed_input_bound(gain)
        info.update(u_bound=u_bound, u_max=problem.u_max, w_energy=problem.w_energy)
        if np.any(u_bound > problem.u_max * (1.0 + tol.U_BOUND_CHECK)):
            raise ConvergenceError(f"internal check failed: the guaranteed input bound {u_bound.tolist()} "
                                   f"exceeds u_max = {problem.u_max.tolist()} (solver inaccuracy); increase backoff")
    return info
