"""
Tune a robust controller for your own plant
===========================================

The paper's method as a tool, on a plant that is not the paper's truck: an
**active quarter-car suspension** whose sprung mass (the body plus its load)
is only known to lie between 250 and 450 kg. The steps are the same for any
plant:

1. a model ``params -> Plant`` (continuous, discretised by zero-order hold);
2. the uncertainty: scenario plants over the parameter range
   (:func:`robustctl.sample_plants`) and a norm-bounded model that contains
   them (:meth:`robustctl.NormBounded.from_plants`);
3. the goals (:mod:`moo.tuning`): ride comfort, suspension travel
   after a bump and peak actuator force as objectives, a certified robust
   margin as a constraint;
4. tuning with a MOEA and MO-LSP (:func:`moo.tuning.tune`, a small budget
   here), Monte Carlo selection of one design, and its certificate
   (:func:`robustctl.robust_stability`).
"""

# %%
# The plant
# ---------
# States ``x = [zs - zu, zs', zu - zr, zu']``: suspension deflection, body
# velocity, tyre deflection, wheel velocity; input ``u``: the actuator force
# in kN between body and wheel; road disturbance ``w = zr'`` (road
# velocity). The passive spring ``ks`` and damper ``cs`` stay in place; the
# controller adds ``u = K x``.
import matplotlib.pyplot as plt
import numpy as np

import robustctl as rc
from moo import tuning

M_WHEEL, K_SPRING, C_DAMPER, K_TYRE = 40.0, 16.0e3, 1.0e3, 160.0e3   # kg, N/m, Ns/m, N/m
DT = 0.01                                                            # s


def matrices(ms):
    """Continuous ``dx/dt = A x + B u + Bw w`` for a sprung mass ``ms`` (kg); ``u`` in kN."""
    mu, ks, cs, kt = M_WHEEL, K_SPRING, C_DAMPER, K_TYRE
    A = np.array([[0.0, 1.0, 0.0, -1.0],
                  [-ks / ms, -cs / ms, 0.0, cs / ms],
                  [0.0, 0.0, 0.0, 1.0],
                  [ks / mu, cs / mu, -kt / mu, -cs / mu]])
    B = np.array([[0.0], [1e3 / ms], [0.0], [-1e3 / mu]])
    Bw = np.array([[0.0], [0.0], [-1.0], [0.0]])
    return A, B, Bw


def quarter_car(ms):
    """The discrete plant (zero-order hold) for a sprung mass ``ms``."""
    A, B, _ = matrices(ms)
    return rc.Plant.from_continuous(A, B, dt=DT)


# %%
# The uncertainty
# ---------------
# Five scenario plants span the mass range (a grid, ends included); the
# norm-bounded model ``[dF dG] = H Delta [EF EG]``, ``||Delta|| <= 1`` is
# fitted about the mid-range car and checked to contain every scenario
# exactly. A mass between the grid points (here 300 kg) is inside the model
# too: its least-squares ``Delta`` has norm below 1.
samples = rc.sample_plants(quarter_car, {"ms": (250.0, 450.0)}, n=5)
scenarios = list(samples)
nominal = quarter_car(350.0)
uncertainty = rc.NormBounded.from_plants(nominal, scenarios)
print(samples)
print(uncertainty)


def inside(plant):
    """``(||Delta||, residual)`` of the least-squares ``Delta`` reproducing ``plant``'s deviation."""
    D = np.hstack([plant.F - nominal.F, plant.G - nominal.G])
    E = np.hstack([uncertainty.EF, uncertainty.EG])
    Delta = np.linalg.pinv(uncertainty.H) @ D @ np.linalg.pinv(E)
    return np.linalg.norm(Delta, 2), np.linalg.norm(D - uncertainty.H @ Delta @ E, 2)


print("ms = 300 kg: ||Delta|| = {:.3f}, residual {:.1e}".format(*inside(quarter_car(300.0))))

