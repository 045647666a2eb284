"""
Output-feedback H-infinity for a plant with one measured output
===============================================================

Two masses coupled by a spring (the noncollocated benchmark of Wie &
Bernstein): the actuator pushes the first mass, a disturbance force acts on
the second, and only the position of the second mass is measured, with
noise. No state feedback is possible: :func:`robustctl.hinf` returns a
full-order dynamic controller ``u = K(s) y`` as soon as the plant declares
its output (``Plant(..., C=...)``). Both of its paths are compared with
python-control's ``hinfsyn`` (SLICOT), and every closed loop is assembled
and measured by python-control itself.
"""

# %%
# The plant and the channels
# --------------------------
# States ``(x1, x2, v1, v2)``; ``w = (disturbance force, sensor noise)``;
# ``z = (x2, 0.3 u)``: keep the second mass still without too much force;
# ``y = x2 + 0.05 noise``.
import control
import matplotlib.pyplot as plt
import numpy as np

import robustctl as rc

k, c = 1.0, 0.02
A = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0], [-k, k, -c, c], [k, -k, c, -c]])
G = np.array([[0.0], [0.0], [1.0], [0.0]])
plant = rc.Plant(A, G, None, C=[[0.0, 1.0, 0.0, 0.0]])
Bw = np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [1.0, 0.0]])
Cz = np.array([[0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]])
Dzu = np.array([[0.0], [0.3]])
Dyw = np.array([[0.0, 0.05]])

# %%
# Design, and the same problem in python-control
# ----------------------------------------------
# The LMI path (default) minimises the level and reconstructs the controller
# at ``(1 + backoff)`` times it; the Riccati path iterates on the two Riccati
# equations of Glover & Doyle and returns the central controller. python-
# control takes the generalised plant ``[w; u] -> [z; y]``.
lmi = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dyw=Dyw)
fast = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dyw=Dyw, synthesis="riccati")
P = control.ss(A, np.hstack([Bw, G]), np.vstack([Cz, plant.C]),
               np.block([[np.zeros((2, 2)), Dzu], [Dyw, np.zeros((1, 1))]]))
K_pc, _, gamma_pc, _ = control.hinfsyn(P, 1, 1)

loops = {"robustctl, LMI": P.lft(lmi.controller_statespace()),
         "robustctl, Riccati": P.lft(fast.controller_statespace()),
         "python-control hinfsyn": P.lft(K_pc)}
print(f"optimal level: LMI {lmi.gamma_opt:.6f}, Riccati {fast.gamma_opt:.6f}, hinfsyn {gamma_pc:.6f}")
for name, cl in loops.items():
    print(f"{name:24s} ||T_zw||_inf = {control.linfnorm(cl)[0]:.6f}, "
          f"largest closed-loop pole real part {np.max(cl.poles().real):.4f}")
print(f"guaranteed: LMI {lmi.gamma:.6f}, Riccati {fast.gamma:.6f}; controller order {lmi.order}")
for name, K in (("LMI", lmi.controller_statespace()), ("Riccati", fast.controller_statespace()),
                ("hinfsyn", K_pc)):
    print(f"fastest controller pole, {name}: {np.min(K.poles().real):.3g}")

# %%
# The three closed loops, frequency by frequency
# ----------------------------------------------
# The largest singular value of ``T_zw(j w)``, sampled: all three lie at or
# below the level, nearly flat (the equalising that H-infinity-optimal loops
# show). Ours are built 0.1 % above the optimum, where the reconstruction is
# well conditioned and the controller's poles moderate. hinfsyn's
# controller is computed at the optimum itself, where a mode of the central
# controller escapes to infinity: its fastest pole (printed above) makes the
# loop so stiff that python-control's own ``linfnorm`` of it (printed above)
# is not its peak over frequency.
w = np.logspace(-2, 4, 1200)
fig, ax = plt.subplots(figsize=(6.4, 3.4), layout="constrained")
for (name, cl), ls in zip(loops.items(), ["-", "--", ":"], strict=True):
    sv = np.array([np.linalg.svd(cl(1j * wi), compute_uv=False)[0] for wi in w])
    ax.semilogx(w, sv, ls, label=name)
ax.axhline(lmi.gamma, color="k", lw=0.8, label=rf"guaranteed $\gamma$ = {lmi.gamma:.4g}")
ax.set(xlabel=r"$\omega$ [rad/s]", ylabel=r"$\bar\sigma(T_{zw}(j\omega))$", ylim=(1.0, 1.08))
ax.legend(fontsize=8)

