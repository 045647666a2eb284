r"""H-infinity state feedback by LMI optimisation (cvxpy + Clarabel).

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

Pole regions (``poles=Disk(...)``, :mod:`robustctl.regions`): the LMI
``M_D(F X + G Y, X) < 0`` of Chilali & Gahinet (1996) at every vertex, with
the same ``X`` as the H-infinity bound.

Numerics
--------
The synthesis is a sequence of pure stages (:mod:`robustctl._hinf._synthesis`
lists them; every tolerance is named in ``robustctl._hinf._tolerances``):

* Coordinates (:mod:`._coordinates`): ``w`` and ``z`` scaled to unit size
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
* Blocks (:mod:`._lmis`): the constant disturbance block ``I`` is
  eliminated by a Schur complement (e.g. the discrete block becomes
  ``[[X - Bw Bw', A X + G Y, -Bw Dzw'], [*, X, (Cz X + Dzu Y)'], [*, *,
  gamma^2 I - Dzw Dzw']] >= 0``): same set, ``q`` rows smaller. For the
  plain discrete problem (one plant, no input bound, pole region or
  uncertainty, a backoff) up to ``PROJECTED_MAX_N`` states the level is
  minimised with ``Y`` eliminated as well (projection lemma, Gahinet &
  Apkarian 1994; :func:`._lmis.projected_blocks`): with ``Abar = [F; Cz]``,
  ``Bbar = [G; Dzu]``, ``Phi = diag(X, gamma^2 I) - [Bw; Dzw][Bw; Dzw]'``
  and ``N`` a basis of the null space of ``Bbar'``, the blocks
  ``N'(Phi - Abar X Abar')N >= 0`` and ``Phi >= 0`` (orders ``n + p - m``
  and ``n + p``), and the gain is the weighted least-squares one,
  ``K = -(Bbar' Phi^-1 Bbar)^-1 Bbar' Phi^-1 Abar``
  (:func:`._lmis.projected_gain`), certified like every other gain.
* Level (:mod:`._level`): ``gamma_opt`` minimises ``gamma^2`` (non-strict
  LMIs: the infimum), in the LQR coordinates of one plant at tolerance
  1e-8, first without Clarabel's iterative refinement (see
  :func:`robustctl._cvx.solve_sdp`), otherwise at 1e-10 with refinement
  (the truck polytope is badly conditioned), with fallbacks to the
  balanced coordinates, to a restart of the extended LMI from the standard
  one, and a polish of an ``optimal_inaccurate`` result.
* Gain (:mod:`._gains`): at the optimum ``X`` can be nearly singular and
  ``K = Y X^-1`` huge, so unless ``backoff=0`` the gain is certified at
  ``gamma = (1 + backoff) gamma_opt`` by the first of an ordered list of
  strategies (the optimum's own gain with a Riccati-built certificate for
  one discrete plant; centring re-solves; a raised backoff).
  ``info["gain_from"]`` names the route.
* Every solve goes through :func:`robustctl._cvx.solve_sdp`: status check,
  explicit symmetrisation, certificate eigenvalues; solver failures are
  retried with looser tolerances, the certificate is checked regardless.
* A fixed ``gamma`` is a feasibility problem posed as "maximise the common
  margin ``t <= 1``" (always feasible); ``t <= 0`` means infeasible.
* ``synthesis="riccati"`` (:mod:`._riccati_path`; the plain problem: one
  plant, free level, no input bound, pole region or uncertainty) replaces
  the SDP by a bisection on the game Riccati equation
  (:func:`robustctl.hinf_riccati.bisect_level`, the library's one such
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
"""

from ._synthesis import HinfController, hinf

__all__ = ["hinf", "HinfController"]
