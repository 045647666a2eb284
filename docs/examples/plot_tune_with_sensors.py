"""
Tune a controller for a plant with one sensor
=============================================

Most plants measure a few outputs, not their whole state. Here a **servo
with an elastic shaft** (a motor driving a load through a torsional spring)
has one encoder, on the motor; the load's inertia varies by a factor of four
(0.01 to 0.04 kg m^2, an empty to a full gripper). The steps:

1. the plant with its output model ``y = C x`` (:class:`robustctl.Plant`
   with ``C``) and the scenario plants;
2. a fixed-structure controller family: a discrete PID on the encoder
   (:class:`moo.tuning.PIDFamily`; :class:`~moo.tuning.StaticOutputFeedbackFamily`
   and :class:`~moo.tuning.FixedOrderFamily` work the same way);
3. goals on the loops: a position step (tracking error, overshoot, peak
   input), the disk margin at the plant input and the position variance
   under encoder noise;
4. tuning, the Monte Carlo selection, and the chosen controller checked
   against python-control's closed loop.
"""

# %%
# The plant and its scenarios
# ---------------------------
# States: motor angle and speed, load angle and speed; input: the motor
# current; output: the motor angle (the encoder). The rigid-body mode is an
# integrator (a pole at ``z = 1``); the shaft adds a lightly damped mode.
import control
import matplotlib.pyplot as plt
import numpy as np

import robustctl as rc
from moo import tuning

DT = 0.01


def servo(load_inertia):
    """Continuous ``(A, B)`` of the two-inertia servo (motor 0.01 kg m^2, shaft 2 N m/rad, 0.5 N m/A)."""
    Jm, bm, bl, ks, km = 0.01, 0.02, 0.01, 2.0, 0.5
    JL = load_inertia
    A = np.array([[0.0, 1.0, 0.0, 0.0], [-ks / Jm, -bm / Jm, ks / Jm, 0.0],
                  [0.0, 0.0, 0.0, 1.0], [ks / JL, 0.0, -ks / JL, -bl / JL]])
    return A, np.array([[0.0], [km / Jm], [0.0], [0.0]])


plant = rc.Plant.from_continuous(*servo(0.02), dt=DT, C=[[1.0, 0.0, 0.0, 0.0]])
loads = (0.01, 0.02, 0.04)
scenarios = [rc.Plant.from_continuous(*servo(J), dt=DT) for J in loads]     # their C: the family's
print(plant)
print("open-loop pole moduli:", np.abs(np.linalg.eigvals(plant.F)).round(4))

# %%
# The family and the goals
# ------------------------
# A PID per (output, input) loop in the parallel form ``(Kp, Ki, Kd, Tf)``
# acting on ``e = r - y``, discretised with a forward-difference integral and
# a backward-difference filtered derivative; the decision vector holds
# ``log10`` of the four. In the library's convention ``u = K(z) (y - r)``
# the controller is ``K(z) = -C_PID(z)``. The goals, all batched over the
# population and the three scenarios:
#
# * a 1 rad position step over 3 s: mean squared tracking error (mean over
#   the scenarios), overshoot and peak current (worst scenario);
# * the disk margin at the plant input, worst scenario (maximised; it is
#   minimised as its inverse): the simultaneous gain and phase variations
#   the loop tolerates;
# * constraints: the disk margin guarantees 6 dB and 35 degrees in every
#   scenario (``Margins``), and the position variance caused by an encoder
#   noise of standard deviation 1 mrad stays below 1e-6 rad^2.
family = tuning.PIDFamily(plant)
print(family, family.parameters)
step = tuning.StepTracking(300, signal=0, amplitude=1.0, width=1, n=4)
objectives = [step.error(name="position MSE"), step.overshoot(name="overshoot"),
              step.peak_input(name="peak current"), tuning.DiskMargin()]
noise = tuning.Variance(Bw=np.zeros((4, 1)), V=[[1e-6]], name="position variance")
constraints = [tuning.at_most(tuning.Margins(gain_db=6.0, phase_deg=35.0), 1.0), tuning.at_most(noise, 1e-6)]
problem = tuning.TuningProblem(family, scenarios, objectives, constraints)
print(problem)

# %%
# Tuning and selection
# --------------------
# A small budget keeps this page fast (a real run uses thousands of
# evaluations); the hypervolume is measured from a reference point sampled
# from random designs, not from the penalty.
result = tuning.tune(problem, evals=1500, seed=1, pop_size=40)
print(result)
print(result.summary())
selection = result.select(n_sims=200, seed=0)
chosen = selection.controller
prm = family.pid_parameters(result.X[selection.index])
print(selection)
print("chosen PID:", {name: float(np.round(value[0, 0], 4)) for name, value in prm.items()})

# %%
# Check against python-control
# ----------------------------
# The chosen controller is ``K(z)`` in ``u = K(z) (y - r)``: the classic
# negative-feedback loop of the plant and ``-K(z)`` has the same step
# response as the one the goals simulated, and python-control's disk margin
# of that loop at the frequency of the peak that :func:`robustctl.loop_margins`
# found is the goal's value.
fig, (ax_y, ax_u) = plt.subplots(1, 2, figsize=(10, 3.6), layout="constrained")
t = np.arange(300) * DT
for J, scenario in zip(loads, scenarios, strict=True):
    P = control.ss(scenario.F, scenario.G, plant.C, 0.0, DT)
    loop = control.feedback(P * -chosen.controller_statespace())
    _, y = control.step_response(loop, t)
    ours = rc.sim.simulate_output_feedback(chosen.as_batch(), [scenario], 300, reference=np.ones((300, 1)))
    assert np.allclose(ours.outputs[0, 0, :, 0], y, atol=1e-9)
    ax_y.plot(t, y, label=f"load {J} kg m^2")
    ax_u.plot(t, ours.inputs[0, 0, :, 0])
    on_scenario = rc.Controller.dynamic(chosen.Ac, chosen.Bc, chosen.Cc, chosen.Dc, "pid",
                                        rc.Plant(scenario.F, scenario.G, DT, C=plant.C))
    margins = rc.loop_margins(on_scenario)
    dm = control.disk_margins(P * -chosen.controller_statespace(), np.array([margins.alpha_freq]))[0]
    assert np.isclose(margins.alpha, dm, rtol=1e-8)
    print(f"load {J}: loop poles inside the unit circle: {bool(np.all(np.abs(loop.poles()) < 1))}, "
          f"position at 3 s {y[-1]:.3f} rad, disk margin {margins.alpha:.3f} "
          f"(gain {margins.gain_range[0]:.2f} to {margins.gain_range[1]:.2f}, phase +-{margins.phase_range:.1f} deg)")
ax_y.axhline(1.0, color="k", lw=0.8, ls=":")
ax_y.set(xlabel="t [s]", ylabel="motor angle [rad]", title="position step, chosen PID")
ax_u.set(xlabel="t [s]", ylabel="current [A]", title="input")
ax_y.legend()
plt.show()