# %%
# A disturbance pulse
# -------------------
# The position of the second mass after a unit force pulse of 1 s on it,
# and the sensor noise switched off: with each controller, and open loop
# (the spring mode barely damped).
t = np.linspace(0.0, 40.0, 2001)
pulse = np.vstack([(t < 1.0).astype(float), np.zeros_like(t)])
fig, ax = plt.subplots(figsize=(6.4, 3.2), layout="constrained")
for (name, cl), ls in zip(loops.items(), ["-", "--", ":"], strict=True):
    ax.plot(t, control.forced_response(cl, t, pulse).outputs[0], ls, label=name)
open_loop = control.ss(A, Bw[:, :1], Cz[:1], 0)
ax.plot(t, control.forced_response(open_loop, t, pulse[:1]).outputs, color="0.6", lw=0.8, label="open loop")
ax.set(xlabel="t [s]", ylabel="$x_2$", ylim=(-1.5, 1.5))
ax.legend(fontsize=8, ncol=2)

# %%
# Loop margins and robust stability
# ---------------------------------
# :func:`robustctl.loop_margins` breaks the loop at the plant input
# (``L = -K(s) P(s)``: our controllers feed back without a minus sign, so
# the negative-feedback loop transfer carries it): the disk margin
# ``alpha`` with the gain and phase variations it guarantees together, the
# classical gain and phase margins and the sensitivity peaks, all exact (level
# sets and eigenvalue problems, no frequency grid). python-control's
# ``stability_margins`` of the same loop, built by hand, agrees. A
# norm-bounded uncertainty of the spring constant, ``k (1 + delta)``,
# ``|delta| <= r``, enters ``A`` through ``H Delta EF``;
# :func:`robustctl.robust_stability` certifies the loop for the largest
# ``r`` (its ``margin``, a robust-stability radius, another kind of margin).
m = rc.loop_margins(lmi, at="input")
print(f"disk margin alpha = {m.alpha:.4f}: gain in [{m.gain_range[0]:.3f}, {m.gain_range[1]:.3f}], "
      f"phase +-{m.phase_range:.1f} deg; GM {m.gain_margin:.3f}, PM {m.phase_margin:.1f} deg, "
      f"S peak {m.S_peak:.3f}, T peak {m.T_peak:.3f}")
L_hand = -lmi.controller_statespace() * plant.to_statespace()
gm, pm = control.stability_margins(L_hand)[:2]
print(f"python-control on -K(s) P(s): GM {gm:.3f}, PM {pm:.1f} deg")
H = np.array([[0.0], [0.0], [1.0], [-1.0]])
EF = np.array([[-k, k, 0.0, 0.0]])
spring = rc.NormBounded(H, EF, np.zeros((1, 1)))
res = rc.robust_stability(lmi, spring)
print(f"spring stiffness: certified stable for |delta| <= {res.margin:.3f} (certificate {res.certified})")

# %%
# The margins are small: the design asked only for disturbance rejection
# against a sensor it was told is nearly noiseless, so the controller uses
# the measurement aggressively. Telling the design the sensor is noisier
# (a larger ``Dyw``) trades level for margins; the margins are goals a
# tuning problem can set directly (``moo.tuning.DiskMargin``).
for noise in (0.05, 0.3, 1.0):
    ctrl = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dyw=[[0.0, noise]], synthesis="riccati")
    mi = rc.loop_margins(ctrl, at="input")
    print(f"sensor noise weight {noise:4.2f}: gamma {ctrl.gamma:.3f}, disk margin {mi.alpha:.3f}, "
          f"GM {mi.gain_margin:.3f}, PM {mi.phase_margin:.1f} deg, "
          f"spring |delta| <= {rc.robust_stability(ctrl, spring).margin:.3f}")

# %%
# What the result holds
# ---------------------
# ``ctrl.info["certificate"]`` is the closed loop's certificate by
# eigenvalues: its stability margin and the distance of its Hamiltonian's
# eigenvalues from the imaginary axis at the guaranteed level (none on the
# axis: the bounded-real lemma's frequency form); ``info["solves"]`` the two
# SDP solves of the LMI path.
print(lmi.info["certificate"], [s["status"] for s in lmi.info["solves"]])
print(fast.info["synthesis"], fast.info["riccati"])