# %%
# The goals
# ---------
# * **ride comfort**: the H2 norm from road velocity (white noise) to the body
#   acceleration ``zs'' = A[1] x + B[1] u`` (output map of the mid-range
#   mass; the dynamics are each scenario's), worst scenario;
# * **suspension travel** after a 5 cm step bump (the tyre starts deflected
#   by 5 cm): the integral of the squared deflection, mean over the
#   scenarios, with the actuator saturated at 1.5 kN;
# * **peak force** in that run, worst scenario;
# * constraint: the robust margin against the norm-bounded model is at least
#   1, i.e. the design is *certified* stable for every ``||Delta|| <= 1``.
#
# The two time-domain goals share one batched simulation per population.
A, B, Bw = matrices(350.0)
Bw_d = rc.Plant.from_continuous(A, Bw, dt=DT).G          # road input, same hold
bump = tuning.Response(x0=[0.0, 0.0, -0.05, 0.0], steps=150, u_limit=1.5)
objectives = [
    tuning.H2Norm(Bw_d, A[1], B[1], name="body acceleration (H2)"),
    bump.error(states=[0], measure="ise", name="suspension travel (ISE)"),
    bump.peak_input(name="peak force [kN]"),
]
constraints = [tuning.at_least(tuning.RobustMargin(uncertainty, nominal=nominal), 1.0)]

# %%
# Tuning
# ------
# The design family is LQR on the mid-range car with diagonal weights,
# ``z = (log10 diag Q, log10 R)``; designs that do not stabilise every
# scenario are penalised by the problem and never reach the goals. A small
# budget keeps this page fast; a real run uses thousands of evaluations.
family = tuning.LQRFamily(nominal)
problem = tuning.TuningProblem(family, scenarios, objectives, constraints)
result = tuning.tune(problem, evals=300, seed=1, pop_size=20)
print(f"{len(result.X)} designs on the front after {result.run.n_evals} evaluations")

# %%
# Selection and certificate
# -------------------------
# The paper's Monte Carlo selection: each simulation draws a scenario, the
# front design with the least (range-normalised) sum of objectives on it
# wins, the most frequent winner is chosen. Its certificate is an LMI proof
# (a quadratic Lyapunov function) for every plant of the norm-bounded model.
selection = result.select(n_sims=100, seed=0)
K = selection.K
certificate = rc.robust_stability((nominal, K), uncertainty)
print(selection)
print("K =", np.array2string(K, precision=3))
print(certificate)

# %%
# Figures
# -------
# Left: the front (ride comfort against suspension travel, coloured by the
# peak force) and the chosen design. Right: the bump response of the chosen
# design on every scenario, against the passive suspension (``K = 0``).
F = result.F
runs = bump.simulate(np.stack([K, np.zeros_like(K)]), scenarios)
t = np.arange(bump.steps) * DT
masses = samples.params[:, 0]

fig, (ax_f, ax_x, ax_u) = plt.subplots(1, 3, figsize=(13, 3.8), layout="constrained")
sc = ax_f.scatter(F[:, 0], F[:, 1], c=F[:, 2], cmap="viridis", s=25)
ax_f.scatter(F[selection.index, 0], F[selection.index, 1], marker="*", s=200,
             color="C3", label="selected")
fig.colorbar(sc, ax=ax_f, label=problem.objective_names[2])
ax_f.set(xlabel=problem.objective_names[0], ylabel=problem.objective_names[1],
         title="front")
ax_f.legend()
for s, ms in enumerate(masses):
    c = plt.cm.plasma(s / (len(masses) - 1) * 0.8)
    ax_x.plot(t, 100 * runs.states[0, s, :, 0], color=c, label=f"{ms:.0f} kg")
    ax_x.plot(t, 100 * runs.states[1, s, :, 0], color=c, ls=":", lw=1)
    ax_u.plot(t, runs.inputs[0, s, :, 0], color=c)
ax_x.set(xlabel="time [s]", ylabel="suspension deflection [cm]",
         title="after a 5 cm bump (dotted: passive)")
ax_x.legend(fontsize=8)
ax_u.axhline(1.5, color="k", lw=0.8, ls="--")
ax_u.axhline(-1.5, color="k", lw=0.8, ls="--")
ax_u.set(xlabel="time [s]", ylabel="actuator force [kN]", title="force (limit 1.5 kN)")
plt.show()

# %%
# Every mass of a finer grid over the range is inside the norm-bounded model
# (a contraction ``Delta`` reproduces its deviation), so the certificate
# covers it, and indeed the spectral radius of ``F + G K`` stays below 1.
fine = rc.sample_plants(quarter_car, {"ms": (250.0, 450.0)}, n=41)
fits = np.array([inside(p) for p in fine])
rho = [rc.spectral_radius(p.F + p.G @ K) for p in fine]
print(f"41 masses in 250-450 kg: largest ||Delta|| {fits[:, 0].max():.3f} "
      f"(residual <= {fits[:, 1].max():.1e}), largest spectral radius {max(rho):.4f}")
