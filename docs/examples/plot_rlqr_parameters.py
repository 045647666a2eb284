"""
Choosing the robust LQR's mu, alpha and H
=========================================

A user who fits a norm-bounded model to a plant set with
:meth:`robustctl.NormBounded.from_plants` and hands it to the robust LQR
(:func:`robustctl.rlqr`) as it is, with a large penalty ``mu``, expects a more
robust loop than the plain LQR. This page measures what happens instead, on
three plant sets, and shows what to do: tune the uncertainty parameters of
the RLQR, as the paper does (:class:`moo.tuning.RLQRFamily`), and judge every
design by its *certified* margin against the fitted model. The explanation
is in the user guide (:doc:`/user_guide/rlqr_parameters`).

The three plant sets, each a nominal plant and its two extremes:

* an active quarter-car suspension whose sprung mass lies in 250-450 kg
  (the :ref:`sphx_glr_auto_examples_plot_quarter_car.py` model);
* a hovering helicopter (Franklin, Powell & Emami-Naeini) whose rotor gain is
  known to 20 %;
* the paper's truck from 0 to 300 % payload (:mod:`robustctl.models.truck`).
"""

# %%
# The plant sets and the fitted models
# ------------------------------------
import matplotlib.pyplot as plt
import numpy as np

import robustctl as rc
from moo import tuning
from robustctl.models.truck import truck_plant


def quarter_car(ms):
    mu, ks, cs, kt = 40.0, 16.0e3, 1.0e3, 160.0e3
    A = np.array([[0.0, 1.0, 0.0, -1.0], [-ks / ms, -cs / ms, 0.0, cs / ms], [0.0, 0.0, 0.0, 1.0],
                  [ks / mu, cs / mu, -kt / mu, -cs / mu]])
    return rc.Plant.from_continuous(A, np.array([[0.0], [1e3 / ms], [0.0], [-1e3 / mu]]), dt=0.01)


A_H = np.array([[-0.4, 0.0, -0.01], [1.0, 0.0, 0.0], [-1.4, 9.8, -0.02]])
B_H = np.array([[6.3], [0.0], [9.8]])


def helicopter(gain):
    return rc.Plant.from_continuous(A_H, B_H * gain, dt=0.05)


SETS = {
    "quarter car": (quarter_car(350.0), [quarter_car(250.0), quarter_car(450.0)]),
    "helicopter": (helicopter(1.0), [helicopter(0.8), helicopter(1.2)]),
    "truck": (truck_plant(150.0), [truck_plant(0.0), truck_plant(300.0)]),
}
for name, (nominal, extremes) in SETS.items():
    print(f"{name:12s} {rc.NormBounded.from_plants(nominal, extremes)}")

# %%
# What the fitted model gives
# ---------------------------
# For each set: the LQR of ``Q = I``, ``R = I`` and the RLQR of the fitted
# ``(H, E_F, E_G)`` for growing ``mu`` (``alpha = 0.1``, the default). Two
# numbers per design: the margin certified against the fitted model
# (:func:`robustctl.robust_stability`: stability for every
# ``||Delta|| < margin``) and the slowest closed loop over the three plants
# (the largest spectral radius: closer to 1 is slower).


def judge(nominal, plants, unc, K):
    margin = rc.robust_stability((nominal, K), unc).margin
    rho = max(rc.spectral_radius(p.F + p.G @ K) for p in plants)
    return margin, rho


rows = []
for name, (nominal, extremes) in SETS.items():
    plants = [nominal, *extremes]
    unc = rc.NormBounded.from_plants(nominal, extremes)
    rows.append((name, "LQR", *judge(nominal, plants, unc, rc.lqr(nominal).K)))
    for mu in (1e4, 1e8, np.inf):
        try:
            K = rc.rlqr(nominal, unc.EF, unc.EG, mu, H=unc.H).K
            rows.append((name, f"RLQR mu={mu:g}", *judge(nominal, plants, unc, K)))
        except rc.RobustCtlError as exc:
            first = str(exc).split(" (equivalently")[0].split(": no stabilising")[0]      # the message's first clause
            rows.append((name, f"RLQR mu={mu:g}", type(exc).__name__, first))
for row in rows:
    if isinstance(row[2], str):
        print(f"{row[0]:12s} {row[1]:14s} failed: {row[2]}: {row[3]}")
    else:
        print(f"{row[0]:12s} {row[1]:14s} certified margin {row[2]:7.3f}   slowest loop rho {row[3]:.5f}")

# %%
# Read the table: at ``mu = 1e8`` the robust LQR of the fitted model is in
# every set *slower* than the LQR (a spectral radius closer to 1), and in two
# of the three it certifies a *smaller* margin; ``mu = inf`` fails in all
# three (a rank condition: ``E_G`` would need full row rank, impossible with
# one input and a model of several rows; or, with ``E_F = 0``, it asks for
# ``E_G K = 0``, the open loop). The RLQR minimises a worst-case *cost*
# against the model, it does not maximise a stability margin, and a fitted
# model with a large ``E_G`` makes it save input at every cost.

# %%
# What to do: tune the uncertainty parameters
# -------------------------------------------
# The paper's method treats ``(E_F, E_G, mu)`` as design knobs: the RLQR
# family maps them to gains and a MOEA searches them, with the margin against
# the *fitted* model as a goal. Here two objectives, the certified margin
# (maximised) and the slowest loop, on the three plants of each set, with
# the fitted ``H`` (where the uncertainty enters) and ``mu`` up to ``1e8``.
fronts = {}
for name, (nominal, extremes) in SETS.items():
    plants = [nominal, *extremes]
    unc = rc.NormBounded.from_plants(nominal, extremes)
    family = tuning.RLQRFamily(nominal, H=unc.H, e_bound=2.0, log_mu_bound=64.0)
    problem = tuning.TuningProblem(family, plants, [tuning.RobustMargin(unc, nominal=nominal),
                                                   tuning.SpectralRadius()])
    result = tuning.tune(problem, evals=3000, seed=0, pop_size=40)
    margin = tuning.RobustMargin(unc, nominal=nominal).measure(result.gains, plants)
    rho = tuning.SpectralRadius()(result.gains, plants)
    lqr_margin, lqr_rho = judge(nominal, plants, unc, rc.lqr(nominal).K)
    fronts[name] = (margin, rho, lqr_margin, lqr_rho)
    both = int(np.sum((margin > lqr_margin) & (rho < lqr_rho)))
    print(f"{name:12s} tuned front: {len(margin)} designs, largest certified margin {margin.max():.3f} "
          f"(LQR {lqr_margin:.3f}), fastest loop rho {rho.min():.5f} (LQR {lqr_rho:.5f}); "
          f"{both} beat the LQR in both")

# %%
# The fronts against the LQR (the star) and the fitted-model RLQR at
# ``mu = 1e8`` (the cross).
fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), layout="constrained")
for ax, (name, (margin, rho, lqr_margin, lqr_rho)) in zip(axes, fronts.items(), strict=True):
    fitted = next(r for r in rows if r[0] == name and r[1] == "RLQR mu=1e+08")
    ax.scatter(rho, margin, s=12, label="tuned RLQR family")
    ax.scatter([lqr_rho], [lqr_margin], marker="*", s=120, color="C3", label="LQR (Q = I, R = I)")
    if not isinstance(fitted[2], str):
        ax.scatter([fitted[3]], [fitted[2]], marker="x", s=80, color="k", label="RLQR of the fitted model")
    ax.set_xlabel("slowest loop (spectral radius)")
    ax.set_title(name)
axes[0].set_ylabel("certified margin")
axes[0].legend(fontsize=8)
plt.show()
