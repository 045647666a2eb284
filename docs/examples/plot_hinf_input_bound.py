"""
H-infinity with an input bound, and its certificate
===================================================

:func:`robustctl.hinf` minimises the level ``gamma`` of the closed loop
``||T_zw||_inf < gamma`` by LMIs (bounded-real lemma, ``Y = K X``). The same
Lyapunov matrix ``X`` bounds the states reachable with disturbances of energy
``sum |w|^2 <= E``, so the LMI ``[[u_max^2/E, y], [y', X]] >= 0`` guarantees
``|u| <= u_max`` for all of them (Boyd et al. 1994, Sec. 7.2.3). A tighter
bound costs performance: ``gamma`` grows.

The plant is the paper's truck at nominal payload; the disturbances are a
lateral-displacement impulse and the path curvature, the performance output
weights states and steering with Bryson's rule.
"""

# %%
# Level against input bound
# -------------------------
import control
import matplotlib.pyplot as plt
import numpy as np

import robustctl as rc
from robustctl.models import truck

plant = truck.truck_plant(0.0)
Q, R = truck.lqr_weights()
_, _, Gk = truck.discretise(0.0)
Bw = np.column_stack([[0.0, 0.0, 1.0, 0.0], Gk[0] / 200.0])
Cz, Dzu = rc.lq_output(Q, R)                  # z = [Q^1/2 x; R^1/2 u]

free = rc.design("hinf", plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
bounds = [0.1, 0.2, 0.3, 0.45, 0.7, 1.0]
designs = [rc.design("hinf", plant, Bw=Bw, Cz=Cz, Dzu=Dzu, u_max=u,
                     w_energy=1.0) for u in bounds]

fig, ax = plt.subplots(figsize=(6, 3.4), layout="constrained")
ax.plot(bounds, [d.gamma for d in designs], "o-", label="with the input bound")
ax.axhline(free.gamma, color="k", ls="--", lw=0.8,
           label=f"no bound: $\\gamma$ = {free.gamma:.3g}")
ax.set(xlabel=r"guaranteed $|\alpha| \leq u_{max}$ [rad] (unit-energy $w$)",
       ylabel=r"$\gamma$")
ax.legend()

# %%
# The certificate, checked independently
# --------------------------------------
# ``info["certificate"]`` holds the smallest eigenvalue of every LMI block
# at the returned point: all positive means the LMIs hold strictly. The level
# is checked against python-control's ``linfnorm`` of the closed loop
# ``x+ = (F + G K) x + Bw w``, ``z = (Cz + Dzu K) x``, and the input bound
# against ``u_bound`` = ``max sqrt(E k X k')``.
ctrl = designs[bounds.index(0.45)]
cl = control.ss(ctrl.closed_loop(), Bw, Cz + Dzu @ ctrl.K, np.zeros((5, 2)),
                plant.dt)
norm, _ = control.linfnorm(cl)
print(f"gamma = {ctrl.gamma:.5g} (optimum {ctrl.gamma_opt:.5g}), "
      f"||T_zw||_inf = {norm:.5g}")
for block, eig in ctrl.info["certificate"].items():
    print(f"  LMI block {block}: smallest eigenvalue {eig:.3g}")
u_bound = float(np.max(ctrl.info["u_bound"]))
print(f"guaranteed max |alpha| = {u_bound:.4f} rad (asked 0.45)")

# %%
# Worst-case steering over unit-energy disturbances
# -------------------------------------------------
# The largest ``|alpha| = |k x|`` that any disturbance of unit energy can
# produce from ``x0 = 0`` is ``sqrt(k Wc k')``, with ``Wc`` the
# controllability Gramian of ``(F + G K, Bw)`` (a Lyapunov equation, scipy);
# the disturbance that achieves it in ``N`` steps is
# ``w[j] = Bw' (A')^(N-1-j) k' / sqrt(k Wc_N k')``. The guarantee must lie
# above it; random unit-energy disturbances stay well below.
from scipy.linalg import solve_discrete_lyapunov

A, k = ctrl.closed_loop(), ctrl.K
Wc = solve_discrete_lyapunov(A, Bw @ Bw.T)
worst = float(np.sqrt(k @ Wc @ k.T)[0, 0])

N = 300
powers = [np.linalg.matrix_power(A.T, N - 1 - j) for j in range(N)]
w = np.array([Bw.T @ P @ k.T for P in powers])[:, :, 0]
w /= np.sqrt((w**2).sum())
x, steer = np.zeros(4), []
for j in range(N):
    x = A @ x + Bw @ w[j]
    steer.append(float((k @ x)[0]))

rng = np.random.default_rng(0)
W = rng.standard_normal((2000, N, 2))
W /= np.sqrt((W**2).sum(axis=(1, 2)))[:, None, None]
X = np.zeros((2000, 4))
peak = np.zeros(2000)
for j in range(N):
    X = X @ A.T + W[:, j] @ Bw.T
    peak = np.maximum(peak, np.abs(X @ k.T)[:, 0])

bound = float(np.max(ctrl.info["u_bound"]))
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.2), layout="constrained")
ax1.plot(np.arange(1, N + 1) * plant.dt, steer)
ax1.axhline(bound, color="r", label="guaranteed bound")
ax1.set(xlabel="time [s]", ylabel=r"$\alpha$ [rad]",
        title="worst-case disturbance (peak at the end)")
ax1.legend()
ax2.hist(peak, bins=40, label="2000 random disturbances")
ax2.axvline(worst, color="k", ls="--", label="worst case")
ax2.axvline(bound, color="r", label="guaranteed bound")
ax2.set(xlabel=r"peak $|\alpha|$ [rad]", ylabel="count")
ax2.legend(fontsize=8)
print(f"worst case sqrt(k Wc k') = {worst:.4f} rad <= bound {bound:.4f} rad")
print(f"2000 random unit-energy disturbances: at most {peak.max():.4f} rad")
