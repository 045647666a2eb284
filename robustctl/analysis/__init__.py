r"""Robust analysis of a state feedback ``u = K x``: LMI certificates and a worst-case search.

For a plant ``(F, G)`` and a gain ``K`` the nominal closed loop is
``A = F + G K``. A norm-bounded uncertainty ``[dF dG] = H Delta [EF EG]``
(:class:`~robustctl.NormBounded`) gives the uncertain loop

    x+ = (A + H Delta E) x,    E = EF + EG K,    ||Delta||_2 <= 1

(``x' = ...`` in continuous time, ``plant.dt is None``), i.e. the feedback
of the nominal loop with ``q = Delta p``, ``p = E x`` entering through ``H``.
A polytope ``vertices=[Plant, ...]`` gives ``A_i = F_i + G_i K``.

Every function takes the controller as a :class:`~robustctl.Controller`
(its ``K`` and ``plant``) or as a pair ``(plant, K)`` (e.g. a gain designed
elsewhere, or a continuous-time one).

The LMIs (discrete time; ``M >= 0`` means positive semidefinite). With the
S-procedure for the quadratic constraint ``|q|^2 <= |E x|^2`` (lossless for
one full block ``Delta``; its multiplier is normalised to 1 where the LMI is
homogeneous):

* quadratic stability for ``||Delta|| <= r`` (Boyd, El Ghaoui, Feron &
  Balakrishnan 1994, Sec. 5.1.2)::

      [ P - A'PA - E'E    -r A'PH       ]
      [ -r H'PA           I - r^2 H'PH  ]  > 0,   P > 0

  By the bounded-real lemma this holds for some ``P`` iff ``A`` is stable
  and ``r ||E (zI - A)^-1 H||_inf < 1`` (Khargonekar, Petersen & Zhou
  1990), so the largest such ``r`` (the *margin*) is the small-gain value.
  It is computed as ``1 / sqrt(mu)`` from the convex problem "minimise
  ``mu`` s.t. ``[[P - A'PA - E'E, -A'PH], [-H'PA, mu I - H'PH]] >= 0``".
* guaranteed cost (Petersen & McFarlane 1994): with ``Q_K = Q + K'RK``::

      [ P - A'PA - Q_K - lam E'E    -A'PH          ]
      [ -H'PA                       lam I - H'PH   ]  >= 0

  implies ``V(x+) - V(x) <= -x'Q_K x`` for ``V = x'Px`` and every
  ``Delta`` (also time-varying), hence ``sum_k x'Qx + u'Ru <= x0'P x0``.
* robust H-infinity performance: with ``z = C_K x + Dzw w``,
  ``C_K = Cz + Dzu K`` and the inputs ``(q, w)``::

      diag(P, 0, 0) - [A H Bw]'P[A H Bw] - lam diag(E'E, -I, 0)
          - [C_K 0 Dzw]'[C_K 0 Dzw] + diag(0, 0, gamma^2 I)  >= 0

  implies ``V(x+) - V(x) <= gamma^2 |w|^2 - |z|^2`` for every ``Delta``,
  hence ``||T_zw||_inf <= gamma``.

Continuous time replaces ``diag(P, 0) - [A B]'P[A B]`` by
``-(He([I 0]' P [A B]))``, ``He(M) = M + M'``.

Norm-bounded robust stability without an SDP
--------------------------------------------
The margin is the small-gain value ``1 / ||E (zI - A)^-1 H||_inf``,
computed by a level-set H-infinity norm (Bruinsma & Steinbuch 1990;
imaginary-axis eigenvalues of a Hamiltonian, the discrete case through a
bilinear transform; :mod:`robustctl.analysis._hinfnorm`) to ``2e-10`` relative, on
the whole stack of gains at once. One gain per call uses SLICOT's AB13DD
(the same algorithm with a structure-preserving Hamiltonian eigensolver,
through slycot) when slycot is installed, the level-set iteration without
it (``info["norm"]``: ``"ab13dd"`` or ``"level-set"``). The certificate ``P`` at the radius
``r`` (1 if the margin exceeds 1, else ``margin / (1 + 1e-3)``) is the
stabilising solution of the bounded-real Riccati equation of
``(A, r H, [E; sqrt(eps) I])`` at the level ``gamma`` with
``gamma^2 = (1 + (r / margin)^2) / 2``: between the norm of the scaled loop
and 1, so that the LMI is strictly feasible (its Schur complement is at
least ``eps I``); for one gain of state size 14 or more it is computed by the
structure-preserving doubling algorithm (``n x n`` matrices only; Chu, Fan &
Lin 2005), with the Hamiltonian's eigenvectors as the fallback
(``info["riccati"]``). It is verified like any other certificate (eigenvalues of
the LMI blocks at ``P`` in the plant's coordinates); only a design whose
Riccati certificate fails that check goes to the SDP below (``info["path"]``
says which: ``"riccati"`` or ``"sdp"``). Polytopes always use the SDP.

Numerics of the SDPs
--------------------
* Each problem is solved in coordinates ``x = L'^-1 x^`` where the
  Lyapunov solution ``P_L = L L'`` of the nominal loop (weight: the
  problem's state weight plus ``1e-3`` of its norm times ``I``) becomes
  ``I``, with ``H`` and ``E`` scaled to comparable norms (the margin problem:
  unit norms), ``Bw`` to unit norm and the guaranteed-cost objective to
  unit size. Results are mapped back; margins and bounds are unchanged.
  Every bound is then independent of the units of the weights, of ``w``,
  ``z`` and ``x0`` (scaling ``Q, R`` by ``a^2`` scales the cost by ``a^2``;
  unscaled, the authors' truck weights ``R = 33535`` made the
  guaranteed-cost LMI fail).
* The margin minimisation is non-strict (it computes the infimum); the
  returned ``P`` comes from its optimum ``P*`` as ``P* + eps P_L``, which
  is strictly feasible at any radius below the margin for small ``eps``
  (no second solve). A certificate is a list of smallest eigenvalues,
  computed with numpy from the returned ``P`` in the original coordinates;
  it counts as strict when each exceeds ``1e-12`` times the block's norm.
* Every solve goes through :func:`robustctl._cvx.solve_sdp` (Clarabel,
  status checks, certificate eigenvalues).

Readings where the issue leaves room
------------------------------------
* ``certified`` is decided by the certificate at radius 1, not by
  ``margin > 1`` alone: for a margin within solver rounding of 1 it may be
  ``False``.
* The polytope margin is the largest ``r`` for which the polytope scaled
  by ``r`` about the nominal plant, ``conv{A_0 + r (A_i - A_0)}``, has a
  common Lyapunov matrix (a generalised eigenvalue problem, Boyd et al.
  1994, Sec. 5.1.1), solved by bisection to ``1e-3`` relative (the
  reported value is the certified end of the bracket) up to ``r = 1000``.
* ``guaranteed_cost`` without ``x0`` minimises ``lambda_max(P)``: one
  ``P`` bounds the cost of every unit initial state.

References
----------
S. Boyd, L. El Ghaoui, E. Feron, V. Balakrishnan, *Linear Matrix Inequalities
in System and Control Theory*, SIAM 1994, Sec. 5.1, 6.3.
P. P. Khargonekar, I. R. Petersen, K. Zhou, "Robust stabilization of uncertain
linear systems: quadratic stabilizability and H-infinity control theory",
IEEE TAC 35(3), 1990.
I. R. Petersen, D. C. McFarlane, "Optimal guaranteed cost control and
filtering for uncertain linear systems", IEEE TAC 39(9), 1994.
"""

from __future__ import annotations

from .cost import guaranteed_cost, robust_hinf_bound
from .loop_margins import LoopMargins, disk_ranges, loop_margins
from .margins_report import MarginsReport, margins_report
from .results import CostBound, CostBoundBatch, HinfBound, RobustStability, RobustStabilityBatch, WorstCase
from .robust_stability import robust_stability
from .worst_case import worst_case

__all__ = ["robust_stability", "guaranteed_cost", "robust_hinf_bound", "worst_case", "margins_report",
           "loop_margins", "disk_ranges",
           "RobustStability", "RobustStabilityBatch", "CostBound", "CostBoundBatch", "HinfBound", "WorstCase",
           "MarginsReport", "LoopMargins"]
