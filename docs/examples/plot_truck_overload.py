"""
RLQR vs LQR vs H-infinity on the truck under overload
=====================================================

The paper's applied comparison (Morais et al. 2022, Section 4.5.2): three
state-feedback gains, each designed on the *nominal* truck (0 % overload),
drive the truck along a 9 km route while the real payload is 0, 100, 200 and
300 % above nominal. The controllers know only the nominal model; the payload
changes the plant's mass and yaw inertia.

* **LQR** with Bryson's-rule weights (:func:`robustctl.models.truck.lqr_weights`).
* **RLQR^MOP**: the robust LQR with the uncertainty the paper's MOEA found,
  its printed decision vector :data:`robustctl.models.morais2022.RLQR_MOP_Z`, on the
  doubled steering column (two inputs whose sum is the steering angle).
* **H-infinity** by LMIs, with a lateral-displacement impulse and the path
  curvature as disturbances and the guaranteed input bound
  ``|alpha| <= 0.45 rad`` for unit-energy disturbances.
"""

# %%
# Design the three gains on the nominal model
# -------------------------------------------
import matplotlib.pyplot as plt
import numpy as np

import robustctl as rc
from robustctl.models import morais2022, truck
from robustctl.models.path import default_route
from robustctl.models.pathfollow import simulate

plant = truck.truck_plant(0.0)    # x = [ydot, psidot, rho, theta], u = alpha
Q, R = truck.lqr_weights()
lqr = rc.design("lqr", plant, Q=Q, R=R)

plant2 = truck.truck_plant(0.0, doubled=True)   # G2 = [G G], alpha = u1 + u2
Q2, R2 = truck.lqr_weights(doubled=True)
EF, EG, mu = morais2022.uncertainty_from_z(morais2022.RLQR_MOP_Z)
rlqr = rc.design("rlqr", plant2, EF[0], EG[0], mu[0], Q=Q2, R=R2,
                 H=np.ones((4, 1)))

# disturbances: a rho impulse and the curvature of a 200 m bend
_, _, Gk = truck.discretise(0.0)       # curvature input of the ZOH model
Bw = np.column_stack([[0.0, 0.0, 1.0, 0.0], Gk[0] / 200.0])
Cz, Dzu = rc.lq_output(Q, R)                  # z = [Q^1/2 x; R^1/2 u]
hinf = rc.design("hinf", plant, Bw=Bw, Cz=Cz, Dzu=Dzu,
                 u_max=truck.STEER_LIMIT, w_energy=1.0)

print(lqr)
print(rlqr)
bound = float(np.max(hinf.info["u_bound"]))
print(f"H-infinity: gamma = {hinf.gamma:.4g}, "
      f"guaranteed |alpha| <= {bound:.3f} rad")

# %%
# Simulate every gain at every payload in one batched call
# ---------------------------------------------------------
# The simulator takes a stack of gains ``(B, m, n)``; the RLQR gain has two
# input rows (the doubled column), so each gain is reduced to the steering
# gain ``alpha = (sum of the rows) e``, which is what the simulator applies.
names = ["LQR", "RLQR$^{MOP}$", "H-infinity"]
K = np.stack([lqr.K, rlqr.K.sum(axis=0, keepdims=True), hinf.K])
overloads = [0.0, 100.0, 200.0, 300.0]
path = default_route()
res = simulate(K, path, overloads)
mse = res.mse()      # (B, S, 4): f1..f4 = MSE of rho, psidot, ydot, theta
print(f"{path.T} steps, diverged: {res.diverged.any()}")

# %%
# Lateral displacement error at 300 % overload
# --------------------------------------------
t = np.arange(path.T) * path.dt
fig, ax = plt.subplots(figsize=(8, 3.2), layout="constrained")
for b, name in enumerate(names):
    ax.plot(t, res.errors[b, -1, :, 2], lw=0.8, label=name)
ax.set(xlabel="time [s]", ylabel=r"$\rho - \rho_{ref}$ [m]",
       title="300 % overload")
fig.legend(loc="outside right upper")

# %%
# MSE of the four objectives against the payload
# ----------------------------------------------
labels = [r"$f_1$: $\rho$ [m$^2$]", r"$f_2$: $\dot\psi$ [rad$^2$/s$^2$]",
          r"$f_3$: $\dot y$ [m$^2$/s$^2$]", r"$f_4$: $\theta$ [rad$^2$]"]
fig, axes = plt.subplots(1, 4, figsize=(11, 3), layout="constrained")
for j, ax in enumerate(axes):
    for b, name in enumerate(names):
        ax.semilogy(overloads, mse[b, :, j], "o-", label=name)
    ax.set(xlabel="overload [%]", title=labels[j])
axes[0].legend()

print(f"{'MSE at 300 %':14s}",
      "  ".join(f"{h:>9s}" for h in ("f1", "f2", "f3", "f4")))
for b, name in enumerate(["LQR", "RLQR^MOP", "H-infinity"]):
    print(f"{name:14s}", "  ".join(f"{v:.3e}" for v in mse[b, -1]))
